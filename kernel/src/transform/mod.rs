//! The universal 4x4 transform chain (docs/math.md §1, seed 003).
//!
//! A machine is a [`Chain`]: an ordered product of elementary factors
//! ([`FactorKind`]: three translations, three rotations), each a constant of
//! the machine's geometry or bound to a named axis with a scale (the sign, or
//! 0.5 for a lathe's diameter programming) and an offset. The product maps a
//! point of the tool's own frame to the part frame: `r0 = A r1` (S003-1),
//! with factors listed left to right as they stand in the product.
//!
//! ```
//! use pilgrim_kernel::{Chain, FactorKind::*, Point3};
//! // A turn about Z of the part, then the tool's X move: r0 = Rz(C) Tx(X) r1.
//! let chain = Chain::builder().axis(Rz, "C").axis(Tx, "X").build().unwrap();
//! let p = chain.apply(&[std::f64::consts::FRAC_PI_2, 10.0], &Point3::origin()).unwrap();
//! pilgrim_kernel::assert_near!(p.y, 10.0, 1e-12);
//! ```

mod batch;
mod ik;
mod universal;

pub use ik::{IkOptions, IkSolution, Target};
pub use universal::UNIVERSAL_PARAMETERS;

use crate::input::InputError;
use crate::math::{Mat3, Mat4, Point3, Real, Vec3};
use serde::{Deserialize, Serialize};

/// One of the six elementary factors of a chain: the plugin ABI's type,
/// defined once there (a machine's description names its factors with
/// it); [`FactorGeometry`] gives its direction and matrix in the kernel's
/// types.
pub use pilgrim_plugin_abi::types::FactorKind;

/// A factor's geometry in the kernel's types.
pub trait FactorGeometry {
    /// The unit vector it moves along or about.
    fn direction(self) -> Vec3;
    /// The 4x4 matrix of the factor at `value`.
    fn matrix(self, value: Real) -> Mat4;
}

impl FactorGeometry for FactorKind {
    fn direction(self) -> Vec3 {
        let mut v = Vec3::zeros();
        v[self.direction_index()] = 1.0;
        v
    }

    fn matrix(self, value: Real) -> Mat4 {
        let mut m = Mat4::identity();
        let (s, c) = crate::math::sin_cos(value);
        match self {
            Self::Tx | Self::Ty | Self::Tz => m[(self.direction_index(), 3)] = value,
            Self::Rx => {
                m[(1, 1)] = c;
                m[(1, 2)] = -s;
                m[(2, 1)] = s;
                m[(2, 2)] = c;
            }
            Self::Ry => {
                m[(0, 0)] = c;
                m[(0, 2)] = s;
                m[(2, 0)] = -s;
                m[(2, 2)] = c;
            }
            Self::Rz => {
                m[(0, 0)] = c;
                m[(0, 1)] = -s;
                m[(1, 0)] = s;
                m[(1, 1)] = c;
            }
        }
        m
    }
}

/// The value of one factor: a constant, or `scale * q[axis] + offset`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum FactorValue {
    /// A constant of the machine's geometry (mm or rad).
    Const(Real),
    /// Bound to the chain's axis number `axis`.
    Axis {
        /// Index into [`Chain::axis_names`].
        axis: usize,
        /// Multiplies the axis value: +1 or -1 for the sign, 0.5 for a
        /// diameter-programmed lathe X.
        scale: Real,
        /// Added after scaling (mm or rad).
        offset: Real,
    },
}

/// One factor of a chain.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Factor {
    /// Which elementary factor.
    pub kind: FactorKind,
    /// Its value.
    pub value: FactorValue,
}

impl Factor {
    /// The factor's value for the axis values `q`.
    #[inline]
    pub fn value_at(&self, q: &[Real]) -> Real {
        match self.value {
            FactorValue::Const(v) => v,
            FactorValue::Axis {
                axis,
                scale,
                offset,
            } => scale * q[axis] + offset,
        }
    }
}

