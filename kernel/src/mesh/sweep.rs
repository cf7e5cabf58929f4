//! A closed section carried along a path.

use super::{cross, dot, normalize, sub, MeshError, TriMesh};
use crate::math::Real;

/// The solid bounded by a sequence of closed sections (rings of the same
/// number of points, the section's shape may change along the path), with
/// flat caps on the first and last rings. Each cap is triangulated in its
/// section's plane by ear clipping (`earcutr`, a port of Mapbox's earcut),
/// so an end section may be any simple polygon (a roll's rim with a groove
/// cut in it). The sections' sampling is the caller's (keep it within the
/// chordal tolerance wanted). Either winding of the rings is accepted: the
/// mesh is oriented outward.
///
/// # Failures
/// Fewer than 2 rings or 3 points a ring, rings of different sizes, a value
/// not finite; a degenerate face or an end section that is not a simple
/// plane polygon (named by ring).
///
/// ```
/// use pilgrim_kernel::mesh::sweep;
/// // A square tube section carried 10 mm along Z: a box.
/// let ring = |z: f64| vec![[0.0, 0.0, z], [1.0, 0.0, z], [1.0, 1.0, z], [0.0, 1.0, z]];
/// let m = sweep(&[ring(0.0), ring(10.0)]).unwrap();
/// m.check_closed().unwrap();
/// assert!((m.volume() - 10.0).abs() < 1e-12);
/// ```
pub fn sweep(rings: &[Vec<[Real; 3]>]) -> Result<TriMesh, MeshError> {
    swept(rings, None)
}

/// The solid between two sequences of closed sections, `outer` and the
/// hole `inner` inside it (a nut: its outside, its thread), as [`sweep`]
/// makes one: each sequence's sides, and flat caps with the hole in them
/// (ear clipping with a hole). Each sequence has its own number of rings
/// and of points a ring (a straight outside needs two rings); their first
/// rings lie in one plane, their last in another, the hole's wound as the
/// outside's.
///
/// # Failures
/// As [`sweep`]'s, for either sequence.
///
/// ```
/// use pilgrim_kernel::mesh::sweep_hollow;
/// // A square tube: 2 mm square outside, a 1 mm square hole, 10 mm long.
/// let ring = |z: f64, a: f64, b: f64| vec![[a, a, z], [b, a, z], [b, b, z], [a, b, z]];
/// let outer = [ring(0.0, 0.0, 2.0), ring(10.0, 0.0, 2.0)];
/// let inner = [ring(0.0, 0.5, 1.5), ring(10.0, 0.5, 1.5)];
/// let m = sweep_hollow(&outer, &inner).unwrap();
/// m.check_closed().unwrap();
/// assert!((m.volume() - 30.0).abs() < 1e-9);
/// ```
pub fn sweep_hollow(
    outer: &[Vec<[Real; 3]>],
    inner: &[Vec<[Real; 3]>],
) -> Result<TriMesh, MeshError> {
    swept(outer, Some(inner))
}

/// The rings checked: at least 2, of the same size (at least 3), finite.
fn check_rings(rings: &[Vec<[Real; 3]>]) -> Result<usize, MeshError> {
    if rings.len() < 2 {
        return Err(MeshError::Degenerate(format!(
            "a sweep needs at least 2 sections, got {}",
            rings.len()
        )));
    }
    let m = rings[0].len();
    if m < 3 {
        return Err(MeshError::Degenerate(format!(
            "a section needs at least 3 points, got {m}"
        )));
    }
    for (j, r) in rings.iter().enumerate() {
        if r.len() != m {
            return Err(MeshError::Degenerate(format!(
                "section {j} has {} points, section 0 has {m}",
                r.len()
            )));
        }
        for (k, p) in r.iter().enumerate() {
            for v in p {
                crate::math::finite(&format!("section {j} point {k}"), *v)?;
            }
        }
    }
    Ok(m)
}

