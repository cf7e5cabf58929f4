//! Reading machines from TOML, with errors naming the key and its line.

use super::{Axis, AxisKind, Machine, MachineError};
use crate::math::{Real, Vec3};
use crate::transform::{Chain, FactorKind, ToolFrame};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::Path;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MachineFile {
    name: Spanned<String>,
    #[serde(default)]
    description: String,
    control: Option<String>,
    tool: Option<ToolFile>,
    axes: Vec<AxisFile>,
    chain: Spanned<Vec<FactorFile>>,
    #[serde(default)]
    bodies: BTreeMap<String, BodyFile>,
    #[serde(default)]
    constants: BTreeMap<String, Spanned<Real>>,
    program_decimals: Option<Spanned<i64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ToolFile {
    point: Spanned<[Real; 3]>,
    axis: Spanned<[Real; 3]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AxisFile {
    name: Spanned<String>,
    kind: Spanned<AxisKind>,
    min: Option<Spanned<Real>>,
    max: Option<Spanned<Real>>,
    max_feed: Option<Spanned<Real>>,
    min_deg: Option<Spanned<Real>>,
    max_deg: Option<Spanned<Real>>,
    max_feed_deg: Option<Spanned<Real>>,
    max_rpm: Option<Spanned<Real>>,
    #[serde(default = "yes")]
    programmed: bool,
    #[serde(default)]
    description: String,
    moves: Option<Spanned<[Real; 3]>>,
    turns: Option<Spanned<[Real; 3]>>,
    body: Option<Spanned<String>>,
}

fn yes() -> bool {
    true
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FactorFile {
    factor: Spanned<FactorKind>,
    axis: Option<Spanned<String>>,
    scale: Option<Spanned<Real>>,
    offset: Option<Spanned<Real>>,
    offset_deg: Option<Spanned<Real>>,
    value: Option<Spanned<Real>>,
    value_deg: Option<Spanned<Real>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BodyFile {
    #[serde(default)]
    #[allow(dead_code)]
    description: String,
    chain: Spanned<Vec<FactorFile>>,
}

/// Turns byte spans into `file:line:column` errors.
struct Source<'a> {
    name: &'a str,
    text: &'a str,
}

impl Source<'_> {
    fn err(&self, span: Range<usize>, message: impl Into<String>) -> MachineError {
        let mut start = span.start.min(self.text.len());
        while !self.text.is_char_boundary(start) {
            start -= 1;
        }
        let before = &self.text[..start];
        let line = before.matches('\n').count() + 1;
        let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
        MachineError::File {
            file: self.name.to_owned(),
            line,
            column,
            message: message.into(),
        }
    }

    fn finite(&self, key: &str, v: &Spanned<Real>) -> Result<Real, MachineError> {
        let x = *v.get_ref();
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.err(v.span(), format!("{key} = {x} is not a finite number")))
        }
    }
}

