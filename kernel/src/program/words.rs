//! The words of a G-code block as its control reads them: a letter and a
//! number exactly as written, nothing dropped, rounded or skipped.
//!
//! Written here rather than taken from a G-code crate: the `gcode` crate
//! this reader used read numbers as `f32` and silently dropped a code
//! whose decimal part it could not hold (`G91.000010`, which LinuxCNC
//! reads as G91: every later move incremental), and gave codes by their
//! integer part (`G33.1`, rigid tapping, read as a thread). A control reads
//! every character of a block or stops with an alarm; so does this reader.
//! The grammar is small (ISO 6983 words, the dialects' comments already
//! blanked by the caller): a word is one upper-case letter and a number,
//! `[+-]digits[.digits]`; anything else (a parameter `#1`, an expression
//! `[..]`, an instruction of several letters `TRANS`, a letter without its
//! number, a lower-case letter) is refused naming it.

use crate::math::Real;

/// The longest number a word may hold (characters): past it, a control's
/// own reader refuses it (Fanuc takes 8 digits).
pub const MAX_NUMBER: usize = 24;

/// One word of a block: its letter and its number as written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Word {
    /// The address (upper case).
    pub letter: char,
    /// The number as written (`-12.50`, `01`, `.5`).
    pub number: String,
}

impl Word {
    /// The word as written (`G01`, `X-12.50`).
    pub fn text(&self) -> String {
        format!("{}{}", self.letter, self.number)
    }

    /// Whether the number is written with a decimal point.
    pub fn has_point(&self) -> bool {
        self.number.contains('.')
    }

    /// The number's value (f64, as written: the grammar admits only
    /// numbers `str::parse` reads).
    pub fn value(&self) -> Real {
        self.number.parse().unwrap_or(Real::NAN)
    }

    /// The word as a code (G, M): its number with no sign, leading zeros
    /// and trailing zeros of the decimals taken off, as a control compares
    /// codes (`G01` and `G1.0` are `1`, `G33.1` is `33.1`, `G91.000010` is
    /// `91.00001`); `None` for a number with a sign.
    pub fn code(&self) -> Option<String> {
        if self.number.starts_with(['+', '-']) {
            return None;
        }
        let (int, frac) = self
            .number
            .split_once('.')
            .unwrap_or((self.number.as_str(), ""));
        let int = int.trim_start_matches('0');
        let int = if int.is_empty() { "0" } else { int };
        let frac = frac.trim_end_matches('0');
        Some(if frac.is_empty() {
            int.to_owned()
        } else {
            format!("{int}.{frac}")
        })
    }

    /// The word as a whole number written as one (`N`, `T`, `D`, a code
    /// where the dialect reads codes as whole numbers): digits only, no
    /// sign, no point (`D1.` is refused where `D1` is read), or `None`.
    pub fn integer(&self) -> Option<u32> {
        if !self.number.is_empty() && self.number.bytes().all(|b| b.is_ascii_digit()) {
            self.number.parse().ok()
        } else {
            None
        }
    }

    /// The word as a code read to its decimals, a whole one (LinuxCNC's
    /// `G1.0` is G1):
    /// digits only, or `None`.
    pub fn whole(&self) -> Option<u32> {
        let c = self.code()?;
        if c.contains('.') {
            return None;
        }
        c.parse().ok()
    }
}

/// The words of `code`, one block's text with its comments blanked.
///
/// # Failures
/// The first character that does not begin or continue a word, named with
/// what it is.
pub fn words(code: &str) -> Result<Vec<Word>, super::ProgramFault> {
    words_text(code).map_err(super::ProgramFault::new)
}

