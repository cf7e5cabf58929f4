//! Closed-form kinematics of the caliber grinders: the chain
//! `Rz(-A) Tz(X) Tx(Z) [Ty(Y)] Rx(B)` from the wheel's frame to the
//! roll's, both ways. Written out rather than solved by the kernel's
//! generic solver: the plugin does not link the kernel, the closed form is
//! exact and branch-free per pose, and it says what the 4-axis machine
//! cannot do instead of converging on a compromise.

use pilgrim_plugin_abi::PluginError;

type V3 = [f64; 3];

/// `Rz(t) v`.
fn rz(t: f64, v: V3) -> V3 {
    let (s, c) = t.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]
}

/// `Rx(t) v`.
fn rx(t: f64, v: V3) -> V3 {
    let (s, c) = t.sin_cos();
    [v[0], c * v[1] - s * v[2], s * v[1] + c * v[2]]
}

/// The angle in (-pi, pi].
fn wrap(t: f64) -> f64 {
    let w = t.rem_euclid(std::f64::consts::TAU);
    if w > std::f64::consts::PI {
        w - std::f64::consts::TAU
    } else {
        w
    }
}

/// Below this sine of the angle between the wheel's axis and the roll's
/// (0.2 arcsec), the Mannesmann takes the axis as the roll's: any roll
/// turn then gives it, and the one that brings the wheel's centre into the
/// plane of the roll's axis is taken (Y = 0), as the LZ-250 does. Above
/// it the axis fixes the turn; a turn read off an axis a rounding error
/// away from the roll's would swing from block to block.
const AXIAL: f64 = 1e-6;

/// The caliber grinders' kinematics: the LZ-250's four axes, or with
/// `cross` the Mannesmann's five. Rows are the solved axes in the
/// descriptions' order: `[X, Z, A, B]` or `[X, Z, Y, A, B]` (mm, rad).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CaliberKinematics {
    /// Whether the machine has the cross axis Y.
    pub cross: bool,
}

impl CaliberKinematics {
    fn width(self) -> usize {
        if self.cross {
            5
        } else {
            4
        }
    }

    /// The axes for one pose: `p` the tracked point, `a` the tool's axis
    /// (part frame); `r`, `t` the tool's point and axis in its own frame.
    ///
    /// The roll turn A: for the Mannesmann, the turn that leaves the
    /// wheel's axis no radial part (of the two, the one with the wheel's
    /// centre on the positive radial side; from the point when the axis is
    /// along the roll's); for the LZ-250, the turn that brings the tracked
    /// point into the plane of the roll's axis and the radius. Then B
    /// swivels the tool's axis onto the asked one's part across the radius,
    /// and X, Z (and Y) place the point.
    pub fn solve(self, p: V3, a: V3, r: V3, t: V3) -> Result<Vec<f64>, String> {
        let norm = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        if !(norm > 0.5 && norm < 2.0) || p.iter().chain(&r).chain(&t).any(|v| !v.is_finite()) {
            return Err(format!(
                "the pose is not a point and a unit axis: axis length {norm}"
            ));
        }
        let a = [a[0] / norm, a[1] / norm, a[2] / norm];
        let swivel = |turn: f64| {
            let q = rz(turn, a);
            wrap(q[2].atan2(q[1]) - t[2].atan2(t[1]))
        };
        // The turn that brings the point's y (after Rz(A)) to `c`, with the
        // point on the positive radial side.
        let point_turn = |c: f64| -> Result<f64, String> {
            let rho = p[0].hypot(p[1]);
            if rho < c.abs() || rho == 0.0 {
                return Err(format!(
                    "the point is {rho:.6} mm from the roll's axis: no roll turn brings it into the wheel's plane"
                ));
            }
            Ok(wrap((c / rho).asin() - p[1].atan2(p[0])))
        };
        let (turn, b) = if self.cross && a[0].hypot(a[1]) > AXIAL {
            // a.x cos A - a.y sin A = t.x: A = +-acos(t.x / rho) - phi.
            let rho = a[0].hypot(a[1]);
            let phi = a[1].atan2(a[0]);
            let base = (t[0] / rho).clamp(-1.0, 1.0).acos();
            let candidates = [wrap(base - phi), wrap(-base - phi)];
            let radial = |turn: f64| {
                let b = swivel(turn);
                rz(turn, p)[0] - rx(b, r)[0]
            };
            let turn = if radial(candidates[0]) >= radial(candidates[1]) {
                candidates[0]
            } else {
                candidates[1]
            };
            (turn, swivel(turn))
        } else {
            // The point into the plane y = (Rx(B) r).y: B depends on A only
            // through the axis, so a few rounds settle it (exactly when the
            // tool's point is its origin).
            let mut turn = point_turn(0.0)?;
            let mut b = swivel(turn);
            for _ in 0..8 {
                turn = point_turn(rx(b, r)[1])?;
                b = swivel(turn);
            }
            (turn, b)
        };
        let q = rz(turn, p);
        let o = rx(b, r);
        let (z, y, x) = (q[0] - o[0], q[1] - o[1], q[2] - o[2]);
        Ok(if self.cross {
            vec![x, z, y, turn, b]
        } else {
            vec![x, z, turn, b]
        })
    }

