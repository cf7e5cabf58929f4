//! Thread profiles from the standards' formulas, with their limits.
//!
//! - **ISO metric** (ISO 68-1 basic profile, ISO 965-1 tolerances): 60
//!   degrees, `H = sqrt(3)/2 P`; `d2 = d - 3/4 H` (0.649519 P), `d1 = d -
//!   5/4 H` (1.082532 P); an external thread's rounded root `d3 = d1 -
//!   H/6` (radius `H/6`). The tolerances and fundamental deviations are
//!   ISO 965-1's published tables ([`super::iso965`]), not the formulas
//!   behind them: a class is a grade and a position (`6g`, `6H`) or two
//!   grades of one position (`5g6g`: the pitch diameter's, then the
//!   crest's), and a grade or pitch the tables do not hold is refused.
//! - **Trapezoidal** (ISO 2904): 30 degrees, `H1 = P/2`, the crest
//!   clearance `ac` by pitch, `h3 = H4 = H1 + ac`; `d2 = d - P/2`, `d3 = d
//!   - 2 h3`, `D1 = d - P`, `D4 = d + 2 ac`. Limits stated (see
//!   [`StatedLimits`]).
//! - **ACME** general purpose (ASME B1.5), inch: 29 degrees, `h = P/2`,
//!   basic pitch diameter `D - P/2`; class 2G: the external pitch
//!   diameter's allowance `0.008 sqrt(D)`, its tolerance `0.030 sqrt(P) +
//!   0.006 sqrt(D)`, the major's tolerance `0.05 P`, the minor at most `D -
//!   (P + 0.020)` (`0.010` finer than 10 tpi) with 1.5 times the pitch
//!   diameter's tolerance; the internal thread's pitch diameter from the
//!   basic up by the same tolerance, its minor from `D - P` up by `0.05 P`.
//!   Checked against B1.5's published 2G sizes; 3G and 4G are not offered
//!   until theirs are.
//! - **Buttress 7/45** (ASME B1.9), inch: the load flank at 7 degrees, the
//!   other at 45, `h = 0.6 P` of engagement, the external thread's depth
//!   `0.66271 P`, root radius `0.07141 P`. Limits stated.
//!
//! - **Pipe threads, straight** (ISO 228-1, `G`): the Whitworth form of
//!   ISO 7-1, 55 degrees, `H = 0.960491 P`, depth `h = 0.640327 P`, crest
//!   and root rounded `r = 0.137329 P`; `d2 = d - h`, `d1 = d - 2 h`; the
//!   sizes and threads per inch of its table 1, and its tolerances by
//!   threads per inch: the internal pitch diameter `+TD2` above the basic,
//!   the external one `TD2` (class A) or `2 TD2` (class B) below it, the
//!   external major `2 TD2` below, the internal minor its own band above
//!   (the crest's rounding is not modelled: the blank is turned to the
//!   major, the bore to the minor).
//!
//! Hand-written: these are tables and one-line formulas of the standards,
//! with no crate that holds them.

use super::iso965::{self, Quantity};
use super::profile::{Hand, Limits, ThreadLimits, ThreadProfile, ThreadSection};
use crate::input::InputError;
use crate::math::{positive, Real};
use crate::profile::FlankForm;

/// The mm of an inch.
pub const INCH: Real = 25.4;

/// An ISO metric thread `M d x P`, external or internal, of tolerance
/// class `class` (grade and position: `6g`, `6H`, `4h`, ...), `starts`
/// starts (P the pitch between neighbouring threads).
///
/// # Failures
/// A size that is not positive; a pitch outside ISO 965-1's table, a
/// diameter outside 1 to 180 mm, a class it does not name.
pub fn metric(
    d: Real,
    pitch: Real,
    internal: bool,
    class: &str,
    starts: u32,
    hand: Hand,
) -> Result<ThreadProfile, InputError> {
    positive("major diameter d", d)?;
    positive("pitch P", pitch)?;
    let (position, grade, crest) = class_grades(class).ok_or_else(|| {
        iso965::bad_class(
            class,
            if internal {
                "is not a grade and G or H, as 6H, nor two grades of one position, as 5H6H"
            } else {
                "is not a grade and e, f, g or h, as 6g, nor two grades of one position, as 5g6g"
            },
        )
    })?;
    let basic = MetricBasic::of(d, pitch);
    let limits = metric_limits(&basic, internal, class, (position, grade, crest))?;
    let (h, d1, d2) = (basic.h, basic.d1, basic.d2);
    let fine = if starts == 1 && (pitch - coarse_pitch(d)).abs() < crate::tolerance::SAME_LENGTH {
        format!("M{}", number(d))
    } else {
        format!("M{}x{}", number(d), lead_and_pitch(pitch, starts))
    };
    Ok(ThreadProfile {
        designation: format!("{fine}-{class}{}", hand_suffix(hand)),
        standard: "ISO 68-1, ISO 965-1".into(),
        section: ThreadSection {
            internal,
            pitch,
            starts,
            hand,
            major: d,
            pitch_diameter: d2,
            root_diameter: if internal { d } else { d1 - h / 6.0 },
            crest_diameter: if internal { d1 } else { d },
            flanks: [30.0_f64.to_radians(); 2],
            space_at_pitch: pitch / 2.0,
            root_radius: if internal { 0.0 } else { h / 6.0 },
            form: FlankForm::Axial,
        },
        limits,
    })
}

