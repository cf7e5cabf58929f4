//! The kernel's solids as parry's shapes, and its poses as parry's.
//!
//! Each body's shape is a convex primitive where the body is one (a
//! roller, a cylinder, a box, a wheel), a compound of convex sectors for a
//! guard, the convex hull of another tool's mesh (a cutter's blade is
//! convex; a tool that is not is taken at its hull, which holds it), and
//! the part as its envelope of revolution, a stack of cylinders. Convex
//! primitives answer parry's queries through their support maps in
//! constant time, whatever the meshes' tolerance.

use crate::machine::Solid;
use crate::math::{Mat4, Real, Vec3};
use crate::mesh::TriMesh;
use parry3d_f64::math::{Pose, Rot3, Vector};
use parry3d_f64::shape::SharedShape;

/// The least half-length (mm) of a cylinder of the stack: a disc of no
/// thickness is not a solid the collision library accepts, and a
/// nanometre of thickness changes no distance it gives.
const THINNEST_HALF: Real = 1e-6;

/// How far (mm) the rays that tell inside from outside are lifted off
/// the stations' heights: an odd amount far below any feature, so that no
/// ray runs through a vertex of the mesh.
const RAY_OFFSET: Real = 1.234_567e-7;

/// How far a guard's convex sectors may fill its inner side, toward the
/// wheel (mm): the sectors are as many as that takes (at most
/// [`MAX_SECTORS`]).
pub const GUARD_FILL: Real = 0.5;

/// The most sectors of a guard.
const MAX_SECTORS: usize = 96;

/// Points on each arc of a guard's sector.
const ARC_POINTS: usize = 3;

/// The sides of the polygons whose hull holds a cone's frustum: 64 stand
/// off its circles by at most 0.12 % of their radius.
const CONE_SIDES: usize = 64;

/// A shape and where it stands in its body's frame.
#[derive(Clone)]
pub struct Shaped {
    /// The shape, in its own frame.
    pub shape: SharedShape,
    /// Its frame in the body's.
    pub local: Mat4,
    /// The axis through its own frame's origin (in its own frame) about
    /// which it is a solid of revolution, if it is one: turning it about
    /// that axis changes no distance to it.
    pub axis: Option<Vec3>,
}

impl std::fmt::Debug for Shaped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Shaped")
            .field("local", &self.local)
            .finish()
    }
}

impl Shaped {
    /// How far the shape reaches from its body's origin (mm): the radius
    /// of a ball about the origin that holds it.
    pub fn reach(&self) -> Real {
        let s = self.shape.compute_local_bounding_sphere();
        let c = self.local.transform_point(&crate::math::Point3::new(
            s.center.x, s.center.y, s.center.z,
        ));
        c.coords.norm() + s.radius
    }
}

/// The shape of a machine body's solid.
pub fn solid(s: &Solid) -> Shaped {
    let here = |shape| Shaped {
        shape,
        local: Mat4::identity(),
        axis: None,
    };
    // parry's cylinders stand along Y in their own frame.
    let cylinder = |half: Real, radius: Real, local: Mat4| Shaped {
        shape: SharedShape::cylinder(half, radius),
        local,
        axis: Some(Vec3::y()),
    };
    match *s {
        // parry's cylinders stand along Y, as a roller does.
        Solid::Roller { radius, length } => cylinder(length / 2.0, radius, Mat4::identity()),
        Solid::Cylinder { radius, length } => cylinder(length / 2.0, radius, along_z()),
        Solid::Cone {
            radius,
            end_radius,
            length,
        } => {
            // The hull of two polygons whose edges touch the circles: it
            // holds the frustum.
            let n = CONE_SIDES;
            let out = 1.0 / (std::f64::consts::PI / n as Real).cos();
            let points: Vec<Vector> = [(radius, -length / 2.0), (end_radius, length / 2.0)]
                .into_iter()
                .flat_map(|(r, z)| {
                    (0..n).map(move |i| {
                        let (s, c) = (std::f64::consts::TAU * i as Real / n as Real).sin_cos();
                        Vector::new(out * r * c, out * r * s, z)
                    })
                })
                .collect();
            match SharedShape::convex_hull(&points) {
                Some(hull) => here(hull),
                // Points that span no volume cannot come of sizes above 0;
                // the cylinder that holds the frustum, were they to.
                None => cylinder(length / 2.0, radius.max(end_radius), along_z()),
            }
        }
        Solid::Block { size } => here(SharedShape::cuboid(
            size[0] / 2.0,
            size[1] / 2.0,
            size[2] / 2.0,
        )),
        Solid::Guard {
            inner,
            outer,
            width,
            cover,
        } => {
            let pieces = ring_sectors(inner, outer, width, cover, GUARD_FILL)
                .into_iter()
                .map(|h| (Pose::identity(), h))
                .collect();
            here(SharedShape::compound(pieces))
        }
    }
}

