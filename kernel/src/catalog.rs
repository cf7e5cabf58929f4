//! Where machines come from: the built-ins (the data machines of the seeds,
//! [`crate::machine::BUILTIN_MACHINES`], and the plugins compiled into the
//! program), plugin libraries, machine files and machine scripts. A machine
//! opened for a job is its kinematics and its post-processor
//! ([`OpenMachine`]).

use crate::machine::{ChainMachine, Machine, MachineError, MachineKinematics, BUILTIN_MACHINES};
use crate::plugin::{PluginLoadError, PluginMachine};
use crate::program::{PostProcessor, SharedPost};
use pilgrim_plugin_abi::EntryFn;
use std::path::{Path, PathBuf};

/// Where an opened machine came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Origin {
    /// A plugin compiled into the program.
    BuiltinPlugin,
    /// A data machine built into the kernel.
    Builtin,
    /// A plugin library.
    Plugin(PathBuf),
    /// A machine file (TOML).
    File(PathBuf),
    /// A machine script (Rhai).
    Script(PathBuf),
}

impl std::fmt::Display for Origin {
    /// As `pilgrim machines` lists it: `built-in plugin`, `plugin PATH`,
    /// `from PATH`; empty for a data built-in.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::BuiltinPlugin => f.write_str("built-in plugin"),
            Self::Builtin => Ok(()),
            Self::Plugin(p) => write!(f, "plugin {}", p.display()),
            Self::File(p) | Self::Script(p) => write!(f, "from {}", p.display()),
        }
    }
}

/// A machine ready for a job: its kinematics and its post-processor.
pub struct OpenMachine {
    /// Inverse and forward kinematics, and the descriptor.
    pub kinematics: Box<dyn MachineKinematics>,
    /// What writes its programs.
    pub post: Box<dyn PostProcessor>,
    /// How it was named (to open it again).
    pub spec: String,
    /// Where it came from.
    pub origin: Origin,
}

impl std::fmt::Debug for OpenMachine {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OpenMachine")
            .field("name", &self.kinematics.info().name)
            .field("spec", &self.spec)
            .field("origin", &self.origin)
            .finish()
    }
}

impl OpenMachine {
    /// A data machine, posted by the shared writer.
    pub fn data(machine: Machine, spec: &str, origin: Origin) -> Self {
        Self {
            kinematics: Box::new(ChainMachine::new(machine)),
            post: Box::new(SharedPost),
            spec: spec.to_owned(),
            origin,
        }
    }

    /// A plugin, posted by its own post-processor if it has one, else by the
    /// shared writer.
    pub fn plugin(plugin: PluginMachine, spec: &str, origin: Origin) -> Self {
        let post: Box<dyn PostProcessor> = match plugin.post_processor() {
            Some(p) => Box::new(p),
            None => Box::new(SharedPost),
        };
        Self {
            kinematics: Box::new(plugin),
            post,
            spec: spec.to_owned(),
            origin,
        }
    }
}

/// Why a machine could not be opened.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CatalogError {
    /// A plugin that cannot be loaded.
    #[error(transparent)]
    Plugin(#[from] PluginLoadError),
    /// A machine file or script that is wrong.
    #[error(transparent)]
    Machine(#[from] MachineError),
    /// A name that is no built-in and no file.
    #[error("unknown machine '{spec}': give a built-in ({known}), a plugin library (.so), a machine file (.toml) or a machine script (.rhai)")]
    Unknown {
        /// The name given.
        spec: String,
        /// The built-ins' names.
        known: String,
    },
}

/// A plugin compiled into the program: its entry function and symbol.
#[derive(Debug, Clone, Copy)]
pub struct CompiledPlugin {
    /// The entry's symbol, `pilgrim_plugin_<name>` (for messages).
    pub symbol: &'static str,
    /// The entry.
    pub entry: EntryFn,
}

/// The machines a program knows by name: its compiled-in plugins (checked
/// through the ABI as a loaded library is) and the kernel's data
/// built-ins.
#[derive(Debug, Clone)]
pub struct Catalog {
    plugins: Vec<PluginMachine>,
}

impl Catalog {
    /// A catalog with the plugins compiled into the program.
    ///
    /// # Failures
    /// A compiled-in plugin that fails its checks (a build error of the
    /// program, named).
    pub fn new(compiled: &[CompiledPlugin]) -> Result<Self, CatalogError> {
        let plugins = compiled
            .iter()
            .map(|c| PluginMachine::from_entry(c.symbol, c.symbol, c.entry))
            .collect::<Result<_, _>>()?;
        Ok(Self { plugins })
    }

    /// The built-ins' names: the compiled-in plugins, then the data
    /// machines a plugin of the same name does not stand for (a name opens
    /// the plugin first).
    pub fn builtin_names(&self) -> Vec<String> {
        let mut names: Vec<String> = self.plugins.iter().map(|p| p.info().name.clone()).collect();
        for m in BUILTIN_MACHINES {
            if !names.iter().any(|n| n.eq_ignore_ascii_case(m)) {
                names.push(m.to_owned());
            }
        }
        names
    }

    /// Opens `spec`: `*.so`/`*.dylib`/`*.dll` (a plugin), `*.toml` (a
    /// machine file), `*.rhai` (a script whose `fn machine()` returns the
    /// machine file's table as a map), or a built-in's name
    /// (case-insensitive).
    ///
    /// # Failures
    /// [`CatalogError`]: the plugin, file or script's error; an unknown
    /// name, listing the built-ins.
    pub fn open(&self, spec: &str) -> Result<OpenMachine, CatalogError> {
        let m = self.open_unchecked(spec)?;
        // The power-on state against the control's modal groups: machine
        // data the machine module cannot judge, the dialects being the
        // programs'.
        let info = m.kinematics.info();
        crate::program::check_power_on(info).map_err(|message| MachineError::Description {
            machine: info.name.clone(),
            message: message.to_string(),
        })?;
        Ok(m)
    }

    fn open_unchecked(&self, spec: &str) -> Result<OpenMachine, CatalogError> {
        let path = Path::new(spec);
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        match ext.as_str() {
            "so" | "dylib" | "dll" => Ok(OpenMachine::plugin(
                PluginMachine::load_checked(path)?.0,
                spec,
                Origin::Plugin(path.to_owned()),
            )),
            "toml" => Ok(OpenMachine::data(
                Machine::from_file(path)?,
                spec,
                Origin::File(path.to_owned()),
            )),
            "rhai" => Ok(OpenMachine::data(
                crate::script::machine_from_script(path)?,
                spec,
                Origin::Script(path.to_owned()),
            )),
            _ => {
                if let Some(p) = self
                    .plugins
                    .iter()
                    .find(|p| p.info().name.eq_ignore_ascii_case(spec))
                {
                    return Ok(OpenMachine::plugin(p.clone(), spec, Origin::BuiltinPlugin));
                }
                match Machine::builtin(spec) {
                    Ok(m) => Ok(OpenMachine::data(m, spec, Origin::Builtin)),
                    Err(_) => Err(CatalogError::Unknown {
                        spec: spec.to_owned(),
                        known: self.builtin_names().join(", "),
                    }),
                }
            }
        }
    }
}
