//! Bounds on a zipped workbook (XLSX, ODS), checked before the spreadsheet
//! reader expands it.
//!
//! A few kilobytes of workbook can stand for gigabytes: XML compresses a
//! thousandfold (an XLSX whose shared strings inflate to 6 GiB), and an ODS
//! sheet says "this row, a million times" in one attribute, which the reader
//! (calamine) turns into a rectangle of cells, holding up to 100 million of
//! them, before the table's own cell count is seen. So, first: every part of
//! the archive is inflated into nothing, at most [`MAX_INFLATED_BYTES`] in
//! all and [`MAX_PARTS`] parts; then an ODS's `content.xml` is read as a
//! stream of events (quick-xml) and the cells its repetitions make are
//! counted as the reader would build them, at most [`super::table::MAX_CELLS`].
//! The counting is hand-written because it must follow calamine's own
//! expansion; the XML and the archive are read by their libraries.

use super::table::{TableError, MAX_CELLS};
use std::io::Read;

/// The most bytes a workbook's parts may inflate to, all together: 128 MiB.
pub const MAX_INFLATED_BYTES: u64 = 128 << 20;

/// The most parts (files) a workbook may hold.
pub const MAX_PARTS: usize = 10_000;

/// The most rows and columns an ODS sheet has, as the reader caps them.
const ODS_MAX_ROWS: u64 = 1_048_576;
const ODS_MAX_COLUMNS: u64 = 16_384;

/// Checks a workbook's bytes before it is opened: nothing for a file that
/// is not a zip archive (XLS, whose format bounds its sheets).
///
/// # Failures
/// [`TableError::Read`] naming `file` and what is too large.
pub fn check(bytes: &[u8], file: &str) -> Result<(), TableError> {
    check_within(bytes, file, MAX_INFLATED_BYTES)
}

/// [`check`] with at most `max_inflated` bytes of parts.
fn check_within(bytes: &[u8], file: &str, max_inflated: u64) -> Result<(), TableError> {
    if !bytes.starts_with(b"PK\x03\x04") {
        return Ok(());
    }
    let fail = |message: String| TableError::Read {
        file: file.to_owned(),
        message,
    };
    let mut archive = zip::ZipArchive::new(std::io::Cursor::new(bytes))
        .map_err(|e| fail(crate::files::excerpt(&e.to_string())))?;
    if archive.len() > MAX_PARTS {
        return Err(fail(format!(
            "the workbook holds {} parts, more than {MAX_PARTS}",
            archive.len()
        )));
    }
    let mut left = max_inflated;
    let mut content = None;
    for i in 0..archive.len() {
        let mut part = archive
            .by_index(i)
            .map_err(|e| fail(crate::files::excerpt(&e.to_string())))?;
        let name = String::from_utf8_lossy(part.name_raw()).into_owned();
        // Inflated into nothing, one byte past what is left at most.
        let got = std::io::copy(&mut (&mut part).take(left + 1), &mut std::io::sink())
            .map_err(|e| fail(format!("part {}: {}", crate::files::excerpt(&name), e)))?;
        if got > left {
            return Err(fail(format!(
                "the workbook's parts inflate to more than {} MiB (at {}): a compressed bomb, or a table too large to read",
                max_inflated >> 20,
                crate::files::excerpt(&name)
            )));
        }
        left -= got;
        if name == "content.xml" {
            content = Some(i);
        }
    }
    if let Some(i) = content {
        let part = archive
            .by_index(i)
            .map_err(|e| fail(crate::files::excerpt(&e.to_string())))?;
        let cells = ods_cells(std::io::BufReader::new(part)).map_err(fail)?;
        if cells > MAX_CELLS as u64 {
            return Err(fail(format!(
                "the table has more than {MAX_CELLS} cells (counted with the sheet's repetitions)"
            )));
        }
    }
    Ok(())
}

