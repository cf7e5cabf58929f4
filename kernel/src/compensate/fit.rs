//! The measured error fitted by a cubic smoothing spline (de Boor's
//! `csaps`, the `csaps` crate): among the splines `f` minimising `p sum
//! (e_i - f(s_i))^2 + (1 - p) integral f''^2`, the one whose residual's
//! root mean square is the measurement's stated uncertainty (the
//! discrepancy principle): smoother would leave error the measurement
//! shows, rougher would follow its noise. Where even the straight line
//! (`p = 0`) stays within the uncertainty, the line is the fit.

use super::CompensateError;
use crate::math::Real;
use csaps::CubicSmoothingSpline;

/// The error fitted: see the module's docs.
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorFit {
    /// The places measured.
    pub at: Vec<Real>,
    /// The error at each: measured minus nominal.
    pub error: Vec<Real>,
    /// The uncertainty the fit was held to (its residual's RMS).
    pub uncertainty: Real,
    /// The smoothing parameter found, from 0 (a straight line) to 1 (the
    /// interpolating spline).
    pub smooth: Real,
    /// The residual's root mean square.
    pub rms_residual: Real,
    /// A quantity corrected as one value: the errors' mean, the fit
    /// everywhere ([`fit_mean`]).
    pub mean: Option<Real>,
}

