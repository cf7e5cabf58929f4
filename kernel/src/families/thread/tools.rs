//! The shop's threading tools as data: a table (CSV or a spreadsheet, as
//! `read_table` reads it) of external cutters and boring bars, one a
//! row, from which the family picks the largest that fits the thread.
//! A row says what the tool cuts (outside or inside, the profiles its
//! inserts carry, a pitch range, how deep its edge reaches, the least
//! diameter or bore it works in, the longest thread) and its own sizes of
//! the machine's bodies that ride with it (columns `body:<constant>`: its
//! holder's, its bar's), which the run places those bodies with.
//!
//! The columns, by header:
//!
//! | column | what |
//! |---|---|
//! | `name` | the tool's name (it reaches the program's comments) |
//! | `number` | its tool number (T word), 0 to 99 |
//! | `side` | `external` (a cutter on a holder) or `internal` (on a boring bar) |
//! | `profile_deg` | the included angles its inserts come in, space-separated (`60`, `55 60`); empty: ground to the thread's own profile |
//! | `pitch_min_mm`, `pitch_max_mm` | the pitches it cuts |
//! | `nose_mm` | its nose radius; empty: the standard's root rounding (a full-profile insert of the pitch) |
//! | `depth_mm` | the deepest thread its edge reaches (beyond the holder, past the bar) |
//! | `shank_mm` | its holder's shank or its bar's diameter: the largest that fits is picked |
//! | `least_diameter_mm` | external: the least major it cuts (its turret clear of the chuck); internal: the least bore it enters |
//! | `longest_mm` | the longest thread it reaches along; empty: any |
//! | `body:<constant>` | its value of the machine constant `<constant>` sizing a body that rides with it; empty: the machine's |

use super::standards::number;
use crate::math::Real;
use crate::profile::{Table, TableError};
use std::collections::BTreeMap;

/// The prefix of a column that gives a tool's size of a body riding with
/// it, followed by the machine constant's name.
pub const BODY_COLUMN: &str = "body:";

/// How near an insert's included angle must be to the thread's (deg).
const SAME_ANGLE_DEG: Real = 0.01;

/// One tool of a table.
#[derive(Debug, Clone, PartialEq)]
pub struct TableTool {
    /// The row as the file numbers it (from 1, the header's included).
    pub row: usize,
    /// Its name.
    pub name: String,
    /// Its tool number.
    pub number: u32,
    /// It cuts inside a bore, on a boring bar.
    pub inside: bool,
    /// The included angles its inserts come in (deg); empty: ground to
    /// any profile.
    pub profiles: Vec<Real>,
    /// The pitches it cuts, least and most (mm).
    pub pitch: [Real; 2],
    /// Its nose radius (mm); none: the standard's root rounding.
    pub nose: Option<Real>,
    /// The deepest thread its edge reaches (mm).
    pub depth: Real,
    /// Its shank's or bar's size (mm).
    pub shank: Real,
    /// The least major (external) or bore (internal) it works on (mm).
    pub least_diameter: Real,
    /// The longest thread it reaches along (mm); none: any.
    pub longest: Option<Real>,
    /// Its sizes of the machine's bodies riding with it, by constant.
    pub bodies: BTreeMap<String, Real>,
}

/// A table of tools, as read.
#[derive(Debug, Clone, PartialEq)]
pub struct ToolTable {
    /// Where it was read from.
    pub source: String,
    /// Its tools, in the table's order.
    pub tools: Vec<TableTool>,
}

/// What a thread asks of the tool that cuts it.
#[derive(Debug, Clone, PartialEq)]
pub struct Need {
    /// The thread's designation, for a message.
    pub thread: String,
    /// It is cut inside a bore.
    pub inside: bool,
    /// Its flanks' included angle (deg); none: curved flanks, which only a
    /// tool ground to them cuts.
    pub included: Option<Real>,
    /// Its pitch (mm).
    pub pitch: Real,
    /// Its depth from crest to root (mm).
    pub depth: Real,
    /// Its crest's diameter: external the major, internal the bore (mm).
    pub diameter: Real,
    /// Its length (mm).
    pub length: Real,
}

