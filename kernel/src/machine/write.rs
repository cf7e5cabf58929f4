//! A machine's description written as a machine file: the format
//! [`Machine::from_toml_str`](super::Machine::from_toml_str) reads, so that
//! a compiled-in machine (a plugin's descriptor) can be the start of a
//! shop's own file without a second copy of it kept in the repository.
//!
//! Built on the `toml` crate's tables; what is written here is only the
//! mapping from [`MachineInfo`] to the file's keys (degrees for rotary
//! axes and rotation factors, `value` for a constant factor), the inverse
//! of the reader's.

use super::{Axis, AxisKind, BodySpec, FactorSpec, MachineInfo, ToolSpec};
use crate::math::Real;
use pilgrim_plugin_abi::types::{FactorKind, ProgramSetup};
use toml::{Table, Value};

/// `info` as a machine file (TOML), with a comment naming where it came
/// from. Reading it back gives the same description: the same axes,
/// chains, constants and setup, angles to the degree's tenth decimal.
///
/// ```
/// use pilgrim_kernel::machine::{machine_file, Machine};
/// let mill = Machine::builtin("vertical-mill").unwrap();
/// let text = machine_file(mill.info(), "the built-in vertical-mill");
/// let again = Machine::from_toml_str(&text, "written").unwrap();
/// assert_eq!(again.info(), mill.info());
/// ```
pub fn machine_file(info: &MachineInfo, origin: &str) -> String {
    let mut t = Table::new();
    t.insert("name".into(), info.name.clone().into());
    if !info.description.is_empty() {
        t.insert("description".into(), info.description.clone().into());
    }
    t.insert("control".into(), info.control.clone().into());
    if let Some(f) = info.min_feed {
        t.insert("min_feed".into(), f.into());
    }
    if let Some(d) = info.program_decimals {
        t.insert("program_decimals".into(), (d as i64).into());
    }
    if !info.driven_axes.is_empty() {
        t.insert("driven_axes".into(), strings(&info.driven_axes));
    }
    if !info.constants.is_empty() {
        let c: Table = info
            .constants
            .iter()
            .map(|(k, v)| (k.clone(), Value::from(*v)))
            .collect();
        t.insert("constants".into(), c.into());
    }
    if info.tool != ToolSpec::default() {
        let mut tool = Table::new();
        tool.insert("point".into(), triple(info.tool.point));
        tool.insert("axis".into(), triple(info.tool.axis));
        t.insert("tool".into(), tool.into());
    }
    t.insert(
        "axes".into(),
        Value::Array(info.axes.iter().map(axis).collect()),
    );
    t.insert("chain".into(), chain(&info.chain));
    if !info.bodies.is_empty() {
        let b: Table = info
            .bodies
            .iter()
            .map(|b| (b.name.clone(), body(b)))
            .collect();
        t.insert("bodies".into(), b.into());
    }
    if info.setup != ProgramSetup::default() {
        if let Ok(Value::Table(s)) = Value::try_from(&info.setup) {
            t.insert("setup".into(), s.into());
        }
    }
    // A comment line each; a control character in a name or description
    // (which a loaded machine cannot have anyway) cannot end the comment.
    let line = |s: &str| -> String {
        s.chars()
            .map(|c| if c.is_control() { ' ' } else { c })
            .collect()
    };
    let head = format!(
        "# {}\n# The machine file of {}, written from {}.\n\
         # Millimetres and degrees (the _deg keys); edit it and run with --machine FILE.\n",
        line(&info.description),
        line(&info.name),
        line(origin)
    );
    format!("{head}{}", toml::to_string(&t).unwrap_or_default())
}

fn strings(v: &[String]) -> Value {
    Value::Array(v.iter().map(|s| s.clone().into()).collect())
}

fn triple(v: [Real; 3]) -> Value {
    Value::Array(v.iter().map(|x| Value::from(*x)).collect())
}

/// Radians as the file's degrees: rounded to 1e-10 deg, so a machine
/// given in whole degrees is written in whole degrees.
fn degrees(rad: Real) -> Value {
    Value::from((rad.to_degrees() * 1e10).round() / 1e10)
}

fn axis(a: &Axis) -> Value {
    let mut t = Table::new();
    t.insert("name".into(), a.name.clone().into());
    t.insert("kind".into(), a.kind.word().into());
    match a.kind {
        AxisKind::Linear => {
            t.insert("min".into(), a.min.into());
            t.insert("max".into(), a.max.into());
            t.insert("max_feed".into(), a.max_feed.into());
            if let Some(v) = a.max_accel {
                t.insert("max_accel".into(), v.into());
            }
        }
        AxisKind::Rotary => {
            t.insert("min_deg".into(), degrees(a.min));
            t.insert("max_deg".into(), degrees(a.max));
            t.insert("max_feed_deg".into(), degrees(a.max_feed));
            if let Some(v) = a.max_accel {
                t.insert("max_accel_deg".into(), degrees(v));
            }
        }
        AxisKind::Spindle => {
            t.insert("max_rpm".into(), a.max.into());
        }
    }
    if !a.programmed && a.kind != AxisKind::Spindle {
        t.insert("programmed".into(), false.into());
    }
    if let Some(m) = a.moves {
        t.insert("moves".into(), triple(m));
    }
    if let Some(r) = a.turns {
        t.insert("turns".into(), triple(r));
    }
    if a.turns_part {
        t.insert("turns_part".into(), true.into());
    }
    if let Some(b) = &a.body {
        t.insert("body".into(), b.clone().into());
    }
    if !a.description.is_empty() {
        t.insert("description".into(), a.description.clone().into());
    }
    t.into()
}

