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
                let plain = Path::new(name)
                    .file_name()
                    .is_some_and(|f| f == std::ffi::OsStr::new(name))
                    && name != "."
                    && name != "..";
                if !plain {
                    return Err(refused());
                }
                if let Some((_, text)) = given.iter().find(|(n, _)| n == name) {
                    return kernel(crate::profile::read_table_str(text, name));
                }
                let found = dirs
                    .iter()
                    .filter_map(|d| d.join(name).canonicalize().ok().map(|c| (d, c)))
                    .find(|(d, c)| c.parent() == Some(d.as_path()) && c.is_file());
                let Some((_, canon)) = found else {
                    return Err(refused());
                };
                log.record(&canon);
                kernel(crate::profile::read_table(&canon))
            },
        );
}
