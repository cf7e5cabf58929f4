//! Choosing a machine: a built-in name, a plugin library, a TOML file or a
//! Rhai script.

use grinder_3k152vf20::Grinder;
use pilgrim_kernel::machine::BUILTIN_MACHINES;
use pilgrim_kernel::plugin::PluginMachine;
use pilgrim_kernel::{ChainMachine, Machine, MachineKinematics};
use std::path::Path;

/// Opens `spec`: `*.so`/`*.dylib`/`*.dll` (a plugin), `*.toml` (a machine
/// file), `*.rhai` (a script whose `fn machine()` returns the machine file's
/// table as a map), or a built-in's name (the 3K152VF20 is the compiled-in
/// plugin; the others are data machines).
pub fn open(spec: &str) -> Result<Box<dyn MachineKinematics>, String> {
    let path = Path::new(spec);
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "so" | "dylib" | "dll" => Ok(Box::new(PluginMachine::load(path).map_err(|e| e.to_string())?)),
        "toml" => Ok(Box::new(ChainMachine::new(Machine::from_file(path).map_err(|e| e.to_string())?))),
        "rhai" => Ok(Box::new(ChainMachine::new(from_script(path)?))),
        _ if spec.eq_ignore_ascii_case("3K152VF20") => Ok(Box::new(Grinder::new())),
        _ => match Machine::builtin(spec) {
            Ok(m) => Ok(Box::new(ChainMachine::new(m))),
            Err(_) => Err(format!(
                "unknown machine '{spec}': give a built-in ({}), a plugin library (.so), a machine file (.toml) or a machine script (.rhai)",
                BUILTIN_MACHINES.join(", ")
            )),
        },
    }
}

/// A machine written in Rhai: `fn machine()` returns the machine file's
/// table (the same keys as a `.toml` machine), so a script can compute a
/// machine's geometry; it is read and checked as a machine file is.
fn from_script(path: &Path) -> Result<Machine, String> {
    let shown = path.display().to_string();
    let source = std::fs::read_to_string(path).map_err(|e| format!("{shown}: {e}"))?;
    let engine = pilgrim_kernel::script::engine(&Default::default(), &Default::default());
    let ast = engine
        .compile(&source)
        .map_err(|e| format!("{shown}:{}: {}", e.position(), e.err_type()))?;
    let map: rhai::Dynamic = engine
        .call_fn(&mut rhai::Scope::new(), &ast, "machine", ())
        .map_err(|e| format!("{shown}: fn machine(): {e}"))?;
    let value: toml::Value = rhai::serde::from_dynamic(&map)
        .map_err(|e| format!("{shown}: fn machine() must return the machine's table: {e}"))?;
    let text = toml::to_string(&value).map_err(|e| format!("{shown}: {e}"))?;
    Machine::from_toml_str(&text, &format!("{shown} (fn machine())")).map_err(|e| e.to_string())
}