/// [`words`], its failure as text.
fn words_text(code: &str) -> Result<Vec<Word>, String> {
    let b = code.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i] as char;
        if c == ' ' || c == '\t' {
            i += 1;
            continue;
        }
        if !c.is_ascii_uppercase() {
            return Err(match c {
                '%' => "'%': a tape's start or end, which frames only a whole program, on its first and last lines"
                    .to_owned(),
                '#' => "'#': a parameter (a variable), which the verification does not simulate"
                    .to_owned(),
                '[' | ']' | '=' | '*' | '/' => format!(
                    "'{c}': an expression or a block skip, which the verification does not simulate"
                ),
                c if c.is_ascii_lowercase() => format!(
                    "'{c}': a lower-case address, which not every control reads: write '{}'",
                    c.to_ascii_uppercase()
                ),
                c => format!("'{c}' where a word's address letter is wanted"),
            });
        }
        // An instruction of several letters (Sinumerik's `TRANS`, `GOTOF`).
        let letters = b[i..]
            .iter()
            .take_while(|x| x.is_ascii_alphabetic())
            .count();
        if letters > 1 {
            let name = &code[i..i + letters];
            return Err(format!(
                "'{name}': an instruction the verification does not read"
            ));
        }
        let start = i + 1;
        let mut j = start;
        if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
            j += 1;
        }
        let digits_from = j;
        while j < b.len() && b[j].is_ascii_digit() {
            j += 1;
        }
        let mut digits = j - digits_from;
        if j < b.len() && b[j] == b'.' {
            j += 1;
            let f = j;
            while j < b.len() && b[j].is_ascii_digit() {
                j += 1;
            }
            digits += j - f;
        }
        if digits == 0 {
            return Err(match b.get(j) {
                Some(b'#') => format!(
                    "{c}#: a parameter (a variable), which the verification does not simulate"
                ),
                Some(b'[') => {
                    format!("{c}[: an expression, which the verification does not simulate")
                }
                _ => format!("{c}: an address without its number"),
            });
        }
        let number = &code[start..j];
        if number.len() > MAX_NUMBER {
            return Err(format!(
                "{c}{}...: a number longer than {MAX_NUMBER} characters",
                &number[..MAX_NUMBER]
            ));
        }
        if j < b.len() && b[j] == b'.' {
            return Err(format!("{c}{number}.: a number with two decimal points"));
        }
        out.push(Word {
            letter: c,
            number: number.to_owned(),
        });
        i = j;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one(t: &str) -> Word {
        let w = words(t).unwrap();
        assert_eq!(w.len(), 1, "{t}");
        w.into_iter().next().unwrap()
    }

    #[test]
    fn codes_keep_their_decimals() {
        for (t, c) in [
            ("G1", "1"),
            ("G01", "1"),
            ("G1.0", "1"),
            ("G01.000", "1"),
            ("G0", "0"),
            ("G00", "0"),
            ("G.0", "0"),
            ("G33.1", "33.1"),
            ("G91.000010", "91.00001"),
            ("G59.300010", "59.30001"),
            ("M3.5", "3.5"),
        ] {
            assert_eq!(one(t).code().as_deref(), Some(c), "{t}");
        }
        assert_eq!(one("G-1").code(), None);
        assert_eq!(one("T0101").whole(), Some(101));
        assert_eq!(one("N1.5").whole(), None);
        assert_eq!(one("G01").integer(), Some(1));
        assert_eq!(one("G1.0").integer(), None);
        assert_eq!(one("D+1").integer(), None);
    }

    #[test]
    fn numbers_are_read_as_written() {
        let w = words("N10G1X-12.50Z.5 F100.").unwrap();
        let t: Vec<String> = w.iter().map(Word::text).collect();
        assert_eq!(t, ["N10", "G1", "X-12.50", "Z.5", "F100."]);
        assert_eq!(w[2].value(), -12.5);
        assert_eq!(w[3].value(), 0.5);
        assert!(w[4].has_point() && !w[0].has_point());
    }

    #[test]
    fn what_is_not_a_word_is_refused() {
        for (t, says) in [
            ("G1 X#1", "parameter"),
            ("X[1+2]", "expression"),
            ("g1", "lower-case"),
            ("TRANS X1", "TRANS"),
            ("G1 X", "without its number"),
            ("X1.2.3", "two decimal points"),
            ("X+", "without its number"),
            ("X1,5", "','"),
        ] {
            let e = words(t).unwrap_err().message;
            assert!(e.contains(says), "{t}: {e}");
        }
        let long = format!("X1.{}", "0".repeat(40));
        assert!(words(&long).unwrap_err().message.contains("longer"));
    }
}
