//! Writing and reading a run's output directory: all of it or none of it,
//! only over a directory pilgrim wrote, never through a link, and never
//! removing a file pilgrim did not write.
//!
//! Every write goes through [`write_dir`] (a run, a failed run's
//! diagnostic, an export: [`update_dir`] carries the run's other files
//! over) or [`write_generated_file`] (`api-docs`). A directory is written
//! whole into a temporary directory beside the target, created exclusively
//! under a name no other process uses (`.NAME.tmp-PID.N`: `mkdir` fails on
//! anything already there, a planted link included, and the next `N` is
//! tried), its files created exclusively inside it. It is marked with
//! [`MARKER`], which lists its files, and swapped in: on Linux by an atomic
//! exchange of the two directories (`renameat2(RENAME_EXCHANGE)`), so the
//! target always holds the old output or the whole new one; elsewhere by
//! two renames. The target must be new, or a previous pilgrim output (it
//! holds the marker) holding only the files its marker lists: anything
//! else, whatever its name, is refused, naming what is in the way, and
//! nothing is touched.
//!
//! What is removed is only what a marker lists: the old output once the
//! new one is in place, and the temporary directories killed runs left
//! beside the target (of a process that is gone). Each is emptied of the
//! files its marker lists, then removed if that left it empty; a file
//! pilgrim did not write keeps the directory in place.
//!
//! A run's files are read back ([`RunDir`]) only by the plain names its
//! marker lists, never through a link, and only if they are regular files.

use std::io::Write;
use std::path::{Path, PathBuf};

/// The file that marks a directory as pilgrim's output.
pub const MARKER: &str = ".pilgrim-output";

/// An output that cannot be written or read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{path}: {message}")]
pub struct OutputError {
    /// The path.
    pub path: String,
    /// Why, and what to do.
    pub message: String,
}

/// A finished run whose files cannot be used as the run left them (to
/// verify, export or correct it): each names the run's file or the input
/// given beside it, and what to do. Outside text in it is quoted short
/// ([`crate::files::excerpt`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RunError {
    /// The run's directory or one of its files that cannot be read.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// An input named beside the run that cannot be read.
    #[error(transparent)]
    File(#[from] crate::files::FileError),
    /// A file of the run that is not as the run wrote it.
    #[error("{file}: {what} (not as the run wrote it)")]
    NotAsWritten {
        /// The file, with its run's directory.
        file: String,
        /// What is wrong with it.
        what: String,
    },
    /// A body whose file `report.json` names is not one of the run's.
    #[error("{run}: report.json names the file '{file}' for body '{body}', which is not a file of this run")]
    NotTheRunsFile {
        /// The run's directory.
        run: String,
        /// The file named.
        file: String,
        /// The body.
        body: String,
    },
    /// A run with no 3-D models to export.
    #[error("{run}: the run has no 3-D models (its family has no fn part(p))")]
    NoModels {
        /// The run's directory.
        run: String,
    },
    /// A control in the report that is not a dialect pilgrim reads.
    #[error("{file}: names the control '{control}', which is not a dialect pilgrim reads")]
    UnknownControl {
        /// The report, with its run's directory.
        file: String,
        /// The control named.
        control: String,
    },
    /// An input the run kept beside its files, changed since.
    #[error("{file}: changed since the run kept it (its SHA-256 is not the one report.json records): a run's inputs stay as they were; run again to change them")]
    KeptChanged {
        /// The kept file, with its run's directory.
        file: String,
    },
    /// A file the command line names that is not the one the run kept.
    #[error("{given}: not the {what} the run was made with (kept as {kept}): verify against the kept one (leave the option out), or run again")]
    NotTheKept {
        /// The file given.
        given: String,
        /// What it is (`family`, `machine file`).
        what: String,
        /// The kept file, with its run's directory.
        kept: String,
    },
    /// A run made with a plugin library, which the command line does not
    /// name.
    #[error("{run}: the run's machine is the plugin library {file} (sha256 {sha256}): name it with --machine (pilgrim loads a library only when the command line names it)")]
    PluginNotNamed {
        /// The run's directory.
        run: String,
        /// The library's file name, as kept.
        file: String,
        /// Its digest.
        sha256: String,
    },
    /// A plugin library named that is not the one the run was made with.
    #[error("{given}: not the plugin library the run was made with ({file}, sha256 {sha256}): verify with that library, or run again")]
    OtherPlugin {
        /// The library given.
        given: String,
        /// The run's library's file name.
        file: String,
        /// Its digest.
        sha256: String,
    },
    /// A run made on a machine that is not built in, which the command
    /// line does not name.
    #[error("{run}: the run's machine '{machine}' is not a built-in: name it with --machine (pilgrim loads a plugin or machine file only when the command line names it)")]
    MachineNotNamed {
        /// The run's directory.
        run: String,
        /// The machine the report names.
        machine: String,
    },
    /// A machine named that is not the built-in one the run was made on.
    #[error("{given}: not the machine the run was made on (the built-in {machine}): leave --machine out, or run again")]
    OtherMachine {
        /// The machine given.
        given: String,
        /// The run's.
        machine: String,
    },
    /// A report whose kept inputs name no family's script.
    #[error("{run}/report.json: its inputs name no family's script")]
    NoFamily {
        /// The run's directory.
        run: String,
    },
    /// An older run's family, no longer where its report names it.
    #[error("{run}: the run's family '{script}' is not there (its report names it from where the run was made)")]
    FamilyGone {
        /// The run's directory.
        run: String,
        /// The script its report names.
        script: String,
    },
    /// An input whose name the run cannot keep beside its files.
    #[error("{path}: an input whose name the run cannot keep beside its files")]
    UnkeepableName {
        /// The input.
        path: String,
    },
    /// An input whose name is another of the run's files'.
    #[error("{path}: the run keeps its inputs beside its files, and '{name}' is the name of another of them; rename it")]
    NameTaken {
        /// The input.
        path: String,
        /// Its file name.
        name: String,
    },
    /// A prediction the report records that its program, verified again,
    /// does not give.
    #[error("{file}: its table {table} {what}: the report or the program was changed since the run (run the job again, and measure the part its program makes)")]
    PredictionChanged {
        /// The report, with its run's directory.
        file: String,
        /// The table.
        table: String,
        /// What differs, where, both values.
        what: String,
    },
    /// A run's program that, verified again to predict its part, is
    /// refused.
    #[error("{file}: the run's program, verified again to predict its part, is refused: {why}")]
    PredictionRefused {
        /// The program, with its run's directory.
        file: String,
        /// The refusal, as the verification gives it.
        why: String,
    },
}

