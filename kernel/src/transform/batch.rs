//! A chain compiled for batches: consecutive translations merged into one
//! move, rotations applied to the columns of the rotation block, plain
//! arrays, no per-factor dispatch on the value's kind.

use super::{Chain, FactorKind, FactorValue, Pose, ToolFrame};
use crate::math::{sin_cos, sin_cos4, Point3, Real, Vec3};

/// Poses evaluated side by side.
const LANES: usize = 4;
type Lanes = [Real; LANES];

/// `scale * q[axis] + offset`; constants read the extra zero at `q[dof]`.
#[derive(Clone, Copy)]
struct Slot {
    axis: usize,
    scale: Real,
    offset: Real,
}

impl Slot {
    #[inline(always)]
    fn value(&self, q: &[Real]) -> Real {
        self.scale * q[self.axis] + self.offset
    }
}

#[derive(Clone, Copy)]
enum Op {
    /// Translation by (x, y, z) in the current frame.
    Move([Slot; 3]),
    /// Rotation mixing columns i and j of the rotation block.
    Turn(usize, usize),
}

/// The compiled chain.
pub(super) struct Program {
    ops: Vec<Op>,
    /// The rotations' slots, in order: their sines and cosines are computed
    /// first, all together, so that they overlap in the pipeline.
    turns: Vec<Slot>,
}

impl Program {
    pub(super) fn new(chain: &Chain) -> Self {
        let zero = chain.dof();
        let none = Slot {
            axis: zero,
            scale: 0.0,
            offset: 0.0,
        };
        let mut ops: Vec<Op> = Vec::new();
        let mut turns = Vec::new();
        for f in chain.factors() {
            let slot = match f.value {
                FactorValue::Const(v) => Slot {
                    axis: zero,
                    scale: 0.0,
                    offset: v,
                },
                FactorValue::Axis {
                    axis,
                    scale,
                    offset,
                } => Slot {
                    axis,
                    scale,
                    offset,
                },
            };
            if f.kind.is_rotation() {
                let (i, j) = match f.kind {
                    FactorKind::Rx => (1, 2),
                    FactorKind::Ry => (2, 0),
                    _ => (0, 1),
                };
                ops.push(Op::Turn(i, j));
                turns.push(slot);
            } else {
                let d = f.kind.direction_index();
                // Translations commute: merge into the last move while its
                // slot for this direction is free.
                match ops.last_mut() {
                    Some(Op::Move(m)) if m[d].axis == zero && m[d].offset == 0.0 => m[d] = slot,
                    _ => {
                        let mut m = [none; 3];
                        m[d] = slot;
                        ops.push(Op::Move(m));
                    }
                }
            }
        }
        Self { ops, turns }
    }

    /// Poses for every row of `q_rows` (`dof` values each, already checked),
    /// appended to `out`: four rows at a time, lane by lane, the rest singly.
    pub(super) fn poses(&self, q_rows: &[Real], dof: usize, tool: &ToolFrame, out: &mut Vec<Pose>) {
        let mut q_ext = vec![0.0; dof + 1];
        let mut sc1 = vec![(0.0, 1.0); self.turns.len()];
        let mut qv: Vec<Lanes> = vec![[0.0; LANES]; dof + 1];
        let mut sc: Vec<(Lanes, Lanes)> = vec![([0.0; LANES], [1.0; LANES]); self.turns.len()];
        let blocks = q_rows.chunks_exact(dof * LANES);
        let rest = blocks.remainder();
        for block in blocks {
            for (l, row) in block.chunks_exact(dof).enumerate() {
                for (a, &v) in row.iter().enumerate() {
                    qv[a][l] = v;
                }
            }
            self.poses4(&qv, tool, &mut sc, out);
        }
        for q in rest.chunks_exact(dof) {
            q_ext[..dof].copy_from_slice(q);
            out.push(self.pose(&q_ext, tool, &mut sc1));
        }
    }