/// [`sweep`], with a hole through it where `holes` are given.
fn swept(rings: &[Vec<[Real; 3]>], holes: Option<&[Vec<[Real; 3]>]>) -> Result<TriMesh, MeshError> {
    let m = check_rings(rings)?;
    let h = holes.map(check_rings).transpose()?.unwrap_or(0);
    let mut mesh = TriMesh::default();
    // The sides: the outside's, then the hole's wound the other way (its
    // faces look into the hole).
    for (sequence, reversed) in [(rings, false), (holes.unwrap_or(&[]), true)] {
        let base = mesh.positions.len() as u32;
        for r in sequence {
            mesh.positions.extend_from_slice(r);
        }
        let m32 = sequence.first().map_or(0, Vec::len) as u32;
        for j in 0..(sequence.len() as u32).saturating_sub(1) {
            let (a, b) = (base + j * m32, base + (j + 1) * m32);
            for k in 0..m32 {
                let k1 = (k + 1) % m32;
                let (t1, t2) = ([a + k, b + k, b + k1], [a + k, b + k1, a + k1]);
                if reversed {
                    mesh.triangles.push([t1[0], t1[2], t1[1]]);
                    mesh.triangles.push([t2[0], t2[2], t2[1]]);
                } else {
                    mesh.triangles.push(t1);
                    mesh.triangles.push(t2);
                }
            }
        }
    }
    let side_count = mesh.triangles.len();
    let outside_sides = 2 * m * (rings.len() - 1);
    // Which sections a side face `i` lies between, named.
    let between = |i: usize| -> String {
        let (whose, ring) = if i < outside_sides {
            ("", i / (2 * m))
        } else {
            ("the hole's ", (i - outside_sides) / (2 * h))
        };
        format!("{whose}sections {ring} and {}", ring + 1)
    };
    // Caps, on vertices of their own (flat shading): each section
    // triangulated in its plane, the triangles wound as the ring (the
    // first cap) or against it (the last), as the sides are.
    for (j, first) in [(0, true), (rings.len() - 1, false)] {
        // The section, its hole's points after its own (the hole's first
        // or last ring).
        let hole = holes.map_or(&[][..], |hs| {
            if first {
                &hs[0][..]
            } else {
                &hs[hs.len() - 1][..]
            }
        });
        let r: Vec<[Real; 3]> = rings[j].iter().chain(hole).copied().collect();
        // The ring's plane: Newell's normal, and two axes in it.
        let mut n = [0.0; 3];
        for k in 0..m {
            let (p, q) = (r[k], r[(k + 1) % m]);
            n[0] += (p[1] - q[1]) * (p[2] + q[2]);
            n[1] += (p[2] - q[2]) * (p[0] + q[0]);
            n[2] += (p[0] - q[0]) * (p[1] + q[1]);
        }
        let area2 = dot(n, n).sqrt();
        if !(area2 > 0.0) {
            return Err(MeshError::Degenerate(format!(
                "section {j} encloses no area: its cap cannot be made"
            )));
        }
        let n = normalize(n);
        let u = normalize(sub(r[1], r[0]));
        let u = if dot(u, u) > 0.0 {
            u
        } else {
            normalize(sub(r[2], r[0]))
        };
        let v = cross(n, u);
        let flat: Vec<Real> = r
            .iter()
            .flat_map(|p| {
                let d = sub(*p, r[0]);
                [dot(d, u), dot(d, v)]
            })
            .collect();
        let hole_starts: &[usize] = if h > 0 { &[m] } else { &[] };
        let tris = earcutr::earcut(&flat, hole_starts, 2).map_err(|e| {
            MeshError::Degenerate(format!("section {j} cannot be triangulated: {e:?}"))
        })?;
        // A simple polygon's triangles cover exactly its area (less its
        // hole's).
        let hole_area2 = if h > 0 {
            let mut a = 0.0;
            for k in 0..h {
                let (p, q) = (r[m + k], r[m + (k + 1) % h]);
                a += dot(cross(p, q), n);
            }
            a.abs()
        } else {
            0.0
        };
        let covered: Real = tris
            .chunks_exact(3)
            .map(|t| dot(cross(sub(r[t[1]], r[t[0]]), sub(r[t[2]], r[t[0]])), n).abs())
            .sum();
        let want = area2 - hole_area2;
        let count = if h > 0 { m + h } else { m - 2 };
        if tris.len() != 3 * count || (covered - want).abs() > crate::tolerance::SAME_RATIO * area2
        {
            return Err(MeshError::Degenerate(format!(
                "section {j} is not a simple polygon: its cap cannot be made"
            )));
        }
        let base = mesh.positions.len() as u32;
        mesh.positions.extend_from_slice(&r);
        for t in tris.chunks_exact(3) {
            let (a, b, c) = (t[0], t[1], t[2]);
            let along = dot(cross(sub(r[b], r[a]), sub(r[c], r[a])), n) > 0.0;
            let (b, c) = if along == first { (b, c) } else { (c, b) };
            mesh.triangles
                .push([base + a as u32, base + b as u32, base + c as u32]);
        }
    }
    // Orient outward.
    if mesh.volume() < 0.0 {
        for t in &mut mesh.triangles {
            t.swap(1, 2);
        }
    }
    // Normals: side vertices averaged over their faces, caps flat.
    let mut acc = vec![[0.0; 3]; mesh.positions.len()];
    for (i, t) in mesh.triangles.iter().enumerate() {
        let (a, b, c) = (
            mesh.positions[t[0] as usize],
            mesh.positions[t[1] as usize],
            mesh.positions[t[2] as usize],
        );
        let n = cross(sub(b, a), sub(c, a));
        if dot(n, n) == 0.0 {
            return Err(MeshError::Degenerate(if i < side_count {
                format!("a face between {} has no area", between(i))
            } else {
                "a face of an end section's cap has no area".to_owned()
            }));
        }
        for v in t {
            let s = &mut acc[*v as usize];
            for k in 0..3 {
                s[k] += n[k];
            }
        }
    }
    mesh.normals = acc.into_iter().map(normalize).collect();
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(z: Real, a: Real, b: Real) -> Vec<[Real; 3]> {
        vec![[a, a, z], [b, a, z], [b, b, z], [a, b, z]]
    }

    /// A degenerate face of a hole's side is named as the hole's: two of
    /// its sections in one place leave its faces between them no area.
    #[test]
    fn a_flat_hole_is_named_by_its_own_sections() {
        let outer = [square(0.0, 0.0, 2.0), square(10.0, 0.0, 2.0)];
        let inner = [
            square(0.0, 0.5, 1.5),
            square(5.0, 0.5, 1.5),
            square(5.0, 0.5, 1.5),
            square(10.0, 0.5, 1.5),
        ];
        let e = sweep_hollow(&outer, &inner).unwrap_err().to_string();
        assert!(
            e.contains("a face between the hole's sections 1 and 2 has no area"),
            "{e}"
        );
    }
}
