//! Text from outside, checked where it enters.
//!
//! A control executes what it reads: a tool called `T1)` followed by a line
//! break and `G00 X0 Z0` would put a rapid into a program if its name were
//! written as it came. So every text a program carries (tool, machine,
//! family and pass names) is a **name**, refused unless it holds only the
//! characters no dialect reads as anything but comment text
//! ([`is_name_char`]: ASCII letters, digits, the space and `_ - . , : / + #
//! =`), at most [`MAX_NAME`] of them. Texts that reach only reports, pages
//! and the terminal (descriptions, warnings, checks, parameter strings)
//! are **texts**: one line of any printable characters, but no control
//! characters (a lone carriage return is a line end to some controls and
//! terminals, an escape sequence rewrites a terminal) and no bidirectional
//! overrides (which make a terminal or page show other text than the file
//! holds), at most [`MAX_TEXT`] characters.
//!
//! Both checks quote the value with its control characters escaped
//! (`"T1)\nG00 X0 Z0 ("`), so the message shows what was refused.
//! The writers of each dialect neutralise comments again
//! ([`crate::program::post()`]), and the lint refuses any line it cannot
//! account for ([`crate::program::lint`]): three layers, each tested alone.

use crate::input::InputError;

/// The most characters of a name.
pub const MAX_NAME: usize = 80;

/// The most characters of a text.
pub const MAX_TEXT: usize = 2000;

/// The punctuation a name may hold besides letters, digits and the space.
pub const NAME_PUNCTUATION: &str = "_-.,:/+#=";

/// Whether `c` may stand in a name: an ASCII letter or digit, the space, or
/// one of [`NAME_PUNCTUATION`]. None of them opens or closes a comment or
/// a block in any dialect pilgrim writes (`(`, `)`, `;`, `%`, `$`, quotes
/// and line ends are all outside the set).
pub fn is_name_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == ' ' || NAME_PUNCTUATION.contains(c)
}

/// The value as a message quotes it: at most [`crate::files::MAX_EXCERPT`]
/// characters, control characters escaped.
pub fn quoted(value: &str) -> String {
    let shown: String = value.escape_debug().collect();
    format!("\"{}\"", crate::files::excerpt(&shown))
}

fn refused(what: &str, value: &str, reason: String) -> InputError {
    InputError::BadText {
        what: what.to_owned(),
        value: quoted(value),
        reason,
    }
}

/// Checks that `value`, the `what` (e.g. `tool name`), is a name: see the
/// [module docs](self).
///
/// # Failures
/// [`InputError::BadText`]: an empty name, one longer than [`MAX_NAME`], or
/// one holding a character outside the set (named, with its position).
pub fn check_name(what: &str, value: &str) -> Result<(), InputError> {
    if value.trim().is_empty() {
        return Err(refused(what, value, "is empty".into()));
    }
    let n = value.chars().count();
    if n > MAX_NAME {
        return Err(refused(
            what,
            value,
            format!("has {n} characters, more than the {MAX_NAME} a name may have"),
        ));
    }
    if let Some((i, c)) = value.chars().enumerate().find(|(_, c)| !is_name_char(*c)) {
        return Err(refused(
            what,
            value,
            format!(
                "holds '{}' at character {}: a name that reaches a program may hold only letters, digits, spaces and {}",
                c.escape_debug(),
                i + 1,
                NAME_PUNCTUATION.chars().map(String::from).collect::<Vec<_>>().join(" ")
            ),
        ));
    }
    Ok(())
}

/// Whether `c` is refused in a text: a control character or a
/// bidirectional override, isolate or mark.
fn is_hidden(c: char) -> bool {
    c.is_control()
        || matches!(c, '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}' | '\u{200e}' | '\u{200f}')
}

/// Checks that `value`, the `what` (e.g. `machine description`), is a text:
/// see the [module docs](self).
///
/// # Failures
/// [`InputError::BadText`]: one longer than [`MAX_TEXT`], or holding a
/// control character (line ends and tabs included) or a bidirectional
/// control.
pub fn check_text(what: &str, value: &str) -> Result<(), InputError> {
    let n = value.chars().count();
    if n > MAX_TEXT {
        return Err(refused(
            what,
            value,
            format!("has {n} characters, more than the {MAX_TEXT} a text may have"),
        ));
    }
    if let Some((i, c)) = value.chars().enumerate().find(|(_, c)| is_hidden(*c)) {
        return Err(refused(
            what,
            value,
            format!(
                "holds the control character U+{:04X} at character {}",
                u32::from(c),
                i + 1
            ),
        ));
    }
    Ok(())
}

/// A text cell of a CSV file as a spreadsheet must show it, not evaluate
/// it: text that opens with `=`, `+`, `-`, `@`, a tab or a carriage return
/// (a formula to Excel, LibreOffice and Google Sheets; a pass may be named
/// `=HYPERLINK(...)`) gets a leading `'`, the OWASP rule for CSV
/// injection. Numbers are written by the caller and never pass here.
pub fn spreadsheet_text(text: &str) -> String {
    if text.starts_with(['=', '+', '-', '@', '\t', '\r']) {
        format!("'{text}")
    } else {
        text.to_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_of_the_jobs_pass() {
        for good in [
            "pass 1, stock 225.0 um",
            "pass 12, start 2, finish, radial, depth 11.000",
            "pass 3, psi -80 deg",
            "caliber wheel",
            "LZ-250",
            "3K152VF20",
            "fanuc-0i-tc",
            "mandrel.rhai",
            "wheel D500 R20/W40 #2 +CBN=1",
        ] {
            check_name("name", good).unwrap_or_else(|e| panic!("{good}: {e}"));
        }
    }

    /// What would break a comment or a block in some dialect is refused,
    /// the character named and the value shown escaped.
    #[test]
    fn what_breaks_a_comment_is_refused() {
        let e = check_name("tool name", "T1)\nG00 X0 Z0 (")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("tool name \"T1)\\nG00 X0 Z0 (\"") && e.contains("')' at character 3"),
            "{e}"
        );
        for bad in [
            "a\rb",
            "a;b",
            "a(b",
            "a)b",
            "%",
            "$PATH",
            "a\"b",
            "a'b",
            "\u{202e}x",
            "a\tb",
            "é",
        ] {
            assert!(check_name("pass name", bad).is_err(), "{bad:?}");
        }
        assert!(check_name("n", "").is_err());
        assert!(check_name("n", &"x".repeat(MAX_NAME + 1)).is_err());
    }

    #[test]
    fn texts_refuse_only_hidden_characters() {
        check_text("description", "a grinder (CNC) \"3K152\"; é, 0.5 µm").unwrap();
        for bad in [
            "a\rb",
            "a\nb",
            "a\tb",
            "a\u{1b}[31mred",
            "x\u{202e}gpj.exe",
            "\u{0}",
        ] {
            let e = check_text("description", bad).unwrap_err().to_string();
            assert!(e.contains("control character U+"), "{e}");
        }
    }
}
