//! Solids that are not bodies of revolution (the caliber's roll with its
//! groove, a worm's thread) as STEP: a body swept through a family of closed
//! sections, each section's pieces carried along the sweep as one B-spline
//! surface, fitted within a stated tolerance of the body's own geometry,
//! closed by two planar end faces.
//!
//! The surfaces interpolate the body's points on a grid (cubic across each
//! piece and along the sweep; linear across a piece that is a straight line
//! in every section) and are refined, adding points, until the surface
//! stays within the tolerance of the body at the middle of every cell.
//! Neighbouring pieces share the curve between them (the same control
//! points), so the faces meet exactly and the shell closes. The
//! interpolation is written here (de Boor's averaged knots and a banded
//! solve, about 80 lines) because truck-geometry 0.5 fits no B-spline to
//! points, and curvo's `try_interpolate` fits one curve at a time on its own
//! chord-length parameters: a tensor-product surface needs the same knots
//! for every row and column, and one factorization here serves the
//! thousands of columns of a fit.

use super::{write, StepError};
use crate::math::Real;
use truck_modeling::{
    BSplineCurve, BSplineSurface, Curve, Edge, Face, KnotVec, Point3, Shell, Surface, Vertex, Wire,
};

/// The most control points a swept solid may have in all (a STEP file of
/// tens of megabytes); more is refused, naming the tolerance.
pub const MAX_CONTROL_POINTS: usize = 2_000_000;

/// The most grid points along the sweep or across a piece.
const MAX_ALONG: usize = 20_000;

/// A body swept through closed sections: for `v` from 0 to 1 along the
/// sweep, the section is the closed loop of `pieces()` curves, piece `k`
/// running for `u` from 0 to 1 from where piece `k - 1` ends to where piece
/// `k + 1` starts (the last piece ends where the first starts). The
/// sections at `v = 0` and `v = 1` must each lie in a plane, and each of
/// those planes must either contain the Z axis or be square to it, or
/// both be parallel to Z ([`Sections::ends_along_z`]): the volume is found
/// from the lateral faces alone.
pub trait Sections {
    /// How many pieces each section has.
    fn pieces(&self) -> usize;
    /// Whether piece `k` is a straight line in every section (a ruled face,
    /// fitted linear across).
    fn straight(&self, k: usize) -> bool;
    /// The point of piece `k` at `u` across it, `v` along the sweep (mm).
    fn point(&self, k: usize, u: Real, v: Real) -> [Real; 3];
    /// How many points along the sweep to start from (refined as needed).
    fn along(&self) -> usize;
    /// Whether the end sections lie in planes parallel to Z (a blade's
    /// faces): the volume is then the flux of `(0, 0, z)` through the
    /// lateral faces, which does not cross them; else (the default) of
    /// `(x, y, 0) / 2`, which does not cross planes containing Z or square
    /// to it.
    fn ends_along_z(&self) -> bool {
        false
    }
    /// A hollow body's outside: the solid is then the space between a
    /// cylinder of this radius about Z, from the first section's plane to
    /// the last's (each square to Z), and the sections, which bound its
    /// hole (a nut round its thread). `None` (the default): the sections
    /// bound the solid.
    fn outside(&self) -> Option<Real> {
        None
    }
}

/// What fitting a swept solid found.
#[derive(Debug, Clone, PartialEq)]
pub struct SweptFit {
    /// The STEP file's text.
    pub text: String,
    /// The solid's volume from its own surfaces (mm^3).
    pub volume: Real,
    /// The largest distance between a surface and the body at the middle
    /// of the grid's cells (mm).
    pub deviation: Real,
    /// Faces across a section (one per piece).
    pub faces: usize,
    /// Grid points along the sweep.
    pub along: usize,
}

/// A clamped knot vector averaged over uniform parameters (de Boor): the
/// interpolation's knots for `n` points, degree `p`.
fn knots(n: usize, p: usize) -> Vec<Real> {
    let t = |i: usize| i as Real / (n - 1) as Real;
    let mut k = vec![0.0; p + 1];
    for j in 1..n - p {
        k.push((j..j + p).map(t).sum::<Real>() / p as Real);
    }
    k.extend(std::iter::repeat_n(1.0, p + 1));
    k
}