/// ISO 68-1's basic sizes of a metric thread: the major diameter, the
/// pitch, the fundamental triangle's height H, the minor and pitch
/// diameters.
#[derive(Debug, Clone, Copy)]
struct MetricBasic {
    d: Real,
    pitch: Real,
    h: Real,
    d1: Real,
    d2: Real,
}

impl MetricBasic {
    /// The basic sizes of `M<d>x<pitch>`.
    fn of(d: Real, pitch: Real) -> Self {
        let h = 3.0_f64.sqrt() / 2.0 * pitch;
        // 3/8 and 5/8 of the fundamental triangle's height H from the major.
        Self {
            d,
            pitch,
            h,
            d1: d - 1.25 * h,
            d2: d - 0.75 * h,
        }
    }
}

/// A metric class's position and its grades, the pitch diameter's and
/// the crest's: `6g` one grade for both, `5g6g` (ISO 965-1's two-part
/// class) each its own, both of one position; `None` for another form.
fn class_grades(class: &str) -> Option<(&str, u32, u32)> {
    let mut chars = class.chars();
    let grade = chars.next()?.to_digit(10)?;
    let rest = chars.as_str();
    match rest.find(|c: char| c.is_ascii_digit()) {
        Some(i) => {
            let (position, tail) = rest.split_at(i);
            let mut t = tail.chars();
            let crest = t.next()?.to_digit(10)?;
            (t.as_str() == position).then_some((position, grade, crest))
        }
        None => Some((rest, grade, grade)),
    }
}

/// The limits of `basic` in `class` (its tolerance position, the pitch
/// diameter's grade and the crest's), from ISO 965-1's tables.
///
/// # Failures
/// A position the thread cannot have (lower case is external, upper case
/// internal), a cell the tables do not hold.
fn metric_limits(
    basic: &MetricBasic,
    internal: bool,
    class: &str,
    (position, grade, crest): (&str, u32, u32),
) -> Result<ThreadLimits, InputError> {
    let MetricBasic {
        d,
        pitch,
        h,
        d1,
        d2,
    } = *basic;
    let upper = position.chars().all(|c| c.is_ascii_uppercase());
    if upper != internal {
        return Err(iso965::bad_class(
            class,
            if internal {
                "is not an internal thread's: its position is G or H (upper case), as 6H"
            } else {
                "is not an external thread's: its position is e, f, g or h (lower case), as 6g"
            },
        ));
    }
    let deviation = iso965::deviation(position, pitch, class)?;
    let table = |q, g| iso965::tolerance(q, d, pitch, g, class);
    let source = format!("ISO 965-1 {class}");
    Ok(if internal {
        let ei = deviation;
        let td2 = table(Quantity::NutPitch, grade)?;
        let td1 = table(Quantity::NutMinor, crest)?;
        ThreadLimits {
            pitch_diameter: Limits {
                min: d2 + ei,
                max: d2 + ei + td2,
            },
            crest: Limits {
                min: d1 + ei,
                max: d1 + ei + td1,
            },
            // The nut's root: at least the major; its rounding free.
            root: Limits {
                min: d + ei,
                max: d + ei + h / 8.0,
            },
            source,
        }
    } else {
        let es = deviation;
        let td2 = table(Quantity::BoltPitch, grade)?;
        let td = table(Quantity::BoltMajor, crest)?;
        let d3 = d1 - h / 6.0;
        ThreadLimits {
            pitch_diameter: Limits {
                min: d2 + es - td2,
                max: d2 + es,
            },
            crest: Limits {
                min: d + es - td,
                max: d + es,
            },
            // The bolt's root below the nut's crest by its rounding:
            // at most d3 shifted by the deviation, at least a pitch
            // diameter's tolerance below it.
            root: Limits {
                min: d3 + es - td2,
                max: d3 + es,
            },
            source,
        }
    })
}

/// ISO 261's coarse pitch of the diameters it names (0 for others): the
/// designation leaves a coarse pitch out.
pub(crate) fn coarse_pitch(d: Real) -> Real {
    const COARSE: [(Real, Real); 16] = [
        (3.0, 0.5),
        (4.0, 0.7),
        (5.0, 0.8),
        (6.0, 1.0),
        (8.0, 1.25),
        (10.0, 1.5),
        (12.0, 1.75),
        (16.0, 2.0),
        (20.0, 2.5),
        (24.0, 3.0),
        (30.0, 3.5),
        (36.0, 4.0),
        (42.0, 4.5),
        (48.0, 5.0),
        (56.0, 5.5),
        (64.0, 6.0),
    ];
    COARSE
        .iter()
        .find(|(n, _)| (n - d).abs() < crate::tolerance::SAME_LENGTH)
        .map_or(0.0, |c| c.1)
}

