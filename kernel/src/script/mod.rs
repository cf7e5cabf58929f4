//! The Rhai host: part families written as scripts (ARCHITECTURE §4).
//!
//! A family is a Rhai script that defines
//!
//! - `fn params()`: a map of parameters, each `#{ value, unit, doc }` (the
//!   default, its unit, a one-line description);
//! - `fn toolpath(p)`: the toolpath for the parameter values `p` (a map);
//! - optionally `fn part(p)` (the part's geometry, for export) and
//!   `fn checks(p)` (an array of `#{ name, ok, detail }`).
//!
//! The engine runs with limits ([`Limits`]: operations, call depth,
//! expression depth, array, string and map sizes): a script that runs away
//! is stopped with a clear error. Scripts reach files only through kernel
//! functions (`read_table`), and only inside the input directories given
//! ([`Access`]); `import` is off. Every error carries the script's file,
//! line and column. The functions scripts can call are listed, from their
//! doc comments, by [`api_reference`] (`docs/script-api.md`).

mod api;
mod docs;

pub use api::Floats;
pub use docs::api_reference;

use crate::math::Real;
use crate::toolpath::Toolpath;
use rhai::{Dynamic, Engine, EvalAltResult, Map, Position, Scope, AST};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The engine's limits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// Operations per call (a runaway loop is stopped here).
    pub max_operations: u64,
    /// Nested function calls.
    pub max_call_levels: usize,
    /// Nesting of expressions (global, in functions).
    pub max_expr_depth: (usize, usize),
    /// Elements of a Rhai array (Floats are native and not limited).
    pub max_array_size: usize,
    /// Bytes of a string.
    pub max_string_size: usize,
    /// Entries of a map.
    pub max_map_size: usize,
}

impl Default for Limits {
    /// 50 million operations (a few seconds), 64 calls deep, expressions 64
    /// (32 in functions), 1 million array elements, 1 MB strings, 10,000
    /// map entries.
    fn default() -> Self {
        Self {
            max_operations: 50_000_000,
            max_call_levels: 64,
            max_expr_depth: (64, 32),
            max_array_size: 1_000_000,
            max_string_size: 1 << 20,
            max_map_size: 10_000,
        }
    }
}

/// Where scripts may read files.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Access {
    /// Directories scripts may read tables from (and below).
    pub input_dirs: Vec<PathBuf>,
}

/// A script's error: where, and what.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ScriptError {
    /// The script file could not be read.
    #[error("{file}: {message}")]
    Io {
        /// The file.
        file: String,
        /// The system's message.
        message: String,
    },
    /// An error at a place in the script.
    #[error("{file}:{line}:{column}: {message}")]
    At {
        /// The script.
        file: String,
        /// Line (from 1).
        line: usize,
        /// Column (from 1).
        column: usize,
        /// What went wrong.
        message: String,
    },
    /// An error the engine gives no place for (a stopped runaway script).
    #[error("{file}: {message}")]
    Script {
        /// The script.
        file: String,
        /// What went wrong.
        message: String,
    },
    /// The script does not keep the family contract.
    #[error("{file}: {message}")]
    Contract {
        /// The script.
        file: String,
        /// What is missing or wrong.
        message: String,
    },
    /// A parameter given that the family does not have.
    #[error("unknown parameter '{name}' from {source_name} (parameters: {known})")]
    UnknownParam {
        /// The name given.
        name: String,
        /// Where it was given (`--set`, a file).
        source_name: String,
        /// The family's parameters.
        known: String,
    },
    /// A parameter value of the wrong kind.
    #[error("parameter '{name}' from {source_name}: {message}")]
    BadParam {
        /// The parameter.
        name: String,
        /// Where it was given.
        source_name: String,
        /// What is wrong.
        message: String,
    },
}

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