/// The B-spline basis functions of degree `p` (at most 3) over `knots` at
/// `t` that can be non-zero: the first one's index and their values
/// (Cox-de Boor; at the last knot, the last function is 1). On the stack:
/// a check or an integral evaluates it millions of times.
fn basis(knots: &[Real], p: usize, t: Real) -> (usize, [Real; 4]) {
    debug_assert!(p <= 3);
    let n = knots.len() - p - 1;
    let span = if t >= knots[n] {
        n - 1
    } else {
        knots
            .partition_point(|k| *k <= t)
            .saturating_sub(1)
            .clamp(p, n - 1)
    };
    let mut b = [1.0, 0.0, 0.0, 0.0];
    let (mut left, mut right) = ([0.0; 4], [0.0; 4]);
    for j in 1..=p {
        left[j] = t - knots[span + 1 - j];
        right[j] = knots[span + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            let d = right[r + 1] + left[j - r];
            let tmp = if d == 0.0 { 0.0 } else { b[r] / d };
            b[r] = saved + right[r + 1] * tmp;
            saved = left[j - r] * tmp;
        }
        b[j] = saved;
    }
    (span - p, b)
}

/// The basis functions that can be non-zero at a place: the first's index
/// and their values.
type Basis = (usize, [Real; 4]);

/// The interpolation of `n` points at uniform parameters by a B-spline of
/// degree `p`: its knots and the collocation matrix factored without
/// pivoting (it is totally positive and banded, de Boor), so that each set
/// of points is solved in O(n).
struct Interpolation {
    knots: Vec<Real>,
    /// Row `i`: the first column and the band's values after elimination.
    rows: Vec<(usize, Vec<Real>)>,
    /// The elimination's multipliers: row `i` less `m * row j`.
    steps: Vec<(usize, usize, Real)>,
}

impl Interpolation {
    fn new(n: usize, p: usize) -> Self {
        let knots = knots(n, p);
        let mut rows: Vec<(usize, Vec<Real>)> = (0..n)
            .map(|i| {
                let (first, b) = basis(&knots, p, i as Real / (n - 1) as Real);
                // Widen each row to a band of 2p + 1 from i - p.
                let lo = i.saturating_sub(p);
                let mut band = vec![0.0; 2 * p + 1];
                for (j, v) in b.into_iter().take(p + 1).enumerate() {
                    band[first + j - lo] = v;
                }
                (lo, band)
            })
            .collect();
        let mut steps = Vec::new();
        for j in 0..n {
            let pivot_row = rows[j].clone();
            let pivot = pivot_row.1[j - pivot_row.0];
            for i in j + 1..(j + p + 1).min(n) {
                let (lo, band) = &mut rows[i];
                let m = band[j - *lo] / pivot;
                if m == 0.0 {
                    continue;
                }
                for c in j..(pivot_row.0 + pivot_row.1.len()).min(n) {
                    band[c - *lo] -= m * pivot_row.1[c - pivot_row.0];
                }
                steps.push((i, j, m));
            }
        }
        Interpolation { knots, rows, steps }
    }

    /// The control points that interpolate `points`.
    fn solve(&self, points: &[[Real; 3]]) -> Vec<[Real; 3]> {
        let mut b = points.to_vec();
        for &(i, j, m) in &self.steps {
            let bj = b[j];
            for c in 0..3 {
                b[i][c] -= m * bj[c];
            }
        }
        let n = b.len();
        let mut x = vec![[0.0; 3]; n];
        for i in (0..n).rev() {
            let (lo, band) = &self.rows[i];
            let mut s = b[i];
            for c in i + 1..(lo + band.len()).min(n) {
                for d in 0..3 {
                    s[d] -= band[c - lo] * x[c][d];
                }
            }
            let diag = band[i - lo];
            x[i] = [s[0] / diag, s[1] / diag, s[2] / diag];
        }
        x
    }
}