    /// The angle (rad) between the axis `a` asked for and the one the axes
    /// `row` give the tool's axis `t`: zero wherever the machine reaches
    /// the pose.
    pub fn axis_error(self, row: &[f64], a: V3, t: V3) -> f64 {
        let got = self.pose(row, [0.0; 3], t);
        let g = [got[3], got[4], got[5]];
        let norm = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        let dot = (g[0] * a[0] + g[1] * a[1] + g[2] * a[2]) / norm;
        dot.clamp(-1.0, 1.0).acos()
    }

    /// The tool's point and axis in the part frame for the axes `row`.
    pub fn pose(self, row: &[f64], r: V3, t: V3) -> [f64; 6] {
        let (x, z, y, turn, b) = if self.cross {
            (row[0], row[1], row[2], row[3], row[4])
        } else {
            (row[0], row[1], 0.0, row[2], row[3])
        };
        let o = rx(b, r);
        let p = rz(-turn, [z + o[0], y + o[1], x + o[2]]);
        let a = rz(-turn, rx(b, t));
        [p[0], p[1], p[2], a[0], a[1], a[2]]
    }

    /// Inverse kinematics of rows of 6 (point, axis) into rows of the
    /// solved axes ([`Self::solve`]), the roll's turn continuous from row
    /// to row (the first in (-180, 180] deg, each next the one nearest
    /// its predecessor).
    ///
    /// # Failures
    /// A pose that is not a point and a unit axis, or (LZ-250) a point on
    /// the roll's axis; named by row.
    pub fn inverse(
        self,
        poses: &[f64],
        tool: &[f64; 6],
        out: &mut [f64],
    ) -> Result<(), PluginError> {
        let r = [tool[0], tool[1], tool[2]];
        let t = [tool[3], tool[4], tool[5]];
        let turn_at = if self.cross { 3 } else { 2 };
        let mut last: Option<f64> = None;
        for (i, (p, q)) in poses
            .chunks_exact(6)
            .zip(out.chunks_exact_mut(self.width()))
            .enumerate()
        {
            let row = self
                .solve([p[0], p[1], p[2]], [p[3], p[4], p[5]], r, t)
                .map_err(|m| PluginError::at(i, m))?;
            q.copy_from_slice(&row);
            // The roll turns on: each turn the one nearest the last (a
            // groove may run past half a turn), not wrapped.
            if let Some(prev) = last {
                q[turn_at] = prev + wrap(q[turn_at] - prev);
            }
            last = Some(q[turn_at]);
        }
        Ok(())
    }