/// Errors of chains and inverse kinematics.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TransformError {
    /// The run's time limit passed while this was being done.
    #[error(transparent)]
    OverTime(#[from] crate::budget::OverTime),
    /// A rejected number.
    #[error(transparent)]
    Input(#[from] InputError),
    /// The number of axis values does not match the chain's axes.
    #[error("the chain has {expected} axes ({names}), got {got} values")]
    AxisCount {
        /// How many axes the chain has.
        expected: usize,
        /// How many values were given.
        got: usize,
        /// The chain's axis names, comma separated.
        names: String,
    },
    /// One axis is bound to both translations and rotations.
    #[error("axis {axis} is bound to both a translation and a rotation")]
    MixedAxis {
        /// The axis name.
        axis: String,
    },
    /// An axis factor with a zero scale (the axis would do nothing).
    #[error("axis {axis} has scale 0 in factor {factor}")]
    ZeroScale {
        /// The axis name.
        axis: String,
        /// Index of the factor in the chain.
        factor: usize,
    },
    /// Inverse kinematics asked of a chain with no axes.
    #[error("the chain has no axes to solve for")]
    NoAxes,
    /// The target pose could not be reached within the tolerance.
    #[error(
        "target point ({:.6}, {:.6}, {:.6}) is unreachable: best position error {pos_err:.3e} mm, \
         axis error {dir_err:.3e} rad after {iterations} iterations",
        point[0], point[1], point[2]
    )]
    Unreachable {
        /// The target point.
        point: [Real; 3],
        /// Best position error reached (mm).
        pos_err: Real,
        /// Best tool-axis error reached (rad).
        dir_err: Real,
        /// Iterations spent over all starts.
        iterations: usize,
    },
    /// The target was reached only with an axis outside its travel.
    #[error("axis {axis} would need {value:.6}, outside its travel [{min}, {max}]")]
    OutsideTravel {
        /// The axis name.
        axis: String,
        /// The value it would need (mm or rad).
        value: Real,
        /// Lower travel limit.
        min: Real,
        /// Upper travel limit.
        max: Real,
    },
}

/// A tool's reference point and axis in the tool's own frame (the `r1` of S003-1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ToolFrame {
    /// Reference point (mm), e.g. the centre of a wheel's rounding.
    pub point: Point3,
    /// Unit axis, e.g. a wheel's axis of rotation.
    pub axis: Vec3,
}

impl Default for ToolFrame {
    /// The origin and +Z.
    fn default() -> Self {
        Self {
            point: Point3::origin(),
            axis: Vec3::z(),
        }
    }
}

/// A tool's reference point and unit axis in the part frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Reference point (mm).
    pub point: Point3,
    /// Unit axis direction.
    pub axis: Vec3,
}

/// A rigid motion `x -> rot * x + pos`, the working form of a chain's matrix.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Rotation block.
    pub rot: Mat3,
    /// Translation (mm).
    pub pos: Vec3,
}

impl Frame {
    /// The identity motion.
    pub fn identity() -> Self {
        Self {
            rot: Mat3::identity(),
            pos: Vec3::zeros(),
        }
    }

    /// Right-multiplies by the elementary factor `kind` at `value`: `self = self * F`.
    #[inline]
    pub fn push(&mut self, kind: FactorKind, value: Real) {
        if kind.is_rotation() {
            let (s, c) = crate::math::sin_cos(value);
            self.push_rotation(kind, s, c);
        } else {
            let col = self.rot.column(kind.direction_index()).into_owned();
            self.pos += col * value;
        }
    }

    /// Right-multiplies by a rotation of kind `kind` given its sine and cosine.
    #[inline]
    pub(crate) fn push_rotation(&mut self, kind: FactorKind, s: Real, c: Real) {
        // R * Rx mixes columns 1 and 2, R * Ry columns 2 and 0, R * Rz columns 0 and 1.
        let (i, j) = match kind {
            FactorKind::Rx => (1, 2),
            FactorKind::Ry => (2, 0),
            _ => (0, 1),
        };
        let ci = self.rot.column(i).into_owned();
        let cj = self.rot.column(j).into_owned();
        self.rot.set_column(i, &(ci * c + cj * s));
        self.rot.set_column(j, &(cj * c - ci * s));
    }

