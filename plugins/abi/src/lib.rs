//! # pilgrim-plugin-abi
//!
//! The C ABI between pilgrim and a machine plugin (a shared library), on
//! the model of LinuxCNC's kinematics modules: a fixed, small set of entry
//! points with plain `double` arrays and integer status codes, and the JSON
//! types those entries carry ([`types`]). No Rust type, trait object or
//! allocation crosses the boundary; this crate does not depend on the
//! kernel, so a plugin links this crate (and serde) only.
//!
//! A plugin exports one function whose name starts with `pilgrim_plugin_`
//! (`pilgrim_plugin_acme_lathe`); the host finds it by that prefix, so the
//! library's file may be renamed. (A library exporting several, a bundle of
//! machines, is loaded by the one named after its file; distinct names also
//! let several plugins be compiled into one binary.) It returns a pointer
//! to a static [`PluginTable`]:
//!
//! - `abi_major`, `abi_minor`, `size` first: the host refuses another major
//!   and reads only the fields that lie wholly below `size` (fields are only
//!   ever appended);
//! - `capabilities` (since 1.1): which entries the plugin offers
//!   ([`CAP_INVERSE`], [`CAP_FORWARD`], [`CAP_POST`]); a 1.0 table, which has
//!   no such field, offers all three;
//! - coarse calls carry JSON: `describe` (the machine's [`MachineInfo`]),
//!   `post` (a [`PostRequest`] in, the program's text out);
//! - hot calls are batches of `f64`: `inverse` (poses to axis values) and
//!   `forward` (axis values to poses), many rows per call;
//! - every entry catches panics (the plugin's own construction included) and
//!   returns a status ([`STATUS_OK`], [`STATUS_ERROR`], [`STATUS_PANIC`]);
//!   `last_error` gives the message;
//! - a [`Buffer`] is freed by whoever allocated it: buffers a plugin returns
//!   go back through its `free_buffer`.
//!
//! The crate stands alone (nothing inherited from pilgrim's workspace); C
//! plugins use its header `include/pilgrim_plugin.h`, generated from it by
//! cbindgen. pilgrim's `docs/plugins.md` is the how-to and the contract.
//!
//! A Rust plugin implements [`Plugin`] and exports it with [`export_plugin!`]:
//!
//! ```
//! use pilgrim_plugin_abi::types::{Axis, AxisKind, MachineInfo};
//! use pilgrim_plugin_abi::{export_plugin, Plugin, PluginError};
//!
//! #[derive(Default)]
//! struct Lathe;
//!
//! impl Plugin for Lathe {
//!     fn describe(&self) -> MachineInfo {
//!         let axis = |name: &str| Axis {
//!             name: name.into(), kind: AxisKind::Linear, min: -500.0, max: 500.0,
//!             max_feed: 8000.0, programmed: true, description: String::new(),
//!             moves: None, turns: None, body: None, max_accel: None,
//!             turns_part: false,
//!         };
//!         MachineInfo {
//!             name: "lathe".into(), description: String::new(), control: "fanuc".into(),
//!             axes: vec![axis("X"), axis("Z")], solved_axes: vec!["X".into(), "Z".into()],
//!             constants: Default::default(), program_decimals: None, driven_axes: vec![],
//!             bodies: vec![], chain: vec![], tool: Default::default(), min_feed: None,
//!             setup: Default::default(),
//!         }
//!     }
//!     fn inverse(&self, poses: &[f64], tool: &[f64; 6], out: &mut [f64]) -> Result<(), PluginError> {
//!         for (p, q) in poses.chunks_exact(6).zip(out.chunks_exact_mut(2)) {
//!             q[0] = 2.0 * (p[0] - tool[0]); // diameter
//!             q[1] = p[2] - tool[2];
//!         }
//!         Ok(())
//!     }
//!     fn forward(&self, axes: &[f64], tool: &[f64; 6], out: &mut [f64]) -> Result<(), PluginError> {
//!         for (q, p) in axes.chunks_exact(2).zip(out.chunks_exact_mut(6)) {
//!             p.copy_from_slice(&[0.5 * q[0] + tool[0], tool[1], q[1] + tool[2], tool[3], tool[4], tool[5]]);
//!         }
//!         Ok(())
//!     }
//! }
//!
//! export_plugin!(pilgrim_plugin_lathe, Lathe);
//!
//! let table = unsafe { &*pilgrim_plugin_lathe() };
//! assert_eq!(table.abi_major, pilgrim_plugin_abi::ABI_MAJOR);
//! assert_eq!(table.capabilities, pilgrim_plugin_abi::CAP_INVERSE | pilgrim_plugin_abi::CAP_FORWARD);
//! assert!(table.post.is_none());
//! ```

