//! Reading machines from TOML, with errors naming the key and its line.

use super::info::{Invalid, Place};
use super::ToolSpec;
use super::{Axis, AxisKind, BodyShape, BodySpec, FactorSpec, Machine, MachineError, MachineInfo};
use crate::math::Real;
use pilgrim_plugin_abi::types::{FactorKind, ProgramSetup};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::Path;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MachineFile {
    name: Spanned<String>,
    description: Option<Spanned<String>>,
    control: Option<String>,
    tool: Option<ToolFile>,
    axes: Vec<AxisFile>,
    chain: Spanned<Vec<FactorFile>>,
    #[serde(default)]
    bodies: BTreeMap<String, BodyFile>,
    #[serde(default)]
    constants: BTreeMap<String, Spanned<Real>>,
    program_decimals: Option<Spanned<i64>>,
    #[serde(default)]
    driven_axes: Vec<String>,
    min_feed: Option<Spanned<Real>>,
    setup: Option<Spanned<ProgramSetup>>,
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
    max_accel: Option<Spanned<Real>>,
    max_accel_deg: Option<Spanned<Real>>,
    #[serde(default = "yes")]
    programmed: bool,
    #[serde(default)]
    description: String,
    moves: Option<Spanned<[Real; 3]>>,
    turns: Option<Spanned<[Real; 3]>>,
    body: Option<Spanned<String>>,
    turns_part: Option<Spanned<bool>>,
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
    constant: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BodyFile {
    #[serde(default)]
    description: String,
    #[serde(default)]
    label: String,
    chain: Spanned<Vec<FactorFile>>,
    shape: Option<Spanned<BodyShape>>,
    approach_feed: Option<Spanned<crate::machine::Quantity>>,
    mount: Option<Spanned<crate::machine::Mount>>,
    reach: Option<Spanned<pilgrim_plugin_abi::types::Reach>>,
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
        let text = crate::files::read_text(path, crate::files::MAX_TEXT_BYTES).map_err(|e| {
            MachineError::Io {
                file: e.file,
                message: e.message,
            }
        })?;
        Self::from_toml_str(&text, &path.display().to_string())
    }

    /// Reads a machine from TOML text; `source` names it in errors.
    ///
    /// The format (`pilgrim machines --toml NAME` writes any machine pilgrim
    /// knows as a full example):
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
    /// a `label` (how reports name the point the body's origin tracks) and a
    /// `shape` in the body's own frame, each size a number (mm) or a
    /// constant's name: `{ kind = "roller", radius = "rest_radius", length =
    /// 40.0 }` (a cylinder along Y, a steady rest's), `{ kind = "cylinder",
    /// radius, length }` (along Z: a chuck, a quill, an arbor), `{ kind =
    /// "box", size = [x, y, z] }` (a wheelhead, a turret, a holder), `{ kind
    /// = "guard", inner, outer, width, cover_deg }` (a tube round Z over
    /// `cover_deg` centred on +X, open toward -X: a wheel's guard); each is
    /// centred on the body's origin ([`crate::machine::Solid`]). An axis that
    /// moves a body says so (`body = "rest"`). `[constants]` holds named machine
    /// constants (mm; a `_deg` key is stored in radians without the suffix);
    /// a constant factor may take one (`constant = "rest_offset_b"`).
    /// An axis that turns the part on the machine says so (`turns_part =
    /// true`): a spindle carrying the part, or a rotary axis whose Rz leads
    /// the chain (a roll's turn); the page's player turns the part by it.
    /// `driven_axes` lists programmed axes the machine takes from the
    /// toolpath rather than solving; `min_feed` is the least feed of a
    /// cutting move (mm/min). Every linear axis states `moves` and
    /// every rotary axis `turns` (the axis the tool turns about, relative to
    /// the part); both are checked against the chain when the file is read.
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
            src.err(span, crate::files::excerpt(e.message().trim()))
        })?;
        let axes = file
            .axes
            .iter()
            .map(|a| read_axis(&src, a))
            .collect::<Result<Vec<_>, _>>()?;
        let chain = read_chain(&src, file.chain.get_ref())?;
        let mut bodies = Vec::new();
        for (name, body) in &file.bodies {
            bodies.push(BodySpec {
                name: name.clone(),
                description: body.description.clone(),
                label: body.label.clone(),
                chain: read_chain(&src, body.chain.get_ref())?,
                shape: body.shape.as_ref().map(|s| s.get_ref().clone()),
                approach_feed: body.approach_feed.as_ref().map(|s| s.get_ref().clone()),
                mount: body
                    .mount
                    .as_ref()
                    .map(|m| *m.get_ref())
                    .unwrap_or_default(),
                reach: body
                    .reach
                    .as_ref()
                    .map(|r| *r.get_ref())
                    .unwrap_or_default(),
            });
        }
        let tool = match &file.tool {
            None => ToolSpec::default(),
            Some(t) => ToolSpec {
                point: *t.point.get_ref(),
                axis: *t.axis.get_ref(),
            },
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
            Some(d) => match usize::try_from(*d.get_ref()) {
                Ok(n) => Some(n),
                Err(_) => {
                    return Err(src.err(
                        d.span(),
                        format!("program_decimals = {} must be 0 to 6", d.get_ref()),
                    ))
                }
            },
        };
        // The tool chain's axes, in the machine's order, are what inverse
        // kinematics solves.
        let solved_axes = axes
            .iter()
            .filter(|a| chain.iter().any(|f| f.axis.as_deref() == Some(&a.name)))
            .map(|a| a.name.clone())
            .collect();
        let info = MachineInfo {
            name: file.name.get_ref().clone(),
            description: file
                .description
                .as_ref()
                .map(|d| d.get_ref().clone())
                .unwrap_or_default(),
            control: file.control.clone().unwrap_or_else(|| "sinumerik".into()),
            axes,
            solved_axes,
            constants,
            program_decimals,
            driven_axes: file.driven_axes.clone(),
            bodies,
            chain,
            tool,
            min_feed: match &file.min_feed {
                Some(f) => Some(src.finite("min_feed", f)?),
                None => None,
            },
            setup: file
                .setup
                .as_ref()
                .map(|s| s.get_ref().clone())
                .unwrap_or_default(),
        };
        Machine::compile(info).map_err(|e| src.err(span_of(&file, &e), e.message))
    }
}

