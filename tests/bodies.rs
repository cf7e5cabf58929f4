//! A machine's bodies as data: the boxes, cylinders and guards a machine
//! file describes are checked when it is read, placed by their chains and
//! drawn in the scene; a size that cannot be is refused naming the body,
//! the key and the line.

use crate::common;

use common::{pilgrim, s, scratch};

/// The vertical mill with a spindle head riding the tool 250 mm above its
/// tip, a guard round the cutter and a fixed column beside the table.
fn mill_with_bodies(extra: &str) -> String {
    let (code, mill, err) = pilgrim(&["machines", "--toml", "vertical-mill"]);
    assert_eq!(code, 0, "{err}");
    assert!(!mill.contains("[bodies"), "{mill}");
    let tool = r#"{ factor = "rz", axis = "C" }, { factor = "tx", axis = "X" }, { factor = "ty", axis = "Y" }, { factor = "tz", axis = "Z" }"#;
    format!(
        "{mill}\n\
         [bodies.head]\n\
         description = \"spindle head\"\n\
         shape = {{ kind = \"box\", size = [200.0, 160.0, 300.0] }}\n\
         chain = [{tool}, {{ factor = \"tz\", value = 250.0 }}]\n\n\
         [bodies.hood]\n\
         description = \"the cutter's guard\"\n\
         shape = {{ kind = \"guard\", inner = {extra}, outer = 34.0, width = 60.0, cover_deg = 270.0 }}\n\
         chain = [{tool}, {{ factor = \"tz\", value = 40.0 }}]\n\n\
         [bodies.column]\n\
         description = \"the machine's column\"\n\
         shape = {{ kind = \"cylinder\", radius = 150.0, length = 800.0 }}\n\
         chain = [{{ factor = \"tx\", value = -600.0 }}]\n"
    )
}

#[test]
fn a_machine_files_bodies_are_drawn_where_their_chains_put_them() {
    let dir = scratch("bodies", "mill");
    let file = dir.join("mill.toml");
    std::fs::write(&file, mill_with_bodies("30.0")).unwrap();
    let out = dir.join("out");
    let (code, _, err) = pilgrim(&[
        "run",
        "scripts/examples/mill_circle.rhai",
        "--machine",
        s(&file),
        "--out",
        s(&out),
    ]);
    assert_eq!(code, 0, "{err}");
    let at = common::scene_nodes(&out);
    // The head and the guard ride the tool along its axis (+Z); the
    // column stands where its constant chain puts it.
    let (tool, head, hood, column) = (at("cutter"), at("head"), at("hood"), at("column"));
    for (body, up) in [(head, 250.0), (hood, 40.0)] {
        let d: Vec<f32> = (0..3).map(|k| body[k] - tool[k]).collect();
        assert!(
            d[0].abs() < 1e-3 && d[1].abs() < 1e-3 && (d[2] - up).abs() < 1e-3,
            "{d:?}"
        );
    }
    assert_eq!(column, [-600.0, 0.0, 0.0]);
    common::leave_for_checkers(&out, "bodies");
}

#[test]
fn a_body_that_cannot_be_is_refused_naming_it() {
    let dir = scratch("bodies", "bad");
    let file = dir.join("mill.toml");
    let text = mill_with_bodies("40.0");
    std::fs::write(&file, &text).unwrap();
    let (code, _, err) = pilgrim(&["machines", "--only-files", "--file", s(&file)]);
    assert_eq!(code, 1, "{err}");
    let line = text
        .lines()
        .position(|l| l.contains("inner = 40.0"))
        .unwrap()
        + 1;
    assert!(
        err.contains(&format!("mill.toml:{line}:"))
            && err.contains("body hood: inner = 40 must be below outer = 34"),
        "{err}"
    );
}
