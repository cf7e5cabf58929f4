//! The shop's offset table (`--offsets FILE`): what a tool offset other
//! than the tool call's own, or a work offset other than the part zero,
//! does to where the tool reaches. Without it the reader refuses such a
//! program (`D2`, `T0105`, a switch to `G55`), since the control would
//! move the tool by an amount the verification does not know; with it,
//! each one the file gives moves every later position by its shift.
//!
//! ```toml
//! # Shifts of the position the tool reaches, per program axis, in the
//! # program's units (X as the program writes it: radius or diameter),
//! # with the sign of the move they cause.
//! [tool]
//! D2 = { X = -0.012 }          # Sinumerik: the edge D2 reaches 12 um lower in X than D1
//! T0102 = { X = 0.0, Z = 0.05 } # Fanuc: tool 01 with offset 02, against T0101
//! [work]
//! G55 = { Z = -0.5 }           # a point under G55 lies 0.5 mm lower in Z of the part than under the first offset
//! ```
//!
//! A tool entry is against the tool call's own offset (`D1`, `T0101`); a
//! work entry against the work offset the program selects first, the
//! part zero. A shift applies to every move after the word that selects it
//! (the control applies a length offset with the next move; the
//! verification takes it at once: never later than the control).

use crate::math::Real;
use std::collections::BTreeMap;

/// The largest shift an entry may give (mm): an offset table's
/// differences are corrections, not set-ups.
pub const MAX_SHIFT: Real = 1000.0;

/// An offset table: the shifts of tool offsets and work offsets by word.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Offsets {
    /// Where the table came from, for messages.
    pub source: String,
    /// Tool offsets by word (`D2`, `T0102`): each axis's shift.
    pub tool: BTreeMap<String, BTreeMap<String, Real>>,
    /// Work offsets by word (`G55`): each axis's shift.
    pub work: BTreeMap<String, BTreeMap<String, Real>>,
}

impl Offsets {
    /// Reads a table from its TOML text; `source` names it in errors.
    ///
    /// # Failures
    /// Text that is not TOML; a key other than `tool` and `work`; a word
    /// not of the forms `D<n>`, `T<four digits>`, `G54`..`G59`; an axis
    /// name not a capital letter; a shift not finite or beyond
    /// [`MAX_SHIFT`]. Each names the file, the word and the axis.
    pub fn from_toml_str(text: &str, source: &str) -> Result<Self, super::ProgramFault> {
        Self::from_toml_text(text, source).map_err(super::ProgramFault::new)
    }