/// The span in the file of an invalid value's place.
fn span_of(file: &MachineFile, e: &Invalid) -> Range<usize> {
    let key = |v: Option<&Range<usize>>, fallback: Range<usize>| v.cloned().unwrap_or(fallback);
    match &e.place {
        Place::Axis(i, k) => {
            let Some(a) = file.axes.get(*i) else {
                return 0..0;
            };
            let name = a.name.span();
            let span = |v: &Option<Spanned<Real>>| v.as_ref().map(Spanned::span);
            match *k {
                "max" => key(
                    span(&a.max)
                        .or(span(&a.max_deg))
                        .or(span(&a.max_rpm))
                        .as_ref(),
                    name,
                ),
                "max_accel" => key(span(&a.max_accel).or(span(&a.max_accel_deg)).as_ref(), name),
                "moves" => key(a.moves.as_ref().map(Spanned::span).as_ref(), name),
                "turns" => key(a.turns.as_ref().map(Spanned::span).as_ref(), name),
                "body" => key(a.body.as_ref().map(Spanned::span).as_ref(), name),
                "turns_part" => key(a.turns_part.as_ref().map(Spanned::span).as_ref(), name),
                _ => name,
            }
        }
        Place::Chain(None) => file.chain.span(),
        Place::Chain(Some(b)) => file.bodies.get(b).map_or(0..0, |body| body.chain.span()),
        // A body's shape or approach feed where the file gives it, else
        // its chain.
        Place::Body(b, k) => file.bodies.get(b).map_or(0..0, |body| {
            let at = match *k {
                "shape" => body.shape.as_ref().map(Spanned::span),
                "approach_feed" => body.approach_feed.as_ref().map(Spanned::span),
                "mount" => body.mount.as_ref().map(Spanned::span),
                "reach" => body.reach.as_ref().map(Spanned::span),
                _ => None,
            };
            at.unwrap_or_else(|| body.chain.span())
        }),
        Place::Factor(owner, i, k) => {
            let chain = match owner {
                None => Some(file.chain.get_ref()),
                Some(b) => file.bodies.get(b).map(|body| body.chain.get_ref()),
            };
            let Some(f) = chain.and_then(|c| c.get(*i)) else {
                return 0..0;
            };
            let at = f.factor.span();
            match *k {
                "axis" => key(f.axis.as_ref().map(Spanned::span).as_ref(), at),
                "scale" => key(
                    f.scale.as_ref().map(Spanned::span).as_ref(),
                    f.axis.as_ref().map_or(at, Spanned::span),
                ),
                "constant" => key(f.constant.as_ref().map(Spanned::span).as_ref(), at),
                _ => at,
            }
        }
        Place::Name => file.name.span(),
        Place::Description => file
            .description
            .as_ref()
            .map_or_else(|| file.name.span(), Spanned::span),
        Place::Tool => file.tool.as_ref().map_or(0..0, |t| t.point.span()),
        Place::Decimals => file.program_decimals.as_ref().map_or(0..0, Spanned::span),
        Place::Setup => file.setup.as_ref().map_or(0..0, Spanned::span),
    }
}

