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
        file: path.display().to_string(),
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
    let len = check_regular(path, limit)?;
    let file = std::fs::File::open(path).map_err(|e| error(path, e.to_string()))?;
    let mut bytes = Vec::with_capacity(len as usize);
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| error(path, e.to_string()))?;
    if bytes.len() as u64 > limit {
        return Err(error(path, format!("more than {limit} bytes")));
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

/// Whether `name` is a plain name (letters, digits, `_`, `-`): what a body
/// or part name must be before it becomes a file name.
pub fn is_plain_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= 64
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

/// `text` cut to [`MAX_EXCERPT`] characters, marking the cut.
pub fn excerpt(text: &str) -> String {
    match text.char_indices().nth(MAX_EXCERPT) {
        None => text.to_owned(),
        Some((i, _)) => format!("{}...", &text[..i]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn excerpts_are_short() {
        assert_eq!(excerpt("short"), "short");
        let long = "é".repeat(10_000);
        let e = excerpt(&long);
        assert_eq!(e.chars().count(), MAX_EXCERPT + 3);
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
