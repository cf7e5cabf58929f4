//! Writing a run's output directory: all of it or none of it, and only
//! over a directory that pilgrim wrote.
//!
//! A run writes its files into a temporary directory beside the target
//! (`.NAME.tmp-PID`), marks it with [`MARKER`] (which lists the files), and
//! swaps it in: on Linux by an atomic exchange of the two directories
//! (`renameat2(RENAME_EXCHANGE)`), so the target always holds the old
//! output or the whole new one; elsewhere by two renames. The target must
//! be new, or a previous pilgrim output (it holds the marker) holding no
//! file the marker does not list: anything else is refused, naming what
//! is in the way, and nothing is touched. Temporary directories that killed
//! runs left beside the target are removed by the next run, but only those
//! of a process that is gone and only if pilgrim marked them.

use std::path::{Path, PathBuf};

/// The file that marks a directory as pilgrim's output.
pub const MARKER: &str = ".pilgrim-output";

/// An output that cannot be written.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{path}: {message}")]
pub struct OutputError {
    /// The path.
    pub path: String,
    /// Why, and what to do.
    pub message: String,
}

fn err(path: &Path, message: impl Into<String>) -> OutputError {
    OutputError {
        path: path.display().to_string(),
        message: message.into(),
    }
}

/// What a FAILED run's marker says on its first line.
const FAILED_RUN: &str = "of a FAILED run (no program)";

/// The marker's text: what wrote the directory (a run, or a failed run),
/// and its files.
fn marker_text(files: &[&str], failed: bool) -> String {
    let mut s = format!(
        "pilgrim {} output directory{}: the next run to it replaces it as a whole.\n",
        crate::VERSION,
        if failed {
            format!(" {FAILED_RUN}")
        } else {
            String::new()
        }
    );
    for f in files {
        s.push_str(f);
        s.push('\n');
    }
    s
}

/// The files a marker lists.
fn marked_files(text: &str) -> Vec<&str> {
    text.lines().skip(1).filter(|l| !l.is_empty()).collect()
}

/// Whether `name` may be written in an output directory: a plain file name.
fn plain(name: &str) -> bool {
    !name.is_empty()
        && name != "."
        && name != ".."
        && !name.starts_with('.')
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'))
}

/// Checks that `out` may be replaced: it does not exist, or it is a
/// directory pilgrim wrote, holding only the files its marker lists.
///
/// # Failures
/// A path that is not a directory, a directory without the marker, or one
/// holding files the marker does not list: each named.
pub fn check_replaceable(out: &Path) -> Result<(), OutputError> {
    let meta = match std::fs::symlink_metadata(out) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(err(out, e.to_string())),
        Ok(m) => m,
    };
    if !meta.is_dir() {
        return Err(err(
            out,
            "is not a directory: pilgrim writes its outputs into a directory of their own; give --out a new directory name",
        ));
    }
    let marker = std::fs::read_to_string(out.join(MARKER)).ok();
    let entries: Vec<String> = std::fs::read_dir(out)
        .map_err(|e| err(out, e.to_string()))?
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n != MARKER && !is_temporary(n))
        .collect();
    let Some(marker) = marker else {
        let mut shown: Vec<&str> = entries.iter().map(String::as_str).collect();
        shown.sort_unstable();
        shown.truncate(5);
        return Err(err(
            out,
            format!(
                "exists and was not written by pilgrim (it holds {}): pilgrim replaces only its own output directories; give --out a new directory name, or move this one away yourself",
                if shown.is_empty() {
                    "nothing".to_owned()
                } else {
                    shown.join(", ")
                }
            ),
        ));
    };
    let listed = marked_files(&marker);
    let mut foreign: Vec<&str> = entries
        .iter()
        .map(String::as_str)
        .filter(|n| !listed.contains(n))
        .collect();
    if !foreign.is_empty() {
        foreign.sort_unstable();
        foreign.truncate(5);
        return Err(err(
            out,
            format!(
                "is a pilgrim output, but holds files pilgrim did not write ({}): move them away, or give --out another directory",
                foreign.join(", ")
            ),
        ));
    }
    Ok(())
}

/// Whether `name` is one of pilgrim's own temporary files or directories
/// (`.NAME.tmp-PID`, `.NAME.old-PID`).
fn is_temporary(name: &str) -> bool {
    name.starts_with('.')
        && [".tmp-", ".old-"].iter().any(|k| {
            name.rsplit_once(k)
                .is_some_and(|(_, pid)| !pid.is_empty() && pid.bytes().all(|b| b.is_ascii_digit()))
        })
}

