//! The machine's bodies as meshes: each [`Solid`] a machine describes
//! (rollers, cylinders, boxes, guards) in its own frame, within a chordal
//! tolerance, closed and oriented outward, built on the mesh module's
//! revolve and sweep.

use super::{arc_segments, check_tol, cylinder, sweep, MeshError, TriMesh};
use crate::machine::Solid;
use crate::math::{Mat4, Real, Vec3};

/// `solid` in its body's frame (see [`Solid`] for where each stands).
///
/// # Failures
/// A tolerance not above 0, or one that needs more segments than a mesh
/// may have.
///
/// ```
/// use pilgrim_kernel::machine::Solid;
/// use pilgrim_kernel::mesh::body_mesh;
/// let head = body_mesh(&Solid::Block { size: [300.0, 200.0, 100.0] }, 0.01).unwrap();
/// head.check_closed().unwrap();
/// assert!((head.volume() - 6.0e6).abs() < 1e-6);
/// ```
pub fn body_mesh(solid: &Solid, tol: Real) -> Result<TriMesh, MeshError> {
    check_tol(tol)?;
    match *solid {
        Solid::Roller { radius, length } => Ok(cylinder(radius, length, tol)?.transformed(
            &(Mat4::from_axis_angle(&Vec3::x_axis(), std::f64::consts::FRAC_PI_2)
                * Mat4::new_translation(&Vec3::new(0.0, 0.0, -length / 2.0))),
        )),
        Solid::Cylinder { radius, length } => Ok(cylinder(radius, length, tol)?
            .transformed(&Mat4::new_translation(&Vec3::new(0.0, 0.0, -length / 2.0)))),
        Solid::Cone {
            radius,
            end_radius,
            length,
        } => {
            // Two polygons inscribed within the tolerance, the wider's
            // count for both.
            let n = arc_segments(radius.max(end_radius), std::f64::consts::TAU, tol, 8)?;
            let ring = |r: Real, z: Real| {
                (0..n)
                    .map(|i| {
                        let (s, c) = (std::f64::consts::TAU * i as Real / n as Real).sin_cos();
                        [r * c, r * s, z]
                    })
                    .collect::<Vec<_>>()
            };
            sweep(&[ring(radius, -length / 2.0), ring(end_radius, length / 2.0)])
        }
        Solid::Block { size: [x, y, z] } => {
            let ring = |h: Real| {
                vec![
                    [-x / 2.0, -y / 2.0, h],
                    [x / 2.0, -y / 2.0, h],
                    [x / 2.0, y / 2.0, h],
                    [-x / 2.0, y / 2.0, h],
                ]
            };
            sweep(&[ring(-z / 2.0), ring(z / 2.0)])
        }
        Solid::Guard {
            inner,
            outer,
            width,
            cover,
        } => {
            // The section (inner and outer radius, across the width) carried
            // round Z from -cover/2 to +cover/2 about +X.
            // An even count: a section stands on +X, the guard's middle.
            let n = arc_segments(outer, cover, tol, 2)?;
            let n = n + n % 2;
            let rings: Vec<Vec<[Real; 3]>> = (0..=n)
                .map(|i| {
                    let a = -cover / 2.0 + cover * i as Real / n as Real;
                    let (s, c) = a.sin_cos();
                    [
                        (inner, -width / 2.0),
                        (outer, -width / 2.0),
                        (outer, width / 2.0),
                        (inner, width / 2.0),
                    ]
                    .iter()
                    .map(|&(r, z)| [r * c, r * s, z])
                    .collect()
                })
                .collect();
            sweep(&rings)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each solid closed, of its volume within the chords' loss, where its
    /// description puts it.
    #[test]
    fn each_solid_is_closed_and_of_its_volume() {
        let pi = std::f64::consts::PI;
        let tol = 0.005;
        for (solid, volume) in [
            (
                Solid::Roller {
                    radius: 25.0,
                    length: 40.0,
                },
                pi * 625.0 * 40.0,
            ),
            (
                Solid::Cylinder {
                    radius: 60.0,
                    length: 80.0,
                },
                pi * 3600.0 * 80.0,
            ),
            (
                Solid::Block {
                    size: [300.0, 200.0, 100.0],
                },
                6.0e6,
            ),
            (
                Solid::Cone {
                    radius: 4.0,
                    end_radius: 27.0,
                    length: 40.0,
                },
                pi / 3.0 * 40.0 * (16.0 + 4.0 * 27.0 + 729.0),
            ),
            (
                Solid::Guard {
                    inner: 260.0,
                    outer: 280.0,
                    width: 90.0,
                    cover: 1.5 * pi,
                },
                0.75 * pi * (280.0f64.powi(2) - 260.0f64.powi(2)) * 90.0,
            ),
        ] {
            let m = body_mesh(&solid, tol).unwrap();
            m.check_closed().unwrap();
            let v = m.volume();
            // Chords within tol lose at most 2 tol / r of a section's area.
            let r = match solid {
                Solid::Roller { radius, .. } | Solid::Cylinder { radius, .. } => radius,
                Solid::Cone { radius, .. } => radius,
                Solid::Guard { inner, .. } => inner,
                Solid::Block { .. } => f64::INFINITY,
            };
            assert!(
                v <= volume + 1e-6 && v > volume * (1.0 - 2.0 * tol / r) - 1e-6,
                "{solid:?}: {v} vs {volume}"
            );
            let (lo, hi) = m.bounds();
            match solid {
                Solid::Roller { length, .. } => assert!((hi[1] - lo[1] - length).abs() < 1e-9),
                Solid::Cylinder { length, .. } | Solid::Cone { length, .. } => {
                    assert!(
                        (lo[2] + length / 2.0).abs() < 1e-9 && (hi[2] - length / 2.0).abs() < 1e-9
                    )
                }
                // The guard opens toward -X: nothing of it beyond its cover.
                Solid::Guard { outer, cover, .. } => {
                    assert!((hi[0] - outer).abs() < 1e-9);
                    assert!(lo[0] >= outer * (cover / 2.0).cos() - 1e-9, "{lo:?}");
                }
                Solid::Block { size } => {
                    for k in 0..3 {
                        assert!((hi[k] - lo[k] - size[k]).abs() < 1e-9);
                    }
                }
            }
        }
    }
}
