//! A machine's description ([`MachineInfo`]) checked and compiled: the
//! tool's chain and every other body's, from their factors as data, and the
//! axes' stated signs checked against them.
//!
//! One validation serves every source: a machine file (whose reader turns
//! each [`Invalid`]'s place into the file's line and column) and a plugin's
//! descriptor ([`Machine::from_info`]).

use super::{Axis, AxisKind, BodyShape, BodySpec, FactorSpec, Machine, MachineError, MachineInfo};
use crate::math::{Point3, Real, Vec3};
use crate::transform::{Chain, FactorKind, ToolFrame};
use pilgrim_plugin_abi::types::Radial;
use std::collections::BTreeMap;

/// How far a rotary axis's stated direction (a unit vector) may be from
/// the one its chain turns it about, found by a central difference
/// ([`crate::tolerance::DERIVATIVE_STEP`], exact to 1e-12): far below any
/// misstated direction, far above the difference's error.
const TURNS_AGREE: Real = 1e-5;

/// A moving body other than the tool (a steady rest): its description and
/// the chain placing its frame in the part frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    spec: BodySpec,
    chain: Chain,
}

impl Body {
    /// Its name.
    pub fn name(&self) -> &str {
        &self.spec.name
    }

    /// Its description as data.
    pub fn spec(&self) -> &BodySpec {
        &self.spec
    }

    /// The chain placing it in the part frame.
    pub fn chain(&self) -> &Chain {
        &self.chain
    }
}