pub mod types;

pub use types::{MachineInfo, PostRequest};

use std::panic::{catch_unwind, AssertUnwindSafe};

/// The ABI's major version: a host refuses a plugin of another major.
pub const ABI_MAJOR: u32 = 1;
/// The ABI's minor version: fields appended to the table and to the JSON
/// types since the major (1.1: the table's `capabilities`; the descriptor's
/// `driven_axes`, `bodies`, `chain`, `tool`, `min_feed`; 1.2: the
/// descriptor's and the program's `setup`, a block's `keep`; 1.3: the
/// setup's `feed_group`; 1.4: a thread block's `start_deg`; 1.5: a body's
/// `approach_feed`, a block's `number`; 1.6: the body shapes `cylinder`,
/// `box` and `guard`; 1.7: a body's `mount`, a constant factor's `scale`,
/// an axis's `max_accel`; 1.8: an axis's `turns_part`; 1.9: the body
/// shape `cone`; 1.10: a body's `reach`; 1.11: a program's threading
/// `cycles`; 1.12: the setup's `power_on`;
/// 1.13: a program's `fanuc_cycles`, a block's `line`; 1.14: a block's
/// `dwell_s`).
pub const ABI_MINOR: u32 = 14;

/// The call succeeded.
pub const STATUS_OK: i32 = 0;
/// The call failed; `last_error` has the message.
pub const STATUS_ERROR: i32 = 1;
/// The call panicked (and was stopped at the boundary); `last_error` has the message.
pub const STATUS_PANIC: i32 = 2;

/// `failed_row` when a failure is not tied to a row.
pub const NO_ROW: usize = usize::MAX;

/// The plugin solves inverse kinematics (`inverse`).
pub const CAP_INVERSE: u32 = 1;
/// The plugin solves forward kinematics (`forward`).
pub const CAP_FORWARD: u32 = 2;
/// The plugin posts its own programs (`post`); without it the host's
/// writer posts them in the descriptor's `control` dialect.
pub const CAP_POST: u32 = 4;
/// What a table without the `capabilities` field (ABI 1.0) offers.
pub const CAP_ABI_1_0: u32 = CAP_INVERSE | CAP_FORWARD | CAP_POST;

/// Bytes allocated by the plugin and handed to the host, which copies them
/// and returns the buffer through the table's `free_buffer`.
#[repr(C)]
#[derive(Debug)]
pub struct Buffer {
    /// Start of the bytes (UTF-8 text).
    pub ptr: *mut u8,
    /// Number of bytes.
    pub len: usize,
    /// Allocated capacity (for the plugin's own freeing).
    pub cap: usize,
}

impl Buffer {
    /// An empty buffer (nothing to free).
    pub const fn empty() -> Self {
        Self {
            ptr: std::ptr::null_mut(),
            len: 0,
            cap: 0,
        }
    }

    /// Hands a string's bytes over.
    pub fn from_string(s: String) -> Self {
        let mut v = std::mem::ManuallyDrop::new(s.into_bytes());
        Self {
            ptr: v.as_mut_ptr(),
            len: v.len(),
            cap: v.capacity(),
        }
    }
}

/// `describe(out)`: writes the JSON descriptor ([`MachineInfo`]) into `out`.
pub type DescribeFn = unsafe extern "C" fn(out: *mut Buffer) -> i32;
/// `inverse(poses, count, tool, out, width, failed_row)`: `poses` holds
/// `count` rows of 6 (point, unit axis; part frame, mm); `tool` 6 values
/// (the tracked point and axis in the tool's frame); `out` room for `count`
/// rows of `width` values, the descriptor's `solved_axes` (mm, rad), which
/// the plugin checks. On failure `failed_row` receives the row or [`NO_ROW`].
pub type InverseFn = unsafe extern "C" fn(
    poses: *const f64,
    count: usize,
    tool: *const f64,
    out: *mut f64,
    width: usize,
    failed_row: *mut usize,
) -> i32;
/// `forward(axes, count, width, tool, out)`: `count` rows of `width` solved
/// axes to `count` rows of 6 (point, axis).
pub type ForwardFn = unsafe extern "C" fn(
    axes: *const f64,
    count: usize,
    width: usize,
    tool: *const f64,
    out: *mut f64,
) -> i32;
/// `post(request, len, out)`: a JSON [`PostRequest`] of `len` bytes to the
/// program's text.
pub type PostFn = unsafe extern "C" fn(request: *const u8, len: usize, out: *mut Buffer) -> i32;
/// `last_error(out)`: the message of this thread's last failed call.
pub type LastErrorFn = unsafe extern "C" fn(out: *mut Buffer) -> i32;
/// `free_buffer(buffer)`: frees a buffer this plugin returned.
pub type FreeBufferFn = unsafe extern "C" fn(buffer: Buffer);
/// The exported entry: returns the plugin's static table.
pub type EntryFn = unsafe extern "C" fn() -> *const PluginTable;

