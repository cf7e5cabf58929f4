//! Tables for scripts: `read_table` (only inside the input directories)
//! and a table's columns, read by header when asked for, so a column of
//! notes is never read as numbers.

use super::floats::{kernel, Floats};
use super::Access;
use crate::profile::Table;
use rhai::plugin::*;
use rhai::{Array, Dynamic, Engine, EvalAltResult};
use std::path::{Path, PathBuf};

/// A table's columns.
#[export_module]
pub mod table_api {
    use super::*;

    /// The numbers of the column `name` (its header, its letter `"B"` or its
    /// number from 1), every data row; an unknown column lists the table's,
    /// a cell that is not a number names its row and column.
    ///
    /// ```rhai
    /// let t = read_table("caliber.csv");
    /// let depth = t["Hp"];
    /// ```
    #[rhai_fn(index_get, pure, return_raw)]
    pub fn column(t: &mut Table, name: &str) -> Result<Floats, Box<EvalAltResult>> {
        kernel(t.column(name)).map(Floats::new)
    }

    /// The cells of the column `name` as text (a column of notes or
    /// names; numbers in their shortest form, empty cells empty).
    ///
    /// ```rhai
    /// let zones = read_table("caliber-groove.csv").texts("zone");
    /// ```
    #[rhai_fn(pure, return_raw)]
    pub fn texts(t: &mut Table, name: &str) -> Result<Array, Box<EvalAltResult>> {
        Ok(kernel(t.texts(name))?
            .into_iter()
            .map(|c| Dynamic::from(crate::files::excerpt(&c)))
            .collect())
    }

    /// The column headers, in order.
    #[rhai_fn(get = "headers", pure)]
    pub fn headers(t: &mut Table) -> Array {
        t.headers()
            .iter()
            .map(|h| Dynamic::from(h.clone()))
            .collect()
    }

    /// Number of data rows.
    #[rhai_fn(get = "rows", pure)]
    pub fn rows(t: &mut Table) -> i64 {
        t.row_count() as i64
    }
}

/// The file `name` directly inside one of `dirs` (canonical), by its
/// plain name: no directory in it, no link leading elsewhere.
fn beside(dirs: &[PathBuf], name: &str) -> Option<PathBuf> {
    let plain = Path::new(name)
        .file_name()
        .is_some_and(|f| f == std::ffi::OsStr::new(name))
        && name != "."
        && name != "..";
    if !plain {
        return None;
    }
    dirs.iter()
        .filter_map(|d| d.join(name).canonicalize().ok().map(|c| (d, c)))
        .find(|(d, c)| c.parent() == Some(d.as_path()) && c.is_file())
        .map(|(_, c)| c)
}

/// The keys `read_dxf(name, options)` reads.
const DXF_KEYS: [&str; 3] = ["layer", "diameter", "chordal"];

/// A DXF drawing's nominal, options read strictly.
fn dxf_profile(
    path: &Path,
    name: &str,
    options: &rhai::Map,
) -> Result<crate::profile::Profile, Box<EvalAltResult>> {
    if let Some(k) = options.keys().find(|k| !DXF_KEYS.contains(&k.as_str())) {
        return Err(format!(
            "read_dxf: unknown key '{}' (keys: {})",
            crate::files::excerpt(k),
            DXF_KEYS.join(", ")
        )
        .into());
    }
    let layer = match options.get("layer") {
        Some(l) => l
            .clone()
            .into_string()
            .map_err(|_| "read_dxf: 'layer' must be text")?,
        None => return Err("read_dxf: give the outline's layer: #{ layer: \"PROFILE\" }".into()),
    };
    let diameter = match options.get("diameter") {
        Some(d) => d
            .as_bool()
            .map_err(|_| "read_dxf: 'diameter' must be true or false")?,
        None => false,
    };
    let chordal = match options.get("chordal") {
        Some(c) => super::floats::number(c).ok_or("read_dxf: 'chordal' must be a number (mm)")?,
        None => DXF_CHORDAL,
    };
    let bytes = kernel(crate::files::read_bytes(path, crate::files::MAX_DATA_BYTES))?;
    let opts = crate::profile::DxfOptions {
        layer,
        diameter,
        chordal,
    };
    kernel(crate::profile::profile_from_dxf(&bytes, name, &opts))
}

