//! Numerical inverse kinematics for any [`Chain`] (Levenberg–Marquardt).
//!
//! The residual is the tool point's position error (mm) and, when the
//! target gives one, the tool axis's direction error scaled by
//! [`IkOptions::axis_weight`] (mm per unit chord) so that both weigh alike.
//! The Jacobian is exact: one backward sweep carries the tool point and axis
//! through the factors, one forward sweep accumulates the rotations, so an
//! iteration costs about two chain evaluations.

use super::FactorGeometry;
use super::{Chain, FactorKind, FactorValue, Frame, ToolFrame, TransformError};
use crate::input::InputError;
use crate::math::{Point3, Real, Vec3};
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// The inverse kinematics' default tolerance on the tool's position (mm):
/// 0.1 nm, a thousandth of the finest step a program is written in.
const IK_POSITION: Real = 1e-7;

/// The inverse kinematics' default tolerance on the tool's axis (the unit
/// vectors' difference): 1e-9, a nanometre at a metre from the pivot.
const IK_DIRECTION: Real = 1e-9;

/// What inverse kinematics should reach.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Target {
    /// The tool's reference point in the part frame (mm).
    pub point: Point3,
    /// The tool's axis in the part frame, if it is prescribed (any length
    /// but zero; it is normalised).
    pub axis: Option<Vec3>,
}

impl Target {
    /// A position-only target.
    pub fn point(point: Point3) -> Self {
        Self { point, axis: None }
    }

    /// A position and tool-axis target.
    pub fn pose(point: Point3, axis: Vec3) -> Self {
        Self {
            point,
            axis: Some(axis),
        }
    }
}

/// Tolerances and limits of [`Chain::inverse`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct IkOptions {
    /// Largest accepted position error (mm). Default 1e-7 mm.
    pub tol_pos: Real,
    /// Largest accepted tool-axis error, as the chord between unit vectors
    /// (about the angle in rad). Default 1e-9.
    pub tol_dir: Real,
    /// Iteration limit per start. Default 100.
    pub max_iter: usize,
    /// Weight of the axis error against the position error (mm). Default 100 mm.
    pub axis_weight: Real,
    /// Whether to try further starts (rotary axes turned by a quarter or
    /// half turn) when the given seed fails. Default true.
    pub restarts: bool,
}

impl Default for IkOptions {
    fn default() -> Self {
        Self {
            tol_pos: IK_POSITION,
            tol_dir: IK_DIRECTION,
            max_iter: 100,
            axis_weight: 100.0,
            restarts: true,
        }
    }
}

/// A solution of [`Chain::inverse`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IkSolution {
    /// Axis values in the chain's order (mm, rad).
    pub q: Vec<Real>,
    /// Iterations spent over all starts.
    pub iterations: usize,
    /// Position error reached (mm).
    pub pos_err: Real,
    /// Tool-axis error reached (chord).
    pub dir_err: Real,
}

/// Scratch space and the evaluation of residual and Jacobian.
struct Solver<'a> {
    chain: &'a Chain,
    tool: &'a ToolFrame,
    target_p: Vec3,
    target_w: Option<Vec3>,
    weight: Real,
    m: usize,
    /// Residual rows: 3, or 6 with an axis target.
    rows: usize,
    sincos: Vec<(Real, Real)>,
    s: Vec<Vec3>,
    w: Vec<Vec3>,
    /// Jacobian, row-major `rows x m`.
    jac: Vec<Real>,
    res: [Real; 6],
}

#[inline]
fn rotate(kind: FactorKind, s: Real, c: Real, v: &Vec3) -> Vec3 {
    match kind {
        FactorKind::Rx => Vec3::new(v.x, c * v.y - s * v.z, s * v.y + c * v.z),
        FactorKind::Ry => Vec3::new(c * v.x + s * v.z, v.y, -s * v.x + c * v.z),
        _ => Vec3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z),
    }
}

impl<'a> Solver<'a> {
    fn new(chain: &'a Chain, tool: &'a ToolFrame, target: &Target, weight: Real) -> Self {
        let n = chain.factors.len();
        let m = chain.dof();
        let rows = if target.axis.is_some() { 6 } else { 3 };
        Self {
            chain,
            tool,
            target_p: target.point.coords,
            target_w: target.axis.map(|a| a.normalize()),
            weight,
            m,
            rows,
            sincos: vec![(0.0, 1.0); n],
            s: vec![Vec3::zeros(); n],
            w: vec![Vec3::zeros(); n],
            jac: vec![0.0; rows * m],
            res: [0.0; 6],
        }
    }

