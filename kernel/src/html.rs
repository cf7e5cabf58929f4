//! The few HTML pieces the report page and the families' sections of it
//! share: text escaped, a table row. Hand-written: two functions do not
//! warrant a template engine, and the page is built as one string.

use std::fmt::Write;

/// Escapes text for HTML (element content and quoted attributes).
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// A table row of cells (already escaped).
pub fn row(out: &mut String, cells: &[String]) {
    row_at(out, None, cells);
}

/// A table row of cells (already escaped) that names the program's block
/// `block` (from 0) where it has one: the page's player goes there when
/// the row is clicked.
pub fn row_at(out: &mut String, block: Option<usize>, cells: &[String]) {
    match block {
        Some(b) => {
            let _ = write!(out, "<tr data-block=\"{b}\">");
        }
        None => out.push_str("<tr>"),
    }
    for c in cells {
        let _ = write!(out, "<td>{c}</td>");
    }
    out.push_str("</tr>\n");
}
