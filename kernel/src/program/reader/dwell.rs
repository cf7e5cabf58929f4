//! A dwell (`G4`): the axes stand while the spindle turns, for a time
//! the block gives by one of its dialect's addresses in its unit
//! ([`DwellUnit`]). The block holds the dwell alone; its time is counted
//! before the next move ([`super::ReadMove::dwell_s`]), where the tool
//! stands: the last move's end.

use super::{Block, Reader, Standing};
use crate::math::Real;
use crate::program::lint::LintError;
use crate::program::post::DwellUnit;

impl Reader<'_> {
    /// Whether block `b` of a program read as it stands is a dwell's: a
    /// `G4` among its words, where the dialect reads a dwell.
    pub(super) fn is_dwell(&self, b: &Block) -> bool {
        self.reading
            && !self.d.reading.dwell.is_empty()
            && (b.tokens.iter()).any(|w| w.letter == 'G' && self.code_number(w) == Some(4))
    }

    /// The seconds block `b`'s dwell stands, from `at`, the standing
    /// before it (the spindle's speed where the dwell counts turns).
    ///
    /// # Failures
    /// Another word in the block, no time or two, a time that is not a
    /// number of its unit, turns with the spindle stopped or before any
    /// speed.
    pub(super) fn dwell(&self, at: &Standing, b: &Block) -> Result<Real, LintError> {
        let d = self.d;
        let fail = |m: String| self.err(self.place(b, at.k), m);
        let letters: Vec<String> = (d.reading.dwell.iter())
            .map(|(c, _)| c.to_string())
            .collect();
        let addresses = match letters.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
            _ => letters.concat(),
        };
        if !b.own.is_empty() {
            return Err(fail(format!(
                "a word of {}'s own in a dwell's block, which holds only G4 and its time ({addresses})",
                d.name
            )));
        }
        let mut time = None;
        for w in &b.tokens {
            if w.letter == 'G' && self.code_number(w) == Some(4) {
                continue;
            }
            let Some(unit) =
                (d.reading.dwell.iter()).find_map(|(c, u)| (*c == w.letter).then_some(*u))
            else {
                return Err(fail(format!(
                    "{}: another word in a dwell's block, which holds only G4 and its time ({addresses} on {})",
                    w.text(),
                    d.name
                )));
            };
            if time.is_some() {
                return Err(fail(format!(
                    "{}: a second time in one dwell ({addresses} on {})",
                    w.text(),
                    d.name
                )));
            }
            time = Some(self.dwell_seconds(at, w, unit).map_err(fail)?);
        }
        time.ok_or_else(|| fail(format!("G4 without its time ({addresses} on {})", d.name)))
    }

    /// The seconds of dwell word `w` in `unit`, from `at`.
    fn dwell_seconds(
        &self,
        at: &Standing,
        w: &crate::program::words::Word,
        unit: DwellUnit,
    ) -> Result<Real, String> {
        let v = w.value();
        if !(v.is_finite() && v >= 0.0) {
            return Err(format!(
                "{}: a dwell's time is a number not below 0",
                w.text()
            ));
        }
        Ok(match unit {
            DwellUnit::Seconds => v,
            DwellUnit::Milliseconds if w.has_point() => {
                return Err(format!(
                "{}: a decimal point in a dwell of milliseconds, which {} reads as a whole number",
                w.text(),
                self.d.name
            ))
            }
            DwellUnit::Milliseconds => v * MS,
            DwellUnit::SecondsByPoint if w.has_point() => v,
            DwellUnit::SecondsByPoint => v * MS,
            DwellUnit::Revolutions => {
                let rpm = at.st.speed.filter(|s| *s > 0.0).ok_or_else(|| {
                    format!(
                        "{}: a dwell in turns of the spindle before any speed S",
                        w.text()
                    )
                })?;
                if !at.st.spindle_on {
                    return Err(format!(
                        "{}: a dwell in turns of the spindle while it stands (M3 first)",
                        w.text()
                    ));
                }
                v * 60.0 / rpm
            }
        })
    }
}

/// A millisecond in seconds.
const MS: Real = 1e-3;