    /// Evaluates residual (and the Jacobian if `with_jac`); returns the
    /// weighted squared norm of the residual.
    fn eval(&mut self, q: &[Real], with_jac: bool) -> Real {
        let factors = &self.chain.factors;
        let mut s = self.tool.point.coords;
        let mut w = self.tool.axis;
        for (k, f) in factors.iter().enumerate().rev() {
            let v = f.value_at(q);
            if f.kind.is_rotation() {
                let (sn, cs) = crate::math::sin_cos(v);
                self.sincos[k] = (sn, cs);
                s = rotate(f.kind, sn, cs, &s);
                w = rotate(f.kind, sn, cs, &w);
            } else {
                s[f.kind.direction_index()] += v;
            }
            self.s[k] = s;
            self.w[k] = w;
        }
        let dp = s - self.target_p;
        self.res[..3].copy_from_slice(dp.as_slice());
        if let Some(tw) = self.target_w {
            let dw = (w - tw) * self.weight;
            self.res[3..].copy_from_slice(dw.as_slice());
        }
        if with_jac {
            self.jac.iter_mut().for_each(|x| *x = 0.0);
            let mut fr = Frame::identity();
            for (k, f) in factors.iter().enumerate() {
                if let FactorValue::Axis { axis, scale, .. } = f.value {
                    let e = f.kind.direction();
                    let (dp, dw) = if f.kind.is_rotation() {
                        (fr.rot * e.cross(&self.s[k]), fr.rot * e.cross(&self.w[k]))
                    } else {
                        (fr.rot * e, Vec3::zeros())
                    };
                    for r in 0..3 {
                        self.jac[r * self.m + axis] += scale * dp[r];
                    }
                    if self.rows == 6 {
                        for r in 0..3 {
                            self.jac[(r + 3) * self.m + axis] += scale * dw[r] * self.weight;
                        }
                    }
                }
                if f.kind.is_rotation() {
                    let (sn, cs) = self.sincos[k];
                    fr.push_rotation(f.kind, sn, cs);
                }
            }
        }
        self.res[..self.rows].iter().map(|r| r * r).sum()
    }

    fn errors(&self) -> (Real, Real) {
        let pos = Vec3::new(self.res[0], self.res[1], self.res[2]).norm();
        let dir = if self.rows == 6 {
            Vec3::new(self.res[3], self.res[4], self.res[5]).norm() / self.weight
        } else {
            0.0
        };
        (pos, dir)
    }

    /// The Jacobian of the last evaluation that made it, `rows x m`.
    fn jacobian(&self) -> nalgebra::DMatrix<Real> {
        nalgebra::DMatrix::from_row_slice(self.rows, self.m, &self.jac)
    }

    /// The Gauss–Newton step at the last evaluation with its Jacobian:
    /// the least-squares solution of `J d = -r` by the Jacobian's SVD.
    /// A direction whose singular value is below [`SINGULAR`] of the
    /// largest (an axis whose effect nearly vanishes, as a rotary's on the
    /// tool's axis when the tool lies almost along it) is left out while
    /// the residual along it is within `tol` (the tolerances, weighted as
    /// the residual is): there the target does not fix the axis, and the
    /// solution keeps the start's value (the caller's seed decides, not
    /// rounding errors in the target amplified by the weak effect).
    fn gauss_newton(&self, tol: Real) -> Option<nalgebra::DVector<Real>> {
        let svd = self.jacobian().svd(true, true);
        let (u, v_t) = (svd.u.as_ref()?, svd.v_t.as_ref()?);
        let sigma = &svd.singular_values;
        let largest = sigma.max();
        if !(largest > 0.0 && largest.is_finite()) {
            return None;
        }
        let mut step = nalgebra::DVector::zeros(self.m);
        for (i, &s) in sigma.iter().enumerate() {
            let c: Real = -(0..self.rows)
                .map(|r| u[(r, i)] * self.res[r])
                .sum::<Real>();
            let weak = s < SINGULAR * largest;
            if s <= Real::EPSILON * largest || (weak && c.abs() <= tol) {
                continue;
            }
            step += v_t.row(i).transpose() * (c / s);
        }
        Some(step)
    }

