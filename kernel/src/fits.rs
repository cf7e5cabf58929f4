//! Tolerances as drawings write them on a diameter: an ISO 286 fit of a
//! shaft (`h6`, `g5`, `js4`, `k6`) or the limits themselves (`±0.01`,
//! `+0.02/-0.01`, `0/-0.016`), read to the diameter's upper and lower
//! deviations (mm).
//!
//! The fits are ISO 286-1's published tables, not the formulas behind
//! them (the standard rounds its values; the table is the standard):
//! - the standard tolerance grades IT1 to IT16 (ISO 286-1:2010, table 1)
//!   for nominal sizes over 0 up to 500 mm;
//! - the fundamental deviations of shafts d, e, f, g, h (upper, `es`),
//!   js (`±IT/2`), k, m, n, p (lower, `ei`) (ISO 286-1:2010, table 2),
//!   k's `ei` being +0 outside grades 4 to 7, as the table gives it.
//!
//! Values as reproduced in the standard's tables and in engineering
//! handbooks (Roloff/Matek, Tabellenbuch Metall); `tests` below hold the
//! common fits read from a second source, ISO 286-2's tables of limits.
//! Holes (capital letters) are refused: a body of revolution's diameters
//! are a shaft's.

use crate::math::Real;

/// The nominal sizes' ranges (mm), each over the one before up to this.
const SIZES: [Real; 13] = [
    3.0, 6.0, 10.0, 18.0, 30.0, 50.0, 80.0, 120.0, 180.0, 250.0, 315.0, 400.0, 500.0,
];

/// IT1 to IT16 (um), by size range.
const IT: [[Real; 13]; 16] = [
    [
        0.8, 1.0, 1.0, 1.2, 1.5, 1.5, 2.0, 2.5, 3.5, 4.5, 6.0, 7.0, 8.0,
    ],
    [
        1.2, 1.5, 1.5, 2.0, 2.5, 2.5, 3.0, 4.0, 5.0, 7.0, 8.0, 9.0, 10.0,
    ],
    [
        2.0, 2.5, 2.5, 3.0, 4.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 13.0, 15.0,
    ],
    [
        3.0, 4.0, 4.0, 5.0, 6.0, 7.0, 8.0, 10.0, 12.0, 14.0, 16.0, 18.0, 20.0,
    ],
    [
        4.0, 5.0, 6.0, 8.0, 9.0, 11.0, 13.0, 15.0, 18.0, 20.0, 23.0, 25.0, 27.0,
    ],
    [
        6.0, 8.0, 9.0, 11.0, 13.0, 16.0, 19.0, 22.0, 25.0, 29.0, 32.0, 36.0, 40.0,
    ],
    [
        10.0, 12.0, 15.0, 18.0, 21.0, 25.0, 30.0, 35.0, 40.0, 46.0, 52.0, 57.0, 63.0,
    ],
    [
        14.0, 18.0, 22.0, 27.0, 33.0, 39.0, 46.0, 54.0, 63.0, 72.0, 81.0, 89.0, 97.0,
    ],
    [
        25.0, 30.0, 36.0, 43.0, 52.0, 62.0, 74.0, 87.0, 100.0, 115.0, 130.0, 140.0, 155.0,
    ],
    [
        40.0, 48.0, 58.0, 70.0, 84.0, 100.0, 120.0, 140.0, 160.0, 185.0, 210.0, 230.0, 250.0,
    ],
    [
        60.0, 75.0, 90.0, 110.0, 130.0, 160.0, 190.0, 220.0, 250.0, 290.0, 320.0, 360.0, 400.0,
    ],
    [
        100.0, 120.0, 150.0, 180.0, 210.0, 250.0, 300.0, 350.0, 400.0, 460.0, 520.0, 570.0, 630.0,
    ],
    [
        140.0, 180.0, 220.0, 270.0, 330.0, 390.0, 460.0, 540.0, 630.0, 720.0, 810.0, 890.0, 970.0,
    ],
    [
        250.0, 300.0, 360.0, 430.0, 520.0, 620.0, 740.0, 870.0, 1000.0, 1150.0, 1300.0, 1400.0,
        1550.0,
    ],
    [
        400.0, 480.0, 580.0, 700.0, 840.0, 1000.0, 1200.0, 1400.0, 1600.0, 1850.0, 2100.0, 2300.0,
        2500.0,
    ],
    [
        600.0, 750.0, 900.0, 1100.0, 1300.0, 1600.0, 1900.0, 2200.0, 2500.0, 2900.0, 3200.0,
        3600.0, 4000.0,
    ],
];

