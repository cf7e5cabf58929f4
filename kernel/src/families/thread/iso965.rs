//! ISO 965-1's tolerances of ISO metric threads, as its tables publish
//! them.
//!
//! ISO 965-1 derives its tolerances from formulas (`Td2(6) = 90 P^0.4
//! d^0.1` um and the like) but publishes them as rounded table values, and
//! where the two disagree the table is the standard: the formula rounded
//! to R40 gives M3x0.5-6g's least pitch diameter 2.5752 mm where the table
//! gives 2.580 mm (5 um on the side where parts the standard rejects would
//! pass), M12x1.5-6H's greatest 11.2057 mm where the table gives 11.216 mm.
//! So the tolerances here are the tables' cells, and a grade or a pitch a
//! table does not hold for a diameter range is refused, not computed.
//!
//! Source: ISO 965-1:1998, tables 1 (fundamental deviations), 2 (TD1, the
//! internal minor diameter), 3 (Td, the external major diameter), 4 (TD2,
//! the internal pitch diameter) and 5 (Td2, the external pitch diameter),
//! typed from the standard's tables as engineering handbooks reproduce them
//! (the same cells ASME B1.13M reprints for the M profile). They are
//! checked, cell by cell, against ISO 965-2's limits of sizes as another
//! source publishes them (`kernel/tests/data/iso965-2-limits.tsv`, 218
//! sizes from 1.6 to 100 mm, each limit a basic size, a deviation and a
//! tolerance from here).
//!
//! Hand-written: tables of a standard, with no crate that holds them.

use crate::input::InputError;
use crate::math::Real;
use crate::tolerance::SAME_LENGTH;

/// ISO 965-1's diameter ranges (mm): over the first, up to the second.
const RANGES: [(Real, Real); 9] = [
    (0.99, 1.4),
    (1.4, 2.8),
    (2.8, 5.6),
    (5.6, 11.2),
    (11.2, 22.4),
    (22.4, 45.0),
    (45.0, 90.0),
    (90.0, 180.0),
    (180.0, 355.0),
];