/// Whether the process `pid` is gone (Linux: no `/proc/PID`; elsewhere
/// never known, so never).
fn process_gone(pid: u32) -> bool {
    cfg!(target_os = "linux") && !Path::new("/proc").join(pid.to_string()).exists()
}

/// Removes the temporary directories of killed runs to `base` in `parent`:
/// `.BASE.tmp-PID` and `.BASE.old-PID` of a process that is gone, if pilgrim
/// marked them.
fn clean_stale(parent: &Path, base: &str) {
    let Ok(entries) = std::fs::read_dir(parent) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let pid = [".tmp-", ".old-"].iter().find_map(|kind| {
            name.strip_prefix(&format!(".{base}{kind}"))
                .and_then(|p| p.parse::<u32>().ok())
        });
        let Some(pid) = pid else { continue };
        let path = e.path();
        if pid != std::process::id()
            && process_gone(pid)
            && path.join(MARKER).is_file()
            && std::fs::symlink_metadata(&path).is_ok_and(|m| m.is_dir())
        {
            let _ = std::fs::remove_dir_all(&path);
        }
    }
}

/// Swaps `a` and `b` atomically where the system can (both must exist).
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> std::io::Result<bool> {
    use std::os::unix::ffi::OsStrExt;
    let ca = std::ffi::CString::new(a.as_os_str().as_bytes())?;
    let cb = std::ffi::CString::new(b.as_os_str().as_bytes())?;
    // SAFETY: two valid NUL-terminated paths, relative to the working
    // directory; the call reads nothing else.
    let r = unsafe {
        libc::renameat2(
            libc::AT_FDCWD,
            ca.as_ptr(),
            libc::AT_FDCWD,
            cb.as_ptr(),
            libc::RENAME_EXCHANGE,
        )
    };
    if r == 0 {
        Ok(true)
    } else {
        let e = std::io::Error::last_os_error();
        match e.raw_os_error() {
            // Not supported by this file system or kernel: fall back.
            Some(libc::EINVAL) | Some(libc::ENOSYS) => Ok(false),
            _ => Err(e),
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn exchange(_: &Path, _: &Path) -> std::io::Result<bool> {
    Ok(false)
}

/// Whether `dir` holds a pilgrim output of a run that succeeded: its
/// marker is there and does not say the run failed.
pub fn holds_good_output(dir: &Path) -> bool {
    std::fs::read_to_string(dir.join(MARKER))
        .is_ok_and(|m| m.lines().next().is_some_and(|l| !l.contains(FAILED_RUN)))
}

/// Where a failed run's diagnostic goes when it was asked to write into
/// `out`: `out` itself, unless `out` holds the output of a run that
/// succeeded, which stays as it is: then `<out>.failed` beside it. The two
/// are never confused: a failed run's marker, report and page say FAILED,
/// and it holds no program.
pub fn failed_dir(out: &Path) -> PathBuf {
    if holds_good_output(out) {
        let mut name = out.file_name().unwrap_or_default().to_os_string();
        name.push(".failed");
        out.with_file_name(name)
    } else {
        out.to_owned()
    }
}

/// Writes a failed run's `files` (its diagnostic: no program) where
/// [`failed_dir`] says, as [`write_dir`] writes; the directory written.
///
/// # Failures
/// As [`write_dir`].
pub fn write_failed(out: &Path, files: &[(String, Vec<u8>)]) -> Result<PathBuf, OutputError> {
    let dir = failed_dir(out);
    write_marked(&dir, files, true)?;
    Ok(dir)
}

/// Writes `files` as the directory `out`, replacing a previous pilgrim
/// output there, and removes the diagnostic a failed run left beside it
/// (`<out>.failed`, if pilgrim wrote it and it says so). See the [module
/// docs](self).
///
/// # Failures
/// [`check_replaceable`]'s; a file name that is not a plain name; a write
/// or rename failing (the target is then as it was).
pub fn write_dir(out: &Path, files: &[(String, Vec<u8>)]) -> Result<(), OutputError> {
    write_marked(out, files, false)?;
    let mut name = out.file_name().unwrap_or_default().to_os_string();
    name.push(".failed");
    let stale = out.with_file_name(name);
    let failed_marker = std::fs::read_to_string(stale.join(MARKER))
        .is_ok_and(|m| m.lines().next().is_some_and(|l| l.contains(FAILED_RUN)));
    if failed_marker
        && std::fs::symlink_metadata(&stale).is_ok_and(|m| m.is_dir())
        && check_replaceable(&stale).is_ok()
    {
        let _ = std::fs::remove_dir_all(&stale);
    }
    Ok(())
}

/// [`write_dir`]'s writing, the marker saying whether the run failed.
fn write_marked(out: &Path, files: &[(String, Vec<u8>)], failed: bool) -> Result<(), OutputError> {
    let parent = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_owned(),
        _ => PathBuf::from("."),
    };
    let base = out
        .file_name()
        .and_then(|n| n.to_str())
        .ok_or_else(|| err(out, "not a directory name"))?;
    if let Some((bad, _)) = files.iter().find(|(n, _)| !plain(n)) {
        return Err(err(out, format!("'{bad}' is not a plain file name")));
    }
    check_replaceable(out)?;
    std::fs::create_dir_all(&parent).map_err(|e| err(&parent, e.to_string()))?;
    clean_stale(&parent, base);
    let tmp = parent.join(format!(".{base}.tmp-{}", std::process::id()));
    let old = parent.join(format!(".{base}.old-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    let result = (|| {
        std::fs::create_dir(&tmp).map_err(|e| err(&tmp, e.to_string()))?;
        let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
        std::fs::write(tmp.join(MARKER), marker_text(&names, failed))
            .map_err(|e| err(&tmp, e.to_string()))?;
        for (name, bytes) in files {
            let p = tmp.join(name);
            std::fs::write(&p, bytes).map_err(|e| err(&p, e.to_string()))?;
        }
        if out.exists() {
            if exchange(&tmp, out).map_err(|e| err(out, e.to_string()))? {
                // `tmp` now holds the old output.
                let _ = std::fs::remove_dir_all(&tmp);
                return Ok(());
            }
            std::fs::rename(out, &old).map_err(|e| err(out, e.to_string()))?;
        }
        std::fs::rename(&tmp, out).map_err(|e| {
            let _ = std::fs::rename(&old, out);
            err(out, e.to_string())
        })?;
        let _ = std::fs::remove_dir_all(&old);
        Ok(())
    })();
    if result.is_err() {
        let _ = std::fs::remove_dir_all(&tmp);
    }
    result
}

/// Writes `files` over some of those of the pilgrim output `dir`, each
/// through a temporary file and a rename, and adds them to its marker.
///
/// # Failures
/// `dir` not a pilgrim output ([`check_replaceable`]); a file name that is
/// not a plain name; a write failing.
pub fn update_dir(dir: &Path, files: &[(String, Vec<u8>)]) -> Result<(), OutputError> {
    if !dir.join(MARKER).is_file() {
        return Err(err(dir, "is not a pilgrim output directory"));
    }
    check_replaceable(dir)?;
    let marker = std::fs::read_to_string(dir.join(MARKER)).map_err(|e| err(dir, e.to_string()))?;
    let mut names: Vec<String> = marked_files(&marker)
        .iter()
        .map(|s| (*s).to_owned())
        .collect();
    for (name, bytes) in files {
        if !plain(name) {
            return Err(err(dir, format!("'{name}' is not a plain file name")));
        }
        let path = dir.join(name);
        let tmp = dir.join(format!(".{name}.tmp-{}", std::process::id()));
        std::fs::write(&tmp, bytes).map_err(|e| err(&tmp, e.to_string()))?;
        std::fs::rename(&tmp, &path).map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            err(&path, e.to_string())
        })?;
        if !names.contains(name) {
            names.push(name.clone());
        }
    }
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    let tmp = dir.join(format!("{MARKER}.tmp-{}", std::process::id()));
    let failed = !holds_good_output(dir);
    std::fs::write(&tmp, marker_text(&refs, failed)).map_err(|e| err(&tmp, e.to_string()))?;
    std::fs::rename(&tmp, dir.join(MARKER)).map_err(|e| err(dir, e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_plain_names_are_written() {
        for bad in ["../x", "/etc/passwd", "a/b", ".hidden", "..", ""] {
            assert!(!plain(bad), "{bad}");
        }
        for good in ["part.stl", "scene.glb", "report-2.csv"] {
            assert!(plain(good), "{good}");
        }
    }
}