/// One piece's fitted surface: control points `[across][along]` and the
/// knots across.
struct Patch {
    knots_u: Vec<Real>,
    ctrl: Vec<Vec<[Real; 3]>>,
}

impl Patch {
    /// Its degree across.
    fn degree_u(&self) -> usize {
        self.knots_u.len() - self.ctrl.len() - 1
    }

    /// Its point at `(u, v)`, the knots along being `knots_v` (cubic): only
    /// the (p + 1)^2 control points whose functions are not nil there (truck
    /// evaluates every basis function, which makes a check of a fine grid
    /// quadratic in its size).
    fn at(&self, knots_v: &[Real], u: Real, v: Real) -> [Real; 3] {
        let pv = knots_v.len() - self.ctrl[0].len() - 1;
        self.with(
            basis(&self.knots_u, self.degree_u(), u),
            basis(knots_v, pv, v),
            pv,
        )
    }

    /// Its point from the basis functions across and along (degree `pv`
    /// along) at a place.
    fn with(
        &self,
        (iu, bu): (usize, [Real; 4]),
        (iv, bv): (usize, [Real; 4]),
        pv: usize,
    ) -> [Real; 3] {
        let mut p = [0.0; 3];
        for (a, wu) in bu.iter().take(self.degree_u() + 1).enumerate() {
            for (b, wv) in bv.iter().take(pv + 1).enumerate() {
                let c = self.ctrl[iu + a][iv + b];
                for d in 0..3 {
                    p[d] += wu * wv * c[d];
                }
            }
        }
        p
    }

    /// The patch of its derivative across (one degree lower across).
    fn d_across(&self) -> Patch {
        let (k, p) = (&self.knots_u, self.degree_u());
        let ctrl = (0..self.ctrl.len() - 1)
            .map(|i| {
                let f = p as Real / (k[i + p + 1] - k[i + 1]);
                (0..self.ctrl[i].len())
                    .map(|j| scaled_difference(f, self.ctrl[i][j], self.ctrl[i + 1][j]))
                    .collect()
            })
            .collect();
        Patch {
            knots_u: k[1..k.len() - 1].to_vec(),
            ctrl,
        }
    }

    /// The patch of its derivative along, over `knots_v` (the knots along
    /// of the derivative are `knots_v` less its ends).
    fn d_along(&self, knots_v: &[Real]) -> Patch {
        let p = knots_v.len() - self.ctrl[0].len() - 1;
        let ctrl = self
            .ctrl
            .iter()
            .map(|row| {
                (0..row.len() - 1)
                    .map(|j| {
                        let f = p as Real / (knots_v[j + p + 1] - knots_v[j + 1]);
                        scaled_difference(f, row[j], row[j + 1])
                    })
                    .collect()
            })
            .collect();
        Patch {
            knots_u: self.knots_u.clone(),
            ctrl,
        }
    }
}

/// `f (b - a)`: a control point of a B-spline's derivative from two of its
/// own.
fn scaled_difference(f: Real, a: [Real; 3], b: [Real; 3]) -> [Real; 3] {
    [f * (b[0] - a[0]), f * (b[1] - a[1]), f * (b[2] - a[2])]
}

/// The patches of every piece, `across[k]` points across piece `k` and
/// `along` along the sweep; the first column of each patch is the last of
/// the one before, exactly.
fn patches(body: &dyn Sections, across: &[usize], along: usize) -> Vec<Patch> {
    let iv = Interpolation::new(along, 3.min(along - 1));
    let vs: Vec<Real> = (0..along)
        .map(|j| j as Real / (along - 1) as Real)
        .collect();
    let mut out: Vec<Patch> = across
        .iter()
        .enumerate()
        .map(|(k, &n)| {
            let p = if body.straight(k) { 1 } else { 3.min(n - 1) };
            let iu = Interpolation::new(n, p);
            // Along the sweep first, then across at each control column.
            let rows: Vec<Vec<[Real; 3]>> = (0..n)
                .map(|i| {
                    let u = i as Real / (n - 1) as Real;
                    iv.solve(&vs.iter().map(|&v| body.point(k, u, v)).collect::<Vec<_>>())
                })
                .collect();
            let mut ctrl = vec![vec![[0.0; 3]; along]; n];
            for j in 0..along {
                let col = iu.solve(&rows.iter().map(|r| r[j]).collect::<Vec<_>>());
                for (i, c) in col.into_iter().enumerate() {
                    ctrl[i][j] = c;
                }
            }
            Patch {
                knots_u: iu.knots,
                ctrl,
            }
        })
        .collect();
    // Each piece ends on the curve the next one starts on.
    for k in 0..out.len() {
        let next = out[(k + 1) % out.len()].ctrl[0].clone();
        if let Some(last) = out[k].ctrl.last_mut() {
            *last = next;
        }
    }
    out
}