/// Where in a description a value is wrong.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Place {
    /// The axis at this index, at this key (`name`, `max`, `moves`, ...).
    Axis(usize, &'static str),
    /// The tool's chain (`None`) or a body's, as a whole.
    Chain(Option<String>),
    /// A factor of the tool's chain (`None`) or a body's, at this key.
    Factor(Option<String>, usize, &'static str),
    /// A body, at this key (`name`, `shape`).
    Body(String, &'static str),
    /// The machine's name.
    Name,
    /// The machine's description.
    Description,
    /// The tool frame.
    Tool,
    /// The program decimals.
    Decimals,
    /// The program's start and end settings.
    Setup,
}

/// A wrong value in a description: where, and what.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Invalid {
    pub(super) place: Place,
    pub(super) message: String,
}

fn invalid(place: Place, message: impl Into<String>) -> Invalid {
    Invalid {
        place,
        message: message.into(),
    }
}

/// Compiles the factors of `body`'s chain (`None`: the tool's).
fn compile_chain(
    info: &MachineInfo,
    body: Option<&str>,
    factors: &[FactorSpec],
) -> Result<Chain, Invalid> {
    let owner = body.map(str::to_owned);
    if factors.is_empty() {
        let whose = body.map_or("the tool chain".to_owned(), |b| format!("body {b}'s chain"));
        return Err(invalid(
            Place::Chain(owner),
            format!("{whose} has no factors"),
        ));
    }
    let mut b = Chain::builder();
    // Axes take the machine's order.
    for a in &info.axes {
        if factors.iter().any(|f| f.axis.as_deref() == Some(&a.name)) {
            b = b.declare(&a.name);
        }
    }
    for (i, f) in factors.iter().enumerate() {
        let at = |key| Place::Factor(owner.clone(), i, key);
        let kind = f.factor;
        let word = format!("{kind:?}").to_lowercase();
        let finite = |v: Real, key| {
            if v.is_finite() {
                Ok(v)
            } else {
                Err(invalid(
                    at(key),
                    format!("factor {word}: {key} = {v} is not a finite number"),
                ))
            }
        };
        match (&f.axis, &f.constant) {
            (Some(name), None) => {
                let axis = info.axis(name).ok_or_else(|| {
                    invalid(
                        at("axis"),
                        format!(
                            "chain names axis '{name}', which is not declared (axes: {})",
                            info.axes
                                .iter()
                                .map(|a| a.name.as_str())
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    )
                })?;
                let expected = if kind.is_rotation() {
                    AxisKind::Rotary
                } else {
                    AxisKind::Linear
                };
                if axis.kind != expected {
                    return Err(invalid(
                        at("axis"),
                        format!(
                            "axis {} is {} but factor {word} needs a {} axis",
                            axis.name,
                            axis.kind.word(),
                            expected.word()
                        ),
                    ));
                }
                let scale = finite(f.scale, "scale")?;
                if scale == 0.0 {
                    return Err(invalid(at("scale"), "scale must not be 0"));
                }
                b = b.axis_scaled(kind, name, scale, finite(f.offset, "offset")?);
            }
            (None, Some(c)) => {
                let v = info.constants.get(c).copied().ok_or_else(|| {
                    invalid(
                        at("constant"),
                        format!("factor {word}: no machine constant '{c}'"),
                    )
                })?;
                let scale = finite(f.scale, "scale")?;
                b = b.constant(kind, finite(scale * v, "constant")?);
            }
            (None, None) => b = b.constant(kind, finite(f.offset, "value")?),
            (Some(_), Some(_)) => {
                return Err(invalid(
                    at("axis"),
                    "a factor has either an axis or a constant value, not both",
                ))
            }
        }
    }
    b.build()
        .map_err(|e| invalid(Place::Chain(owner), e.to_string()))
}

/// The axis letters a machine may name (ISO 841's): the address letters
/// that no dialect pilgrim writes uses for anything else.
pub const AXIS_LETTERS: &str = "XYZABCUVW";

/// Checks the names and texts of a description ([`crate::names`]): the
/// machine's name is a name (programs carry it); its description, its
/// axes' and bodies' descriptions and labels are texts; an axis's name is
/// one of [`AXIS_LETTERS`] (a spindle's `S` or `S` and a number).
fn check_texts(info: &MachineInfo) -> Result<(), Invalid> {
    use crate::names::{check_name, check_text};
    check_name("machine name", &info.name).map_err(|e| invalid(Place::Name, e.to_string()))?;
    check_text("machine description", &info.description)
        .map_err(|e| invalid(Place::Description, e.to_string()))?;
    for (i, a) in info.axes.iter().enumerate() {
        let ok = if a.kind == AxisKind::Spindle {
            // A spindle is not a word of the program (its speed is S).
            a.name.starts_with('S') && a.name[1..].bytes().all(|b| b.is_ascii_digit())
        } else {
            a.name.len() == 1 && AXIS_LETTERS.contains(a.name.as_str())
        };
        if !ok {
            return Err(invalid(
                Place::Axis(i, "name"),
                format!(
                    "axis name {} must be {} (ISO 841's letters: others are words of the controls)",
                    crate::names::quoted(&a.name),
                    if a.kind == AxisKind::Spindle {
                        "S, or S and a number, for a spindle".to_owned()
                    } else {
                        format!("one of the letters {AXIS_LETTERS}")
                    }
                ),
            ));
        }
        check_text(&format!("axis {} description", a.name), &a.description)
            .map_err(|e| invalid(Place::Axis(i, "description"), e.to_string()))?;
    }
    for b in &info.bodies {
        for (what, t) in [("description", &b.description), ("label", &b.label)] {
            check_text(&format!("body {} {what}", b.name), t)
                .map_err(|e| invalid(Place::Body(b.name.clone(), "name"), e.to_string()))?;
        }
    }
    Ok(())
}

/// Checks the description's axes, decimals and tool frame.
fn check_axes(info: &MachineInfo) -> Result<ToolFrame, Invalid> {
    for (i, a) in info.axes.iter().enumerate() {
        let at = |key| Place::Axis(i, key);
        let name = &a.name;
        if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(invalid(
                at("name"),
                format!("axis name '{name}' must be letters, digits or _"),
            ));
        }
        if info.axes[..i].iter().any(|b| &b.name == name) {
            return Err(invalid(
                at("name"),
                format!("axis '{name}' is declared twice"),
            ));
        }
        for (v, key) in [(a.min, "min"), (a.max, "max"), (a.max_feed, "max_feed")] {
            if !v.is_finite() {
                return Err(invalid(
                    at(key),
                    format!("axis {name}: {key} = {v} is not a finite number"),
                ));
            }
        }
        if a.min >= a.max {
            return Err(invalid(
                at("max"),
                format!("axis {name}: travel max must exceed min"),
            ));
        }
        if let Some(v) = a.max_accel {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(
                    at("max_accel"),
                    format!("axis {name}: max_accel = {v} must be a number > 0"),
                ));
            }
        }
        if a.max_feed <= 0.0 {
            return Err(invalid(
                at("name"),
                format!("axis {name}: the maximum feed must be > 0"),
            ));
        }
        for (v, key, wanted) in [
            (a.moves, "moves", a.kind == AxisKind::Linear),
            (a.turns, "turns", a.kind == AxisKind::Rotary),
        ] {
            match (v, wanted) {
                (Some(x), true) => {
                    let x = Vec3::from(x);
                    if !x.iter().all(|c| c.is_finite()) || x.norm() == 0.0 {
                        return Err(invalid(
                            at(key),
                            format!("axis {name}: {key} must be a finite, non-zero vector"),
                        ));
                    }
                }
                (Some(_), false) => {
                    return Err(invalid(
                        at(key),
                        format!("axis {name}: key '{key}' does not apply to a {} axis", a.kind.word()),
                    ))
                }
                (None, true) => {
                    return Err(invalid(
                        at("name"),
                        format!("axis {name}: state its sign with '{key}' (the tool's motion in the part frame for a positive move)"),
                    ))
                }
                (None, false) => {}
            }
        }
        if a.turns_part {
            let why = match (a.kind, &a.body) {
                (AxisKind::Linear, _) => Some("a linear axis moves the part, it does not turn it"),
                (_, Some(_)) => Some("it moves a body, not the tool"),
                (AxisKind::Rotary, None) if info.chain.is_empty() => {
                    Some("the machine states no tool chain for its turn to lead")
                }
                _ => None,
            };
            if let Some(why) = why {
                return Err(invalid(
                    at("turns_part"),
                    format!("axis {name}: turns_part cannot be set: {why}"),
                ));
            }
        }
        if a.kind == AxisKind::Spindle && a.programmed {
            return Err(invalid(
                at("name"),
                format!("spindle {name} cannot be programmed as a position"),
            ));
        }
    }
    if let Some(d) = info.program_decimals {
        if d > 6 {
            return Err(invalid(
                Place::Decimals,
                format!("program_decimals = {d} must be 0 to 6"),
            ));
        }
    }
    let (p, a) = (info.tool.point, info.tool.axis);
    if p.iter().chain(&a).any(|v| !v.is_finite()) {
        return Err(invalid(Place::Tool, "tool point and axis must be finite"));
    }
    let axis = Vec3::from(a);
    if axis.norm() == 0.0 {
        return Err(invalid(Place::Tool, "tool axis must not be zero"));
    }
    Ok(ToolFrame {
        point: Point3::from(p),
        axis: axis.normalize(),
    })
}