impl Machine {
    /// Reads a machine from a TOML file.
    ///
    /// # Failures
    /// An unreadable file, or any error of [`Machine::from_toml_str`].
    pub fn from_file(path: impl AsRef<Path>) -> Result<Machine, MachineError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| MachineError::Io {
            file: path.display().to_string(),
            message: e.to_string(),
        })?;
        Self::from_toml_str(&text, &path.display().to_string())
    }

    /// Reads a machine from TOML text; `source` names it in errors.
    ///
    /// The format (the built-ins in `kernel/machines/` are full examples):
    ///
    /// ```toml
    /// name = "lathe"
    /// description = "two-axis lathe"
    /// control = "fanuc"
    ///
    /// [[axes]]
    /// name = "X"
    /// kind = "linear"          # linear | rotary | spindle
    /// min = 0.0                # mm (rotary: min_deg, max_deg, max_feed_deg)
    /// max = 400.0
    /// max_feed = 8000.0        # mm/min (spindle: max_rpm)
    /// moves = [0.5, 0.0, 0.0]  # tool displacement in the part frame per mm of X
    /// description = "cross slide, diameter"
    ///
    /// [[axes]]
    /// name = "Z"
    /// kind = "linear"
    /// min = -600.0
    /// max = 10.0
    /// max_feed = 10000.0
    /// moves = [0.0, 0.0, 1.0]
    ///
    /// [[chain]]                # left to right in r_part = A r_tool
    /// factor = "tz"            # tx ty tz rx ry rz
    /// axis = "Z"
    ///
    /// [[chain]]
    /// factor = "tx"
    /// axis = "X"
    /// scale = 0.5              # and offset (mm) / offset_deg; constants: value / value_deg
    /// ```
    ///
    /// Other moving bodies have their own chains (`[[bodies.rest.chain]]`),
    /// and an axis that moves one says so (`body = "rest"`). `[constants]`
    /// holds named machine constants (mm; a `_deg` key is stored in radians
    /// without the suffix). Every linear axis states `moves` and every rotary
    /// axis `turns` (the axis the tool turns about, relative to the part);
    /// both are checked against the chain when the file is read.
    ///
    /// # Failures
    /// [`MachineError::File`] naming the line, column and key: TOML syntax;
    /// an unknown or missing key; a travel, feed or constant that is not a
    /// finite number or in the wrong order; a chain naming an unknown axis or
    /// a spindle, or binding an axis of the other kind; a stated sign that
    /// the chain contradicts.
    pub fn from_toml_str(text: &str, source: &str) -> Result<Machine, MachineError> {
        let src = Source { name: source, text };
        let file: MachineFile = toml::from_str(text).map_err(|e| {
            let span = e.span().unwrap_or(0..0);
            src.err(span, e.message().trim().to_owned())
        })?;
        let axes = file
            .axes
            .iter()
            .map(|a| read_axis(&src, a))
            .collect::<Result<Vec<_>, _>>()?;
        for (i, a) in file.axes.iter().enumerate() {
            if axes[..i].iter().any(|b| b.name == axes[i].name) {
                return Err(src.err(
                    a.name.span(),
                    format!("axis '{}' is declared twice", axes[i].name),
                ));
            }
        }
        if file.chain.get_ref().is_empty() {
            return Err(src.err(file.chain.span(), "the tool chain has no factors"));
        }
        let chain = read_chain(&src, &axes, file.chain.get_ref())?;
        let mut bodies = BTreeMap::new();
        for (name, body) in &file.bodies {
            bodies.insert(name.clone(), read_chain(&src, &axes, body.chain.get_ref())?);
        }
        let tool = match &file.tool {
            None => ToolFrame::default(),
            Some(t) => {
                let p = t.point.get_ref();
                let a = t.axis.get_ref();
                if p.iter().chain(a).any(|v| !v.is_finite()) {
                    return Err(src.err(t.point.span(), "tool point and axis must be finite"));
                }
                let axis = Vec3::from(*a);
                if axis.norm() == 0.0 {
                    return Err(src.err(t.axis.span(), "tool axis must not be zero"));
                }
                ToolFrame {
                    point: (*p).into(),
                    axis: axis.normalize(),
                }
            }
        };
        let mut constants = BTreeMap::new();
        for (k, v) in &file.constants {
            let x = src.finite(&format!("constants.{k}"), v)?;
            match k.strip_suffix("_deg") {
                Some(base) => constants.insert(base.to_owned(), x.to_radians()),
                None => constants.insert(k.clone(), x),
            };
        }
        let program_decimals = match &file.program_decimals {
            None => None,
            Some(d) if (0..=6).contains(d.get_ref()) => Some(*d.get_ref() as usize),
            Some(d) => {
                return Err(src.err(
                    d.span(),
                    format!("program_decimals = {} must be 0 to 6", d.get_ref()),
                ))
            }
        };
        let machine = Machine {
            program_decimals,
            name: file.name.get_ref().clone(),
            description: file.description,
            control: file.control,
            axes,
            chain,
            tool,
            bodies,
            constants,
        };
        for (a, af) in machine.axes.iter().zip(&file.axes) {
            check_sign(&src, &machine, a, af)?;
        }
        Ok(machine)
    }
}

