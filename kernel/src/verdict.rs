//! What a run's checks found, as data: passed, failed or not verified, the
//! figures each verification holds against its tolerance, and each failure
//! with the rule or figure, the place and what to change.
//!
//! Every verification (the grinding replay, the caliber's 3-D replay, the
//! worm's simulation) and every rule of the process gives its figures and
//! its failures in these terms ([`Figure`], [`Finding`]), so that the run,
//! the report and the page treat them alike and know no family by name.
//! A failed run still writes what it found (`report.json`, `report.html`,
//! the plots, the scene at the worst place), marked FAILED, and no
//! program: failure is a state of the product, not one line of text.

use serde::{Deserialize, Serialize};

/// A verified figure against its tolerance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Figure {
    /// What it is (`finish: deviation from the nominal`).
    pub name: String,
    /// Its value, in `unit` (signed where the sign says something).
    pub value: f64,
    /// What it may be at most in size, in `unit`.
    pub tolerance: f64,
    /// The unit (`mm`, `deg`, `%`).
    pub unit: String,
    /// Where it is (`z = 212.503 mm, N1130 in "pass 4"`), or empty.
    pub place: String,
    /// The block where it is (from 0), where it is at one: the page's
    /// player goes there when the figure is clicked.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub block: Option<usize>,
}

impl Figure {
    /// A figure.
    pub fn new(name: &str, value: f64, tolerance: f64, unit: &str, place: String) -> Self {
        Self {
            name: name.to_owned(),
            value,
            tolerance,
            unit: unit.to_owned(),
            place,
            block: None,
        }
    }

    /// The figure at block `block` (from 0).
    pub fn at_block(mut self, block: usize) -> Self {
        self.block = Some(block);
        self
    }

    /// Its size as a share of its tolerance (1 is the tolerance).
    pub fn share(&self) -> f64 {
        if self.tolerance > 0.0 {
            self.value.abs() / self.tolerance
        } else {
            f64::INFINITY
        }
    }

    /// Whether it holds its tolerance.
    pub fn holds(&self) -> bool {
        self.value.abs() <= self.tolerance
    }
}

/// A rule or a figure that failed, or that the run warns of.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Finding {
    /// The rule or figure (`verification`, `rapid through material`).
    pub rule: String,
    /// The block as the program numbers it (`N570 in "pass 1"`), if one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub block: Option<String>,
    /// The block's index (from 1, the program's and `report.csv`'s
    /// count), where the scene of a failed run stands.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub block_index: Option<usize>,
    /// The line (from 1) of the program's file a reading refused, where
    /// the refusal stands on no move.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line: Option<usize>,
    /// What is wrong, and what to change.
    pub message: String,
}

impl Finding {
    /// A finding of `rule` with no block.
    pub fn new(rule: &str, message: impl Into<String>) -> Self {
        Self {
            rule: rule.to_owned(),
            block: None,
            block_index: None,
            line: None,
            message: message.into(),
        }
    }

    /// The same on line `line` (from 1) of the program's file.
    pub fn on_line(mut self, line: Option<usize>) -> Self {
        self.line = line;
        self
    }

    /// The same at block `index` (from 0) named `name`.
    pub fn at(mut self, index: usize, name: String) -> Self {
        self.block = Some(name);
        self.block_index = Some(index + 1);
        self
    }
}

/// The run's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Every check and every figure held.
    Passed,
    /// A check, a rule or a figure failed: no program was written.
    Failed,
    /// The checks held, but the family declares no verification: nothing
    /// says the program makes the part.
    NotVerified,
}

/// What the run found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Verdict {
    /// Passed, failed or not verified.
    pub status: Status,
    /// What failed, in the order found.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub failures: Vec<Finding>,
    /// What the run warns of (the process's rules and the family's).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<Finding>,
    /// Each verified figure against its tolerance.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub figures: Vec<Figure>,
}

impl Default for Verdict {
    fn default() -> Self {
        Self {
            status: Status::NotVerified,
            failures: Vec::new(),
            warnings: Vec::new(),
            figures: Vec::new(),
        }
    }
}

impl Verdict {
    /// The verdict of `failures`, `warnings` and `figures`: failed if any
    /// failure, else passed if `verified`, else not verified.
    pub fn of(
        verified: bool,
        failures: Vec<Finding>,
        warnings: Vec<Finding>,
        figures: Vec<Figure>,
    ) -> Self {
        let status = if !failures.is_empty() {
            Status::Failed
        } else if verified {
            Status::Passed
        } else {
            Status::NotVerified
        };
        Self {
            status,
            failures,
            warnings,
            figures,
        }
    }

    /// Whether the run failed.
    pub fn failed(&self) -> bool {
        self.status == Status::Failed
    }

    /// The failures in one message, each with its block where the message
    /// does not name it: what a failed run says on the terminal.
    pub fn message(&self) -> String {
        self.failures
            .iter()
            .map(|f| match &f.block {
                Some(b) if !f.message.contains(b.as_str()) => format!("{b}: {}", f.message),
                _ => f.message.clone(),
            })
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// The block (from 0) a failed run's scene shows: the first failure's
    /// that names one.
    pub fn worst_block(&self) -> Option<usize> {
        self.failures
            .iter()
            .find_map(|f| f.block_index)
            .map(|b| b - 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_verdict_is_its_worst_finding() {
        let figure = Figure::new("finish", -0.0008, 0.001, "mm", String::new());
        assert!(figure.holds() && (figure.share() - 0.8).abs() < 1e-12);
        let v = Verdict::of(true, vec![], vec![], vec![figure.clone()]);
        assert_eq!(v.status, Status::Passed);
        assert_eq!(
            Verdict::of(false, vec![], vec![], vec![]).status,
            Status::NotVerified
        );
        let f = Finding::new("verification", "the finish strays 2 um").at(9, "N100".into());
        let v = Verdict::of(true, vec![f], vec![], vec![figure]);
        assert!(v.failed());
        assert_eq!(v.worst_block(), Some(9));
        assert_eq!(v.message(), "N100: the finish strays 2 um");
    }
}
