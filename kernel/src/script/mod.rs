//! The Rhai host: part families written as scripts (docs/architecture.md, the extension points).
//!
//! A family is a Rhai script that defines
//!
//! - `fn params()`: a map of parameters, each `#{ value, unit, doc }` (the
//!   default, its unit, a one-line description), optionally `min`, `max`
//!   (bounds; a quantity that drives work has a ceiling) and `max_len` (for
//!   a list), `machine` (the machine constant that gives the default) and
//!   `tolerance: true` (a tolerance the verification holds the part to);
//!   `needs_axis: "Y"` (on a true/false parameter: the machine axis a
//!   true value needs, refused before planning on a machine without it);
//! - `fn toolpath(p)`: the toolpath for the parameter values `p` (a map);
//! - optionally `fn part(p)` (the part's geometry, for export),
//!   `fn checks(p)` (an array of `#{ name, ok, detail }`), `fn verify(p)`
//!   and `fn default_machine()`.
//!
//! [`ScriptFamily`] is such a script as a [`PartFamily`]. The engine runs
//! with limits ([`Limits`]: operations, call depth, expression depth,
//! array, string and map sizes): a script that runs away is stopped with a
//! clear error. Scripts reach files only through kernel functions
//! (`read_table`), and only inside the input directories given
//! ([`Access`]); `import` is off. Every error carries the script's file,
//! line and column. The functions scripts can call are listed, from their
//! doc comments, by [`api_reference`] (`docs/script-api.md`). A machine may
//! be a script too ([`machine_from_script`]).

mod bind_offset;
mod bind_profile;
mod bind_table;
mod bind_toolpath;
mod bind_transform;
mod compat;
mod docs;
mod verify;

use crate::binding::{floats, ApiGroup};
pub use crate::binding::{Access, Floats, ReadLog};
pub use docs::api_reference;

use crate::family::{Check, FamilyError, PartBody, PartFamily, PartGeometry, Verification};
use crate::machine::{Machine, MachineError};
use crate::params::{ParamSpec, ParamValue, Params};
use crate::profile::Profile;
use crate::toolpath::Toolpath;
use rhai::{Dynamic, Engine, EvalAltResult, Map, Position, Scope, AST};
use std::path::Path;

/// The engine's limits.
#[derive(Debug, Clone, Copy, PartialEq)]
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
    /// Wall-clock seconds per call of a family's function: the operation
    /// count alone does not bound time (an operation on a large array costs
    /// in proportion to it).
    pub max_seconds: f64,
    /// Megabytes a script may hold (what its thread holds, after every
    /// operation, where the program's allocator counts it
    /// ([`set_allocated_probe`]); else the process's resident memory every
    /// 4096 operations, Linux): the size limits alone do not bound memory (Rhai
    /// 1.27 does not count a map's entries added by `m[key] = value`).
    pub max_memory_mb: u64,
}

impl Default for Limits {
    /// 50 million operations (a few seconds), 64 calls deep, expressions 64
    /// (32 in functions), 1 million array elements, 1 MB strings, 10,000
    /// map entries, 60 seconds a call, 4 GB of memory.
    fn default() -> Self {
        Self {
            max_operations: 50_000_000,
            max_call_levels: 64,
            max_expr_depth: (64, 32),
            max_array_size: 1_000_000,
            max_string_size: 1 << 20,
            max_map_size: 10_000,
            max_seconds: 60.0,
            max_memory_mb: 4096,
        }
    }
}

/// Bytes the calling thread holds now: set by a program whose global
/// allocator counts them ([`set_allocated_probe`]), so that a script's
/// memory is looked at after every operation at the cost of one read.
static ALLOCATED: std::sync::OnceLock<fn() -> usize> = std::sync::OnceLock::new();

/// Tells the script engines how to read the bytes the calling thread holds
/// (the `pilgrim` program's allocator counts them per thread; a script runs
/// on one thread).
/// Without it the memory limit reads the resident size from the system
/// every 4096 operations, which one operation on a large value can outrun.
pub fn set_allocated_probe(probe: fn() -> usize) {
    let _ = ALLOCATED.set(probe);
}