    /// The homogeneous 4x4 matrix.
    pub fn to_matrix(&self) -> Mat4 {
        let mut m = Mat4::identity();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.rot);
        m.fixed_view_mut::<3, 1>(0, 3).copy_from(&self.pos);
        m
    }

    /// Applies the motion to a point.
    #[inline]
    pub fn transform_point(&self, p: &Point3) -> Point3 {
        Point3::from(self.rot * p.coords + self.pos)
    }

    /// Applies the rotation to a direction.
    #[inline]
    pub fn transform_vector(&self, v: &Vec3) -> Vec3 {
        self.rot * v
    }
}

/// The points `(x[i], y[i], z[i])` mapped by the homogeneous matrix `m`
/// (`r0 = m r1`, docs/math.md §1), as three arrays.
///
/// # Failures
/// Arrays of different lengths.
pub fn map_points(
    m: &Mat4,
    x: &[Real],
    y: &[Real],
    z: &[Real],
) -> Result<[Vec<Real>; 3], InputError> {
    if y.len() != x.len() || z.len() != x.len() {
        return Err(InputError::LengthMismatch {
            what: "points x, y and z".into(),
            left: x.len(),
            right: if y.len() != x.len() { y.len() } else { z.len() },
        });
    }
    let mut out = [
        Vec::with_capacity(x.len()),
        Vec::with_capacity(x.len()),
        Vec::with_capacity(x.len()),
    ];
    for i in 0..x.len() {
        let p = m * nalgebra::Vector4::new(x[i], y[i], z[i], 1.0);
        out[0].push(p.x);
        out[1].push(p.y);
        out[2].push(p.z);
    }
    Ok(out)
}

/// An ordered product of elementary factors, some bound to named axes.
///
/// See the [module docs](self). Build one with [`Chain::builder`], or take
/// the universal preset [`Chain::universal`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Chain {
    axes: Vec<String>,
    factors: Vec<Factor>,
}

/// Builds a [`Chain`] factor by factor, left to right as in the product.
#[derive(Debug, Clone, Default)]
pub struct ChainBuilder {
    axes: Vec<String>,
    factors: Vec<Factor>,
}

impl ChainBuilder {
    /// Declares an axis without binding a factor to it yet, fixing its place
    /// in the order of axis values.
    pub fn declare(mut self, name: &str) -> Self {
        self.axis_index(name);
        self
    }

    fn axis_index(&mut self, name: &str) -> usize {
        match self.axes.iter().position(|a| a == name) {
            Some(i) => i,
            None => {
                self.axes.push(name.to_owned());
                self.axes.len() - 1
            }
        }
    }

    /// Appends a factor with a constant value (mm or rad).
    pub fn constant(mut self, kind: FactorKind, value: Real) -> Self {
        self.factors.push(Factor {
            kind,
            value: FactorValue::Const(value),
        });
        self
    }

    /// Appends a factor bound to axis `name` with scale 1 and offset 0.
    pub fn axis(self, kind: FactorKind, name: &str) -> Self {
        self.axis_scaled(kind, name, 1.0, 0.0)
    }

    /// Appends a factor bound to axis `name`: value = `scale * q + offset`.
    pub fn axis_scaled(mut self, kind: FactorKind, name: &str, scale: Real, offset: Real) -> Self {
        let axis = self.axis_index(name);
        self.factors.push(Factor {
            kind,
            value: FactorValue::Axis {
                axis,
                scale,
                offset,
            },
        });
        self
    }

    /// Checks the chain and builds it.
    ///
    /// # Failures
    /// A non-finite constant, scale or offset; an axis bound to both
    /// translations and rotations; a zero scale.
    pub fn build(self) -> Result<Chain, TransformError> {
        Chain::new(self.axes, self.factors)
    }
}

impl Chain {
    /// Starts an empty chain.
    pub fn builder() -> ChainBuilder {
        ChainBuilder::default()
    }

