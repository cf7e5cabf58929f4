//! Constant surface speed (`G96`): the spindle's speed S in m/min at the
//! tool's diameter, clamped by the program's limit (Fanuc's `G50 S`,
//! LinuxCNC's `D` in the `G96` block, Sinumerik's `LIMS=`) and the
//! spindle's range; `G97` back to a speed in rpm, with its S.
//!
//! The control turns the spindle faster as the tool goes in; pilgrim's
//! axis program holds one speed per block. A cutting move is given the
//! speed at its larger diameter (the slowest the spindle turns along it,
//! so its feed per turn is the most it is along the move: what the feed
//! rule and the ridge it leaves must hold); a rapid the speed at its end,
//! where the next cut begins. Under G96 a thread is refused (its lead is
//! tied to the spindle's turn), and so is an arc (its diameter between
//! its ends is not followed).

use super::{placed, Block, Reader, Said, Standing};
use crate::math::Real;
use crate::program::lint::LintError;
use crate::program::post::SpeedClamp;
use pilgrim_plugin_abi::types::Radial;

impl Reader<'_> {
    /// LinuxCNC's clamp `D` in block `b`'s `G96`, taken out of `said`.
    ///
    /// # Failures
    /// A clamp below 1 rpm.
    pub(super) fn clamp_word(
        &self,
        at: &mut Standing,
        b: &Block,
        said: &mut Said,
    ) -> Result<(), LintError> {
        let clamp = self.d.reading.speed_clamp;
        if clamp == Some(SpeedClamp::DWithG96) && said.surface == Some(true) {
            if let Some(p) = said.read.iter().position(|(c, ..)| *c == 'D') {
                let (_, v, text) = said.read.remove(p);
                let v = positive_rpm(v, &text).map_err(|m| self.err(self.place(b, at.k), m))?;
                at.st.clamp = Some(v);
            }
        }
        Ok(())
    }

    /// The spindle's words of block `b` (`speed` its S, `moves` whether it
    /// moves an axis) under constant surface speed: Fanuc's `G50 S` the
    /// clamp, an S under G96 its surface speed. The S left is a speed in
    /// rpm.
    ///
    /// # Failures
    /// `G50` with an axis or without S; a speed or clamp not above 0; `G97`
    /// after G96 without its S.
    pub(super) fn surface_words(
        &self,
        at: &mut Standing,
        b: &Block,
        said: &Said,
        speed: Option<Real>,
        moves: bool,
    ) -> Result<Option<Real>, LintError> {
        let fail = |m: String| self.err(self.place(b, at.k), m);
        // LinuxCNC reads G96's speed in its own block ("S word missing
        // with G96", its interpreter says).
        let own_s = self.d.reading.speed_clamp == Some(SpeedClamp::DWithG96);
        if own_s && said.surface == Some(true) && speed.is_none() {
            return Err(fail(format!(
                "G96 without its surface speed S in the block, which {} reads there",
                self.d.name
            )));
        }
        if said.clamp {
            if moves {
                return Err(fail(
                    "G50 with an axis: a coordinate system setting, which the verification does not follow (G50 S alone clamps the spindle's speed)".into(),
                ));
            }
            let v = speed.ok_or_else(|| {
                fail(format!(
                    "G50 without S: on {} a coordinate system setting with an axis, which the verification does not follow, or the spindle's speed clamp with its S",
                    self.d.name
                ))
            })?;
            at.st.clamp = Some(positive_rpm(v, &format!("S{v}")).map_err(fail)?);
            return Ok(None);
        }
        if at.st.surface {
            if let Some(v) = speed {
                if !(v.is_finite() && v > 0.0) {
                    return Err(fail(format!(
                        "S{v}: a surface speed under G96 is a number of m/min above 0"
                    )));
                }
                at.st.surface_speed = Some(v);
            }
            return Ok(None);
        }
        if said.surface == Some(false) && at.st.surface_speed.is_some() {
            if speed.is_none() {
                return Err(fail(
                    "G97 after G96 without S: controls differ in the speed they keep (the last G96 one, or the last S as rpm); write G97 S(rpm)".into(),
                ));
            }
            // A later G96 gives its own S: this one is in rpm.
            at.st.surface_speed = None;
        }
        Ok(speed)
    }

    /// The spindle's speed (rpm) of block `b`'s move under G96, from the
    /// radial axis's value `from` (where the tool stands, if known) to
    /// where the modal state `at` now places it, a rapid's at its end, a
    /// cut's at its larger diameter; it becomes the speed in force.
    ///
    /// # Failures
    /// No surface speed yet, no clamp, a machine whose setup states no
    /// radial programming, an arc or a thread under G96.
    pub(super) fn surface_move(
        &self,
        at: &mut Standing,
        b: &Block,
        from: Option<Real>,
        rapid: bool,
        arc: bool,
    ) -> Result<(), LintError> {
        let fail = |m: String| self.err(self.place(b, at.k), m);
        let st = &at.st;
        let vc = st
            .surface_speed
            .ok_or_else(|| fail("a move under G96 before its surface speed S (m/min)".into()))?;
        if arc {
            return Err(fail(
                "an arc under constant surface speed (G96): the spindle's speed along it follows the diameter between its ends, which the verification does not; write G97 S(rpm) before it".into(),
            ));
        }
        let (Some(i), Some(radial)) = (self.radial_index(), self.program.setup.radial) else {
            return Err(fail(
                "G96 on a machine whose setup states no radial axis and programming: the diameter the speed follows is not known".into(),
            ));
        };
        let to = placed(st)[i];
        let on_radius = if radial == Radial::Radius { 2.0 } else { 1.0 };
        let diameter = |v: Option<Real>| v.map_or(0.0, |v| v.abs() * on_radius);
        let d = if rapid {
            diameter(to)
        } else {
            diameter(from).max(diameter(to))
        };
        let top = match (st.clamp, self.spindle.map(|a| a.max)) {
            (Some(c), Some(m)) => c.min(m),
            (Some(c), None) => c,
            (None, Some(m)) => m,
            (None, None) => {
                return Err(fail(format!(
                    "a move under G96 with no clamp of the spindle's speed ({}) and no spindle on the machine to state its top speed",
                    match self.d.reading.speed_clamp {
                        Some(SpeedClamp::G50) => "G50 S",
                        Some(SpeedClamp::DWithG96) => "D in the G96 block",
                        _ => "LIMS=",
                    }
                )))
            }
        };
        let low = self.spindle.map_or(1.0, |a| a.min.max(1.0));
        let rpm = if d > 0.0 {
            (1000.0 * vc / (std::f64::consts::PI * d)).min(top)
        } else {
            top
        }
        .max(low);
        if at.st.speed != Some(rpm) {
            at.st.speed = Some(rpm);
            at.speed_next = Some(rpm);
        }
        Ok(())
    }

    /// The index of the setup's radial axis among the program's axes.
    pub(super) fn radial_index(&self) -> Option<usize> {
        let setup = &self.program.setup;
        let letter = setup.radial_axis.chars().next().unwrap_or('X');
        self.names.iter().position(|c| *c == letter)
    }
}

/// `v` (written `text`) as a clamp of the spindle's speed: at least 1 rpm.
fn positive_rpm(v: Real, text: &str) -> Result<Real, String> {
    if v.is_finite() && v >= 1.0 {
        Ok(v)
    } else {
        Err(format!(
            "{text}: a clamp of the spindle's speed is at least 1 rpm"
        ))
    }
}