/// The convex sectors that hold a ring about Z from radius `inner` to
/// `outer`, `width` along Z about 0, over the angle `cover` about +X:
/// each sector the hull of its inner arc's ends (a chord inside the arc by
/// at most `fill`, the sectors as many as that takes, at most
/// [`MAX_SECTORS`]) and of its outer arc's points pushed out so that the
/// hull's edges touch the arc.
fn ring_sectors(
    inner: Real,
    outer: Real,
    width: Real,
    cover: Real,
    fill: Real,
) -> Vec<SharedShape> {
    let per = 2.0 * (1.0 - fill / inner).clamp(-1.0, 1.0).acos();
    let sectors = ((cover / per).ceil() as usize).clamp(1, MAX_SECTORS);
    let spacing = cover / (sectors * (ARC_POINTS - 1)) as Real;
    let out = outer / (spacing / 2.0).cos();
    (0..sectors)
        .filter_map(|i| {
            let at = |k: usize| -cover / 2.0 + spacing * (i * (ARC_POINTS - 1) + k) as Real;
            let points: Vec<Vector> = (0..ARC_POINTS)
                .flat_map(|k| {
                    let (s, c) = at(k).sin_cos();
                    [inner, out].into_iter().flat_map(move |r| {
                        [-width / 2.0, width / 2.0].map(|z| Vector::new(r * c, r * s, z))
                    })
                })
                .collect();
            SharedShape::convex_hull(&points)
        })
        .collect()
}

/// The tool's solid in the tool frame: a wheel exactly, as a round
/// cylinder (its section a rectangle with its corners rounded at the
/// rounding radius) about its axis, centred at `centre`; another tool as
/// the convex hull of its mesh (`None` for a tool with no mesh, or a flat
/// one).
pub fn tool(tool: &crate::tool::Tool, mesh: Option<&TriMesh>, centre: Vec3) -> Option<Shaped> {
    match tool.shape {
        crate::tool::ToolShape::Wheel(w) => {
            let r = w.rounding_radius;
            Some(Shaped {
                shape: SharedShape::round_cylinder(
                    (w.width / 2.0 - r).max(0.0),
                    (w.diameter / 2.0 - r).max(0.0),
                    r,
                ),
                local: Mat4::new_translation(&centre) * along_z(),
                axis: Some(Vec3::y()),
            })
        }
        _ => {
            let points: Vec<Vector> = mesh?
                .positions
                .iter()
                .map(|p| Vector::new(p[0], p[1], p[2]))
                .collect();
            SharedShape::convex_hull(&points).map(|shape| Shaped {
                shape,
                local: Mat4::identity(),
                axis: None,
            })
        }
    }
}

/// parry's cylinders stand along Y: this turns one to stand along Z.
fn along_z() -> Mat4 {
    Mat4::from_axis_angle(&Vec3::x_axis(), std::f64::consts::FRAC_PI_2)
}

/// The most slabs of a part's envelope.
const MAX_SLABS: usize = 64;