fn err(path: &Path, message: impl Into<String>) -> OutputError {
    OutputError {
        path: crate::files::shown_path(path),
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
        crate::version::VERSION,
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

/// The files a marker lists (plain names only: a line that is not one is
/// not pilgrim's and lists nothing).
fn marked_files(text: &str) -> Vec<&str> {
    text.lines()
        .skip(1)
        .filter(|l| is_plain_file_name(l))
        .collect()
}

/// Whether a marker's text says its run failed.
fn says_failed(text: &str) -> bool {
    text.lines().next().is_some_and(|l| l.contains(FAILED_RUN))
}

/// Whether `name` may be written in an output directory: a plain file name.
pub fn is_plain_file_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= 255
        && name != "."
        && name != ".."
        && !name.starts_with('.')
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'))
}

/// The bytes of the regular file `path`, at most `limit`, opened without
/// following a link (a link, a directory, a FIFO or a device is refused,
/// and nothing is waited on).
fn read_no_follow(path: &Path, limit: u64) -> Result<Vec<u8>, OutputError> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK);
    }
    #[cfg(not(unix))]
    if std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink()) {
        return Err(err(
            path,
            "is a link: pilgrim reads a run's files only as it wrote them",
        ));
    }
    let file = options.open(path).map_err(|e| {
        #[cfg(unix)]
        if e.raw_os_error() == Some(libc::ELOOP) {
            return err(
                path,
                "is a link: pilgrim reads a run's files only as it wrote them, never through a link",
            );
        }
        err(path, e.to_string())
    })?;
    crate::files::read_opened(path, file, limit).map_err(|e| OutputError {
        path: e.file,
        message: e.message,
    })
}

/// The marker of `dir`, read without following a link; `None` if there is
/// none (or it is not a regular file, or not text).
fn read_marker(dir: &Path) -> Option<String> {
    read_no_follow(&dir.join(MARKER), crate::files::MAX_TEXT_BYTES)
        .ok()
        .and_then(|b| String::from_utf8(b).ok())
}

