//! An OpenDocument spreadsheet in memory, for tests that read one: the
//! zip with its `mimetype` first and stored, an empty manifest (the
//! reader needs no more), and the given `content.xml`. Included by path (`#[path = ...] mod ods;`) by the
//! kernel's unit tests and the kernel's and pilgrim's integration tests,
//! which share no crate to hold it.

use std::io::Write;

/// The ODS file holding `content` as its `content.xml`.
pub fn ods_bytes(content: &str) -> Vec<u8> {
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let stored =
        zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    zip.start_file("mimetype", stored).unwrap();
    zip.write_all(b"application/vnd.oasis.opendocument.spreadsheet")
        .unwrap();
    zip.start_file("META-INF/manifest.xml", stored).unwrap();
    zip.write_all(b"<manifest:manifest/>").unwrap();
    zip.start_file("content.xml", stored).unwrap();
    zip.write_all(content.as_bytes()).unwrap();
    zip.finish().unwrap().into_inner()
}