/// The shafts' fundamental deviations (um) by size range: the upper
/// deviation `es` of d to h, the lower `ei` of k (grades 4 to 7), m, n, p.
const DEVIATIONS: [(&str, [Real; 13]); 9] = [
    (
        "d",
        [
            -20.0, -30.0, -40.0, -50.0, -65.0, -80.0, -100.0, -120.0, -145.0, -170.0, -190.0,
            -210.0, -230.0,
        ],
    ),
    (
        "e",
        [
            -14.0, -20.0, -25.0, -32.0, -40.0, -50.0, -60.0, -72.0, -85.0, -100.0, -110.0, -125.0,
            -135.0,
        ],
    ),
    (
        "f",
        [
            -6.0, -10.0, -13.0, -16.0, -20.0, -25.0, -30.0, -36.0, -43.0, -50.0, -56.0, -62.0,
            -68.0,
        ],
    ),
    (
        "g",
        [
            -2.0, -4.0, -5.0, -6.0, -7.0, -9.0, -10.0, -12.0, -14.0, -15.0, -17.0, -18.0, -20.0,
        ],
    ),
    ("h", [0.0; 13]),
    (
        "k",
        [
            0.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0, 4.0, 5.0,
        ],
    ),
    (
        "m",
        [
            2.0, 4.0, 6.0, 7.0, 8.0, 9.0, 11.0, 13.0, 15.0, 17.0, 20.0, 21.0, 23.0,
        ],
    ),
    (
        "n",
        [
            4.0, 8.0, 10.0, 12.0, 15.0, 17.0, 20.0, 23.0, 27.0, 31.0, 34.0, 37.0, 40.0,
        ],
    ),
    (
        "p",
        [
            6.0, 12.0, 15.0, 18.0, 22.0, 26.0, 32.0, 37.0, 43.0, 50.0, 56.0, 62.0, 68.0,
        ],
    ),
];

/// A diameter's limits: its upper and lower deviations (mm) and the text
/// they were read from.
#[derive(Debug, Clone, PartialEq)]
pub struct Limits {
    /// The upper deviation (mm, on the diameter).
    pub upper: Real,
    /// The lower deviation (mm, on the diameter).
    pub lower: Real,
    /// As the drawing wrote it (`h6`, `±0.01`).
    pub text: String,
}

impl Limits {
    /// The band's middle on the diameter (mm): where the nominal aims.
    pub fn middle(&self) -> Real {
        0.5 * (self.upper + self.lower)
    }

    /// Half the band's width on the diameter (mm).
    pub fn half_width(&self) -> Real {
        0.5 * (self.upper - self.lower)
    }

    /// As a message names them on the diameter `size` (as the caller
    /// writes it): `d 18 h4: +0/-0.005 mm`.
    pub fn said(&self, size: &str) -> String {
        format!(
            "d {size} {}: {:+}/{:+} mm",
            self.text, self.upper, self.lower
        )
    }
}

/// A tolerance a drawing writes that cannot be read, and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("tolerance {}: {why}", crate::names::quoted(text))]
pub struct FitError {
    /// The text.
    pub text: String,
    /// Why it is refused.
    pub why: String,
}

/// The limits `text` gives a diameter of `size` mm: an ISO 286 shaft fit
/// (a position and a grade, `h6`), `±a` (or `+-a`), or `upper/lower`
/// (signed numbers, mm: `+0.02/-0.01`, `0/-0.016`).
///
/// # Failures
/// A fit whose position or grade the tables do not hold, a hole's fit,
/// a size outside 0 to 500 mm for a fit, limits that are not numbers or
/// whose upper is not above the lower.
pub fn limits(text: &str, size: Real) -> Result<Limits, FitError> {
    let t = text.trim();
    let fail = |why: String| FitError {
        text: text.to_owned(),
        why,
    };
    let number = |s: &str| {
        s.trim()
            .parse::<Real>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                fail(format!(
                    "'{}' is not a number (mm)",
                    crate::files::excerpt(s)
                ))
            })
    };
    let (upper, lower) = if let Some(a) = t.strip_prefix('±').or_else(|| t.strip_prefix("+-")) {
        let a = number(a)?;
        (a, -a)
    } else if let Some((u, l)) = t.split_once('/') {
        (number(u)?, number(l)?)
    } else {
        let (upper, lower) = shaft_fit(t, size).map_err(fail)?;
        return Ok(Limits {
            upper,
            lower,
            text: t.to_owned(),
        });
    };
    if upper <= lower {
        return Err(fail(format!(
            "the upper deviation {upper} mm must be above the lower {lower} mm"
        )));
    }
    Ok(Limits {
        upper,
        lower,
        text: t.to_owned(),
    })
}