fn chain(factors: &[FactorSpec]) -> Value {
    Value::Array(factors.iter().map(factor).collect())
}

fn factor(f: &FactorSpec) -> Value {
    let rot = matches!(f.factor, FactorKind::Rx | FactorKind::Ry | FactorKind::Rz);
    let length = |x: Real| if rot { degrees(x) } else { Value::from(x) };
    let suffix = if rot { "_deg" } else { "" };
    let mut t = Table::new();
    t.insert(
        "factor".into(),
        format!("{:?}", f.factor).to_lowercase().into(),
    );
    match (&f.axis, &f.constant) {
        (Some(axis), constant) => {
            t.insert("axis".into(), axis.clone().into());
            if f.scale != 1.0 {
                t.insert("scale".into(), f.scale.into());
            }
            if f.offset != 0.0 {
                t.insert(format!("offset{suffix}"), length(f.offset));
            }
            if let Some(c) = constant {
                t.insert("constant".into(), c.clone().into());
            }
        }
        (None, Some(c)) => {
            t.insert("constant".into(), c.clone().into());
            if f.scale != 1.0 {
                t.insert("scale".into(), f.scale.into());
            }
        }
        (None, None) => {
            t.insert(format!("value{suffix}"), length(f.offset));
        }
    }
    t.into()
}

fn body(b: &BodySpec) -> Value {
    let mut t = Table::new();
    if !b.description.is_empty() {
        t.insert("description".into(), b.description.clone().into());
    }
    if !b.label.is_empty() {
        t.insert("label".into(), b.label.clone().into());
    }
    if let Some(shape) = b.shape.as_ref().and_then(|s| Value::try_from(s).ok()) {
        t.insert("shape".into(), shape);
    }
    if let Some(feed) = b
        .approach_feed
        .as_ref()
        .and_then(|q| Value::try_from(q).ok())
    {
        t.insert("approach_feed".into(), feed);
    }
    if !b.mount.is_part() {
        t.insert("mount".into(), b.mount.word().into());
    }
    if !b.reach.is_any() {
        t.insert("reach".into(), b.reach.word().into());
    }
    t.insert("chain".into(), chain(&b.chain));
    t.into()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::Machine;
    use crate::machine::Mount;
    use pilgrim_plugin_abi::types::Reach;

    /// The mill with a body of each shape (sizes as numbers and as a
    /// constant).
    fn mill_with_bodies() -> MachineInfo {
        use crate::machine::{BodyShape, Quantity};
        use pilgrim_plugin_abi::types::FactorKind;
        let mut info = Machine::builtin("vertical-mill").unwrap().info().clone();
        info.constants.insert("guard_width".into(), 60.0);
        let v = Quantity::Value;
        for (name, shape) in [
            (
                "column",
                BodyShape::Cylinder {
                    radius: v(150.0),
                    length: v(800.0),
                },
            ),
            (
                "head",
                BodyShape::Block {
                    size: [v(200.0), v(160.0), v(300.0)],
                },
            ),
            (
                "hood",
                BodyShape::Guard {
                    inner: v(30.0),
                    outer: v(34.0),
                    width: Quantity::Constant("guard_width".into()),
                    cover_deg: 270.0,
                },
            ),
        ] {
            info.bodies.push(BodySpec {
                name: name.into(),
                description: String::new(),
                label: String::new(),
                chain: vec![
                    FactorSpec::axis(FactorKind::Tz, "Z"),
                    FactorSpec::value(FactorKind::Rz, 90f64.to_radians()),
                ],
                shape: Some(shape),
                approach_feed: None,
                mount: Mount::Part,
                reach: Default::default(),
            });
        }
        // A body on the tool for tools that cut inside a bore, and one
        // where the part begins.
        for (name, mount, reach) in [
            ("collar", Mount::Tool, Reach::Inside),
            ("chuck", Mount::PartStart, Reach::Any),
        ] {
            info.bodies.push(BodySpec {
                name: name.into(),
                description: String::new(),
                label: String::new(),
                chain: vec![FactorSpec::value(FactorKind::Tz, -50.0)],
                shape: Some(BodyShape::Cylinder {
                    radius: v(40.0),
                    length: v(60.0),
                }),
                approach_feed: None,
                mount,
                reach,
            });
        }
        info
    }

    /// Every compiled-in machine's descriptor, and the mill with a body of
    /// each shape, written and read back, is the same description.
    #[test]
    fn descriptors_survive_the_file() {
        for info in [
            grinder_3k152vf20::describe(),
            lz_250::describe(),
            mannesmann::describe(),
            fanuc_0i_tc::describe(),
            Machine::builtin("vertical-mill").unwrap().info().clone(),
            mill_with_bodies(),
        ] {
            let text = machine_file(&info, "a test");
            let again = Machine::from_toml_str(&text, "written")
                .unwrap_or_else(|e| panic!("{}: {e}\n{text}", info.name));
            // A file's bodies are a table by name: they read back in
            // their names' order.
            let mut info = info;
            info.bodies.sort_by(|a, b| a.name.cmp(&b.name));
            assert_eq!(again.info(), &info, "{text}");
        }
    }
}
