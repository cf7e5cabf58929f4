//! The machine twin's collision check: every pair of bodies the program
//! moves relative to each other (the tool, the machine's guard, flanges,
//! wheelhead, rest arm, holder, turret, chuck, tailstock, and the part)
//! measured along every move. The default jobs are clear, each pair's
//! smallest clearance in the report; a machine whose body is put where it
//! must collide fails the run naming the two bodies and the block, and
//! writes no program.

use crate::common;

use common::{pilgrim, s, scratch};
use serde_json::Value;

/// The machine file of `machine` (as `pilgrim machines --toml` writes it)
/// with each `(from, to)` text replaced once.
fn machine_with(machine: &str, edits: &[(&str, &str)]) -> String {
    let (code, mut text, err) = pilgrim(&["machines", "--toml", machine]);
    assert_eq!(code, 0, "{err}");
    for (from, to) in edits {
        assert!(text.contains(from), "no {from} in\n{text}");
        text = text.replacen(from, to, 1);
    }
    text
}

/// The pair's smallest clearance in a report.
fn clearance(r: &Value, a: &str, b: &str) -> f64 {
    r["collisions"]["clearances"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| {
            let names = [c["bodies"][0].as_str(), c["bodies"][1].as_str()];
            names == [Some(a), Some(b)] || names == [Some(b), Some(a)]
        })
        .unwrap_or_else(|| panic!("no pair {a} / {b} in {}", r["collisions"]))["clearance_mm"]
        .as_f64()
        .unwrap()
}

#[test]
fn the_default_jobs_are_clear_and_report_each_pairs_clearance() {
    for (job, pairs) in [
        (
            "mandrel",
            &[
                ("wheel", "tailstock_centre"),
                ("rest_arm", "chuck"),
                ("guard", "blank"),
                ("rest_arm", "blank"),
            ][..],
        ),
        (
            "caliber",
            &[
                ("wheel", "collar_front"),
                ("wheel", "arbor"),
                ("housing", "caliber"),
                ("guard", "caliber"),
            ][..],
        ),
        (
            "worm",
            &[
                ("cutter", "chuck"),
                ("holder", "worm"),
                ("turret", "chuck"),
                ("holder", "tailstock_quill"),
            ][..],
        ),
    ] {
        let out = scratch("collisions", job).join("out");
        let (code, _, err) = pilgrim(&[
            "run",
            &format!("scripts/{job}.rhai"),
            "--out",
            s(&out),
            "--quiet",
        ]);
        assert_eq!(code, 0, "{job}: {err}");
        let r = common::report_of(&out);
        let all = r["collisions"]["clearances"].as_array().unwrap();
        // Every pair checked is clear, and the ones named are among them.
        assert!(all.len() >= pairs.len(), "{job}: {all:?}");
        for c in all {
            assert!(c["clearance_mm"].as_f64().unwrap() > 0.0, "{job}: {c}");
        }
        for (a, b) in pairs {
            let d = clearance(&r, a, b);
            assert!(d > 1.0 && d < 400.0, "{job}: {a} / {b}: {d}");
        }
        // The tool and the part touch by design (the verification measures
        // the cut): never a pair here; nor a body and its own mount.
        let named = |c: &Value, a: &str, b: &str| {
            let n = [c["bodies"][0].as_str(), c["bodies"][1].as_str()];
            n == [Some(a), Some(b)] || n == [Some(b), Some(a)]
        };
        assert!(!all.iter().any(|c| named(c, "wheel", "guard")
            || named(c, "cutter", "holder")
            || named(c, "rest", "rest_arm")));
        let page = std::fs::read_to_string(out.join("report.html")).unwrap();
        assert!(page.contains("<h2>Clearances</h2>"), "{job}");
    }
}