/// A size as a designation writes it: no trailing zeros.
/// A designation's size after the `x`: the pitch, or for more starts the
/// lead with the pitch, as ISO writes it (`14(P7)`).
fn lead_and_pitch(pitch: Real, starts: u32) -> String {
    if starts == 1 {
        number(pitch)
    } else {
        format!("{}(P{})", number(Real::from(starts) * pitch), number(pitch))
    }
}

/// `-LH` for a left hand (ISO's and ASME's suffix), nothing for a right.
fn hand_suffix(hand: Hand) -> &'static str {
    match hand {
        Hand::Left => "-LH",
        Hand::Right => "",
    }
}

/// An inch thread's size after its diameter: threads per inch, or for
/// more starts ASME's pitch and lead in inches (`0.2P-0.4L`).
fn inch_lead(tpi: Real, starts: u32) -> String {
    if starts == 1 {
        number(tpi)
    } else {
        format!(
            "{}P-{}L",
            number(1.0 / tpi),
            number(Real::from(starts) / tpi)
        )
    }
}

pub(crate) fn number(v: Real) -> String {
    let s = format!("{v:.4}");
    s.trim_end_matches('0').trim_end_matches('.').to_owned()
}

/// Limits a standard leaves to the drawing, stated: the pitch diameter's
/// band below the basic (external) or above it (internal), the crest's and
/// the root's bands.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StatedLimits {
    /// The pitch diameter's deviation from the basic, towards the
    /// clearance (mm, at least 0).
    pub pitch_allowance: Real,
    /// The pitch diameter's tolerance (mm).
    pub pitch_tolerance: Real,
    /// The crest's tolerance (mm).
    pub crest_tolerance: Real,
    /// The root's tolerance (mm).
    pub root_tolerance: Real,
}

impl StatedLimits {
    /// The limits about basic pitch, crest and root diameters.
    pub(super) fn limits(
        &self,
        internal: bool,
        pitch: Real,
        crest: Real,
        root: Real,
    ) -> ThreadLimits {
        let s = if internal { 1.0 } else { -1.0 };
        let band = |basic: Real, tol: Real| {
            let near = basic + s * self.pitch_allowance;
            let far = near + s * tol;
            Limits {
                min: near.min(far),
                max: near.max(far),
            }
        };
        ThreadLimits {
            pitch_diameter: band(pitch, self.pitch_tolerance),
            crest: band(crest, self.crest_tolerance),
            root: band(root, self.root_tolerance),
            source: "stated".into(),
        }
    }
}

/// ISO 2904's crest clearance `ac` by pitch.
fn trapezoidal_clearance(pitch: Real) -> Real {
    match pitch {
        p if p <= 1.5 => 0.15,
        p if p <= 5.0 => 0.25,
        p if p <= 12.0 => 0.5,
        _ => 1.0,
    }
}

/// A trapezoidal thread `Tr d x P` (ISO 2904), its limits `stated`.
///
/// # Failures
/// A size that is not positive; a pitch outside ISO 2904's 1.5 to 44 mm; a
/// diameter that leaves no core.
pub fn trapezoidal(
    d: Real,
    pitch: Real,
    internal: bool,
    starts: u32,
    hand: Hand,
    stated: StatedLimits,
) -> Result<ThreadProfile, InputError> {
    positive("major diameter d", d)?;
    positive("pitch P", pitch)?;
    if !(1.5..=44.0).contains(&pitch) {
        return Err(InputError::out_of_range(
            "pitch P",
            pitch,
            "1.5 to 44 mm (ISO 2904)",
        ));
    }
    let ac = trapezoidal_clearance(pitch);
    let h3 = 0.5 * pitch + ac;
    if d <= 2.0 * h3 {
        return Err(InputError::out_of_range(
            "major diameter d",
            d,
            format!("above 2 h3 = {} (a core)", 2.0 * h3),
        ));
    }
    let d2 = d - 0.5 * pitch;
    let (root, crest) = if internal {
        (d + 2.0 * ac, d - pitch)
    } else {
        (d - 2.0 * h3, d)
    };
    Ok(ThreadProfile {
        designation: format!(
            "Tr{}x{}{}",
            number(d),
            lead_and_pitch(pitch, starts),
            hand_suffix(hand)
        ),
        standard: "ISO 2904".into(),
        section: ThreadSection {
            internal,
            pitch,
            starts,
            hand,
            major: d,
            pitch_diameter: d2,
            root_diameter: root,
            crest_diameter: crest,
            flanks: [15.0_f64.to_radians(); 2],
            space_at_pitch: pitch / 2.0,
            root_radius: 0.0,
            form: FlankForm::Axial,
        },
        limits: stated.limits(internal, d2, crest, root),
    })
}