/// Checks a body's name and shape.
fn check_body(info: &MachineInfo, b: &BodySpec) -> Result<(), Invalid> {
    if !crate::files::is_plain_name(&b.name) {
        return Err(invalid(
            Place::Body(b.name.clone(), "name"),
            format!(
                "body name '{}' must be a plain name (letters, digits, _ or -)",
                b.name
            ),
        ));
    }
    if !b.mount.is_part() {
        if let Some(i) = b.chain.iter().position(|f| f.axis.is_some()) {
            return Err(invalid(
                Place::Factor(Some(b.name.clone()), i, "axis"),
                format!(
                    "body {} is mounted on the {}: its chain takes constants only (its mount moves it)",
                    b.name,
                    b.mount.word()
                ),
            ));
        }
        if b.mount == super::Mount::Tool && info.chain.is_empty() {
            return Err(invalid(
                Place::Body(b.name.clone(), "mount"),
                format!(
                    "body {} is mounted on the tool, but the machine states no tool chain to carry it",
                    b.name
                ),
            ));
        }
        if b.approach_feed.is_some() {
            return Err(invalid(
                Place::Body(b.name.clone(), "approach_feed"),
                format!(
                    "body {} is mounted on the {}: only a body on the part frame rides the part",
                    b.name,
                    b.mount.word()
                ),
            ));
        }
    }
    if let Some(q) = &b.approach_feed {
        let v = q.resolve(&info.constants).map_err(|m| {
            invalid(
                Place::Body(b.name.clone(), "approach_feed"),
                format!("body {}: approach_feed: {m}", b.name),
            )
        })?;
        if !(v.is_finite() && v > 0.0) {
            return Err(invalid(
                Place::Body(b.name.clone(), "approach_feed"),
                format!("body {}: approach_feed = {v} mm/min must be > 0", b.name),
            ));
        }
    }
    match &b.shape {
        None => Ok(()),
        Some(shape) => Solid::of(shape, &info.constants).map(|_| ()).map_err(|m| {
            invalid(
                Place::Body(b.name.clone(), "shape"),
                format!("body {}: {m}", b.name),
            )
        }),
    }
}