    /// Four poses; `qv[axis]` holds the axis's value in each lane (and
    /// `qv[dof]` zeros).
    #[inline]
    fn poses4(
        &self,
        qv: &[Lanes],
        tool: &ToolFrame,
        sc: &mut [(Lanes, Lanes)],
        out: &mut Vec<Pose>,
    ) {
        let value = |s: &Slot| -> Lanes {
            let q = &qv[s.axis];
            [
                s.scale * q[0] + s.offset,
                s.scale * q[1] + s.offset,
                s.scale * q[2] + s.offset,
                s.scale * q[3] + s.offset,
            ]
        };
        for (out, s) in sc.iter_mut().zip(&self.turns) {
            *out = sin_cos4(value(s));
        }
        let mut sc = sc.iter();
        let one = [1.0; LANES];
        let zero = [0.0; LANES];
        // r[column][row][lane], t[row][lane].
        let mut r = [[one, zero, zero], [zero, one, zero], [zero, zero, one]];
        let mut t = [zero; 3];
        for op in &self.ops {
            match *op {
                Op::Move(m) => {
                    let v = [value(&m[0]), value(&m[1]), value(&m[2])];
                    for k in 0..3 {
                        for l in 0..LANES {
                            t[k][l] +=
                                r[0][k][l] * v[0][l] + r[1][k][l] * v[1][l] + r[2][k][l] * v[2][l];
                        }
                    }
                }
                Op::Turn(i, j) => {
                    let (sn, cs) = sc.next().copied().unwrap_or((zero, one));
                    let (ci, cj) = (r[i], r[j]);
                    for k in 0..3 {
                        for l in 0..LANES {
                            r[i][k][l] = ci[k][l] * cs[l] + cj[k][l] * sn[l];
                            r[j][k][l] = cj[k][l] * cs[l] - ci[k][l] * sn[l];
                        }
                    }
                }
            }
        }
        let (p, a) = (tool.point.coords, tool.axis);
        for l in 0..LANES {
            let rot = |v: &Vec3, k: usize| r[0][k][l] * v.x + r[1][k][l] * v.y + r[2][k][l] * v.z;
            out.push(Pose {
                point: Point3::new(
                    rot(&p, 0) + t[0][l],
                    rot(&p, 1) + t[1][l],
                    rot(&p, 2) + t[2][l],
                ),
                axis: Vec3::new(rot(&a, 0), rot(&a, 1), rot(&a, 2)),
            });
        }
    }

    /// The tool's pose; `q` holds the axis values and one extra 0, `sc` is
    /// scratch of [`Self::turn_count`] entries.
    #[inline]
    fn pose(&self, q: &[Real], tool: &ToolFrame, sc: &mut [(Real, Real)]) -> Pose {
        for (out, s) in sc.iter_mut().zip(&self.turns) {
            *out = sin_cos(s.value(q));
        }
        let mut sc = sc.iter();
        // Columns of the rotation block, and the translation.
        let mut r = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let mut t = [0.0; 3];
        for op in &self.ops {
            match *op {
                Op::Move(m) => {
                    let v = [m[0].value(q), m[1].value(q), m[2].value(q)];
                    for k in 0..3 {
                        t[k] += r[0][k] * v[0] + r[1][k] * v[1] + r[2][k] * v[2];
                    }
                }
                Op::Turn(i, j) => {
                    let (sn, cs) = sc.next().copied().unwrap_or((0.0, 1.0));
                    let (ci, cj) = (r[i], r[j]);
                    for k in 0..3 {
                        r[i][k] = ci[k] * cs + cj[k] * sn;
                        r[j][k] = cj[k] * cs - ci[k] * sn;
                    }
                }
            }
        }
        let rot = |v: &Vec3| -> [Real; 3] {
            let mut o = [0.0; 3];
            for k in 0..3 {
                o[k] = r[0][k] * v.x + r[1][k] * v.y + r[2][k] * v.z;
            }
            o
        };
        let p = rot(&tool.point.coords);
        let a = rot(&tool.axis);
        Pose {
            point: Point3::new(p[0] + t[0], p[1] + t[1], p[2] + t[2]),
            axis: Vec3::new(a[0], a[1], a[2]),
        }
    }
}