/// The entry table. Fields are only ever appended; `size` says how many a
/// plugin has. Entries are `Option` so that a C plugin's `NULL` is seen,
/// not called.
#[repr(C)]
#[derive(Debug)]
pub struct PluginTable {
    /// [`ABI_MAJOR`] of the plugin's build.
    pub abi_major: u32,
    /// [`ABI_MINOR`] of the plugin's build.
    pub abi_minor: u32,
    /// `size_of::<PluginTable>()` in the plugin's build.
    pub size: u32,
    // The entries' types are written out, not named by their aliases
    // below: cbindgen cannot see through `Option<alias>` (cbindgen #326),
    // and the C header must have function pointers here. The assertions
    // after the struct hold each field to its alias.
    /// See [`DescribeFn`].
    pub describe: Option<unsafe extern "C" fn(out: *mut Buffer) -> i32>,
    /// See [`InverseFn`].
    pub inverse: Option<
        unsafe extern "C" fn(
            poses: *const f64,
            count: usize,
            tool: *const f64,
            out: *mut f64,
            width: usize,
            failed_row: *mut usize,
        ) -> i32,
    >,
    /// See [`ForwardFn`].
    pub forward: Option<
        unsafe extern "C" fn(
            axes: *const f64,
            count: usize,
            width: usize,
            tool: *const f64,
            out: *mut f64,
        ) -> i32,
    >,
    /// See [`PostFn`]; `None` unless [`CAP_POST`].
    pub post: Option<unsafe extern "C" fn(request: *const u8, len: usize, out: *mut Buffer) -> i32>,
    /// See [`LastErrorFn`].
    pub last_error: Option<unsafe extern "C" fn(out: *mut Buffer) -> i32>,
    /// See [`FreeBufferFn`].
    pub free_buffer: Option<unsafe extern "C" fn(buffer: Buffer)>,
    /// Since 1.1: the `CAP_*` bits of the entries offered.
    pub capabilities: u32,
}

// Each entry of the table is its alias's type (a compile error otherwise).
const _: fn(&PluginTable) -> Option<DescribeFn> = |t| t.describe;
const _: fn(&PluginTable) -> Option<InverseFn> = |t| t.inverse;
const _: fn(&PluginTable) -> Option<ForwardFn> = |t| t.forward;
const _: fn(&PluginTable) -> Option<PostFn> = |t| t.post;
const _: fn(&PluginTable) -> Option<LastErrorFn> = |t| t.last_error;
const _: fn(&PluginTable) -> Option<FreeBufferFn> = |t| t.free_buffer;

/// The size of the table in this build (what `size` says).
pub const TABLE_SIZE: u32 = std::mem::size_of::<PluginTable>() as u32;

/// The size of an ABI 1.0 table: every field before `capabilities`.
pub const TABLE_SIZE_1_0: u32 = std::mem::offset_of!(PluginTable, capabilities) as u32;

/// A plugin's failure: a message, and the row of a batch it happened at.
#[derive(Debug, Clone, PartialEq)]
pub struct PluginError {
    /// The row, for batch calls.
    pub row: Option<usize>,
    /// What went wrong.
    pub message: String,
}

impl PluginError {
    /// A failure not tied to a row.
    pub fn new(message: impl Into<String>) -> Self {
        Self {
            row: None,
            message: message.into(),
        }
    }

    /// A failure at a row of a batch.
    pub fn at(row: usize, message: impl Into<String>) -> Self {
        Self {
            row: Some(row),
            message: message.into(),
        }
    }
}