    /// [`Self::from_toml_str`], its failure as text.
    fn from_toml_text(text: &str, source: &str) -> Result<Self, String> {
        let shown = crate::files::excerpt(source);
        let table: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| format!("{shown}: {}", e.message()))?;
        let mut out = Self {
            source: source.to_owned(),
            ..Self::default()
        };
        for (key, value) in &table {
            let (into, form): (&mut BTreeMap<_, _>, fn(&str) -> bool) = match key.as_str() {
                "tool" => (&mut out.tool, is_tool_word),
                "work" => (&mut out.work, is_work_word),
                other => {
                    return Err(format!(
                        "{shown}: '{}' is not a table of the offsets file (tool, work)",
                        crate::files::excerpt(other)
                    ))
                }
            };
            let toml::Value::Table(words) = value else {
                return Err(format!("{shown}: [{key}] must be a table of words"));
            };
            for (word, shifts) in words {
                if !form(word) {
                    return Err(format!(
                        "{shown}: [{key}] '{}' is not a {} word ({})",
                        crate::files::excerpt(word),
                        key,
                        if key == "tool" {
                            "D and a number, or T and four digits"
                        } else {
                            "G54 to G59"
                        }
                    ));
                }
                let toml::Value::Table(axes) = shifts else {
                    return Err(format!(
                        "{shown}: [{key}] {word} must be a table of axes and shifts, {word} = {{ X = 0.0 }}"
                    ));
                };
                let mut by_axis = BTreeMap::new();
                for (axis, v) in axes {
                    if !(axis.len() == 1 && axis.chars().all(|c| c.is_ascii_uppercase())) {
                        return Err(format!(
                            "{shown}: [{key}] {word}: '{}' is not an axis (a capital letter)",
                            crate::files::excerpt(axis)
                        ));
                    }
                    let v = match v {
                        toml::Value::Float(f) => *f,
                        toml::Value::Integer(i) => *i as Real,
                        _ => {
                            return Err(format!(
                                "{shown}: [{key}] {word}.{axis} must be a number (mm)"
                            ))
                        }
                    };
                    if !(v.is_finite() && v.abs() <= MAX_SHIFT) {
                        return Err(format!(
                            "{shown}: [{key}] {word}.{axis} = {v} must be finite and within {MAX_SHIFT} mm"
                        ));
                    }
                    by_axis.insert(axis.clone(), v);
                }
                into.insert(word.clone(), by_axis);
            }
        }
        Ok(out)
    }

    /// The shifts of the tool word `word`, in the order of `axes`, if the
    /// table gives it.
    pub fn tool_shift(&self, word: &str, axes: &[char]) -> Option<Vec<Real>> {
        self.tool.get(word).map(|s| by_axes(s, axes))
    }

    /// The shifts of the work offset `word`, in the order of `axes`, if
    /// the table gives it.
    pub fn work_shift(&self, word: &str, axes: &[char]) -> Option<Vec<Real>> {
        self.work.get(word).map(|s| by_axes(s, axes))
    }

    /// The axes the table names that are not among `axes`, as `word.axis`.
    pub fn unknown_axes(&self, axes: &[char]) -> Vec<String> {
        self.tool
            .iter()
            .chain(&self.work)
            .flat_map(|(w, s)| {
                s.keys()
                    .filter(|a| !a.chars().next().is_some_and(|c| axes.contains(&c)))
                    .map(move |a| format!("{w}.{a}"))
            })
            .collect()
    }
}

fn by_axes(shifts: &BTreeMap<String, Real>, axes: &[char]) -> Vec<Real> {
    axes.iter()
        .map(|c| shifts.get(&c.to_string()).copied().unwrap_or(0.0))
        .collect()
}

fn is_tool_word(w: &str) -> bool {
    match w.split_at_checked(1) {
        Some(("D", n)) => !n.is_empty() && n.len() <= 3 && n.bytes().all(|b| b.is_ascii_digit()),
        Some(("T", n)) => n.len() == 4 && n.bytes().all(|b| b.is_ascii_digit()),
        _ => false,
    }
}

fn is_work_word(w: &str) -> bool {
    matches!(w, "G54" | "G55" | "G56" | "G57" | "G58" | "G59")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_table_is_read_and_its_faults_named() {
        let o = Offsets::from_toml_str(
            "[tool]\nD2 = { X = -0.012 }\n[work]\nG55 = { Z = 2 }\n",
            "shop.toml",
        )
        .unwrap();
        assert_eq!(o.tool_shift("D2", &['X', 'Z']), Some(vec![-0.012, 0.0]));
        assert_eq!(o.work_shift("G55", &['X', 'Z']), Some(vec![0.0, 2.0]));
        assert_eq!(o.tool_shift("D3", &['X']), None);
        assert_eq!(o.unknown_axes(&['X']), ["G55.Z"]);
        for (text, says) in [
            ("[tools]\n", "'tools' is not a table"),
            ("[tool]\nD2x = { X = 0.0 }\n", "'D2x' is not a tool word"),
            ("[tool]\nT102 = { X = 0.0 }\n", "'T102' is not a tool word"),
            ("[work]\n\"G54.1\" = { X = 0.0 }\n", "is not a work word"),
            ("[tool]\nD2 = { x = 0.0 }\n", "'x' is not an axis"),
            ("[tool]\nD2 = { X = nan }\n", "D2.X = NaN must be finite"),
            ("[tool]\nD2 = { X = 1e9 }\n", "must be finite and within"),
            ("[tool]\nD2 = 1.0\n", "must be a table of axes"),
        ] {
            let e = Offsets::from_toml_str(text, "shop.toml")
                .unwrap_err()
                .message;
            assert!(
                e.starts_with("shop.toml: ") && e.contains(says),
                "{text}: {e}"
            );
        }
    }
}