/// A tool table that cannot be read, or one with no tool that fits.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ToolError {
    /// The table itself: a missing column, a cell that is no number.
    #[error(transparent)]
    Table(#[from] TableError),
    /// A row's cell that is not what its column takes.
    #[error("{file}, row {row}, column {column}: {message}")]
    Cell {
        /// The table.
        file: String,
        /// The row, as the file numbers it.
        row: usize,
        /// The column's header.
        column: String,
        /// What is wrong.
        message: String,
    },
    /// No tool of the table fits the thread.
    #[error("no tool of {file} cuts {thread} ({need}): {nearest}; add a row to {file} for a tool that does, or name the shop's own table")]
    NoneFits {
        /// The table.
        file: String,
        /// The thread.
        thread: String,
        /// What the thread asks, in words.
        need: String,
        /// The nearest tool and what it lacks, in words.
        nearest: String,
    },
}

/// The numeric columns of a tool table, in the order [`Columns::numbers`]
/// holds them.
const NUMBER_COLUMNS: [&str; 7] = [
    "pitch_min_mm",
    "pitch_max_mm",
    "nose_mm",
    "depth_mm",
    "shank_mm",
    "least_diameter_mm",
    "longest_mm",
];

/// A tool table's columns, read whole.
struct Columns {
    file: String,
    names: Vec<String>,
    numbers: Vec<Real>,
    sides: Vec<String>,
    profiles: Vec<String>,
    /// [`NUMBER_COLUMNS`]' cells, empty ones none.
    sizes: Vec<Vec<Option<Real>>>,
    /// Each `body:` column: the constant's name and its cells.
    bodies: Vec<(String, Vec<Option<Real>>)>,
}

impl Columns {
    fn of(table: &Table) -> Result<Self, ToolError> {
        let file = table.source().to_owned();
        Ok(Self {
            names: table.texts("name")?,
            numbers: table.column("number")?,
            sides: table.texts("side")?,
            profiles: table.texts("profile_deg")?,
            sizes: NUMBER_COLUMNS
                .iter()
                .map(|c| table.optional(c))
                .collect::<Result<_, _>>()?,
            bodies: table
                .headers()
                .iter()
                .filter_map(|h| h.strip_prefix(BODY_COLUMN).map(|c| (h, c)))
                .map(|(h, c)| table.optional(h).map(|v| (c.trim().to_owned(), v)))
                .collect::<Result<_, _>>()?,
            file,
        })
    }

    fn cell(&self, row: usize, column: &str, message: String) -> ToolError {
        ToolError::Cell {
            file: self.file.clone(),
            row,
            column: column.to_owned(),
            message,
        }
    }