    /// Forward kinematics of rows of the solved axes into rows of 6.
    ///
    /// # Failures
    /// None (every row of numbers is a pose).
    pub fn forward(
        self,
        axes: &[f64],
        tool: &[f64; 6],
        out: &mut [f64],
    ) -> Result<(), PluginError> {
        let r = [tool[0], tool[1], tool[2]];
        let t = [tool[3], tool[4], tool[5]];
        for (q, p) in axes.chunks_exact(self.width()).zip(out.chunks_exact_mut(6)) {
            p.copy_from_slice(&self.pose(q, r, t));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pilgrim_kernel::machine::{ChainMachine, Machine, MachineKinematics};
    use pilgrim_kernel::math::{Point3, Vec3};
    use pilgrim_kernel::transform::ToolFrame;

    /// Axis rows spread over the machine's travel, deterministic.
    fn rows(cross: bool, n: usize) -> Vec<f64> {
        (0..n)
            .flat_map(|i| {
                let s = i as f64;
                let x = -100.0 + 7.3 * s % 200.0;
                let z = 150.0 + 11.7 * s % 300.0;
                let y = -40.0 + 3.1 * s % 80.0;
                let a = (-170.0 + 37.0 * s % 340.0).to_radians();
                let b = (-40.0 + 9.0 * s % 80.0).to_radians();
                if cross {
                    vec![x, z, y, a, b]
                } else {
                    vec![x, z, a, b]
                }
            })
            .collect()
    }

    /// Forward kinematics is the description's chain, as the kernel
    /// evaluates it; inverse kinematics gives the rows back: the signs the
    /// module states are the chain's.
    #[test]
    fn closed_form_is_the_chain_both_ways() {
        for cross in [false, true] {
            let k = CaliberKinematics { cross };
            let info = crate::caliber_grinder("caliber grinder", "", cross);
            let chain = ChainMachine::new(Machine::from_info(info).unwrap());
            for tool in [
                ToolFrame {
                    point: Point3::origin(),
                    axis: Vec3::z(),
                },
                ToolFrame {
                    point: Point3::new(0.0, 0.0, 12.0),
                    axis: Vec3::z(),
                },
            ] {
                let t6 = [tool.point.x, tool.point.y, tool.point.z, 0.0, 0.0, 1.0];
                let q = rows(cross, 60);
                let (mut ours, mut theirs) = (vec![0.0; 360], vec![]);
                k.forward(&q, &t6, &mut ours).unwrap();
                chain.forward(&q, &tool, &mut theirs).unwrap();
                for (x, y) in ours.iter().zip(&theirs) {
                    assert!((x - y).abs() < 1e-9, "cross {cross}: {x} vs {y}");
                }
                let mut back = vec![0.0; q.len()];
                k.inverse(&ours, &t6, &mut back).unwrap();
                let w = k.width();
                for (x, y) in back.chunks(w).zip(q.chunks(w)) {
                    // B = 0 puts the wheel's axis along the roll's: the
                    // Mannesmann may then turn the roll anywhere (it takes
                    // Y = 0); the pose is the same.
                    if !cross || y[w - 1].abs() > 1e-6 {
                        for (u, v) in x.iter().zip(y) {
                            assert!(wrap(u - v).abs() < 1e-9, "cross {cross}: {x:?} vs {y:?}");
                        }
                    }
                    let (mut a, mut b) = (vec![0.0; 6], vec![0.0; 6]);
                    k.forward(x, &t6, &mut a).unwrap();
                    k.forward(y, &t6, &mut b).unwrap();
                    for (u, v) in a.iter().zip(&b) {
                        assert!((u - v).abs() < 1e-9, "cross {cross}: {a:?} vs {b:?}");
                    }
                }
            }
        }
    }

    /// +1 deg of A turns the roll +1 deg: a wheel standing still at
    /// theta = 0 is at -1 deg on the roll; +1 deg of B turns the wheel's
    /// axis toward -Y (right-handed about the radial +X).
    #[test]
    fn the_stated_signs_hold() {
        let k = CaliberKinematics { cross: false };
        let p = k.pose(
            &[0.0, 100.0, 1f64.to_radians(), 0.0],
            [0.0; 3],
            [0.0, 0.0, 1.0],
        );
        assert!((p[1].atan2(p[0]) + 1f64.to_radians()).abs() < 1e-12);
        let p = k.pose(
            &[0.0, 100.0, 0.0, 1f64.to_radians()],
            [0.0; 3],
            [0.0, 0.0, 1.0],
        );
        assert!(p[4] < 0.0 && (p[4] + 1f64.to_radians().sin()).abs() < 1e-12);
        let p = k.pose(&[5.0, 100.0, 0.0, 0.0], [0.0; 3], [0.0, 0.0, 1.0]);
        assert_eq!((p[0], p[2]), (100.0, 5.0));
    }

    /// A groove runs past half a turn: along a pass round 300 deg of the
    /// roll the turn A runs on continuously (it had jumped by 360 deg at
    /// 180, which the feed check read as a turn at 115,830 deg/min).
    #[test]
    fn the_roll_turns_on_past_half_a_turn() {
        for cross in [false, true] {
            let k = CaliberKinematics { cross };
            let poses: Vec<f64> = (0..=300)
                .flat_map(|d| {
                    let t = (d as f64).to_radians();
                    let w = [-0.1 * t.sin(), 0.1 * t.cos(), 1.0];
                    let n = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
                    [
                        250.0 * t.cos(),
                        250.0 * t.sin(),
                        5.0,
                        w[0] / n,
                        w[1] / n,
                        w[2] / n,
                    ]
                })
                .collect();
            let width = k.width();
            let mut out = vec![0.0; 301 * width];
            k.inverse(&poses, &[0.0, 0.0, 0.0, 0.0, 0.0, 1.0], &mut out)
                .unwrap();
            let turn = width - 2;
            for r in out.chunks(width).collect::<Vec<_>>().windows(2) {
                assert!(
                    (r[1][turn] - r[0][turn]).abs() < 2f64.to_radians(),
                    "{cross}: {r:?}"
                );
            }
            assert!(
                (out[300 * width + turn] + 300f64.to_radians()).abs() < 1e-9,
                "A = -theta"
            );
        }
    }

    /// A pose whose axis has a radial part: the Mannesmann reaches it (the
    /// roll turns, Y places the centre); the LZ-250 places the point
    /// exactly and the axis as near as it can, the difference the radial
    /// part's angle.
    #[test]
    fn the_four_axis_machine_does_its_best() {
        let t = [0.0, 0.0, 1.0];
        let tilt = 0.05f64;
        let a = [
            tilt.sin(),
            -tilt.cos() * 0.2f64.sin(),
            tilt.cos() * 0.2f64.cos(),
        ];
        let p = [120.0, 15.0, 30.0];
        let five = CaliberKinematics { cross: true };
        let row = five.solve(p, a, [0.0; 3], t).unwrap();
        let got = five.pose(&row, [0.0; 3], t);
        for i in 0..3 {
            assert!((got[i] - p[i]).abs() < 1e-9 && (got[3 + i] - a[i]).abs() < 1e-12);
        }
        let four = CaliberKinematics { cross: false };
        let row = four.solve(p, a, [0.0; 3], t).unwrap();
        let got = four.pose(&row, [0.0; 3], t);
        for i in 0..3 {
            assert!((got[i] - p[i]).abs() < 1e-9);
        }
        let err = four.axis_error(&row, a, t);
        assert!(err > 0.0 && err < tilt + 0.01, "{err}");
        // Reachable poses cost nothing.
        let reach = four.pose(&[3.0, 140.0, 0.4, 0.2], [0.0; 3], t);
        let row = four
            .solve(
                [reach[0], reach[1], reach[2]],
                [reach[3], reach[4], reach[5]],
                [0.0; 3],
                t,
            )
            .unwrap();
        assert!(four.axis_error(&row, [reach[3], reach[4], reach[5]], t) < 1e-12);
    }
}
