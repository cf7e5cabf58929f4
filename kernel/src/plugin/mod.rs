//! The plugin host: machine plugins (docs/architecture.md, the extension points, the ABI in the
//! `pilgrim-plugin-abi` crate), loaded from shared libraries or compiled
//! in. How to write one: `docs/plugins.md`.
//!
//! A library's code never runs in the host. [`PluginMachine::load`] first
//! reads the file (`elf`): a complete shared object for this machine,
//! its dynamic section pointing inside it, and its entry, the one function
//! it exports named `pilgrim_plugin_*` (whatever the file is called). A
//! bare file name is a path in the working directory, never a search of
//! the system's library path. The library is then opened in a child
//! process (`remote`: `pilgrim plugin-server`), which runs its
//! initialisers, calls its entry and answers every later call; a crash, an
//! abort, an exit or a hang there is an error naming the library and what
//! it did, within a time bound ([`Bounds`]), and the host goes on.
//! [`PluginMachine::from_entry`] takes the entry of a plugin compiled into
//! the program, called in this process. Both then go the same way: the ABI
//! version is checked (another major is refused, naming both), only the
//! table's fields lying wholly below its declared `size` are read, the
//! entries its capabilities promise must be there, and the machine's
//! descriptor is read and checked ([`crate::machine::check_description`]).
//! It is wrapped as a [`MachineKinematics`], and as a [`PostProcessor`]
//! when it posts its own programs ([`PluginMachine::post_processor`]). A
//! plugin's panic comes back as an error; its messages are quoted short.
//! [`exercise`] tries its kinematics over the travel (`pilgrim
//! plugin-check`).

mod elf;
pub mod exercise;
mod remote;
pub mod server;
mod table;
mod wire;

pub use elf::ENTRY_PREFIX;
pub use remote::{configure, Bounds, CHUNK_ROWS};

use crate::machine::{batch_rows, KinematicsError, MachineInfo, MachineKinematics};
use crate::program::{AxisProgram, PostError, PostProcessor};
use crate::transform::ToolFrame;
use pilgrim_plugin_abi::{
    EntryFn, PostRequest, ABI_MAJOR, ABI_MINOR, CAP_FORWARD, CAP_INVERSE, CAP_POST,
};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use wire::TableHeader;

/// A failed call of a plugin: the row of a batch it failed at, and the
/// message (the plugin's own text quoted at most
/// [`crate::files::MAX_EXCERPT`] characters long, control characters
/// escaped, where it enters the host).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct CallError {
    row: Option<usize>,
    message: String,
}

impl CallError {
    fn whole(message: impl Into<String>) -> Self {
        Self {
            row: None,
            message: message.into(),
        }
    }
}

/// A plugin's entries, called in this process ([`table::Table`]) or in a
/// child process ([`remote::Remote`]). Batches are already checked for
/// length: `out` holds a row of output per row of input.
pub(crate) trait Calls:
    Send + Sync + std::fmt::Debug + std::panic::RefUnwindSafe + std::panic::UnwindSafe
{
    /// The descriptor's JSON.
    fn describe(&self) -> Result<String, CallError>;
    /// Inverse kinematics: rows of 6 to rows of `width`.
    fn inverse(
        &self,
        poses: &[f64],
        tool: &[f64; 6],
        width: usize,
        out: &mut [f64],
    ) -> Result<(), CallError>;
    /// Forward kinematics: rows of `width` to rows of 6.
    fn forward(
        &self,
        axes: &[f64],
        tool: &[f64; 6],
        width: usize,
        out: &mut [f64],
    ) -> Result<(), CallError>;
    /// The program's text for a JSON post request.
    fn post(&self, request: &[u8]) -> Result<String, CallError>;
}

