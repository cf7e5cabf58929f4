//! Threads of any profile: the profile as data ([`ThreadProfile`]: the
//! axial section with its limits) and the standards that give it
//! ([`standards`]: ISO metric, trapezoidal, ACME, buttress, straight pipe;
//! [`WormSizes`]: cylindrical worms, ZA, ZN and ZI), read from a drawing's
//! designation ([`designated`]).

mod designation;
mod profile;
pub mod standards;
mod worm_sizes;

pub use designation::{designated, Drawing};
pub use profile::{Hand, Limits, ThreadLimits, ThreadProfile, ThreadSection};
pub use worm_sizes::{WormProfile, WormSizes};
