//! Tables from real spreadsheet files: XLSX (written by rust_xlsxwriter), ODS
//! (assembled as the zip of XML that LibreOffice writes) and CSV.

#[path = "support/ods.rs"]
mod ods;

use pilgrim_kernel::{read_table, read_table_str, TableError};
use std::path::PathBuf;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("pilgrim-tables-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn xlsx_groove_table_with_headers() {
    let dir = scratch("xlsx");
    let path = dir.join("groove.xlsx");
    let mut book = rust_xlsxwriter::Workbook::new();
    let sheet = book.add_worksheet();
    for (c, h) in ["theta", "Hp", "B"].iter().enumerate() {
        sheet.write_string(0, c as u16, *h).unwrap();
    }
    for i in 0..10u32 {
        sheet.write_number(i + 1, 0, i as f64 * 10.0).unwrap();
        sheet.write_number(i + 1, 1, 5.0 + 0.1 * i as f64).unwrap();
        if i != 6 {
            sheet.write_number(i + 1, 2, 12.0 - 0.2 * i as f64).unwrap();
        }
    }
    sheet.write_string(4, 1, "n/a").unwrap();
    book.save(&path).unwrap();

    let t = read_table(&path).unwrap();
    assert_eq!(t.headers(), ["theta", "Hp", "B"]);
    assert_eq!(t.column("theta").unwrap()[3], 30.0);
    let file = path.display().to_string();
    // Row 5 of the sheet holds text in Hp; row 8 has no B.
    assert_eq!(
        t.column("Hp").unwrap_err(),
        TableError::NotNumber {
            file: file.clone(),
            row: 5,
            column: "B (Hp)".into(),
            text: "n/a".into()
        }
    );
    assert_eq!(
        t.column("B").unwrap_err(),
        TableError::MissingCell {
            file,
            row: 8,
            column: "C (B)".into()
        }
    );
    std::fs::remove_dir_all(&dir).ok();
}

fn ods_cell(v: &str) -> String {
    match v.parse::<f64>() {
        Ok(x) => format!(
            r#"<table:table-cell office:value-type="float" office:value="{x}"><text:p>{v}</text:p></table:table-cell>"#
        ),
        Err(_) if v.is_empty() => "<table:table-cell/>".to_owned(),
        Err(_) => format!(
            r#"<table:table-cell office:value-type="string"><text:p>{v}</text:p></table:table-cell>"#
        ),
    }
}

fn write_ods(path: &std::path::Path, rows: &[&[&str]]) {
    let body: String = rows
        .iter()
        .map(|r| {
            format!(
                "<table:table-row>{}</table:table-row>",
                r.iter().map(|c| ods_cell(c)).collect::<String>()
            )
        })
        .collect();
    let content = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<office:document-content xmlns:office="urn:oasis:names:tc:opendocument:xmlns:office:1.0" xmlns:table="urn:oasis:names:tc:opendocument:xmlns:table:1.0" xmlns:text="urn:oasis:names:tc:opendocument:xmlns:text:1.0" office:version="1.2"><office:body><office:spreadsheet><table:table table:name="Sheet1">{body}</table:table></office:spreadsheet></office:body></office:document-content>"#
    );
    std::fs::write(path, ods::ods_bytes(&content)).unwrap();
}

#[test]
fn ods_profile_table() {
    let dir = scratch("ods");
    let path = dir.join("profile.ods");
    write_ods(
        &path,
        &[
            &["z", "x"],
            &["0", "19"],
            &["10", "19.5"],
            &["20", "20.25"],
            &["30", "21"],
        ],
    );
    let t = read_table(&path).unwrap();
    let p = t.profile("z", "x").unwrap();
    assert_eq!(p.x(), [19.0, 19.5, 20.25, 21.0]);
    // z that does not increase: the row is named.
    let bad = dir.join("bad.ods");
    write_ods(
        &bad,
        &[&["z", "x"], &["0", "19"], &["10", "19.5"], &["5", "20"]],
    );
    let e = read_table(&bad)
        .unwrap()
        .profile("z", "x")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("bad.ods, row 4, column A (z): 5 does not increase"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn csv_file_and_broken_spreadsheet() {
    let dir = scratch("csv");
    let path = dir.join("p.csv");
    std::fs::write(&path, "z\tx\n0\t1,5\n1\t1,75\n2\t2\n").unwrap();
    let t = read_table(&path).unwrap();
    assert_eq!(t.column("x").unwrap(), vec![1.5, 1.75, 2.0]);
    let junk = dir.join("junk.xlsx");
    std::fs::write(&junk, "not a zip").unwrap();
    let e = read_table(&junk).unwrap_err();
    assert!(matches!(e, TableError::Read { .. }), "{e}");
    assert!(
        e.to_string().starts_with(&junk.display().to_string()),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A table of more than 10 million cells is refused with the bound named.
#[test]
fn tables_are_bounded_in_cells() {
    let row = "1,".repeat(999) + "1\n";
    let text = row.repeat(10_001);
    let e = read_table_str(&text, "big.csv").unwrap_err().to_string();
    assert!(
        e.contains("big.csv") && e.contains("more than 10000000 cells"),
        "{e}"
    );
}