/// One pitch's row: the pitch (mm) and its cells (um), from the table's
/// first grade on; a shorter row has no cell for the higher grades.
type Row = (Real, &'static [u16]);

/// Table 1, the fundamental deviations (um) by pitch: e, f, g of the
/// external thread (its upper deviation, below the basic size; 0 where
/// the table has none) and G of the internal (its lower, above the basic
/// size, the size of g's); h and H are 0.
const DEVIATIONS: [(Real, [u16; 3]); 25] = [
    (0.2, [0, 0, 17]),
    (0.25, [0, 0, 18]),
    (0.3, [0, 0, 18]),
    (0.35, [0, 34, 19]),
    (0.4, [0, 34, 19]),
    (0.45, [0, 35, 20]),
    (0.5, [50, 36, 20]),
    (0.6, [53, 36, 21]),
    (0.7, [56, 38, 22]),
    (0.75, [56, 38, 22]),
    (0.8, [60, 38, 24]),
    (1.0, [60, 40, 26]),
    (1.25, [63, 42, 28]),
    (1.5, [67, 45, 32]),
    (1.75, [71, 48, 34]),
    (2.0, [71, 52, 38]),
    (2.5, [80, 58, 42]),
    (3.0, [85, 63, 48]),
    (3.5, [90, 70, 53]),
    (4.0, [95, 75, 60]),
    (4.5, [100, 80, 63]),
    (5.0, [106, 85, 71]),
    (5.5, [112, 90, 75]),
    (6.0, [118, 95, 80]),
    (8.0, [140, 118, 100]),
];

/// Table 2, TD1 (um) by pitch, grades 4 to 8.
const NUT_MINOR: [Row; 25] = [
    (0.2, &[38]),
    (0.25, &[45, 56]),
    (0.3, &[53, 67, 85]),
    (0.35, &[63, 80, 100]),
    (0.4, &[71, 90, 112]),
    (0.45, &[80, 100, 125]),
    (0.5, &[90, 112, 140, 180]),
    (0.6, &[100, 125, 160, 200]),
    (0.7, &[112, 140, 180, 224]),
    (0.75, &[118, 150, 190, 236]),
    (0.8, &[125, 160, 200, 250, 315]),
    (1.0, &[150, 190, 236, 300, 375]),
    (1.25, &[170, 212, 265, 335, 425]),
    (1.5, &[190, 236, 300, 375, 475]),
    (1.75, &[212, 265, 335, 425, 530]),
    (2.0, &[236, 300, 375, 475, 600]),
    (2.5, &[280, 355, 450, 560, 710]),
    (3.0, &[315, 400, 500, 630, 800]),
    (3.5, &[355, 450, 560, 710, 900]),
    (4.0, &[375, 475, 600, 750, 950]),
    (4.5, &[425, 530, 670, 850, 1060]),
    (5.0, &[450, 560, 710, 900, 1120]),
    (5.5, &[475, 600, 750, 950, 1180]),
    (6.0, &[500, 630, 800, 1000, 1250]),
    (8.0, &[630, 800, 1000, 1250, 1600]),
];

/// Table 3, Td (um) by pitch, grades 4, 6 and 8.
const BOLT_MAJOR: [Row; 25] = [
    (0.2, &[36, 56]),
    (0.25, &[42, 67]),
    (0.3, &[48, 75]),
    (0.35, &[53, 85]),
    (0.4, &[60, 95]),
    (0.45, &[63, 100]),
    (0.5, &[67, 106]),
    (0.6, &[80, 125]),
    (0.7, &[90, 140]),
    (0.75, &[90, 140]),
    (0.8, &[95, 150, 236]),
    (1.0, &[112, 180, 280]),
    (1.25, &[132, 212, 335]),
    (1.5, &[150, 236, 375]),
    (1.75, &[170, 265, 425]),
    (2.0, &[180, 280, 450]),
    (2.5, &[212, 335, 530]),
    (3.0, &[236, 375, 600]),
    (3.5, &[265, 425, 670]),
    (4.0, &[300, 475, 750]),
    (4.5, &[315, 500, 800]),
    (5.0, &[335, 530, 850]),
    (5.5, &[355, 560, 900]),
    (6.0, &[375, 600, 950]),
    (8.0, &[450, 710, 1180]),
];

/// Table 4, TD2 (um) by diameter range (as [`RANGES`]) and pitch, grades
/// 4 to 8.
const NUT_PITCH: [&[Row]; 9] = [
    &[(0.2, &[40]), (0.25, &[45, 56]), (0.3, &[48, 60, 75])],
    &[
        (0.2, &[42]),
        (0.25, &[48, 60]),
        (0.35, &[53, 67, 85]),
        (0.4, &[56, 71, 90]),
        (0.45, &[60, 75, 95]),
    ],
    &[
        (0.35, &[56, 71, 90]),
        (0.5, &[63, 80, 100, 125]),
        (0.6, &[71, 90, 112, 140]),
        (0.7, &[75, 95, 118, 150]),
        (0.75, &[75, 95, 118, 150]),
        (0.8, &[80, 100, 125, 160, 200]),
    ],
    &[
        (0.75, &[85, 106, 132, 170]),
        (1.0, &[95, 118, 150, 190, 236]),
        (1.25, &[100, 125, 160, 200, 250]),
        (1.5, &[112, 140, 180, 224, 280]),
    ],
    &[
        (1.0, &[100, 125, 160, 200, 250]),
        (1.25, &[112, 140, 180, 224, 280]),
        (1.5, &[118, 150, 190, 236, 300]),
        (1.75, &[125, 160, 200, 250, 315]),
        (2.0, &[132, 170, 212, 265, 335]),
        (2.5, &[140, 180, 224, 280, 355]),
    ],
    &[
        (1.0, &[106, 132, 170, 212]),
        (1.5, &[125, 160, 200, 250, 315]),
        (2.0, &[140, 180, 224, 280, 355]),
        (3.0, &[170, 212, 265, 335, 425]),
        (3.5, &[180, 224, 280, 355, 450]),
        (4.0, &[190, 236, 300, 375, 475]),
        (4.5, &[200, 250, 315, 400, 500]),
    ],
    &[
        (1.5, &[132, 170, 212, 265, 335]),
        (2.0, &[150, 190, 236, 300, 375]),
        (3.0, &[180, 224, 280, 355, 450]),
        (4.0, &[200, 250, 315, 400, 500]),
        (5.0, &[212, 265, 335, 425, 530]),
        (5.5, &[224, 280, 355, 450, 560]),
        (6.0, &[236, 300, 375, 475, 600]),
    ],
    &[
        (2.0, &[160, 200, 250, 315, 400]),
        (3.0, &[190, 236, 300, 375, 475]),
        (4.0, &[212, 265, 335, 425, 530]),
        (6.0, &[250, 315, 400, 500, 630]),
        (8.0, &[280, 355, 450, 560, 710]),
    ],
    &[
        (3.0, &[212, 265, 335, 425, 530]),
        (4.0, &[236, 300, 375, 475, 600]),
        (6.0, &[265, 335, 425, 530, 670]),
        (8.0, &[300, 375, 475, 600, 750]),
    ],
];

/// Table 5, Td2 (um) by diameter range (as [`RANGES`]) and pitch, grades
/// 3 to 9.
const BOLT_PITCH: [&[Row]; 9] = [
    &[
        (0.2, &[24, 30, 38, 48]),
        (0.25, &[26, 34, 42, 53]),
        (0.3, &[28, 36, 45, 56]),
    ],
    &[
        (0.2, &[25, 32, 40, 50]),
        (0.25, &[28, 36, 45, 56]),
        (0.35, &[32, 40, 50, 63, 80]),
        (0.4, &[34, 42, 53, 67, 85]),
        (0.45, &[36, 45, 56, 71, 90]),
    ],
    &[
        (0.35, &[34, 42, 53, 67, 85]),
        (0.5, &[38, 48, 60, 75, 95]),
        (0.6, &[42, 53, 67, 85, 106]),
        (0.7, &[45, 56, 71, 90, 112]),
        (0.75, &[45, 56, 71, 90, 112]),
        (0.8, &[48, 60, 75, 95, 118, 150, 190]),
    ],
    &[
        (0.75, &[50, 63, 80, 100, 125]),
        (1.0, &[56, 71, 90, 112, 140, 180, 224]),
        (1.25, &[60, 75, 95, 118, 150, 190, 236]),
        (1.5, &[67, 85, 106, 132, 170, 212, 265]),
    ],
    &[
        (1.0, &[60, 75, 95, 118, 150, 190, 236]),
        (1.25, &[67, 85, 106, 132, 170, 212, 265]),
        (1.5, &[71, 90, 112, 140, 180, 224, 280]),
        (1.75, &[75, 95, 118, 150, 190, 236, 300]),
        (2.0, &[80, 100, 125, 160, 200, 250, 315]),
        (2.5, &[85, 106, 132, 170, 212, 265, 335]),
    ],
    &[
        (1.0, &[63, 80, 100, 125, 160, 200, 250]),
        (1.5, &[75, 95, 118, 150, 190, 236, 300]),
        (2.0, &[85, 106, 132, 170, 212, 265, 335]),
        (3.0, &[100, 125, 160, 200, 250, 315, 400]),
        (3.5, &[106, 132, 170, 212, 265, 335, 425]),
        (4.0, &[112, 140, 180, 224, 280, 355, 450]),
        (4.5, &[118, 150, 190, 236, 300, 375, 475]),
    ],
    &[
        (1.5, &[80, 100, 125, 160, 200, 250, 315]),
        (2.0, &[90, 112, 140, 180, 224, 280, 355]),
        (3.0, &[106, 132, 170, 212, 265, 335, 425]),
        (4.0, &[118, 150, 190, 236, 300, 375, 475]),
        (5.0, &[125, 160, 200, 250, 315, 400, 500]),
        (5.5, &[132, 170, 212, 265, 335, 425, 530]),
        (6.0, &[140, 180, 224, 280, 355, 450, 560]),
    ],
    &[
        (2.0, &[95, 118, 150, 190, 236, 300, 375]),
        (3.0, &[112, 140, 180, 224, 280, 355, 450]),
        (4.0, &[125, 160, 200, 250, 315, 400, 500]),
        (6.0, &[150, 190, 236, 300, 375, 475, 600]),
        (8.0, &[170, 212, 265, 335, 425, 530, 670]),
    ],
    &[
        (3.0, &[125, 160, 200, 250, 315, 400, 500]),
        (4.0, &[140, 180, 224, 280, 355, 450, 560]),
        (6.0, &[160, 200, 250, 315, 400, 500, 630]),
        (8.0, &[180, 224, 280, 355, 450, 560, 710]),
    ],
];

/// A toleranced quantity of ISO 965-1, with its table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// Td2: the external thread's pitch diameter.
    BoltPitch,
    /// TD2: the internal thread's pitch diameter.
    NutPitch,
    /// Td: the external thread's major diameter (its crest).
    BoltMajor,
    /// TD1: the internal thread's minor diameter (its crest).
    NutMinor,
}