/// The process's resident memory (MB), where the system tells it (Linux).
fn resident_mb() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: u64 = text.split_whitespace().nth(1)?.parse().ok()?;
    // SAFETY: sysconf reads a system constant.
    let page = unsafe { libc::sysconf(libc::_SC_PAGESIZE) };
    Some(pages * u64::try_from(page).ok()? / (1 << 20))
}

/// A part family written in Rhai: a script as a [`PartFamily`].
pub struct ScriptFamily {
    script: Script,
    specs: Vec<ParamSpec>,
}

/// A compiled script and the engine that runs it, shared: the family and
/// the verification it declares call the same script (a verification
/// judged by the script calls it after the replay).
#[derive(Clone)]
pub(crate) struct Script {
    engine: std::rc::Rc<Engine>,
    ast: std::rc::Rc<AST>,
    file: String,
    max_seconds: f64,
}

impl std::fmt::Debug for Script {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Script").field("file", &self.file).finish()
    }
}

impl Script {
    /// Whether the script defines `fn name` with `arity` parameters.
    pub(crate) fn has_fn(&self, name: &str, arity: usize) -> bool {
        self.ast
            .iter_functions()
            .any(|f| f.name == name && f.params.len() == arity)
    }

    /// Calls `fn name(args)` within the run's limits.
    pub(crate) fn call(
        &self,
        name: &str,
        args: impl rhai::FuncArgs,
    ) -> Result<Dynamic, FamilyError> {
        let mut scope = Scope::new();
        let got = crate::budget::with_limit(self.max_seconds, "the script's", || {
            self.engine
                .call_fn::<Dynamic>(&mut scope, &self.ast, name, args)
        })
        .map_err(|e| locate(&self.file, name, &e));
        // Earlier releases' forms called outside the toolpath (which
        // carries them into the report) are said on the error stream.
        if name != "toolpath" {
            for w in compat::take_warnings() {
                eprintln!("{}: warning: {w}", self.file);
            }
        }
        got
    }

    /// The script's contract broken: `message` naming its file.
    pub(crate) fn contract(&self, message: String) -> FamilyError {
        FamilyError::Contract {
            family: self.file.clone(),
            message,
        }
    }
}

impl std::fmt::Debug for ScriptFamily {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ScriptFamily")
            .field("file", &self.script.file)
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
    // The memory limit after every operation where the allocator counts
    // (else the resident size every 4096), the time limit every 64. One
    // operation's growth is bounded by the size limits above.
    let max_mb = limits.max_memory_mb;
    let max_bytes = usize::try_from(max_mb.saturating_mul(1 << 20)).unwrap_or(usize::MAX);
    let probe = ALLOCATED.get().copied();
    e.on_progress(move |ops| {
        let over = match probe {
            Some(allocated) => allocated() > max_bytes,
            None => ops % 4096 == 0 && resident_mb().is_some_and(|mb| mb > max_mb),
        };
        if over {
            return Some(Dynamic::from_int(max_mb as rhai::INT));
        }
        if ops % 64 != 0 {
            return None;
        }
        crate::budget::expired()
            .map(|(seconds, whose)| Dynamic::from(format!("{whose} time limit of {seconds} s")))
    });
    // Scripts print to the error stream, never into outputs, quoted as any
    // outside text is: short, control characters (a terminal's escape
    // sequences) escaped.
    e.on_print(|s| eprintln!("{}", crate::files::excerpt(s)));
    e.on_debug(|s, src, pos| {
        eprintln!(
            "{}:{pos}: {}",
            crate::files::excerpt(src.unwrap_or("script")),
            crate::files::excerpt(s)
        )
    });
    register_types(&mut e);
    for group in api() {
        (group.register)(&mut e, access);
    }
    e
}

