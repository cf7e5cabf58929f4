//! A part family's parameters: their specs (name, default, unit, doc, the
//! machine constant a default may come from) and the resolution of values
//! from the defaults, a machine's constants and the sources a caller gives
//! (a TOML file's table, `NAME=VALUE` pairs), each labelled by the caller
//! (`--set`, a file's name) for messages. Nothing here knows how a family
//! is written.

use crate::math::Real;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A parameter's value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ParamValue {
    /// A whole number.
    Int(i64),
    /// A number.
    Float(f64),
    /// Yes or no.
    Bool(bool),
    /// Text.
    Text(String),
    /// A list of numbers.
    List(Vec<f64>),
}

/// Parameter values by name.
pub type Params = BTreeMap<String, ParamValue>;

impl ParamValue {
    /// What kind of value it is, in words (`a whole number`, ...).
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Int(_) => "a whole number",
            Self::Float(_) => "a number",
            Self::Bool(_) => "true or false",
            Self::Text(_) => "text",
            Self::List(_) => "a list of numbers",
        }
    }

    /// The number, if the value is one (whole or not).
    pub fn as_number(&self) -> Option<Real> {
        match self {
            Self::Int(i) => Some(*i as Real),
            Self::Float(f) => Some(*f),
            _ => None,
        }
    }

    /// The value of a machine constant, of the same kind as `like`: a
    /// number as it is, a whole number if it is one, true/false as not 0/0.
    ///
    /// # Failures
    /// A kind a constant cannot give (text, a list), or a fractional value
    /// for a whole number.
    pub fn from_constant(x: Real, like: &ParamValue) -> Result<Self, NotOfKind> {
        match like {
            Self::Float(_) => Ok(Self::Float(x)),
            Self::Int(_) if x.fract() == 0.0 && x.abs() < 9e15 => Ok(Self::Int(x as i64)),
            Self::Bool(_) => Ok(Self::Bool(x != 0.0)),
            _ => Err(NotOfKind {
                value: x,
                kind: like.kind(),
            }),
        }
    }

    /// The value of a TOML value, of the same kind as `like`.
    fn from_toml(v: &toml::Value, like: &ParamValue) -> Result<Self, String> {
        let got = || {
            format!(
                "expected {}, got {}",
                like.kind(),
                crate::files::excerpt(&v.to_string())
            )
        };
        Ok(match (like, v) {
            (Self::Int(_), toml::Value::Integer(i)) => Self::Int(*i),
            (Self::Float(_), toml::Value::Float(f)) => Self::Float(*f),
            (Self::Float(_), toml::Value::Integer(i)) => Self::Float(*i as f64),
            (Self::Bool(_), toml::Value::Boolean(b)) => Self::Bool(*b),
            (Self::Text(_), toml::Value::String(s)) => Self::Text(s.clone()),
            (Self::List(_), toml::Value::Array(a)) => Self::List(
                a.iter()
                    .map(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)))
                    .collect::<Option<Vec<_>>>()
                    .ok_or_else(got)?,
            ),
            _ => return Err(got()),
        })
    }

    /// The value of a `NAME=VALUE` text, of the same kind as `like`.
    fn parse(text: &str, like: &ParamValue) -> Result<Self, String> {
        let t = text.trim();
        let bad = || format!("'{}' is not {}", crate::files::excerpt(text), like.kind());
        Ok(match like {
            Self::Int(_) => Self::Int(t.parse().map_err(|_| bad())?),
            Self::Float(_) => Self::Float(t.parse().map_err(|_| bad())?),
            Self::Bool(_) => Self::Bool(t.parse().map_err(|_| bad())?),
            Self::Text(_) => Self::Text(text.to_owned()),
            Self::List(_) => Self::List(
                t.trim_matches(|c| c == '[' || c == ']')
                    .split(',')
                    .filter(|s| !s.trim().is_empty())
                    .map(|s| s.trim().parse::<f64>().map_err(|_| bad()))
                    .collect::<Result<_, _>>()?,
            ),
        })
    }

    /// Numbers finite; text free of control characters
    /// ([`crate::names::check_text`]: a parameter's text may become a pass's
    /// name or reach the page and the terminal).
    fn check_value(&self) -> Result<(), String> {
        match self {
            Self::Float(f) if !f.is_finite() => Err(format!("{f} is not a finite number")),
            Self::List(v) if v.iter().any(|x| !x.is_finite()) => {
                Err("the list holds a value that is not finite".into())
            }
            Self::Text(t) => crate::names::check_text("text", t).map_err(|e| e.to_string()),
            _ => Ok(()),
        }
    }
}

