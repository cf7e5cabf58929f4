//! What a run keeps of its inputs, so that `verify DIR` and `compensate`
//! work from what the run was made with, not from whatever lies at the
//! paths it was given then: the family's script and the tables it read
//! (beside the run's files, under their own names: the run's directory
//! is a family folder the script reads its tables from again), a machine
//! file or machine script, and a plugin library's SHA-256 (a library is
//! code, never copied). `report.json` lists each with its digest; a kept
//! file that no longer matches it, or a script or machine named on the
//! command line that is not the one kept, is refused naming it. A folder
//! copied or moved works as it stood.

use super::Error;
use crate::catalog::Origin;
use crate::output::{RunDir, RunError};
pub use crate::report::KeptInput;
use crate::report::Report;
use crate::script::ReadLog;
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// What a run keeps: the script, the log of the tables it reads, and
/// where its machine came from ([`super::JobOptions::keep`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Keep {
    /// The family's script.
    pub script: PathBuf,
    /// The tables it read (the log given to its [`crate::script::Access`]).
    pub tables: ReadLog,
}

/// The SHA-256 of `bytes`, in hexadecimal.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The file name of `path`, as the run keeps it.
fn name_of(path: &Path) -> Result<String, Error> {
    path.file_name()
        .and_then(|n| n.to_str())
        .filter(|n| crate::output::is_plain_file_name(n))
        .map(str::to_owned)
        .ok_or_else(|| {
            RunError::UnkeepableName {
                path: crate::files::excerpt(&path.display().to_string()),
            }
            .into()
        })
}

/// The kept inputs of a run and their bytes (none for a plugin): the
/// script, every table it read, the machine file or script where
/// `origin` is one, a plugin library's digest. `taken` are the run's
/// other files' names.
///
/// # Failures
/// An input that cannot be read (within [`crate::files::MAX_DATA_BYTES`],
/// a library within 1 GiB); two inputs of one name, or one named as a
/// file the run writes.
pub fn inputs(
    keep: &Keep,
    origin: &Origin,
    taken: &[String],
) -> Result<Vec<(KeptInput, Vec<u8>)>, Error> {
    let read = |p: &Path, limit: u64| crate::files::read_bytes(p, limit).map_err(Error::from);
    let mut out: Vec<(KeptInput, Vec<u8>)> = Vec::new();
    let mut add = |role: &str, path: &Path, bytes: Vec<u8>, file: bool| -> Result<(), Error> {
        let name = name_of(path)?;
        if file
            && (taken.contains(&name)
                || out
                    .iter()
                    .any(|(k, _)| k.file == name && k.role != "plugin"))
        {
            return Err(RunError::NameTaken {
                path: crate::files::excerpt(&path.display().to_string()),
                name,
            }
            .into());
        }
        let kept = KeptInput {
            role: role.into(),
            file: name,
            sha256: sha256_hex(&bytes),
        };
        out.push((kept, if file { bytes } else { Vec::new() }));
        Ok(())
    };
    let limit = crate::files::MAX_DATA_BYTES;
    add("family", &keep.script, read(&keep.script, limit)?, true)?;
    for t in keep.tables.paths() {
        add("table", &t, read(&t, limit)?, true)?;
    }
    match origin {
        Origin::File(p) | Origin::Script(p) => add("machine", p, read(p, limit)?, true)?,
        Origin::Plugin(p) => add("plugin", p, read(p, 1 << 30)?, false)?,
        Origin::Builtin | Origin::BuiltinPlugin => {}
    }
    Ok(out)
}

