//! A plugin's entry table, called in this process: the plugins compiled
//! into the program, and, in the child process, a loaded library's.

use super::wire::TableHeader;
use super::{CallError, Calls};
use pilgrim_plugin_abi::{
    Buffer, PluginTable, ABI_MAJOR, CAP_ABI_1_0, NO_ROW, STATUS_OK, STATUS_PANIC,
};
use std::mem::{offset_of, size_of};

/// A plugin's entry table as read: the fields its size covers.
#[derive(Debug, Clone, Copy)]
pub(super) struct Table {
    table: *const PluginTable,
    size: u32,
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

impl Table {
    /// The table an entry returned, and its header; `None` for a null
    /// table. Of a table of another ABI major only the version is read.
    ///
    /// # Safety
    /// `ptr` is null or points to a table laid out as the ABI says for its
    /// first `size` bytes, living as long as the process.
    pub(super) unsafe fn read(ptr: *const PluginTable) -> Option<(Self, TableHeader)> {
        if ptr.is_null() {
            return None;
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
        let table = Self { table: ptr, size };
        if major != ABI_MAJOR {
            let header = TableHeader {
                major,
                minor,
                size,
                capabilities: 0,
                present: [false; 6],
            };
            return Some((table, header));
        }
        let header = TableHeader {
            major,
            minor,
            size,
            capabilities: field!(ptr, size, capabilities).unwrap_or(CAP_ABI_1_0),
            present: [
                table.describe().is_some(),
                table.inverse().is_some(),
                table.forward().is_some(),
                table.post().is_some(),
                table.last_error().is_some(),
                table.free_buffer().is_some(),
            ],
        };
        Some((table, header))
    }

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
        .map(|t| crate::files::excerpt(&t))
        .unwrap_or_else(|| "unknown error".into());
        if status == STATUS_PANIC && !text.contains("panick") {
            format!("the plugin panicked: {text}")
        } else {
            text
        }
    }

    /// Calls an entry that fills a buffer; copies its text (at most
    /// [`crate::files::MAX_DATA_BYTES`]) and frees it.
    fn call_text(&self, f: impl FnOnce(*mut Buffer) -> i32) -> Result<String, String> {
        let mut buf = Buffer::empty();
        let status = f(&mut buf);
        let text = if buf.ptr.is_null() {
            String::new()
        } else {
            let len = buf.len.min(crate::files::MAX_DATA_BYTES as usize);
            // SAFETY: the plugin filled buf with len readable bytes.
            let bytes = unsafe { std::slice::from_raw_parts(buf.ptr, len) };
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

    fn missing(what: &str) -> CallError {
        CallError::whole(format!("the plugin offers no {what}"))
    }
}

impl Calls for Table {
    fn describe(&self) -> Result<String, CallError> {
        let describe = Table::describe(self).ok_or_else(|| Self::missing("describe"))?;
        // SAFETY: the entry fills the buffer it is given.
        self.call_text(|out| unsafe { describe(out) })
            .map_err(CallError::whole)
    }

    fn inverse(
        &self,
        poses: &[f64],
        tool: &[f64; 6],
        width: usize,
        out: &mut [f64],
    ) -> Result<(), CallError> {
        let inverse = Table::inverse(self).ok_or_else(|| Self::missing("inverse kinematics"))?;
        let count = poses.len() / 6;
        debug_assert_eq!(out.len(), count * width);
        let mut failed = NO_ROW;
        // SAFETY: arrays of the sizes the ABI states.
        let status = unsafe {
            inverse(
                poses.as_ptr(),
                count,
                tool.as_ptr(),
                out.as_mut_ptr(),
                width,
                &mut failed,
            )
        };
        if status != STATUS_OK {
            return Err(CallError {
                row: (failed != NO_ROW && failed < count).then_some(failed),
                message: self.last_error_text(status),
            });
        }
        Ok(())
    }

    fn forward(
        &self,
        axes: &[f64],
        tool: &[f64; 6],
        width: usize,
        out: &mut [f64],
    ) -> Result<(), CallError> {
        let forward = Table::forward(self).ok_or_else(|| Self::missing("forward kinematics"))?;
        let count = axes.len().checked_div(width).unwrap_or(0);
        debug_assert_eq!(out.len(), count * 6);
        // SAFETY: arrays of the sizes the ABI states.
        let status =
            unsafe { forward(axes.as_ptr(), count, width, tool.as_ptr(), out.as_mut_ptr()) };
        if status != STATUS_OK {
            return Err(CallError::whole(self.last_error_text(status)));
        }
        Ok(())
    }

    fn post(&self, request: &[u8]) -> Result<String, CallError> {
        let post = Table::post(self).ok_or_else(|| Self::missing("post-processor"))?;
        // SAFETY: the request's bytes are readable for its length.
        self.call_text(|out| unsafe { post(request.as_ptr(), request.len(), out) })
            .map_err(CallError::whole)
    }
}