    /// Runs Levenberg–Marquardt from `q`, each iteration trying the
    /// undamped Gauss–Newton step first ([`Self::gauss_newton`]): near a
    /// singular pose the damped steps crawl along the valley the weak
    /// direction leaves, where Gauss–Newton converges in a step or two.
    /// Once within the tolerances, one more Gauss–Newton step is taken if
    /// it lowers the residual, so that the solution is as exact as the
    /// target (a rotary barely fixed by the tool's axis is then right to
    /// the program's decimals, not only to the axis tolerance). Returns
    /// (converged, iterations). With `bounds`, every trial point is
    /// projected into the box (the entries that are `None`, rotary axes,
    /// stay free).
    fn solve(
        &mut self,
        q: &mut [Real],
        opts: &IkOptions,
        bounds: &[Option<(Real, Real)>],
    ) -> (bool, usize) {
        let m = self.m;
        let mut a = vec![0.0; m * m];
        let mut g = vec![0.0; m];
        let mut delta = vec![0.0; m];
        let mut damped = vec![0.0; m * m];
        let mut trial = q.to_vec();
        let mut lambda: Real = 1e-3;
        let mut cost = self.eval(q, true);
        // A start that gains less than 10% in STALL iterations is stuck
        // (against the travel box, or in a local minimum): give it up.
        const STALL: usize = 6;
        let mut checkpoint = cost;
        // The tolerances as the residual weighs them (mm).
        let tol_weighted = if self.rows == 6 {
            opts.tol_pos.min(opts.tol_dir * self.weight)
        } else {
            opts.tol_pos
        };
        for it in 0..opts.max_iter {
            let (pe, de) = self.errors();
            let within = pe <= opts.tol_pos && de <= opts.tol_dir;
            // The Gauss–Newton step, shortened by halves until it lowers
            // the residual (a long step along a weak direction meets the
            // chain's curvature), kept if one does.
            if let Some(step) = self.gauss_newton(0.5 * tol_weighted) {
                let mut accepted = false;
                for halving in 0..8 {
                    let f = 0.5f64.powi(halving);
                    for (i, t) in trial.iter_mut().enumerate() {
                        *t = q[i] + f * step[i];
                        if let Some(Some((lo, hi))) = bounds.get(i) {
                            *t = t.clamp(*lo, *hi);
                        }
                    }
                    let c = self.eval(&trial, false);
                    if c.is_finite() && c < cost {
                        accepted = true;
                        break;
                    }
                }
                if accepted {
                    q.copy_from_slice(&trial);
                    cost = self.eval(q, true);
                    lambda = (lambda / 3.0).max(crate::tolerance::ROUNDING);
                    if within {
                        return (true, it + 1);
                    }
                    continue;
                }
                // Back to the last point's residual and Jacobian.
                self.eval(q, true);
            }
            if within {
                return (true, it);
            }
            if it > 0 && it % STALL == 0 {
                if cost > 0.9 * checkpoint {
                    return (false, it);
                }
                checkpoint = cost;
            }
            // Normal equations A = J^T J, g = J^T r.
            for i in 0..m {
                g[i] = (0..self.rows)
                    .map(|r| self.jac[r * m + i] * self.res[r])
                    .sum();
                for j in 0..=i {
                    let v: Real = (0..self.rows)
                        .map(|r| self.jac[r * m + i] * self.jac[r * m + j])
                        .sum();
                    a[i * m + j] = v;
                    a[j * m + i] = v;
                }
            }
            let max_diag = (0..m).map(|i| a[i * m + i]).fold(0.0, Real::max);
            let floor = crate::tolerance::ROUNDING * max_diag.max(crate::tolerance::TINY);
            let mut improved = false;
            while lambda < 1e12 {
                damped.copy_from_slice(&a);
                for i in 0..m {
                    damped[i * m + i] += lambda * a[i * m + i].max(floor);
                }
                delta.iter_mut().zip(&g).for_each(|(d, gi)| *d = -gi);
                if solve_spd(&mut damped, &mut delta, m) {
                    for (i, t) in trial.iter_mut().enumerate() {
                        *t = q[i] + delta[i];
                        if let Some(Some((lo, hi))) = bounds.get(i) {
                            *t = t.clamp(*lo, *hi);
                        }
                    }
                    let c = self.eval(&trial, false);
                    if c.is_finite() && c < cost {
                        q.copy_from_slice(&trial);
                        cost = self.eval(q, true);
                        lambda = (lambda / 3.0).max(crate::tolerance::ROUNDING);
                        improved = true;
                        break;
                    }
                }
                lambda *= 4.0;
            }
            if !improved {
                let (pe, de) = self.errors();
                return (pe <= opts.tol_pos && de <= opts.tol_dir, it + 1);
            }
        }
        let (pe, de) = self.errors();
        (pe <= opts.tol_pos && de <= opts.tol_dir, opts.max_iter)
    }
}

