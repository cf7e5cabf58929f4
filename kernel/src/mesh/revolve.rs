//! Solids of revolution about Z.

use super::{arc_segments, check_tol, MeshError, TriMesh};
use crate::math::Real;
use crate::profile::Profile;
use crate::tool::Wheel;
use std::collections::HashMap;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Section vertices whose edges turn by less than this share normals
/// (smooth shading); sharper corners get a crease.
const CREASE: Real = 30.0 * PI / 180.0;

/// Whether closed segments `a-b` and `c-d` (in the plane) meet.
fn segments_meet(a: [Real; 2], b: [Real; 2], c: [Real; 2], d: [Real; 2]) -> bool {
    let orient = |p: [Real; 2], q: [Real; 2], r: [Real; 2]| {
        (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
    };
    let on = |p: [Real; 2], q: [Real; 2], r: [Real; 2]| {
        r[0] >= p[0].min(q[0])
            && r[0] <= p[0].max(q[0])
            && r[1] >= p[1].min(q[1])
            && r[1] <= p[1].max(q[1])
    };
    let (d1, d2, d3, d4) = (
        orient(c, d, a),
        orient(c, d, b),
        orient(a, b, c),
        orient(a, b, d),
    );
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    (d1 == 0.0 && on(c, d, a))
        || (d2 == 0.0 && on(c, d, b))
        || (d3 == 0.0 && on(a, b, c))
        || (d4 == 0.0 && on(a, b, d))
}

/// The first pair of non-adjacent edges of the closed polygon that meet.
fn crossing(p: &[[Real; 2]]) -> Option<(usize, usize)> {
    let n = p.len();
    let edge = |i: usize| (p[i], p[(i + 1) % n]);
    let mut order: Vec<usize> = (0..n).collect();
    let lo = |i: usize| edge(i).0[0].min(edge(i).1[0]);
    let hi = |i: usize| edge(i).0[0].max(edge(i).1[0]);
    order.sort_by(|&a, &b| lo(a).total_cmp(&lo(b)));
    let mut active: Vec<usize> = Vec::new();
    for &i in &order {
        active.retain(|&j| hi(j) >= lo(i));
        for &j in &active {
            let adjacent = (i + 1) % n == j || (j + 1) % n == i;
            if !adjacent {
                let (a, b) = edge(i);
                let (c, d) = edge(j);
                if segments_meet(a, b, c, d) {
                    return Some((i.min(j), i.max(j)));
                }
            }
        }
        active.push(i);
    }
    None
}

/// The solid swept by a closed section turning about Z.
///
/// `section` holds points `(z, r)` with `r >= 0`, the last equal to the
/// first; either orientation. Edges along the axis close the solid and make
/// no faces; a vertex on the axis becomes a pole. The angular step keeps
/// chords within `tol` on the largest radius.
///
/// # Failures
/// A non-positive tolerance; fewer than three distinct points; a value not
/// finite; [`MeshError::Open`] when the section does not close;
/// [`MeshError::SelfIntersecting`] when edges cross, when a point lies below
/// the axis, or when the section touches the axis at a single point (the
/// solid would pinch); a section of zero area.
///
/// ```
/// use pilgrim_kernel::mesh::revolve;
/// // A cylinder of radius 10 and length 20.
/// let m = revolve(&[[0.0, 0.0], [20.0, 0.0], [20.0, 10.0], [0.0, 10.0], [0.0, 0.0]], 0.01).unwrap();
/// m.check_closed().unwrap();
/// // Inscribed polygons: short of pi r^2 L by about V (2 pi / n)^2 / 6, n = 71 steps.
/// let deficit = std::f64::consts::PI * 100.0 * 20.0 - m.volume();
/// assert!(deficit > 0.0 && deficit < 9.0);
/// ```
pub fn revolve(section: &[[Real; 2]], tol: Real) -> Result<TriMesh, MeshError> {
    check_tol(tol)?;
    for (i, p) in section.iter().enumerate() {
        crate::math::finite(&format!("section point {i} z"), p[0])?;
        crate::math::finite(&format!("section point {i} r"), p[1])?;
        if p[1] < 0.0 {
            return Err(MeshError::SelfIntersecting(format!(
                "point {i} ({}, {}) lies below the axis (r < 0)",
                p[0], p[1]
            )));
        }
    }
    if section.len() < 4 {
        return Err(MeshError::Degenerate(format!(
            "a section needs at least 3 points and its closing one, got {}",
            section.len()
        )));
    }
    let (first, last) = (section[0], section[section.len() - 1]);
    let scale = section
        .iter()
        .map(|p| p[0].abs().max(p[1]))
        .fold(1.0, Real::max);
    if (first[0] - last[0]).abs() > crate::tolerance::SAME_RATIO * scale
        || (first[1] - last[1]).abs() > crate::tolerance::SAME_RATIO * scale
    {
        return Err(MeshError::Open { first, last });
    }
    // Distinct points, cyclic.
    let mut pts: Vec<[Real; 2]> = Vec::with_capacity(section.len());
    for p in &section[..section.len() - 1] {
        if pts.last() != Some(p) {
            pts.push(*p);
        }
    }
    while pts.len() > 1 && pts.first() == pts.last() {
        pts.pop();
    }
    if pts.len() < 3 {
        return Err(MeshError::Degenerate(
            "the section has fewer than 3 distinct points".into(),
        ));
    }
    if let Some((i, j)) = crossing(&pts) {
        return Err(MeshError::SelfIntersecting(format!(
            "edge {i} ({:?} to {:?}) meets edge {j} ({:?} to {:?})",
            pts[i],
            pts[(i + 1) % pts.len()],
            pts[j],
            pts[(j + 1) % pts.len()]
        )));
    }
    let area: Real = (0..pts.len())
        .map(|i| {
            let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<Real>()
        / 2.0;
    if !(area.abs() > crate::tolerance::ROUNDING * scale * scale) {
        return Err(MeshError::Degenerate(format!(
            "the section's area is {area}"
        )));
    }
    if area < 0.0 {
        pts.reverse();
    }
    let n = pts.len();
    let on_axis = |s: usize| pts[s][1] == 0.0 && pts[(s + 1) % n][1] == 0.0;
    for i in 0..n {
        let prev = (i + n - 1) % n;
        if pts[i][1] == 0.0 && !on_axis(i) && !on_axis(prev) {
            return Err(MeshError::SelfIntersecting(format!(
                "point {i} ({}, 0) touches the axis: the solid would pinch there",
                pts[i][0]
            )));
        }
    }
    let r_max = pts.iter().map(|p| p[1]).fold(0.0, Real::max);
    // An even count puts a vertex at every half turn (the wheel's lowest
    // point, the programmed one, at angle pi); angles as pi (2k / n) are
    // exact there.
    let na = super::arc_segments(r_max, TAU, tol, 8)?.next_multiple_of(2);
    // Each section segment makes a band of at most 2 triangles a sector.
    super::check_triangles(na.saturating_mul(2).saturating_mul(n), tol)?;
    let trig: Vec<(Real, Real)> = (0..na)
        .map(|k| (PI * (2 * k) as Real / na as Real).sin_cos())
        .collect();
    // Outward normal (n_z, n_r) of segment s: for a counter-clockwise
    // section, (dr, -dz) / length.
    let seg_normal = |s: usize| {
        let (a, b) = (pts[s], pts[(s + 1) % n]);
        let (dz, dr) = (b[0] - a[0], b[1] - a[1]);
        let l = dz.hypot(dr);
        [dr / l, -dz / l]
    };
    let smooth = |i: usize| {
        let prev = (i + n - 1) % n;
        if pts[i][1] == 0.0 || on_axis(i) || on_axis(prev) {
            return false;
        }
        let (a, b) = (seg_normal(prev), seg_normal(i));
        (a[0] * b[0] + a[1] * b[1]).clamp(-1.0, 1.0).acos() < CREASE
    };
    let mut mesh = TriMesh::default();
    let mut shared: HashMap<usize, u32> = HashMap::new();
    // A ring of vertices at section point i for segment s; its first index.
    let mut ring = |mesh: &mut TriMesh, i: usize, s: usize| -> u32 {
        let p = pts[i];
        let make = |mesh: &mut TriMesh, nrm: [Real; 2]| -> u32 {
            let base = mesh.positions.len() as u32;
            if p[1] == 0.0 {
                mesh.positions.push([0.0, 0.0, p[0]]);
                mesh.normals
                    .push([0.0, 0.0, if nrm[0] < 0.0 { -1.0 } else { 1.0 }]);
            } else {
                for &(sn, cs) in &trig {
                    mesh.positions.push([p[1] * cs, p[1] * sn, p[0]]);
                    mesh.normals
                        .push(super::normalize([nrm[1] * cs, nrm[1] * sn, nrm[0]]));
                }
            }
            base
        };
        if smooth(i) {
            if let Some(&b) = shared.get(&i) {
                return b;
            }
            let (a, b) = (seg_normal((i + n - 1) % n), seg_normal(i));
            let base = make(mesh, [a[0] + b[0], a[1] + b[1]]);
            shared.insert(i, base);
            base
        } else {
            make(mesh, seg_normal(s))
        }
    };
    for s in 0..n {
        if on_axis(s) {
            continue;
        }
        let (ia, ib) = (s, (s + 1) % n);
        let a = ring(&mut mesh, ia, s);
        let b = ring(&mut mesh, ib, s);
        let na32 = na as u32;
        for k in 0..na32 {
            let k1 = (k + 1) % na32;
            match (pts[ia][1] == 0.0, pts[ib][1] == 0.0) {
                (true, false) => mesh.triangles.push([a, b + k, b + k1]),
                (false, true) => mesh.triangles.push([a + k, b, a + k1]),
                _ => {
                    mesh.triangles.push([a + k, b + k, b + k1]);
                    mesh.triangles.push([a + k, b + k1, a + k1]);
                }
            }
        }
    }
    Ok(mesh)
}

/// The solid of revolution of a profile `x(z)` about Z, with flat end caps
/// (or poles where the profile reaches the axis at its ends). The profile is
/// thinned to `tol / 2` and turned in steps keeping chords within `tol / 2`.
///
/// # Tolerance
/// The surface is within `tol` of the revolved profile. The volume is short
/// of the exact one by at most `V (2 pi / n)^2 / 6` for `n` angular steps,
/// plus `tol / 2` times the lateral area.
///
/// # Failures
/// A non-positive tolerance; a radius below zero, or zero inside the
/// profile (the solid would pinch), named by its z.
pub fn body_of_revolution(profile: &Profile, tol: Real) -> Result<TriMesh, MeshError> {
    check_tol(tol)?;
    let (z, x) = (profile.z(), profile.x());
    let n = z.len();
    for i in 0..n {
        if x[i] < 0.0 || (x[i] == 0.0 && i > 0 && i < n - 1) {
            return Err(MeshError::SelfIntersecting(format!(
                "the profile's radius at z = {} is {}: a body of revolution needs a positive radius inside",
                z[i], x[i]
            )));
        }
    }
    let keep = crate::profile::simplify_polyline(z, x, tol / 2.0);
    let mut section = Vec::with_capacity(keep.len() + 3);
    section.push([z[0], 0.0]);
    section.push([z[n - 1], 0.0]);
    for &i in keep.iter().rev() {
        section.push([z[i], x[i]]);
    }
    section.push([z[0], 0.0]);
    revolve(&section, tol / 2.0)
}

/// A grinding wheel: a disk of the wheel's width whose periphery is rounded
/// with its rounding radius (a torus where the rounding is half the width),
/// placed in the frame of [`Tool::wheel`](crate::tool::Tool::wheel): its axis
/// along Z through `(D/2, 0, 0)`, the lowest point of its periphery at the
/// origin, its mid-plane at z = 0.
///
/// # Failures
/// A non-positive tolerance.
pub fn wheel(w: &Wheel, tol: Real) -> Result<TriMesh, MeshError> {
    check_tol(tol)?;
    let (half, r_out, rho) = (0.5 * w.width, 0.5 * w.diameter, w.rounding_radius);
    let steps = arc_segments(rho, FRAC_PI_2, tol / 2.0, 2)?;
    // Counter-clockwise in (z, r): along the axis, up the right face, round
    // the right corner (centre (half - rho, r_out - rho)), along the
    // periphery, round the left corner, down the left face. Arc ends are
    // the exact corner points; repeated points (rho = half) drop out.
    let (cr, arc) = (r_out - rho, |cz: Real, a: Real| {
        [cz + rho * a.cos(), r_out - rho + rho * a.sin()]
    });
    let mut s = vec![[-half, 0.0], [half, 0.0], [half, cr]];
    s.extend((1..steps).map(|k| arc(half - rho, FRAC_PI_2 * k as Real / steps as Real)));
    s.push([half - rho, r_out]);
    s.push([-half + rho, r_out]);
    s.extend((1..steps).map(|k| arc(-half + rho, FRAC_PI_2 * (1.0 + k as Real / steps as Real))));
    s.push([-half, cr]);
    s.push([-half, 0.0]);
    let mesh = revolve(&s, tol / 2.0)?;
    let shift = crate::math::Mat4::new_translation(&crate::math::Vec3::new(r_out, 0.0, 0.0));
    Ok(mesh.transformed(&shift))
}

/// A cylinder of `radius` along Z from 0 to `length` (a steady rest's
/// support, an end mill).
///
/// # Failures
/// A non-positive radius, length or tolerance.
pub fn cylinder(radius: Real, length: Real, tol: Real) -> Result<TriMesh, MeshError> {
    crate::math::positive("cylinder radius", radius)?;
    crate::math::positive("cylinder length", length)?;
    revolve(
        &[
            [0.0, 0.0],
            [length, 0.0],
            [length, radius],
            [0.0, radius],
            [0.0, 0.0],
        ],
        tol,
    )
}
