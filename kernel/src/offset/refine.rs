//! Nodes added to a profile where the tool's centre, moving in straight
//! lines between the centres over the profile's nodes, would stray from the
//! centre's true path: a drawing's few stations joined by a cubic are far
//! apart, and the path through their centres alone cuts the chords.

use super::Side;
use crate::math::{positive, Real};
use crate::profile::{Profile, ProfileError, MAX_NODES};

/// The deepest an interval is halved (2^24 pieces of it).
const MAX_DEPTH: u32 = 24;

/// `profile` with nodes added between its own until the straight line
/// between the centres of a tool of `radius` on `side` over two
/// neighbouring nodes strays at most `sag` (mm) from the centre over the
/// curve between them (checked at each piece's middle; the curve the
/// profile's [`Profile::eval`] reads, with its derivatives from
/// [`Profile::jet`], so the curvature check of [`super::equidistant`]
/// sees the curve between the nodes too). Straight intervals beside a
/// kink are kept as they are.
///
/// # Failures
/// A `radius` or `sag` that is not positive; more than [`MAX_NODES`]
/// nodes.
pub fn refined(
    profile: &Profile,
    radius: Real,
    side: Side,
    sag: Real,
) -> Result<Profile, ProfileError> {
    positive("tool radius", radius)?;
    positive("tool path's chordal sag", sag)?;
    let (pz, px) = (profile.z(), profile.x());
    let slopes = profile.slopes().into_owned();
    let d2 = profile.second_derivatives().into_owned();
    let r = radius * side.sign();
    let centre = |z: Real, x: Real, s: Real| {
        let c = 1.0 / (1.0 + s * s).sqrt();
        (z - r * s * c, x + r * c)
    };
    let mut out = Jets::default();
    for i in 0..pz.len() - 1 {
        out.push(pz[i], px[i], slopes[i], d2[i]);
        if d2[i].is_infinite() || d2[i + 1].is_infinite() {
            continue;
        }
        // A place of the curve: z, its jet and the centre over it.
        let at = |z: Real| -> Result<Place, ProfileError> {
            let j = profile.jet(z)?;
            Ok((z, j, centre(z, j[0], j[1])))
        };
        // Pieces still to judge, left first: a piece that holds adds its
        // right end (the interval's own end excepted), so nodes come in
        // order. Only the middle is evaluated per piece.
        let mut todo = vec![(at(pz[i])?, at(pz[i + 1])?, 0u32)];
        while let Some((a, b, depth)) = todo.pop() {
            let m = at(0.5 * (a.0 + b.0))?;
            if depth < MAX_DEPTH && off_chord(a.2, b.2, m.2) > sag {
                todo.push((m, b, depth + 1));
                todo.push((a, m, depth + 1));
                continue;
            }
            if b.0 < pz[i + 1] {
                out.push(b.0, b.1[0], b.1[1], b.1[2]);
                if out.z.len() > MAX_NODES {
                    return Err(crate::input::InputError::out_of_range(
                        "tool path's chordal sag",
                        sag,
                        format!("a sag giving at most {MAX_NODES} nodes"),
                    )
                    .into());
                }
            }
        }
    }
    let last = pz.len() - 1;
    out.push(pz[last], px[last], slopes[last], d2[last]);
    // The same curve: the same drawing's bands and sources.
    Ok(Profile::with_derivatives(out.z, out.x, out.d1, out.d2)?
        .with_interpolation(profile.interpolation())
        .with_bands(profile.bands().to_vec())
        .with_sources(profile.sources().to_vec()))
}

/// How far `m` lies from the line through `a` and `b`.
fn off_chord(a: (Real, Real), b: (Real, Real), m: (Real, Real)) -> Real {
    let (dz, dx) = (b.0 - a.0, b.1 - a.1);
    let len = dz.hypot(dx);
    if len == 0.0 {
        return (m.0 - a.0).hypot(m.1 - a.1);
    }
    ((m.0 - a.0) * dx - (m.1 - a.1) * dz).abs() / len
}

/// A place of the curve: its z, its jet (x and two derivatives) and the
/// tool's centre over it.
type Place = (Real, [Real; 3], (Real, Real));

/// Nodes with their derivatives.
#[derive(Default)]
struct Jets {
    z: Vec<Real>,
    x: Vec<Real>,
    d1: Vec<Real>,
    d2: Vec<Real>,
}

impl Jets {
    fn push(&mut self, z: Real, x: Real, d1: Real, d2: Real) {
        self.z.push(z);
        self.x.push(x);
        self.d1.push(d1);
        self.d2.push(d2);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Four stations of a monotone cubic: the centres over the nodes alone
    /// stray from the true path by far more than the sag; refined, the
    /// path between every two neighbouring centres stays within it.
    #[test]
    fn refined_centres_follow_the_curve_between_stations() {
        let p = Profile::new(vec![0.0, 60.0, 120.0, 135.0], vec![9.0, 9.2, 9.6, 8.0])
            .unwrap()
            .with_interpolation(crate::profile::Interpolation::Monotone);
        let sag = 1e-4;
        let q = refined(&p, 20.0, Side::Outside, sag).unwrap();
        assert!(q.len() > 20, "{}", q.len());
        assert!(q.z().windows(2).all(|w| w[1] > w[0]));
        let e = super::super::equidistant(&q, 20.0, Side::Outside).unwrap();
        for i in 0..e.z.len() - 1 {
            // The true centre halfway between two nodes of the result.
            let zm = 0.5 * (q.z()[i] + q.z()[i + 1]);
            let j = p.jet(zm).unwrap();
            let c = 1.0 / (1.0 + j[1] * j[1]).sqrt();
            let cm = (zm - 20.0 * j[1] * c, j[0] + 20.0 * c);
            let d = off_chord((e.z[i], e.x[i]), (e.z[i + 1], e.x[i + 1]), cm);
            assert!(d <= 1.01 * sag, "interval {i}: {d}");
        }
        assert!(refined(&p, 20.0, Side::Outside, 0.0).is_err());
    }
}
