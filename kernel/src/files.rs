//! Reading what comes from outside: regular files only (a FIFO or a device
//! would make a run wait, or read for ever), each kind bounded in size, and
//! messages that quote at most a short excerpt of what was read.

use std::io::Read;
use std::path::Path;

/// The largest script, parameter file or machine file read (bytes).
pub const MAX_TEXT_BYTES: u64 = 4 << 20;
/// The largest table (CSV or spreadsheet) or run file read (bytes).
pub const MAX_DATA_BYTES: u64 = 256 << 20;
/// The most characters of an input an error message quotes.
pub const MAX_EXCERPT: usize = 120;

/// A file that cannot be read as an input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}: {message}")]
pub struct FileError {
    /// The file, as given.
    pub file: String,
    /// Why not.
    pub message: String,
}

fn error(path: &Path, message: impl Into<String>) -> FileError {
    FileError {
        file: shown_path(path),
        message: message.into(),
    }
}

/// Checks that `path` is a regular file (following links) of at most
/// `limit` bytes, without opening it.
///
/// # Failures
/// A missing file, one that is not a regular file, or a larger one.
pub fn check_regular(path: &Path, limit: u64) -> Result<u64, FileError> {
    let meta = std::fs::metadata(path).map_err(|e| error(path, e.to_string()))?;
    regular_within(path, &meta, limit)
}

/// The length of the file `meta` describes, if it is a regular file of at
/// most `limit` bytes.
fn regular_within(path: &Path, meta: &std::fs::Metadata, limit: u64) -> Result<u64, FileError> {
    if !meta.is_file() {
        return Err(error(
            path,
            "not a regular file (pilgrim reads only regular files)",
        ));
    }
    if meta.len() > limit {
        return Err(error(
            path,
            format!(
                "{} bytes, more than the {limit} bytes read from such a file",
                meta.len()
            ),
        ));
    }
    Ok(meta.len())
}

/// The bytes of the regular file `path`, at most `limit` of them.
///
/// # Failures
/// As [`check_regular`]; a read error; a file that grew past the limit
/// while it was read.
pub fn read_bytes(path: &Path, limit: u64) -> Result<Vec<u8>, FileError> {
    // Checked before it is opened: opening a FIFO would wait for a writer.
    check_regular(path, limit)?;
    let file = std::fs::File::open(path).map_err(|e| error(path, e.to_string()))?;
    read_opened(path, file, limit)
}

/// The bytes of the opened file `file` (at `path`, for messages), at most
/// `limit`: it must be a regular file (as opened: what a link pointed to,
/// or the link itself refused by the way it was opened) of at most
/// `limit` bytes, and must not grow past them while it is read.
///
/// # Failures
/// A file that is not regular, larger than `limit`, or grew past it; a
/// read error.
pub fn read_opened(path: &Path, file: std::fs::File, limit: u64) -> Result<Vec<u8>, FileError> {
    let meta = file.metadata().map_err(|e| error(path, e.to_string()))?;
    let len = regular_within(path, &meta, limit)?;
    let mut bytes = Vec::with_capacity(len as usize);
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| error(path, e.to_string()))?;
    if bytes.len() as u64 > limit {
        return Err(error(
            path,
            format!("grew past {limit} bytes while it was read"),
        ));
    }
    Ok(bytes)
}

/// The text (UTF-8) of the regular file `path`, at most `limit` bytes.
///
/// # Failures
/// As [`read_bytes`]; text that is not UTF-8.
pub fn read_text(path: &Path, limit: u64) -> Result<String, FileError> {
    String::from_utf8(read_bytes(path, limit)?)
        .map_err(|e| error(path, format!("not UTF-8 text: {}", e.utf8_error())))
}

/// The text of file `name` in folder `dir` (a subprogram a program calls
/// by name), `None` where there is no such file or no folder. `name` is a
/// file's name only (letters, digits, `_`, `-`, one `.`): never a path, so
/// nothing outside the folder is read.
///
/// # Failures
/// A name that is not a plain file name; a file that cannot be read or is
/// larger than [`MAX_TEXT_BYTES`].
pub fn beside(dir: Option<&Path>, name: &str) -> Result<Option<String>, FileError> {
    let plain =
        name.split('.').count() <= 2 && name.split('.').all(|p| !p.is_empty() && is_plain_name(p));
    if !plain {
        return Err(FileError {
            file: excerpt(name),
            message: "not a file's name a call may open (letters, digits, '_', '-' and one '.')"
                .into(),
        });
    }
    let Some(dir) = dir else { return Ok(None) };
    let path = dir.join(name);
    if !path.is_file() {
        return Ok(None);
    }
    read_text(&path, MAX_TEXT_BYTES).map(Some)
}

/// Whether `name` is a plain name (letters, digits, `_`, `-`): what a body
/// or part name must be before it becomes a file name.
pub fn is_plain_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= 64
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