impl Quantity {
    /// The quantity's symbol and name, for messages.
    fn said(self) -> &'static str {
        match self {
            Self::BoltPitch => "the pitch diameter's tolerance Td2",
            Self::NutPitch => "the pitch diameter's tolerance TD2",
            Self::BoltMajor => "the major diameter's tolerance Td",
            Self::NutMinor => "the minor diameter's tolerance TD1",
        }
    }

    /// The grades the table's columns hold, in order.
    fn grades(self) -> &'static [u32] {
        match self {
            Self::BoltPitch => &[3, 4, 5, 6, 7, 8, 9],
            Self::NutPitch | Self::NutMinor => &[4, 5, 6, 7, 8],
            Self::BoltMajor => &[4, 6, 8],
        }
    }

    /// The table's rows for a diameter in range `range` (an index into
    /// [`RANGES`]).
    fn rows(self, range: usize) -> &'static [Row] {
        match self {
            Self::BoltPitch => BOLT_PITCH[range],
            Self::NutPitch => NUT_PITCH[range],
            Self::BoltMajor => &BOLT_MAJOR,
            Self::NutMinor => &NUT_MINOR,
        }
    }
}

/// The tolerance (mm) of `quantity` in `grade` for a thread of major
/// diameter `d` and pitch `pitch` (mm), as ISO 965-1's table gives it.
///
/// # Failures
/// A diameter outside the table's ranges, a pitch the table does not hold
/// for the diameter's range, a grade it has no column or no cell for;
/// `class` (as written) names the class in the message.
pub fn tolerance(
    quantity: Quantity,
    d: Real,
    pitch: Real,
    grade: u32,
    class: &str,
) -> Result<Real, InputError> {
    let range = range_of(d)?;
    let rows = quantity.rows(range);
    let Some(&(_, cells)) = rows.iter().find(|(p, _)| same(*p, pitch)) else {
        let (over, to) = RANGES[range];
        let pitches: Vec<String> = rows.iter().map(|(p, _)| p.to_string()).collect();
        return Err(InputError::out_of_range(
            "pitch P",
            pitch,
            format!(
                "a pitch ISO 965-1 tabulates for diameters over {over} to {to} mm: {}",
                pitches.join(", ")
            ),
        ));
    };
    let grades = quantity.grades();
    let column = grades.iter().position(|g| *g == grade).ok_or_else(|| {
        let hint = match quantity {
            Quantity::BoltMajor | Quantity::NutMinor => {
                "; a class of two grades gives the crest's second, as 5g6g"
            }
            _ => "",
        };
        bad_class(
            class,
            format!(
                "has grade {grade} where ISO 965-1 tabulates {} in grades {}{hint}",
                quantity.said(),
                listed(grades)
            ),
        )
    })?;
    let cell = cells.get(column).ok_or_else(|| {
        bad_class(
            class,
            format!(
                "has grade {grade} where ISO 965-1 tabulates {} for P = {pitch} mm in grades {} only",
                quantity.said(),
                listed(&grades[..cells.len()])
            ),
        )
    })?;
    Ok(Real::from(*cell) * 1e-3)
}