/// The cells the reader builds from an ODS `content.xml` (an upper bound,
/// counted with saturation): per sheet, the rows from its first non-empty
/// row to its last, repetitions included, times its widest row up to that
/// row's last non-empty cell; and every row's own cells as read.
fn ods_cells(source: impl std::io::BufRead) -> Result<u64, String> {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_reader(source);
    let mut buf = Vec::new();
    let mut total: u64 = 0;
    // The sheet being read: rows seen (with repeats), the span of rows with
    // content (rows up to and including the last such), the widest row.
    let (mut rows, mut span_end, mut span_start, mut widest) = (0u64, 0u64, None, 0u64);
    // The row being read: its repeats, its width so far, up to its last
    // non-empty cell.
    let (mut repeats, mut width, mut filled) = (1u64, 0u64, 0u64);
    let repeat = |e: &quick_xml::events::BytesStart<'_>, name: &str| -> u64 {
        e.try_get_attribute(name)
            .ok()
            .flatten()
            .and_then(|a| a.value.trim().parse().ok())
            .unwrap_or(1)
    };
    // A sheet's rectangle: the rows with content (and those between) times
    // its widest row.
    let rectangle = |start: Option<u64>, end: u64, widest: u64| {
        start.map_or(0, |s| end.saturating_sub(s).saturating_mul(widest))
    };
    loop {
        let event = reader
            .read_event_into(&mut buf)
            .map_err(|e| format!("content.xml: {}", crate::files::excerpt(&e.to_string())))?;
        match event {
            Event::Start(e) | Event::Empty(e) if e.name().as_ref() == "table:table-row" => {
                repeats =
                    repeat(&e, "table:number-rows-repeated").min(ODS_MAX_ROWS.saturating_sub(rows));
                (width, filled) = (0, 0);
            }
            ref ev @ (Event::Start(ref e) | Event::Empty(ref e))
                if e.name().as_ref() == "table:table-cell"
                    || e.name().as_ref() == "table:covered-table-cell" =>
            {
                let n = repeat(e, "table:number-columns-repeated");
                width = width.saturating_add(n).min(ODS_MAX_COLUMNS);
                // A cell with a value, a formula or content is not empty.
                let full = matches!(ev, Event::Start(_))
                    || e.try_get_attribute("office:value-type")
                        .ok()
                        .flatten()
                        .is_some()
                    || e.try_get_attribute("table:formula")
                        .ok()
                        .flatten()
                        .is_some();
                if full {
                    filled = width;
                }
            }
            Event::End(e) if e.name().as_ref() == "table:table-row" => {
                total = total.saturating_add(filled);
                if filled > 0 {
                    span_start.get_or_insert(rows);
                    span_end = rows + repeats;
                    widest = widest.max(filled);
                }
                rows = rows.saturating_add(repeats);
            }
            Event::End(e) if e.name().as_ref() == "table:table" => {
                total = total.saturating_add(rectangle(span_start, span_end, widest));
                (rows, span_end, span_start, widest) = (0, 0, None, 0);
            }
            Event::Eof => {
                total = total.saturating_add(rectangle(span_start, span_end, widest));
                break;
            }
            _ => {}
        }
        if total > MAX_CELLS as u64 {
            break;
        }
        buf.clear();
    }
    Ok(total)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn content(rows: &str) -> String {
        format!(
            "<office:document-content><office:body><office:spreadsheet><table:table table:name=\"S\">{rows}</table:table></office:spreadsheet></office:body></office:document-content>"
        )
    }

    #[test]
    fn repetitions_are_counted_as_the_reader_expands_them() {
        let cell = "<table:table-cell office:value-type=\"float\" office:value=\"1\"><text:p>1</text:p></table:table-cell>";
        let count = |rows: &str| ods_cells(content(rows).as_bytes()).unwrap();
        // Two rows of two cells.
        let two = format!("<table:table-row>{cell}{cell}</table:table-row>");
        assert_eq!(count(&two.repeat(2)), 2 + 2 + 4);
        // A million rows of a thousand: past the bound at once.
        let many = "<table:table-row table:number-rows-repeated=\"1000000\"><table:table-cell table:number-columns-repeated=\"1000\" office:value-type=\"float\" office:value=\"1\"/></table:table-row>";
        assert!(count(many) > MAX_CELLS as u64);
        // Empty repeated rows after the last value cost nothing.
        let trailing = format!(
            "{two}<table:table-row table:number-rows-repeated=\"1048000\"><table:table-cell table:number-columns-repeated=\"1024\"/></table:table-row>"
        );
        assert_eq!(count(&trailing), 2 + 2);
    }

    /// A part inflating past the bound is refused, naming the part, after
    /// inflating no more than the bound.
    #[test]
    fn parts_inflating_past_the_bound_are_refused() {
        use std::io::Write;
        let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
        let deflated = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated);
        zip.start_file("xl/sharedStrings.xml", deflated).unwrap();
        for _ in 0..(3 << 20) / 17 {
            zip.write_all(b"<si><t>a</t></si>").unwrap();
        }
        let bytes = zip.finish().unwrap().into_inner();
        assert!(bytes.len() < 100_000, "{} bytes", bytes.len());
        let e = check_within(&bytes, "b.xlsx", 2 << 20)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("b.xlsx") && e.contains("more than 2 MiB") && e.contains("sharedStrings"),
            "{e}"
        );
        assert!(check_within(&bytes, "b.xlsx", 4 << 20).is_ok());
    }
}

#[cfg(test)]
#[path = "../../tests/support/ods.rs"]
mod ods;

#[cfg(test)]
mod reader_tests {
    /// The ODS shape the bounds count is one the reader reads and expands:
    /// a row of values repeated, its cells repeated (small here).
    #[test]
    fn the_reader_expands_what_is_counted() {
        let content = "<?xml version=\"1.0\"?><office:document-content><office:body><office:spreadsheet>\
            <table:table table:name=\"S\"><table:table-row table:number-rows-repeated=\"30\">\
            <table:table-cell table:number-columns-repeated=\"20\" office:value-type=\"float\" office:value=\"1\"/>\
            </table:table-row></table:table></office:spreadsheet></office:body></office:document-content>";
        let bytes = super::ods::ods_bytes(content);
        assert_eq!(super::ods_cells(content.as_bytes()).unwrap(), 20 + 30 * 20);
        let table = super::super::table::read_table_bytes(&bytes, "t.ods").unwrap();
        assert_eq!(table.column("T").unwrap().len(), 30);
    }
}