/// Why a plugin could not be loaded or called.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PluginLoadError {
    /// The file is not a complete shared object for this machine.
    #[error("{path}: {message}")]
    NotLibrary {
        /// The file.
        path: String,
        /// What it is instead.
        message: String,
    },
    /// The library could not be opened.
    #[error("{path}: cannot load the library: {message}")]
    Open {
        /// The library.
        path: String,
        /// The system's message.
        message: String,
    },
    /// The library has no entry, or several and none named for its file.
    #[error("{path}: no entry: {message}")]
    NoEntry {
        /// The library.
        path: String,
        /// What it exports instead.
        message: String,
    },
    /// The plugin's kinematics disagree with themselves or with its
    /// declared chain ([`exercise`]).
    #[error("{path}: the plugin's kinematics are not consistent; pilgrim refuses to program with them (`pilgrim plugin-check` reports the same):\n{report}")]
    Kinematics {
        /// The library.
        path: String,
        /// The exercise's report.
        report: String,
    },
    /// The library's process crashed, ended, hung or could not start.
    #[error("{path}: the plugin {message}")]
    Process {
        /// The library.
        path: String,
        /// What happened, and when.
        message: String,
    },
    /// The entry returned a null table.
    #[error("{path}: the entry '{symbol}' returned no table")]
    NullTable {
        /// The library.
        path: String,
        /// The entry symbol.
        symbol: String,
    },
    /// Another ABI major version.
    #[error(
        "{path}: the plugin speaks ABI {plugin_major}.{plugin_minor}, this pilgrim ABI {host_major}.{host_minor}: \
         major versions differ, rebuild the plugin against pilgrim-plugin-abi {host_major}"
    )]
    Version {
        /// The library.
        path: String,
        /// The plugin's major.
        plugin_major: u32,
        /// The plugin's minor.
        plugin_minor: u32,
        /// The host's major.
        host_major: u32,
        /// The host's minor.
        host_minor: u32,
    },
    /// An entry the host needs is missing (null, or beyond the table's size).
    #[error("{path}: the plugin's table has no '{entry}' entry (table of {size} bytes)")]
    MissingEntry {
        /// The library.
        path: String,
        /// The entry's name.
        entry: &'static str,
        /// The table's declared size.
        size: u32,
    },
    /// The descriptor is not valid JSON of a machine, or not a valid machine.
    #[error("{path}: bad machine descriptor: {message}")]
    Descriptor {
        /// The library.
        path: String,
        /// What is wrong.
        message: String,
    },
}

/// A machine plugin, loaded from a shared library (in a child process) or
/// compiled in.
#[derive(Debug, Clone)]
pub struct PluginMachine {
    origin: String,
    calls: Arc<dyn Calls>,
    info: MachineInfo,
    abi: (u32, u32),
    capabilities: u32,
}