/// A general-purpose ACME thread (ASME B1.5) of `d_in` inches and `tpi`
/// threads per inch, class 2G (`grade` 2), in mm.
///
/// # Failures
/// A size that is not positive; a class other than 2.
pub fn acme(
    d_in: Real,
    tpi: Real,
    internal: bool,
    grade: u32,
    starts: u32,
    hand: Hand,
) -> Result<ThreadProfile, InputError> {
    positive("major diameter D (in)", d_in)?;
    positive("threads per inch", tpi)?;
    // B1.5's class 2G; the finer classes' factors are not checked here.
    let (allowance, scale) = match grade {
        2 => (0.008, 1.0),
        _ => {
            return Err(InputError::out_of_range(
                "ACME class",
                Real::from(grade),
                "2 (2G; 3G and 4G are not offered yet)",
            ))
        }
    };
    // B1.5 rounds each term to 4 decimals of the inch before adding them
    // (its tables: 3/4-6's minimum pitch diameter 0.6667 - 0.0069 -
    // 0.0174 = 0.6424, not 0.6423).
    let r4 = |v: Real| (v * 1e4).round() / 1e4;
    let p = 1.0 / tpi;
    let e = r4(d_in - 0.5 * p);
    let es = r4(allowance * d_in.sqrt());
    let exact_td2 = scale * (0.030 * p.sqrt() + 0.006 * d_in.sqrt());
    let td2 = r4(exact_td2);
    let (td1, tmajor) = (r4(1.5 * exact_td2), r4(0.05 * p));
    let minor_clearance = if tpi <= 10.0 { 0.020 } else { 0.010 };
    let (pitch_l, crest, root, root_basic, crest_basic) = if internal {
        let minor = r4(d_in - p);
        let major = r4(d_in + minor_clearance);
        (
            (e, e + td2),
            (minor, minor + tmajor),
            (major, major + td1),
            major,
            minor,
        )
    } else {
        let minor = r4(d_in - (p + minor_clearance));
        (
            (e - es - td2, e - es),
            (d_in - tmajor, d_in),
            (minor - td1, minor),
            minor,
            d_in,
        )
    };
    let mm = |(a, b): (Real, Real)| Limits {
        min: a * INCH,
        max: b * INCH,
    };
    Ok(ThreadProfile {
        designation: format!(
            "{}-{} ACME-{grade}G{}",
            number(d_in),
            inch_lead(tpi, starts),
            hand_suffix(hand)
        ),
        standard: "ASME B1.5".into(),
        section: ThreadSection {
            internal,
            pitch: p * INCH,
            starts,
            hand,
            major: d_in * INCH,
            pitch_diameter: e * INCH,
            root_diameter: root_basic * INCH,
            crest_diameter: crest_basic * INCH,
            flanks: [14.5_f64.to_radians(); 2],
            space_at_pitch: p * INCH / 2.0,
            root_radius: 0.0,
            form: FlankForm::Axial,
        },
        limits: ThreadLimits {
            pitch_diameter: mm(pitch_l),
            crest: mm(crest),
            root: mm(root),
            source: format!("ASME B1.5 {grade}G"),
        },
    })
}

/// Which side a buttress thread's load flank faces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoadFlank {
    /// The load is taken towards -Z (the chuck): the space's flank towards
    /// +Z is the thread's load flank.
    TowardsChuck,
    /// The load is taken towards +Z.
    AwayFromChuck,
}

/// A 7/45 buttress thread (ASME B1.9) of `d_in` inches and `tpi` threads
/// per inch, in mm, its limits `stated` (mm).
///
/// # Failures
/// A size that is not positive, or that leaves no core.
pub fn buttress(
    d_in: Real,
    tpi: Real,
    internal: bool,
    load: LoadFlank,
    starts: u32,
    hand: Hand,
    stated: StatedLimits,
) -> Result<ThreadProfile, InputError> {
    positive("major diameter D (in)", d_in)?;
    positive("threads per inch", tpi)?;
    let p = 1.0 / tpi * INCH;
    let d = d_in * INCH;
    let depth = 0.66271 * p;
    if d <= 2.0 * depth {
        return Err(InputError::out_of_range(
            "major diameter D (in)",
            d_in,
            "larger than twice the thread's depth",
        ));
    }
    let e = d - 0.6 * p;
    let (root, crest) = if internal {
        (d + 2.0 * (depth - 0.6 * p), d - 1.2 * p)
    } else {
        (d - 2.0 * depth, d)
    };
    let (seven, fortyfive) = (7.0_f64.to_radians(), 45.0_f64.to_radians());
    let flanks = match load {
        LoadFlank::TowardsChuck => [fortyfive, seven],
        LoadFlank::AwayFromChuck => [seven, fortyfive],
    };
    Ok(ThreadProfile {
        designation: format!(
            "{}-{} BUTT 7/45{}",
            number(d_in),
            inch_lead(tpi, starts),
            hand_suffix(hand)
        ),
        standard: "ASME B1.9".into(),
        section: ThreadSection {
            internal,
            pitch: p,
            starts,
            hand,
            major: d,
            pitch_diameter: e,
            root_diameter: root,
            crest_diameter: crest,
            flanks,
            space_at_pitch: p / 2.0,
            root_radius: 0.07141 * p,
            form: FlankForm::Axial,
        },
        limits: stated.limits(internal, e, crest, root),
    })
}

