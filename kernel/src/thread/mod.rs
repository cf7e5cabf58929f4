//! Threads of any profile: the profile as data ([`ThreadProfile`]: the
//! axial section with its limits) and the standards that give it
//! ([`standards`]: ISO metric, trapezoidal, ACME, buttress), read from a
//! drawing's designation ([`designated`]).

mod designation;
mod profile;
pub mod standards;

pub use designation::{designated, Drawing};
pub use profile::{Hand, Limits, ThreadLimits, ThreadProfile, ThreadSection};