/// An ISO 286 shaft fit's upper and lower deviations (mm) at `size`.
fn shaft_fit(fit: &str, size: Real) -> Result<(Real, Real), String> {
    let split = fit
        .find(|c: char| c.is_ascii_digit())
        .filter(|&i| i > 0)
        .ok_or_else(|| {
            "neither limits (±a, upper/lower in mm) nor an ISO 286 fit (a position and a grade, as h6)".to_owned()
        })?;
    let (position, grade) = fit.split_at(split);
    if position.chars().any(|c| c.is_ascii_uppercase()) {
        return Err(format!(
            "'{position}' is a hole's position; a body of revolution's diameter takes a shaft's (lower case: {})",
            position.to_lowercase()
        ));
    }
    let grade: usize = grade
        .parse()
        .ok()
        .filter(|g| (1..=IT.len()).contains(g))
        .ok_or_else(|| {
            format!(
                "grade '{grade}': ISO 286's tables here hold IT1 to IT{}",
                IT.len()
            )
        })?;
    if !(size > 0.0 && size <= SIZES[SIZES.len() - 1]) {
        return Err(format!(
            "the diameter {size} mm is outside ISO 286's sizes held here (over 0 up to 500 mm)"
        ));
    }
    let range = SIZES
        .iter()
        .position(|&s| size <= s)
        .unwrap_or(SIZES.len() - 1);
    let it = IT[grade - 1][range];
    let positions: Vec<&str> = DEVIATIONS.iter().map(|d| d.0).chain(["js"]).collect();
    let (upper, lower) = match position {
        "js" => (0.5 * it, -0.5 * it),
        "k" if !(4..=7).contains(&grade) => (it, 0.0),
        p => match DEVIATIONS.iter().find(|d| d.0 == p) {
            Some((p, row)) if "defgh".contains(p) => (row[range], row[range] - it),
            Some((_, row)) => (row[range] + it, row[range]),
            None => {
                return Err(format!(
                    "position '{p}': the tables here hold {}",
                    positions.join(", ")
                ))
            }
        },
    };
    Ok((upper / 1e3, lower / 1e3))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Common fits as ISO 286-2's tables of limits give them (um): the
    /// table here, read to its limits, agrees exactly.
    #[test]
    fn fits_read_as_iso_286_2_tabulates_them() {
        for (fit, size, upper, lower) in [
            ("h6", 40.0, 0, -16),
            ("g6", 40.0, -9, -25),
            ("f7", 40.0, -25, -50),
            ("e8", 40.0, -50, -89),
            ("d9", 40.0, -80, -142),
            ("h5", 18.0, 0, -8),
            ("h7", 25.0, 0, -21),
            ("k6", 25.0, 15, 2),
            ("m6", 25.0, 21, 8),
            ("n6", 25.0, 28, 15),
            ("p6", 25.0, 35, 22),
            ("js6", 50.0, 8, -8),
            ("g5", 10.0, -5, -11),
            ("h4", 100.0, 0, -10),
            ("k6", 100.0, 25, 3),
            ("k8", 100.0, 54, 0),
            ("h11", 6.0, 0, -75),
            ("f6", 200.0, -50, -79),
        ] {
            let l = limits(fit, size).unwrap();
            assert_eq!(
                (
                    (l.upper * 1e3).round() as i64,
                    (l.lower * 1e3).round() as i64
                ),
                (upper, lower),
                "{fit} at {size}"
            );
        }
    }

    /// The range's upper bound belongs to it: 18 is in "over 10 up to 18".
    #[test]
    fn a_size_at_a_ranges_end_is_in_it() {
        assert_eq!(limits("h6", 18.0).unwrap().lower, -0.011);
        assert_eq!(limits("h6", 18.001).unwrap().lower, -0.013);
    }

    #[test]
    fn limits_as_written_and_refusals() {
        let l = limits("±0.01", 40.0).unwrap();
        assert_eq!((l.upper, l.lower, l.middle()), (0.01, -0.01, 0.0));
        let l = limits("+0.02/-0.01", 40.0).unwrap();
        assert!((l.middle() - 0.005).abs() < 1e-15 && (l.half_width() - 0.015).abs() < 1e-15);
        assert_eq!(limits("+-0.005", 1.0).unwrap().lower, -0.005);
        for (text, says) in [
            ("H7", "a hole's position"),
            ("h19", "IT1 to IT16"),
            ("x6", "position 'x'"),
            ("0.01", "neither limits"),
            ("-0.01/0.01", "must be above"),
            ("±a", "is not a number"),
        ] {
            let e = limits(text, 40.0).unwrap_err().to_string();
            assert!(e.contains(says), "{text}: {e}");
        }
        assert!(limits("h6", 600.0)
            .unwrap_err()
            .to_string()
            .contains("500 mm"));
    }
}