/// Whether `path` is a directory itself (not a link to one).
fn is_real_dir(path: &Path) -> bool {
    std::fs::symlink_metadata(path).is_ok_and(|m| m.is_dir())
}

/// A directory held by one command for the whole of it: `.<name>.lock`
/// beside the directory, holding the process's id and the command, made
/// only where no such file is (`O_EXCL`) and removed when dropped. A
/// second command on the directory fails at once, naming the holder; a
/// lock whose process is gone (killed) is taken over.
#[derive(Debug)]
pub struct DirLock {
    path: PathBuf,
}

impl DirLock {
    /// Holds `dir` for `command` (`pilgrim run`, shown to a second one).
    ///
    /// # Failures
    /// The directory held by a live process (named with its command), or
    /// the lock file not writable.
    pub fn take(dir: &Path, command: &str) -> Result<Self, OutputError> {
        let (parent, base) = parent_and_base(dir)?;
        std::fs::create_dir_all(&parent).map_err(|e| err(&parent, e.to_string()))?;
        let path = parent.join(format!(".{base}.lock"));
        let text = format!("{}\n{}\n", std::process::id(), command);
        for _ in 0..2 {
            match create_file(&path, text.as_bytes()) {
                Ok(()) => return Ok(Self { path }),
                Err(_) if std::fs::symlink_metadata(&path).is_ok() => {}
                Err(e) => return Err(e),
            }
            let held = crate::files::read_text(&path, 4096).unwrap_or_default();
            let mut lines = held.lines();
            let pid = lines.next().and_then(|p| p.trim().parse::<u32>().ok());
            let by = lines.next().unwrap_or("another command");
            match pid {
                Some(pid) if !process_gone(pid) => {
                    return Err(err(
                        dir,
                        format!(
                            "is being written by `{}` (process {pid}): wait for it to end, or write elsewhere",
                            crate::files::excerpt(by)
                        ),
                    ))
                }
                // A killed command's lock (or one that says no process).
                _ => {
                    let _ = std::fs::remove_file(&path);
                }
            }
        }
        Err(err(
            &path,
            "could not be taken: another command took it first",
        ))
    }
}

impl Drop for DirLock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// Checks that `out`, where a command writes its directory, neither is
/// nor holds `input`, what the command reads (a run's directory, a
/// program file): writing there would replace what it was asked to check
/// or correct. Links and relative paths are resolved first.
///
/// # Failures
/// `out` equal to `input` or one of its parents, named with both.
pub fn apart(out: &Path, input: &Path) -> Result<(), OutputError> {
    let (o, i) = (resolved(out), resolved(input));
    if i.starts_with(&o) {
        return Err(err(
            out,
            format!(
                "{} {}: writing there would replace what this command reads; give --out another directory",
                if i == o { "is" } else { "holds" },
                input.display()
            ),
        ));
    }
    Ok(())
}

/// `path` absolute, links resolved as far as it exists.
fn resolved(path: &Path) -> PathBuf {
    if let Ok(p) = std::fs::canonicalize(path) {
        return p;
    }
    match (path.parent(), path.file_name()) {
        (Some(parent), Some(name)) if !parent.as_os_str().is_empty() => resolved(parent).join(name),
        _ => std::env::current_dir()
            .map(|d| d.join(path))
            .unwrap_or_else(|_| path.to_owned()),
    }
}

/// Checks that `out` may be replaced: it does not exist, or it is a
/// directory pilgrim wrote, holding only the marker and the files it lists.
///
/// # Failures
/// A path that is not a directory (a link to one included), a directory
/// without the marker, or one holding anything the marker does not list,
/// whatever its name: each named.
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
    let marker = read_marker(out);
    let mut entries: Vec<String> = std::fs::read_dir(out)
        .map_err(|e| err(out, e.to_string()))?
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n != MARKER)
        .collect();
    entries.sort_unstable();
    let shown = |names: &[&String]| {
        let mut s: Vec<String> = names
            .iter()
            .take(5)
            .map(|n| crate::names::quoted(n))
            .collect();
        if names.len() > 5 {
            s.push(format!("and {} more", names.len() - 5));
        }
        s.join(", ")
    };
    let Some(marker) = marker else {
        let all: Vec<&String> = entries.iter().collect();
        return Err(err(
            out,
            format!(
                "exists and was not written by pilgrim (it holds {}): pilgrim replaces only its own output directories; give --out a new directory name, or move this one away yourself",
                if all.is_empty() {
                    "nothing".to_owned()
                } else {
                    shown(&all)
                }
            ),
        ));
    };
    let listed = marked_files(&marker);
    let foreign: Vec<&String> = entries
        .iter()
        .filter(|n| !listed.contains(&n.as_str()))
        .collect();
    if !foreign.is_empty() {
        return Err(err(
            out,
            format!(
                "is a pilgrim output, but holds files pilgrim did not write ({}): move them away, or give --out another directory",
                shown(&foreign)
            ),
        ));
    }
    Ok(())
}

