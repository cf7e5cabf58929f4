//! The plugin host: machine plugins (ARCHITECTURE §4, the ABI in the
//! `pilgrim-plugin-abi` crate), loaded from shared libraries or compiled
//! in.
//!
//! [`PluginMachine::load`] first checks, with the `object` crate's ELF
//! reader, that the file is a complete shared object for this machine (its
//! program headers and loaded segments lie inside the file: a truncated
//! library would otherwise crash the process with SIGBUS when mapped), then
//! opens it (a bare file name is a path in the working directory, never a
//! search of the system's library path; a failure gives the system's
//! reason) and finds its entry
//! `pilgrim_plugin_<name>` (`<name>`: the file name without `lib` and the
//! extension, `-` read as `_`); [`PluginMachine::from_entry`] takes the
//! entry of a plugin compiled into the program. Both then go the same way:
//! the ABI version is checked (another major is refused, naming both), the
//! table is read field by field, only the fields lying wholly below its
//! declared `size`, the entries its capabilities promise must be there, and
//! the machine's descriptor is read and checked
//! ([`crate::machine::check_description`]). It is wrapped as a
//! [`MachineKinematics`], and as a [`PostProcessor`] when it posts its own
//! programs ([`PluginMachine::post_processor`]). Every failure is an error
//! naming the library; a plugin's panic comes back as an error and the host
//! goes on. A loaded library stays loaded for the life of the process, so
//! nothing from it can outlive it.
//!
//! # Safety
//! Loading a library runs its initialisation code and trusts its entry
//! table to follow the ABI: load only plugins you would run as programs.

use crate::machine::{batch_rows, KinematicsError, MachineInfo, MachineKinematics};
use crate::program::{AxisProgram, PostError, PostProcessor};
use crate::transform::ToolFrame;
use pilgrim_plugin_abi::{
    Buffer, EntryFn, PluginTable, PostRequest, ABI_MAJOR, ABI_MINOR, CAP_ABI_1_0, CAP_FORWARD,
    CAP_INVERSE, CAP_POST, NO_ROW, STATUS_OK, STATUS_PANIC,
};
use std::mem::{offset_of, size_of};
use std::path::{Path, PathBuf};
use std::sync::Arc;

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
    /// The descriptor is not valid JSON of a machine, or not a valid machine.
    #[error("{path}: bad machine descriptor: {message}")]
    Descriptor {
        /// The library.
        path: String,
        /// What is wrong.
        message: String,
    },
}

/// A plugin's entry table as read: the fields its size covers.
#[derive(Debug, Clone, Copy)]
struct Table {
    table: *const PluginTable,
    size: u32,
    capabilities: u32,
}

// SAFETY: the table is a static of the plugin, which is never unloaded, and
// its entries are `extern "C"` functions the ABI requires to be callable
// from any thread (each keeps its last error per thread).
unsafe impl Send for Table {}
// SAFETY: as above; the table is never written.
unsafe impl Sync for Table {}

/// Reads field `$field` of the table at `$ptr` if it lies wholly below
/// `$size`, else `None`.
macro_rules! field {
    ($ptr:expr, $size:expr, $field:ident) => {{
        let end = offset_of!(PluginTable, $field) + size_of_field(|t: &PluginTable| &t.$field);
        if ($size as usize) < end {
            None
        } else {
            // SAFETY: the field lies inside the table the plugin declared,
            // and reading it unaligned copies its bytes.
            Some(unsafe { std::ptr::addr_of!((*$ptr).$field).read_unaligned() })
        }
    }};
}

/// The size of a field, from an accessor (for [`field!`]).
fn size_of_field<T>(_: impl Fn(&PluginTable) -> &T) -> usize {
    size_of::<T>()
}

/// A machine plugin, loaded from a shared library or compiled in.
#[derive(Debug, Clone)]
pub struct PluginMachine {
    origin: String,
    table: Arc<Table>,
    info: MachineInfo,
    abi: (u32, u32),
}