impl PluginMachine {
    /// Loads and checks a plugin library, in a child process. See the
    /// [module docs](self).
    ///
    /// # Failures
    /// [`PluginLoadError`]: not a complete library; no entry; the library
    /// cannot be opened; its process crashing, ending or hanging while it
    /// loads; a null table; another ABI major; a missing entry; a bad
    /// descriptor.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, PluginLoadError> {
        let given = path.as_ref();
        let shown = crate::files::shown_path(given);
        // A bare name would make dlopen search the system's library path.
        let path = if given.components().count() == 1 && !given.is_absolute() {
            Path::new(".").join(given)
        } else {
            given.to_owned()
        };
        let symbol = elf::inspect(&path).map_err(|r| match r {
            elf::Refusal::NotLibrary(message) => PluginLoadError::NotLibrary {
                path: shown.clone(),
                message,
            },
            elf::Refusal::NoEntry(message) => PluginLoadError::NoEntry {
                path: shown.clone(),
                message,
            },
        })?;
        let (remote, header) =
            remote::Remote::start(&path, &symbol, &shown).map_err(|e| match e {
                remote::StartError::Open(message) => PluginLoadError::Open {
                    path: shown.clone(),
                    message: crate::files::excerpt(&message),
                },
                remote::StartError::NoEntry => PluginLoadError::NoEntry {
                    path: shown.clone(),
                    message: format!("the loader finds no symbol {symbol}"),
                },
                remote::StartError::NullTable => PluginLoadError::NullTable {
                    path: shown.clone(),
                    symbol: symbol.clone(),
                },
                remote::StartError::Process(message) => PluginLoadError::Process {
                    path: shown.clone(),
                    message,
                },
            })?;
        Self::checked(&shown, header, Arc::new(remote))
    }

    /// [`Self::load`], then its kinematics tried over the travel
    /// ([`exercise`]): what a run does before it trusts a library.
    ///
    /// # Failures
    /// As [`Self::load`]; [`PluginLoadError::Kinematics`].
    pub fn load_checked(
        path: impl AsRef<Path>,
    ) -> Result<(Self, exercise::Exercise), PluginLoadError> {
        let plugin = Self::load(&path)?;
        let tried = exercise::exercise(&plugin);
        if !tried.passed() {
            return Err(PluginLoadError::Kinematics {
                path: plugin.origin.clone(),
                report: tried.to_string(),
            });
        }
        Ok((plugin, tried))
    }

    /// A plugin compiled into the program, from its entry function;
    /// `origin` names it in messages. Called in this process, and checked
    /// as a loaded library is.
    ///
    /// # Failures
    /// As [`Self::load`], but for opening the library.
    pub fn from_entry(origin: &str, symbol: &str, entry: EntryFn) -> Result<Self, PluginLoadError> {
        // SAFETY: calling the entry of a plugin compiled into this program,
        // which returns its static table.
        let read = unsafe { table::Table::read(entry()) };
        let Some((table, header)) = read else {
            return Err(PluginLoadError::NullTable {
                path: origin.to_owned(),
                symbol: symbol.to_owned(),
            });
        };
        Self::checked(origin, header, Arc::new(table))
    }

    /// The table's header checked, the descriptor read and checked.
    fn checked(
        shown: &str,
        header: TableHeader,
        calls: Arc<dyn Calls>,
    ) -> Result<Self, PluginLoadError> {
        let shown = shown.to_owned();
        if header.major != ABI_MAJOR {
            return Err(PluginLoadError::Version {
                path: shown,
                plugin_major: header.major,
                plugin_minor: header.minor,
                host_major: ABI_MAJOR,
                host_minor: ABI_MINOR,
            });
        }
        let caps = header.capabilities;
        let [describe, inverse, forward, post, last_error, free_buffer] = header.present;
        for (present, needed, entry) in [
            (describe, true, "describe"),
            (inverse, caps & CAP_INVERSE != 0, "inverse"),
            (forward, caps & CAP_FORWARD != 0, "forward"),
            (post, caps & CAP_POST != 0, "post"),
            (last_error, true, "last_error"),
            (free_buffer, true, "free_buffer"),
        ] {
            if needed && !present {
                return Err(PluginLoadError::MissingEntry {
                    path: shown,
                    entry,
                    size: header.size,
                });
            }
        }
        let bad = |message: String| PluginLoadError::Descriptor {
            path: shown.clone(),
            message,
        };
        let descriptor = calls.describe().map_err(|e| bad(e.message))?;
        let info: MachineInfo = serde_json::from_str(&descriptor)
            .map_err(|e| bad(crate::files::excerpt(&e.to_string())))?;
        for s in &info.solved_axes {
            if info.axis(s).is_none() {
                return Err(bad(format!(
                    "solved axis {} is not among the axes",
                    crate::names::quoted(s)
                )));
            }
        }
        crate::machine::check_description(&info).map_err(|e| bad(e.to_string()))?;
        Ok(Self {
            origin: shown,
            calls,
            info,
            abi: (header.major, header.minor),
            capabilities: caps,
        })
    }

    /// Where the plugin came from: the library's path, or the name a
    /// compiled-in plugin was given.
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// The library's path (its origin).
    pub fn path(&self) -> PathBuf {
        PathBuf::from(&self.origin)
    }

    /// The plugin's ABI version (major, minor).
    pub fn abi_version(&self) -> (u32, u32) {
        self.abi
    }

    /// The plugin's capabilities (`CAP_*` bits).
    pub fn capabilities(&self) -> u32 {
        self.capabilities
    }

    /// The plugin's own post-processor, if it posts its programs.
    pub fn post_processor(&self) -> Option<PluginPost> {
        (self.capabilities & CAP_POST != 0).then(|| PluginPost {
            calls: self.calls.clone(),
        })
    }

    /// A failed call as a kinematics error.
    fn message(e: CallError) -> KinematicsError {
        KinematicsError {
            index: e.row,
            message: e.message,
        }
    }
}

