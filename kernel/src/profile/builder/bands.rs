//! A drawing's own tolerances on a chain's elements: each element's ends
//! moved to its band's middle, and the bands the profile carries.

use super::Segment;
use crate::input::InputError;
use crate::math::Real;
use crate::profile::{Band, ProfileError};

/// A chain aimed at its bands' middles: its start, its segments, its
/// bands.
pub(super) type Aimed = ((Real, Real), Vec<Segment>, Vec<Band>);

/// Where segment `k` ends, if it is a line or an arc (given by its end).
fn end_of(segments: &[Segment], k: usize) -> Option<(Real, Real)> {
    match segments.get(k)? {
        Segment::Line { z, x } | Segment::Arc { z, x, .. } | Segment::TangentArc { z, x } => {
            Some((*z, *x))
        }
        _ => None,
    }
}

/// The chain from `start` with each element `bands` names (its index and
/// its tolerance) aimed at its band's middle: its two ends moved by half
/// the middle on the radius. A point is the end of the segment before it
/// (`Some(index)`) or the start (`None`).
///
/// # Failures
/// A tolerance given to no line or arc, or right after the mandrel law
/// (whose end the law fixes); a tolerance that cannot be read; two
/// elements moving their shared point to two middles. Each names the
/// element.
pub(super) fn aimed(
    start: (Real, Real),
    segments: &[Segment],
    bands: &[(usize, String)],
) -> Result<Aimed, ProfileError> {
    let refuse = |k: usize, text: &str, why: String| -> ProfileError {
        InputError::BadText {
            what: format!("segment {k}: tolerance"),
            value: crate::names::quoted(text),
            reason: why,
        }
        .into()
    };
    let mut shifts: Vec<(Option<usize>, Real, usize)> = Vec::new();
    let mut out = Vec::new();
    for (k, text) in bands {
        let k = *k;
        let end = end_of(segments, k).ok_or_else(|| {
            refuse(
                k,
                text,
                "is given to the line or arc it follows, and none ends here".into(),
            )
        })?;
        // The point the element starts at: the last end before it.
        let before = (0..k).rev().find(|&j| {
            !matches!(
                segments[j],
                Segment::Fillet { .. } | Segment::Chamfer { .. }
            )
        });
        let from = match before {
            None => start,
            Some(j) => end_of(segments, j).ok_or_else(|| {
                refuse(k, text, "the element starts where the mandrel law ends, which the law fixes: tolerance a line or an arc after a line or an arc".into())
            })?,
        };
        let limits = crate::fits::limits(text, 2.0 * from.1.max(end.1))
            .map_err(|e| refuse(k, text, e.why))?;
        let m = 0.5 * limits.middle();
        for point in [before, Some(k)] {
            match shifts.iter().find(|s| s.0 == point) {
                Some(s) if (s.1 - m).abs() > crate::tolerance::SAME_LENGTH => {
                    return Err(refuse(k, text, format!("it shares a point with segment {}, whose tolerance aims it at another middle: give the two one tolerance, or an element between them", s.2)));
                }
                Some(_) => {}
                None => shifts.push((point, m, k)),
            }
        }
        out.push(Band {
            from: from.0,
            to: end.0,
            half: 0.5 * limits.half_width(),
            source: format!(
                "segment {k} (z = {} to {} mm), {}",
                crate::math::fixed(from.0, 3),
                crate::math::fixed(end.0, 3),
                limits.said(&crate::math::fixed(2.0 * from.1.max(end.1), 3))
            ),
        });
    }
    let mut start = start;
    let mut segments = segments.to_vec();
    for (point, m, _) in shifts {
        match point {
            None => start.1 += m,
            Some(j) => match &mut segments[j] {
                Segment::Line { x, .. }
                | Segment::Arc { x, .. }
                | Segment::TangentArc { x, .. } => *x += m,
                _ => unreachable!("a point is a line's or an arc's end"),
            },
        }
    }
    Ok((start, segments, out))
}

#[cfg(test)]
mod tests {
    use crate::profile::{Bulge, ProfileBuilder};