impl ParamValue {
    fn kind(&self) -> &'static str {
        match self {
            Self::Int(_) => "a whole number",
            Self::Float(_) => "a number",
            Self::Bool(_) => "true or false",
            Self::Text(_) => "text",
            Self::List(_) => "a list of numbers",
        }
    }

    fn to_dynamic(&self) -> Dynamic {
        match self {
            Self::Int(i) => Dynamic::from_int(*i),
            Self::Float(f) => Dynamic::from_float(*f),
            Self::Bool(b) => Dynamic::from_bool(*b),
            Self::Text(s) => Dynamic::from(s.clone()),
            Self::List(v) => {
                Dynamic::from_array(v.iter().map(|x| Dynamic::from_float(*x)).collect())
            }
        }
    }

    fn from_dynamic(d: &Dynamic) -> Option<Self> {
        if let Ok(i) = d.as_int() {
            Some(Self::Int(i))
        } else if let Ok(f) = d.as_float() {
            Some(Self::Float(f))
        } else if let Ok(b) = d.as_bool() {
            Some(Self::Bool(b))
        } else if d.is_string() {
            Some(Self::Text(d.clone().into_string().ok()?))
        } else if d.is_array() {
            let a = d.clone().cast::<rhai::Array>();
            a.iter()
                .map(api::number)
                .collect::<Option<Vec<_>>>()
                .map(Self::List)
        } else {
            None
        }
    }

    /// The value of a machine constant, of the same kind as `like`: a
    /// number as it is, a whole number if it is one, true/false as not 0/0.
    fn from_constant(x: Real, like: &ParamValue) -> Result<Self, String> {
        match like {
            Self::Float(_) => Ok(Self::Float(x)),
            Self::Int(_) if x.fract() == 0.0 && x.abs() < 9e15 => Ok(Self::Int(x as i64)),
            Self::Bool(_) => Ok(Self::Bool(x != 0.0)),
            _ => Err(format!("{x} is not {}", like.kind())),
        }
    }

    /// The value of a TOML value, of the same kind as `like`.
    fn from_toml(v: &toml::Value, like: &ParamValue) -> Result<Self, String> {
        let got = || format!("expected {}, got {v}", like.kind());
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

    /// The value of a `--set` text, of the same kind as `like`.
    fn parse(text: &str, like: &ParamValue) -> Result<Self, String> {
        let t = text.trim();
        let bad = || format!("'{text}' is not {}", like.kind());
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

    fn check_finite(&self) -> Result<(), String> {
        match self {
            Self::Float(f) if !f.is_finite() => Err(format!("{f} is not a finite number")),
            Self::List(v) if v.iter().any(|x| !x.is_finite()) => {
                Err("the list holds a value that is not finite".into())
            }
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
    /// it (`machine: "rest_radius"` in the spec), if any.
    #[serde(default)]
    pub machine: Option<String>,
}

/// What a family's finished part must be: the nominal profile, over
/// `[from, to]`, within `tolerance` (mm).
#[derive(Debug, Clone, PartialEq)]
pub struct Verification {
    /// The nominal profile.
    pub profile: crate::Profile,
    /// Start of the range held to the tolerance.
    pub from: f64,
    /// End of that range.
    pub to: f64,
    /// The tolerance (mm).
    pub tolerance: f64,
}

/// The result of one of a family's checks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Check {
    /// What is checked.
    pub name: String,
    /// Whether it holds.
    pub ok: bool,
    /// Details (values, places).
    pub detail: String,
}

/// A part family loaded from a script.
pub struct Family {
    engine: Engine,
    ast: AST,
    file: String,
    specs: Vec<ParamSpec>,
}

impl std::fmt::Debug for Family {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Family")
            .field("file", &self.file)
            .field("params", &self.specs)
            .finish()
    }
}

/// An engine with the kernel's API and the limits set.
pub fn engine(limits: &Limits, access: &Access) -> Engine {
    let mut e = Engine::new();
    e.set_max_operations(limits.max_operations)
        .set_max_call_levels(limits.max_call_levels)
        .set_max_expr_depths(limits.max_expr_depth.0, limits.max_expr_depth.1)
        .set_max_array_size(limits.max_array_size)
        .set_max_string_size(limits.max_string_size)
        .set_max_map_size(limits.max_map_size)
        .set_module_resolver(rhai::module_resolvers::DummyModuleResolver::new());
    // Scripts print to the error stream, never into outputs.
    e.on_print(|s| eprintln!("{s}"));
    e.on_debug(|s, src, pos| eprintln!("{}:{pos}: {s}", src.unwrap_or("script")));
    api::register(&mut e);
    register_files(&mut e, access);
    e
}

/// `read_table(path)`, allowed only inside the input directories.
fn register_files(engine: &mut Engine, access: &Access) {
    let dirs: Vec<PathBuf> = access
        .input_dirs
        .iter()
        .filter_map(|d| d.canonicalize().ok())
        .collect();
    rhai::FuncRegistration::new("read_table")
        .with_params_info(["path: &str", "Table"])
        .with_comments([
            "/// A table (CSV, XLSX, XLS, ODS) from a file inside the input directories",
            "/// (the script's own, and the parameter file's); a relative path is taken",
            "/// from the first of them. Returns a map of columns by header: `#{ theta: Floats, ... }`.",
        ])
        .register_into_engine(engine, move |path: &str| -> Result<Map, Box<EvalAltResult>> {
            let p = Path::new(path);
            let full = if p.is_absolute() {
                p.to_owned()
            } else {
                dirs.first().map(|d| d.join(p)).ok_or("no input directory is open to scripts")?
            };
            let canon = full.canonicalize().map_err(|e| format!("{}: {e}", full.display()))?;
            if !dirs.iter().any(|d| canon.starts_with(d)) {
                return Err(format!("{} is outside the input directories", full.display()).into());
            }
            let table = crate::profile::read_table(&canon).map_err(|e| e.to_string())?;
            let mut m = Map::new();
            for (i, h) in table.headers().iter().enumerate() {
                let col = table.column(&(i + 1).to_string()).map_err(|e| e.to_string())?;
                m.insert(h.as_str().into(), Dynamic::from(Floats::new(col)));
            }
            Ok(m)
        });
}

/// Where an error happened and what it says, from the innermost error.
fn locate(file: &str, called: &str, e: &EvalAltResult) -> ScriptError {
    let mut inner = e;
    let mut outer_pos = e.position();
    let mut in_fn: Option<String> = None;
    while let EvalAltResult::ErrorInFunctionCall(name, _, next, pos) = inner {
        if !pos.is_none() {
            outer_pos = *pos;
        }
        in_fn.get_or_insert(name.clone());
        inner = next;
    }
    let pos = if inner.position().is_none() {
        outer_pos
    } else {
        inner.position()
    };
    let mut message = match inner {
        EvalAltResult::ErrorTooManyOperations(_) => {
            "the script ran past its operation limit and was stopped (an endless loop?)".to_owned()
        }
        EvalAltResult::ErrorStackOverflow(_) => {
            "the script's calls nest too deep (endless recursion?)".to_owned()
        }
        EvalAltResult::ErrorRuntime(d, _) => d.to_string(),
        // Rhai's text ends with " (line L, position C)": the place is given apart.
        other => {
            let text = other.to_string();
            match text.rfind(" (line ") {
                Some(i) if text.ends_with(')') => text[..i].to_owned(),
                _ => text,
            }
        }
    };
    message.push_str(&format!(" (in fn {})", in_fn.as_deref().unwrap_or(called)));
    at(file, pos, message)
}

fn at(file: &str, pos: Position, message: String) -> ScriptError {
    if pos.is_none() {
        return ScriptError::Script {
            file: file.to_owned(),
            message,
        };
    }
    ScriptError::At {
        file: file.to_owned(),
        line: pos.line().unwrap_or(0),
        column: pos.position().unwrap_or(0),
        message,
    }
}

impl Family {
    /// Loads a family from its script file; the script's directory is an
    /// input directory too.
    ///
    /// # Failures
    /// An unreadable file; a syntax error (file:line:col); a script without
    /// `fn params()` or `fn toolpath(p)`, or whose `params()` fails or
    /// returns something other than a map of `#{value, unit, doc}`.
    pub fn load(path: &Path, limits: &Limits, access: &Access) -> Result<Self, ScriptError> {
        let file = path.display().to_string();
        let source = std::fs::read_to_string(path).map_err(|e| ScriptError::Io {
            file: file.clone(),
            message: e.to_string(),
        })?;
        let mut access = access.clone();
        if let Some(dir) = path.parent() {
            let dir = if dir.as_os_str().is_empty() {
                Path::new(".")
            } else {
                dir
            };
            access.input_dirs.insert(0, dir.to_owned());
        }
        Self::from_source(&source, &file, limits, &access)
    }

    /// Loads a family from source text; `file` names it in errors.
    ///
    /// # Failures
    /// As [`Family::load`].
    pub fn from_source(
        source: &str,
        file: &str,
        limits: &Limits,
        access: &Access,
    ) -> Result<Self, ScriptError> {
        let engine = engine(limits, access);
        let mut ast = engine
            .compile(source)
            .map_err(|e| at(file, e.position(), e.err_type().to_string()))?;
        ast.set_source(file);
        let mut fam = Self {
            engine,
            ast,
            file: file.to_owned(),
            specs: vec![],
        };
        for (name, arity) in [("params", 0), ("toolpath", 1)] {
            if !fam.has_fn(name, arity) {
                return Err(fam.contract(format!(
                    "a part family defines fn {name}({})",
                    if arity == 1 { "p" } else { "" }
                )));
            }
        }
        let params = fam.call("params", ())?;
        let map = params.try_cast::<Map>().ok_or_else(|| {
            fam.contract("fn params() must return a map of #{ value, unit, doc }".into())
        })?;
        for (name, spec) in map {
            let spec = spec.try_cast::<Map>().ok_or_else(|| {
                fam.contract(format!(
                    "parameter '{name}' must be #{{ value, unit, doc }}"
                ))
            })?;
            let field = |k: &str| spec.get(k).cloned();
            let default = field("value")
                .as_ref()
                .and_then(ParamValue::from_dynamic)
                .ok_or_else(|| {
                    fam.contract(format!(
                        "parameter '{name}' needs a value (number, bool, text or list)"
                    ))
                })?;
            let text = |k: &str| {
                field(k)
                    .and_then(|d| d.into_string().ok())
                    .unwrap_or_default()
            };
            let machine = Some(text("machine")).filter(|m| !m.is_empty());
            if machine.is_some() && ParamValue::from_constant(0.0, &default).is_err() {
                return Err(fam.contract(format!(
                    "parameter '{name}' takes its default from a machine constant, so it must be a number or true/false, not {}",
                    default.kind()
                )));
            }
            fam.specs.push(ParamSpec {
                name: name.to_string(),
                default,
                unit: text("unit"),
                doc: text("doc"),
                machine,
            });
        }
        Ok(fam)
    }

    fn contract(&self, message: String) -> ScriptError {
        ScriptError::Contract {
            file: self.file.clone(),
            message,
        }
    }

    /// Whether the script defines `fn name` with `arity` parameters.
    pub fn has_fn(&self, name: &str, arity: usize) -> bool {
        self.ast
            .iter_functions()
            .any(|f| f.name == name && f.params.len() == arity)
    }

    fn call(&self, name: &str, args: impl rhai::FuncArgs) -> Result<Dynamic, ScriptError> {
        let mut scope = Scope::new();
        self.engine
            .call_fn::<Dynamic>(&mut scope, &self.ast, name, args)
            .map_err(|e| locate(&self.file, name, &e))
    }

    /// The script's file name.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// The family's parameters (by name).
    pub fn params(&self) -> &[ParamSpec] {
        &self.specs
    }

    fn known(&self) -> String {
        self.specs
            .iter()
            .map(|s| s.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The parameter values: defaults, then those of a TOML file's table
    /// (`file`: its name and text), then `--set name=value` pairs.
    ///
    /// # Failures
    /// A TOML syntax error; an unknown name (listing the valid ones); a
    /// value of another kind than the default's, or not finite.
    pub fn resolve(
        &self,
        file: Option<(&str, &str)>,
        sets: &[(String, String)],
    ) -> Result<BTreeMap<String, ParamValue>, ScriptError> {
        self.resolve_on(&BTreeMap::new(), file, sets)
    }

    /// As [`Family::resolve`], on a machine with `constants`: a parameter
    /// whose spec names a machine constant the machine has takes it as its
    /// default (the file and `--set` still win).
    ///
    /// # Failures
    /// As [`Family::resolve`]; a constant that is not of the parameter's
    /// kind (a whole number, say), naming both.
    pub fn resolve_on(
        &self,
        constants: &BTreeMap<String, Real>,
        file: Option<(&str, &str)>,
        sets: &[(String, String)],
    ) -> Result<BTreeMap<String, ParamValue>, ScriptError> {
        let mut values = BTreeMap::new();
        for s in &self.specs {
            let value = match s
                .machine
                .as_ref()
                .and_then(|m| Some((m, constants.get(m)?)))
            {
                Some((m, &x)) => ParamValue::from_constant(x, &s.default).map_err(|message| {
                    ScriptError::BadParam {
                        name: s.name.clone(),
                        source_name: format!("the machine's constant {m}"),
                        message,
                    }
                })?,
                None => s.default.clone(),
            };
            values.insert(s.name.clone(), value);
        }
        let spec = |name: &str, source: &str| {
            self.specs
                .iter()
                .find(|s| s.name == name)
                .ok_or_else(|| ScriptError::UnknownParam {
                    name: name.to_owned(),
                    source_name: source.to_owned(),
                    known: self.known(),
                })
        };
        let bad = |name: &str, source: &str, message: String| ScriptError::BadParam {
            name: name.to_owned(),
            source_name: source.to_owned(),
            message,
        };
        if let Some((fname, text)) = file {
            let table: toml::Table = toml::from_str(text).map_err(|e| ScriptError::Contract {
                file: fname.to_owned(),
                message: e.to_string().trim().to_owned(),
            })?;
            for (k, v) in &table {
                let s = spec(k, fname)?;
                let value = ParamValue::from_toml(v, &s.default).map_err(|m| bad(k, fname, m))?;
                value.check_finite().map_err(|m| bad(k, fname, m))?;
                values.insert(k.clone(), value);
            }
        }
        for (k, text) in sets {
            let s = spec(k, "--set")?;
            let value = ParamValue::parse(text, &s.default).map_err(|m| bad(k, "--set", m))?;
            value.check_finite().map_err(|m| bad(k, "--set", m))?;
            values.insert(k.clone(), value);
        }
        Ok(values)
    }

    fn param_map(values: &BTreeMap<String, ParamValue>) -> Map {
        values
            .iter()
            .map(|(k, v)| (k.as_str().into(), v.to_dynamic()))
            .collect()
    }

    /// Runs `fn toolpath(p)`.
    ///
    /// # Failures
    /// The script's error (file:line:col), or a result that is not a toolpath.
    pub fn toolpath(&self, values: &BTreeMap<String, ParamValue>) -> Result<Toolpath, ScriptError> {
        let d = self.call("toolpath", (Self::param_map(values),))?;
        let handle = d.try_cast::<api::ToolpathHandle>().ok_or_else(|| {
            self.contract("fn toolpath(p) must return a toolpath (new_toolpath(...))".into())
        })?;
        // The script's variables are gone: the handle is the last owner, and
        // the toolpath is moved out rather than copied.
        Ok(std::rc::Rc::try_unwrap(handle)
            .map(|c| c.into_inner())
            .unwrap_or_else(|h| h.borrow().clone()))
    }

    /// Runs `fn checks(p)`, if the family has it.
    ///
    /// # Failures
    /// The script's error, or a result that is not an array of
    /// `#{name, ok, detail}`.
    pub fn checks(&self, values: &BTreeMap<String, ParamValue>) -> Result<Vec<Check>, ScriptError> {
        if !self.has_fn("checks", 1) {
            return Ok(vec![]);
        }
        let d = self.call("checks", (Self::param_map(values),))?;
        let shape =
            || self.contract("fn checks(p) must return an array of #{ name, ok, detail }".into());
        let arr = d.try_cast::<rhai::Array>().ok_or_else(shape)?;
        arr.into_iter()
            .map(|c| {
                let m = c.try_cast::<Map>().ok_or_else(shape)?;
                Ok(Check {
                    name: m
                        .get("name")
                        .and_then(|d| d.clone().into_string().ok())
                        .ok_or_else(shape)?,
                    ok: m
                        .get("ok")
                        .and_then(|d| d.as_bool().ok())
                        .ok_or_else(shape)?,
                    detail: m
                        .get("detail")
                        .and_then(|d| d.clone().into_string().ok())
                        .unwrap_or_default(),
                })
            })
            .collect()
    }

    /// The machine the family names with `fn default_machine()`, if it has one.
    ///
    /// # Failures
    /// The script's error, or a result that is not text.
    pub fn default_machine(&self) -> Result<Option<String>, ScriptError> {
        if !self.has_fn("default_machine", 0) {
            return Ok(None);
        }
        let d = self.call("default_machine", ())?;
        d.into_string().map(Some).map_err(|t| {
            self.contract(format!(
                "fn default_machine() must return a machine's name, not {t}"
            ))
        })
    }

    /// Runs `fn verify(p)`, if the family has it: what the finished part
    /// must be, where, and how closely.
    ///
    /// # Failures
    /// The script's error, or a result that is not
    /// `#{ profile, from, to, tolerance }`.
    pub fn verification(
        &self,
        values: &BTreeMap<String, ParamValue>,
    ) -> Result<Option<Verification>, ScriptError> {
        if !self.has_fn("verify", 1) {
            return Ok(None);
        }
        let d = self.call("verify", (Self::param_map(values),))?;
        let shape =
            || self.contract("fn verify(p) must return #{ profile, from, to, tolerance }".into());
        let m = d.try_cast::<Map>().ok_or_else(shape)?;
        let num = |k: &str| m.get(k).and_then(api::number).ok_or_else(shape);
        Ok(Some(Verification {
            profile: m
                .get("profile")
                .and_then(|p| p.clone().try_cast::<crate::Profile>())
                .ok_or_else(shape)?,
            from: num("from")?,
            to: num("to")?,
            tolerance: num("tolerance")?,
        }))
    }

    /// Runs `fn name(p)` and returns its raw result (for `part`).
    ///
    /// # Failures
    /// The script's error.
    pub fn call_with_params(
        &self,
        name: &str,
        values: &BTreeMap<String, ParamValue>,
    ) -> Result<Dynamic, ScriptError> {
        self.call(name, (Self::param_map(values),))
    }
}