/// A direction of the Jacobian whose singular value is below this share of
/// the largest is weak: on a caliber grinder, a roll turn whose effect on
/// the wheel's axis is the sine of a swivel below about 3e-7 rad, where
/// rounding errors of 1e-13 in the asked axis would swing the turn by
/// 3e-7 rad and the cross slide by tenths of a micron.
const SINGULAR: Real = 1e-7;

impl Solver<'_> {
    /// At a solution `q`, the directions the target leaves free (the weak
    /// ones of [`Self::gauss_newton`]: a singular pose) are settled so that
    /// the linear axes change least from the `seed`: where the pose leaves
    /// a turn and a slide to make up for each other (a swivel at zero
    /// leaves a caliber grinder's roll turn free, its cross slide making
    /// up for it), the rotary turns and the slides stay as the seed had
    /// them. Moves along the free directions, then back onto the target
    /// with Gauss–Newton, at most three rounds; kept only if the target is
    /// still met within the tolerances. Returns the iterations spent.
    fn settle(
        &mut self,
        q: &mut [Real],
        seed: &[Real],
        opts: &IkOptions,
        bounds: &[Option<(Real, Real)>],
    ) -> usize {
        let linear: Vec<usize> = (0..self.m).filter(|&i| !self.chain.is_rotary(i)).collect();
        let mut spent = 0;
        for _ in 0..3 {
            self.eval(q, true);
            // The free directions: the eigenvectors of J^T J whose
            // eigenvalues (the singular values squared) are weak, which
            // also gives the directions of rows a position-only target
            // does not have.
            let eig = (self.jacobian().transpose() * self.jacobian()).symmetric_eigen();
            let largest = eig.eigenvalues.max();
            let basis: Vec<nalgebra::DVector<Real>> = (0..self.m)
                .filter(|&i| eig.eigenvalues[i] < SINGULAR * SINGULAR * largest)
                .map(|i| eig.eigenvectors.column(i).into_owned())
                .collect();
            if basis.is_empty() || linear.is_empty() {
                break;
            }
            // The move along the free directions that brings the linear
            // axes nearest the seed's, each weighed by its share in those
            // directions (the slide that makes up for the turn, not one
            // the turn moves only at second order).
            let share: Vec<Real> = linear
                .iter()
                .map(|&i| basis.iter().map(|v| v[i] * v[i]).sum::<Real>().sqrt())
                .collect();
            let a = nalgebra::DMatrix::from_fn(linear.len(), basis.len(), |r, c| {
                share[r] * basis[c][linear[r]]
            });
            let d = nalgebra::DVector::from_iterator(
                linear.len(),
                linear
                    .iter()
                    .zip(&share)
                    .map(|(&i, w)| w * (seed[i] - q[i])),
            );
            let Ok(alpha) = a.svd(true, true).solve(&d, crate::tolerance::ROUNDING) else {
                break;
            };
            let mut moved = q.to_vec();
            for (c, v) in basis.iter().enumerate() {
                for (i, m) in moved.iter_mut().enumerate() {
                    *m += alpha[c] * v[i];
                }
            }
            let change: Real = moved
                .iter()
                .zip(q.iter())
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, Real::max);
            if !(change > crate::tolerance::ROUNDING) {
                break;
            }
            let (ok, it) = self.solve(&mut moved, opts, bounds);
            spent += it;
            if !ok {
                break;
            }
            q.copy_from_slice(&moved);
        }
        self.eval(q, true);
        spent
    }
}

