//! Tables of numbers from CSV and spreadsheet files (XLSX, XLS, ODS).
//!
//! Engineers keep profiles and groove tables (`Hp = f1(theta)`,
//! `B = f2(theta)`, docs/math.md §3.1) in spreadsheets. A [`Table`] reads the first
//! sheet (or a CSV file), takes the first row as headers when any of its
//! cells is not a number, and converts a column to numbers only when it is
//! asked for, so a notes column does not get in the way. Every error names
//! the file, the row (as the spreadsheet numbers it, from 1) and the column
//! (letter and header).
//!
//! CSV files may use `,`, `;` or tab as the delimiter (detected from the
//! first line); with `;` or tab, a decimal comma (`12,5`) is accepted.
//! Lines starting with `#` are comments.
//!
//! Bounds: only regular files are read, of at most
//! [`crate::files::MAX_DATA_BYTES`]; a table holds at most [`MAX_CELLS`]
//! cells (its rows' widths added up), checked as it is read: an XLSX sheet
//! is read cell by cell, never as the rectangle its farthest cell spans.
//! Before a zipped workbook (XLSX, ODS) is opened, its parts' inflated size
//! and an ODS sheet's repetitions are bounded ([`super::workbook`]). (An XLS
//! sheet is at most 65,536 x 256 cells by its format.)

use super::{Profile, ProfileError};
use crate::input::InputError;
use crate::math::Real;
use std::path::Path;

/// The most cells a table may hold: 10 million.
pub const MAX_CELLS: usize = 10_000_000;

/// Errors reading tables; each names the file, and the row and column where
/// there is one.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TableError {
    /// The file could not be read or parsed as its format.
    #[error("{file}: {message}")]
    Read {
        /// The file.
        file: String,
        /// What went wrong.
        message: String,
    },
    /// The file's extension names no format this reader knows.
    #[error(
        "{file}: unknown table format '{extension}' (use .csv, .txt, .xlsx, .xlsm, .xls or .ods)"
    )]
    UnknownFormat {
        /// The file.
        file: String,
        /// Its extension.
        extension: String,
    },
    /// No data rows.
    #[error("{file}: the table has no data rows")]
    Empty {
        /// The file.
        file: String,
    },
    /// A column asked for is not in the table.
    #[error("{file}: no column '{column}' (columns: {available})")]
    UnknownColumn {
        /// The file.
        file: String,
        /// The name asked for.
        column: String,
        /// The columns there are.
        available: String,
    },
    /// A cell in a used column is empty.
    #[error("{file}, row {row}, column {column}: the cell is empty")]
    MissingCell {
        /// The file.
        file: String,
        /// Row number (from 1, as the spreadsheet shows it).
        row: usize,
        /// Column letter and header.
        column: String,
    },
    /// A cell in a used column is not a number.
    #[error("{file}, row {row}, column {column}: '{text}' is not a number")]
    NotNumber {
        /// The file.
        file: String,
        /// Row number (from 1).
        row: usize,
        /// Column letter and header.
        column: String,
        /// The cell's text.
        text: String,
    },
    /// A value that is a number but not acceptable where it stands.
    #[error("{file}, row {row}, column {column}: {message}")]
    BadValue {
        /// The file.
        file: String,
        /// Row number (from 1).
        row: usize,
        /// Column letter and header.
        column: String,
        /// Why.
        message: String,
    },
}

/// The formats [`read_table`] reads, chosen by extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableFormat {
    /// Comma-, semicolon- or tab-separated text (`.csv`, `.txt`, `.tsv`).
    Csv,
    /// A spreadsheet (`.xlsx`, `.xlsm`, `.xls`, `.ods`), first sheet.
    Spreadsheet,
}