/// The script types, by the names scripts and the reference use.
fn register_types(e: &mut Engine) {
    use crate::offset::Equidistant;
    use crate::profile::{MandrelLaw, Polyline, ProfileBuilder, Smoothing, Table};
    e.register_type_with_name::<Floats>("Floats")
        .register_type_with_name::<Profile>("Profile")
        .register_type_with_name::<MandrelLaw>("MandrelLaw")
        .register_type_with_name::<ProfileBuilder>("ProfileBuilder")
        .register_type_with_name::<Smoothing>("Smoothing")
        .register_type_with_name::<Polyline>("Path")
        .register_type_with_name::<Equidistant>("Equidistant")
        .register_type_with_name::<crate::tool::Tool>("Tool")
        .register_type_with_name::<bind_transform::Transform>("Transform")
        .register_type_with_name::<bind_transform::Points>("Points")
        .register_type_with_name::<Table>("Table")
        .register_type_with_name::<bind_toolpath::ToolpathHandle>("Toolpath")
        .register_type_with_name::<crate::family::Swept>("Solid");
    for group in crate::families::script_api() {
        (group.types)(e);
    }
}

/// No types of its own.
fn no_types(_: &mut Engine) {}

/// The script API, group by group, as the reference lists it: the generic
/// groups that come before the families', the families', the rest.
fn api() -> impl Iterator<Item = &'static ApiGroup> {
    BEFORE_FAMILIES
        .iter()
        .chain(crate::families::script_api())
        .chain(AFTER_FAMILIES.iter())
}

/// The generic groups listed before the families' own.
const BEFORE_FAMILIES: [ApiGroup; 5] = [
    ApiGroup {
        title: "Numbers (`Floats`)",
        types: no_types,
        verify: None,
        register: |e, _| {
            e.register_global_module(rhai::exported_module!(floats::floats_api).into());
            floats::register_arithmetic(e);
        },
    },
    ApiGroup {
        title: "Profiles (`Profile`, `MandrelLaw`, `Smoothing`)",
        types: no_types,
        verify: None,
        register: |e, _| {
            e.register_global_module(rhai::exported_module!(bind_profile::profile_api).into());
        },
    },
    ApiGroup {
        title: "Whole parts from segments (`ProfileBuilder`)",
        types: no_types,
        verify: None,
        register: |e, _| {
            e.register_global_module(rhai::exported_module!(bind_profile::builder_api).into());
        },
    },
    ApiGroup {
        title: "Paths of tool centres (`Path`)",
        types: no_types,
        verify: None,
        register: |e, _| {
            e.register_global_module(rhai::exported_module!(bind_profile::path_api).into());
        },
    },
    ApiGroup {
        title: "Equidistants, envelopes, wheel paths, ridges (`Equidistant`)",
        types: no_types,
        verify: None,
        register: |e, _| {
            e.register_global_module(rhai::exported_module!(bind_offset::offset_api).into());
        },
    },
];

/// The generic groups listed after the families' own.
const AFTER_FAMILIES: [ApiGroup; 5] = [
    ApiGroup {
        title: "Transforms (`Transform`, `Points`)",
        types: no_types,
        verify: None,
        register: |e, _| {
            e.register_global_module(rhai::exported_module!(bind_transform::transform_api).into());
        },
    },
    ApiGroup {
        title: "Tools (`Tool`)",
        types: no_types,
        verify: None,
        register: |e, _| {
            e.register_global_module(rhai::exported_module!(bind_toolpath::tool_api).into());
        },
    },
    ApiGroup {
        title: "Toolpaths (`Toolpath`)",
        types: no_types,
        verify: None,
        register: |e, _| {
            e.register_global_module(rhai::exported_module!(bind_toolpath::toolpath_api).into());
        },
    },
    ApiGroup {
        title: "Tables (`Table`)",
        types: no_types,
        verify: None,
        register: |e, access| {
            e.register_global_module(rhai::exported_module!(bind_table::table_api).into());
            bind_table::register(e, access);
        },
    },
    ApiGroup {
        title: "Earlier releases' forms (callable for a release more, with a warning naming the replacement)",
        types: no_types,
        verify: None,
        register: |e, _| {
            e.register_global_module(rhai::exported_module!(compat::compat_api).into());
        },
    },
];