fn surface(p: &Patch, knots_v: &[Real]) -> BSplineSurface<Point3> {
    let pts = p
        .ctrl
        .iter()
        .map(|r| r.iter().map(|c| Point3::new(c[0], c[1], c[2])).collect())
        .collect();
    BSplineSurface::new(
        (
            KnotVec::from(p.knots_u.clone()),
            KnotVec::from(knots_v.to_vec()),
        ),
        pts,
    )
}

/// The largest distance between the surfaces and the body at the middles
/// of the grid's cells: `(across each piece, along, both)`.
fn deviations(
    body: &dyn Sections,
    patches: &[Patch],
    knots_v: &[Real],
    along: usize,
) -> (Vec<Real>, Real, Real) {
    let mut e_u = vec![0.0; patches.len()];
    let (mut e_v, mut e_uv) = (0.0 as Real, 0.0 as Real);
    for (k, s) in patches.iter().enumerate() {
        let n = s.ctrl.len();
        let dist = |u: Real, v: Real| {
            let p = s.at(knots_v, u, v);
            let q = body.point(k, u, v);
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
        };
        let h_u = 1.0 / (n - 1) as Real;
        let h_v = 1.0 / (along - 1) as Real;
        for i in 0..n {
            for j in 0..along {
                let (u, v) = (i as Real * h_u, j as Real * h_v);
                if i + 1 < n {
                    e_u[k] = Real::max(e_u[k], dist(u + 0.5 * h_u, v));
                }
                if j + 1 < along {
                    e_v = e_v.max(dist(u, v + 0.5 * h_v));
                }
                if i + 1 < n && j + 1 < along {
                    e_uv = e_uv.max(dist(u + 0.5 * h_u, v + 0.5 * h_v));
                }
            }
        }
    }
    (e_u, e_v, e_uv)
}

/// The volume the lateral surfaces enclose: half the flux of (x, y, 0)
/// through them (through end planes that contain Z or are square to it, the
/// flux is nil), or with `axial` the flux of (0, 0, z) (nil through end
/// planes parallel to Z), by 5-point Gauss-Legendre on each knot span
/// (exact for the integrand's degree).
fn volume(patches: &[Patch], knots_v: &[Real], axial: bool) -> Real {
    const X: [Real; 5] = [
        0.0,
        -0.538_469_310_105_683,
        0.538_469_310_105_683,
        -0.906_179_845_938_664,
        0.906_179_845_938_664,
    ];
    const W: [Real; 5] = [
        0.568_888_888_888_888_9,
        0.478_628_670_499_366_5,
        0.478_628_670_499_366_5,
        0.236_926_885_056_189_1,
        0.236_926_885_056_189_1,
    ];
    let spans = |k: &[Real]| -> Vec<(Real, Real)> {
        k.windows(2)
            .filter(|w| w[1] > w[0])
            .map(|w| (w[0], w[1]))
            .collect()
    };
    // Each Gauss point of each span: its weight times half the span and
    // the basis functions of the degree given and one lower there.
    let points = |k: &[Real], p: usize| -> Vec<(Real, Basis, Basis)> {
        let lower = &k[1..k.len() - 1];
        spans(k)
            .into_iter()
            .flat_map(|(t0, t1)| {
                (0..5).map(move |a| {
                    let t = 0.5 * (t0 + t1) + 0.5 * (t1 - t0) * X[a];
                    (
                        W[a] * 0.5 * (t1 - t0),
                        basis(k, p, t),
                        basis(lower, p.saturating_sub(1), t),
                    )
                })
            })
            .collect()
    };
    let along = points(knots_v, 3);
    let mut sum = 0.0;
    for s in patches {
        let (su_net, sv_net) = (s.d_across(), s.d_along(knots_v));
        let pu = s.degree_u();
        for (wu, bu, bu_d) in points(&s.knots_u, pu) {
            for (wv, bv, bv_d) in &along {
                let p = s.with(bu, *bv, 3);
                let su = su_net.with(bu_d, *bv, 3);
                let sv = sv_net.with(bu, *bv_d, 2);
                let (nx, ny) = (su[1] * sv[2] - su[2] * sv[1], su[2] * sv[0] - su[0] * sv[2]);
                sum += wu
                    * wv
                    * if axial {
                        // z (su x sv)_z, twice: the field is (0, 0, z).
                        2.0 * p[2] * (su[0] * sv[1] - su[1] * sv[0])
                    } else {
                        // (x, y) . (su x sv)
                        p[0] * nx + p[1] * ny
                    };
            }
        }
    }
    0.5 * sum
}