/// Checks that `path` is a complete ELF shared object of this machine's
/// class, byte order and architecture: its program headers and every
/// loaded segment lie inside the file.
fn check_elf(path: &Path) -> Result<(), String> {
    use object::elf;
    use object::read::elf::{FileHeader, ProgramHeader};
    use object::Endianness;
    let data =
        crate::files::read_bytes(path, crate::files::MAX_DATA_BYTES).map_err(|e| e.message)?;
    let data = data.as_slice();
    if !data.starts_with(&elf::ELFMAG) {
        return Err(
            "not an ELF shared object (pilgrim loads machine plugins built as .so libraries)"
                .into(),
        );
    }
    let incomplete = |what: &str| {
        format!("not a complete shared object: {what} (the file is cut short or damaged)")
    };
    let header = elf::FileHeader64::<Endianness>::parse(data)
        .map_err(|_| incomplete("its ELF header cannot be read, or it is not a 64-bit library"))?;
    let endian = header
        .endian()
        .map_err(|_| incomplete("its byte order cannot be read"))?;
    if (endian == Endianness::Little) != cfg!(target_endian = "little") {
        return Err("a library for another byte order".into());
    }
    let machine = if cfg!(target_arch = "x86_64") {
        Some(elf::EM_X86_64)
    } else if cfg!(target_arch = "aarch64") {
        Some(elf::EM_AARCH64)
    } else {
        None
    };
    if machine.is_some_and(|m| header.e_machine(endian) != m) {
        return Err(format!(
            "a library for another machine (ELF machine {})",
            header.e_machine(endian)
        ));
    }
    if header.e_type(endian) != elf::ET_DYN {
        return Err(format!(
            "not a shared object (ELF type {})",
            header.e_type(endian)
        ));
    }
    let phdrs = header
        .program_headers(endian, data)
        .map_err(|_| incomplete("its program headers lie beyond its end"))?;
    for ph in phdrs {
        if ph.p_type(endian) == elf::PT_LOAD {
            let end = ph.p_offset(endian).checked_add(ph.p_filesz(endian));
            if end.is_none_or(|e| e > data.len() as u64) {
                return Err(incomplete("a loaded segment lies beyond its end"));
            }
        }
    }
    Ok(())
}

/// The entry symbol for a library file: `pilgrim_plugin_<stem>`.
pub fn entry_symbol(path: &Path) -> String {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
    let stem = stem.strip_prefix("lib").unwrap_or(stem);
    format!("pilgrim_plugin_{}", stem.replace(['-', '.'], "_"))
}

impl Table {
    /// Calls entry `$field`, which loading checked is present.
    fn describe(&self) -> Option<pilgrim_plugin_abi::DescribeFn> {
        field!(self.table, self.size, describe).flatten()
    }
    fn inverse(&self) -> Option<pilgrim_plugin_abi::InverseFn> {
        field!(self.table, self.size, inverse).flatten()
    }
    fn forward(&self) -> Option<pilgrim_plugin_abi::ForwardFn> {
        field!(self.table, self.size, forward).flatten()
    }
    fn post(&self) -> Option<pilgrim_plugin_abi::PostFn> {
        field!(self.table, self.size, post).flatten()
    }
    fn last_error(&self) -> Option<pilgrim_plugin_abi::LastErrorFn> {
        field!(self.table, self.size, last_error).flatten()
    }
    fn free_buffer(&self) -> Option<pilgrim_plugin_abi::FreeBufferFn> {
        field!(self.table, self.size, free_buffer).flatten()
    }

    /// The message of the plugin's last failure on this thread.
    fn last_error_text(&self, status: i32) -> String {
        let text = match self.last_error() {
            // SAFETY: the entry fills the buffer it is given.
            Some(f) => self.call_text(|out| unsafe { f(out) }).ok(),
            None => None,
        }
        .unwrap_or_else(|| "unknown error".into());
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
            if let Some(free) = self.free_buffer() {
                // SAFETY: the buffer came from this plugin and is returned once.
                unsafe { free(buf) };
            }
            t
        };
        if status == STATUS_OK {
            Ok(text)
        } else {
            Err(self.last_error_text(status))
        }
    }
}

