//! A thread named as a drawing names it: `M20x2.5-6g`, `M30x2-6H`,
//! `M20x5(P2.5)-6g-LH`, `Tr40x7`, `Tr40x14(P7)`, `1-5 ACME-2G`,
//! `3/4-6 ACME-2G`, `2-8 BUTT 7/45`, read into a [`ThreadProfile`] by the
//! standards' formulas ([`super::standards`]).
//!
//! The grammar, each part separated by `-` or a space:
//! - ISO metric: `M<d>[x<lead>[(P<pitch>)]][-<class>]`; the pitch left out
//!   is ISO 261's coarse one; the class (`6g`, `6H`, ...) says external
//!   (lower case) or internal (upper case); none: 6g or 6H.
//! - trapezoidal: `Tr<d>x<lead>[(P<pitch>)]`, its limits stated (ISO
//!   2903's classes are not offered).
//! - ACME: `<D>-<tpi> ACME-<n>G`, `D` in inches, decimal or a fraction;
//!   more starts as ASME writes them, `<D>-<pitch>P-<lead>L ACME-<n>G`.
//! - buttress: `<D>-<tpi> BUTT [7/45]`, ASME B1.9's form, limits stated.
//! - straight pipe (ISO 228-1): `G<size>` internal, `G<size>A` or
//!   `G<size>B` external, the size as the standard writes it (`1/2`,
//!   `1 1/2`).
//! - a cylindrical worm (DIN 3975): `Z<A|N|I> m<module> z<starts>
//!   d<pitch diameter> [a<angle>]`, as `ZI m5 z2 d50`: the worm job's
//!   sizes (c* 0.2, the thickness half the axial pitch), the angle (20
//!   degrees unless given) a ZA worm's in the axial section, a ZN or ZI
//!   worm's normal one; external, its limits stated. pilgrim's own
//!   shorthand: DIN 3975 names the quantities, not a one-line form.
//! - a trailing `LH` makes it left-handed (`RH`, the default, may be
//!   written), in either case.
//! - the metric and trapezoidal prefixes in any case, with a space after
//!   them (ISO 2904's `Tr 40x7`) and spaces round the `x` (`M20 x 2.5`);
//!   a metric class in two parts, the pitch diameter's and the crest's
//!   (`M20x2.5-5g6g`).
//!
//! What a designation leaves to the drawing (internal or external where
//! its class does not say, the stated limits, the buttress's load flank)
//! comes in [`Drawing`].
//!
//! Hand-written: a few fixed forms with no crate that reads them.

use super::profile::{Hand, ThreadProfile};
use super::standards::{self, LoadFlank, StatedLimits};
use crate::input::InputError;
use crate::math::Real;

/// What a designation leaves to the drawing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drawing {
    /// Internal (a nut's) or external; `None`: as the designation says (a
    /// metric class's letter), else external.
    pub internal: Option<bool>,
    /// The limits of the threads whose standard leaves them to the
    /// drawing (trapezoidal, buttress).
    pub stated: StatedLimits,
    /// Which way a buttress's load flank faces.
    pub load: LoadFlank,
}

/// The longest designation read.
const MAX_LEN: usize = 64;