/// Checks that pose `row` (point and axis, 6 values) keeps a machine that
/// moves its tool in the part's axial section (the XZ plane through the
/// tool's reference) with the tool's axis the part's (a cylindrical
/// grinder, a lathe): y and the axis as the `tool` reference has them,
/// within `tol`. `tool_name` names the tool in the message.
///
/// # Failures
/// The point off the section, or the axis turned, named by row.
pub fn check_axial_section(
    row: usize,
    pose: &[f64],
    tool: &[f64; 6],
    tol: f64,
    tool_name: &str,
) -> Result<(), PluginError> {
    if (pose[1] - tool[1]).abs() > tol {
        return Err(PluginError::at(
            row,
            format!(
                "the point is {:.6} mm off the axial section the {tool_name} moves in (y must be {})",
                pose[1] - tool[1],
                tool[1]
            ),
        ));
    }
    let tilt =
        ((pose[3] - tool[3]).powi(2) + (pose[4] - tool[4]).powi(2) + (pose[5] - tool[5]).powi(2))
            .sqrt();
    if tilt > tol {
        return Err(PluginError::at(
            row,
            format!(
                "the {tool_name}'s axis ({:.6}, {:.6}, {:.6}) must stay parallel to the part's ({}, {}, {})",
                pose[3], pose[4], pose[5], tool[3], tool[4], tool[5]
            ),
        ));
    }
    Ok(())
}

/// What a Rust plugin implements; [`export_plugin!`] makes the C entry
/// points from it. Slices are the batches described at [`InverseFn`] and
/// [`ForwardFn`], already checked for length against the descriptor's
/// `solved_axes`.
pub trait Plugin {
    /// Whether the plugin posts its own programs ([`CAP_POST`]); otherwise
    /// the host's writer does, in the descriptor's `control` dialect.
    const POSTS: bool = false;

    /// The machine's descriptor.
    fn describe(&self) -> MachineInfo;
    /// Inverse kinematics of a batch.
    fn inverse(&self, poses: &[f64], tool: &[f64; 6], out: &mut [f64]) -> Result<(), PluginError>;
    /// Forward kinematics of a batch.
    fn forward(&self, axes: &[f64], tool: &[f64; 6], out: &mut [f64]) -> Result<(), PluginError>;
    /// The program's text for a request; called only if [`Self::POSTS`].
    fn post(&self, request: &PostRequest) -> Result<String, PluginError> {
        let _ = request;
        Err(PluginError::new("this plugin does not post programs"))
    }
}

/// The glue [`export_plugin!`] expands to: each function builds the plugin
/// (on first use) and calls it inside one panic guard, and keeps the last
/// error. Not for direct use.
pub mod entry {
    use super::*;
    use std::cell::RefCell;

    thread_local! {
        static LAST_ERROR: RefCell<String> = const { RefCell::new(String::new()) };
    }

    fn set_error(message: String) {
        LAST_ERROR.with(|e| *e.borrow_mut() = message);
    }

    fn panic_message(p: Box<dyn std::any::Any + Send>) -> String {
        let text = p
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| p.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        format!("the plugin panicked: {text}")
    }

    /// Runs `f`, turning an error or a panic into a status.
    fn guarded(failed_row: *mut usize, f: impl FnOnce() -> Result<(), PluginError>) -> i32 {
        match catch_unwind(AssertUnwindSafe(f)) {
            Ok(Ok(())) => STATUS_OK,
            Ok(Err(e)) => {
                if !failed_row.is_null() {
                    // SAFETY: the host passes a valid pointer or null.
                    unsafe { *failed_row = e.row.unwrap_or(NO_ROW) };
                }
                set_error(e.message);
                STATUS_ERROR
            }
            Err(p) => {
                set_error(panic_message(p));
                STATUS_PANIC
            }
        }
    }

    fn write(out: *mut Buffer, s: String) -> Result<(), PluginError> {
        if out.is_null() {
            return Err(PluginError::new("null output buffer"));
        }
        // SAFETY: the host passes a valid, writable Buffer.
        unsafe { *out = Buffer::from_string(s) };
        Ok(())
    }

    fn tool6(tool: *const f64) -> Result<[f64; 6], PluginError> {
        if tool.is_null() {
            return Err(PluginError::new("null tool frame"));
        }
        let mut t = [0.0; 6];
        // SAFETY: the host passes 6 readable values.
        t.copy_from_slice(unsafe { std::slice::from_raw_parts(tool, 6) });
        Ok(t)
    }