impl std::fmt::Display for ParamValue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Int(i) => write!(f, "{i}"),
            Self::Float(x) => write!(f, "{x}"),
            Self::Bool(b) => write!(f, "{b}"),
            Self::Text(s) => write!(f, "\"{s}\""),
            Self::List(v) => write!(f, "{v:?}"),
        }
    }
}

/// One parameter of a family.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamSpec {
    /// Its name.
    pub name: String,
    /// The default.
    pub default: ParamValue,
    /// Its unit (may be empty).
    pub unit: String,
    /// One line of description.
    pub doc: String,
    /// The machine constant that gives its default on a machine that has
    /// it, if any.
    #[serde(default)]
    pub machine: Option<String>,
    /// The place of a machine's body it restates, `"<body>.<x|y|z>"`: the
    /// body's origin relative to the tool along that axis of the part, as
    /// the machine's chain puts it (every axis at zero). The run takes its
    /// default from the chain and refuses a value the chain contradicts.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body: Option<String>,
    /// The least value allowed (a number, or each number of a list).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<f64>,
    /// The greatest value allowed: the ceiling of a quantity that drives
    /// work (passes, points), checked before any work.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<f64>,
    /// The most values a list may hold.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_len: Option<usize>,
    /// Whether it is a tolerance the verification holds the part to (a
    /// larger value is looser): a verification takes a value looser than
    /// the default only from its own command line, never from a file a
    /// run wrote.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub tolerance: bool,
    /// The machine axis a true value needs (a mode of the family only a
    /// machine with that axis runs, e.g. the caliber's `cross_axis` and
    /// Y): the run refuses the value before any planning on a machine
    /// without the axis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub needs_axis: Option<String>,
}

impl ParamSpec {
    /// A spec with no bounds.
    pub fn new(name: &str, default: ParamValue, unit: &str, doc: &str) -> Self {
        Self {
            name: name.to_owned(),
            default,
            unit: unit.to_owned(),
            doc: doc.to_owned(),
            machine: None,
            body: None,
            min: None,
            max: None,
            max_len: None,
            tolerance: false,
            needs_axis: None,
        }
    }

    /// The machine body and part axis (0: x, 1: y, 2: z) of its `body`
    /// place, if it has one and it is well formed.
    pub fn body_place(&self) -> Option<(&str, usize)> {
        let (body, axis) = self.body.as_deref()?.rsplit_once('.')?;
        let along = ["x", "y", "z"].iter().position(|a| *a == axis)?;
        (!body.is_empty()).then_some((body, along))
    }

    /// The bounds in words, for listings: `[1, 100]`, `>= 0.0001`, ...
    pub fn range_text(&self) -> String {
        let mut parts = vec![];
        match (self.min, self.max) {
            (Some(a), Some(b)) => parts.push(format!("[{a}, {b}]")),
            (Some(a), None) => parts.push(format!(">= {a}")),
            (None, Some(b)) => parts.push(format!("<= {b}")),
            (None, None) => {}
        }
        if let Some(n) = self.max_len {
            parts.push(format!("at most {n} values"));
        }
        parts.join(", ")
    }

    /// Checks `value` against the bounds.
    fn check(&self, value: &ParamValue) -> Result<(), String> {
        let check_one = |x: f64| -> Result<(), String> {
            if let Some(max) = self.max {
                if x > max {
                    return Err(format!(
                        "{} is above the ceiling {max}",
                        crate::math::shown(x)
                    ));
                }
            }
            if let Some(min) = self.min {
                if x < min {
                    return Err(format!(
                        "{} is below the least value allowed, {min}",
                        crate::math::shown(x)
                    ));
                }
            }
            Ok(())
        };
        match value {
            ParamValue::Int(i) => check_one(*i as f64),
            ParamValue::Float(x) => check_one(*x),
            ParamValue::List(v) => {
                if let Some(n) = self.max_len {
                    if v.len() > n {
                        return Err(format!(
                            "{} values are more than the ceiling of {n}",
                            v.len()
                        ));
                    }
                }
                v.iter().try_for_each(|x| check_one(*x))
            }
            ParamValue::Bool(_) | ParamValue::Text(_) => Ok(()),
        }
    }
}

