//! The machines of the seeds, embedded so they work with no files around.

use super::{Machine, MachineError};

/// `(name, TOML text)` of every built-in data machine. (The 3K152VF20 is
/// a plugin crate, `plugins/grinder-3k152vf20`, compiled into the program.)
pub const BUILTIN_SOURCES: [(&str, &str); 4] = [
    ("LZ-250", include_str!("../../machines/lz-250.toml")),
    ("Mannesmann", include_str!("../../machines/mannesmann.toml")),
    (
        "fanuc-0i-tc",
        include_str!("../../machines/fanuc-0i-tc.toml"),
    ),
    (
        "vertical-mill",
        include_str!("../../machines/vertical-mill.toml"),
    ),
];

/// The names of the built-in data machines.
pub const BUILTIN_MACHINES: [&str; 4] = [
    BUILTIN_SOURCES[0].0,
    BUILTIN_SOURCES[1].0,
    BUILTIN_SOURCES[2].0,
    BUILTIN_SOURCES[3].0,
];

impl Machine {
    /// A built-in data machine by name (case-insensitive): `LZ-250` and
    /// `Mannesmann` (caliber grinders), `fanuc-0i-tc` (lathe),
    /// `vertical-mill` (MATH §1's example).
    ///
    /// # Failures
    /// [`MachineError::UnknownMachine`] listing the built-ins.
    pub fn builtin(name: &str) -> Result<Machine, MachineError> {
        let (key, text) = BUILTIN_SOURCES
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .ok_or_else(|| MachineError::UnknownMachine {
                name: name.to_owned(),
                known: BUILTIN_MACHINES.join(", "),
            })?;
        Machine::from_toml_str(text, &format!("built-in machine {key}"))
    }
}