/// The thread `text` names, with what `drawing` adds.
///
/// # Failures
/// Text that is none of the forms above, naming what was expected; a size
/// the standard refuses ([`super::standards`]); a lead that is not a whole
/// number of pitches; an internal thread asked of an external class (or
/// the reverse).
pub fn designated(text: &str, drawing: &Drawing) -> Result<ThreadProfile, InputError> {
    let r = Reader { text, drawing };
    if text.len() > MAX_LEN || text.chars().any(|c| c.is_control()) {
        return Err(r.bad(&format!(
            "not a designation (at most {MAX_LEN} printable characters)"
        )));
    }
    let spelled = spelled(text);
    let mut words: Vec<&str> = spelled
        .split([' ', '-'])
        .filter(|w| !w.is_empty())
        .collect();
    let hand = match words.last() {
        Some(w) if w.eq_ignore_ascii_case("LH") => {
            words.pop();
            Hand::Left
        }
        Some(w) if w.eq_ignore_ascii_case("RH") => {
            words.pop();
            Hand::Right
        }
        _ => Hand::Right,
    };
    let internal = drawing.internal.unwrap_or(false);
    match words.as_slice() {
        [m, rest @ ..] if m.starts_with('M') && rest.len() <= 1 => r.metric(&m[1..], rest, hand),
        [t] if t.starts_with("Tr") => {
            let (d, lp) = t[2..]
                .split_once('x')
                .ok_or_else(|| r.bad("a trapezoidal thread is Tr<d>x<pitch>, as Tr40x7"))?;
            let (pitch, starts) = r.lead_pitch(lp)?;
            let d = r.num(d, "diameter")?;
            standards::trapezoidal(d, pitch, internal, starts, hand, drawing.stated)
        }
        [d, size @ .., acme, class] if *acme == "ACME" && (1..=2).contains(&size.len()) => {
            r.acme(d, size, class, hand)
        }
        [d, tpi, butt, form @ ..] if *butt == "BUTT" && (form.is_empty() || form == ["7/45"]) => {
            standards::buttress(
                r.num(d, "diameter")?,
                r.num(tpi, "threads per inch")?,
                internal,
                drawing.load,
                1,
                hand,
                drawing.stated,
            )
        }
        [kind, sizes @ ..] if kind.len() == 2 && kind.starts_with('Z') => r.worm(kind, sizes, hand),
        [g, ..] if g.starts_with('G') => r.pipe(&words.join(" ")[1..], hand),
        _ => Err(r.bad(
            "not a form pilgrim reads: M20x2.5-6g, M30x2-6H, Tr40x7, Tr40x14(P7), 1-5 ACME-2G, 1-0.2P-0.4L ACME-2G, 2-8 BUTT 7/45, G1/2A, G1 1/2, ZI m5 z2 d50 (LH at the end for a left hand)",
        )),
    }
    .map_err(|e| match e {
        InputError::BadText { ref what, .. } if what == "thread designation" => e,
        other => r.bad(&other.to_string()),
    })
}

/// A metric or trapezoidal designation as the standards print it, from
/// the ways drawings write it: the prefix in any case (`m20`, `TR40`), a
/// space after it (ISO 2904's own `Tr 40x7`), spaces round the `x` and an
/// `X` for it (`M20 x 2.5`, `Tr40X7`). Other forms are left as written.
fn spelled(text: &str) -> String {
    let t = text.trim();
    let lower = t.to_ascii_lowercase();
    let (prefix, rest) = if lower.starts_with("tr") {
        ("Tr", &t[2..])
    } else if lower.starts_with('m') {
        ("M", &t[1..])
    } else {
        return t.to_owned();
    };
    let rest = rest.trim_start();
    if !rest.starts_with(|c: char| c.is_ascii_digit()) {
        return t.to_owned();
    }
    let chars: Vec<char> = rest.chars().collect();
    let mut out = String::from(prefix);
    for (i, &c) in chars.iter().enumerate() {
        let prev = out.chars().last();
        let next = chars[i + 1..].iter().find(|c| **c != ' ').copied();
        match c {
            ' ' if prev == Some('x') || matches!(next, Some('x' | 'X')) => {}
            'X' if prev.is_some_and(|p| p.is_ascii_digit()) => out.push('x'),
            _ => out.push(c),
        }
    }
    out
}

/// A designation being read: its text and the drawing's other notes.
struct Reader<'a> {
    text: &'a str,
    drawing: &'a Drawing,
}

