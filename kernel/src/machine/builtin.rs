//! The data machine built into the kernel, embedded so it works with no
//! files around. The seeds' own machines (the 3K152VF20, LZ-250,
//! Mannesmann and Fanuc 0i-TC) are plugin crates compiled into the
//! program, described there once; [`super::machine_file`] writes any of
//! them as a machine file.

use super::{Machine, MachineError};

/// `(name, TOML text)` of every built-in data machine: the vertical mill
/// of docs/math.md §1's example, the universal chain with only the mill's axes.
pub const BUILTIN_SOURCES: [(&str, &str); 1] = [(
    "vertical-mill",
    include_str!("../../machines/vertical-mill.toml"),
)];

/// The names of the built-in data machines.
pub const BUILTIN_MACHINES: [&str; 1] = [BUILTIN_SOURCES[0].0];

impl Machine {
    /// A built-in data machine by name (case-insensitive): `vertical-mill`.
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