/// The STEP file of `body` (the product named `name`, described as
/// `what`), its surfaces within `tol` of the body at the middle of every
/// cell of the grid they interpolate.
///
/// # Failures
/// A body of fewer than one piece or non-finite points; a tolerance not
/// positive; a fit that needs more than [`MAX_CONTROL_POINTS`]; faces that
/// do not close a solid.
pub fn swept_step(
    name: &str,
    what: &str,
    body: &dyn Sections,
    tol: Real,
) -> Result<SweptFit, StepError> {
    crate::math::positive("STEP tolerance", tol)?;
    let bad = |message: String| StepError::Section {
        body: name.to_owned(),
        message,
    };
    let n = body.pieces();
    if n == 0 {
        return Err(bad("the section has no pieces".into()));
    }
    let mut across: Vec<usize> = (0..n)
        .map(|k| if body.straight(k) { 2 } else { 4 })
        .collect();
    let mut along = body.along().max(4);
    let mut before = Real::INFINITY;
    let (ps, deviation) = loop {
        let total: usize = across.iter().sum::<usize>() * along;
        if total > MAX_CONTROL_POINTS || along > MAX_ALONG || across.iter().any(|&a| a > MAX_ALONG)
        {
            return Err(bad(format!(
                "a fit within {tol} mm needs more than {MAX_CONTROL_POINTS} control points: loosen --step-tolerance"
            )));
        }
        let ps = patches(body, &across, along);
        let knots_v = knots(along, 3);
        let (e_u, e_v, e_uv) = deviations(body, &ps, &knots_v, along);
        let worst = e_u.iter().copied().fold(e_v.max(e_uv), Real::max);
        if !worst.is_finite() {
            return Err(bad("the body has points that are not finite".into()));
        }
        if worst <= tol {
            break (ps, worst);
        }
        // Each refinement should divide the error by 5 at least: a fit that
        // no longer improves has met the points' own rounding.
        if worst > 0.8 * before {
            return Err(bad(format!(
                "the fit stops improving at {worst:.3e} mm, above the tolerance {tol} mm: loosen --step-tolerance"
            )));
        }
        before = worst;
        // A cubic's error goes with the fourth power of the spacing: as
        // many more points as that asks, and a tenth more.
        let more = |n: usize, e: Real| {
            let f = (1.1 * (e / tol).powf(0.25)).clamp(1.5, 4.0);
            ((n - 1) as Real * f).ceil() as usize + 1
        };
        let mixed = e_uv > tol && e_v <= tol && e_u.iter().all(|e| *e <= tol);
        if e_v > tol || mixed {
            along = more(along, e_v.max(e_uv));
        }
        for (k, e) in e_u.iter().enumerate() {
            if *e > tol || mixed {
                across[k] = more(across[k], e.max(e_uv));
            }
        }
    };
    let knots_v = knots(along, 3);
    let signed = volume(&ps, &knots_v, body.ends_along_z());
    let surfaces: Vec<_> = ps.iter().map(|p| surface(p, &knots_v)).collect();
    let point = |c: [Real; 3]| Point3::new(c[0], c[1], c[2]);
    let curve = |knots: &[Real], pts: Vec<[Real; 3]>| {
        Curve::BSplineCurve(BSplineCurve::new(
            KnotVec::from(knots.to_vec()),
            pts.into_iter().map(point).collect(),
        ))
    };
    // Vertices where piece k starts, at either end of the sweep.
    let v0: Vec<Vertex> = ps
        .iter()
        .map(|p| Vertex::new(point(p.ctrl[0][0])))
        .collect();
    let v1: Vec<Vertex> = ps
        .iter()
        .map(|p| Vertex::new(point(p.ctrl[0][along - 1])))
        .collect();
    // The curve where piece k starts, along the sweep.
    let long: Vec<Edge> = (0..n)
        .map(|k| Edge::new(&v0[k], &v1[k], curve(&knots_v, ps[k].ctrl[0].clone())))
        .collect();
    let end_edge = |k: usize, j: usize, vs: &[Vertex]| {
        let pts = ps[k].ctrl.iter().map(|r| r[j]).collect();
        Edge::new(&vs[k], &vs[(k + 1) % n], curve(&ps[k].knots_u, pts))
    };
    let first: Vec<Edge> = (0..n).map(|k| end_edge(k, 0, &v0)).collect();
    let last: Vec<Edge> = (0..n).map(|k| end_edge(k, along - 1, &v1)).collect();
    let mut faces = Vec::with_capacity(n + 2);
    for (k, s) in surfaces.into_iter().enumerate() {
        let wire: Wire = vec![
            first[k].clone(),
            long[(k + 1) % n].clone(),
            last[k].inverse(),
            long[k].inverse(),
        ]
        .into();
        let face = Face::try_new(vec![wire], Surface::BSplineSurface(s))
            .map_err(|e| bad(format!("piece {k}'s face cannot be made: {e}")))?;
        faces.push(face);
    }
    let start: Wire = first.iter().rev().map(Edge::inverse).collect();
    let end: Wire = last.iter().cloned().collect();
    let (solid, volume) =
        match body.outside() {
            None => {
                for (which, wire) in [("first", start), ("last", end)] {
                    faces.push(truck_modeling::builder::try_attach_plane(&[wire]).map_err(
                        |e| bad(format!("the {which} section is not a plane face: {e}")),
                    )?);
                }
                if signed < 0.0 {
                    faces = faces.iter().map(Face::inverse).collect();
                }
                let solid = truck_modeling::Solid::try_new(vec![Shell::from(faces)])
                    .map_err(|e| bad(format!("the faces do not close a solid: {e}")))?;
                (solid, signed.abs())
            }
            Some(radius) => {
                // The sections' faces look into the hole; the caps are rings
                // between the cylinder's circles and the sections' ends.
                let (z0, z1) = (ps[0].ctrl[0][0][2], ps[0].ctrl[0][along - 1][2]);
                let (mut start, mut end) = (start, end);
                if signed >= 0.0 {
                    faces = faces.iter().map(Face::inverse).collect();
                    start = start.inverse();
                    end = end.inverse();
                }
                let solid = hollow(faces, [start, end], radius, [z0, z1])
                    .map_err(|e| bad(format!("the nut's faces do not close a solid: {e}")))?;
                let outside = std::f64::consts::PI * radius * radius * (z1 - z0).abs();
                (solid, outside - signed.abs())
            }
        };
    let text = write(name, what, &solid, &crate::math::Mat4::identity())?;
    Ok(SweptFit {
        text,
        volume,
        deviation,
        faces: n,
        along,
    })
}