impl Reader<'_> {
    /// The designation refused: `why`.
    fn bad(&self, why: &str) -> InputError {
        InputError::BadText {
            what: "thread designation".into(),
            value: format!("'{}':", crate::files::excerpt(self.text)),
            reason: why.into(),
        }
    }

    /// The positive number `s` (a fraction `a/b` too), the designation's
    /// `what`.
    fn num(&self, s: &str, what: &str) -> Result<Real, InputError> {
        let v = match s.split_once('/') {
            Some((a, b)) => (a.parse::<Real>().ok())
                .zip(b.parse::<Real>().ok())
                .map(|(a, b)| a / b),
            None => s.parse::<Real>().ok(),
        };
        v.filter(|v| v.is_finite() && *v > 0.0)
            .ok_or_else(|| self.bad(&format!("{what} '{s}' is not a positive number")))
    }

    /// `<lead>[(P<pitch>)]`: the pitch and the number of starts.
    fn lead_pitch(&self, s: &str) -> Result<(Real, u32), InputError> {
        let (lead, pitch) = match s.split_once("(P") {
            Some((l, p)) => {
                let p = p
                    .strip_suffix(')')
                    .ok_or_else(|| self.bad("'(P' without its ')'"))?;
                (self.num(l, "lead")?, self.num(p, "pitch")?)
            }
            None => {
                let l = self.num(s, "pitch")?;
                (l, l)
            }
        };
        let starts = (lead / pitch).round();
        if (lead / pitch - starts).abs() > crate::tolerance::SAME_RATIO
            || !(1.0..=12.0).contains(&starts)
        {
            return Err(self.bad(&format!(
                "the lead {lead} is not 1 to 12 times the pitch {pitch}"
            )));
        }
        Ok((pitch, starts as u32))
    }

    /// Whether the thread is internal, as its class says (`asked`): the
    /// drawing must not say otherwise.
    fn external_unless(&self, asked: bool) -> Result<bool, InputError> {
        match self.drawing.internal {
            Some(i) if i != asked => Err(self.bad(&format!(
                "its class is an {} thread's, and the drawing says {}",
                if asked { "internal" } else { "external" },
                if i { "internal" } else { "external" }
            ))),
            _ => Ok(asked),
        }
    }

    /// ISO metric: `M<d>[x<lead>[(P<pitch>)]]` and its class, if any.
    fn metric(&self, size: &str, rest: &[&str], hand: Hand) -> Result<ThreadProfile, InputError> {
        let (d, pitch, starts) = match size.split_once('x') {
            Some((d, lp)) => {
                let (p, z) = self.lead_pitch(lp)?;
                (self.num(d, "diameter")?, p, z)
            }
            None => {
                let d = self.num(size, "diameter")?;
                let p = standards::coarse_pitch(d);
                if p == 0.0 {
                    return Err(self.bad(&format!(
                        "M{size} has no coarse pitch in ISO 261's table: give it, as M{size}x1.5"
                    )));
                }
                (d, p, 1)
            }
        };
        let internal = self.drawing.internal.unwrap_or(false);
        let (class, internal) = match rest {
            [c] => {
                let upper = c.chars().last().is_some_and(|l| l.is_ascii_uppercase());
                (*c, self.external_unless(upper)?)
            }
            _ => (if internal { "6H" } else { "6g" }, internal),
        };
        standards::metric(d, pitch, internal, class, starts, hand)
    }

    /// ACME: `<d>-<tpi> ACME-<n>G`, or ASME's multiple-start
    /// `<d>-<pitch>P-<lead>L ACME-<n>G` (inches).
    fn acme(
        &self,
        d: &str,
        size: &[&str],
        class: &str,
        hand: Hand,
    ) -> Result<ThreadProfile, InputError> {
        let grade = (class.strip_suffix('G'))
            .and_then(|g| g.parse::<u32>().ok())
            .ok_or_else(|| self.bad(&format!("ACME class '{class}' is not <n>G, as 2G")))?;
        let (tpi, starts) = match size {
            [tpi] => (self.num(tpi, "threads per inch")?, 1),
            [p, l] => {
                let inches = |w: &str, end: char, what: &str| {
                    w.strip_suffix(end)
                        .ok_or_else(|| {
                            self.bad(&format!("'{w}' is not the {what} as <inches>{end}"))
                        })
                        .and_then(|v| self.num(v, what))
                };
                let (pitch, lead) = (inches(p, 'P', "pitch")?, inches(l, 'L', "lead")?);
                let (_, starts) = self.lead_pitch(&format!("{lead}(P{pitch})"))?;
                (1.0 / pitch, starts)
            }
            _ => return Err(self.bad("an ACME size is <tpi> or <pitch>P-<lead>L")),
        };
        let internal = self.drawing.internal.unwrap_or(false);
        standards::acme(self.num(d, "diameter")?, tpi, internal, grade, starts, hand)
    }

    /// A cylindrical worm: `Z<A|N|I> m<module> z<starts> d<pitch diameter>
    /// [a<angle>]`.
    fn worm(&self, kind: &str, sizes: &[&str], hand: Hand) -> Result<ThreadProfile, InputError> {
        let profile = super::WormProfile::parse(kind).map_err(|e| self.bad(&e.to_string()))?;
        let form =
            "a worm is Z<A|N|I> m<module> z<starts> d<pitch diameter> [a<angle>], as ZI m5 z2 d50";
        let (mut m, mut z, mut d, mut a) = (None, None, None, 20.0);
        for w in sizes {
            let Some((k, v)) = w.char_indices().nth(1).map(|(i, _)| w.split_at(i)) else {
                return Err(self.bad(form));
            };
            match k {
                "m" => m = Some(self.num(v, "module")?),
                "z" => z = Some(self.num(v, "number of starts")?),
                "d" => d = Some(self.num(v, "pitch diameter")?),
                "a" => a = self.num(v, "profile angle")?,
                _ => return Err(self.bad(form)),
            }
        }
        let (Some(m), Some(z), Some(d)) = (m, z, d) else {
            return Err(self.bad(form));
        };
        if z.fract() != 0.0 || z > 12.0 {
            return Err(self.bad(&format!(
                "the number of starts z{z} is not a whole number from 1 to 12"
            )));
        }
        self.external_unless(false)?;
        let sizes =
            super::WormSizes::with_profile(m, z as i64, d, 0.2, a.to_radians(), None, profile)
                .map_err(|e| self.bad(&e.to_string()))?;
        Ok(sizes.drawn(hand, &self.drawing.stated))
    }

    /// ISO 228-1: `G<size>` internal, `G<size>A` or `B` external (`body`:
    /// what follows the `G`).
    fn pipe(&self, body: &str, hand: Hand) -> Result<ThreadProfile, InputError> {
        let body = body.trim();
        let (size, class) = match body.chars().last() {
            Some(c @ ('A' | 'B')) => (body[..body.len() - 1].trim(), Some(c)),
            _ => (body, None),
        };
        let internal = match class {
            Some(_) => self.external_unless(false)?,
            None => self.drawing.internal.unwrap_or(true),
        };
        standards::pipe(size, internal, class, 1, hand)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::families::thread::ThreadSection;

    const DRAWING: Drawing = Drawing {
        internal: None,
        stated: StatedLimits {
            pitch_allowance: 0.0,
            pitch_tolerance: 0.1,
            crest_tolerance: 0.2,
            root_tolerance: 0.3,
        },
        load: LoadFlank::TowardsChuck,
    };

    fn read(t: &str) -> ThreadProfile {
        designated(t, &DRAWING).unwrap_or_else(|e| panic!("{t}: {e}"))
    }

    /// Designations as drawings spell them read as the canonical ones;
    /// a two-part class takes the pitch diameter's limits from its first
    /// grade and the crest's from its second.
    #[test]
    fn designations_as_drawings_spell_them() {
        for (spelled, canonical) in [
            ("Tr 40x7", "Tr40x7"),
            ("tr40 x 7", "Tr40x7"),
            ("TR40X14(P7) lh", "Tr40x14(P7)-LH"),
            ("M20 x 2.5-6g", "M20x2.5-6g"),
            ("m20x2.5-6g", "M20x2.5-6g"),
            ("M 20 X 2.5 - 6H", "M20x2.5-6H"),
            ("M20x2.5-6g LH", "M20x2.5-6g-LH"),
        ] {
            assert_eq!(read(spelled), read(canonical), "{spelled}");
        }
        // A class in two parts: the pitch diameter's grade, the crest's.
        // ISO 965-1's Td2 in grade 5 for 11.2 to 22.4 mm at P 2.5 is 132 um;
        // grade 5 has no Td, so `5g` alone is no class.
        let (two, crest) = (read("M20x2.5-5g6g"), read("M20x2.5-6g"));
        let band = two.limits.pitch_diameter.max - two.limits.pitch_diameter.min;
        assert!((band - 0.132).abs() < 1e-12, "{band}");
        assert_eq!(
            two.limits.pitch_diameter.max,
            crest.limits.pitch_diameter.max
        );
        assert_eq!(two.limits.crest, crest.limits.crest);
        assert!(designated("M20x2.5-5g", &DRAWING).is_err());
        assert!(two.designation.contains("5g6g"), "{}", two.designation);
        let nut = read("M20x2.5-5H6H");
        assert_eq!(nut.limits.crest, read("M20x2.5-6H").limits.crest);
        assert_eq!(
            nut.limits.pitch_diameter,
            read("M20x2.5-5H").limits.pitch_diameter
        );
        let e = designated("M20x2.5-5g6h", &DRAWING)
            .unwrap_err()
            .to_string();
        assert!(e.contains("5g6h"), "{e}");
    }

    /// Each form reads into the standard's profile, as its own function
    /// makes it.
    #[test]
    fn designations_read_into_the_standards_profiles() {
        let s = DRAWING.stated;
        // A worm: the worm job's sizes, its kind's curves, the drawing's
        // stated limits about its basic diameters (external), its hand.
        let a = 20f64.to_radians();
        for (kind, profile) in [
            ("ZA", super::super::WormProfile::ZA),
            ("ZN", super::super::WormProfile::ZN),
            ("ZI", super::super::WormProfile::ZI),
        ] {
            let w =
                super::super::WormSizes::with_profile(5.0, 2, 50.0, 0.2, a, None, profile).unwrap();
            let t = read(&format!("{kind} m5 z2 d50-LH"));
            assert_eq!(t.designation, format!("{kind} m5 z2 d50-LH"));
            assert_eq!(
                t.section,
                ThreadSection {
                    hand: Hand::Left,
                    ..w.section()
                }
            );
            assert_eq!(t.limits.pitch_diameter.max, 50.0);
            assert!((t.limits.pitch_diameter.min - (50.0 - s.pitch_tolerance)).abs() < 1e-12);
            assert_eq!(t.limits.crest.max, 60.0);
        }
        assert_eq!(read("ZN m4 z1 d40 a15").designation, "ZN m4 z1 d40 a15");
        assert_eq!(
            read("M20x2.5-6g"),
            standards::metric(20.0, 2.5, false, "6g", 1, Hand::Right).unwrap()
        );
        assert_eq!(read("M20"), read("M20-6g"));
        assert_eq!(
            read("M30x2-6H"),
            standards::metric(30.0, 2.0, true, "6H", 1, Hand::Right).unwrap()
        );
        let two = read("M20x5(P2.5)-6g-LH");
        assert_eq!((two.section.starts, two.section.hand), (2, Hand::Left));
        assert_eq!(two.section.lead(), 5.0);
        // Reported as it was read: the lead with its pitch, the hand.
        assert_eq!(two.designation, "M20x5(P2.5)-6g-LH");
        assert_eq!(read("Tr40x14(P7)").designation, "Tr40x14(P7)");
        assert_eq!(read("Tr40x7 LH").designation, "Tr40x7-LH");
        assert_eq!(read("1-5 ACME-2G-LH").designation, "1-5 ACME-2G-LH");
        let two_start = standards::acme(1.0, 5.0, false, 2, 2, Hand::Right).unwrap();
        assert_eq!(two_start.designation, "1-0.2P-0.4L ACME-2G");
        assert_eq!(read("1-0.2P-0.4L ACME-2G"), two_start);
        assert_eq!(
            read("Tr40x7"),
            standards::trapezoidal(40.0, 7.0, false, 1, Hand::Right, s).unwrap()
        );
        assert_eq!(read("Tr40x14(P7)").section.starts, 2);
        assert_eq!(
            read("1-5 ACME-2G"),
            standards::acme(1.0, 5.0, false, 2, 1, Hand::Right).unwrap()
        );
        assert_eq!(read("3/4-6 ACME-2G").section.major, 0.75 * 25.4);
        let b = read("2-8 BUTT 7/45");
        assert_eq!(
            b,
            standards::buttress(2.0, 8.0, false, LoadFlank::TowardsChuck, 1, Hand::Right, s)
                .unwrap()
        );
        assert_eq!(read("2-8 BUTT"), b);
        let nut = designated(
            "Tr40x7",
            &Drawing {
                internal: Some(true),
                ..DRAWING
            },
        )
        .unwrap();
        assert!(nut.section.internal);
        // ISO 228-1: a class says external; none, internal.
        for (text, size, internal, class) in [
            ("G1/2A", "1/2", false, Some('A')),
            ("G 1/2 B", "1/2", false, Some('B')),
            ("G1 1/2A", "1 1/2", false, Some('A')),
            ("G1-1/2", "1 1/2", true, None),
        ] {
            assert_eq!(
                read(text),
                standards::pipe(size, internal, class, 1, Hand::Right).unwrap(),
                "{text}"
            );
        }
        assert_eq!(read("G3/4-LH").section.hand, Hand::Left);
    }

    /// What is not a designation, or not a size the standard has, is
    /// refused, naming the text and what was expected.
    #[test]
    fn bad_designations_are_named() {
        for (t, says) in [
            ("M21-6g", "no coarse pitch"),
            ("M20x2.5-9g", "tolerance class '9g'"),
            ("M20x2.7-6g", "ISO 965-1's table"),
            ("M20x5(P2)-6g", "not 1 to 12 times the pitch"),
            ("M20x2.5(P2.5-6g", "without its ')'"),
            ("Tr40", "Tr<d>x<pitch>"),
            ("1-5 ACME-3G", "ACME class"),
            ("1-5 ACME-2", "ACME class '2'"),
            ("UNC 1/2-13", "not a form pilgrim reads"),
            ("M20xA-6g", "pitch 'A' is not a positive number"),
            ("", "not a form"),
            ("G9/16A", "not a size of ISO 228-1"),
            ("ZI m5 z2", "a worm is Z<A|N|I> m<module>"),
            ("ZI m5 z2 d50 q3", "a worm is Z<A|N|I> m<module>"),
            ("ZK m5 z2 d50", "\"ZK\" is not ZA, ZN or ZI"),
            ("ZI m5 z1.5 d50", "z1.5 is not a whole number"),
            ("ZI m5 z1 d20", "above its base cylinder's diameter 11.09"),
            ("ZA m0 z1 d20", "module '0' is not a positive number"),
        ] {
            let e = designated(t, &DRAWING).unwrap_err().to_string();
            assert!(
                e.contains(&format!("thread designation '{t}'")) && e.contains(says),
                "{t}: {e}"
            );
        }
        let e = designated(
            "M30x2-6H",
            &Drawing {
                internal: Some(false),
                ..DRAWING
            },
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("an internal thread's, and the drawing says external"),
            "{e}"
        );
        let e = designated(
            "ZI m5 z2 d50",
            &Drawing {
                internal: Some(true),
                ..DRAWING
            },
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("an external thread's, and the drawing says internal"),
            "{e}"
        );
        assert!(designated(&"M".repeat(100), &DRAWING)
            .unwrap_err()
            .to_string()
            .contains("at most 64"));
    }
}
