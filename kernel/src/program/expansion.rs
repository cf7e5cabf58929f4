//! What a reading expanded: the runs of moves that a cycle or an arc in
//! one block, a loop, or a subprogram's call made, each traced to the
//! lines it was read from. The verify page lists them beside the program's
//! own text, where such a move has no line of its own.

use serde::Serialize;

/// Where a block's move was read, as the reader places it: its file (0:
/// the program's own), its line there (from 0), and the program's own
/// line whose call made it (from 0), where a subprogram's did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Origin {
    /// The file (0: the program's own).
    pub file: usize,
    /// The line in that file (from 0).
    pub line: usize,
    /// The program's own line (from 0) of the call, where a call made it.
    pub via: Option<usize>,
}

/// What made a run of moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Made {
    /// Several moves of one block: a cycle, an arc in chords.
    Block,
    /// Lines read more than once in a row: a loop, a jump back.
    Loop,
    /// A subprogram's lines, in its own file or the program's.
    Call,
}

/// A run of consecutive blocks the reading expanded from one source.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Expansion {
    /// Its first block (from 0).
    pub first: usize,
    /// Its last block (from 0, inclusive).
    pub last: usize,
    /// What made it.
    pub made: Made,
    /// The file its lines are in (empty: the program's own).
    pub file: String,
    /// The first and last of its lines (from 1) in that file.
    pub lines: (usize, usize),
    /// The program's own line (from 1) whose call made it, for a call.
    pub called_at: Option<usize>,
    /// The most moves any one of its lines made in the run.
    pub times: usize,
}

impl Expansion {
    /// The run's source in a sentence: "FINISH.SPF lines 2 to 9, called
    /// at line 12", "line 7: 58 moves of one block".
    pub fn describe(&self) -> String {
        let lines = match self.lines {
            (a, b) if a == b => format!("line {a}"),
            (a, b) => format!("lines {a} to {b}"),
        };
        let moves = self.last - self.first + 1;
        match self.made {
            Made::Call => {
                let at = self
                    .called_at
                    .map_or(String::new(), |l| format!(", called at line {l}"));
                match self.file.as_str() {
                    "" => format!("the subprogram at {lines}{at}"),
                    f => format!("{f} {lines}{at}"),
                }
            }
            Made::Block => format!("{lines}: {moves} moves of one block (a cycle or an arc)"),
            Made::Loop => format!("{lines}, read up to {} times (a loop)", self.times),
        }
    }
}

/// The runs of `origins` (each block's, in order) that do not stand one
/// move to a line of the program's own text, with the files' names
/// (`files[f - 1]` is file `f`): each run's blocks come from one call, or
/// from the program's own lines read more than once or making more than
/// one move. A line's moves are counted over the whole reading, so a loop
/// whose lines are each read once per turn is one run.
pub fn expansions(origins: &[Origin], files: &[String]) -> Vec<Expansion> {
    let mut count = std::collections::HashMap::<(usize, usize), usize>::new();
    for o in origins {
        *count.entry((o.file, o.line)).or_default() += 1;
    }
    let mut runs: Vec<Expansion> = Vec::new();
    // The last run's file, and the moves each of its lines made.
    let mut run_file = 0;
    let mut per_line = std::collections::HashMap::<usize, usize>::new();
    for (k, o) in origins.iter().enumerate() {
        let called = o.file != 0 || o.via.is_some();
        if !called && count[&(o.file, o.line)] == 1 {
            continue;
        }
        let joins = runs.last().is_some_and(|r| {
            r.last + 1 == k
                && (r.made == Made::Call) == called
                && r.called_at == o.via.map(|l| l + 1)
                && run_file == o.file
                // A cycle whose every move is in the run ends at the next line.
                && !(r.made == Made::Block
                    && o.line + 1 != r.lines.0
                    && r.times == count[&(o.file, r.lines.0 - 1)])
        });
        if !joins {
            per_line.clear();
            run_file = o.file;
            runs.push(Expansion {
                first: k,
                last: k,
                made: if called { Made::Call } else { Made::Block },
                file: match o.file {
                    0 => String::new(),
                    f => files.get(f - 1).cloned().unwrap_or_default(),
                },
                lines: (o.line + 1, o.line + 1),
                called_at: o.via.map(|l| l + 1),
                times: 0,
            });
        }
        let Some(r) = runs.last_mut() else { continue };
        r.last = k;
        r.lines = (r.lines.0.min(o.line + 1), r.lines.1.max(o.line + 1));
        let n = per_line.entry(o.line).or_default();
        *n += 1;
        r.times = r.times.max(*n);
        if r.made == Made::Block && r.lines.0 != r.lines.1 {
            r.made = Made::Loop;
        }
    }
    runs
}

#[cfg(test)]
mod tests {
    use super::*;

    fn own(line: usize) -> Origin {
        Origin {
            file: 0,
            line,
            via: None,
        }
    }

    #[test]
    fn plain_blocks_make_no_run_and_each_source_its_own() {
        let sub = |line| Origin {
            file: 1,
            line,
            via: Some(8),
        };
        let mut origins = vec![own(0), own(1)];
        // A cycle of three moves on line 3, a plain block, two calls.
        origins.extend([own(3), own(3), own(3), own(4)]);
        origins.extend([sub(1), sub(2), sub(1), sub(2)]);
        origins.push(Origin {
            via: Some(9),
            ..sub(1)
        });
        // A cycle of two moves on line 10, then a loop over lines 11
        // and 12, twice.
        origins.extend([own(10), own(10)]);
        origins.extend([own(11), own(12), own(11), own(12)]);
        let files = vec!["O2000.nc".to_owned()];
        let runs = expansions(&origins, &files);
        let seen: Vec<(usize, usize, Made, usize)> = runs
            .iter()
            .map(|r| (r.first, r.last, r.made, r.times))
            .collect();
        assert_eq!(
            seen,
            [
                (2, 4, Made::Block, 3),
                (6, 9, Made::Call, 2),
                (10, 10, Made::Call, 1),
                (11, 12, Made::Block, 2),
                (13, 16, Made::Loop, 2)
            ]
        );
        assert_eq!(
            runs[1].describe(),
            "O2000.nc lines 2 to 3, called at line 9"
        );
        assert_eq!(
            runs[0].describe(),
            "line 4: 3 moves of one block (a cycle or an arc)"
        );
        assert_eq!(
            runs[4].describe(),
            "lines 12 to 13, read up to 2 times (a loop)"
        );
    }
}