/// A body's solid with its sizes resolved (mm; the guard's cover in
/// radians), checked: every size finite and above 0, a guard's inner
/// radius below its outer and its cover within the turn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Solid {
    /// A cylinder along the frame's Y, centred on the origin.
    Roller {
        /// Radius (mm).
        radius: Real,
        /// Length (mm).
        length: Real,
    },
    /// A cylinder along the frame's Z, centred on the origin.
    Cylinder {
        /// Radius (mm).
        radius: Real,
        /// Length (mm).
        length: Real,
    },
    /// A cone's frustum along the frame's Z, centred on the origin.
    Cone {
        /// Radius at the -Z end (mm).
        radius: Real,
        /// Radius at the +Z end (mm).
        end_radius: Real,
        /// Length (mm).
        length: Real,
    },
    /// A box centred on the origin, edges along the frame's axes.
    Block {
        /// Its edges along X, Y and Z (mm).
        size: [Real; 3],
    },
    /// A tube round Z over `cover` about +X, centred on the origin.
    Guard {
        /// Inner radius (mm).
        inner: Real,
        /// Outer radius (mm).
        outer: Real,
        /// Width along Z (mm).
        width: Real,
        /// The angle covered (rad).
        cover: Real,
    },
}

/// A body's shape whose sizes cannot be taken: the key and what is wrong
/// with it (a constant the machine lacks, a size not above 0).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct BodyError(pub String);

impl Solid {
    /// `shape` with its sizes taken from `constants` where it names them.
    ///
    /// # Failures
    /// A constant the machine lacks, a size not above 0, a guard whose
    /// inner radius is not below its outer or whose cover is not within
    /// (0, 360) deg: the message names the key.
    pub fn of(shape: &BodyShape, constants: &BTreeMap<String, Real>) -> Result<Solid, BodyError> {
        Self::of_text(shape, constants).map_err(BodyError)
    }

    /// [`Self::of`], its failure as text.
    fn of_text(shape: &BodyShape, constants: &BTreeMap<String, Real>) -> Result<Solid, String> {
        let size = |q: &super::Quantity, what: &str| -> Result<Real, String> {
            let v = q.resolve(constants).map_err(|m| format!("{what}: {m}"))?;
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(format!("{what} = {v} must be > 0"))
            }
        };
        Ok(match shape {
            BodyShape::Roller { radius, length } => Solid::Roller {
                radius: size(radius, "radius")?,
                length: size(length, "length")?,
            },
            BodyShape::Cylinder { radius, length } => Solid::Cylinder {
                radius: size(radius, "radius")?,
                length: size(length, "length")?,
            },
            BodyShape::Cone {
                radius,
                end_radius,
                length,
            } => Solid::Cone {
                radius: size(radius, "radius")?,
                end_radius: size(end_radius, "end_radius")?,
                length: size(length, "length")?,
            },
            BodyShape::Block { size: [x, y, z] } => Solid::Block {
                size: [size(x, "size x")?, size(y, "size y")?, size(z, "size z")?],
            },
            BodyShape::Guard {
                inner,
                outer,
                width,
                cover_deg,
            } => {
                let (inner, outer) = (size(inner, "inner")?, size(outer, "outer")?);
                if inner >= outer {
                    return Err(format!("inner = {inner} must be below outer = {outer}"));
                }
                if !(cover_deg.is_finite() && *cover_deg > 0.0 && *cover_deg < 360.0) {
                    return Err(format!(
                        "cover_deg = {cover_deg} must be above 0 and below 360"
                    ));
                }
                Solid::Guard {
                    inner,
                    outer,
                    width: size(width, "width")?,
                    cover: cover_deg.to_radians(),
                }
            }
        })
    }
}