/// Fits `error` at the places `at` (increasing, at least 3) within
/// `uncertainty`: see the module's docs.
///
/// # Failures
/// An uncertainty not positive; the spline failing (named).
pub fn fit_error(
    at: &[Real],
    error: &[Real],
    uncertainty: Real,
) -> Result<ErrorFit, CompensateError> {
    positive_uncertainty(uncertainty)?;
    let mut fit = ErrorFit {
        at: at.to_vec(),
        error: error.to_vec(),
        uncertainty,
        smooth: 0.0,
        rms_residual: 0.0,
        mean: None,
    };
    let rms = |p: Real| -> Result<Real, CompensateError> {
        let f = evaluate(at, error, p, at)?;
        let n = at.len() as Real;
        Ok((f
            .iter()
            .zip(error)
            .map(|(f, e)| (f - e).powi(2))
            .sum::<Real>()
            / n)
            .sqrt())
    };
    // The residual falls as p grows: halve the interval to the p whose
    // residual is the uncertainty (60 halvings: 1e-18 of the interval).
    if rms(0.0)? > uncertainty {
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if rms(mid)? > uncertainty {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        fit.smooth = hi;
    }
    fit.rms_residual = rms(fit.smooth)?;
    Ok(fit)
}

/// The errors `error` at `at` (one place at least) as one value, their
/// mean: a quantity whose correction is one value (a thread start's
/// passes move as one). Its residual says how far the error varies along
/// the part beyond that, which such a correction leaves.
///
/// # Failures
/// An uncertainty not positive; no place.
pub fn fit_mean(
    at: &[Real],
    error: &[Real],
    uncertainty: Real,
) -> Result<ErrorFit, CompensateError> {
    positive_uncertainty(uncertainty)?;
    if error.is_empty() {
        return Err(CompensateError::Fit("no place measured".into()));
    }
    let n = error.len() as Real;
    let mean = error.iter().sum::<Real>() / n;
    Ok(ErrorFit {
        at: at.to_vec(),
        error: error.to_vec(),
        uncertainty,
        smooth: 0.0,
        rms_residual: (error.iter().map(|e| (e - mean).powi(2)).sum::<Real>() / n).sqrt(),
        mean: Some(mean),
    })
}

/// Refuses an uncertainty that is not above 0, naming it.
fn positive_uncertainty(uncertainty: Real) -> Result<(), CompensateError> {
    crate::math::positive("the measurement's uncertainty", uncertainty)
        .map(|_| ())
        .map_err(|e| CompensateError::Fit(e.to_string()))
}

/// The smoothing spline of `error` at `at` with parameter `p`, evaluated
/// at `xi`.
fn evaluate(
    at: &[Real],
    error: &[Real],
    p: Real,
    xi: &[Real],
) -> Result<Vec<Real>, CompensateError> {
    let failed = |e: csaps::CsapsError| CompensateError::Fit(e.to_string());
    let spline = CubicSmoothingSpline::new(at, error)
        .with_smooth(p)
        .make()
        .map_err(failed)?;
    Ok(spline.evaluate(xi).map_err(failed)?.to_vec())
}

impl ErrorFit {
    /// The fitted error at `xi`.
    ///
    /// # Failures
    /// The spline failing.
    pub fn at(&self, xi: &[Real]) -> Result<Vec<Real>, CompensateError> {
        if let Some(mean) = self.mean {
            return Ok(vec![mean; xi.len()]);
        }
        evaluate(&self.at, &self.error, self.smooth, xi)
    }

    /// The target's shift against the error: `-gain` times the fit at
    /// each place of `grid`.
    ///
    /// # Failures
    /// A gain outside (0, 2]; the spline failing.
    pub fn correction(&self, grid: &[Real], gain: Real) -> Result<Vec<Real>, CompensateError> {
        if !(gain > 0.0 && gain <= 2.0) {
            return Err(CompensateError::Fit(format!(
                "the gain {gain} is out of range: above 0, at most 2 (1: the whole measured error)"
            )));
        }
        Ok(self.at(grid)?.iter().map(|e| -gain * e).collect())
    }
}

/// Refuses a correction `shift` at the places `at` larger than `limit`
/// anywhere, naming the first such place (`place` says it: `of the
/// depth at theta = 12.000 deg`) and the `file` measured.
///
/// # Failures
/// That.
pub fn within_limit(
    at: &[Real],
    shift: &[Real],
    limit: Real,
    place: &dyn Fn(Real) -> String,
    file: &str,
) -> Result<(), CompensateError> {
    match at.iter().zip(shift).find(|(_, c)| c.abs() > limit) {
        Some((s, c)) => Err(CompensateError::TooLarge {
            at: place(*s),
            correction: *c,
            limit,
            why: format!(
                "an error this large is not the process's drift: look at the measurement ({file}) or the part"
            ),
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A known smooth error (a taper and a bow, 10 um) measured every 10
    /// mm with a scatter of 0.87 um RMS (a fixed sequence, not random),
    /// held to an uncertainty of 1 um, is fitted within twice that of the
    /// truth, its residual the uncertainty; a straight error within the
    /// uncertainty is fitted by its line.
    #[test]
    fn the_fit_follows_the_error_not_the_scatter() {
        let at: Vec<Real> = (0..=40).map(|i| 10.0 * i as Real).collect();
        let truth = |z: Real| 0.004 + 0.006 * z / 400.0 - 0.01 * (z / 200.0 - 1.0).powi(2);
        let scatter = [0.8, -1.1, 0.3, 1.2, -0.6, -0.9, 0.5, 0.1, -1.3, 1.0];
        let error: Vec<Real> = at
            .iter()
            .enumerate()
            .map(|(i, &z)| truth(z) + 1e-3 * scatter[i % scatter.len()])
            .collect();
        let fit = fit_error(&at, &error, 1e-3).unwrap();
        assert!((fit.rms_residual - 1e-3).abs() < 1e-6, "{fit:?}");
        assert!(fit.smooth > 0.0 && fit.smooth < 1.0);
        let grid: Vec<Real> = (0..=400).map(|i| i as Real).collect();
        let worst = fit
            .at(&grid)
            .unwrap()
            .iter()
            .zip(&grid)
            .map(|(f, &z)| (f - truth(z)).abs())
            .fold(0.0, Real::max);
        assert!(worst < 2e-3, "{worst}");
        // A straight error within the uncertainty: the line.
        let line: Vec<Real> = at.iter().map(|z| 0.002 + 1e-5 * z).collect();
        let fit = fit_error(&at, &line, 1e-3).unwrap();
        assert_eq!(fit.smooth, 0.0);
        assert!(fit.rms_residual < 1e-12);
        // The correction: against the error, bounded.
        let grid = [0.0, 200.0, 400.0];
        let c = fit.correction(&grid, 1.0).unwrap();
        assert!((c[2] + 0.006).abs() < 1e-12, "{c:?}");
        let place = |z: Real| format!("at z = {z:.3} mm");
        within_limit(&grid, &c, 0.01, &place, "bench.csv").unwrap();
        let e = within_limit(&grid, &c, 0.005, &place, "bench.csv")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("-0.0060 mm at z = 400.000 mm is beyond its limit of 0.005 mm"),
            "{e}"
        );
        assert!(e.contains("(bench.csv)"), "{e}");
        assert!(fit.correction(&grid, 0.0).is_err());
        // As one value: the mean, the rest its residual.
        let fit = fit_mean(&[0.0, 10.0], &[0.010, 0.014], 1e-3).unwrap();
        assert!((fit.at(&[5.0, 99.0]).unwrap()[1] - 0.012).abs() < 1e-15);
        assert!((fit.rms_residual - 0.002).abs() < 1e-15);
    }
}
