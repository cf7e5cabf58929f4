//! The kernel's version, a leaf: the outputs that name their writer (the
//! programs' headers, the report, the 3-D files) take it from here.

/// The kernel's version, as in its `Cargo.toml`.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
