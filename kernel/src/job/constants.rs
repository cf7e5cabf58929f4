//! Where a family's parameter and a machine constant both set a quantity:
//! which wins and why, stated as a warning of the run (the report, the
//! terminal), never a silent replacement.

use crate::machine::MachineInfo;
use crate::math::Real;
use crate::params::{ParamSpec, Params, MACHINE_CONTROL};
use crate::verdict::Finding;
use std::collections::BTreeMap;

/// The rule of the warnings below.
pub const CONSTANTS: &str = "machine constants";

/// One warning per parameter restating a machine constant whose value
/// differs from what the family or the user gave: the machine's constant
/// replacing the family's default, or a value set for the run replacing
/// the machine's constant for the whole run (its chains, bodies, scene).
/// `origins` says where each value came from
/// ([`crate::params::resolve_traced`]).
pub fn stated(
    specs: &[ParamSpec],
    values: &Params,
    origins: &BTreeMap<String, String>,
    machine: &MachineInfo,
) -> Vec<Finding> {
    let mut out = Vec::new();
    for s in specs {
        let Some(m) = s.machine.as_deref().filter(|m| *m != MACHINE_CONTROL) else {
            continue;
        };
        let Some(&constant) = machine.constants.get(m) else {
            continue;
        };
        let (Some(default), Some(value)) = (
            s.default.as_number(),
            values.get(&s.name).and_then(|v| v.as_number()),
        ) else {
            continue;
        };
        let origin = origins.get(&s.name).map(String::as_str).unwrap_or_default();
        let show = |v: Real| crate::math::fixed(v, 4);
        let unit = if s.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", s.unit)
        };
        let message = if origin.starts_with("the machine's constant") {
            if same(default, constant) {
                continue;
            }
            format!(
                "the machine's {m} = {}{unit} replaces the family's default {} = {}{unit}: a parameter that restates a machine constant takes the machine's value; to run with {}, set it (--set {}={}), which sets the machine's {m} for the whole run",
                show(constant),
                s.name,
                show(default),
                show(default),
                s.name,
                show(default)
            )
        } else {
            if same(value, constant) {
                continue;
            }
            format!(
                "{} = {}{unit} ({origin}) sets the machine's {m} (the machine states {}{unit}) for the whole run: its chains, its bodies and the scene take {}",
                s.name,
                show(value),
                show(constant),
                show(value)
            )
        };
        out.push(Finding::new(CONSTANTS, message));
    }
    out
}

/// Equal as a machine file and a script write them.
fn same(a: Real, b: Real) -> bool {
    (a - b).abs() <= crate::tolerance::SAME_RATIO * (1.0 + a.abs().max(b.abs()))
}