impl TableFormat {
    /// The format for a path's extension.
    pub fn of(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "csv" | "txt" | "tsv" => Some(Self::Csv),
            "xlsx" | "xlsm" | "xls" | "xlsb" | "ods" => Some(Self::Spreadsheet),
            _ => None,
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Cell {
    Number(Real),
    Text(String),
    Empty,
}

/// A table of cells with optional headers. See the module docs (`profile::table`).
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    source: String,
    headers: Vec<String>,
    /// (row number from 1, cells)
    rows: Vec<(usize, Vec<Cell>)>,
}

/// Reads a table from a file, by its extension.
///
/// # Failures
/// An unreadable file, an unknown extension, a malformed file, or a table
/// with no data rows.
pub fn read_table(path: impl AsRef<Path>) -> Result<Table, TableError> {
    let path = path.as_ref();
    let file = path.display().to_string();
    format_of(path, &file)?;
    let bytes = crate::files::read_bytes(path, crate::files::MAX_DATA_BYTES).map_err(|e| {
        TableError::Read {
            file: file.clone(),
            message: e.message,
        }
    })?;
    read_table_bytes(&bytes, &file)
}

/// The format a file's extension names.
fn format_of(path: &Path, file: &str) -> Result<TableFormat, TableError> {
    TableFormat::of(path).ok_or_else(|| TableError::UnknownFormat {
        file: file.to_owned(),
        extension: path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_owned(),
    })
}

/// Reads a table from a file's bytes; `file` names it in errors and its
/// extension gives the format.
///
/// # Failures
/// As [`read_table`], but for reading the file.
pub fn read_table_bytes(bytes: &[u8], file: &str) -> Result<Table, TableError> {
    match format_of(Path::new(file), file)? {
        TableFormat::Csv => read_table_str(&String::from_utf8_lossy(bytes), file),
        TableFormat::Spreadsheet => read_spreadsheet(bytes, file.to_owned()),
    }
}

/// Parses CSV text; `source` names it in errors.
pub fn read_table_str(text: &str, source: &str) -> Result<Table, TableError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let first = text
        .lines()
        .find(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .unwrap_or("");
    let delimiter = [b';', b'\t', b',']
        .into_iter()
        .max_by_key(|d| {
            first.bytes().filter(|b| b == d).count() * 4
                + usize::from(*d == b';') * 2
                + usize::from(*d == b'\t')
        })
        .unwrap_or(b',');
    let decimal_comma = delimiter != b',';
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .delimiter(delimiter)
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let mut rows = Vec::new();
    let mut cells_read = 0usize;
    for rec in reader.records() {
        let rec = rec.map_err(|e| TableError::Read {
            file: source.to_owned(),
            message: crate::files::excerpt(&e.to_string()),
        })?;
        cells_read += rec.len();
        check_cells(cells_read, source)?;
        let line = rec.position().map_or(0, |p| p.line() as usize);
        let cells = rec
            .iter()
            .map(|s| {
                if s.is_empty() {
                    Cell::Empty
                } else {
                    let t = if decimal_comma {
                        s.replace(',', ".")
                    } else {
                        s.to_owned()
                    };
                    match t.parse::<Real>() {
                        Ok(v) => Cell::Number(v),
                        Err(_) => Cell::Text(s.to_owned()),
                    }
                }
            })
            .collect();
        rows.push((line, cells));
    }
    Table::from_rows(source.to_owned(), rows)
}

/// An error once a table has more than [`MAX_CELLS`] cells.
fn check_cells(n: usize, file: &str) -> Result<(), TableError> {
    if n > MAX_CELLS {
        return Err(TableError::Read {
            file: file.to_owned(),
            message: format!("the table has more than {MAX_CELLS} cells"),
        });
    }
    Ok(())
}

/// A spreadsheet cell as the table keeps it.
fn cell_of(c: &calamine::Data) -> Cell {
    use calamine::Data;
    match c {
        Data::Int(v) => Cell::Number(*v as Real),
        Data::Float(v) => Cell::Number(*v),
        Data::Empty => Cell::Empty,
        Data::String(s) => match s.trim().parse::<Real>() {
            Ok(v) => Cell::Number(v),
            Err(_) if s.trim().is_empty() => Cell::Empty,
            Err(_) => Cell::Text(s.clone()),
        },
        other => Cell::Text(other.to_string()),
    }
}

/// Rows of `(row, column, cell)` triples, in any order, as the table's rows
/// (numbered from 1), each as wide as its farthest cell; bounded by
/// [`MAX_CELLS`] as they are laid out.
fn rows_of(
    mut cells: Vec<(u32, u32, Cell)>,
    file: &str,
) -> Result<Vec<(usize, Vec<Cell>)>, TableError> {
    cells.sort_by_key(|c| (c.0, c.1));
    let mut rows: Vec<(usize, Vec<Cell>)> = Vec::new();
    let mut total = 0usize;
    for (r, c, cell) in cells {
        if cell == Cell::Empty {
            continue;
        }
        if rows.last().is_none_or(|(n, _)| *n != r as usize + 1) {
            rows.push((r as usize + 1, Vec::new()));
        }
        let row = &mut rows.last_mut().expect("pushed above").1;
        let width = c as usize + 1;
        total += width.saturating_sub(row.len());
        check_cells(total, file)?;
        row.resize(width.max(row.len()), Cell::Empty);
        row[c as usize] = cell;
    }
    Ok(rows)
}

fn read_spreadsheet(bytes: &[u8], file: String) -> Result<Table, TableError> {
    use calamine::{Reader, Sheets};
    let read_err = |e: &dyn std::fmt::Display| TableError::Read {
        file: file.clone(),
        message: crate::files::excerpt(&e.to_string()),
    };
    super::workbook::check(bytes, &file)?;
    let mut book = calamine::open_workbook_auto_from_rs(std::io::Cursor::new(bytes))
        .map_err(|e| read_err(&e))?;
    let first = book
        .sheet_names()
        .first()
        .cloned()
        .ok_or_else(|| read_err(&"the workbook has no sheets"))?;
    let mut cells = Vec::new();
    if let Sheets::Xlsx(xlsx) = &mut book {
        // Cell by cell: a far cell must not make a rectangle of cells.
        let mut reader = xlsx
            .worksheet_cells_reader(&first)
            .map_err(|e| read_err(&e))?;
        while let Some(c) = reader.next_cell().map_err(|e| read_err(&e))? {
            let (r, col) = c.get_position();
            let data: calamine::Data = c.get_value().clone().into();
            cells.push((r, col, cell_of(&data)));
            check_cells(cells.len(), &file)?;
        }
    } else {
        let range = book.worksheet_range(&first).map_err(|e| read_err(&e))?;
        check_cells(range.get_size().0.saturating_mul(range.get_size().1), &file)?;
        for (r, c, d) in range.used_cells() {
            let (row0, col0) = range.start().unwrap_or((0, 0));
            cells.push((row0 + r as u32, col0 + c as u32, cell_of(d)));
        }
    }
    Table::from_rows(file.clone(), rows_of(cells, &file)?)
}

/// Spreadsheet column letters: 0 -> A, 25 -> Z, 26 -> AA.
fn column_letter(mut i: usize) -> String {
    let mut s = Vec::new();
    loop {
        s.push(b'A' + (i % 26) as u8);
        if i < 26 {
            break;
        }
        i = i / 26 - 1;
    }
    s.reverse();
    String::from_utf8(s).unwrap_or_default()
}

impl Table {
    fn from_rows(source: String, mut rows: Vec<(usize, Vec<Cell>)>) -> Result<Self, TableError> {
        rows.retain(|(_, cells)| cells.iter().any(|c| *c != Cell::Empty));
        let mut headers = Vec::new();
        if let Some((_, first)) = rows.first() {
            if first.iter().any(|c| matches!(c, Cell::Text(_))) {
                headers = first
                    .iter()
                    .map(|c| match c {
                        Cell::Text(t) => t.trim().to_owned(),
                        Cell::Number(v) => v.to_string(),
                        Cell::Empty => String::new(),
                    })
                    .collect();
                rows.remove(0);
            }
        }
        if rows.is_empty() {
            return Err(TableError::Empty { file: source });
        }
        Ok(Self {
            source,
            headers,
            rows,
        })
    }