    /// Data row `i`, numbered `row` as the file numbers it.
    fn tool(&self, i: usize, row: usize) -> Result<TableTool, ToolError> {
        let size = |k: usize| self.sizes[k][i];
        let needed = |k: usize| {
            size(k).ok_or_else(|| {
                let empty = "the cell is empty: the column needs a value".to_owned();
                self.cell(row, NUMBER_COLUMNS[k], empty)
            })
        };
        let positive = |v: Real, c: &str| {
            if v > 0.0 {
                Ok(v)
            } else {
                Err(self.cell(row, c, format!("{v} must be more than 0 (mm)")))
            }
        };
        let name = &self.names[i];
        crate::names::check_name("tool name", name)
            .map_err(|e| self.cell(row, "name", e.to_string()))?;
        let number = self.numbers[i];
        if !(number.fract() == 0.0 && (0.0..=99.0).contains(&number)) {
            let message = format!("{number} is not a tool number 0 to 99");
            return Err(self.cell(row, "number", message));
        }
        let pitch = [needed(0)?, needed(1)?];
        if !(pitch[0] > 0.0 && pitch[0] <= pitch[1]) {
            let message = format!("the pitches {} to {} are no range", pitch[0], pitch[1]);
            return Err(self.cell(row, "pitch_max_mm", message));
        }
        let bodies = self
            .bodies
            .iter()
            .filter_map(|(c, v)| v[i].map(|x| (c.clone(), x)))
            .map(|(c, x)| positive(x, &format!("{BODY_COLUMN}{c}")).map(|x| (c, x)))
            .collect::<Result<_, _>>()?;
        Ok(TableTool {
            row,
            name: name.clone(),
            number: number as u32,
            inside: self.side(i, row)?,
            profiles: self.angles(i, row)?,
            pitch,
            nose: size(2).map(|v| positive(v, "nose_mm")).transpose()?,
            depth: positive(needed(3)?, "depth_mm")?,
            shank: positive(needed(4)?, "shank_mm")?,
            least_diameter: needed(5)?.max(0.0),
            longest: size(6).map(|v| positive(v, "longest_mm")).transpose()?,
            bodies,
        })
    }

    /// Whether row `i` cuts inside a bore.
    fn side(&self, i: usize, row: usize) -> Result<bool, ToolError> {
        match self.sides[i].to_ascii_lowercase().as_str() {
            "external" => Ok(false),
            "internal" => Ok(true),
            other => Err(self.cell(
                row,
                "side",
                format!(
                    "'{}' is not external or internal",
                    crate::files::excerpt(other)
                ),
            )),
        }
    }

    /// Row `i`'s included angles.
    fn angles(&self, i: usize, row: usize) -> Result<Vec<Real>, ToolError> {
        self.profiles[i]
            .split_whitespace()
            .map(|a| match a.parse::<Real>() {
                Ok(v) if v > 0.0 && v < 180.0 => Ok(v),
                _ => Err(self.cell(
                    row,
                    "profile_deg",
                    format!(
                        "'{}' is not an included angle in degrees (0 to 180)",
                        crate::files::excerpt(a)
                    ),
                )),
            })
            .collect()
    }
}

impl ToolTable {
    /// The tools of `table`, every row checked.
    ///
    /// # Failures
    /// A missing column; a cell that is empty where its column needs a
    /// value, not a number, or out of range (named by row and column).
    pub fn read(table: &Table) -> Result<Self, ToolError> {
        let columns = Columns::of(table)?;
        let tools = (0..table.row_count())
            .map(|i| columns.tool(i, table.row_number(i)))
            .collect::<Result<_, _>>()?;
        Ok(Self {
            source: columns.file,
            tools,
        })
    }

    /// The largest tool (by its shank) that cuts the thread `need`
    /// describes, the first in the table among equals.
    ///
    /// # Failures
    /// None fits: the message names the nearest tool of the thread's side
    /// and what it lacks.
    pub fn pick(&self, need: &Need) -> Result<&TableTool, ToolError> {
        let fitting = self
            .tools
            .iter()
            .filter(|t| t.shortfalls(need).is_empty())
            .fold(None::<&TableTool>, |best, t| match best {
                Some(b) if b.shank >= t.shank => Some(b),
                _ => Some(t),
            });
        if let Some(t) = fitting {
            return Ok(t);
        }
        let nearest = self
            .tools
            .iter()
            .filter(|t| t.inside == need.inside)
            .map(|t| (t, t.shortfalls(need)))
            .min_by(|(_, a), (_, b)| {
                let by = |s: &[(String, Real)]| (s.len(), s.iter().map(|x| x.1).sum::<Real>());
                let (ka, kb) = (by(a), by(b));
                ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1))
            })
            .map_or_else(
                || {
                    format!(
                        "the table has no {} tool",
                        if need.inside { "internal" } else { "external" }
                    )
                },
                |(t, lacks)| {
                    format!(
                        "the nearest, row {} '{}', {}",
                        t.row,
                        crate::files::excerpt(&t.name),
                        lacks
                            .iter()
                            .map(|l| l.0.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                },
            );
        Err(ToolError::NoneFits {
            file: self.source.clone(),
            thread: need.thread.clone(),
            need: need.words(),
            nearest,
        })
    }
}