/// The fundamental deviation (mm) of tolerance position `position` at
/// pitch `pitch`: an external thread's upper deviation (e, f, g below the
/// basic size, negative; h 0), an internal thread's lower (G above it,
/// positive; H 0).
///
/// # Failures
/// A pitch outside table 1, a position it does not name, or one it has no
/// cell for at that pitch (e below 0.5 mm, f below 0.35 mm).
pub fn deviation(position: &str, pitch: Real, class: &str) -> Result<Real, InputError> {
    let Some(&(_, [e, f, g])) = DEVIATIONS.iter().find(|(p, _)| same(*p, pitch)) else {
        return Err(InputError::out_of_range(
            "pitch P",
            pitch,
            "a pitch of ISO 965-1's table: 0.2 to 6 mm or 8 mm",
        ));
    };
    let um = match position {
        "h" | "H" => return Ok(0.0),
        "e" => -Real::from(e),
        "f" => -Real::from(f),
        "g" => -Real::from(g),
        "G" => Real::from(g),
        _ => {
            return Err(bad_class(
                class,
                "has no position of ISO 965-1: e, f, g or h (external), G or H (internal)",
            ))
        }
    };
    if um == 0.0 {
        return Err(bad_class(
            class,
            format!(
                "has position {position}, which ISO 965-1 has no deviation for at P = {pitch} mm"
            ),
        ));
    }
    Ok(um * 1e-3)
}