/// Where parameter values come from, in the order they apply (a later
/// source wins). `label` names the source in messages: `--set`, a file's
/// name.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamSource {
    /// A TOML table of `name = value`.
    Toml {
        /// The source's name in messages.
        label: String,
        /// The TOML text.
        text: String,
    },
    /// `NAME=VALUE` pairs as typed.
    Pairs {
        /// The source's name in messages.
        label: String,
        /// The pairs.
        pairs: Vec<(String, String)>,
    },
}

/// A machine constant's value that a parameter of its kind cannot take
/// (a fraction for a whole number, any number for a text).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{value} is not {kind}")]
pub struct NotOfKind {
    /// The constant's value.
    pub value: Real,
    /// The kind the parameter takes (`a whole number`).
    pub kind: &'static str,
}

/// A parameter that cannot be resolved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamError {
    /// A source that cannot be read (a TOML syntax error).
    #[error("{source_name}: {message}")]
    Source {
        /// The source.
        source_name: String,
        /// What is wrong.
        message: String,
    },
    /// A parameter given that the family does not have.
    #[error("unknown parameter '{name}' from {source_name} (parameters: {known})")]
    Unknown {
        /// The name given.
        name: String,
        /// Where it was given (`--set`, a file).
        source_name: String,
        /// The family's parameters.
        known: String,
    },
    /// A parameter value of the wrong kind.
    #[error("parameter '{name}' from {source_name}: {message}")]
    Bad {
        /// The parameter.
        name: String,
        /// Where it was given.
        source_name: String,
        /// What is wrong.
        message: String,
    },
}

/// What a text parameter names as its `machine` to read the machine's
/// control (its dialect's name, `fanuc`, `linuxcnc`, ...): the run sets
/// it, and refuses another value.
pub const MACHINE_CONTROL: &str = "control";

/// Where [`resolve_traced`] says a value came from when it is the spec's
/// default.
pub const DEFAULT_SOURCE: &str = "its default";

/// The values of the parameters `specs`: defaults (a machine constant's
/// value for a parameter tied to one that `constants` has), then each
/// source in order; then every value against its spec's bounds.
///
/// # Failures
/// A TOML syntax error; an unknown name (listing the valid ones); a value
/// of another kind than the default's, or not finite; a machine constant
/// that is not of its parameter's kind (a whole number, say), naming both;
/// a value outside its bounds, naming the parameter, where the value came
/// from, the value and the bound.
pub fn resolve(
    specs: &[ParamSpec],
    constants: &BTreeMap<String, Real>,
    sources: &[ParamSource],
) -> Result<Params, ParamError> {
    resolve_traced(specs, constants, sources).map(|(values, _)| values)
}