/// Runs `script` on the machine file `text`: the failed run's report,
/// after checking that it failed and left no program.
fn refused(tag: &str, script: &str, text: &str) -> (Value, String) {
    let dir = scratch("collisions", tag);
    let file = dir.join("machine.toml");
    std::fs::write(&file, text).unwrap();
    let out = dir.join("out");
    let (code, _, err) = pilgrim(&[
        "run",
        script,
        "--machine",
        s(&file),
        "--out",
        s(&out),
        "--quiet",
    ]);
    assert_ne!(code, 0, "{tag}: {err}");
    // A first run that fails leaves its report where it was asked to.
    let failed = out;
    let r = common::report_of(&failed);
    assert_eq!(r["verdict"]["status"], "failed", "{tag}");
    for program in ["program.mpf", "program.nc", "program.cld"] {
        assert!(!failed.join(program).exists(), "{tag}: {program}");
    }
    (r, err)
}

/// The collision of the two bodies the report names.
fn collision<'a>(r: &'a Value, a: &str, b: &str) -> &'a Value {
    let pair = format!("the {a} and the {b} collide");
    r["verdict"]["failures"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| {
            f["rule"] == "bodies clear of each other"
                && f["message"].as_str().is_some_and(|m| m.contains(&pair))
        })
        .unwrap_or_else(|| panic!("no '{pair}' in {}", r["verdict"]))
}

#[test]
fn a_guard_that_wraps_the_wheel_round_through_the_part_is_refused() {
    // Wrapped over 350 degrees, 280 mm round the wheel's centre, the
    // guard's wall passes through the mandrel on the side away from the
    // wheel.
    let text = machine_with(
        "3K152VF20",
        &[
            ("guard_inner = 310.0", "guard_inner = 280.0"),
            ("guard_outer = 330.0", "guard_outer = 300.0"),
            ("cover_deg = 200.0", "cover_deg = 350.0"),
        ],
    );
    let (r, err) = refused("guard", "scripts/mandrel.rhai", &text);
    let f = collision(&r, "guard", "blank");
    let message = f["message"].as_str().unwrap();
    // Named as the program numbers it; the scene stands at the first
    // block that failed.
    let block = f["block"].as_str().unwrap();
    assert!(block.starts_with('N') && message.starts_with(block), "{f}");
    assert_eq!(
        r["pose_block"], r["verdict"]["failures"][0]["block_index"],
        "{}",
        r["verdict"]
    );
    assert_eq!(clearance(&r, "guard", "blank"), 0.0);
    assert!(err.contains("the guard and the blank collide"), "{err}");
}

#[test]
fn a_rest_arm_wide_enough_to_reach_the_chuck_is_refused() {
    // 200 mm wide along the part, the arm reaches 100 mm toward the
    // headstock from the rest's centre: past the chuck's face when the
    // rest stands nearest it.
    let text = machine_with(
        "3K152VF20",
        &[("rest_arm_width = 40.0", "rest_arm_width = 200.0")],
    );
    let (r, _) = refused("rest-arm", "scripts/mandrel.rhai", &text);
    collision(&r, "chuck", "rest_arm");
    // The default arm clears it: the same pair, measured, is the margin.
    assert_eq!(clearance(&r, "chuck", "rest_arm"), 0.0);
}

#[test]
fn a_chuck_too_close_to_the_threads_run_out_is_refused() {
    // Jaws 5 mm beyond the worm's end: the cutter runs out 7.5 mm past it.
    let text = machine_with("fanuc-0i-tc", &[("chuck_gap = 30.0", "chuck_gap = 5.0")]);
    let (r, _) = refused("chuck", "scripts/worm.rhai", &text);
    let f = collision(&r, "cutter", "chuck");
    assert!(f["block"].as_str().unwrap().starts_with("block "), "{f}");
    assert_eq!(clearance(&r, "cutter", "chuck"), 0.0);
}