/// Solves `a x = b` in place for a symmetric positive definite `a` (m x m,
/// row-major) by Cholesky; `false` if `a` is not positive definite.
fn solve_spd(a: &mut [Real], b: &mut [Real], m: usize) -> bool {
    for j in 0..m {
        let mut d = a[j * m + j];
        for k in 0..j {
            d -= a[j * m + k] * a[j * m + k];
        }
        if d <= 0.0 || !d.is_finite() {
            return false;
        }
        let d = d.sqrt();
        a[j * m + j] = d;
        for i in j + 1..m {
            let mut v = a[i * m + j];
            for k in 0..j {
                v -= a[i * m + k] * a[j * m + k];
            }
            a[i * m + j] = v / d;
        }
    }
    for i in 0..m {
        let mut v = b[i];
        for k in 0..i {
            v -= a[i * m + k] * b[k];
        }
        b[i] = v / a[i * m + i];
    }
    for i in (0..m).rev() {
        let mut v = b[i];
        for k in i + 1..m {
            v -= a[k * m + i] * b[k];
        }
        b[i] = v / a[i * m + i];
    }
    true
}

/// Brings rotary values into their travel by whole turns; returns the first
/// axis still outside travel, if any.
fn fit_travel(chain: &Chain, q: &mut [Real], travel: &[(Real, Real)]) -> Option<usize> {
    for (i, (v, &(lo, hi))) in q.iter_mut().zip(travel).enumerate() {
        if chain.is_rotary(i) && (*v < lo || *v > hi) {
            let turned = *v + TAU * ((lo - *v) / TAU).ceil();
            if turned <= hi {
                *v = turned;
            }
        }
        if *v < lo || *v > hi {
            return Some(i);
        }
    }
    None
}

