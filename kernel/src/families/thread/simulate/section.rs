//! The axial section's polygons: the blank, the nominal spaces, and the
//! crossings and edges the gauges read.

use super::ThreadRequest;
use crate::families::thread::ThreadSection;
use crate::math::Real;
use geo::{Coord, LineString, MultiPolygon, Polygon};

/// `m` mirrored across the axis (r to -r).
pub(super) fn flipped(m: &MultiPolygon<Real>) -> MultiPolygon<Real> {
    use geo::MapCoords;
    m.map_coords(|c| Coord { x: c.x, y: -c.y })
}

/// The section of a check read back from a report, which does not hold it.
pub(super) fn no_section() -> MultiPolygon<Real> {
    MultiPolygon::new(Vec::new())
}

/// A polygon of `(z, r)` points.
pub(in crate::families::thread) fn poly(points: &[[Real; 2]]) -> Polygon<Real> {
    Polygon::new(
        LineString::from(points.iter().map(|p| (p[0], p[1])).collect::<Vec<_>>()),
        vec![],
    )
}

/// The rectangle `[z0, z1] x [r0, r1]`.
pub(in crate::families::thread) fn rect(z0: Real, z1: Real, r0: Real, r1: Real) -> Polygon<Real> {
    poly(&[[z0, r0], [z1, r0], [z1, r1], [z0, r1]])
}

/// Every edge of a multipolygon's rings.
pub(super) fn edges(
    m: &MultiPolygon<Real>,
) -> impl Iterator<Item = (Coord<Real>, Coord<Real>)> + '_ {
    m.0.iter()
        .flat_map(|p| std::iter::once(p.exterior()).chain(p.interiors()))
        .flat_map(|ring| ring.lines().map(|l| (l.start, l.end)))
}

/// The z where the material's boundary crosses the radius `r`, sorted.
pub(super) fn crossings_at(m: &MultiPolygon<Real>, r: Real) -> Vec<Real> {
    let mut out: Vec<Real> = edges(m)
        .filter(|(a, b)| (a.y <= r) != (b.y <= r))
        .map(|(a, b)| a.x + (r - a.y) / (b.y - a.y) * (b.x - a.x))
        .collect();
    out.sort_by(Real::total_cmp);
    out
}

/// The highest material at `z`.
pub(super) fn vertical_top(m: &MultiPolygon<Real>, z: Real) -> Option<Real> {
    edges(m)
        .filter(|(a, b)| (a.x <= z) != (b.x <= z))
        .map(|(a, b)| a.y + (z - a.x) / (b.x - a.x) * (b.y - a.y))
        .max_by(Real::total_cmp)
}

/// The lowest (`lowest`) or the highest of the material's tops over `z`
/// in `[a, b]`: a space's bottom between its flanks, a thread's crest.
/// The boundary is piecewise linear, so its extremes lie at its vertices
/// or at the interval's ends: those are the places looked at.
pub(super) fn extreme_top(m: &MultiPolygon<Real>, a: Real, b: Real, lowest: bool) -> Option<Real> {
    let vertices = edges(m).map(|(p, _)| p.x).filter(|z| *z > a && *z < b);
    let tops = [a, b]
        .into_iter()
        .chain(vertices)
        .filter_map(|z| vertical_top(m, z));
    if lowest {
        tops.min_by(Real::total_cmp)
    } else {
        tops.max_by(Real::total_cmp)
    }
}

/// The space around `c` at radius `r`: the material's boundary just left
/// and just right of it, if `c` is in a space there.
pub(super) fn space_edges(m: &MultiPolygon<Real>, r: Real, c: Real) -> Option<(Real, Real)> {
    let x = crossings_at(m, r);
    let i = x.iter().position(|z| *z > c)?;
    // Crossings alternate into and out of material from the left: an even
    // count to the left of c means c is outside the material.
    (i % 2 == 0 && i > 0).then(|| (x[i - 1], x[i]))
}

pub(super) fn segment_distance(p: [Real; 2], a: [Real; 2], b: [Real; 2]) -> Real {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((p[0] - a[0] - t * dx).powi(2) + (p[1] - a[1] - t * dy).powi(2)).sqrt()
}

/// How far the middles of the threads' crests either side of a space
/// stand from its centre (the root's middle): before it (towards -Z), then
/// after it. Below the crest the thread is wider, so a line there stays in
/// the thread (a buttress's too).
pub(super) fn thread_middle(t: &ThreadSection) -> [Real; 2] {
    let reach = t.reach(t.crest_diameter / 2.0);
    let half = (t.pitch - reach[0] - reach[1]) / 2.0;
    [reach[0] + half, reach[1] + half]
}

/// The nominal spaces of one lead's window (and one either side), each an
/// outline from the root to above the crest: a trapezoid, or curved
/// flanks in chords of [`NOMINAL_CHORDS`] along the depth; each start's
/// moved radially by its correction ([`ThreadRequest::pitch_shift`]).
pub(super) fn nominal_spaces(req: &ThreadRequest, c0: Real) -> Vec<Vec<[Real; 2]>> {
    let t = &req.section;
    let n = if t.form.is_axial() { 1 } else { NOMINAL_CHORDS };
    (-1..=i64::from(t.starts))
        .map(|k| {
            // The place's start (start_place is its own inverse), its
            // space moved by its corrections.
            let start = t.hand.start_place(k, t.starts);
            let c = c0 + k as Real * t.pitch + req.start_shift(start);
            let s = req.start_section(start);
            let (root, top) = (s.root_diameter / 2.0, s.crest_diameter / 2.0 + 2.0);
            let radii: Vec<Real> = (0..=n)
                .map(|i| root + (top - root) * i as Real / n as Real)
                .collect();
            let reach: Vec<[Real; 2]> = radii.iter().map(|&r| s.reach(r)).collect();
            // From the -Z flank's root corner along the root, up the +Z
            // flank, back down the -Z flank.
            let up = radii.iter().zip(&reach).map(|(&r, e)| [c + e[1], r]);
            let down = radii.iter().zip(&reach).rev().map(|(&r, e)| [c - e[0], r]);
            let mut outline: Vec<[Real; 2]> = up.chain(down).collect();
            outline.rotate_right(1);
            outline
        })
        .collect()
}

/// The chords of a curved nominal flank: 64 over a worm's depth of 11 mm
/// and 2 above it leave 0.2 mm each, within 0.02 um of a ZI flank's curve
/// (its axial angle turns 3 degrees over the depth).
pub(super) const NOMINAL_CHORDS: usize = 64;