impl PluginMachine {
    /// Loads and checks a plugin library. See the [module docs](self).
    ///
    /// # Failures
    /// [`PluginLoadError`]: the library cannot be opened; no entry symbol; a
    /// null table; another ABI major; a missing entry; a bad descriptor.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, PluginLoadError> {
        let given = path.as_ref();
        let shown = given.display().to_string();
        // A bare name would make dlopen search the system's library path.
        let path = if given.components().count() == 1 && !given.is_absolute() {
            Path::new(".").join(given)
        } else {
            given.to_owned()
        };
        let symbol = entry_symbol(&path);
        check_elf(&path).map_err(|message| PluginLoadError::NotLibrary {
            path: shown.clone(),
            message,
        })?;
        // SAFETY: loading runs the library's initialisers; see the module docs.
        let lib = unsafe { libloading::Library::new(&path) }.map_err(|e| {
            use std::error::Error as _;
            PluginLoadError::Open {
                path: shown.clone(),
                message: match e.source() {
                    Some(reason) => format!("{e}: {reason}"),
                    None => e.to_string(),
                },
            }
        })?;
        // Never unloaded: nothing from the library may outlive it.
        let lib: &'static libloading::Library = Box::leak(Box::new(lib));
        // SAFETY: the symbol's type is the ABI's entry type.
        let entry: libloading::Symbol<'static, EntryFn> = unsafe { lib.get(symbol.as_bytes()) }
            .map_err(|_| PluginLoadError::NoEntry {
                path: shown.clone(),
                symbol: symbol.clone(),
            })?;
        Self::from_entry(&shown, &symbol, *entry)
    }

    /// A plugin compiled into the program, from its entry function;
    /// `origin` names it in messages. Checked as a loaded library is.
    ///
    /// # Failures
    /// As [`Self::load`], but for opening the library.
    pub fn from_entry(origin: &str, symbol: &str, entry: EntryFn) -> Result<Self, PluginLoadError> {
        let shown = origin.to_owned();
        // SAFETY: calling the plugin's entry, which takes no arguments.
        let ptr = unsafe { entry() };
        if ptr.is_null() {
            return Err(PluginLoadError::NullTable {
                path: shown,
                symbol: symbol.to_owned(),
            });
        }
        // The first three fields are fixed for every version.
        // SAFETY: any plugin's table starts with three u32s.
        let (major, minor, size) = unsafe {
            (
                std::ptr::addr_of!((*ptr).abi_major).read_unaligned(),
                std::ptr::addr_of!((*ptr).abi_minor).read_unaligned(),
                std::ptr::addr_of!((*ptr).size).read_unaligned(),
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
        let capabilities = field!(ptr, size, capabilities).unwrap_or(CAP_ABI_1_0);
        let table = Table {
            table: ptr,
            size,
            capabilities,
        };
        let missing = |entry: &'static str| PluginLoadError::MissingEntry {
            path: shown.clone(),
            entry,
            size,
        };
        for (present, needed, name) in [
            (table.describe().is_some(), true, "describe"),
            (
                table.inverse().is_some(),
                capabilities & CAP_INVERSE != 0,
                "inverse",
            ),
            (
                table.forward().is_some(),
                capabilities & CAP_FORWARD != 0,
                "forward",
            ),
            (table.post().is_some(), capabilities & CAP_POST != 0, "post"),
            (table.last_error().is_some(), true, "last_error"),
            (table.free_buffer().is_some(), true, "free_buffer"),
        ] {
            if needed && !present {
                return Err(missing(name));
            }
        }
        let describe = table.describe().ok_or_else(|| missing("describe"))?;
        let bad = |message: String| PluginLoadError::Descriptor {
            path: shown.clone(),
            message,
        };
        // SAFETY: the entry fills the buffer it is given.
        let descriptor = table
            .call_text(|out| unsafe { describe(out) })
            .map_err(bad)?;
        let info: MachineInfo =
            serde_json::from_str(&descriptor).map_err(|e| bad(e.to_string()))?;
        for s in &info.solved_axes {
            if info.axis(s).is_none() {
                return Err(bad(format!("solved axis '{s}' is not among the axes")));
            }
        }
        crate::machine::check_description(&info).map_err(|e| bad(e.to_string()))?;
        Ok(Self {
            origin: shown,
            table: Arc::new(table),
            info,
            abi: (major, minor),
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
        self.table.capabilities
    }

    /// The plugin's own post-processor, if it posts its programs.
    pub fn post_processor(&self) -> Option<PluginPost> {
        (self.table.capabilities & CAP_POST != 0).then(|| PluginPost {
            table: self.table.clone(),
        })
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
        let inverse = self
            .table
            .inverse()
            .ok_or_else(|| KinematicsError::whole("the plugin offers no inverse kinematics"))?;
        let width = self.info.solved_axes.len();
        out.clear();
        out.resize(count * width, 0.0);
        let t = tool6(tool);
        let mut failed = NO_ROW;
        // SAFETY: arrays of the sizes the ABI states.
        let status = unsafe {
            inverse(
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
                message: self.table.last_error_text(status),
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
        let count = batch_rows(axes, width, "axis")?;
        let forward = self
            .table
            .forward()
            .ok_or_else(|| KinematicsError::whole("the plugin offers no forward kinematics"))?;
        out.clear();
        out.resize(count * 6, 0.0);
        let t = tool6(tool);
        // SAFETY: arrays of the sizes the ABI states.
        let status = unsafe { forward(axes.as_ptr(), count, width, t.as_ptr(), out.as_mut_ptr()) };
        if status != STATUS_OK {
            out.clear();
            return Err(KinematicsError::whole(self.table.last_error_text(status)));
        }
        Ok(())
    }
}

/// A plugin's own post-processor ([`PluginMachine::post_processor`]).
#[derive(Debug, Clone)]
pub struct PluginPost {
    table: Arc<Table>,
}

impl PostProcessor for PluginPost {
    fn post(&self, program: &AxisProgram, dialect: &str) -> Result<String, PostError> {
        let request = serde_json::to_string(&PostRequest {
            dialect: dialect.to_owned(),
            program: program.clone(),
        })
        .map_err(|e| PostError::Plugin(e.to_string()))?;
        let post = self
            .table
            .post()
            .ok_or_else(|| PostError::Plugin("the plugin offers no post-processor".into()))?;
        // SAFETY: the request's bytes are readable for its length.
        self.table
            .call_text(|out| unsafe { post(request.as_ptr(), request.len(), out) })
            .map_err(PostError::Plugin)
    }
}
