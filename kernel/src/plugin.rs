//! The plugin host: machine plugins loaded from shared libraries
//! (ARCHITECTURE §4, the ABI in the `pilgrim-plugin-abi` crate).
//!
//! [`PluginMachine::load`] opens a library, finds its entry
//! `pilgrim_plugin_<name>` (`<name>`: the file name without `lib` and the
//! extension, `-` read as `_`), checks the ABI version (another major is
//! refused, naming both), the table's size and entries, and the machine's
//! descriptor, and wraps it as a [`MachineKinematics`]. Every failure is an
//! error naming the library; a plugin's panic comes back as an error and the
//! host goes on. A loaded library stays loaded for the life of the process,
//! so nothing from it can outlive it.
//!
//! # Safety
//! Loading a library runs its initialisation code and trusts its entry
//! table to follow the ABI: load only plugins you would run as programs.

use crate::program::{AxisProgram, KinematicsError, MachineInfo, MachineKinematics, PostError};
use crate::transform::ToolFrame;
use pilgrim_plugin_abi::{
    Buffer, EntryFn, PluginTable, ABI_MAJOR, ABI_MINOR, NO_ROW, STATUS_OK, STATUS_PANIC, TABLE_SIZE,
};
use std::path::{Path, PathBuf};

/// Why a plugin could not be loaded or called.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PluginLoadError {
    /// The library could not be opened.
    #[error("{path}: cannot load the library: {message}")]
    Open {
        /// The library.
        path: String,
        /// The system's message.
        message: String,
    },
    /// The library has no entry symbol.
    #[error("{path}: no entry symbol '{symbol}' (a pilgrim machine plugin exports pilgrim_plugin_<library name>)")]
    NoEntry {
        /// The library.
        path: String,
        /// The symbol looked for.
        symbol: String,
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
    /// The descriptor is not valid JSON of a machine.
    #[error("{path}: bad machine descriptor: {message}")]
    Descriptor {
        /// The library.
        path: String,
        /// What is wrong.
        message: String,
    },
}

/// A machine plugin loaded from a shared library.
#[derive(Debug)]
pub struct PluginMachine {
    path: PathBuf,
    table: PluginTable,
    info: MachineInfo,
    abi: (u32, u32),
}

/// The entry symbol for a library file: `pilgrim_plugin_<stem>`.
pub fn entry_symbol(path: &Path) -> String {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
    let stem = stem.strip_prefix("lib").unwrap_or(stem);
    format!("pilgrim_plugin_{}", stem.replace(['-', '.'], "_"))
}

macro_rules! entry {
    ($self:expr, $field:ident) => {
        $self.table.$field.expect("checked when loaded")
    };
}