impl TableTool {
    /// What the tool lacks for the thread `need` describes, each in words
    /// with how far it falls short, as a share of what is asked (1 where
    /// it is not a matter of size); empty: it fits.
    pub fn shortfalls(&self, need: &Need) -> Vec<(String, Real)> {
        let mut out = Vec::new();
        let short =
            |have: Real, want: Real| (have - want).abs() / want.abs().max(Real::MIN_POSITIVE);
        if self.inside != need.inside {
            let side = if self.inside {
                "cuts inside a bore"
            } else {
                "cuts outside"
            };
            out.push((side.to_owned(), 1.0));
        }
        let carries = |a: Real| self.profiles.iter().any(|p| (p - a).abs() < SAME_ANGLE_DEG);
        match need.included {
            _ if self.profiles.is_empty() => {}
            Some(a) if carries(a) => {}
            Some(a) => out.push((
                format!(
                    "carries inserts of {} deg, not {}",
                    angles(&self.profiles),
                    number(a)
                ),
                1.0,
            )),
            None => out.push((
                "carries straight inserts, not curved flanks".to_owned(),
                1.0,
            )),
        }
        if need.pitch < self.pitch[0] || need.pitch > self.pitch[1] {
            let off = short(need.pitch.clamp(self.pitch[0], self.pitch[1]), need.pitch);
            out.push((
                format!(
                    "cuts pitches {} to {} mm, not {}",
                    number(self.pitch[0]),
                    number(self.pitch[1]),
                    number(need.pitch)
                ),
                off,
            ));
        }
        if need.depth > self.depth {
            out.push((
                format!(
                    "reaches {} mm deep, the thread {}",
                    number(self.depth),
                    number(need.depth)
                ),
                short(self.depth, need.depth),
            ));
        }
        if need.diameter < self.least_diameter {
            out.push((
                format!(
                    "needs {} of {} mm or more, the thread's is {}",
                    if need.inside { "a bore" } else { "a major" },
                    number(self.least_diameter),
                    number(need.diameter)
                ),
                short(self.least_diameter, need.diameter),
            ));
        }
        if let Some(l) = self.longest.filter(|&l| need.length > l) {
            out.push((
                format!(
                    "reaches {} mm along, the thread is {} long",
                    number(l),
                    number(need.length)
                ),
                short(l, need.length),
            ));
        }
        out
    }
}

impl Need {
    /// What the thread asks, in words.
    fn words(&self) -> String {
        format!(
            "{}, {}, pitch {} mm, {} mm deep, {} {} mm, {} mm long",
            if self.inside { "internal" } else { "external" },
            self.included
                .map_or("curved flanks".to_owned(), |a| format!("{} deg", number(a))),
            number(self.pitch),
            number(self.depth),
            if self.inside { "bore" } else { "major" },
            number(self.diameter),
            number(self.length)
        )
    }
}

fn angles(a: &[Real]) -> String {
    a.iter()
        .map(|v| number(*v))
        .collect::<Vec<_>>()
        .join(" or ")
}

#[cfg(test)]
mod tests {
    use super::*;

    const TABLE: &str = "name,number,side,profile_deg,pitch_min_mm,pitch_max_mm,nose_mm,depth_mm,shank_mm,least_diameter_mm,longest_mm,body:bar_radius,body:bar_tip\n\
        holder 25,1,external,60,0.5,3,,1.9,25,10,,,\n\
        holder 20,5,external,55 60,0.5,3,0.1,1.9,20,0,,,\n\
        bar 16,2,internal,60,0.5,3,,1.9,16,20,70,8,10\n\
        bar 8,4,internal,60,0.5,2,,1.2,8,10,40,4,5.3\n";