    /// A chain from its axis names and factors.
    ///
    /// # Failures
    /// See [`ChainBuilder::build`]; also a factor bound to an axis index
    /// beyond `axes`.
    pub fn new(axes: Vec<String>, factors: Vec<Factor>) -> Result<Self, TransformError> {
        let mut rotary: Vec<Option<bool>> = vec![None; axes.len()];
        for (k, f) in factors.iter().enumerate() {
            match f.value {
                FactorValue::Const(v) => {
                    crate::math::finite(&format!("factor {k} value"), v)?;
                }
                FactorValue::Axis {
                    axis,
                    scale,
                    offset,
                } => {
                    let name = axes.get(axis).ok_or_else(|| {
                        InputError::out_of_range(
                            format!("factor {k} axis index"),
                            axis as f64,
                            format!("0..{}", axes.len()),
                        )
                    })?;
                    crate::math::finite(&format!("factor {k} scale"), scale)?;
                    crate::math::finite(&format!("factor {k} offset"), offset)?;
                    if scale == 0.0 {
                        return Err(TransformError::ZeroScale {
                            axis: name.clone(),
                            factor: k,
                        });
                    }
                    match rotary[axis] {
                        Some(r) if r != f.kind.is_rotation() => {
                            return Err(TransformError::MixedAxis { axis: name.clone() })
                        }
                        _ => rotary[axis] = Some(f.kind.is_rotation()),
                    }
                }
            }
        }
        Ok(Self { axes, factors })
    }

    /// The axis names, in the order axis values are given.
    pub fn axis_names(&self) -> &[String] {
        &self.axes
    }

    /// Number of axes.
    pub fn dof(&self) -> usize {
        self.axes.len()
    }

    /// The factors, left to right.
    pub fn factors(&self) -> &[Factor] {
        &self.factors
    }

    /// Index of the axis called `name`.
    pub fn axis_index(&self, name: &str) -> Option<usize> {
        self.axes.iter().position(|a| a == name)
    }

    /// The chain with some axes fixed: `values[i]` (when `Some`) replaces
    /// axis `i` by a constant, which leaves the chain without that axis.
    ///
    /// # Failures
    /// `values` of another length than the axes, or a non-finite value.
    ///
    /// ```
    /// use pilgrim_kernel::{Chain, FactorKind::*, Point3};
    /// let ch = Chain::builder().axis(Rz, "C").axis(Tx, "X").build().unwrap();
    /// let fixed = ch.with_fixed(&[Some(0.0), None]).unwrap();
    /// assert_eq!(fixed.axis_names(), ["X"]);
    /// ```
    pub fn with_fixed(&self, values: &[Option<Real>]) -> Result<Chain, TransformError> {
        if values.len() != self.dof() {
            return Err(TransformError::AxisCount {
                expected: self.dof(),
                got: values.len(),
                names: self.axes.join(", "),
            });
        }
        let mut b = Chain::builder();
        for (name, v) in self.axes.iter().zip(values) {
            if v.is_none() {
                b = b.declare(name);
            }
        }
        for f in &self.factors {
            b = match f.value {
                FactorValue::Const(c) => b.constant(f.kind, c),
                FactorValue::Axis {
                    axis,
                    scale,
                    offset,
                } => match values[axis] {
                    Some(v) => b.constant(
                        f.kind,
                        scale * crate::math::finite("fixed axis value", v)? + offset,
                    ),
                    None => b.axis_scaled(f.kind, &self.axes[axis], scale, offset),
                },
            };
        }
        b.build()
    }

    /// Whether axis `i` is bound to rotations (radians); `false` for linear
    /// axes and for axes bound to no factor.
    pub fn is_rotary(&self, i: usize) -> bool {
        self.factors.iter().any(|f| {
            f.kind.is_rotation() && matches!(f.value, FactorValue::Axis { axis, .. } if axis == i)
        })
    }

    fn check_len(&self, q: &[Real]) -> Result<(), TransformError> {
        if q.len() != self.axes.len() {
            return Err(TransformError::AxisCount {
                expected: self.axes.len(),
                got: q.len(),
                names: self.axes.join(", "),
            });
        }
        Ok(())
    }

