//! The part a corrected run predicts, judged: the measured error
//! repeating, less the correction, against the family's tolerance. A fit
//! held to the stated uncertainty may leave a local error unfollowed (a
//! straight line through a wear with a bump on it); the run then fails
//! naming where and by how much, and which uncertainty would follow it.

use super::{CompensateOptions, QuantityRecord};
use crate::compensate::{fit_error, Quantity};
use crate::math::{fixed, Real};
use crate::verdict::{Figure, Finding};

/// The rule of a corrected part predicted beyond its tolerance.
pub const AFTER: &str = "the corrected part within its tolerance";

/// How many times the uncertainty is halved in seeking one that would
/// follow the error (down to 1/256 of it).
const HALVINGS: i32 = 8;

/// Per quantity held to one tolerance and corrected along the coordinate:
/// the figure of the part expected after the correction (its worst
/// place), and where that is beyond the tolerance, the finding saying
/// what the fit left and what uncertainty would follow it.
pub(super) fn judged(
    records: &[QuantityRecord],
    quantities: &[Quantity],
    coordinate: &str,
    options: &CompensateOptions,
) -> (Vec<Figure>, Vec<Finding>) {
    let (mut figures, mut findings) = (Vec::new(), Vec::new());
    for (r, q) in records.iter().zip(quantities) {
        let Some(tolerance) = q.tolerance.filter(|_| r.along) else {
            continue;
        };
        let Some(worst) = (r.places.iter())
            .max_by(|a, b| a.expected_after.abs().total_cmp(&b.expected_after.abs()))
        else {
            continue;
        };
        let place = format!("{coordinate} = {}", fixed(worst.at, 3));
        figures.push(Figure::new(
            &format!(
                "the part after the correction: its {} from the nominal",
                r.name
            ),
            worst.expected_after,
            tolerance,
            "mm",
            place.clone(),
        ));
        if worst.expected_after.abs() <= tolerance {
            continue;
        }
        let follows = following(r, tolerance, options);
        findings.push(Finding::new(
            AFTER,
            format!(
                "the correction, its fit held to the uncertainty {} mm, leaves the part {} mm from the nominal at {place} (tolerance {} mm): the fit strays {} mm from the measured error there; {}",
                options.uncertainty,
                fixed(worst.expected_after, 5),
                tolerance,
                fixed(worst.unmodelled - worst.fitted, 5),
                match follows {
                    Some(u) => format!(
                        "held to {} mm (--uncertainty {}), if the measurement is that good, the fit follows it and leaves the part within the tolerance at the measured places",
                        fixed(u, 6),
                        fixed(u, 6)
                    ),
                    None => format!(
                        "no uncertainty down to {} mm follows it within the tolerance: measure the part there more densely, or correct it by hand",
                        fixed(options.uncertainty * (0.5 as Real).powi(HALVINGS), 6)
                    ),
                }
            ),
        ));
    }
    (figures, findings)
}

/// The largest of the uncertainty's halvings whose fit would leave every
/// measured place within `tolerance`: the part expected after moves by
/// the gain times the change of the fit. (Between the places the fit is
/// not measured.)
fn following(r: &QuantityRecord, tolerance: Real, options: &CompensateOptions) -> Option<Real> {
    let at: Vec<Real> = r.places.iter().map(|p| p.at).collect();
    let error: Vec<Real> = r.places.iter().map(|p| p.unmodelled).collect();
    (1..=HALVINGS)
        .map(|k| options.uncertainty * (0.5 as Real).powi(k))
        .find(|&u| {
            let Ok(fit) = fit_error(&at, &error, u) else {
                return false;
            };
            let Ok(values) = fit.at(&at) else {
                return false;
            };
            (r.places.iter().zip(values))
                .all(|(p, f)| (p.expected_after + options.gain * (p.fitted - f)).abs() <= tolerance)
        })
}