fn tool6(tool: &ToolFrame) -> [f64; 6] {
    [
        tool.point.x,
        tool.point.y,
        tool.point.z,
        tool.axis.x,
        tool.axis.y,
        tool.axis.z,
    ]
}

impl MachineKinematics for PluginMachine {
    fn info(&self) -> &MachineInfo {
        &self.info
    }

    /// The plugin with its description's constants set: the host derives
    /// the bodies' chains from the description, so they follow; a constant
    /// the plugin's own tool chain uses is refused (its kinematics are its
    /// own, and the ABI has no call to change them).
    fn with_constants(
        &self,
        overrides: &[(String, f64)],
    ) -> Result<Box<dyn MachineKinematics>, crate::machine::MachineError> {
        for (name, _) in overrides {
            if self
                .info
                .chain
                .iter()
                .any(|f| f.constant.as_deref() == Some(name))
            {
                return Err(crate::machine::MachineError::Description {
                    machine: self.info.name.clone(),
                    message: format!(
                        "the constant '{name}' is part of the plugin's own kinematics and cannot be changed"
                    ),
                });
            }
        }
        let info = crate::machine::kinematics_overridden(&self.info, overrides)?;
        crate::machine::check_description(&info)?;
        Ok(Box::new(Self {
            info,
            ..self.clone()
        }))
    }

    fn inverse(
        &self,
        poses: &[f64],
        tool: &ToolFrame,
        out: &mut Vec<f64>,
    ) -> Result<(), KinematicsError> {
        let count = batch_rows(poses, 6, "pose")?;
        if self.capabilities & CAP_INVERSE == 0 {
            return Err(KinematicsError::whole(
                "the plugin offers no inverse kinematics",
            ));
        }
        let width = self.info.solved_axes.len();
        out.clear();
        out.resize(count * width, 0.0);
        let result = self.calls.inverse(poses, &tool6(tool), width, out);
        result.map_err(|e| {
            out.clear();
            Self::message(e)
        })
    }

    fn forward(
        &self,
        axes: &[f64],
        tool: &ToolFrame,
        out: &mut Vec<f64>,
    ) -> Result<(), KinematicsError> {
        let width = self.info.solved_axes.len();
        let count = batch_rows(axes, width, "axis")?;
        if self.capabilities & CAP_FORWARD == 0 {
            return Err(KinematicsError::whole(
                "the plugin offers no forward kinematics",
            ));
        }
        out.clear();
        out.resize(count * 6, 0.0);
        let result = self.calls.forward(axes, &tool6(tool), width, out);
        result.map_err(|e| {
            out.clear();
            KinematicsError::whole(Self::message(e).message)
        })
    }
}

/// A plugin's own post-processor ([`PluginMachine::post_processor`]).
#[derive(Debug, Clone)]
pub struct PluginPost {
    calls: Arc<dyn Calls>,
}

impl PostProcessor for PluginPost {
    fn post(&self, program: &AxisProgram, dialect: &str) -> Result<String, PostError> {
        let request = serde_json::to_string(&PostRequest {
            dialect: dialect.to_owned(),
            program: program.clone(),
        })
        .map_err(|e| PostError::Plugin(e.to_string()))?;
        self.calls
            .post(request.as_bytes())
            .map_err(|e| PostError::Plugin(e.message))
    }
}