    /// The rigid motion for the axis values `q` (no checks; `q.len()` must be [`Self::dof`]).
    #[inline]
    pub fn frame_unchecked(&self, q: &[Real]) -> Frame {
        let mut fr = Frame::identity();
        for f in &self.factors {
            fr.push(f.kind, f.value_at(q));
        }
        fr
    }

    /// The rigid motion for the axis values `q`.
    ///
    /// # Failures
    /// A wrong number of values, or a non-finite value.
    pub fn frame(&self, q: &[Real]) -> Result<Frame, TransformError> {
        self.check_len(q)?;
        crate::math::all_finite("axis values", q)?;
        Ok(self.frame_unchecked(q))
    }

    /// The 4x4 matrix `A` for the axis values `q`.
    pub fn matrix(&self, q: &[Real]) -> Result<Mat4, TransformError> {
        Ok(self.frame(q)?.to_matrix())
    }

    /// The matrix as the plain product of the factors' matrices (slow; the
    /// reference the fast path is tested against).
    pub fn matrix_by_product(&self, q: &[Real]) -> Result<Mat4, TransformError> {
        self.check_len(q)?;
        Ok(self
            .factors
            .iter()
            .fold(Mat4::identity(), |m, f| m * f.kind.matrix(f.value_at(q))))
    }

    /// Maps a point of the tool frame to the part frame.
    pub fn apply(&self, q: &[Real], p: &Point3) -> Result<Point3, TransformError> {
        Ok(self.frame(q)?.transform_point(p))
    }

    /// Maps many points of the tool frame, all at the same axis values.
    pub fn apply_points(
        &self,
        q: &[Real],
        points: &[Point3],
    ) -> Result<Vec<Point3>, TransformError> {
        let fr = self.frame(q)?;
        Ok(points.iter().map(|p| fr.transform_point(p)).collect())
    }

    /// The tool's pose for axis values `q`.
    pub fn pose(&self, q: &[Real], tool: &ToolFrame) -> Result<Pose, TransformError> {
        let fr = self.frame(q)?;
        Ok(Pose {
            point: fr.transform_point(&tool.point),
            axis: fr.transform_vector(&tool.axis),
        })
    }

    /// Forward kinematics of a batch: `q_rows` holds one row of
    /// [`Self::dof`] axis values per pose, row after row; the result holds the
    /// tool's pose for each row.
    ///
    /// # Failures
    /// A length that is not a multiple of the axis count, or a non-finite
    /// value (named by its row and axis).
    pub fn poses(&self, q_rows: &[Real], tool: &ToolFrame) -> Result<Vec<Pose>, TransformError> {
        let mut out = Vec::new();
        self.poses_into(q_rows, tool, &mut out)?;
        Ok(out)
    }

    /// [`Self::poses`] into a caller's buffer (cleared first), so a hot loop
    /// allocates once.
    pub fn poses_into(
        &self,
        q_rows: &[Real],
        tool: &ToolFrame,
        out: &mut Vec<Pose>,
    ) -> Result<(), TransformError> {
        let n = self.check_rows(q_rows)?;
        out.clear();
        out.reserve(n);
        if n > 0 {
            batch::Program::new(self).poses(q_rows, self.dof(), tool, out);
        }
        Ok(())
    }

    /// Checks a row-major batch and returns the number of rows.
    fn check_rows(&self, q_rows: &[Real]) -> Result<usize, TransformError> {
        let dof = self.dof();
        if dof == 0 {
            return Ok(0);
        }
        if !q_rows.len().is_multiple_of(dof) {
            return Err(TransformError::AxisCount {
                expected: dof,
                got: q_rows.len() % dof,
                names: self.axes.join(", "),
            });
        }
        if let Some(i) = q_rows.iter().position(|v| !v.is_finite()) {
            return Err(InputError::NonFinite {
                what: format!("axis {} of row", self.axes[i % dof]),
                index: Some(i / dof),
                value: q_rows[i],
            }
            .into());
        }
        Ok(q_rows.len() / dof)
    }
}