    /// A plugin built, with the width of its axis rows (its descriptor's
    /// number of solved axes), read once.
    #[derive(Debug)]
    pub struct Built<P> {
        plugin: P,
        width: usize,
    }

    impl<P: Plugin + Default> Built<P> {
        /// Builds the plugin and reads its width.
        #[allow(clippy::new_without_default)]
        pub fn new() -> Self {
            let plugin = P::default();
            let width = plugin.describe().solved_axes.len();
            Self { plugin, width }
        }
    }

    /// The host's `width` against the plugin's.
    fn check_width<P>(p: &Built<P>, width: usize) -> Result<usize, PluginError> {
        let n = p.width;
        if width != n {
            return Err(PluginError::new(format!(
                "the host gives rows of {width} axis values, the plugin solves {n} axes"
            )));
        }
        Ok(n)
    }

    /// `count * width` values, or an error if that overflows.
    fn values(count: usize, width: usize, what: &str) -> Result<usize, PluginError> {
        count.checked_mul(width).ok_or_else(|| {
            PluginError::new(format!("{count} rows of {width} {what} values overflow"))
        })
    }

    /// A batch's input and output.
    type Batch<'a> = (&'a [f64], &'a mut [f64]);

    /// A batch's input and output as slices; `None` for an empty batch.
    ///
    /// # Safety
    /// Non-null pointers must be valid for `n_in` reads and `n_out` writes.
    unsafe fn batch<'a>(
        input: *const f64,
        n_in: usize,
        output: *mut f64,
        n_out: usize,
    ) -> Result<Option<Batch<'a>>, PluginError> {
        if n_in == 0 && n_out == 0 {
            return Ok(None);
        }
        if input.is_null() || output.is_null() {
            return Err(PluginError::new("null input or output array"));
        }
        // SAFETY: as the caller promises.
        Ok(Some(unsafe {
            (
                std::slice::from_raw_parts(input, n_in),
                std::slice::from_raw_parts_mut(output, n_out),
            )
        }))
    }

    /// `describe` for the plugin `get` builds.
    ///
    /// # Safety
    /// `out` must be a valid pointer to a `Buffer`.
    pub unsafe fn describe<P: Plugin + 'static>(
        get: impl FnOnce() -> &'static Built<P>,
        out: *mut Buffer,
    ) -> i32 {
        guarded(std::ptr::null_mut(), || {
            let text = serde_json::to_string(&get().plugin.describe()).map_err(|e| {
                PluginError::new(format!("the descriptor cannot be written as JSON: {e}"))
            })?;
            write(out, text)
        })
    }

    /// `inverse` for the plugin `get` builds.
    ///
    /// # Safety
    /// Pointers as [`InverseFn`] says.
    #[allow(clippy::too_many_arguments)]
    pub unsafe fn inverse<P: Plugin + 'static>(
        get: impl FnOnce() -> &'static Built<P>,
        poses: *const f64,
        count: usize,
        tool: *const f64,
        out: *mut f64,
        width: usize,
        failed_row: *mut usize,
    ) -> i32 {
        guarded(failed_row, || {
            let p = get();
            let n = check_width(p, width)?;
            let (n_in, n_out) = (values(count, 6, "pose")?, values(count, n, "axis")?);
            // SAFETY: the host passes count*6 poses and count*n outputs.
            match unsafe { batch(poses, n_in, out, n_out)? } {
                Some((poses, out)) => p.plugin.inverse(poses, &tool6(tool)?, out),
                None => Ok(()),
            }
        })
    }

    /// `forward` for the plugin `get` builds.
    ///
    /// # Safety
    /// Pointers as [`ForwardFn`] says.
    pub unsafe fn forward<P: Plugin + 'static>(
        get: impl FnOnce() -> &'static Built<P>,
        axes: *const f64,
        count: usize,
        width: usize,
        tool: *const f64,
        out: *mut f64,
    ) -> i32 {
        guarded(std::ptr::null_mut(), || {
            let p = get();
            let n = check_width(p, width)?;
            let (n_in, n_out) = (values(count, n, "axis")?, values(count, 6, "pose")?);
            // SAFETY: the host passes count*n axis values and count*6 outputs.
            match unsafe { batch(axes, n_in, out, n_out)? } {
                Some((axes, out)) => p.plugin.forward(axes, &tool6(tool)?, out),
                None => Ok(()),
            }
        })
    }

    /// `post` for the plugin `get` builds.
    ///
    /// # Safety
    /// `request` must point to `len` readable bytes; `out` to a `Buffer`.
    pub unsafe fn post<P: Plugin + 'static>(
        get: impl FnOnce() -> &'static Built<P>,
        request: *const u8,
        len: usize,
        out: *mut Buffer,
    ) -> i32 {
        guarded(std::ptr::null_mut(), || {
            if request.is_null() {
                return Err(PluginError::new("null request"));
            }
            // SAFETY: the host passes len readable bytes.
            let bytes = unsafe { std::slice::from_raw_parts(request, len) };
            let req: PostRequest = serde_json::from_slice(bytes)
                .map_err(|e| PluginError::new(format!("bad post request: {e}")))?;
            write(out, get().plugin.post(&req)?)
        })
    }

    /// `last_error`.
    ///
    /// # Safety
    /// `out` must be a valid pointer to a `Buffer`.
    pub unsafe extern "C" fn last_error(out: *mut Buffer) -> i32 {
        let message = LAST_ERROR.with(|e| e.borrow().clone());
        guarded(std::ptr::null_mut(), || write(out, message))
    }

    /// `free_buffer`.
    ///
    /// # Safety
    /// `buffer` must have come from this plugin and not been freed.
    pub unsafe extern "C" fn free_buffer(buffer: Buffer) {
        if !buffer.ptr.is_null() {
            // SAFETY: made by Buffer::from_string in this library.
            drop(unsafe { Vec::from_raw_parts(buffer.ptr, buffer.len, buffer.cap) });
        }
    }
}