    /// Where the table came from (a file name).
    pub fn source(&self) -> &str {
        &self.source
    }

    /// The table's content as a SHA-256 digest (hex): its headers and
    /// cells, each number by its bits, in order; not its source's name or
    /// format, nor its blank rows (the same measurement saved as CSV or as
    /// a workbook has one digest).
    pub fn digest(&self) -> String {
        use sha2::{Digest, Sha256};
        let mut h = Sha256::new();
        for name in &self.headers {
            h.update(b"h");
            h.update((name.len() as u64).to_le_bytes());
            h.update(name.as_bytes());
        }
        for (_, cells) in &self.rows {
            h.update(b"r");
            for c in cells {
                match c {
                    Cell::Number(v) => {
                        h.update(b"n");
                        h.update(v.to_bits().to_le_bytes());
                    }
                    Cell::Text(s) => {
                        h.update(b"t");
                        h.update((s.len() as u64).to_le_bytes());
                        h.update(s.as_bytes());
                    }
                    Cell::Empty => h.update(b"e"),
                }
            }
        }
        h.finalize().iter().map(|b| format!("{b:02x}")).collect()
    }

    /// The table of only the columns `mapping` names, each `(name, column)`
    /// taking the column given by header, letter or number
    /// ([`Self::column_index`]) under the header `name`: a measuring
    /// program's own column names read under the ones a reader asks for.
    /// Rows keep their numbers, so a bad cell is still named by the file's
    /// row; the source names the columns mapped.
    ///
    /// # Failures
    /// A column the table does not have, or one mapped twice.
    pub fn mapped(&self, mapping: &[(String, String)]) -> Result<Table, TableError> {
        let mut cols = Vec::with_capacity(mapping.len());
        for (name, column) in mapping {
            let i = self.column_index(column)?;
            if let Some(k) = cols.iter().position(|&c| c == i) {
                return Err(TableError::UnknownColumn {
                    file: self.source.clone(),
                    column: format!(
                        "{} for {} (already read for {})",
                        self.column_label(i),
                        crate::files::excerpt(name),
                        crate::files::excerpt(&mapping[k].0)
                    ),
                    available: "each column once".into(),
                });
            }
            cols.push(i);
        }
        let shown: Vec<String> = (mapping.iter().zip(&cols))
            .map(|((name, _), &i)| {
                format!(
                    "{} as {}",
                    self.column_label(i),
                    crate::files::excerpt(name)
                )
            })
            .collect();
        Ok(Table {
            source: format!("{} ({})", self.source, shown.join(", ")),
            headers: mapping.iter().map(|(n, _)| n.clone()).collect(),
            rows: (self.rows.iter())
                .map(|(n, cells)| {
                    let row = cols
                        .iter()
                        .map(|&i| cells.get(i).cloned().unwrap_or(Cell::Empty));
                    (*n, row.collect())
                })
                .collect(),
        })
    }

