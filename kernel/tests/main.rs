//! The kernel's public API, tested from outside the crate.
//!
//! One test binary for all of them (see the workspace's `tests/main.rs` for
//! why); run one area with a filter, e.g. `cargo test -p pilgrim-kernel
//! --test kernel caliber::`.

mod caliber;
mod job;
mod machines;
mod mesh;
mod offset;
mod rest;
mod robustness;
mod script;
mod tables;
mod thread_limits;
mod transform;
mod verify;