/// The scene stands each body where the collision check does: the guard
/// and the flanges on the wheel's centre (its radius from the programmed
/// point), the chuck gripping the blank's start, the tailstock's centre at
/// its end.
#[test]
fn the_scene_places_each_body_as_the_check_does() {
    let out = scratch("collisions", "scene").join("out");
    let (code, _, err) = pilgrim(&["run", "scripts/mandrel.rhai", "--out", s(&out), "--quiet"]);
    assert_eq!(code, 0, "{err}");
    let at = common::scene_nodes(&out);
    let wheel = at("wheel");
    for body in ["guard", "hub"] {
        let b = at(body);
        let d: Vec<f32> = (0..3).map(|k| b[k] - wheel[k]).collect();
        // The default wheel is 500 mm across.
        assert!(
            (d[0] - 250.0).abs() < 1e-3 && d[1].abs() < 1e-3 && d[2].abs() < 1e-3,
            "{body}: {d:?}"
        );
    }
    let r = common::report_of(&out);
    let blank = r["bodies"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["name"] == "blank")
        .unwrap()
        .clone();
    assert_eq!(blank["kind"], "part");
    // The blank runs from z = -303 (the tail) to 440 (the cone's end):
    // the chuck (110 long) grips 40 of it, the centre (50 long) stands
    // beyond its end.
    assert!((at("chuck")[2] - (-303.0 + 40.0 - 55.0)).abs() < 1e-3);
    assert!((at("tailstock_centre")[2] - (440.0 + 25.0)).abs() < 1e-3);
}

/// The scene plays the program: `scene.glb` carries one animation whose
/// keys are the blocks' ends at the times the machine reaches them, the
/// wheel where the chain puts it for the block's X and Z, the rest where
/// its chain puts it for Z and U, the last key at the cycle time.
#[test]
fn the_scene_plays_the_program_block_by_block() {
    let out = scratch("collisions", "playback").join("out");
    let (code, _, err) = pilgrim(&["run", "scripts/mandrel.rhai", "--out", s(&out), "--quiet"]);
    assert_eq!(code, 0, "{err}");
    let glb = std::fs::read(out.join("scene.glb")).unwrap();
    let doc = gltf::Gltf::from_slice(&glb).unwrap();
    let blob = doc.blob.clone().unwrap();
    let animation = doc.animations().next().expect("an animation");
    let program: Value =
        serde_json::from_slice(&std::fs::read(out.join("program.json")).unwrap()).unwrap();
    let blocks = program["blocks"].as_array().unwrap();
    let last = &blocks[blocks.len() - 1]["values"];
    let (z, x, u) = (
        last[0].as_f64().unwrap(),
        last[1].as_f64().unwrap(),
        last[2].as_f64().unwrap(),
    );
    let r = common::report_of(&out);
    let cycle_s = 60.0 * r["times"]["accelerated_min"].as_f64().unwrap();
    let mut tracks = std::collections::BTreeMap::new();
    for channel in animation.channels() {
        let node = channel.target().node().name().unwrap().to_owned();
        let reader = channel.reader(|_| Some(&blob[..]));
        let times: Vec<f32> = reader.read_inputs().unwrap().collect();
        assert!(
            times.len() > 100 && times.len() <= blocks.len(),
            "{}",
            times.len()
        );
        assert!(((*times.last().unwrap() as f64) - cycle_s).abs() < 1e-3 * cycle_s);
        if let gltf::animation::util::ReadOutputs::Translations(t) = reader.read_outputs().unwrap()
        {
            tracks.insert(node, t.last().unwrap());
        }
    }
    // The wheel's programmed point is the tool frame's origin: (X, 0, Z).
    let wheel = tracks["wheel"];
    assert!((wheel[0] as f64 - x).abs() < 1e-3 && (wheel[2] as f64 - z).abs() < 1e-3);
    // The rest's support centre: U on the far side, B = -180 mm along Z.
    let rest = tracks["rest"];
    assert!((rest[0] as f64 + u).abs() < 1e-3 && (rest[2] as f64 - (z - 180.0)).abs() < 1e-3);
    // The guard rides the wheel's centre; the chuck stands still.
    assert!((tracks["guard"][0] as f64 - (x + 250.0)).abs() < 1e-3);
    assert!(!tracks.contains_key("chuck"));
}