    /// A land Ø40 h6 between cones: both its ends 4 um low on the radius,
    /// the cones meeting them; the band over the land; a land toleranced
    /// after the law, or two neighbours aimed apart, refused.
    #[test]
    fn an_element_aims_at_its_bands_middle() {
        let p = ProfileBuilder::start(0.0, 15.0)
            .line_to(10.0, 20.0)
            .line_to(30.0, 20.0)
            .toleranced("h6")
            .line_to(40.0, 16.0)
            .build(1e-4, 1.0)
            .unwrap();
        for z in [10.0, 20.0, 30.0] {
            assert!((p.eval(z).unwrap() - 19.996).abs() < 1e-12, "{z}");
        }
        assert!((p.eval(0.0).unwrap() - 15.0).abs() < 1e-12);
        let b = &p.bands()[0];
        assert_eq!((b.from, b.to), (10.0, 30.0));
        // A stretch cut out keeps what it holds of the band and sources.
        let cut = p.between(15.0, 35.0).unwrap();
        assert_eq!((cut.bands()[0].from, cut.bands()[0].to), (15.0, 30.0));
        let spans: Vec<(f64, f64)> = cut.sources().iter().map(|s| (s.from, s.to)).collect();
        assert_eq!(spans, [(15.0, 30.0), (30.0, 35.0)]);
        assert!((b.half - 0.004).abs() < 1e-12);
        assert!(
            b.source
                .starts_with("segment 1 (z = 10.000 to 30.000 mm), d 40.000 h6: +0/-0.016 mm"),
            "{}",
            b.source
        );
        let e = ProfileBuilder::start(0.0, 20.0)
            .line_to(10.0, 20.0)
            .toleranced("h6")
            .line_to(20.0, 20.0)
            .toleranced("g6")
            .build(1e-4, 1.0)
            .unwrap_err();
        assert!(
            e.to_string().contains("shares a point with segment 0"),
            "{e}"
        );
        let e = ProfileBuilder::start(0.0, 20.0)
            .fillet(1.0)
            .toleranced("h6")
            .build(1e-4, 1.0)
            .unwrap_err();
        assert!(e.to_string().contains("segment 0"), "{e}");
        // An arc toleranced too: its ends move, its radius kept.
        let p = ProfileBuilder::start(0.0, 20.0)
            .line_to(10.0, 20.0)
            .arc_to(20.0, 18.0, 30.0, Bulge::Out)
            .toleranced("±0.01")
            .build(1e-4, 1.0)
            .unwrap();
        assert!((p.eval(20.0).unwrap() - 18.0).abs() < 1e-12);
    }

    /// An arc given by its centre: its radius and bulge from it, a tangent
    /// joint where the centre lies on the line's normal; refused where
    /// its ends lie at two distances from the centre.
    #[test]
    fn an_arc_about_its_centre() {
        let p = ProfileBuilder::start(0.0, 20.0)
            .line_to(10.0, 20.0)
            .tangent()
            .arc_about(16.0, 18.0, 10.0, 10.0)
            .build(1e-4, 1.0)
            .unwrap();
        let x = p.eval(13.0).unwrap();
        assert!((x - (10.0 + (100.0_f64 - 9.0).sqrt())).abs() < 1e-6, "{x}");
        let e = ProfileBuilder::start(0.0, 20.0)
            .line_to(10.0, 20.0)
            .arc_about(16.0, 18.5, 10.0, 10.0)
            .build(1e-4, 1.0)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("segment 1: an arc about its centre") && e.contains("10 mm"),
            "{e}"
        );
    }

    /// Each stretch of a chain names the segment it comes from, a fillet
    /// its own arc and the lines it trims theirs.
    #[test]
    fn a_chain_names_its_segments_as_sources() {
        let p = ProfileBuilder::start(0.0, 20.0)
            .line_to(10.0, 20.0)
            .fillet(2.0)
            .line_to(20.0, 15.0)
            .build(1e-4, 1.0)
            .unwrap();
        let at = |z: f64| p.source_at(z).unwrap().label.clone();
        assert_eq!(at(5.0), "segment 0 (the line to z = 10 mm, x = 20 mm)");
        assert_eq!(at(10.0), "segment 1 (the fillet of radius 2 mm)");
        assert_eq!(at(18.0), "segment 2 (the line to z = 20 mm, x = 15 mm)");
    }

    /// A line and an arc declared tangent: passed where the arc's centre
    /// lies on the line's normal, refused (naming the joint and its turn)
    /// where it does not.
    #[test]
    fn a_joint_declared_tangent_is_checked() {
        // The arc from (10, 20) of R 10 bulging out, centre (10, 10): its
        // tangent at the start is horizontal, as the line's.
        let ok = ProfileBuilder::start(0.0, 20.0)
            .line_to(10.0, 20.0)
            .tangent()
            .arc_to(10.0 + 10.0 * 0.6, 10.0 + 10.0 * 0.8, 10.0, Bulge::Out)
            .build(1e-4, 1.0);
        assert!(ok.is_ok(), "{ok:?}");
        let e = ProfileBuilder::start(0.0, 20.0)
            .line_to(10.0, 20.0)
            .tangent()
            .arc_to(15.0, 17.0, 10.0, Bulge::Out)
            .build(1e-4, 1.0)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("the joint after segment 0 at z = 10 mm, declared tangent"),
            "{e}"
        );
    }
}