    fn table() -> ToolTable {
        ToolTable::read(&crate::profile::read_table_str(TABLE, "tools.csv").unwrap()).unwrap()
    }

    fn need(inside: bool, diameter: Real) -> Need {
        Need {
            thread: "M".into(),
            inside,
            included: Some(60.0),
            pitch: 1.5,
            depth: 0.9,
            diameter,
            length: 30.0,
        }
    }

    /// The largest that fits is picked; a smaller major or bore takes the
    /// smaller tool; its sizes of the bodies are the row's.
    #[test]
    fn the_largest_tool_that_fits_is_picked() {
        let t = table();
        assert_eq!(t.pick(&need(false, 12.0)).unwrap().name, "holder 25");
        assert_eq!(t.pick(&need(false, 8.0)).unwrap().name, "holder 20");
        let bar = t.pick(&need(true, 27.8)).unwrap();
        assert_eq!((bar.name.as_str(), bar.row), ("bar 16", 4));
        assert_eq!(bar.bodies["bar_tip"], 10.0);
        let small = t.pick(&need(true, 10.4)).unwrap();
        assert_eq!(small.bodies.get("bar_radius"), Some(&4.0));
        assert_eq!(t.tools[1].profiles, vec![55.0, 60.0]);
        assert_eq!(t.tools[1].nose, Some(0.1));
    }

    /// None fits: the nearest tool of the thread's side is named with what
    /// it lacks, and the table to add to.
    #[test]
    fn a_thread_no_tool_fits_names_the_nearest() {
        let e = table().pick(&need(true, 8.4)).unwrap_err().to_string();
        assert!(e.contains("no tool of tools.csv cuts M"), "{e}");
        assert!(e.contains("row 5 'bar 8'"), "{e}");
        assert!(
            e.contains("needs a bore of 10 mm or more, the thread's is 8.4"),
            "{e}"
        );
        let mut deep = need(true, 40.0);
        deep.depth = 2.4;
        let e = table().pick(&deep).unwrap_err().to_string();
        assert!(e.contains("reaches 1.9 mm deep, the thread 2.4"), "{e}");
        let mut acme = need(false, 25.0);
        acme.included = Some(29.0);
        let e = table().pick(&acme).unwrap_err().to_string();
        assert!(e.contains("carries inserts of 60 deg, not 29"), "{e}");
    }

    /// What reading the table `text` answers, refused.
    fn refused(text: &str) -> String {
        let table = crate::profile::read_table_str(text, "tools.csv").unwrap();
        ToolTable::read(&table).unwrap_err().to_string()
    }

    /// A bad cell is refused by its row and column.
    #[test]
    fn a_bad_cell_names_its_row_and_column() {
        for (bad, want) in [
            (
                "holder 25,1,outside,60",
                "row 2, column side: 'outside' is not external or internal",
            ),
            (
                "holder 25,100,external,60",
                "row 2, column number: 100 is not a tool number",
            ),
            (
                "holder 25,1,external,sixty",
                "row 2, column profile_deg: 'sixty'",
            ),
            // The name reaches the program's tool line: a character a
            // control reads as a comment's end is refused.
            ("holder (25),1,external,60", "row 2, column name: "),
        ] {
            let text = TABLE.replacen("holder 25,1,external,60", bad, 1);
            let e = refused(&text);
            assert!(e.contains(want), "{e}");
        }
        let text = TABLE.replacen(",,1.9,25,10,,,", ",,,25,10,,,", 1);
        let e = refused(&text);
        assert!(
            e.contains("row 2, column depth_mm: the cell is empty"),
            "{e}"
        );
        let text = TABLE.replacen(",,1.9,25,10,,,", ",,deep,25,10,,,", 1);
        let e = refused(&text);
        assert!(
            e.contains("row 2, column H (depth_mm): 'deep' is not a number"),
            "{e}"
        );
    }
}
