//! The program's allocator: the system's, counting per thread the bytes
//! each thread holds (allocated less freed), so that a script's memory
//! limit is looked at after every operation for the cost of one
//! thread-local add per allocation.
//!
//! Hand-written rather than the `cap` crate: `cap` counts in one atomic
//! shared by all threads, which made the caliber job (two threads
//! allocating) 35-40 % slower (1.00 s against 1.40 s, 2026-11-24); a
//! thread's own counter is never shared. A script runs on one thread, so
//! its thread's count is the memory it holds.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

thread_local! {
    /// Bytes this thread has allocated less those it freed (a block freed
    /// by another thread counts there, so one thread's figure may drift;
    /// a script's thread frees what it allocated).
    static HELD: Cell<isize> = const { Cell::new(0) };
}

/// Adds `bytes` to this thread's count; a thread being torn down no
/// longer counts.
fn count(bytes: isize) {
    let _ = HELD.try_with(|h| h.set(h.get().wrapping_add(bytes)));
}

/// The system's allocator, counting.
pub struct Counting;

// SAFETY: every call goes to the system allocator unchanged; the count is
// a thread-local integer without a destructor, touched without allocating.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract, passed on.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            count(layout.size() as isize);
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract, passed on.
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            count(layout.size() as isize);
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: the caller's contract, passed on.
        unsafe { System.dealloc(ptr, layout) };
        count(-(layout.size() as isize));
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: the caller's contract, passed on.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            count(new_size as isize - layout.size() as isize);
        }
        p
    }
}

/// Bytes the calling thread holds (0 if it freed more than it allocated).
pub fn held() -> usize {
    HELD.try_with(Cell::get).unwrap_or(0).max(0) as usize
}