/// Removes from `dir` the files its marker lists, then the marker, then
/// `dir` itself if that left it empty (a file pilgrim did not write keeps
/// it). A directory without pilgrim's marker is removed only when empty (a
/// run killed before it wrote its marker).
fn remove_listed(dir: &Path) {
    if !is_real_dir(dir) {
        return;
    }
    let Some(marker) = read_marker(dir) else {
        let _ = std::fs::remove_dir(dir);
        return;
    };
    for name in marked_files(&marker) {
        let p = dir.join(name);
        // A listed name that is now a directory is not a file pilgrim wrote.
        if std::fs::symlink_metadata(&p).is_ok_and(|m| !m.is_dir()) {
            let _ = std::fs::remove_file(&p);
        }
    }
    let _ = std::fs::remove_file(dir.join(MARKER));
    let _ = std::fs::remove_dir(dir);
}

/// The process of a temporary directory's name `.BASE.tmp-PID.N` or
/// `.BASE.old-PID.N` (as [`write_marked`] names them).
fn temporary_pid(name: &str, base: &str) -> Option<u32> {
    [".tmp-", ".old-"].iter().find_map(|kind| {
        let rest = name.strip_prefix(&format!(".{base}{kind}"))?;
        let (pid, n) = rest.split_once('.')?;
        n.parse::<u32>().ok()?;
        pid.parse::<u32>().ok()
    })
}

/// Whether the process `pid` is gone (Linux: no `/proc/PID`; elsewhere
/// never known, so never).
fn process_gone(pid: u32) -> bool {
    cfg!(target_os = "linux") && !Path::new("/proc").join(pid.to_string()).exists()
}

/// Removes what killed runs to `base` left in `parent`: the files their
/// markers list, in the temporary directories of processes that are gone.
fn clean_stale(parent: &Path, base: &str) {
    let Ok(entries) = std::fs::read_dir(parent) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let Some(pid) = temporary_pid(&name, base) else {
            continue;
        };
        if pid != std::process::id() && process_gone(pid) {
            remove_listed(&e.path());
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
    read_marker(dir).is_some_and(|m| !says_failed(&m))
}

/// Where a failed run's diagnostic goes when it was asked to write into
/// `out`: `out` itself, unless `out` holds the output of a run that
/// succeeded, which stays as it is: then `<out>.failed` beside it. The two
/// are never confused: a failed run's marker, report and page say FAILED,
/// and it holds no program.
pub fn failed_dir(out: &Path) -> PathBuf {
    if holds_good_output(out) {
        failed_sibling(out)
    } else {
        out.to_owned()
    }
}

/// `<out>.failed`.
fn failed_sibling(out: &Path) -> PathBuf {
    let mut name = out.file_name().unwrap_or_default().to_os_string();
    name.push(".failed");
    out.with_file_name(name)
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
    let stale = failed_sibling(out);
    if read_marker(&stale).is_some_and(|m| says_failed(&m)) && check_replaceable(&stale).is_ok() {
        remove_listed(&stale);
    }
    Ok(())
}

/// Creates a directory of pilgrim's own beside `out`: `.BASE.KIND-PID.N`,
/// the first `N` free (`mkdir` never follows or reuses what is there).
fn create_own_dir(parent: &Path, base: &str, kind: &str) -> Result<PathBuf, OutputError> {
    create_own(parent, base, kind, |p| std::fs::create_dir(p))
}

/// Creates `.<base>.<kind>-<pid>.<n>` in `parent` by `create` (which fails
/// with `AlreadyExists` on a name taken), the first `n` free: this
/// process's own, which [`clean_stale`] recognises.
fn create_own(
    parent: &Path,
    base: &str,
    kind: &str,
    create: impl Fn(&Path) -> std::io::Result<()>,
) -> Result<PathBuf, OutputError> {
    let pid = std::process::id();
    for n in 0..1000 {
        let p = parent.join(format!(".{base}.{kind}-{pid}.{n}"));
        match create(&p) {
            Ok(()) => return Ok(p),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(err(&p, e.to_string())),
        }
    }
    Err(err(
        parent,
        format!("a thousand names .{base}.{kind}-{pid}.N are taken: remove them"),
    ))
}

/// The directory `path` lies in (`.` for a bare name) and its own name.
fn parent_and_base(path: &Path) -> Result<(PathBuf, &str), OutputError> {
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_owned(),
        _ => PathBuf::from("."),
    };
    let base = path
        .file_name()
        .and_then(|n| n.to_str())
        .ok_or_else(|| err(path, "not a plain name"))?;
    Ok((parent, base))
}