impl Chain {
    /// Axis values that put `tool` at `target`, starting from `seed`.
    ///
    /// `travel`, if given, holds each axis's `(min, max)` in the chain's
    /// order (mm, rad); rotary values are moved by whole turns to fit it.
    /// When the seed fails and [`IkOptions::restarts`] is set, further starts
    /// are tried: the linear axes at the middle of their travel, and the
    /// rotary axes turned by quarter and half turns (mirrored solutions).
    ///
    /// # Failures
    /// - [`TransformError::Unreachable`]: no start reached the target within
    ///   the tolerances (the error gives the best errors reached);
    /// - [`TransformError::OutsideTravel`]: the target was reached only with
    ///   an axis outside its travel (named with the value it needs);
    /// - a seed or travel of the wrong length, a non-finite target or a zero
    ///   target axis; a chain with no axes.
    ///
    /// ```
    /// use pilgrim_kernel::{Chain, FactorKind::*, IkOptions, Point3, Target, ToolFrame};
    /// let mill = Chain::builder().axis(Rz, "C").axis(Tx, "X").axis(Ty, "Y").build().unwrap();
    /// let target = Target::point(Point3::new(0.0, 25.0, 0.0));
    /// let sol = mill
    ///     .inverse(&target, &ToolFrame::default(), &[0.0, 10.0, 0.0], None, &IkOptions::default())
    ///     .unwrap();
    /// let reached = mill.apply(&sol.q, &Point3::origin()).unwrap();
    /// assert!((reached - target.point).norm() < 1e-7);
    /// ```
    pub fn inverse(
        &self,
        target: &Target,
        tool: &ToolFrame,
        seed: &[Real],
        travel: Option<&[(Real, Real)]>,
        opts: &IkOptions,
    ) -> Result<IkSolution, TransformError> {
        self.check_len(seed)?;
        crate::math::all_finite("IK seed", seed)?;
        crate::math::all_finite("IK target point", target.point.coords.as_slice())?;
        if let Some(a) = target.axis {
            crate::math::all_finite("IK target axis", a.as_slice())?;
            if a.norm() == 0.0 {
                return Err(InputError::NotPositive {
                    what: "IK target axis length".into(),
                    value: 0.0,
                }
                .into());
            }
        }
        if let Some(t) = travel {
            if t.len() != self.dof() {
                return Err(InputError::LengthMismatch {
                    what: "travel limits vs chain axes".into(),
                    left: t.len(),
                    right: self.dof(),
                }
                .into());
            }
        }
        if self.dof() == 0 {
            return Err(TransformError::NoAxes);
        }
        crate::math::positive("IK position tolerance", opts.tol_pos)?;
        crate::math::positive("IK axis tolerance", opts.tol_dir)?;
        crate::math::positive("IK axis weight", opts.axis_weight)?;

        let mut solver = Solver::new(self, tool, target, opts.axis_weight);
        let rotary: Vec<usize> = (0..self.dof()).filter(|&i| self.is_rotary(i)).collect();
        // Starts: the seed; then (with restarts) the seed with the linear
        // axes at the middle of their travel; each also with the rotary axes
        // turned by quarter and half turns, where mirrored solutions lie.
        let mut bases = vec![seed.to_vec()];
        if opts.restarts {
            if let Some(t) = travel {
                let mut mid = seed.to_vec();
                for (i, &(lo, hi)) in t.iter().enumerate() {
                    if !self.is_rotary(i) {
                        mid[i] = 0.5 * (lo + hi);
                    }
                }
                if mid != seed {
                    bases.push(mid);
                }
            }
        }
        let mut turns: Vec<Vec<(usize, Real)>> = vec![vec![]];
        if opts.restarts {
            for turn in [FRAC_PI_2, -FRAC_PI_2, PI] {
                turns.push(rotary.iter().map(|&i| (i, turn)).collect());
            }
            if rotary.len() == 2 {
                for (t0, t1) in [
                    (PI, 0.0),
                    (0.0, PI),
                    (FRAC_PI_2, -FRAC_PI_2),
                    (-FRAC_PI_2, FRAC_PI_2),
                ] {
                    turns.push(vec![(rotary[0], t0), (rotary[1], t1)]);
                }
            }
        }
        let starts = bases.iter().flat_map(|b| {
            turns.iter().map(move |t| {
                let mut s = b.clone();
                t.iter().for_each(|&(i, d)| s[i] += d);
                s
            })
        });
        // Phase 1: each start, with the linear axes kept inside their travel
        // (so that a mirrored solution outside it is not where LM ends up).
        let boxed: Vec<Option<(Real, Real)>> = match travel {
            Some(t) => t
                .iter()
                .enumerate()
                .map(|(i, &b)| (!self.is_rotary(i)).then_some(b))
                .collect(),
            None => vec![],
        };
        let mut iterations = 0;
        let mut best = (Real::INFINITY, Real::INFINITY);
        for mut q in starts {
            for (v, b) in q.iter_mut().zip(&boxed) {
                if let Some((lo, hi)) = b {
                    *v = v.clamp(*lo, *hi);
                }
            }
            let (ok, it) = solver.solve(&mut q, opts, &boxed);
            iterations += it;
            if ok {
                iterations += solver.settle(&mut q, seed, opts, &boxed);
            }
            let (pe, de) = solver.errors();
            if pe + de * opts.axis_weight < best.0 + best.1 * opts.axis_weight {
                best = (pe, de);
            }
            if ok && travel.is_none_or(|t| fit_travel(self, &mut q, t).is_none()) {
                return Ok(IkSolution {
                    q,
                    iterations,
                    pos_err: pe,
                    dir_err: de,
                });
            }
        }
        // Phase 2 (only to explain the failure): free of travel, from the
        // seed, is the target reachable at all, and with which axis outside?
        if let Some(t) = travel {
            let mut q = seed.to_vec();
            let (ok, it) = solver.solve(&mut q, opts, &[]);
            iterations += it;
            if ok {
                if let Some(i) = fit_travel(self, &mut q, t) {
                    return Err(TransformError::OutsideTravel {
                        axis: self.axes[i].clone(),
                        value: q[i],
                        min: t[i].0,
                        max: t[i].1,
                    });
                }
            }
        }
        Err(TransformError::Unreachable {
            point: [target.point.x, target.point.y, target.point.z],
            pos_err: best.0,
            dir_err: best.1,
            iterations,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transform::FactorKind::*;

    fn five_axis() -> Chain {
        Chain::builder()
            .axis_scaled(Rz, "A", -1.0, 0.0)
            .axis(Tz, "X")
            .axis(Tx, "Z")
            .axis(Ty, "Y")
            .axis(Rx, "B")
            .build()
            .unwrap()
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let ch = five_axis();
        let tool = ToolFrame {
            point: Point3::new(1.0, 2.0, 3.0),
            axis: Vec3::new(0.0, 0.6, 0.8),
        };
        let target = Target::pose(Point3::origin(), Vec3::x());
        let mut s = Solver::new(&ch, &tool, &target, 10.0);
        let q = [0.3, 5.0, 120.0, -4.0, 0.2];
        s.eval(&q, true);
        let jac = s.jac.clone();
        let h = 1e-6;
        for i in 0..5 {
            let mut qp = q;
            qp[i] += h;
            s.eval(&qp, false);
            let rp = s.res;
            let mut qm = q;
            qm[i] -= h;
            s.eval(&qm, false);
            for r in 0..6 {
                let fd = (rp[r] - s.res[r]) / (2.0 * h);
                assert!(
                    (fd - jac[r * 5 + i]).abs() < 1e-5 * (1.0 + fd.abs()),
                    "row {r} axis {i}: {fd} vs {}",
                    jac[r * 5 + i]
                );
            }
        }
    }

    /// Near a singular pose (a swivel of 3e-6 rad: the roll's turn moves
    /// the wheel's axis by that much per radian) the turn is still solved
    /// to what the axis fixes, not left where the tolerance stops; at the
    /// singular pose itself (the swivel at zero) the turn is free, and the
    /// solution keeps the cross slide where the seed has it, the turn
    /// making up the point, as the plugin's closed form does.
    #[test]
    fn singular_poses_are_solved_exactly_and_settled_by_the_seed() {
        let ch = five_axis();
        let tool = ToolFrame::default();
        for (b, seed_y) in [(3e-6, 0.0), (0.0, 0.0), (0.0, 0.4)] {
            let truth = [0.7, 5.0, 250.0, seed_y, b];
            let pose = ch.pose(&truth, &tool).unwrap();
            let target = Target::pose(pose.point, pose.axis);
            // The last block's solution: a degree of turn behind.
            let seed = [0.7 - 0.0175, 5.1, 249.0, seed_y, 1.2 * b];
            let sol = ch
                .inverse(&target, &tool, &seed, None, &IkOptions::default())
                .unwrap();
            assert!((sol.q[0] - 0.7).abs() < 1e-9, "B = {b}: {:?}", sol.q);
            assert!((sol.q[3] - seed_y).abs() < 1e-7, "B = {b}: {:?}", sol.q);
        }
    }

    #[test]
    fn unreachable_and_outside_travel_are_named() {
        // A lathe moves only in X and Z: a target off the XZ plane is unreachable.
        let lathe = Chain::builder()
            .axis(Tz, "Z")
            .axis_scaled(Tx, "X", 0.5, 0.0)
            .build()
            .unwrap();
        let e = lathe
            .inverse(
                &Target::point(Point3::new(10.0, 3.0, 5.0)),
                &ToolFrame::default(),
                &[0.0, 0.0],
                None,
                &IkOptions::default(),
            )
            .unwrap_err();
        assert!(matches!(e, TransformError::Unreachable { .. }), "{e}");
        assert!(e.to_string().contains("unreachable"), "{e}");
        let e = lathe
            .inverse(
                &Target::point(Point3::new(10.0, 0.0, 5.0)),
                &ToolFrame::default(),
                &[0.0, 0.0],
                Some(&[(-100.0, 100.0), (0.0, 15.0)]),
                &IkOptions::default(),
            )
            .unwrap_err();
        match e {
            TransformError::OutsideTravel { axis, value, .. } => {
                assert_eq!(axis, "X");
                assert!((value - 20.0).abs() < 1e-6);
            }
            other => panic!("{other}"),
        }
    }

    #[test]
    fn rotary_values_wrap_into_travel() {
        let ch = Chain::builder()
            .axis(Rz, "C")
            .constant(Tx, 10.0)
            .build()
            .unwrap();
        let target = Target::point(Point3::new(0.0, -10.0, 0.0));
        let sol = ch
            .inverse(
                &target,
                &ToolFrame::default(),
                &[0.0],
                Some(&[(0.0, TAU)]),
                &IkOptions::default(),
            )
            .unwrap();
        assert!((sol.q[0] - 1.5 * PI).abs() < 1e-6, "{:?}", sol.q);
    }
}