/// The part at its largest about its axis (the part frame's Z): a stack of
/// cylinders, each as wide as the mesh's farthest vertex from the axis
/// over its length (and the ring of vertices on either side, which bound
/// the surface between them), plus `tol` for the chords between vertices.
/// A slab runs on while the envelope's radius varies by at most `tol`
/// (coarser if that would take more than [`MAX_SLABS`]). With `bore`
/// (the run's tool cuts inside a bore), where the axis is outside the
/// part in a slab (a nut, a bored part: [`axis_inside`]), the slab is a
/// ring whose hole is as wide as the mesh's nearest vertex to
/// the axis there, less `tol` for the chords and `tol` for the ring's own
/// (convex sectors, [`ring_sectors`]). Conservative for any part; exact to
/// `2 tol` for a body of revolution (a mandrel, a roll's blank, a thread's
/// outer cylinder, a nut's bore). Without `bore` the part is taken whole:
/// nothing of the machine enters its bore but what rides with it (a
/// roll's arbor), and a ring's sectors cost every query more than a
/// cylinder. `None` for an empty mesh.
pub fn envelope(mesh: &TriMesh, tol: Real, bore: bool) -> Option<Shaped> {
    let mut rings: Vec<(Real, Real)> = mesh
        .positions
        .iter()
        .map(|p| (p[2], p[0].hypot(p[1])))
        .collect();
    if rings.is_empty() {
        return None;
    }
    rings.sort_by(|a, b| a.0.total_cmp(&b.0));
    // One ring per z, its largest radius.
    let mut merged: Vec<(Real, Real)> = Vec::new();
    for (z, r) in rings {
        match merged.last_mut() {
            Some(last) if z - last.0 <= crate::tolerance::SAME_LENGTH => last.1 = last.1.max(r),
            _ => merged.push((z, r)),
        }
    }
    let slabs = |band: Real| -> Vec<(Real, Real, Real)> {
        let mut out: Vec<(Real, Real, Real)> = Vec::new();
        let (mut lo, mut hi) = (Real::INFINITY, Real::NEG_INFINITY);
        let mut start = merged[0].0;
        for w in merged.windows(2) {
            let (a, b) = (w[0], w[1]);
            let (nlo, nhi) = (lo.min(a.1).min(b.1), hi.max(a.1).max(b.1));
            if nhi - nlo > band && hi.is_finite() {
                out.push((start, a.0, hi));
                start = a.0;
                (lo, hi) = (a.1.min(b.1), a.1.max(b.1));
            } else {
                (lo, hi) = (nlo, nhi);
            }
        }
        let last = merged[merged.len() - 1];
        out.push((start, last.0, hi.max(last.1)));
        out
    };
    let mut band = tol;
    let mut stack = slabs(band);
    while stack.len() > MAX_SLABS {
        band *= 2.0;
        stack = slabs(band);
    }
    let inside = if bore {
        axis_inside(
            mesh,
            &stack.iter().map(|s| (s.0 + s.1) / 2.0).collect::<Vec<_>>(),
        )
    } else {
        vec![true; stack.len()]
    };
    let mut pieces = Vec::new();
    // A stack of cylinders only (no ring's polygonal sectors) is a solid
    // of revolution about Z.
    let mut round = true;
    for ((z0, z1, r), solid) in stack.into_iter().zip(inside) {
        let half = ((z1 - z0) / 2.0).max(THINNEST_HALF);
        let centre = Mat4::new_translation(&Vec3::new(0.0, 0.0, (z0 + z1) / 2.0));
        let hole = (!solid)
            .then(|| {
                mesh.positions
                    .iter()
                    .filter(|p| {
                        p[2] >= z0 - crate::tolerance::SAME_LENGTH
                            && p[2] <= z1 + crate::tolerance::SAME_LENGTH
                    })
                    .map(|p| p[0].hypot(p[1]))
                    .fold(Real::INFINITY, Real::min)
                    - tol
            })
            .filter(|h| h.is_finite() && *h > tol);
        match hole {
            Some(h) => pieces.extend({
                round = false;
                ring_sectors(h, r + tol, 2.0 * half, std::f64::consts::TAU, tol)
                    .into_iter()
                    .map(|s| (pose(&centre), s))
            }),
            None => pieces.push((
                pose(&(centre * along_z())),
                SharedShape::cylinder(half, r + tol),
            )),
        }
    }
    Some(Shaped {
        shape: SharedShape::compound(pieces),
        local: Mat4::identity(),
        axis: round.then(Vec3::z),
    })
}