    /// The header row (empty if the first row held numbers only).
    pub fn headers(&self) -> &[String] {
        &self.headers
    }

    /// Number of data rows.
    pub fn row_count(&self) -> usize {
        self.rows.len()
    }

    /// The row number (from 1, as the file shows it) of data row `i`.
    pub fn row_number(&self, i: usize) -> usize {
        self.rows.get(i).map_or(0, |r| r.0)
    }

    fn width(&self) -> usize {
        self.rows
            .iter()
            .map(|r| r.1.len())
            .chain([self.headers.len()])
            .max()
            .unwrap_or(0)
    }

    /// `B (Hp)`: the column's letter, and its header if it has one.
    pub fn column_label(&self, col: usize) -> String {
        match self.headers.get(col).filter(|h| !h.is_empty()) {
            Some(h) => format!("{} ({})", column_letter(col), crate::files::excerpt(h)),
            None => column_letter(col),
        }
    }

    /// The index of a column given by header (case-insensitive), letter
    /// (`"B"`) or number from 1 (`"2"`).
    pub fn column_index(&self, name: &str) -> Result<usize, TableError> {
        let key = name.trim();
        let width = self.width();
        if let Some(i) = self
            .headers
            .iter()
            .position(|h| h.eq_ignore_ascii_case(key))
        {
            return Ok(i);
        }
        if let Ok(n) = key.parse::<usize>() {
            if (1..=width).contains(&n) {
                return Ok(n - 1);
            }
        }
        if let Some(i) = (0..width).find(|&i| column_letter(i).eq_ignore_ascii_case(key)) {
            return Ok(i);
        }
        Err(TableError::UnknownColumn {
            file: self.source.clone(),
            column: crate::files::excerpt(name),
            available: crate::files::excerpt(
                &(0..width.min(64))
                    .map(|i| self.column_label(i))
                    .collect::<Vec<_>>()
                    .join(", "),
            ),
        })
    }

    /// The numbers of one column, every data row.
    ///
    /// # Failures
    /// An unknown column; an empty, non-numeric or non-finite cell (named
    /// by row and column).
    pub fn column(&self, name: &str) -> Result<Vec<Real>, TableError> {
        let col = self.column_index(name)?;
        self.rows
            .iter()
            .map(
                |(row, cells)| match cells.get(col).unwrap_or(&Cell::Empty) {
                    Cell::Number(v) if v.is_finite() => Ok(*v),
                    Cell::Number(v) => Err(TableError::BadValue {
                        file: self.source.clone(),
                        row: *row,
                        column: self.column_label(col),
                        message: format!("{v} is not a finite number"),
                    }),
                    Cell::Text(t) => Err(TableError::NotNumber {
                        file: self.source.clone(),
                        row: *row,
                        column: self.column_label(col),
                        text: crate::files::excerpt(t),
                    }),
                    Cell::Empty => Err(TableError::MissingCell {
                        file: self.source.clone(),
                        row: *row,
                        column: self.column_label(col),
                    }),
                },
            )
            .collect()
    }