/// One character as a message shows it: control characters (line ends,
/// escapes, bidirectional controls) as escapes, so that quoted text can
/// neither drive a terminal nor hide what it says.
fn shown_char(c: char, out: &mut String) {
    match c {
        '\n' => out.push_str("\\n"),
        '\r' => out.push_str("\\r"),
        '\t' => out.push_str("\\t"),
        c if c.is_control()
            || matches!(c, '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}') =>
        {
            out.push_str(&format!("\\u{{{:x}}}", u32::from(c)));
        }
        c => out.push(c),
    }
}

/// `text` as a message quotes it: control characters escaped, at most
/// [`MAX_EXCERPT`] characters of it, marking the cut with `...`.
pub fn excerpt(text: &str) -> String {
    let mut out = String::new();
    let mut count = 0;
    for c in text.chars() {
        let mut one = String::new();
        shown_char(c, &mut one);
        let n = one.chars().count();
        if count + n > MAX_EXCERPT {
            out.push_str("...");
            return out;
        }
        count += n;
        out.push_str(&one);
    }
    out
}

/// The most characters of one message pilgrim prints (an error, a status
/// line): past it the message is cut, saying how much was.
pub const MAX_MESSAGE: usize = 4000;

/// `text` as pilgrim prints it to a terminal: every control character but
/// the line feed and the tab (a carriage return, an escape sequence, a bell) and every
/// bidirectional override escaped as `\r`, `\u{1b}`, `\u{202e}`, so that no
/// name from outside (a file's, a column's, a machine's) can move the
/// cursor, write the clipboard or make one word display as another; cut
/// after `max` characters, if given, with the count of those cut.
pub fn terminal(text: &str, max: Option<usize>) -> String {
    let mut out = String::with_capacity(text.len());
    for (n, c) in text.chars().enumerate() {
        if max.is_some_and(|m| n >= m) {
            let rest = text.chars().count() - n;
            out.push_str(&format!("... ({rest} more characters cut)"));
            break;
        }
        if c == '\n' || c == '\t' {
            out.push(c);
        } else {
            shown_char(c, &mut out);
        }
    }
    out
}

/// A path as a message shows it: control characters escaped, and a path
/// longer than [`MAX_EXCERPT`] characters cut in the middle, so that both
/// where it starts and the file's name show.
pub fn shown_path(path: &Path) -> String {
    let text = path.display().to_string();
    let mut escaped = String::new();
    for c in text.chars() {
        shown_char(c, &mut escaped);
    }
    let chars: Vec<char> = escaped.chars().collect();
    if chars.len() <= MAX_EXCERPT {
        return escaped;
    }
    let half = MAX_EXCERPT / 2;
    let head: String = chars[..half].iter().collect();
    let tail: String = chars[chars.len() - (MAX_EXCERPT - half - 3)..]
        .iter()
        .collect();
    format!("{head}...{tail}")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A message for the terminal: control characters and overrides
    /// escaped, the line feed and tab kept, cut at its length saying so.
    #[test]
    fn messages_reach_the_terminal_escaped_and_cut() {
        let said = terminal("a\rb\u{1b}[2J\u{202e}c\nd\te", None);
        assert_eq!(said, "a\\rb\\u{1b}[2J\\u{202e}c\nd\te");
        let long = "x".repeat(5000);
        let said = terminal(&long, Some(MAX_MESSAGE));
        assert!(said.starts_with(&"x".repeat(MAX_MESSAGE)));
        assert!(
            said.ends_with("... (1000 more characters cut)"),
            "{}",
            &said[3990..]
        );
    }

    #[test]
    fn excerpts_are_short() {
        assert_eq!(excerpt("short"), "short");
        let long = "é".repeat(10_000);
        let e = excerpt(&long);
        assert_eq!(e.chars().count(), MAX_EXCERPT + 3);
        // Escapes count towards the length and are never cut in two.
        let e = excerpt(&"\u{1b}]52;c;AAAA\u{7}".repeat(100));
        assert!(e.chars().count() <= MAX_EXCERPT + 3, "{e}");
        assert!(!e.contains('\u{1b}') && e.starts_with("\\u{1b}]52"), "{e}");
        let p = Path::new("/tmp").join("d".repeat(300)).join("part.stl");
        let s = shown_path(&p);
        assert_eq!(s.chars().count(), MAX_EXCERPT);
        assert!(s.starts_with("/tmp/ddd") && s.ends_with("/part.stl"), "{s}");
    }

    #[test]
    fn directories_and_large_files_are_refused() {
        let dir = std::env::temp_dir();
        let e = read_text(&dir, MAX_TEXT_BYTES).unwrap_err();
        assert!(e.message.contains("not a regular file"), "{e}");
        let f = dir.join(format!("pilgrim-files-{}", std::process::id()));
        std::fs::write(&f, "0123456789").unwrap();
        assert_eq!(read_text(&f, 10).unwrap(), "0123456789");
        assert!(read_text(&f, 9).unwrap_err().message.contains("more than"));
        std::fs::remove_file(&f).ok();
    }
}