/// For each of `zs`, whether the part frame's axis there lies inside the
/// closed mesh: the parity of a ray's crossings from the axis outwards,
/// each triangle near the ray cast against it (parry's `Triangle`; its
/// mesh ray cast gives the first hit only, and its inside test needs a
/// mesh with merged vertices and pseudo-normals). The ray leaves at an
/// odd angle and a hair off `z` so that it meets no edge or vertex of a
/// mesh built on round angles.
fn axis_inside(mesh: &TriMesh, zs: &[Real]) -> Vec<bool> {
    use parry3d_f64::query::{Ray, RayCast};
    use parry3d_f64::shape::Triangle;
    let (s, c) = 0.123_456_789_f64.sin_cos();
    // The rays' heights, ascending: each triangle meets those within its
    // own span of z only.
    let mut order: Vec<usize> = (0..zs.len()).collect();
    order.sort_by(|&i, &j| zs[i].total_cmp(&zs[j]));
    let heights: Vec<Real> = order.iter().map(|&k| zs[k] + RAY_OFFSET).collect();
    let mut crossings = vec![0usize; zs.len()];
    for t in &mesh.triangles {
        let [a, b, d] = t.map(|i| mesh.positions[i as usize]);
        let (lo, hi) = (a[2].min(b[2]).min(d[2]), a[2].max(b[2]).max(d[2]));
        let first = heights.partition_point(|&z| z < lo);
        let v = |p: [Real; 3]| Vector::new(p[0], p[1], p[2]);
        let triangle = Triangle::new(v(a), v(b), v(d));
        for (n, &z) in heights[first..].iter().enumerate() {
            if z > hi {
                break;
            }
            let ray = Ray::new(Vector::new(0.0, 0.0, z), Vector::new(c, s, 0.0));
            if triangle.intersects_local_ray(&ray, Real::MAX) {
                crossings[order[first + n]] += 1;
            }
        }
    }
    crossings.into_iter().map(|n| n % 2 == 1).collect()
}

