//! The Mannesmann caliber grinder (seed 001, docs/math.md §3.5) as a pilgrim
//! machine plugin: the LZ-250's axes (roll turn A, axial X, radial Z,
//! wheel swivel B) and the cross axis Y, which lets it place the wheel
//! exactly on profiles of large reduction. Its description and kinematics
//! are the LZ-250 crate's ([`lz_250::CaliberGrinder`] with the cross axis);
//! the signs are stated there, and Y +1 mm moves the wheel +1 mm along +Y, tangent to the roll
//! at the wheel.

use lz_250::CaliberGrinder;
use pilgrim_plugin_abi::types::MachineInfo;
use pilgrim_plugin_abi::{export_plugin, Plugin};

/// The machine's name.
pub const NAME: &str = "Mannesmann";

/// The Mannesmann grinder: the LZ-250 crate's caliber grinder with the
/// cross axis.
pub type Mannesmann = CaliberGrinder<true>;

/// The Mannesmann's description.
pub fn describe() -> MachineInfo {
    Mannesmann::default().describe()
}

export_plugin!(pilgrim_plugin_mannesmann, CaliberGrinder<true>);