    /// The numbers of one column where its cells hold one, none where
    /// they are empty (a column a row may leave blank, as a tool table's
    /// optional sizes).
    ///
    /// # Failures
    /// An unknown column; a cell that is text or not finite (named by row
    /// and column).
    pub fn optional(&self, name: &str) -> Result<Vec<Option<Real>>, TableError> {
        let col = self.column_index(name)?;
        let blank = |(_, cells): &&(usize, Vec<Cell>)| {
            matches!(cells.get(col).unwrap_or(&Cell::Empty), Cell::Empty)
        };
        let filled = Table {
            source: self.source.clone(),
            headers: self.headers.clone(),
            rows: self.rows.iter().filter(|r| !blank(r)).cloned().collect(),
        };
        let mut numbers = filled.column(name)?.into_iter();
        Ok(self
            .rows
            .iter()
            .map(|r| if blank(&r) { None } else { numbers.next() })
            .collect())
    }

    /// The cells of one column as text, every data row (numbers as
    /// written by Rust's shortest form, empty cells empty): a column of
    /// notes or names, such as a groove table's zones.
    ///
    /// # Failures
    /// An unknown column.
    pub fn texts(&self, name: &str) -> Result<Vec<String>, TableError> {
        let col = self.column_index(name)?;
        Ok(self
            .rows
            .iter()
            .map(|(_, cells)| match cells.get(col).unwrap_or(&Cell::Empty) {
                Cell::Number(v) => v.to_string(),
                Cell::Text(t) => t.trim().to_owned(),
                Cell::Empty => String::new(),
            })
            .collect())
    }

    /// A profile from two columns: `z` (must increase strictly) and `x`.
    ///
    /// # Failures
    /// As [`Self::column`]; z not increasing or fewer than 3 rows, named by
    /// row and column.
    pub fn profile(&self, z_column: &str, x_column: &str) -> Result<Profile, TableError> {
        let z = self.column(z_column)?;
        let x = self.column(x_column)?;
        let zc = self.column_index(z_column)?;
        Profile::new(z, x).map_err(|e| match e {
            ProfileError::Input(InputError::NotIncreasing {
                index, prev, value, ..
            }) => TableError::BadValue {
                file: self.source.clone(),
                row: self.row_number(index),
                column: self.column_label(zc),
                message: format!("{value} does not increase on the row before ({prev})"),
            },
            other => TableError::Read {
                file: self.source.clone(),
                message: other.to_string(),
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn letters() {
        assert_eq!(column_letter(0), "A");
        assert_eq!(column_letter(25), "Z");
        assert_eq!(column_letter(26), "AA");
        assert_eq!(column_letter(27), "AB");
        assert_eq!(column_letter(701), "ZZ");
        assert_eq!(column_letter(702), "AAA");
    }

    #[test]
    fn csv_with_headers_comments_and_decimal_commas() {
        let t = read_table_str(
            "# groove\ntheta;Hp;B;note\n0;5,5;12;a\n1;5,6;12,1;\n\n2;5,7;12,2;x\n",
            "g.csv",
        )
        .unwrap();
        assert_eq!(t.headers(), ["theta", "Hp", "B", "note"]);
        assert_eq!(t.column("hp").unwrap(), vec![5.5, 5.6, 5.7]);
        assert_eq!(t.column("C").unwrap(), vec![12.0, 12.1, 12.2]);
        assert_eq!(t.column("1").unwrap(), vec![0.0, 1.0, 2.0]);
        let e = t.column("note").unwrap_err().to_string();
        assert_eq!(e, "g.csv, row 3, column D (note): 'a' is not a number");
        let e = t.column("depth").unwrap_err().to_string();
        assert!(
            e.contains("no column 'depth'") && e.contains("B (Hp)"),
            "{e}"
        );
    }

    #[test]
    fn missing_cells_and_bad_z_name_row_and_column() {
        let t = read_table_str("z,x\n0,1\n1,\n2,3\n", "p.csv").unwrap();
        assert_eq!(
            t.column("x").unwrap_err().to_string(),
            "p.csv, row 3, column B (x): the cell is empty"
        );
        let t = read_table_str("0,1\n1,2\n0.5,3\n", "q.csv").unwrap();
        let e = t.profile("A", "B").unwrap_err().to_string();
        assert!(e.contains("q.csv, row 3, column A"), "{e}");
        assert!(matches!(
            read_table_str("a,b\n", "e.csv"),
            Err(TableError::Empty { .. })
        ));
        let e = read_table("x.dwg").unwrap_err().to_string();
        assert!(e.contains("unknown table format 'dwg'"), "{e}");
        let e = read_table("no/such/file.csv").unwrap_err().to_string();
        assert!(e.starts_with("no/such/file.csv: "), "{e}");
    }
}
