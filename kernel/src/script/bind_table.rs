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

/// `read_table(path)`, allowed only inside the input directories.
pub(super) fn register(engine: &mut Engine, access: &Access) {
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
            "/// from the first of them that holds it. Its columns are read by header:",
            "/// `t[\"theta\"]`.",
        ])
        .register_into_engine(
            engine,
            move |path: &str| -> Result<Table, Box<EvalAltResult>> {
                let p = Path::new(path);
                if dirs.is_empty() {
                    return Err("no input directory is open to scripts".into());
                }
                let full = if p.is_absolute() {
                    p.to_owned()
                } else {
                    // The first directory holding it (a script's own example,
                    // or a table beside the parameter file that names it).
                    dirs.iter()
                        .map(|d| d.join(p))
                        .find(|f| f.is_file())
                        .unwrap_or_else(|| dirs[0].join(p))
                };
                // A missing file and one outside get the same answer: a
                // script must not learn what lies outside.
                let refused = || -> Box<EvalAltResult> {
                    format!("{path}: not a readable file inside the input directories").into()
                };
                let canon = full.canonicalize().map_err(|_| refused())?;
                if !dirs.iter().any(|d| canon.starts_with(d)) {
                    return Err(refused());
                }
                kernel(crate::profile::read_table(&canon))
            },
        );
}