/// ISO 228-1's sizes: the size as the designation writes it, threads per
/// inch, the major diameter (mm).
const PIPE_SIZES: [(&str, Real, Real); 24] = [
    ("1/16", 28.0, 7.723),
    ("1/8", 28.0, 9.728),
    ("1/4", 19.0, 13.157),
    ("3/8", 19.0, 16.662),
    ("1/2", 14.0, 20.955),
    ("5/8", 14.0, 22.911),
    ("3/4", 14.0, 26.441),
    ("7/8", 14.0, 30.201),
    ("1", 11.0, 33.249),
    ("1 1/8", 11.0, 37.897),
    ("1 1/4", 11.0, 41.910),
    ("1 1/2", 11.0, 47.803),
    ("1 3/4", 11.0, 53.746),
    ("2", 11.0, 59.614),
    ("2 1/4", 11.0, 65.710),
    ("2 1/2", 11.0, 75.184),
    ("2 3/4", 11.0, 81.534),
    ("3", 11.0, 87.884),
    ("3 1/2", 11.0, 100.330),
    ("4", 11.0, 113.030),
    ("4 1/2", 11.0, 125.730),
    ("5", 11.0, 138.430),
    ("5 1/2", 11.0, 151.130),
    ("6", 11.0, 163.830),
];

/// A straight pipe thread `G<size>` (ISO 228-1), external of class `A`
/// or `B`, or internal (`class` `None`); the sizes as the designation
/// writes them (`1/2`, `1 1/2`).
///
/// # Failures
/// A size ISO 228-1 does not name; a class other than A or B on an
/// external thread, or one on an internal thread.
pub fn pipe(
    size: &str,
    internal: bool,
    class: Option<char>,
    starts: u32,
    hand: Hand,
) -> Result<ThreadProfile, InputError> {
    let Some(&(name, tpi, d)) = PIPE_SIZES.iter().find(|(n, _, _)| *n == size) else {
        return Err(InputError::BadText {
            what: "pipe thread size".into(),
            value: format!("'{}'", crate::files::excerpt(size)),
            reason: format!(
                "not a size of ISO 228-1 ({})",
                PIPE_SIZES.map(|s| s.0).join(", ")
            ),
        });
    };
    let class = pipe_class(internal, class)?;
    let p = INCH / tpi;
    let (h, r) = (0.640327 * p, 0.137329 * p);
    let (d2, d1) = (d - h, d - 2.0 * h);
    let limits = pipe_limits(internal, class, tpi, (d, d1, d2), p);
    let starts_text = if starts == 1 {
        String::new()
    } else {
        format!(" ({starts} starts)")
    };
    Ok(ThreadProfile {
        designation: format!(
            "G{name}{}{starts_text}{}",
            class.map_or(String::new(), String::from),
            hand_suffix(hand)
        ),
        standard: "ISO 228-1".into(),
        section: ThreadSection {
            internal,
            pitch: p,
            starts,
            hand,
            major: d,
            pitch_diameter: d2,
            root_diameter: if internal { d } else { d1 },
            crest_diameter: if internal { d1 } else { d },
            flanks: [27.5_f64.to_radians(); 2],
            space_at_pitch: p / 2.0,
            root_radius: r,
            form: FlankForm::Axial,
        },
        limits,
    })
}

/// ISO 228-1's class of a pipe thread: A or B on an external thread,
/// none on an internal one.
///
/// # Failures
/// Any other.
fn pipe_class(internal: bool, class: Option<char>) -> Result<Option<char>, InputError> {
    Ok(match (internal, class) {
        (false, Some(c @ ('A' | 'B'))) => Some(c),
        (true, None) => None,
        (false, c) => {
            return Err(InputError::out_of_range(
                format!(
                    "ISO 228-1 class '{}'",
                    c.map_or(String::new(), String::from)
                ),
                0.0,
                "A or B on an external thread",
            ))
        }
        (true, Some(c)) => {
            return Err(InputError::out_of_range(
                format!("ISO 228-1 class '{c}'"),
                0.0,
                "none on an internal thread (its pitch diameter has one tolerance)",
            ))
        }
    })
}