/// The solid between a cylinder of `radius` about Z from `z[0]` to `z[1]`
/// and the hole the `inner` faces bound, whose end wires are `ends` (each
/// running as the ring's cap uses it): the cylinder, and the caps as
/// planes with the hole in them. The cylinder is swept from its line
/// upwards (from the lower z), which turns its faces outwards.
fn hollow(
    inner: Vec<Face>,
    ends: [Wire; 2],
    radius: Real,
    z: [Real; 2],
) -> Result<truck_modeling::Solid, String> {
    use truck_modeling::{builder, Point3, Rad, Vector3};
    let a = builder::vertex(Point3::new(radius, 0.0, z[0].min(z[1])));
    let b = builder::vertex(Point3::new(radius, 0.0, z[0].max(z[1])));
    let cylinder = builder::rsweep(
        &builder::line(&a, &b),
        Point3::new(0.0, 0.0, 0.0),
        Vector3::unit_z(),
        Rad(std::f64::consts::TAU),
    );
    // Its two circles, the one at the first section's end first.
    let mut circles = cylinder.extract_boundaries();
    let key = |w: &Wire| w.front_vertex().map_or(0.0, |v| (v.point().z - z[0]).abs());
    circles.sort_by(|p, q| key(p).total_cmp(&key(q)));
    let mut faces = inner;
    faces.extend(cylinder.iter().cloned());
    for (circle, hole) in circles.iter().zip(&ends) {
        faces.push(
            builder::try_attach_plane(&[circle.inverse(), hole.clone()])
                .map_err(|e| e.to_string())?,
        );
    }
    truck_modeling::Solid::try_new(vec![Shell::from(faces)]).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assert_near;
    use std::f64::consts::{PI, TAU};
    use truck_modeling::ParametricSurface;

    /// A twisted bore of radius 5 from z = -10 to 0 (its four quarters
    /// turning a quarter turn along it; swept downwards where `.0`)
    /// through a cylinder of radius 10.
    struct Bore(bool);
    impl Sections for Bore {
        fn pieces(&self) -> usize {
            4
        }
        fn straight(&self, _: usize) -> bool {
            false
        }
        fn point(&self, k: usize, u: Real, v: Real) -> [Real; 3] {
            let v = if self.0 { 1.0 - v } else { v };
            let t = (k as Real + u) * TAU / 4.0 + v * TAU / 4.0;
            [5.0 * t.cos(), 5.0 * t.sin(), -10.0 + 10.0 * v]
        }
        fn along(&self) -> usize {
            8
        }
        fn outside(&self) -> Option<Real> {
            Some(10.0)
        }
    }

    /// A hollow body, its sections swept up or down: the faces close one
    /// solid (the cylinder's, the bore's and two rings), its volume the
    /// tube's (FreeCAD reads both ways as one valid solid of 2356.17 mm^3).
    #[test]
    fn a_hollow_body_is_a_tube_round_its_sections() {
        for down in [false, true] {
            let fit = swept_step("bore", "a tube", &Bore(down), 1e-3).unwrap();
            assert_near!(fit.volume, PI * (100.0 - 25.0) * 10.0, 0.5);
            assert!(fit.text.contains("MANIFOLD_SOLID_BREP"), "{down}");
        }
    }

    /// An annular sector: hub 50, rim 100, 20 wide, over 0.3 to 2.5 rad;
    /// the rim's outer piece bulges as a cosine across (not straight).
    struct Sector;
    impl Sections for Sector {
        fn pieces(&self) -> usize {
            4
        }
        fn straight(&self, k: usize) -> bool {
            k != 1
        }
        fn point(&self, k: usize, u: Real, v: Real) -> [Real; 3] {
            let t = 0.3 + 2.2 * v;
            // (x, rho) round the section: up the left, across the top,
            // down the right, back along the hub.
            let (x, rho) = match k {
                0 => (-10.0, 50.0 + 50.0 * u),
                1 => (-10.0 + 20.0 * u, 100.0 + 2.0 * (PI * u).sin()),
                2 => (10.0, 100.0 - 50.0 * u),
                _ => (10.0 - 20.0 * u, 50.0),
            };
            [rho * t.cos(), rho * t.sin(), x]
        }
        fn along(&self) -> usize {
            8
        }
    }

    /// The sector's volume by hand: the annulus's moment plus the bulge's,
    /// times the angle; its surfaces within the tolerance at points the
    /// fit never looked at; the file repeatable.
    #[test]
    fn a_sector_is_fitted_within_the_tolerance() {
        let fit = swept_step("roll", "a test", &Sector, 1e-3).unwrap();
        // Moment about the axis of the section: int rho dA.
        let annulus = 20.0 * (100.0f64.powi(2) - 50.0f64.powi(2)) / 2.0;
        // The bulge: int over x of (rho^2 - 100^2)/2, rho = 100 + 2 sin.
        let m = 2000;
        let bulge: Real = (0..m)
            .map(|i| {
                let u = (i as Real + 0.5) / m as Real;
                let rho = 100.0 + 2.0 * (PI * u).sin();
                (rho * rho - 1e4) / 2.0 * 20.0 / m as Real
            })
            .sum();
        assert_near!(fit.volume, 2.2 * (annulus + bulge), 0.05);
        assert!(fit.deviation <= 1e-3);
        assert_eq!(fit.faces, 4);
        assert!(fit.text.contains("B_SPLINE_SURFACE_WITH_KNOTS"));
        assert_eq!(
            fit.text,
            swept_step("roll", "a test", &Sector, 1e-3).unwrap().text
        );
        // Tighter asks for more points along.
        let fine = swept_step("roll", "a test", &Sector, 1e-5).unwrap();
        assert!(fine.along > fit.along && fine.deviation <= 1e-5);
    }

    /// The collocation solve reproduces the points it interpolates, for
    /// every degree and size used.
    #[test]
    fn interpolation_passes_through_its_points() {
        for (n, p) in [(2, 1), (4, 3), (7, 3), (33, 3), (5, 1)] {
            let ip = Interpolation::new(n, p);
            let pts: Vec<[Real; 3]> = (0..n)
                .map(|i| {
                    let t = i as Real / (n - 1) as Real;
                    [(TAU * t).cos(), t * t, 1.0]
                })
                .collect();
            let c = ip.solve(&pts);
            let curve = BSplineCurve::new(
                KnotVec::from(ip.knots.clone()),
                c.iter().map(|c| Point3::new(c[0], c[1], c[2])).collect(),
            );
            for (i, q) in pts.iter().enumerate() {
                use truck_modeling::ParametricCurve;
                let p = curve.subs(i as Real / (n - 1) as Real);
                assert_near!(p.x, q[0], 1e-12);
                assert_near!(p.y, q[1], 1e-12);
            }
        }
    }

    /// The patches' own evaluation and derivatives agree with truck's (the
    /// geometry written) on points off the grid.
    #[test]
    fn patches_evaluate_as_truck_does() {
        let ps = patches(&Sector, &[2, 7, 3, 2], 9);
        let kv = knots(9, 3);
        for p in &ps {
            let s = surface(p, &kv);
            let (du, dv) = (p.d_across(), p.d_along(&kv));
            for (u, v) in [(0.13, 0.71), (0.5, 0.05), (0.97, 0.5), (0.0, 0.3)] {
                let (a, b) = (p.at(&kv, u, v), s.subs(u, v));
                let (a_u, b_u) = (du.at(&kv, u, v), s.uder(u, v));
                let (a_v, b_v) = (dv.at(&kv[1..kv.len() - 1], u, v), s.vder(u, v));
                let b = [b.x, b.y, b.z];
                let (b_u, b_v) = ([b_u.x, b_u.y, b_u.z], [b_v.x, b_v.y, b_v.z]);
                for (x, y) in [(a, b), (a_u, b_u), (a_v, b_v)] {
                    for d in 0..3 {
                        assert_near!(x[d], y[d], 1e-9);
                    }
                }
            }
        }
    }

    /// A fit that would need too many points is refused, naming the
    /// tolerance.
    #[test]
    fn an_impossible_tolerance_is_refused() {
        let e = swept_step("roll", "a test", &Sector, 1e-13).unwrap_err();
        assert!(e.to_string().contains("loosen --step-tolerance"), "{e}");
    }
}
