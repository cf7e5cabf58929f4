//! A drawing's table of stations as a profile: straight lines between the
//! stations, each corner sharp or given its fillet or chamfer.

use super::{Interpolation, Profile, ProfileBuilder, ProfileError};
use crate::input::InputError;
use crate::math::Real;

/// What a drawing gives at a station's corner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CornerForm {
    /// Rounded by an arc of this radius (mm) tangent to both lines.
    Fillet(Real),
    /// Cut by a line from this far (mm) back along one line to this far
    /// along the other.
    Chamfer(Real),
}

/// The polyline through the stations `(z, x)` (z increasing), its corners
/// kinks (an infinite second derivative: a wheel's path swings round a
/// convex one and is refused at a concave one it cannot enter), except
/// where `corners` gives a station (by its z) a fillet or a chamfer. Arcs
/// are sampled within `chordal` (mm).
///
/// # Failures
/// As [`Profile::new`]; a corner given at a z that is no inner station
/// (named), one that does not fit the lines beside it (naming the station,
/// the corner's turn and the room there is).
pub fn polyline_through(
    z: &[Real],
    x: &[Real],
    corners: &[(Real, CornerForm)],
    chordal: Real,
) -> Result<Profile, ProfileError> {
    // The stations' own checks (count, finite, z increasing), by index.
    Profile::new(z.to_vec(), x.to_vec())?;
    let mut at = vec![None; z.len()];
    for &(zc, form) in corners {
        let i = z
            .iter()
            .position(|&zi| (zi - zc).abs() <= crate::tolerance::SAME_RATIO * (1.0 + zc.abs()));
        match i {
            Some(i) if i > 0 && i + 1 < z.len() => at[i] = Some(form),
            _ => {
                return Err(InputError::out_of_range(
                    "a station's corner z",
                    zc,
                    format!(
                    "the z of a station between the first and the last ({} stations, z {} to {})",
                    z.len(),
                    z[0],
                    z[z.len() - 1]
                ),
                )
                .into())
            }
        }
    }
    let mut b = ProfileBuilder::start(z[0], x[0]);
    for i in 1..z.len() {
        b = b.line_to(z[i], x[i]);
        b = match at[i] {
            Some(CornerForm::Fillet(r)) => b.fillet(r),
            Some(CornerForm::Chamfer(c)) => b.chamfer(c),
            None => b,
        };
    }
    let span = z[z.len() - 1] - z[0];
    // One line a station pair: the step is the whole span.
    Ok(b.build(chordal, span)?
        .with_interpolation(Interpolation::Linear))
}