/// Writes `bytes` as the new file `path` (never over anything there).
fn create_file(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    let mut f = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(path)
        .map_err(|e| err(path, e.to_string()))?;
    f.write_all(bytes).map_err(|e| err(path, e.to_string()))
}

/// [`write_dir`]'s writing, the marker saying whether the run failed.
fn write_marked(out: &Path, files: &[(String, Vec<u8>)], failed: bool) -> Result<(), OutputError> {
    let (parent, base) = parent_and_base(out)?;
    if let Some((bad, _)) = files.iter().find(|(n, _)| !is_plain_file_name(n)) {
        return Err(err(
            out,
            format!("'{}' is not a plain file name", crate::names::quoted(bad)),
        ));
    }
    check_replaceable(out)?;
    std::fs::create_dir_all(&parent).map_err(|e| err(&parent, e.to_string()))?;
    clean_stale(&parent, base);
    let tmp = create_own_dir(&parent, base, "tmp")?;
    let result = (|| {
        let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
        // The marker first: a killed run's directory lists what it holds.
        create_file(&tmp.join(MARKER), marker_text(&names, failed).as_bytes())?;
        for (name, bytes) in files {
            create_file(&tmp.join(name), bytes)?;
        }
        if std::fs::symlink_metadata(out).is_ok() {
            if exchange(&tmp, out).map_err(|e| err(out, e.to_string()))? {
                // `tmp` now holds the old output.
                remove_listed(&tmp);
                return Ok(());
            }
            let old = create_own_dir(&parent, base, "old")?;
            std::fs::remove_dir(&old).map_err(|e| err(&old, e.to_string()))?;
            std::fs::rename(out, &old).map_err(|e| err(out, e.to_string()))?;
            std::fs::rename(&tmp, out).map_err(|e| {
                let _ = std::fs::rename(&old, out);
                err(out, e.to_string())
            })?;
            remove_listed(&old);
            return Ok(());
        }
        std::fs::rename(&tmp, out).map_err(|e| err(out, e.to_string()))
    })();
    if result.is_err() {
        remove_listed(&tmp);
    }
    result
}

/// A run's output directory, read back: the files its marker lists, each
/// read only as pilgrim wrote it.
#[derive(Debug, Clone)]
pub struct RunDir {
    dir: PathBuf,
    files: Vec<String>,
    failed: bool,
}