/// A rigid motion (rotation and translation only) as parry's pose.
pub fn pose(m: &Mat4) -> Pose {
    let r = m.fixed_view::<3, 3>(0, 0);
    let cols = |j: usize| Vector::new(r[(0, j)], r[(1, j)], r[(2, j)]);
    let rot = Rot3::from_mat3(&parry3d_f64::math::Mat3::from_cols(
        cols(0),
        cols(1),
        cols(2),
    ));
    Pose::from_parts(Vector::new(m[(0, 3)], m[(1, 3)], m[(2, 3)]), rot)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tube's envelope, for a tool inside its bore, is a ring: a bar of
    /// radius 8 on the axis of a 14 mm bore stands 6 mm clear of it (within
    /// the mesh's tolerance), a bar outside stands off its outside; for
    /// other tools it is whole; a solid rod's envelope holds its axis.
    #[test]
    fn a_hollow_parts_envelope_keeps_its_bore() {
        let circle = |r: Real, z: Real| -> Vec<[Real; 3]> {
            (0..96)
                .map(|k| {
                    let a = std::f64::consts::TAU * k as Real / 96.0;
                    [r * a.cos(), r * a.sin(), z]
                })
                .collect()
        };
        let tube = crate::mesh::sweep_hollow(
            &[circle(22.5, -30.0), circle(22.5, 0.0)],
            &[circle(14.0, -30.0), circle(14.0, 0.0)],
        )
        .unwrap();
        let tol = 14.0 * (1.0 - (std::f64::consts::PI / 96.0).cos());
        let env = envelope(&tube, tol, true).unwrap();
        let bar = SharedShape::cylinder(40.0, 8.0);
        let at = |x: Real| {
            let m = Mat4::new_translation(&crate::math::Vec3::new(x, 0.0, -15.0)) * along_z();
            parry3d_f64::query::distance(&pose(&env.local), &*env.shape, &pose(&m), &*bar)
                .unwrap()
                .distance
        };
        let d = at(0.0);
        assert!(d < 6.0 && d > 6.0 - 3.0 * tol, "{d} (tol {tol})");
        let d = at(40.0);
        assert!(
            d <= 40.0 - 8.0 - 22.5 && d > 40.0 - 8.0 - 22.5 - 2.0 * tol,
            "{d}"
        );
        // Taken whole where no tool cuts inside a bore.
        let whole = envelope(&tube, tol, false).unwrap();
        let m = Mat4::new_translation(&crate::math::Vec3::new(0.0, 0.0, -15.0)) * along_z();
        let d = parry3d_f64::query::distance(&pose(&whole.local), &*whole.shape, &pose(&m), &*bar)
            .unwrap()
            .distance;
        assert_eq!(d, 0.0);
        let rod = crate::mesh::sweep(&[circle(22.5, -30.0), circle(22.5, 0.0)]).unwrap();
        let env = envelope(&rod, tol, true).unwrap();
        let d = parry3d_f64::query::distance(
            &pose(&env.local),
            &*env.shape,
            &pose(&(Mat4::new_translation(&crate::math::Vec3::new(0.0, 0.0, -15.0)) * along_z())),
            &*bar,
        )
        .unwrap()
        .distance;
        assert_eq!(d, 0.0);
    }

    /// Two unit-free checks of the conversions: a box 100 mm long along X
    /// turned a quarter about Z stands 50 mm along Y; a guard's compound
    /// is as far from a point on its axis as its inner radius.
    #[test]
    fn shapes_stand_where_the_kernel_puts_them() {
        let bar = solid(&Solid::Block {
            size: [100.0, 10.0, 10.0],
        });
        let turned =
            Mat4::from_axis_angle(&crate::math::Vec3::z_axis(), std::f64::consts::FRAC_PI_2);
        let ball = SharedShape::ball(1.0);
        let probe = Mat4::new_translation(&crate::math::Vec3::new(0.0, 60.0, 0.0));
        let d = parry3d_f64::query::distance(
            &pose(&(turned * bar.local)),
            &*bar.shape,
            &pose(&probe),
            &*ball,
        )
        .unwrap()
        .distance;
        assert!((d - 9.0).abs() < 1e-9, "{d}");
        let guard = solid(&Solid::Guard {
            inner: 200.0,
            outer: 220.0,
            width: 50.0,
            cover: 240f64.to_radians(),
        });
        let d = parry3d_f64::query::distance(
            &pose(&guard.local),
            &*guard.shape,
            &Pose::identity(),
            &*ball,
        )
        .unwrap()
        .distance;
        // The sectors' chords stand inside the inner arc by GUARD_FILL at
        // most.
        assert!(d > 199.0 - GUARD_FILL - 1e-9 && d < 199.0 + 1e-9, "{d}");
        // And they hold its outer side: a ball on the outer arc, midway
        // between two of the outer points, touches a sector.
        let outside = Mat4::new_translation(&crate::math::Vec3::new(221.0, 0.0, 0.0));
        let d = parry3d_f64::query::distance(
            &pose(&guard.local),
            &*guard.shape,
            &pose(&outside),
            &*ball,
        )
        .unwrap()
        .distance;
        assert!(d < 1e-9, "{d}");
        // Its reach holds it.
        assert!(guard.reach() >= 220.0, "{}", guard.reach());
        // A centre's cone, 4 mm at its point (z = -20) to 27 mm at z = 20:
        // a ball of 1 mm on its axis's side 8 mm out clears it by the
        // cone's slant distance near its point, and one touching its wide
        // end's rim touches it (the hull holds the circles).
        let cone = solid(&Solid::Cone {
            radius: 4.0,
            end_radius: 27.0,
            length: 40.0,
        });
        let at = |x: Real, z: Real| {
            let p = Mat4::new_translation(&crate::math::Vec3::new(x, 0.0, z));
            parry3d_f64::query::distance(&pose(&cone.local), &*cone.shape, &pose(&p), &*ball)
                .unwrap()
                .distance
        };
        // The slant at z = -20 + 1: radius 4 + 23/40; the point (8, -19)
        // stands off it by (8 - r) cos(atan(23/40)) less the ball.
        let slope: Real = 23.0 / 40.0;
        let want = (8.0 - (4.0 + slope)) * slope.atan().cos() - 1.0;
        let got = at(8.0, -19.0);
        assert!((got - want).abs() < 0.01 * 8.0, "{got} vs {want}");
        assert!(at(28.0, 20.0) < 1e-9);
        assert!(at(0.0, -22.0) > 0.99 && at(0.0, -22.0) < 1.0 + 1e-9);
    }
}