/// The stated sign of axis `a` against the chain that moves it: `Ok` if
/// it holds, else the key (`moves`, `turns`, `name`, `body`) and the message.
fn sign_error(m: &Machine, a: &Axis) -> Result<(), (&'static str, String)> {
    if a.kind == AxisKind::Spindle {
        let used = std::iter::once(&m.chain)
            .chain(m.bodies.values().map(|b| &b.chain))
            .any(|c| c.axis_index(&a.name).is_some());
        if used {
            return Err((
                "name",
                format!("spindle {} cannot be bound in a chain", a.name),
            ));
        }
        return Ok(());
    }
    let (chain, origin) = match &a.body {
        None => (&m.chain, m.tool.point),
        Some(b) => match m.bodies.get(b) {
            Some(body) => (&body.chain, Point3::origin()),
            None => {
                return Err((
                    "body",
                    format!(
                        "axis {}: no body '{b}' (declare [[bodies.{b}.chain]])",
                        a.name
                    ),
                ))
            }
        },
    };
    let Some(i) = chain.axis_index(&a.name) else {
        let whose = a.body.as_deref().unwrap_or("tool");
        return Err((
            "name",
            format!("axis {} is not bound in the {whose} chain", a.name),
        ));
    };
    let travel = m.travel_of(chain).map_err(|e| ("name", e.to_string()))?;
    let q0: Vec<Real> = travel
        .iter()
        .map(|&(lo, hi)| 0.0_f64.clamp(lo, hi))
        .collect();
    let f0 = chain.frame_unchecked(&q0);
    let mut q1 = q0.clone();
    match a.kind {
        AxisKind::Linear => {
            q1[i] += 1.0;
            let d =
                chain.frame_unchecked(&q1).transform_point(&origin) - f0.transform_point(&origin);
            let stated = Vec3::from(a.moves.unwrap_or_default());
            if (d - stated).norm() > crate::tolerance::SAME_RATIO {
                return Err((
                    "moves",
                    format!("axis {}: moves = [{}, {}, {}] but the chain moves it by [{:.6}, {:.6}, {:.6}]", a.name, stated.x, stated.y, stated.z, d.x, d.y, d.z),
                ));
            }
        }
        _ => {
            let h = crate::tolerance::DERIVATIVE_STEP;
            q1[i] += h;
            let r = chain.frame_unchecked(&q1).rot * f0.rot.transpose();
            let w = Vec3::new(
                r[(2, 1)] - r[(1, 2)],
                r[(0, 2)] - r[(2, 0)],
                r[(1, 0)] - r[(0, 1)],
            ) / (2.0 * h);
            let stated = Vec3::from(a.turns.unwrap_or_default()).normalize();
            if (w - stated).norm() > TURNS_AGREE {
                return Err((
                    "turns",
                    format!("axis {}: turns = [{}, {}, {}] but the chain turns it about [{:.4}, {:.4}, {:.4}]", a.name, stated.x, stated.y, stated.z, w.x, w.y, w.z),
                ));
            }
        }
    }
    Ok(())
}

/// A rotary axis that turns the part must be the part's own turn in the
/// tool chain: its factor an Rz among the chain's leading factors that
/// turn about or move along Z (which commute with it). The chain is then
/// the part's turn times the rest: the part stands on the machine turned
/// by the inverse of its turns, and the rest places the tool there.
fn part_turn_error(m: &Machine, a: &Axis) -> Result<(), String> {
    if !a.turns_part || a.kind != AxisKind::Rotary {
        return Ok(());
    }
    let Some(i) = m.chain.axis_index(&a.name) else {
        return Err(format!(
            "axis {}: turns_part, but the tool chain does not bind it",
            a.name
        ));
    };
    let binds = |k: &usize| matches!(m.chain.factors()[*k].value, crate::transform::FactorValue::Axis { axis, .. } if axis == i);
    let turning = part_turn_factors(&m.chain, &m.info);
    match (0..m.chain.factors().len()).find(binds) {
        Some(k) if !turning.contains(&k) => Err(format!(
            "axis {}: turns_part, but its factor is the tool chain's number {}, {:?}: the part's turn must be an Rz with only Rz and Tz factors before it (those commute with it)",
            a.name,
            k + 1,
            m.chain.factors()[k].kind
        )),
        _ => Ok(()),
    }
}