/// [`resolve`], and where each value came from: `its default`, `the
/// machine's constant NAME`, or the label of the last source that set it.
///
/// # Failures
/// As [`resolve`].
pub fn resolve_traced(
    specs: &[ParamSpec],
    constants: &BTreeMap<String, Real>,
    sources: &[ParamSource],
) -> Result<(Params, BTreeMap<String, String>), ParamError> {
    let mut values = BTreeMap::new();
    let mut came_from: BTreeMap<String, String> = BTreeMap::new();
    for s in specs {
        let value = match s
            .machine
            .as_ref()
            .and_then(|m| Some((m, constants.get(m)?)))
        {
            Some((m, &x)) => {
                came_from.insert(s.name.clone(), format!("the machine's constant {m}"));
                ParamValue::from_constant(x, &s.default).map_err(|message| ParamError::Bad {
                    name: s.name.clone(),
                    source_name: format!("the machine's constant {m}"),
                    message: message.to_string(),
                })?
            }
            None => {
                came_from.insert(s.name.clone(), DEFAULT_SOURCE.into());
                s.default.clone()
            }
        };
        values.insert(s.name.clone(), value);
    }
    let spec = |name: &str, source: &str| {
        specs
            .iter()
            .find(|s| s.name == name)
            .ok_or_else(|| ParamError::Unknown {
                name: crate::files::excerpt(name),
                source_name: source.to_owned(),
                known: specs
                    .iter()
                    .map(|s| s.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    };
    let bad = |name: &str, source: &str, message: String| ParamError::Bad {
        name: crate::files::excerpt(name),
        source_name: source.to_owned(),
        message,
    };
    for source in sources {
        match source {
            ParamSource::Toml { label, text } => {
                let table: toml::Table = toml::from_str(text).map_err(|e| {
                    // The place and the parser's words, not its quote of the
                    // line (which may be a megabyte long).
                    let at = e.span().map_or(0, |s| s.start).min(text.len());
                    let before = &text.as_bytes()[..at];
                    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
                    let column = at
                        - before
                            .iter()
                            .rposition(|&b| b == b'\n')
                            .map_or(0, |i| i + 1)
                        + 1;
                    ParamError::Source {
                        source_name: label.clone(),
                        message: format!(
                            "line {line}, column {column}: {}",
                            crate::files::excerpt(e.message().trim())
                        ),
                    }
                })?;
                for (k, v) in &table {
                    let s = spec(k, label)?;
                    let value =
                        ParamValue::from_toml(v, &s.default).map_err(|m| bad(k, label, m))?;
                    value.check_value().map_err(|m| bad(k, label, m))?;
                    values.insert(k.clone(), value);
                    came_from.insert(k.clone(), label.clone());
                }
            }
            ParamSource::Pairs { label, pairs } => {
                for (k, text) in pairs {
                    let s = spec(k, label)?;
                    let value =
                        ParamValue::parse(text, &s.default).map_err(|m| bad(k, label, m))?;
                    value.check_value().map_err(|m| bad(k, label, m))?;
                    values.insert(k.clone(), value);
                    came_from.insert(k.clone(), label.clone());
                }
            }
        }
    }
    for s in specs {
        let v = &values[&s.name];
        v.check_value()
            .and_then(|_| s.check(v))
            .map_err(|m| bad(&s.name, &came_from[&s.name], m))?;
    }
    Ok((values, came_from))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn specs() -> Vec<ParamSpec> {
        let spec = |name: &str, default, machine: Option<&str>| ParamSpec {
            machine: machine.map(str::to_owned),
            ..ParamSpec::new(name, default, "", "")
        };
        vec![
            spec("n", ParamValue::Int(3), None),
            spec("r", ParamValue::Float(25.0), Some("rest_radius")),
            spec("on", ParamValue::Bool(true), Some("rest_programs_centre")),
        ]
    }

    #[test]
    fn sources_apply_in_order_and_name_themselves() {
        let constants = BTreeMap::from([
            ("rest_radius".to_owned(), 30.0),
            ("rest_programs_centre".to_owned(), 0.0),
        ]);
        let sources = [
            ParamSource::Toml {
                label: "p.toml".into(),
                text: "n = 5\nr = 20".into(),
            },
            ParamSource::Pairs {
                label: "--set".into(),
                pairs: vec![("r".into(), "22.5".into())],
            },
        ];
        let v = resolve(&specs(), &constants, &sources).unwrap();
        let mut bounded = specs();
        bounded[0].max = Some(4.0);
        let e = resolve(&bounded, &constants, &sources).unwrap_err();
        assert_eq!(
            e.to_string(),
            "parameter 'n' from p.toml: 5 is above the ceiling 4"
        );
        assert_eq!(v["n"], ParamValue::Int(5));
        assert_eq!(v["r"], ParamValue::Float(22.5));
        assert_eq!(v["on"], ParamValue::Bool(false), "from the machine");
        let e = resolve(
            &specs(),
            &constants,
            &[ParamSource::Pairs {
                label: "the command line".into(),
                pairs: vec![("m".into(), "1".into())],
            }],
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "unknown parameter 'm' from the command line (parameters: n, r, on)"
        );
        let e = resolve(
            &specs(),
            &BTreeMap::new(),
            &[ParamSource::Toml {
                label: "q.toml".into(),
                text: "n = ".into(),
            }],
        )
        .unwrap_err();
        assert!(e.to_string().starts_with("q.toml: "), "{e}");
    }
}
