//! The Mannesmann caliber grinder (seed 001, MATH §3.5) as a pilgrim
//! machine plugin: the LZ-250's axes (roll turn A, axial X, radial Z,
//! wheel swivel B) and the cross axis Y, which lets it place the wheel
//! exactly on profiles of large reduction. Its description and kinematics
//! are the LZ-250 crate's ([`lz_250::caliber_grinder`],
//! [`lz_250::CaliberKinematics`] with the cross axis); the signs are stated
//! there, and Y +1 mm moves the wheel +1 mm along +Y, tangent to the roll
//! at the wheel.

use lz_250::CaliberKinematics;
use pilgrim_plugin_abi::types::MachineInfo;
use pilgrim_plugin_abi::{export_plugin, Plugin, PluginError};

/// The machine's name.
pub const NAME: &str = "Mannesmann";

/// The Mannesmann's description.
pub fn describe() -> MachineInfo {
    lz_250::caliber_grinder(
        NAME,
        "Mannesmann caliber grinder: roll turn A, axial X, radial Z, cross Y, wheel swivel B",
        true,
    )
}

/// The Mannesmann grinder.
#[derive(Debug, Clone, Default)]
pub struct Mannesmann;

const KINEMATICS: CaliberKinematics = CaliberKinematics { cross: true };

impl Plugin for Mannesmann {
    fn describe(&self) -> MachineInfo {
        describe()
    }

    /// Rows of `[X, Z, Y, A, B]`.
    fn inverse(&self, poses: &[f64], tool: &[f64; 6], out: &mut [f64]) -> Result<(), PluginError> {
        KINEMATICS.inverse(poses, tool, out)
    }

    fn forward(&self, axes: &[f64], tool: &[f64; 6], out: &mut [f64]) -> Result<(), PluginError> {
        KINEMATICS.forward(axes, tool, out)
    }
}

export_plugin!(pilgrim_plugin_mannesmann, Mannesmann);

#[cfg(test)]
mod tests {
    use super::*;
    use pilgrim_kernel::machine::Machine;

    /// The plugin describes the machine the kernel's machine file does.
    #[test]
    fn the_plugin_is_the_machine_file() {
        assert_eq!(Machine::builtin(NAME).unwrap().info(), &describe());
    }
}