/// How far a DXF's splines and arcs may be approximated unless the script
/// says (mm): a tenth of a micron.
const DXF_CHORDAL: crate::math::Real = 1e-4;

/// `read_table(name)`: a file directly inside one of the input
/// directories, by its plain name (no directory in it: a script reads
/// beside itself and beside the parameter file, never below or above).
pub(super) fn register(engine: &mut Engine, access: &Access) {
    let dirs: Vec<PathBuf> = access
        .input_dirs
        .iter()
        .filter_map(|d| d.canonicalize().ok())
        .collect();
    let given = access.tables.clone();
    let log = access.read.clone();
    let dirs_dxf = dirs.clone();
    rhai::FuncRegistration::new("read_table")
        .with_params_info(["name: &str", "Table"])
        .with_comments([
            "/// A table (CSV, XLSX, XLS, ODS) from a file beside the script or beside the",
            "/// parameter file, named by its file name alone (no directory: a script reads",
            "/// nothing below or above those two); the script's directory is looked in",
            "/// first. Its columns are read by header: `t[\"theta\"]`.",
        ])
        .register_into_engine(
            engine,
            move |name: &str| -> Result<Table, Box<EvalAltResult>> {
                // A missing file, one elsewhere, and a link leading
                // elsewhere get the same answer: a script must not learn
                // what lies outside.
                let refused = || -> Box<EvalAltResult> {
                    format!(
                        "{}: not a readable file beside the script or the parameter file (a table is named by its file name alone)",
                        crate::files::excerpt(name)
                    )
                    .into()
                };
                if let Some((_, text)) = given.iter().find(|(n, _)| n == name) {
                    return kernel(crate::profile::read_table_str(text, name));
                }
                let canon = beside(&dirs, name).ok_or_else(refused)?;
                log.record(&canon);
                kernel(crate::profile::read_table(&canon))
            },
        );
    let log_dxf = access.read.clone();
    rhai::FuncRegistration::new("read_dxf")
        .with_params_info(["name: &str", "options: Map", "Profile"])
        .with_comments([
            "/// The nominal a DXF drawing beside the script or the parameter file gives",
            "/// (named by its file name alone): the chain of LWPOLYLINE (bulges as arcs),",
            "/// LINE, ARC and SPLINE on `options.layer`, in the drawing's units",
            "/// (`$INSUNITS`: mm, cm, m or inches), z along the drawing's X, the radius",
            "/// along its Y (`diameter: true`: the diameter), from its origin; the half",
            "/// with Y >= 0 of a full outline, its end faces dropped. `chordal` (mm,",
            "/// default 1e-4): how far a SPLINE's chords and an arc's may stray from it.",
            "/// An open chain, a gap, a face inside the outline, unknown units are",
            "/// refused, naming the entity (type and handle) and where.",
            "///",
            "/// ```rhai",
            "/// let p = read_dxf(\"plug.dxf\", #{ layer: \"PROFILE\" });",
            "/// ```",
        ])
        .register_into_engine(
            engine,
            move |name: &str, options: rhai::Map| -> Result<crate::profile::Profile, Box<EvalAltResult>> {
                let canon = beside(&dirs_dxf, name).ok_or_else(|| -> Box<EvalAltResult> {
                    format!(
                        "{}: not a readable file beside the script or the parameter file (a drawing is named by its file name alone)",
                        crate::files::excerpt(name)
                    )
                    .into()
                })?;
                log_dxf.record(&canon);
                dxf_profile(&canon, name, &options)
            },
        );
}