/// The factors of the tool chain `chain` that are the part's own turn:
/// the Rz factors of axes that turn the part (`info`'s
/// [`Axis::turns_part`]) among the chain's leading factors that turn about
/// or move along Z, which commute with a turn of the part about Z. The
/// chain is their product times the rest: the part stands on the machine
/// turned by their inverse.
pub fn part_turn_factors(chain: &crate::transform::Chain, info: &MachineInfo) -> Vec<usize> {
    chain
        .factors()
        .iter()
        .take_while(|f| matches!(f.kind, FactorKind::Rz | FactorKind::Tz))
        .enumerate()
        .filter(|(_, f)| {
            f.kind == FactorKind::Rz
                && matches!(f.value, crate::transform::FactorValue::Axis { axis, .. }
                    if info.axis(&chain.axis_names()[axis]).is_some_and(|a| a.turns_part))
        })
        .map(|(k, _)| k)
        .collect()
}

/// Checks the bodies and compiles their chains.
fn compile_bodies(info: &MachineInfo) -> Result<BTreeMap<String, Body>, Invalid> {
    let mut bodies = BTreeMap::new();
    for b in &info.bodies {
        check_body(info, b)?;
        if bodies.contains_key(&b.name) {
            return Err(invalid(
                Place::Body(b.name.clone(), "name"),
                format!("body '{}' is declared twice", b.name),
            ));
        }
        let chain = compile_chain(info, Some(&b.name), &b.chain)?;
        bodies.insert(
            b.name.clone(),
            Body {
                spec: b.clone(),
                chain,
            },
        );
    }
    Ok(bodies)
}

/// Checks that the solved and driven axes are programmed axes.
fn check_capabilities(info: &MachineInfo) -> Result<(), Invalid> {
    for s in info.solved_axes.iter().chain(&info.driven_axes) {
        if !info.axis(s).is_some_and(Axis::is_programmed) {
            return Err(invalid(
                Place::Chain(None),
                format!("'{s}' is not a programmed axis of the machine"),
            ));
        }
    }
    Ok(())
}

/// Checks the program's start and end settings: a work offset G54 to G59;
/// a radial axis that is a linear axis whose stated motion (radial, 1 mm
/// or 0.5 mm per mm) says the same programming; every axis named a
/// programmed one; a clear position, within travel, for every axis the
/// start or the end takes clear.
fn check_setup(info: &MachineInfo) -> Result<(), Invalid> {
    let s = &info.setup;
    let bad = |m: String| Err(invalid(Place::Setup, m));
    if let Some(w) = s.work_offset {
        if !(1..=6).contains(&w) {
            return bad(format!(
                "setup: work_offset = {w} must be 1 to 6 (G54 to G59)"
            ));
        }
    }
    if let Some(r) = s.radial {
        let name = if s.radial_axis.is_empty() {
            "X"
        } else {
            &s.radial_axis
        };
        let Some(a) = info.axis(name).filter(|a| a.kind == AxisKind::Linear) else {
            return bad(format!(
                "setup: the radial axis {name} is not a linear axis of the machine"
            ));
        };
        let (word, per_mm) = match r {
            Radial::Radius => ("radius", 1.0),
            Radial::Diameter => ("diameter", 0.5),
        };
        if let Some(m) = a.moves {
            if (m[0].abs() - per_mm).abs() > crate::tolerance::SAME_RATIO
                || m[1] != 0.0
                || m[2] != 0.0
            {
                return bad(format!(
                    "setup: radial = \"{word}\" says 1 mm of {name} moves the tool {per_mm} mm from the part's axis, but the axis states moves = [{}, {}, {}]",
                    m[0], m[1], m[2]
                ));
            }
        }
    }
    let named = s
        .start_clear
        .iter()
        .map(|a| (a, true))
        .chain(s.approach.iter().flatten().map(|a| (a, false)))
        .chain(s.retract.iter().flatten().map(|a| (a, true)))
        .chain(s.clear.keys().map(|a| (a, false)))
        .chain(s.feed_group.iter().map(|a| (a, false)));
    for (name, needs_clear) in named {
        let Some(axis) = info.axis(name).filter(|a| a.is_programmed()) else {
            return bad(format!(
                "setup: '{name}' is not a programmed axis of the machine"
            ));
        };
        match s.clear.get(name) {
            None if needs_clear => {
                return bad(format!(
                    "setup: axis {name} is taken clear but has no clear position"
                ))
            }
            Some(&v) => {
                let internal = axis.from_user(v);
                if !(internal >= axis.min && internal <= axis.max) {
                    return bad(format!(
                        "setup: the clear position of {name}, {v}, is outside its travel [{}, {}] {}",
                        axis.to_user(axis.min),
                        axis.to_user(axis.max),
                        axis.unit()
                    ));
                }
            }
            None => {}
        }
    }
    Ok(())
}