/// Exports a [`Plugin`] (a type with `Default`) as the C entry `$symbol`,
/// whose name must start with `pilgrim_plugin_` (the library's only such
/// export, or the one named after its file). The plugin is built on
/// its first call, inside that call's panic guard: a `Default` that panics
/// is an error the host reports, not an abort.
#[macro_export]
macro_rules! export_plugin {
    ($symbol:ident, $ty:ty) => {
        /// The pilgrim plugin entry: the static entry table.
        #[no_mangle]
        pub extern "C" fn $symbol() -> *const $crate::PluginTable {
            static INSTANCE: ::std::sync::OnceLock<$crate::entry::Built<$ty>> =
                ::std::sync::OnceLock::new();
            fn get() -> &'static $crate::entry::Built<$ty> {
                INSTANCE.get_or_init($crate::entry::Built::new)
            }
            unsafe extern "C" fn describe(out: *mut $crate::Buffer) -> i32 {
                // SAFETY: forwarded from the host's call.
                unsafe { $crate::entry::describe(get, out) }
            }
            unsafe extern "C" fn inverse(
                poses: *const f64,
                count: usize,
                tool: *const f64,
                out: *mut f64,
                width: usize,
                failed_row: *mut usize,
            ) -> i32 {
                // SAFETY: forwarded from the host's call.
                unsafe { $crate::entry::inverse(get, poses, count, tool, out, width, failed_row) }
            }
            unsafe extern "C" fn forward(
                axes: *const f64,
                count: usize,
                width: usize,
                tool: *const f64,
                out: *mut f64,
            ) -> i32 {
                // SAFETY: forwarded from the host's call.
                unsafe { $crate::entry::forward(get, axes, count, width, tool, out) }
            }
            unsafe extern "C" fn post(
                request: *const u8,
                len: usize,
                out: *mut $crate::Buffer,
            ) -> i32 {
                // SAFETY: forwarded from the host's call.
                unsafe { $crate::entry::post(get, request, len, out) }
            }
            const POSTS: bool = <$ty as $crate::Plugin>::POSTS;
            static TABLE: $crate::PluginTable = $crate::PluginTable {
                abi_major: $crate::ABI_MAJOR,
                abi_minor: $crate::ABI_MINOR,
                size: $crate::TABLE_SIZE,
                describe: Some(describe),
                inverse: Some(inverse),
                forward: Some(forward),
                post: if POSTS { Some(post) } else { None },
                last_error: Some($crate::entry::last_error),
                free_buffer: Some($crate::entry::free_buffer),
                capabilities: $crate::CAP_INVERSE
                    | $crate::CAP_FORWARD
                    | if POSTS { $crate::CAP_POST } else { 0 },
            };
            &TABLE
        }
    };
}
