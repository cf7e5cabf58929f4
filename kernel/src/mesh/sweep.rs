//! A closed section carried along a path.

use super::{cross, dot, normalize, sub, MeshError, TriMesh};
use crate::math::Real;

/// The solid bounded by a sequence of closed sections (rings of the same
/// number of points, the section's shape may change along the path), with
/// flat caps on the first and last rings. Each cap is fanned from its
/// centroid, so the end sections must be star-shaped about it. The
/// sections' sampling is the caller's (keep it within the chordal
/// tolerance wanted). Either winding of the rings is accepted: the mesh is
/// oriented outward.
///
/// # Failures
/// Fewer than 2 rings or 3 points a ring, rings of different sizes, a value
/// not finite; a degenerate face or an end section that is not star-shaped
/// about its centroid (named by ring).
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
    // Caps, fanned from their centroids, on vertices of their own (flat shading).
    for (j, first) in [(0, true), (rings.len() - 1, false)] {
        let r = &rings[j];
        let c = r
            .iter()
            .fold([0.0; 3], |s, p| [s[0] + p[0], s[1] + p[1], s[2] + p[2]]);
        let c = [c[0] / m as Real, c[1] / m as Real, c[2] / m as Real];
        let base = mesh.positions.len() as u32;
        mesh.positions.push(c);
        mesh.positions.extend_from_slice(r);
        for k in 0..m32 {
            let k1 = (k + 1) % m32;
            let (p, q) = (base + 1 + k, base + 1 + k1);
            mesh.triangles
                .push(if first { [base, p, q] } else { [base, q, p] });
        }
        let caps = &mesh.triangles[mesh.triangles.len() - m..];
        let normals: Vec<[Real; 3]> = caps
            .iter()
            .map(|t| {
                let (a, b, c) = (
                    mesh.positions[t[0] as usize],
                    mesh.positions[t[1] as usize],
                    mesh.positions[t[2] as usize],
                );
                cross(sub(b, a), sub(c, a))
            })
            .collect();
        let avg = normals
            .iter()
            .fold([0.0; 3], |s, n| [s[0] + n[0], s[1] + n[1], s[2] + n[2]]);
        if normals.iter().any(|n| dot(*n, avg) <= 0.0) {
            return Err(MeshError::Degenerate(format!(
                "section {j} is not star-shaped about its centroid: its cap cannot be fanned"
            )));
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