fn described(info: &MachineInfo, e: Invalid) -> MachineError {
    MachineError::Description {
        machine: info.name.clone(),
        message: e.message,
    }
}

/// Where a machine's chains put the origin of its body `body` relative to
/// the tool's programmed point, every axis at zero, along the part frame's
/// axis `along` (0: x, 1: y, 2: z); `None` when it has no such body on
/// the part frame.
///
/// A family whose parameter restates a body's place (the steady rest's
/// offset along the part) compares its value with this: the chain is what
/// the verification moves, so it is the one truth.
///
/// # Failures
/// As [`check_description`]; an axis index beyond 2.
pub fn body_offset(
    info: &MachineInfo,
    body: &str,
    along: usize,
) -> Result<Option<Real>, MachineError> {
    if along > 2 {
        return Err(described(
            info,
            invalid(
                Place::Body(body.to_owned(), "chain"),
                format!("no part axis {along}"),
            ),
        ));
    }
    let Some(spec) = info
        .bodies
        .iter()
        .find(|b| b.name == body && b.mount.is_part())
    else {
        return Ok(None);
    };
    let origin = |chain: &Chain| -> Result<Real, MachineError> {
        let p = chain.apply(&vec![0.0; chain.dof()], &Point3::origin())?;
        Ok(p[along])
    };
    let at =
        origin(&compile_chain(info, Some(body), &spec.chain).map_err(|e| described(info, e))?)?;
    let tool = if info.chain.is_empty() {
        0.0
    } else {
        origin(&compile_chain(info, None, &info.chain).map_err(|e| described(info, e))?)?
    };
    Ok(Some(at - tool))
}

/// The other moving bodies of a machine, their chains compiled from its
/// description.
///
/// # Failures
/// As [`check_description`].
pub fn bodies_of(info: &MachineInfo) -> Result<Vec<Body>, MachineError> {
    compile_bodies(info)
        .map(|b| b.into_values().collect())
        .map_err(|e| described(info, e))
}

/// Checks a machine's description as far as it goes: its axes, the axes it
/// solves and takes from the toolpath, its bodies; and, when it states its
/// tool's chain, the axes' signs against the chains ([`Machine::from_info`]).
///
/// # Failures
/// [`MachineError::Description`] naming the axis, factor or body.
pub fn check_description(info: &MachineInfo) -> Result<(), MachineError> {
    if !info.chain.is_empty() {
        return Machine::from_info(info.clone()).map(|_| ());
    }
    check_texts(info)
        .and_then(|_| check_axes(info))
        .and_then(|_| check_capabilities(info))
        .and_then(|_| check_setup(info))
        .and_then(|_| compile_bodies(info).map(|_| ()))
        .map_err(|e| described(info, e))
}

impl Machine {
    /// Checks and compiles a description; the one path of machine files and
    /// plugin descriptors.
    pub(super) fn compile(info: MachineInfo) -> Result<Machine, Invalid> {
        check_texts(&info)?;
        let tool = check_axes(&info)?;
        let chain = compile_chain(&info, None, &info.chain)?;
        let bodies = compile_bodies(&info)?;
        check_capabilities(&info)?;
        check_setup(&info)?;
        let machine = Machine {
            info,
            chain,
            tool,
            bodies,
        };
        for (i, a) in machine.info.axes.iter().enumerate() {
            sign_error(&machine, a).map_err(|(key, m)| invalid(Place::Axis(i, key), m))?;
            part_turn_error(&machine, a).map_err(|m| invalid(Place::Axis(i, "turns_part"), m))?;
        }
        Ok(machine)
    }

    /// A machine from its description: a plugin's descriptor, or one built
    /// in code. Checked as a machine file is: axis names, travel, feeds, the
    /// stated signs against the chains, bodies and their shapes.
    ///
    /// # Failures
    /// [`MachineError::Description`] naming the axis, factor or body.
    pub fn from_info(info: MachineInfo) -> Result<Machine, MachineError> {
        let name = info.name.clone();
        Self::compile(info).map_err(|e| MachineError::Description {
            machine: name,
            message: e.message,
        })
    }
}