/// ISO 228-1's limits of a pipe thread of `tpi` threads per inch (pitch
/// `p`) and major, minor and pitch diameters `d`, `d1`, `d2`.
fn pipe_limits(
    internal: bool,
    class: Option<char>,
    tpi: Real,
    (d, d1, d2): (Real, Real, Real),
    p: Real,
) -> ThreadLimits {
    // ISO 228-1's tolerances (mm) by threads per inch: TD2, and the
    // internal minor's.
    let (td2, td1) = match tpi as u32 {
        28 => (0.107, 0.282),
        19 => (0.125, 0.445),
        14 => (0.142, 0.541),
        _ if d <= 60.0 => (0.180, 0.640),
        _ => (0.217, 0.640),
    };
    let big_h = 0.960491 * p;
    if internal {
        ThreadLimits {
            pitch_diameter: Limits {
                min: d2,
                max: d2 + td2,
            },
            crest: Limits {
                min: d1,
                max: d1 + td1,
            },
            // The nut's root: at least the major; its rounding free to
            // the fundamental triangle's truncation.
            root: Limits {
                min: d,
                max: d + big_h / 6.0,
            },
            source: "ISO 228-1".into(),
        }
    } else {
        let band = if class == Some('A') { td2 } else { 2.0 * td2 };
        ThreadLimits {
            pitch_diameter: Limits {
                min: d2 - band,
                max: d2,
            },
            crest: Limits {
                min: d - 2.0 * td2,
                max: d,
            },
            // The root (the rounded minor) at most the basic minor, at
            // least a pitch diameter's band below it.
            root: Limits {
                min: d1 - band,
                max: d1,
            },
            source: format!("ISO 228-1 class {}", class.unwrap_or('A')),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// ISO 228-1's printed G 1/2 (14 threads per inch, mm to 3 decimals):
    /// d 20.955, d2 19.793, d1 18.631; external class A's pitch diameter
    /// 19.651 to 19.793, class B's from 19.509, the major 20.671 to
    /// 20.955; internal, the pitch diameter 19.793 to 19.935, the minor
    /// 18.631 to 19.172. G 1 (11 tpi): d2 31.770, class A from 31.590. The
    /// profile at 27.5 degrees, its spaces half the pitch at d2. The
    /// standard subtracts its depth rounded (1.162) twice for d1, 0.5 um
    /// from the exact depth's: d1 within 1 um.
    #[test]
    fn pipe_sizes_are_the_standards_printed_ones() {
        let a = pipe("1/2", false, Some('A'), 1, Hand::Right).unwrap();
        assert_eq!(a.designation, "G1/2A");
        near(a.section.pitch, 1.814, 3);
        near(a.section.pitch_diameter, 19.793, 3);
        assert!((a.section.root_diameter - 18.631).abs() < 1e-3);
        near(a.limits.pitch_diameter.min, 19.651, 3);
        near(a.limits.crest.min, 20.671, 3);
        near(a.limits.crest.max, 20.955, 3);
        let b = pipe("1/2", false, Some('B'), 1, Hand::Right).unwrap();
        near(b.limits.pitch_diameter.min, 19.509, 3);
        let nut = pipe("1/2", true, None, 1, Hand::Left).unwrap();
        assert_eq!(nut.designation, "G1/2-LH");
        near(nut.limits.pitch_diameter.max, 19.935, 3);
        assert!((nut.limits.crest.min - 18.631).abs() < 1e-3);
        assert!((nut.limits.crest.max - 19.172).abs() < 1e-3);
        let one = pipe("1", false, Some('A'), 1, Hand::Right).unwrap();
        near(one.section.pitch_diameter, 31.770, 3);
        near(one.limits.pitch_diameter.min, 31.590, 3);
        assert!((a.section.flanks[0].to_degrees() - 27.5).abs() < 1e-12);
        near(a.section.space_at(19.793 / 2.0), 1.814 / 2.0, 3);
        assert!(pipe("9/16", false, Some('A'), 1, Hand::Right).is_err());
        assert!(pipe("1/2", false, None, 1, Hand::Right).is_err());
        assert!(pipe("1/2", true, Some('A'), 1, Hand::Right).is_err());
    }

    /// Within half a unit of the last decimal the standard prints.
    fn near(got: Real, want: Real, decimals: i32) {
        let tol = 0.5 * 10.0_f64.powi(-decimals) + 1e-12;
        assert!(
            (got - want).abs() <= tol,
            "{got} vs {want} (to {decimals} decimals)"
        );
    }

    /// 2-8 7/45 buttress, its load flank as asked.
    fn butt_2_8(load: LoadFlank) -> ThreadProfile {
        buttress(2.0, 8.0, false, load, 1, Hand::Right, STATED).unwrap()
    }

    const STATED: StatedLimits = StatedLimits {
        pitch_allowance: 0.0,
        pitch_tolerance: 0.1,
        crest_tolerance: 0.2,
        root_tolerance: 0.3,
    };

    /// ISO 724's and ISO 965-2's printed sizes (mm, to 3 decimals): M20
    /// (coarse, 2.5) 6g and M30x2 6H.
    #[test]
    fn metric_sizes_are_the_standards_printed_ones() {
        let m20 = metric(20.0, 2.5, false, "6g", 1, Hand::Right).unwrap();
        assert_eq!(m20.designation, "M20-6g");
        near(m20.section.pitch_diameter, 18.376, 3);
        near(m20.section.root_diameter, 16.933, 3);
        let l = &m20.limits;
        near(l.crest.max, 19.958, 3);
        near(l.crest.min, 19.623, 3);
        near(l.pitch_diameter.max, 18.334, 3);
        near(l.pitch_diameter.min, 18.164, 3);
        let m30 = metric(30.0, 2.0, true, "6H", 1, Hand::Right).unwrap();
        assert_eq!(m30.designation, "M30x2-6H");
        near(m30.section.crest_diameter, 27.835, 3);
        let l = &m30.limits;
        near(l.pitch_diameter.min, 28.701, 3);
        near(l.pitch_diameter.max, 28.925, 3);
        near(l.crest.min, 27.835, 3);
        near(l.crest.max, 28.210, 3);
        near(l.root.min, 30.0, 3);
        // The basic profile's geometry: the external crest's flat P/8 and
        // the internal crest's P/4 (ISO 68-1) where the spaces meet them.
        near(m20.section.space_at(10.0), 2.5 * 7.0 / 8.0, 9);
        near(m20.section.space_at(17.294 / 2.0), 2.5 / 4.0, 3);
        near(m30.section.space_at(15.0), 2.0 / 8.0, 9);
        for (d, p, class) in [
            (20.0, 3.3, "6g"),
            (200.0, 2.0, "6g"),
            (20.0, 2.5, "6x"),
            (20.0, 2.5, "9g"),
        ] {
            assert!(
                metric(d, p, false, class, 1, Hand::Right).is_err(),
                "{d} {p} {class}"
            );
        }
    }

    /// ISO 2904's Tr 40x7: d2 36.5, d3 32, D1 33, D4 41; the crest's flat
    /// 0.366 P.
    #[test]
    fn trapezoidal_sizes_are_the_standards_printed_ones() {
        let bolt = trapezoidal(40.0, 7.0, false, 1, Hand::Right, STATED).unwrap();
        let nut = trapezoidal(40.0, 7.0, true, 1, Hand::Right, STATED).unwrap();
        assert_eq!(bolt.designation, "Tr40x7");
        near(bolt.section.pitch_diameter, 36.5, 3);
        near(bolt.section.root_diameter, 32.0, 3);
        near(nut.section.crest_diameter, 33.0, 3);
        near(nut.section.root_diameter, 41.0, 3);
        near(7.0 - bolt.section.space_at(20.0), 0.366 * 7.0, 3);
        // Stated limits lie below the basic on a bolt, above it in a nut.
        assert!(bolt.limits.pitch_diameter.max <= 36.5 && nut.limits.pitch_diameter.min >= 36.5);
        assert_eq!(bolt.limits.source, "stated");
        assert!(trapezoidal(40.0, 50.0, false, 1, Hand::Right, STATED).is_err());
    }

    /// ASME B1.5's printed class 2G limits (inch, to 4 decimals) of 1-5 and
    /// 3/4-6 ACME, and its basic crest flat 0.3707 P.
    #[test]
    fn acme_2g_sizes_are_the_standards_printed_ones() {
        for (d, tpi, major, pitch, minor) in [
            (1.0, 5.0, (0.99, 1.0), (0.8726, 0.892), (0.7509, 0.78)),
            (
                0.75,
                6.0,
                (0.7417, 0.75),
                (0.6424, 0.6598),
                (0.5371, 0.5633),
            ),
        ] {
            let t = acme(d, tpi, false, 2, 1, Hand::Right).unwrap();
            let l = &t.limits;
            for (got, want) in [
                (l.crest.min, major.0),
                (l.crest.max, major.1),
                (l.pitch_diameter.min, pitch.0),
                (l.pitch_diameter.max, pitch.1),
                (l.root.min, minor.0),
                (l.root.max, minor.1),
            ] {
                near(got / INCH, want, 4);
            }
            let p = 1.0 / tpi;
            near(
                (p - t.section.space_at(d * INCH / 2.0) / INCH) / p,
                0.3707,
                4,
            );
        }
        assert_eq!(
            acme(1.0, 5.0, false, 2, 1, Hand::Right)
                .unwrap()
                .designation,
            "1-5 ACME-2G"
        );
        assert!(acme(1.0, 5.0, false, 3, 1, Hand::Right).is_err());
    }

    /// ASME B1.9's 7/45 form: the sharp V's height from its flanks is
    /// 0.89064 P, the basic engagement 0.6 P, the bolt's depth 0.66271 P;
    /// the load flank faces the side asked.
    #[test]
    fn buttress_7_45_has_the_standards_form() {
        let t = butt_2_8(LoadFlank::TowardsChuck);
        let p = INCH / 8.0;
        let v = p / (t.section.flanks[0].tan() + t.section.flanks[1].tan());
        near(v / p, 0.89064, 5);
        near(t.section.depth() / p, 0.66271, 5);
        near(
            (t.section.major - t.section.pitch_diameter) / 2.0 / p,
            0.3,
            9,
        );
        assert!(t.section.flanks[1] < t.section.flanks[0]);
        let other = butt_2_8(LoadFlank::AwayFromChuck);
        assert!(other.section.flanks[0] < other.section.flanks[1]);
    }

    /// The measurement over wires against the wire placed by geometry in
    /// the axial section (a circle whose centre, on the space's middle,
    /// stands half the wire from each flank line of the outline) and the
    /// lead angle's share: over the best wires ASME B1.2's `w/2
    /// tan^2(lambda) cos(a) cot(a)` within 0.05 um; between balls a nut's measurement a little
    /// smaller (a helical space is narrower across the helix). M20x2.5's
    /// best wire 1.443 mm gives the handbook's M = d2 + 3 w - 0.866025 P
    /// plus that correction.
    #[test]
    fn over_wires_is_where_the_wire_touches_both_flanks() {
        for t in [
            metric(20.0, 2.5, false, "6g", 1, Hand::Right).unwrap(),
            metric(30.0, 2.0, true, "6H", 1, Hand::Right).unwrap(),
            trapezoidal(40.0, 7.0, false, 1, Hand::Right, STATED).unwrap(),
            acme(1.0, 5.0, false, 2, 1, Hand::Right).unwrap(),
        ] {
            for w in [
                t.section.best_wire().unwrap(),
                1.1 * t.section.best_wire().unwrap(),
            ] {
                let m = t.section.over_wires(w, t.section.pitch_diameter).unwrap();
                // The flank towards +Z, root corner to crest corner.
                let o = t.section.space_outline(0.0);
                let (a, b) = (o[1], o[2]);
                let dist = |r: Real| {
                    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
                    ((0.0 - a[0]) * dy - (r - a[1]) * dx).abs() / dx.hypot(dy)
                };
                // The centre's radius by bisection between the root and far
                // past the crest, where the distance grows.
                let (mut lo, mut hi) = (
                    t.section.root_diameter / 2.0,
                    t.section.root_diameter / 2.0 + t.section.opening() * 5.0 * t.section.pitch,
                );
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if dist(mid) < w / 2.0 {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let centre = 0.5 * (lo + hi);
                let axial = 2.0 * centre + t.section.opening() * w;
                if t.section.internal {
                    assert!(m < axial && axial - m < 3e-3, "{m} {axial}");
                } else {
                    let (half, d2) = (t.section.flanks[0], t.section.pitch_diameter);
                    let lambda = (t.section.lead() / (PI * d2)).atan();
                    let correction = w / 2.0 * lambda.tan().powi(2) * half.cos() / half.tan();
                    // The formula is the best wire's: one a tenth larger
                    // rests up to a tenth of the correction off it (1.2 um
                    // higher on a Tr40x7, 1.6 on a two-start ACME 1-5).
                    let off = if w == t.section.best_wire().unwrap() {
                        0.05e-3
                    } else {
                        0.1 * correction
                    };
                    assert!(
                        (m - axial - correction).abs() < off,
                        "{w} {m} {axial} {correction}"
                    );
                }
            }
        }
        let m20 = metric(20.0, 2.5, false, "6g", 1, Hand::Right).unwrap();
        let w = m20.section.best_wire().unwrap();
        near(w, 1.443, 3);
        let lambda = (2.5 / (PI * 18.376)).atan();
        // cos(30) cot(30) = 1.5.
        let correction = w / 2.0 * lambda.tan().powi(2) * 1.5;
        let m = m20.section.over_wires(w, 18.376).unwrap();
        let handbook = 18.376 + 3.0 * w - 0.866025 * 2.5;
        assert!(
            (m - handbook - correction).abs() < 0.05e-3,
            "{m} {handbook} {correction}"
        );
        // A buttress's wire rests on its 7 and 45 degree flanks too, its
        // contacts straddling the pitch line.
        let b = butt_2_8(LoadFlank::TowardsChuck);
        let w = b.section.best_wire().unwrap();
        assert!((w / b.section.pitch - 0.5112).abs() < 1e-4, "{w}");
        assert!(b.section.over_wires(w, b.section.pitch_diameter).is_some());
    }
}