fn read_axis(src: &Source<'_>, a: &AxisFile) -> Result<Axis, MachineError> {
    let kind = *a.kind.get_ref();
    let name = a.name.get_ref().clone();
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err(src.err(
            a.name.span(),
            format!("axis name '{name}' must be letters, digits or _"),
        ));
    }
    let need = |v: &Option<Spanned<Real>>, key: &str| -> Result<Real, MachineError> {
        match v {
            Some(s) => src.finite(&format!("axis {name}: {key}"), s),
            None => Err(src.err(
                a.name.span(),
                format!("axis {name} ({}) needs key '{key}'", kind_word(kind)),
            )),
        }
    };
    let forbid = |v: &Option<Spanned<Real>>, key: &str| -> Result<(), MachineError> {
        match v {
            Some(s) => Err(src.err(
                s.span(),
                format!(
                    "axis {name}: key '{key}' does not apply to a {} axis",
                    kind_word(kind)
                ),
            )),
            None => Ok(()),
        }
    };
    let (min, max, feed) = match kind {
        AxisKind::Linear => {
            for (v, k) in [
                (&a.min_deg, "min_deg"),
                (&a.max_deg, "max_deg"),
                (&a.max_feed_deg, "max_feed_deg"),
                (&a.max_rpm, "max_rpm"),
            ] {
                forbid(v, k)?;
            }
            (
                need(&a.min, "min")?,
                need(&a.max, "max")?,
                need(&a.max_feed, "max_feed")?,
            )
        }
        AxisKind::Rotary => {
            for (v, k) in [
                (&a.min, "min"),
                (&a.max, "max"),
                (&a.max_feed, "max_feed"),
                (&a.max_rpm, "max_rpm"),
            ] {
                forbid(v, k)?;
            }
            (
                need(&a.min_deg, "min_deg")?.to_radians(),
                need(&a.max_deg, "max_deg")?.to_radians(),
                need(&a.max_feed_deg, "max_feed_deg")?.to_radians(),
            )
        }
        AxisKind::Spindle => {
            for (v, k) in [
                (&a.min, "min"),
                (&a.max, "max"),
                (&a.max_feed, "max_feed"),
                (&a.min_deg, "min_deg"),
                (&a.max_deg, "max_deg"),
                (&a.max_feed_deg, "max_feed_deg"),
            ] {
                forbid(v, k)?;
            }
            let rpm = need(&a.max_rpm, "max_rpm")?;
            (0.0, rpm, rpm)
        }
    };
    let span_of_max = a
        .max
        .as_ref()
        .or(a.max_deg.as_ref())
        .or(a.max_rpm.as_ref())
        .map_or(a.name.span(), |s| s.span());
    if min >= max {
        return Err(src.err(
            span_of_max,
            format!("axis {name}: travel max must exceed min"),
        ));
    }
    if feed <= 0.0 {
        return Err(src.err(
            a.name.span(),
            format!("axis {name}: the maximum feed must be > 0"),
        ));
    }
    let vec3 = |v: &Option<Spanned<[Real; 3]>>,
                key: &str,
                wanted: bool|
     -> Result<Option<Vec3>, MachineError> {
        match (v, wanted) {
            (Some(s), true) => {
                let x = Vec3::from(*s.get_ref());
                if !x.iter().all(|c| c.is_finite()) || x.norm() == 0.0 {
                    return Err(src.err(s.span(), format!("axis {name}: {key} must be a finite, non-zero vector")));
                }
                Ok(Some(x))
            }
            (Some(s), false) => Err(src.err(s.span(), format!("axis {name}: key '{key}' does not apply to a {} axis", kind_word(kind)))),
            (None, true) => Err(src.err(
                a.name.span(),
                format!("axis {name}: state its sign with '{key}' (the tool's motion in the part frame for a positive move)"),
            )),
            (None, false) => Ok(None),
        }
    };
    Ok(Axis {
        moves: vec3(&a.moves, "moves", kind == AxisKind::Linear)?,
        turns: vec3(&a.turns, "turns", kind == AxisKind::Rotary)?,
        name,
        kind,
        min,
        max,
        max_feed: feed,
        programmed: a.programmed && kind != AxisKind::Spindle,
        description: a.description.clone(),
        body: a.body.as_ref().map(|b| b.get_ref().clone()),
    })
}

fn kind_word(k: AxisKind) -> &'static str {
    match k {
        AxisKind::Linear => "linear",
        AxisKind::Rotary => "rotary",
        AxisKind::Spindle => "spindle",
    }
}