/// Where an error happened and what it says, from the innermost error.
fn locate(file: &str, called: &str, e: &EvalAltResult) -> FamilyError {
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
        EvalAltResult::ErrorTerminated(token, _) => match token.as_int() {
            Ok(mb) => format!("the script ran past its memory limit of {mb} MB and was stopped"),
            Err(_) => format!("{token} passed and the script was stopped (an endless loop?)"),
        },
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

fn at(file: &str, pos: Position, message: String) -> FamilyError {
    if pos.is_none() {
        return FamilyError::Failed {
            family: file.to_owned(),
            message,
        };
    }
    FamilyError::At {
        file: file.to_owned(),
        line: pos.line().unwrap_or(0),
        column: pos.position().unwrap_or(0),
        message,
    }
}

impl ScriptFamily {
    /// Loads a family from its script file; the script's directory is an
    /// input directory too.
    ///
    /// # Failures
    /// An unreadable file; a syntax error (file:line:col); a script without
    /// `fn params()` or `fn toolpath(p)`, or whose `params()` fails or
    /// returns something other than a map of `#{value, unit, doc}`.
    pub fn load(path: &Path, limits: &Limits, access: &Access) -> Result<Self, FamilyError> {
        let file = path.display().to_string();
        // The family's name is its path: the report, the page and the
        // terminal show it (its program's name keeps only letters, digits
        // and _).
        crate::names::check_text("the family's name (its script's path)", &file).map_err(|e| {
            FamilyError::Io {
                file: crate::names::quoted(&file),
                message: e.to_string(),
            }
        })?;
        let source = crate::files::read_text(path, crate::files::MAX_TEXT_BYTES).map_err(|e| {
            FamilyError::Io {
                file: file.clone(),
                message: e.message,
            }
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
    /// As [`ScriptFamily::load`].
    pub fn from_source(
        source: &str,
        file: &str,
        limits: &Limits,
        access: &Access,
    ) -> Result<Self, FamilyError> {
        let engine = engine(limits, access);
        let mut ast = engine
            .compile(source)
            .map_err(|e| at(file, e.position(), e.err_type().to_string()))?;
        ast.set_source(file);
        let mut fam = Self {
            script: Script {
                engine: std::rc::Rc::new(engine),
                ast: std::rc::Rc::new(ast),
                file: file.to_owned(),
                max_seconds: limits.max_seconds,
            },
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
                .and_then(param_value)
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
            let control = machine.as_deref() == Some(crate::params::MACHINE_CONTROL);
            if machine.is_some()
                && (if control {
                    !matches!(default, ParamValue::Text(_))
                } else {
                    ParamValue::from_constant(0.0, &default).is_err()
                })
            {
                return Err(fam.contract(if control {
                    format!(
                        "parameter '{name}' reads the machine's control, so it must be text, not {}",
                        default.kind()
                    )
                } else {
                    format!(
                        "parameter '{name}' takes its default from a machine constant, so it must be a number or true/false, not {}",
                        default.kind()
                    )
                }));
            }
            let bound = |k: &str| -> Result<Option<f64>, FamilyError> {
                match field(k) {
                    None => Ok(None),
                    Some(d) => floats::number(&d).map(Some).ok_or_else(|| {
                        fam.contract(format!("parameter '{name}': {k} must be a number"))
                    }),
                }
            };
            let (min, max) = (bound("min")?, bound("max")?);
            let max_len = match bound("max_len")? {
                Some(n) if n >= 0.0 && n.fract() == 0.0 => Some(n as usize),
                Some(_) => {
                    return Err(fam.contract(format!(
                        "parameter '{name}': max_len must be a whole number"
                    )))
                }
                None => None,
            };
            for k in ["unit", "doc", "body"] {
                crate::names::check_text(&format!("parameter '{name}': its {k}"), &text(k))
                    .map_err(|e| fam.contract(e.to_string()))?;
            }
            let body = Some(text("body")).filter(|b| !b.is_empty());
            let tolerance = match field("tolerance") {
                None => false,
                Some(d) => d.as_bool().map_err(|_| {
                    fam.contract(format!(
                        "parameter '{name}': tolerance must be true or false (true: a tolerance the verification holds the part to)"
                    ))
                })?,
            };
            if tolerance && default.as_number().is_none() {
                return Err(fam.contract(format!(
                    "parameter '{name}' is a tolerance, so it must be a number, not {}",
                    default.kind()
                )));
            }
            let needs_axis = Some(text("needs_axis")).filter(|a| !a.is_empty());
            if let Some(a) = &needs_axis {
                if !matches!(default, ParamValue::Bool(_))
                    || !a.chars().all(|c| c.is_ascii_uppercase())
                    || a.len() > 3
                {
                    return Err(fam.contract(format!(
                        "parameter '{name}': needs_axis names the machine axis a true value needs (e.g. \"Y\"), on a true/false parameter"
                    )));
                }
            }
            let spec = ParamSpec {
                machine,
                body,
                min,
                max,
                max_len,
                tolerance,
                needs_axis,
                ..ParamSpec::new(&name, default, &text("unit"), &text("doc"))
            };
            if spec.body.is_some()
                && (spec.body_place().is_none() || spec.default.as_number().is_none())
            {
                return Err(fam.contract(format!(
                    "parameter '{name}': body must read \"<body>.<x|y|z>\" (the machine body's place it restates, e.g. \"rest.z\") on a number, not {:?}",
                    spec.body.as_deref().unwrap_or_default()
                )));
            }
            // The default must be allowed (a family's own mistake).
            if let Err(e) =
                crate::params::resolve(std::slice::from_ref(&spec), &Default::default(), &[])
            {
                return Err(fam.contract(e.to_string()));
            }
            fam.specs.push(spec);
        }
        Ok(fam)
    }

    fn contract(&self, message: String) -> FamilyError {
        self.script.contract(message)
    }

    /// Whether the script defines `fn name` with `arity` parameters.
    pub fn has_fn(&self, name: &str, arity: usize) -> bool {
        self.script.has_fn(name, arity)
    }

    fn call(&self, name: &str, args: impl rhai::FuncArgs) -> Result<Dynamic, FamilyError> {
        self.script.call(name, args)
    }

    /// The script's file name.
    pub fn file(&self) -> &str {
        &self.script.file
    }

    fn param_map(values: &Params) -> Map {
        values
            .iter()
            .map(|(k, v)| (k.as_str().into(), param_dynamic(v)))
            .collect()
    }

    /// Runs `fn name(p)` and returns its raw result.
    ///
    /// # Failures
    /// The script's error.
    pub fn call_with_params(&self, name: &str, values: &Params) -> Result<Dynamic, FamilyError> {
        self.call(name, (Self::param_map(values),))
    }
}

/// A parameter's value as Rhai sees it.
fn param_dynamic(v: &ParamValue) -> Dynamic {
    match v {
        ParamValue::Int(i) => Dynamic::from_int(*i),
        ParamValue::Float(f) => Dynamic::from_float(*f),
        ParamValue::Bool(b) => Dynamic::from_bool(*b),
        ParamValue::Text(s) => Dynamic::from(s.clone()),
        ParamValue::List(v) => {
            Dynamic::from_array(v.iter().map(|x| Dynamic::from_float(*x)).collect())
        }
    }
}

/// A parameter's default from what `fn params()` gave.
fn param_value(d: &Dynamic) -> Option<ParamValue> {
    if let Ok(i) = d.as_int() {
        Some(ParamValue::Int(i))
    } else if let Ok(f) = d.as_float() {
        Some(ParamValue::Float(f))
    } else if let Ok(b) = d.as_bool() {
        Some(ParamValue::Bool(b))
    } else if d.is_string() {
        Some(ParamValue::Text(d.clone().into_string().ok()?))
    } else if d.is_array() {
        let a = d.clone().cast::<rhai::Array>();
        a.iter()
            .map(floats::number)
            .collect::<Option<Vec<_>>>()
            .map(ParamValue::List)
    } else {
        None
    }
}

impl PartFamily for ScriptFamily {
    fn name(&self) -> &str {
        &self.script.file
    }

    fn params(&self) -> &[ParamSpec] {
        &self.specs
    }

    /// `fn default_machine()`, if the script has it.
    fn default_machine(&self) -> Result<Option<String>, FamilyError> {
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

    /// `fn checks(p)`, if the script has it: an array of
    /// `#{name, ok, detail}`.
    fn checks(&self, values: &Params) -> Result<Vec<Check>, FamilyError> {
        if !self.has_fn("checks", 1) {
            return Ok(vec![]);
        }
        let d = self.call_with_params("checks", values)?;
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

    /// `fn toolpath(p)`: the toolpath it builds.
    fn toolpath(&self, values: &Params) -> Result<Toolpath, FamilyError> {
        let d = self.call_with_params("toolpath", values)?;
        let handle = d
            .try_cast::<bind_toolpath::ToolpathHandle>()
            .ok_or_else(|| {
                self.contract("fn toolpath(p) must return a toolpath (new_toolpath(...))".into())
            })?;
        // The script's variables are gone: the handle is the last owner, and
        // the toolpath is moved out rather than copied.
        let mut tp = std::rc::Rc::try_unwrap(handle)
            .map(|c| c.into_inner())
            .unwrap_or_else(|h| h.borrow().clone());
        tp.warnings.extend(compat::take_warnings());
        Ok(tp)
    }

    /// `fn part(p)`, if the script has it: a profile (the body `part`), or
    /// a map of named profiles.
    fn part(&self, values: &Params) -> Result<Vec<PartBody>, FamilyError> {
        if !self.has_fn("part", 1) {
            return Ok(vec![]);
        }
        let d = self.call_with_params("part", values)?;
        let shape = || {
            self.contract(
                "fn part(p) must return a profile or a map of named profiles or solids".into(),
            )
        };
        let geometry = |v: Dynamic| {
            if let Some(p) = v.clone().try_cast::<Profile>() {
                Some(PartGeometry::Revolution(p))
            } else {
                v.try_cast::<crate::family::Swept>()
                    .map(|s| PartGeometry::Swept(Box::new(s)))
            }
        };
        if let Some(g) = geometry(d.clone()) {
            return Ok(vec![PartBody {
                name: "part".into(),
                geometry: g,
            }]);
        }
        let map = d.try_cast::<Map>().ok_or_else(shape)?;
        map.into_iter()
            .map(|(k, v)| {
                geometry(v)
                    .map(|geometry| PartBody {
                        name: k.to_string(),
                        geometry,
                    })
                    .ok_or_else(shape)
            })
            .collect()
    }

    /// `fn verify(p)`, if the script has it: a family's form (each
    /// family's folder reads its own map) or a verification of the
    /// script's own, either with the script's judgement ([`verify`]).
    fn verification(&self, values: &Params) -> Result<Option<Verification>, FamilyError> {
        if !self.has_fn("verify", 1) {
            return Ok(None);
        }
        let d = self.call_with_params("verify", values)?;
        let m = d.try_cast::<Map>().ok_or_else(|| {
            self.contract("fn verify(p) must return a map (the verification's form)".into())
        })?;
        verify::read(&self.script, Self::param_map(values), m)
            .map(Some)
            .map_err(|e| self.contract(e))
    }
}

/// A machine written in Rhai: the script's `fn machine()` returns the
/// machine file's table (the same keys as a `.toml` machine), so a script
/// can compute a machine's geometry; it is read and checked as a machine
/// file is.
///
/// # Failures
/// An unreadable file, a script error, a result that is not a machine
/// file's table, or any error of [`Machine::from_toml_str`].
pub fn machine_from_script(path: &Path) -> Result<Machine, MachineError> {
    let shown = path.display().to_string();
    let io = |message: String| MachineError::Io {
        file: shown.clone(),
        message,
    };
    let source =
        crate::files::read_text(path, crate::files::MAX_TEXT_BYTES).map_err(|e| io(e.message))?;
    let engine = engine(&Limits::default(), &Access::default());
    let ast = engine
        .compile(&source)
        .map_err(|e| io(format!("{}: {}", e.position(), e.err_type())))?;
    let map: Dynamic =
        crate::budget::with_limit(Limits::default().max_seconds, "the script's", || {
            engine.call_fn(&mut Scope::new(), &ast, "machine", ())
        })
        .map_err(|e| io(format!("fn machine(): {e}")))?;
    let value: toml::Value = rhai::serde::from_dynamic(&map)
        .map_err(|e| io(format!("fn machine() must return the machine's table: {e}")))?;
    let text = toml::to_string(&value).map_err(|e| io(e.to_string()))?;
    Machine::from_toml_str(&text, &format!("{shown} (fn machine())"))
}
