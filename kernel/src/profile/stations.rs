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

/// The stations `x` (radii) aimed at the middle of the tolerances a
/// drawing gives their diameters (`tolerances[i]`, `None` for the general
/// one; [`crate::fits::limits`]), and the profile's bands: each run of
/// neighbouring stations with the same tolerance is one, from the first's
/// z to the last's (a lone station's at its z), half the narrowest of
/// their bands wide on the radius.
///
/// # Failures
/// A tolerance that cannot be read (naming the station); as many
/// tolerances as stations not given.
pub fn aimed(
    z: &[Real],
    x: &[Real],
    tolerances: &[Option<String>],
) -> Result<(Vec<Real>, Vec<super::Band>), ProfileError> {
    for (what, n) in [
        ("the stations' x", x.len()),
        ("the stations' tolerances", tolerances.len()),
    ] {
        if n != z.len() {
            return Err(InputError::LengthMismatch {
                what: what.into(),
                left: n,
                right: z.len(),
            }
            .into());
        }
    }
    let mut limits = Vec::with_capacity(z.len());
    for (i, t) in tolerances.iter().enumerate() {
        limits.push(match t {
            Some(t) => {
                Some(
                    crate::fits::limits(t, 2.0 * x[i]).map_err(|e| InputError::BadText {
                        what: format!("station {} (z = {} mm): tolerance", i + 1, z[i]),
                        value: crate::names::quoted(t),
                        reason: e.why,
                    })?,
                )
            }
            None => None,
        });
    }
    let aimed = (x.iter().zip(&limits))
        .map(|(x, l)| x + l.as_ref().map_or(0.0, |l| 0.5 * l.middle()))
        .collect();
    let mut bands = Vec::new();
    let mut i = 0;
    while i < z.len() {
        let Some(first) = &limits[i] else {
            i += 1;
            continue;
        };
        let mut j = i;
        while j + 1 < z.len() && limits[j + 1].as_ref().is_some_and(|l| l.text == first.text) {
            j += 1;
        }
        let half = (limits[i..=j].iter().flatten())
            .map(|l| 0.5 * l.half_width())
            .fold(Real::INFINITY, Real::min);
        let said = |k: usize| first.said(&(2.0 * x[k]).to_string());
        let source = if i == j {
            format!("station {} (z = {} mm), {}", i + 1, z[i], said(i))
        } else {
            format!(
                "stations {} to {} (z = {} to {} mm), {}",
                i + 1,
                j + 1,
                z[i],
                z[j],
                said(i)
            )
        };
        bands.push(super::Band {
            from: z[i],
            to: z[j],
            half,
            source,
        });
        i = j + 1;
    }
    Ok((aimed, bands))
}

/// The stations `(z, x)` as the profile's sources ([`super::Source`]):
/// each from half-way to the one before to half-way to the one after,
/// named by its number (from 1) and its values as given.
pub fn station_sources(z: &[Real], x: &[Real]) -> Vec<super::Source> {
    let n = z.len().min(x.len());
    (0..n)
        .map(|i| super::Source {
            from: if i == 0 {
                z[0]
            } else {
                0.5 * (z[i - 1] + z[i])
            },
            to: if i + 1 == n {
                z[i]
            } else {
                0.5 * (z[i] + z[i + 1])
            },
            index: i + 1,
            label: format!("station {} (z = {} mm, x = {} mm)", i + 1, z[i], x[i]),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A land h6 over two stations and a lone gauge diameter ±0.004: the
    /// stations moved to the bands' middles, two bands, the land's half
    /// of IT6 on the radius.
    #[test]
    fn stations_aim_at_their_bands_middles() {
        let z = [0.0, 20.0, 40.0, 60.0];
        let x = [20.0, 20.0, 22.0, 22.0];
        let t = [
            Some("h6".to_owned()),
            Some("h6".to_owned()),
            None,
            Some("±0.004".to_owned()),
        ];
        let (a, bands) = aimed(&z, &x, &t).unwrap();
        // Ø40 h6: 0/-0.016 on the diameter, -0.004 on the radius.
        assert!((a[0] - 19.996).abs() < 1e-12 && (a[1] - 19.996).abs() < 1e-12);
        assert_eq!((a[2], a[3]), (22.0, 22.0));
        assert_eq!(bands.len(), 2);
        assert_eq!((bands[0].from, bands[0].to), (0.0, 20.0));
        assert!((bands[0].half - 0.004).abs() < 1e-12);
        assert!(bands[0]
            .source
            .starts_with("stations 1 to 2 (z = 0 to 20 mm), d 40 h6"));
        assert_eq!((bands[1].from, bands[1].to), (60.0, 60.0));
        assert!((bands[1].half - 0.002).abs() < 1e-12);
        let e = aimed(&z, &x, &[None, Some("H7".into()), None, None]).unwrap_err();
        assert!(e.to_string().contains("station 2 (z = 20 mm)"), "{e}");
    }
}