/// A class refused, quoted, with why.
pub fn bad_class(class: &str, reason: impl Into<String>) -> InputError {
    InputError::BadText {
        what: "tolerance class".into(),
        value: format!("'{class}'"),
        reason: reason.into(),
    }
}

/// The index in [`RANGES`] of the range holding `d`.
fn range_of(d: Real) -> Result<usize, InputError> {
    RANGES
        .iter()
        .position(|(over, to)| d > *over && d <= *to)
        .ok_or_else(|| {
            InputError::out_of_range(
                "major diameter d",
                d,
                "above 0.99 and at most 355 mm (ISO 965-1's ranges)",
            )
        })
}

/// Two pitches the same (a table's pitch against one as written).
fn same(a: Real, b: Real) -> bool {
    (a - b).abs() < SAME_LENGTH
}

/// Grades as a list, "4, 6 and 8".
fn listed(grades: &[u32]) -> String {
    match grades {
        [] => String::new(),
        [one] => one.to_string(),
        [rest @ .., last] => {
            let rest: Vec<String> = rest.iter().map(u32::to_string).collect();
            format!("{} and {last}", rest.join(", "))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each table's rows are in rising pitch, its cells rising with the
    /// grade, and every row of a range's table no longer than its grades.
    #[test]
    fn the_tables_rise_with_pitch_and_grade() {
        let check = |rows: &[Row], grades: usize| {
            for w in rows.windows(2) {
                assert!(w[0].0 < w[1].0, "{w:?}");
            }
            for (p, cells) in rows {
                assert!(!cells.is_empty() && cells.len() <= grades, "{p}");
                assert!(cells.windows(2).all(|c| c[0] < c[1]), "{p} {cells:?}");
            }
        };
        for q in [
            Quantity::BoltPitch,
            Quantity::NutPitch,
            Quantity::BoltMajor,
            Quantity::NutMinor,
        ] {
            for range in 0..RANGES.len() {
                check(q.rows(range), q.grades().len());
            }
        }
        // A nut's pitch-diameter tolerance is the bolt's grade's 1.32 times,
        // rounded: never below the bolt's.
        for range in 0..RANGES.len() {
            for (p, nut) in NUT_PITCH[range] {
                let bolt = BOLT_PITCH[range].iter().find(|r| r.0 == *p).unwrap().1;
                for (i, n) in nut.iter().enumerate() {
                    assert!(*n > bolt[i + 1], "{range} {p}");
                }
            }
        }
    }

    /// What the tables do not hold is refused, saying what they hold.
    #[test]
    fn cells_the_tables_lack_are_refused() {
        let e = |r: Result<Real, InputError>| r.unwrap_err().to_string();
        let m = e(tolerance(Quantity::BoltMajor, 20.0, 2.5, 5, "5g"));
        assert!(m.contains("grades 4, 6 and 8") && m.contains("5g6g"), "{m}");
        let m = e(tolerance(Quantity::BoltPitch, 8.0, 0.5, 6, "6g"));
        assert!(m.contains("over 5.6 to 11.2 mm: 0.75, 1, 1.25, 1.5"), "{m}");
        let m = e(tolerance(Quantity::NutPitch, 3.0, 0.5, 8, "8H"));
        assert!(m.contains("grades 4, 5, 6 and 7 only"), "{m}");
        let m = e(tolerance(Quantity::BoltPitch, 400.0, 6.0, 6, "6g"));
        assert!(m.contains("355 mm"), "{m}");
        let m = e(deviation("e", 0.4, "6e"));
        assert!(m.contains("no deviation for at P = 0.4"), "{m}");
        assert_eq!(deviation("G", 2.5, "6G").unwrap(), 0.042);
        assert_eq!(deviation("f", 2.5, "6f").unwrap(), -0.058);
    }
}
