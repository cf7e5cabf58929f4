//! Threads of any profile: the profile as data ([`ThreadProfile`]: the
//! axial section with its limits) and the standards that give it
//! ([`standards`]: ISO metric, trapezoidal, ACME, buttress).

mod profile;
pub mod standards;

pub use profile::{Hand, Limits, ThreadLimits, ThreadProfile, ThreadSection};