fn read_axis(src: &Source<'_>, a: &AxisFile) -> Result<Axis, MachineError> {
    let kind = *a.kind.get_ref();
    let name = a.name.get_ref().clone();
    let need = |v: &Option<Spanned<Real>>, key: &str| -> Result<Real, MachineError> {
        match v {
            Some(s) => src.finite(&format!("axis {name}: {key}"), s),
            None => Err(src.err(
                a.name.span(),
                format!("axis {name} ({}) needs key '{key}'", kind.word()),
            )),
        }
    };
    let forbid = |v: &Option<Spanned<Real>>, key: &str| -> Result<(), MachineError> {
        match v {
            Some(s) => Err(src.err(
                s.span(),
                format!(
                    "axis {name}: key '{key}' does not apply to a {} axis",
                    kind.word()
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
                (&a.max_accel_deg, "max_accel_deg"),
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
                (&a.max_accel, "max_accel"),
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
                (&a.max_accel, "max_accel"),
                (&a.max_accel_deg, "max_accel_deg"),
            ] {
                forbid(v, k)?;
            }
            let rpm = need(&a.max_rpm, "max_rpm")?;
            (0.0, rpm, rpm)
        }
    };
    Ok(Axis {
        moves: a.moves.as_ref().map(|s| *s.get_ref()),
        turns: a.turns.as_ref().map(|s| *s.get_ref()),
        name,
        kind,
        min,
        max,
        max_feed: feed,
        programmed: a.programmed && kind != AxisKind::Spindle,
        description: a.description.clone(),
        body: a.body.as_ref().map(|b| b.get_ref().clone()),
        max_accel: match (&a.max_accel, &a.max_accel_deg) {
            (Some(v), _) => Some(src.finite("max_accel", v)?),
            (None, Some(v)) => Some(src.finite("max_accel_deg", v)?.to_radians()),
            (None, None) => None,
        },
        turns_part: a.turns_part.as_ref().is_some_and(|t| *t.get_ref()),
    })
}

/// A constant factor has no scale or offset.
fn no_scale_or_offset(
    src: &Source<'_>,
    f: &FactorFile,
    offset_key: &Option<Spanned<Real>>,
) -> Result<(), MachineError> {
    match f.scale.as_ref().or(offset_key.as_ref()) {
        Some(s) => Err(src.err(
            s.span(),
            "scale and offset apply only to a factor bound to an axis",
        )),
        None => Ok(()),
    }
}

/// The factors of a chain as written, units converted (degrees to
/// radians); whether the axes they name exist and fit is the description's
/// check.
fn read_chain(src: &Source<'_>, factors: &[FactorFile]) -> Result<Vec<FactorSpec>, MachineError> {
    let mut out = Vec::with_capacity(factors.len());
    for f in factors {
        let kind = *f.factor.get_ref();
        let rot = matches!(kind, FactorKind::Rx | FactorKind::Ry | FactorKind::Rz);
        let (good, bad) = if rot { ("_deg", "") } else { ("", "_deg") };
        let value_key = if rot { &f.value_deg } else { &f.value };
        let offset_key = if rot { &f.offset_deg } else { &f.offset };
        let wrong_value = if rot { &f.value } else { &f.value_deg };
        let wrong_offset = if rot { &f.offset } else { &f.offset_deg };
        let word = format!("{kind:?}").to_lowercase();
        if let Some(s) = wrong_value.as_ref().or(wrong_offset.as_ref()) {
            return Err(src.err(
                s.span(),
                format!("factor {word}: use value{good}/offset{good}, not value{bad}/offset{bad}"),
            ));
        }
        let conv = |v: Real| if rot { v.to_radians() } else { v };
        let spec = match (&f.axis, value_key, &f.constant) {
            (Some(name), None, _) => FactorSpec {
                scale: match &f.scale {
                    Some(s) => src.finite("scale", s)?,
                    None => 1.0,
                },
                offset: match offset_key {
                    Some(s) => conv(src.finite("offset", s)?),
                    None => 0.0,
                },
                constant: f.constant.as_ref().map(|c| c.get_ref().clone()),
                ..FactorSpec::axis(kind, name.get_ref())
            },
            (None, Some(v), None) => {
                no_scale_or_offset(src, f, offset_key)?;
                FactorSpec::value(kind, conv(src.finite("value", v)?))
            }
            (None, None, Some(c)) => {
                // A constant may be scaled (half a length: a body centred
                // on its face), not offset.
                if let Some(s) = offset_key {
                    return Err(
                        src.err(s.span(), "offset applies only to a factor bound to an axis")
                    );
                }
                FactorSpec {
                    scale: match &f.scale {
                        Some(s) => src.finite("scale", s)?,
                        None => 1.0,
                    },
                    ..FactorSpec::constant(kind, c.get_ref())
                }
            }
            (Some(name), Some(_), _) => {
                return Err(src.err(
                    name.span(),
                    "a factor has either an axis or a constant value, not both",
                ))
            }
            (None, Some(v), Some(_)) => {
                return Err(src.err(
                    v.span(),
                    "a factor has either a value or a constant, not both",
                ))
            }
            (None, None, _) => {
                return Err(src.err(
                    f.factor.span(),
                    format!(
                        "factor needs an 'axis', a constant 'value{good}' or a machine 'constant'"
                    ),
                ))
            }
        };
        out.push(spec);
    }
    Ok(out)
}