/// The script and the machine of the run `run` (shown as `shown`) from
/// what it kept, each kept file checked against its digest in `report`;
/// `family` and `machine`, where the command line names them, must be the
/// ones kept. `None` for a run that kept nothing (made before runs kept
/// their inputs): the caller takes the paths its report names.
///
/// # Failures
/// A kept file changed or missing, naming it; a script or machine given
/// that differs from the one kept, naming both; a plugin run with no
/// library given.
pub fn kept(
    run: &RunDir,
    report: &Report,
    family: Option<&Path>,
    machine: Option<&str>,
    shown: &str,
) -> Result<Option<(PathBuf, Option<String>)>, Error> {
    if report.inputs.is_empty() {
        return Ok(None);
    }
    let mut script = None;
    let mut spec = None;
    let mut machine_kept = false;
    for k in &report.inputs {
        if k.role == "plugin" {
            machine_kept = true;
            spec = Some(kept_plugin(k, machine, shown)?);
            continue;
        }
        let bytes = kept_file(run, k, shown)?;
        let path = run.path().join(&k.file);
        let same_as = |given: &Path, what: &str| same_as(&bytes, given, what, k, shown);
        match k.role.as_str() {
            "family" => {
                if let Some(given) = family {
                    same_as(given, "family's script")?;
                }
                script = Some(path);
            }
            "machine" => {
                machine_kept = true;
                if let Some(given) = machine {
                    same_as(Path::new(given), "machine")?;
                }
                spec = Some(path.display().to_string());
            }
            _ => {}
        }
    }
    // A built-in machine: the one the report names, or one given that is it.
    if !machine_kept {
        if let Some(given) = machine {
            if !given.eq_ignore_ascii_case(&report.machine_spec) {
                return Err(RunError::OtherMachine {
                    given: crate::files::excerpt(given),
                    machine: crate::files::excerpt(&report.machine_spec),
                }
                .into());
            }
        }
    }
    let script = script.ok_or_else(|| RunError::NoFamily {
        run: shown.to_owned(),
    })?;
    Ok(Some((script, spec)))
}

/// The plugin library the run was made with: the one the command line
/// names (`machine`), checked by its digest.
///
/// # Failures
/// None named, or another library.
fn kept_plugin(k: &KeptInput, machine: Option<&str>, shown: &str) -> Result<String, Error> {
    let Some(given) = machine else {
        return Err(RunError::PluginNotNamed {
            run: shown.to_owned(),
            file: crate::files::excerpt(&k.file),
            sha256: k.sha256.clone(),
        }
        .into());
    };
    let bytes = crate::files::read_bytes(Path::new(given), 1 << 30).map_err(Error::from)?;
    if sha256_hex(&bytes) != k.sha256 {
        return Err(RunError::OtherPlugin {
            given: crate::files::excerpt(given),
            file: crate::files::excerpt(&k.file),
            sha256: k.sha256.clone(),
        }
        .into());
    }
    Ok(given.to_owned())
}

/// The bytes of the file the run kept as `k`, checked by its digest.
///
/// # Failures
/// The file unreadable or changed since the run.
fn kept_file(run: &RunDir, k: &KeptInput, shown: &str) -> Result<Vec<u8>, Error> {
    let bytes = run
        .read(&k.file, crate::files::MAX_DATA_BYTES)
        .map_err(Error::from)?;
    if sha256_hex(&bytes) != k.sha256 {
        return Err(RunError::KeptChanged {
            file: format!("{shown}/{}", crate::files::excerpt(&k.file)),
        }
        .into());
    }
    Ok(bytes)
}

/// Checks the file `given` (the `what` the command line names) is the one
/// the run kept as `k` (its `bytes`).
///
/// # Failures
/// It is unreadable or differs, naming both.
fn same_as(
    bytes: &[u8],
    given: &Path,
    what: &str,
    k: &KeptInput,
    shown: &str,
) -> Result<(), Error> {
    let theirs =
        crate::files::read_bytes(given, crate::files::MAX_DATA_BYTES).map_err(Error::from)?;
    if theirs != bytes {
        return Err(RunError::NotTheKept {
            given: crate::files::excerpt(&given.display().to_string()),
            what: what.to_owned(),
            kept: format!("{shown}/{}", crate::files::excerpt(&k.file)),
        }
        .into());
    }
    Ok(())
}