#[cfg(test)]
mod tests {
    use super::FactorKind::*;
    use super::*;
    use crate::assert_near;

    #[test]
    fn fast_frame_equals_product_of_factors() {
        use FactorKind::*;
        let all = [Tx, Ty, Tz, Rx, Ry, Rz];
        for kind in all {
            for k2 in all {
                let ch = Chain::builder()
                    .axis(kind, "p")
                    .constant(k2, 0.7)
                    .axis_scaled(Rz, "q", -1.0, 0.2)
                    .build()
                    .unwrap();
                let q = [0.3, 1.1];
                let a = ch.matrix(&q).unwrap();
                let b = ch.matrix_by_product(&q).unwrap();
                assert!((a - b).abs().max() < 1e-14, "{kind:?} {k2:?}\n{a}\n{b}");
            }
        }
    }

    #[test]
    fn rotations_are_right_handed() {
        // Rz(90 deg) takes +X to +Y; Rx takes +Y to +Z; Ry takes +Z to +X.
        let v = Rz.matrix(std::f64::consts::FRAC_PI_2) * nalgebra::Vector4::new(1.0, 0.0, 0.0, 1.0);
        assert_near!(v.y, 1.0, 1e-15);
        let v = Rx.matrix(std::f64::consts::FRAC_PI_2) * nalgebra::Vector4::new(0.0, 1.0, 0.0, 1.0);
        assert_near!(v.z, 1.0, 1e-15);
        let v = Ry.matrix(std::f64::consts::FRAC_PI_2) * nalgebra::Vector4::new(0.0, 0.0, 1.0, 1.0);
        assert_near!(v.x, 1.0, 1e-15);
    }

    #[test]
    fn errors_name_the_problem() {
        let ch = Chain::builder()
            .axis(Tx, "X")
            .axis(Rz, "C")
            .build()
            .unwrap();
        let e = ch.matrix(&[1.0]).unwrap_err().to_string();
        assert!(e.contains("2 axes") && e.contains("X, C"), "{e}");
        let e = ch
            .poses(&[1.0, 2.0, 3.0, f64::NAN], &ToolFrame::default())
            .unwrap_err();
        assert!(e.to_string().contains("axis C of row[1]"), "{e}");
        let e = Chain::builder()
            .axis(Tx, "X")
            .axis(Rz, "X")
            .build()
            .unwrap_err();
        assert!(matches!(e, TransformError::MixedAxis { .. }));
        let e = Chain::builder()
            .axis_scaled(Tx, "X", 0.0, 0.0)
            .build()
            .unwrap_err();
        assert!(e.to_string().contains("scale 0"), "{e}");
    }

    #[test]
    fn batch_matches_the_product_of_factors() {
        let tool = ToolFrame {
            point: Point3::new(3.0, -2.0, 7.0),
            axis: Vec3::new(0.0, 0.6, 0.8),
        };
        let chains = [
            Chain::universal(),
            Chain::builder()
                .constant(Tx, 5.0)
                .axis_scaled(Tx, "u", -1.0, 2.0)
                .axis(Rz, "c")
                .constant(Ry, 0.3)
                .axis_scaled(Tz, "w", 0.5, -1.0)
                .axis(Tz, "u")
                .constant(Ty, 4.0)
                .build()
                .unwrap(),
        ];
        for ch in chains {
            let rows: Vec<f64> = (0..ch.dof() * 7)
                .map(|i| (i as f64 * 0.37).sin() * 3.0)
                .collect();
            let poses = ch.poses(&rows, &tool).unwrap();
            assert_eq!(poses.len(), 7);
            for (r, p) in rows.chunks(ch.dof()).zip(&poses) {
                let m = ch.matrix_by_product(r).unwrap();
                let hp = m * tool.point.to_homogeneous();
                let ha = m * tool.axis.to_homogeneous();
                for k in 0..3 {
                    assert_near!(p.point[k], hp[k], 1e-12);
                    assert_near!(p.axis[k], ha[k], 1e-14);
                }
            }
        }
    }
}
