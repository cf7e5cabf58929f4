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
    let mut mesh = TriMesh::default();
    for r in rings {
        mesh.positions.extend_from_slice(r);
    }
    let m32 = m as u32;
    for j in 0..rings.len() as u32 - 1 {
        let (a, b) = (j * m32, (j + 1) * m32);
        for k in 0..m32 {
            let k1 = (k + 1) % m32;
            mesh.triangles.push([a + k, b + k, b + k1]);
            mesh.triangles.push([a + k, b + k1, a + k1]);
        }
    }
    let side_count = mesh.triangles.len();
    // Caps, on vertices of their own (flat shading): each section
    // triangulated in its plane, the triangles wound as the ring (the
    // first cap) or against it (the last), as the sides are.
    for (j, first) in [(0, true), (rings.len() - 1, false)] {
        let r = &rings[j];
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
        let tris = earcutr::earcut(&flat, &[], 2).map_err(|e| {
            MeshError::Degenerate(format!("section {j} cannot be triangulated: {e:?}"))
        })?;
        // A simple polygon's triangles cover exactly its area.
        let covered: Real = tris
            .chunks_exact(3)
            .map(|t| dot(cross(sub(r[t[1]], r[t[0]]), sub(r[t[2]], r[t[0]])), n).abs())
            .sum();
        if tris.len() != 3 * (m - 2) || (covered - area2).abs() > 1e-9 * area2 {
            return Err(MeshError::Degenerate(format!(
                "section {j} is not a simple polygon: its cap cannot be made"
            )));
        }
        let base = mesh.positions.len() as u32;
        mesh.positions.extend_from_slice(r);
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
            let ring = if i < side_count { i / (2 * m) } else { 0 };
            return Err(MeshError::Degenerate(format!(
                "a face between sections {ring} and {} has no area",
                ring + 1
            )));
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
