//! The roll and its groove in 3-D (docs/math.md §3.1).

use super::section::{Edge, EdgeKind, GrooveSection};
use crate::input::InputError;
use crate::math::{Real, Vec3};
use crate::profile::{Profile, ProfileError, Table};

/// Why a groove cannot be built from its tables.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GrooveError {
    /// A table that is not a profile (too short, theta not increasing, a
    /// value not finite).
    #[error("groove table {table}: {source}")]
    Table {
        /// `Hp` or `B`.
        table: &'static str,
        /// What is wrong.
        source: ProfileError,
    },
    /// The two tables at different angles.
    #[error("the groove tables Hp and B must be at the same angles: row {row} has theta = {hp_theta} deg in Hp, {b_theta} deg in B")]
    DifferentTheta {
        /// Row (from 1).
        row: usize,
        /// The angle in Hp's table (deg).
        hp_theta: Real,
        /// The angle in B's table (deg).
        b_theta: Real,
    },
    /// The tables of different lengths.
    #[error(
        "the groove tables Hp and {table} must have the same rows: {hp} in Hp, {rows} in {table}"
    )]
    DifferentRows {
        /// Rows of Hp.
        hp: usize,
        /// The other table: `B`, or the edge's sizes.
        table: &'static str,
        /// Its rows.
        rows: usize,
    },
    /// A depth or width that is not positive, or a depth through the roll.
    #[error(
        "groove table {table}, row {row} (theta = {theta} deg): {table} = {value} mm {expected}"
    )]
    Value {
        /// `Hp` or `B`.
        table: &'static str,
        /// Row (from 1).
        row: usize,
        /// The angle (deg).
        theta: Real,
        /// The value (mm).
        value: Real,
        /// What it must be.
        expected: String,
    },
    /// A table file's cell or row that cannot be a groove's, named by file,
    /// row (as the file numbers it) and column.
    #[error("{file}: {message}")]
    File {
        /// The table's file.
        file: String,
        /// What is wrong, and where.
        message: String,
    },
    /// A table that cannot be read as numbers.
    #[error(transparent)]
    Read(#[from] crate::profile::TableError),
    /// A query outside the tables or a bad number.
    #[error(transparent)]
    Query(#[from] ProfileError),
    /// A bad roll radius.
    #[error(transparent)]
    Input(#[from] InputError),
}

/// A roll of radius `R_d` whose groove, in the section through the roll's
/// axis at angle `theta`, is half an ellipse centred on the periphery:
/// `B(theta) / 2` wide along the axis, `Hp(theta)` deep (tables,
/// interpolated between rows as [`Self::with_interpolation`] states). The point at polar angle `psi` of the
/// section (from the depth direction, positive toward +Z) is at axial
/// position `x_A`, radius `R_d - z_A`, angle `theta`. The edges, where
/// the groove meets the periphery, are sharp, or rounded by a radius from
/// a third table ([`Self::with_edge`]; the section's parameter
/// then runs on along the rounding, [`GrooveSection`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Groove {
    r_d: Real,
    hp: Profile,
    b: Profile,
    edge: Option<(EdgeKind, Profile)>,
    /// A measured part's correction added to the depth and the width
    /// (`pilgrim compensate`): theta (rad) to mm, held at its ends.
    correction: Option<Box<[Profile; 2]>>,
}

/// Step of the numerical derivatives of the surface (rad).
const DIFF_STEP: Real = 1e-6;

impl Groove {
    /// The groove of a roll of radius `r_d` (mm) from its tables: angles
    /// `theta_deg` (degrees, increasing), depths `hp` and widths `b` (mm).
    ///
    /// # Failures
    /// Fewer than 2 rows, angles not increasing, tables of different rows
    /// or angles, a depth or width not positive, a depth at or beyond the
    /// roll's radius (each named by table, row and angle).
    pub fn new(
        r_d: Real,
        theta_deg: (&[Real], &[Real]),
        hp: &[Real],
        b: &[Real],
    ) -> Result<Self, GrooveError> {
        crate::math::positive("roll radius R_d", r_d)?;
        let (ht, bt) = theta_deg;
        if ht.len() != bt.len() || hp.len() != b.len() || ht.len() != hp.len() {
            return Err(GrooveError::DifferentRows {
                hp: ht.len().min(hp.len()),
                table: "B",
                rows: bt.len().min(b.len()),
            });
        }
        if let Some(i) = (0..ht.len()).find(|&i| ht[i] != bt[i]) {
            return Err(GrooveError::DifferentTheta {
                row: i + 1,
                hp_theta: ht[i],
                b_theta: bt[i],
            });
        }
        for (table, values) in [("Hp", hp), ("B", b)] {
            for (i, &v) in values.iter().enumerate() {
                let expected = if !(v > 0.0 && v.is_finite()) {
                    Some("must be a positive number".to_owned())
                } else if table == "Hp" && v >= r_d {
                    Some(format!(
                        "must be less than the roll's radius R_d = {r_d} mm"
                    ))
                } else {
                    None
                };
                if let Some(expected) = expected {
                    return Err(GrooveError::Value {
                        table,
                        row: i + 1,
                        theta: ht[i],
                        value: v,
                        expected,
                    });
                }
            }
        }
        let theta: Vec<Real> = ht.iter().map(|t| t.to_radians()).collect();
        let profile = |table, x: &[Real]| {
            Profile::new(theta.clone(), x.to_vec())
                .map_err(|source| GrooveError::Table { table, source })
        };
        Ok(Self {
            r_d,
            hp: profile("Hp", hp)?,
            b: profile("B", b)?,
            edge: None,
            correction: None,
        })
    }

    /// The groove with its edges rounded or chamfered into the periphery
    /// ([`EdgeKind`]), `sizes` (mm) at each of the tables' rows,
    /// interpolated between them as the tables are.
    ///
    /// # Failures
    /// Not one size per row; a size not positive, or an edge that cannot
    /// be in its section (a chamfer meeting the wall where it is flatter
    /// than 45 deg), named by row and angle.
    pub fn with_edge(self, kind: EdgeKind, sizes: &[Real]) -> Result<Self, GrooveError> {
        let theta = self.hp.z().to_vec();
        if sizes.len() != theta.len() {
            return Err(GrooveError::DifferentRows {
                hp: theta.len(),
                table: kind.name(),
                rows: sizes.len(),
            });
        }
        let value = |i: usize, expected: String| GrooveError::Value {
            table: kind.name(),
            row: i + 1,
            theta: theta[i].to_degrees(),
            value: sizes[i],
            expected,
        };
        if let Some(i) = (0..sizes.len()).find(|&i| !(sizes[i] > 0.0 && sizes[i].is_finite())) {
            return Err(value(i, "must be a positive number".into()));
        }
        let edge = Profile::new(theta.clone(), sizes.to_vec())
            .map_err(|source| GrooveError::Table {
                table: kind.name(),
                source,
            })?
            .with_interpolation(self.interpolation());
        let g = Self {
            edge: Some((kind, edge)),
            ..self
        };
        // Every row's section, then every one between, can be built.
        let at = g.rows_and_midpoints();
        let order = (0..at.len()).step_by(2).chain((1..at.len()).step_by(2));
        for (k, t) in order.map(|k| (k, at[k])) {
            if let Err(e) = g.section(t) {
                let why = match e {
                    GrooveError::Query(ProfileError::Input(e)) => e.to_string(),
                    other => other.to_string(),
                };
                let between = if k % 2 == 1 {
                    format!(
                        " (between it and the next row, at theta = {:.3} deg)",
                        t.to_degrees()
                    )
                } else {
                    String::new()
                };
                return Err(value(k / 2, format!("cannot be{between}: {why}")));
            }
        }
        Ok(g)
    }

    /// [`Self::with_edge`] from a table: its column `theta` (degrees) at
    /// the groove's angles, the sizes in `column` (mm). Errors name the
    /// file, the row as the file numbers it and the column.
    ///
    /// # Failures
    /// As [`Self::with_edge`]; a cell that is not a number; the table's
    /// angles not the groove's.
    pub fn with_edge_from(
        self,
        kind: EdgeKind,
        table: &Table,
        theta: &str,
        column: &str,
    ) -> Result<Self, GrooveError> {
        table.profile(theta, column)?;
        let (deg, sizes) = (table.column(theta)?, table.column(column)?);
        let label = table
            .column_index(column)
            .map(|c| table.column_label(c))
            .unwrap_or_else(|_| column.to_owned());
        let file = || table.source().to_owned();
        let what = kind.describe();
        let ours: Vec<Real> = self.hp.z().iter().map(|t| t.to_degrees()).collect();
        if deg.len() != ours.len() {
            return Err(GrooveError::File {
                file: file(),
                message: format!(
                    "{} rows of {what} in column {label}, but the groove has {} rows: the tables must be at the same angles",
                    deg.len(),
                    ours.len()
                ),
            });
        }
        if let Some(i) =
            (0..deg.len()).find(|&i| (deg[i] - ours[i]).abs() > crate::tolerance::SAME_ANGLE)
        {
            return Err(GrooveError::File {
                file: file(),
                message: format!(
                    "row {}: theta = {} deg, but the groove's row there is at theta = {} deg: {what} must be at the groove's angles",
                    table.row_number(i),
                    deg[i],
                    ours[i]
                ),
            });
        }
        self.with_edge(kind, &sizes).map_err(|e| match e {
            GrooveError::Value {
                row,
                theta,
                value,
                expected,
                ..
            } => GrooveError::File {
                file: file(),
                message: format!(
                    "row {}, column {label}: {what} {} = {value} mm at theta = {theta} deg {expected}",
                    table.row_number(row - 1),
                    kind.name()
                ),
            },
            other => other,
        })
    }

    /// The groove from table files: `hp` and `b` are each a table with the
    /// names of its angle column (degrees) and value column (mm), which
    /// may be the same table (columns of notes are left alone). Errors
    /// name the file, the row as the file numbers it and the column.
    ///
    /// # Failures
    /// A missing, empty or non-numeric cell; angles not increasing; the
    /// tables at different angles; a depth or width not positive; a depth
    /// through the roll.
    pub fn from_tables(
        r_d: Real,
        hp: (&Table, &str, &str),
        b: (&Table, &str, &str),
    ) -> Result<Self, GrooveError> {
        let read = |(t, theta, value): (&Table, &str, &str)| -> Result<_, GrooveError> {
            // Through the table's profile: angles increasing, named by row.
            t.profile(theta, value)?;
            Ok((t.column(theta)?, t.column(value)?))
        };
        let ((ht, hv), (bt, bv)) = (read(hp)?, read(b)?);
        let place = |which: &str, row: usize| {
            let (t, _, col) = if which == "Hp" { hp } else { b };
            let label = t
                .column_index(col)
                .map(|c| t.column_label(c))
                .unwrap_or_else(|_| col.to_owned());
            (t.source().to_owned(), t.row_number(row - 1), label)
        };
        Self::new(r_d, (&ht, &bt), &hv, &bv).map_err(|e| match e {
            GrooveError::Value {
                table,
                row,
                theta,
                value,
                expected,
            } => {
                let (file, row, col) = place(table, row);
                GrooveError::File {
                    file,
                    message: format!(
                        "row {row}, column {col}: {table} = {value} mm at theta = {theta} deg {expected}"
                    ),
                }
            }
            GrooveError::DifferentTheta {
                row,
                hp_theta,
                b_theta,
            } => {
                let ((hf, hr, _), (bf, br, _)) = (place("Hp", row), place("B", row));
                GrooveError::File {
                    file: hf,
                    message: format!(
                        "row {hr}: theta = {hp_theta} deg, but {bf} row {br} gives B at theta = {b_theta} deg: the tables of Hp and B must be at the same angles"
                    ),
                }
            }
            GrooveError::DifferentRows { hp: h, rows: n, .. } => GrooveError::File {
                file: hp.0.source().to_owned(),
                message: format!(
                    "{h} rows of Hp, but {} has {n} rows of B: the tables must be at the same angles",
                    b.0.source()
                ),
            },
            other => other,
        })
    }

    /// Where the concave part of the section at `theta` is most curved:
    /// `0` (the bottom), or where the ellipse ends (`pi/2` at a sharp
    /// edge, where the rounding begins at a rounded one).
    ///
    /// # Failures
    /// `theta` outside the tables.
    pub fn tightest_psi(&self, theta: Real) -> Result<Real, GrooveError> {
        Ok(self.section(theta)?.tightest_psi())
    }

    /// The pass angles `psi` (rad) of a wheel's rounding `r_k` across the
    /// groove, symmetric about its middle out to `psi_max`, `dpsi` apart at
    /// most (the passes spread evenly), with the scallop the step leaves in
    /// the widest section (docs/math.md §3.3: the section circle the groove's
    /// largest profile radius, `max(B/2, Hp)` over the tables). On the
    /// edges' rounding or chamfer, where there is one, the passes run
    /// closer, evenly from where the edge begins in the section it begins
    /// soonest, so that their scallop there is no higher
    /// ([`GrooveSection::edge_psi_step`], the finest any section needs).
    ///
    /// # Failures
    /// `r_k` not smaller than every section's curvature radius (named by
    /// theta and psi); `dpsi` or `psi_max` out of range; more than 10,000
    /// passes.
    pub fn pass_angles(
        &self,
        r_k: Real,
        dpsi: Real,
        psi_max: Real,
    ) -> Result<(Vec<Real>, Real), GrooveError> {
        crate::math::positive("wheel rounding radius r_k", r_k)?;
        crate::math::positive("pass step dpsi", dpsi)?;
        if !(psi_max > 0.0 && psi_max <= std::f64::consts::FRAC_PI_2) {
            return Err(InputError::out_of_range(
                "largest pass angle psi_max (rad)",
                psi_max,
                "(0, pi/2]",
            )
            .into());
        }
        let (r_min, at) = self.min_curvature_radius()?;
        if r_k >= r_min {
            return Err(InputError::out_of_range(
                "wheel rounding radius r_k (mm)",
                r_k,
                format!(
                    "smaller than the groove's tightest curvature radius {r_min:.4} mm, at theta = {:.3} deg, psi = {:.0} deg",
                    at.to_degrees(),
                    self.tightest_psi(at)?.to_degrees()
                ),
            )
            .into());
        }
        let spans = |width: Real, step: Real| {
            let n = (width / step).ceil();
            if n > 10_000.0 {
                Err(InputError::out_of_range(
                    "passes across the groove",
                    n,
                    "at most 10000: a larger step",
                ))
            } else {
                Ok(n.max(1.0) as usize)
            }
        };
        // Where the edges begin soonest: the passes within it are the
        // section's, evenly at `dpsi` at most.
        let sections = match self.edge {
            Some(_) => self
                .rows_and_midpoints()
                .into_iter()
                .map(|t| self.section(t))
                .collect::<Result<Vec<_>, _>>()?,
            None => Vec::new(),
        };
        let inner = sections
            .iter()
            .map(|s| s.edge_from())
            .fold(psi_max, Real::min);
        let n = spans(2.0 * inner, dpsi)?;
        let step = 2.0 * inner / n as Real;
        let rz = super::scallop_height(self.widest_radius(), r_k, step)?;
        // Beyond it, as finely as the finest edge needs for that scallop.
        let mut band_step = Real::INFINITY;
        for s in &sections {
            if let Some(step) = s.edge_psi_step(r_k, rz)? {
                band_step = band_step.min(step);
            }
        }
        let m = if psi_max > inner {
            spans(psi_max - inner, band_step)?
        } else {
            0
        };
        if 2 * m + n > 10_000 {
            return Err(InputError::out_of_range(
                "passes across the groove",
                (2 * m + n) as Real,
                "at most 10000: a larger step",
            )
            .into());
        }
        let outer = |i: usize| inner + (psi_max - inner) * i as Real / m as Real;
        let mut psi: Vec<Real> = (1..=m).rev().map(|i| -outer(i)).collect();
        psi.extend((0..=n).map(|i| -inner + step * i as Real));
        psi.extend((1..=m).map(outer));
        Ok((psi, rz))
    }

    /// The groove's largest profile radius, `max(B/2, Hp)` over the
    /// tables (mm): the section circle the scallop is figured in.
    fn widest_radius(&self) -> Real {
        self.hp
            .x()
            .iter()
            .zip(self.b.x())
            .map(|(h, b)| h.max(b / 2.0))
            .fold(0.0, Real::max)
    }

    /// The tables' angles and the midpoints between them (rad): where
    /// properties of every section are sampled.
    pub(super) fn rows_and_midpoints(&self) -> Vec<Real> {
        let z = self.hp.z();
        let mut at = Vec::with_capacity(2 * z.len());
        for i in 0..z.len() {
            at.push(z[i]);
            if i + 1 < z.len() {
                at.push(0.5 * (z[i] + z[i + 1]));
            }
        }
        at
    }

    /// The node (row, from 0) in the middle of the sizing section: the
    /// longest run of rows of one depth (the groove that sizes the tube),
    /// the smoothing's default anchor (docs/math.md §3.2: its length shrinks
    /// least); the middle row if no two rows have one depth.
    pub fn sizing_middle(&self) -> usize {
        match self.sizing_rows() {
            Some((first, last)) => (first + last) / 2,
            None => self.hp.len() / 2,
        }
    }

    /// The sizing section's first and last rows (from 0): the longest run
    /// of rows of one depth and one width (the groove that sizes the
    /// tube), the first such run if several are as long; `None` if no two
    /// neighbouring rows have one depth and one width.
    pub fn sizing_rows(&self) -> Option<(usize, usize)> {
        let (h, b) = (self.hp.x(), self.b.x());
        let same = |i: usize| {
            (h[i] - h[i - 1]).abs() <= crate::tolerance::SAME_LENGTH
                && (b[i] - b[i - 1]).abs() <= crate::tolerance::SAME_LENGTH
        };
        let (mut best, mut start) = ((0, 0), 0);
        for i in 1..=h.len() {
            if i == h.len() || !same(i) {
                if i - 1 - start > best.1 - best.0 {
                    best = (start, i - 1);
                }
                start = i;
            }
        }
        (best.1 > best.0).then_some(best)
    }

    /// The rows (first and last, from 0) whose angles lie within
    /// `[from_deg, to_deg]`: a sizing section given by the user.
    ///
    /// # Failures
    /// Fewer than two rows in the range.
    pub fn rows_between(
        &self,
        from_deg: Real,
        to_deg: Real,
    ) -> Result<(usize, usize), GrooveError> {
        let deg: Vec<Real> = self.hp.z().iter().map(|t| t.to_degrees()).collect();
        let inside: Vec<usize> = (0..deg.len())
            .filter(|&i| {
                deg[i] >= from_deg - crate::tolerance::SAME_ANGLE
                    && deg[i] <= to_deg + crate::tolerance::SAME_ANGLE
            })
            .collect();
        match (inside.first(), inside.last()) {
            (Some(&a), Some(&b)) if b > a => Ok((a, b)),
            _ => Err(InputError::out_of_range(
                "the sizing section's end (deg)",
                to_deg,
                format!("a range from {from_deg} deg holding at least two of the table's rows"),
            )
            .into()),
        }
    }

    /// The groove with both tables smoothed (docs/math.md §3.2,
    /// [`Profile::smooth_derivative_holding`]): `iterations` of the
    /// three-point rule on the first differences, the rows `held` (the
    /// sizing section, first and last) kept exactly, rebuilt from the row
    /// `anchor` (inside the held rows); with what smoothing did to Hp and
    /// to B.
    ///
    /// # Failures
    /// An anchor beyond the tables or outside the held rows; a rebuilt
    /// depth or width that is not positive (named as the tables' errors
    /// are).
    pub fn smoothed(
        &self,
        iterations: usize,
        anchor: usize,
        held: Option<(usize, usize)>,
    ) -> Result<(Self, crate::profile::Smoothing, crate::profile::Smoothing), GrooveError> {
        let hp = self
            .hp
            .smooth_derivative_holding(iterations, anchor, held)?;
        let b = self.b.smooth_derivative_holding(iterations, anchor, held)?;
        let deg: Vec<Real> = self.hp.z().iter().map(|t| t.to_degrees()).collect();
        let g = Self::new(self.r_d, (&deg, &deg), hp.profile.x(), b.profile.x())?;
        // The same angles exactly (not through degrees and back).
        let g = Self {
            hp: hp.profile.clone(),
            b: b.profile.clone(),
            edge: self.edge.clone(),
            ..g
        };
        Ok((g, hp, b))
    }

    /// The groove with its tables interpolated between rows by
    /// `interpolation` (docs/math.md §3.2: a stated choice; the toolpath and the
    /// verification use the same groove).
    pub fn with_interpolation(self, interpolation: crate::profile::Interpolation) -> Self {
        Self {
            hp: self.hp.with_interpolation(interpolation),
            b: self.b.with_interpolation(interpolation),
            edge: self
                .edge
                .map(|(kind, e)| (kind, e.with_interpolation(interpolation))),
            ..self
        }
    }

    /// How the tables are interpolated between rows.
    pub fn interpolation(&self) -> crate::profile::Interpolation {
        self.hp.interpolation()
    }

    /// The roll's radius (mm).
    pub fn roll_radius(&self) -> Real {
        self.r_d
    }

    /// The range of theta the tables cover (rad).
    pub fn theta_range(&self) -> (Real, Real) {
        self.hp.z_range()
    }

    /// The groove with `dhp` added to its depth and `db` to its width
    /// (mm) at the angles `theta_deg` (increasing), cubic between them
    /// (monotone) and held at its ends beyond them: a measured part's
    /// correction (`pilgrim compensate`). The tables ([`Self::depth`],
    /// [`Self::width`]) stay the nominal; the sections are corrected. An
    /// earlier correction is replaced.
    ///
    /// # Failures
    /// Columns of different lengths, angles not increasing, a value not
    /// finite (named as `dHp` or `dB`); a corrected section that cannot
    /// be (a depth or width no longer positive), named by its angle.
    pub fn corrected(
        self,
        theta_deg: &[Real],
        dhp: &[Real],
        db: &[Real],
    ) -> Result<Self, GrooveError> {
        let theta: Vec<Real> = theta_deg.iter().map(|t| t.to_radians()).collect();
        let profile = |table, x: &[Real]| {
            Profile::new(theta.clone(), x.to_vec())
                .map(|p| p.with_interpolation(crate::profile::Interpolation::Monotone))
                .map_err(|source| GrooveError::Table { table, source })
        };
        let g = Self {
            correction: Some(Box::new([profile("dHp", dhp)?, profile("dB", db)?])),
            ..self
        };
        for t in g.rows_and_midpoints().into_iter().chain(theta) {
            if (g.theta_range().0..=g.theta_range().1).contains(&t) {
                g.section(t)?;
            }
        }
        Ok(g)
    }

    /// The correction added to the depth and the width at `theta` (rad),
    /// (0, 0) without one.
    fn correction_at(&self, theta: Real) -> Result<(Real, Real), GrooveError> {
        match &self.correction {
            None => Ok((0.0, 0.0)),
            Some(c) => {
                let at = |p: &Profile| {
                    let (lo, hi) = p.z_range();
                    p.eval(theta.clamp(lo, hi))
                };
                Ok((at(&c[0])?, at(&c[1])?))
            }
        }
    }

    /// The depth table (theta in rad).
    pub fn depth(&self) -> &Profile {
        &self.hp
    }

    /// The width table (theta in rad).
    pub fn width(&self) -> &Profile {
        &self.b
    }

    /// The edge's kind and its size's table (theta in rad), if it is not
    /// sharp.
    pub fn edge(&self) -> Option<(EdgeKind, &Profile)> {
        self.edge.as_ref().map(|(kind, p)| (*kind, p))
    }

    /// The section at `theta` (rad).
    ///
    /// # Failures
    /// `theta` outside the tables; an edge interpolated to a size that
    /// cannot be.
    pub fn section(&self, theta: Real) -> Result<GrooveSection, GrooveError> {
        let (dhp, db) = self.correction_at(theta)?;
        let hp = self.hp.eval(theta)? + dhp;
        let b = self.b.eval(theta)? + db;
        let edge = match &self.edge {
            None => Edge::Sharp,
            Some((kind, size)) => kind.of(size.eval(theta)?),
        };
        Ok(GrooveSection::new(b / 2.0, hp, edge)?)
    }

    /// The groove's point at `(theta, psi)` (rad) in the roll's frame.
    ///
    /// # Failures
    /// `theta` outside the tables.
    pub fn point(&self, theta: Real, psi: Real) -> Result<Vec3, GrooveError> {
        Ok(self.point_of(&self.section(theta)?, theta, psi))
    }

    /// The groove's point at `psi` of `section`, the section at `theta`
    /// ([`Self::section`]), in the roll's frame: [`Self::point`] for many
    /// points of one section, which is built once.
    pub fn point_of(&self, section: &GrooveSection, theta: Real, psi: Real) -> Vec3 {
        self.placed(theta, section.point(psi))
    }

    /// A point `(x_A, z_A)` of the section at `theta` in the roll's frame.
    fn placed(&self, theta: Real, (x_a, z_a): (Real, Real)) -> Vec3 {
        let rho = self.r_d - z_a;
        Vec3::new(rho * theta.cos(), rho * theta.sin(), x_a)
    }

    /// The groove's unit normal at `(theta, psi)`, out of the roll's
    /// material into the groove's open space (toward a wheel in it): the
    /// second of [`Self::frame`].
    ///
    /// # Failures
    /// `theta` outside the tables.
    pub fn normal(&self, theta: Real, psi: Real) -> Result<Vec3, GrooveError> {
        Ok(self.frame(theta, psi)?.1)
    }

    /// The groove at `(theta, psi)`: its point, its unit normal out of the
    /// roll's material into the groove's open space (toward a wheel in
    /// it), and the point's derivative along theta (the contact's
    /// trajectory along a pass), from the surface's partial derivatives
    /// (central differences of 1e-6 rad, one-sided at the tables' ends;
    /// the section at `theta` evaluated once for its own three points). At
    /// a chamfer's corner, where the point stands while psi turns the
    /// normal, the section's own tangent takes the place of the derivative
    /// along psi. The normal is turned to the side the section's normal
    /// opens to.
    ///
    /// # Failures
    /// `theta` outside the tables.
    pub fn frame(&self, theta: Real, psi: Real) -> Result<(Vec3, Vec3, Vec3), GrooveError> {
        let s = self.section(theta)?;
        let (t0, t1) = self.theta_pair(theta);
        let d_theta = (self.point(t1, psi)? - self.point(t0, psi)?) / (t1 - t0);
        let mut d_psi = (self.placed(theta, s.point(psi + DIFF_STEP))
            - self.placed(theta, s.point(psi - DIFF_STEP)))
            / (2.0 * DIFF_STEP);
        // The section's normal into the material at psi, from the depth
        // direction: its tangent and the side it opens to, in 3-D (depth
        // is inward along the radius).
        let phi = s.normal_angle(psi);
        let radial = Vec3::new(theta.cos(), theta.sin(), 0.0);
        let open = -phi.sin() * Vec3::z() + phi.cos() * radial;
        if !(d_psi.norm() > crate::tolerance::SAME_LENGTH) {
            d_psi = phi.cos() * Vec3::z() + phi.sin() * radial;
        }
        let n = d_theta.cross(&d_psi).normalize();
        let n = if n.dot(&open) >= 0.0 { n } else { -n };
        Ok((self.placed(theta, s.point(psi)), n, d_theta))
    }

    /// The angles either side of `theta` that derivatives along theta are
    /// taken between: `theta -+ 1e-6 rad`, one-sided at the tables' ends.
    pub(super) fn theta_pair(&self, theta: Real) -> (Real, Real) {
        let (lo, hi) = self.theta_range();
        ((theta - DIFF_STEP).max(lo), (theta + DIFF_STEP).min(hi))
    }

    /// The smallest radius of curvature of the groove's sections' concave
    /// part, over the tables' rows and the midpoints between them, with
    /// the theta where it is (rad): the largest a wheel's rounding may be.
    /// In a section it is at the bottom (`psi = 0`, `a^2 / b`) or where the
    /// ellipse ends (`b^2 / a` at a sharp edge): [`Self::tightest_psi`]
    /// says which.
    pub fn min_curvature_radius(&self) -> Result<(Real, Real), GrooveError> {
        let mut best = (Real::INFINITY, self.hp.z()[0]);
        for t in self.rows_and_midpoints() {
            let r = self.section(t)?.min_curvature_radius();
            if r < best.0 {
                best = (r, t);
            }
        }
        Ok(best)
    }
}

/// A groove that cannot be evaluated where a replay measures it is the
/// replay's failure, said as the groove says it.
impl From<GrooveError> for crate::replay::VerifyError {
    fn from(e: GrooveError) -> Self {
        Self::Geometry(e.to_string())
    }
}