impl PluginMachine {
    /// Loads and checks a plugin. See the [module docs](self).
    ///
    /// # Failures
    /// [`PluginLoadError`]: the library cannot be opened; no entry symbol; a
    /// null table; another ABI major; a missing entry; a bad descriptor.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, PluginLoadError> {
        let path = path.as_ref();
        let shown = path.display().to_string();
        let symbol = entry_symbol(path);
        // SAFETY: loading runs the library's initialisers; see the module docs.
        let lib = unsafe { libloading::Library::new(path) }.map_err(|e| PluginLoadError::Open {
            path: shown.clone(),
            message: e.to_string(),
        })?;
        // Never unloaded: nothing from the library may outlive it.
        let lib: &'static libloading::Library = Box::leak(Box::new(lib));
        // SAFETY: the symbol's type is the ABI's entry type.
        let entry: libloading::Symbol<'static, EntryFn> = unsafe { lib.get(symbol.as_bytes()) }
            .map_err(|_| PluginLoadError::NoEntry {
                path: shown.clone(),
                symbol: symbol.clone(),
            })?;
        // SAFETY: calling the plugin's entry, which takes no arguments.
        let ptr = unsafe { entry() };
        if ptr.is_null() {
            return Err(PluginLoadError::NullTable {
                path: shown,
                symbol,
            });
        }
        // The first three fields are fixed for every version.
        // SAFETY: any plugin's table starts with three u32s.
        let (major, minor, size) = unsafe {
            let head = ptr as *const u32;
            (
                head.read_unaligned(),
                head.add(1).read_unaligned(),
                head.add(2).read_unaligned(),
            )
        };
        if major != ABI_MAJOR {
            return Err(PluginLoadError::Version {
                path: shown,
                plugin_major: major,
                plugin_minor: minor,
                host_major: ABI_MAJOR,
                host_minor: ABI_MINOR,
            });
        }
        // Read the fields below `size`; fields a smaller table lacks stay None.
        // SAFETY: an all-zero PluginTable is valid (numbers and None entries);
        // the copy reads no more than the plugin declares.
        let table: PluginTable = unsafe {
            let mut t = std::mem::zeroed::<PluginTable>();
            let n = (size.min(TABLE_SIZE)) as usize;
            std::ptr::copy_nonoverlapping(
                ptr as *const u8,
                &mut t as *mut PluginTable as *mut u8,
                n,
            );
            t
        };
        let missing = |entry: &'static str| PluginLoadError::MissingEntry {
            path: shown.clone(),
            entry,
            size,
        };
        for (present, name) in [
            (table.describe.is_some(), "describe"),
            (table.inverse.is_some(), "inverse"),
            (table.forward.is_some(), "forward"),
            (table.post.is_some(), "post"),
            (table.last_error.is_some(), "last_error"),
            (table.free_buffer.is_some(), "free_buffer"),
        ] {
            if !present {
                return Err(missing(name));
            }
        }
        let mut plugin = Self {
            path: path.to_owned(),
            table,
            info: MachineInfo {
                name: String::new(),
                description: String::new(),
                control: String::new(),
                axes: vec![],
                solved_axes: vec![],
                constants: Default::default(),
                program_decimals: None,
            },
            abi: (major, minor),
        };
        let descriptor = plugin
            .call_text(|out| unsafe { entry!(plugin, describe)(out) })
            .map_err(|message| PluginLoadError::Descriptor {
                path: shown.clone(),
                message,
            })?;
        let info: MachineInfo =
            serde_json::from_str(&descriptor).map_err(|e| PluginLoadError::Descriptor {
                path: shown.clone(),
                message: e.to_string(),
            })?;
        for s in &info.solved_axes {
            if info.axis(s).is_none() {
                return Err(PluginLoadError::Descriptor {
                    path: shown,
                    message: format!("solved axis '{s}' is not among the axes"),
                });
            }
        }
        plugin.info = info;
        Ok(plugin)
    }

    /// The library's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The plugin's ABI version (major, minor).
    pub fn abi_version(&self) -> (u32, u32) {
        self.abi
    }

    /// The message of the plugin's last failure on this thread.
    fn last_error(&self, status: i32) -> String {
        let text = self
            .call_text(|out| unsafe { entry!(self, last_error)(out) })
            .unwrap_or_else(|_| "unknown error".into());
        if status == STATUS_PANIC && !text.contains("panick") {
            format!("the plugin panicked: {text}")
        } else {
            text
        }
    }

    /// Calls an entry that fills a buffer; copies its text and frees it.
    fn call_text(&self, f: impl FnOnce(*mut Buffer) -> i32) -> Result<String, String> {
        let mut buf = Buffer::empty();
        let status = f(&mut buf);
        let text = if buf.ptr.is_null() {
            String::new()
        } else {
            // SAFETY: the plugin filled buf with len readable bytes.
            let bytes = unsafe { std::slice::from_raw_parts(buf.ptr, buf.len) };
            let t = String::from_utf8_lossy(bytes).into_owned();
            // SAFETY: the buffer came from this plugin and is returned once.
            unsafe { entry!(self, free_buffer)(buf) };
            t
        };
        if status == STATUS_OK {
            Ok(text)
        } else {
            Err(self.last_error(status))
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

    fn inverse(
        &self,
        poses: &[f64],
        tool: &ToolFrame,
        out: &mut Vec<f64>,
    ) -> Result<(), KinematicsError> {
        let count = crate::program::batch_rows(poses, 6, "pose")?;
        let width = self.info.solved_axes.len();
        out.clear();
        out.resize(count * width, 0.0);
        let t = tool6(tool);
        let mut failed = NO_ROW;
        // SAFETY: arrays of the sizes the ABI states.
        let status = unsafe {
            entry!(self, inverse)(
                poses.as_ptr(),
                count,
                t.as_ptr(),
                out.as_mut_ptr(),
                width,
                &mut failed,
            )
        };
        if status != STATUS_OK {
            out.clear();
            return Err(KinematicsError {
                index: (failed != NO_ROW).then_some(failed),
                message: self.last_error(status),
            });
        }
        Ok(())
    }

    fn forward(
        &self,
        axes: &[f64],
        tool: &ToolFrame,
        out: &mut Vec<f64>,
    ) -> Result<(), KinematicsError> {
        let width = self.info.solved_axes.len();
        let count = crate::program::batch_rows(axes, width, "axis")?;
        out.clear();
        out.resize(count * 6, 0.0);
        let t = tool6(tool);
        // SAFETY: arrays of the sizes the ABI states.
        let status = unsafe {
            entry!(self, forward)(axes.as_ptr(), count, width, t.as_ptr(), out.as_mut_ptr())
        };
        if status != STATUS_OK {
            out.clear();
            return Err(KinematicsError::whole(self.last_error(status)));
        }
        Ok(())
    }

    fn post(&self, program: &AxisProgram, dialect: &str) -> Result<String, PostError> {
        #[derive(serde::Serialize)]
        struct Request<'a> {
            dialect: &'a str,
            program: &'a AxisProgram,
        }
        let request = serde_json::to_string(&Request { dialect, program })
            .map_err(|e| PostError::Plugin(e.to_string()))?;
        // SAFETY: the request's bytes are readable for its length.
        self.call_text(|out| unsafe { entry!(self, post)(request.as_ptr(), request.len(), out) })
            .map_err(PostError::Plugin)
    }
}