fn read_chain(
    src: &Source<'_>,
    axes: &[Axis],
    factors: &[FactorFile],
) -> Result<Chain, MachineError> {
    let mut b = Chain::builder();
    // Axes take the machine's order.
    for a in axes {
        if factors
            .iter()
            .any(|f| f.axis.as_ref().is_some_and(|n| n.get_ref() == &a.name))
        {
            b = b.declare(&a.name);
        }
    }
    for f in factors {
        let kind = *f.factor.get_ref();
        let rot = kind.is_rotation();
        let (good, bad) = if rot { ("_deg", "") } else { ("", "_deg") };
        let value_key = if rot { &f.value_deg } else { &f.value };
        let offset_key = if rot { &f.offset_deg } else { &f.offset };
        let wrong_value = if rot { &f.value } else { &f.value_deg };
        let wrong_offset = if rot { &f.offset } else { &f.offset_deg };
        if let Some(s) = wrong_value.as_ref().or(wrong_offset.as_ref()) {
            return Err(src.err(
                s.span(),
                format!(
                    "factor {kind:?}: use value{good}/offset{good}, not value{bad}/offset{bad}"
                )
                .to_lowercase(),
            ));
        }
        let conv = |v: Real| if rot { v.to_radians() } else { v };
        match (&f.axis, value_key) {
            (Some(name), None) => {
                let axis = axes
                    .iter()
                    .find(|a| &a.name == name.get_ref())
                    .ok_or_else(|| {
                        src.err(
                            name.span(),
                            format!(
                                "chain names axis '{}', which is not declared (axes: {})",
                                name.get_ref(),
                                axes.iter()
                                    .map(|a| a.name.as_str())
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            ),
                        )
                    })?;
                let expected = if rot {
                    AxisKind::Rotary
                } else {
                    AxisKind::Linear
                };
                if axis.kind != expected {
                    return Err(src.err(
                        name.span(),
                        format!(
                            "axis {} is {} but factor {} needs a {} axis",
                            axis.name,
                            kind_word(axis.kind),
                            format!("{kind:?}").to_lowercase(),
                            kind_word(expected)
                        ),
                    ));
                }
                let scale = match &f.scale {
                    Some(s) => src.finite("scale", s)?,
                    None => 1.0,
                };
                if scale == 0.0 {
                    return Err(src.err(
                        f.scale.as_ref().map_or(name.span(), |s| s.span()),
                        "scale must not be 0",
                    ));
                }
                let offset = match offset_key {
                    Some(s) => conv(src.finite("offset", s)?),
                    None => 0.0,
                };
                b = b.axis_scaled(kind, &axis.name, scale, offset);
            }
            (None, Some(v)) => {
                if let Some(s) = f.scale.as_ref().or(offset_key.as_ref()) {
                    return Err(src.err(
                        s.span(),
                        "scale and offset apply only to a factor bound to an axis",
                    ));
                }
                b = b.constant(kind, conv(src.finite("value", v)?));
            }
            (Some(name), Some(_)) => {
                return Err(src.err(
                    name.span(),
                    "a factor has either an axis or a constant value, not both",
                ))
            }
            (None, None) => {
                return Err(src.err(
                    f.factor.span(),
                    format!("factor needs an 'axis' or a constant 'value{good}'"),
                ))
            }
        }
    }
    b.build().map_err(|e| src.err(0..0, e.to_string()))
}

/// Checks an axis's stated `moves`/`turns` against the chain that moves it.
fn check_sign(src: &Source<'_>, m: &Machine, a: &Axis, af: &AxisFile) -> Result<(), MachineError> {
    if a.kind == AxisKind::Spindle {
        let used = std::iter::once(&m.chain)
            .chain(m.bodies.values())
            .any(|c| c.axis_index(&a.name).is_some());
        if used {
            return Err(src.err(
                af.name.span(),
                format!("spindle {} cannot be bound in a chain", a.name),
            ));
        }
        return Ok(());
    }
    let (chain, origin) = match &a.body {
        None => (&m.chain, m.tool.point),
        Some(b) => match m.bodies.get(b) {
            Some(c) => (c, crate::math::Point3::origin()),
            None => {
                let span = af.body.as_ref().map_or(af.name.span(), |s| s.span());
                return Err(src.err(
                    span,
                    format!(
                        "axis {}: no body '{b}' (declare [[bodies.{b}.chain]])",
                        a.name
                    ),
                ));
            }
        },
    };
    let Some(i) = chain.axis_index(&a.name) else {
        let whose = a.body.as_deref().unwrap_or("tool");
        return Err(src.err(
            af.name.span(),
            format!("axis {} is not bound in the {whose} chain", a.name),
        ));
    };
    let travel = m.travel_of(chain)?;
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
            let stated = a.moves.unwrap_or_default();
            if (d - stated).norm() > 1e-9 {
                let span = af.moves.as_ref().map_or(af.name.span(), |s| s.span());
                return Err(src.err(
                    span,
                    format!("axis {}: moves = [{}, {}, {}] but the chain moves it by [{:.6}, {:.6}, {:.6}]", a.name, stated.x, stated.y, stated.z, d.x, d.y, d.z),
                ));
            }
        }
        _ => {
            let h = 1e-6;
            q1[i] += h;
            let r = chain.frame_unchecked(&q1).rot * f0.rot.transpose();
            let w = Vec3::new(
                r[(2, 1)] - r[(1, 2)],
                r[(0, 2)] - r[(2, 0)],
                r[(1, 0)] - r[(0, 1)],
            ) / (2.0 * h);
            let stated = a.turns.unwrap_or_default().normalize();
            if (w - stated).norm() > 1e-5 {
                let span = af.turns.as_ref().map_or(af.name.span(), |s| s.span());
                return Err(src.err(
                    span,
                    format!("axis {}: turns = [{}, {}, {}] but the chain turns it about [{:.4}, {:.4}, {:.4}]", a.name, stated.x, stated.y, stated.z, w.x, w.y, w.z),
                ));
            }
        }
    }
    Ok(())
}