impl RunDir {
    /// Opens the pilgrim output `dir`.
    ///
    /// # Failures
    /// `dir` not a pilgrim output, or holding files pilgrim did not write
    /// ([`check_replaceable`]).
    pub fn open(dir: &Path) -> Result<Self, OutputError> {
        let marker = read_marker(dir)
            .filter(|_| is_real_dir(dir))
            .ok_or_else(|| err(dir, "is not a pilgrim output directory"))?;
        check_replaceable(dir)?;
        Ok(Self {
            dir: dir.to_owned(),
            files: marked_files(&marker)
                .into_iter()
                .map(str::to_owned)
                .collect(),
            failed: says_failed(&marker),
        })
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// The files the run wrote, as its marker lists them.
    pub fn files(&self) -> &[String] {
        &self.files
    }

    /// Whether the run failed (its marker says so).
    pub fn failed(&self) -> bool {
        self.failed
    }

    /// The bytes of the run's file `name`, at most `limit`.
    ///
    /// # Failures
    /// A name the marker does not list (the run did not write it), a link,
    /// anything but a regular file, a larger file, a read error.
    pub fn read(&self, name: &str, limit: u64) -> Result<Vec<u8>, OutputError> {
        if !self.files.iter().any(|f| f == name) {
            return Err(err(
                &self.dir.join(crate::names::quoted(name)),
                "is not a file this run wrote (its .pilgrim-output does not list it)",
            ));
        }
        read_no_follow(&self.dir.join(name), limit)
    }

    /// The text (UTF-8) of the run's file `name`, at most `limit` bytes.
    ///
    /// # Failures
    /// As [`Self::read`]; text that is not UTF-8.
    pub fn read_text(&self, name: &str, limit: u64) -> Result<String, OutputError> {
        String::from_utf8(self.read(name, limit)?).map_err(|e| {
            err(
                &self.dir.join(name),
                format!("not UTF-8 text: {}", e.utf8_error()),
            )
        })
    }
}

/// Writes `files` over some of those of the run `dir` (opened as
/// [`RunDir::open`]), the others carried over as they are: the whole
/// directory is written again as [`write_dir`] writes it, so an export
/// killed part way leaves the run as it was.
///
/// # Failures
/// As [`RunDir::open`] and [`write_dir`]; a file of the run that cannot be
/// read as pilgrim wrote it.
pub fn update_dir(dir: &RunDir, files: &[(String, Vec<u8>)]) -> Result<(), OutputError> {
    let mut all: Vec<(String, Vec<u8>)> = Vec::new();
    for name in dir.files() {
        if !files.iter().any(|(n, _)| n == name) {
            all.push((name.clone(), dir.read(name, crate::files::MAX_DATA_BYTES)?));
        }
    }
    all.extend(files.iter().cloned());
    write_marked(dir.path(), &all, dir.failed())
}

/// Writes `bytes` as the file `path`: a new file, or one that begins as
/// `bytes` does in its first `header_lines` lines (one pilgrim generated
/// before), replaced through a temporary file created exclusively beside
/// it and a rename. Anything else (a user's file, a link, a directory) is
/// refused and left as it is.
///
/// # Failures
/// What is at `path` is not pilgrim's; a write or rename failing.
pub fn write_generated_file(
    path: &Path,
    bytes: &[u8],
    header_lines: usize,
) -> Result<(), OutputError> {
    let header = |b: &[u8]| -> Vec<u8> {
        b.split_inclusive(|&c| c == b'\n')
            .take(header_lines)
            .flatten()
            .copied()
            .collect()
    };
    match std::fs::symlink_metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(err(path, e.to_string())),
        Ok(m) if m.file_type().is_symlink() => {
            return Err(err(
                path,
                "is a link: pilgrim writes a new file or replaces one it generated, never through a link",
            ))
        }
        Ok(_) => {
            let old = read_no_follow(path, crate::files::MAX_DATA_BYTES).map_err(|_| {
                err(path, "exists and is not a file pilgrim generated: give a new file name")
            })?;
            if header_lines == 0 || header(&old) != header(bytes) {
                return Err(err(
                    path,
                    "exists and is not a file pilgrim generated (its first lines differ): pilgrim replaces only its own; give a new file name, or move this one away yourself",
                ));
            }
        }
    }
    let (parent, base) = parent_and_base(path)?;
    let tmp = create_own(&parent, base, "tmp", |p| {
        std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(p)?
            .write_all(bytes)
    })?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        err(path, e.to_string())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_plain_names_are_written() {
        for bad in ["../x", "/etc/passwd", "a/b", ".hidden", "..", ""] {
            assert!(!is_plain_file_name(bad), "{bad}");
        }
        for good in ["part.stl", "scene.glb", "report-2.csv"] {
            assert!(is_plain_file_name(good), "{good}");
        }
    }

    #[test]
    fn temporaries_are_named_by_process_and_number() {
        assert_eq!(temporary_pid(".out.tmp-123.0", "out"), Some(123));
        assert_eq!(temporary_pid(".out.old-9.12", "out"), Some(9));
        for other in [
            ".out.tmp-123",
            ".out.tmp-x.1",
            ".other.tmp-1.1",
            "out.tmp-1.1",
        ] {
            assert_eq!(temporary_pid(other, "out"), None, "{other}");
        }
    }
}
