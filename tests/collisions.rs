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
            let (d, floor) = (
                c["clearance_mm"].as_f64().unwrap(),
                c["at_least_mm"].as_f64().unwrap(),
            );
            assert!(d > 0.0, "{job}: {c}");
            // The least the sweep allows is below the smallest found and,
            // the default jobs being clear, above nothing.
            assert!(floor > 0.0 && floor <= d, "{job}: {c}");
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
        assert!(page.contains("<th>at least (mm)</th>"), "{job}");
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
    let f = collision(&r, "chuck", "rest_arm");
    // What would resolve it: the constants that place and size both, the
    // family's parameter that restates one, where the part is held, by
    // how much they overlap.
    let message = f["message"].as_str().unwrap();
    for named in [
        "the chuck's constants chuck_grip, chuck_length, chuck_radius",
        "rest_offset_b (the family's rest_b)",
        "rest_arm_width",
        "where the family's part starts (z = ",
        "they overlap by ",
    ] {
        assert!(message.contains(named), "{named}: {message}");
    }
    // The default arm clears it: the same pair, measured, is the margin.
    assert_eq!(clearance(&r, "chuck", "rest_arm"), 0.0);
}

#[test]
fn a_chuck_too_close_to_the_threads_run_out_is_refused() {
    // Jaws 5 mm beyond the worm's end: the cutter runs out 7.5 mm past it.
    let text = machine_with("fanuc-0i-tc", &[("chuck_gap = 30.0", "chuck_gap = 5.0")]);
    let (r, _) = refused("chuck", "scripts/worm.rhai", &text);
    let f = collision(&r, "cutter", "chuck");
    // A Fanuc program numbers no block: it is named by its line.
    assert!(f["block"].as_str().unwrap().starts_with("line "), "{f}");
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
    let play = common::Playback::of(&out);
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
    for ((node, path), (times, values)) in &play.channels {
        assert!(((*times.last().unwrap() as f64) - cycle_s).abs() < 1e-3 * cycle_s);
        if node == "part turn" {
            continue;
        }
        assert!(
            times.len() > 100 && times.len() <= blocks.len(),
            "{}",
            times.len()
        );
        if path == "translation" {
            tracks.insert(node.clone(), values.last().unwrap().clone());
        }
    }
    // The wheel's programmed point is the tool frame's origin: (X, 0, Z).
    let wheel = &tracks["wheel"];
    assert!((wheel[0] as f64 - x).abs() < 1e-3 && (wheel[2] as f64 - z).abs() < 1e-3);
    // The rest's support centre: U on the far side, B = -180 mm along Z.
    let rest = &tracks["rest"];
    assert!((rest[0] as f64 + u).abs() < 1e-3 && (rest[2] as f64 - (z - 180.0)).abs() < 1e-3);
    // The guard rides the wheel's centre; the chuck turns with the part.
    assert!((tracks["guard"][0] as f64 - (x + 250.0)).abs() < 1e-3);
    assert!(!tracks.contains_key("chuck"));
    for body in ["blank", "part", "chuck", "tailstock_centre"] {
        assert!(
            play.turning.iter().any(|b| b == body),
            "{body}: {:?}",
            play.turning
        );
    }
    for body in ["wheel", "rest", "guard"] {
        assert!(!play.turning.iter().any(|b| b == body), "{body}");
    }
    // The work spindle turns the part at the program's S, M3 (about +Z),
    // each key a third of a turn or less from the one before.
    let (times, angles) = play.spin();
    let steps: Vec<f64> = angles.windows(2).map(|w| w[1] - w[0]).collect();
    assert!(steps
        .iter()
        .all(|d| (0.0..=std::f64::consts::TAU / 3.0 + 1e-6).contains(d)));
    let rpm = program["spindle_rpm"].as_f64().unwrap();
    let turned = (angles.last().unwrap() - angles[0]) / std::f64::consts::TAU;
    let spun = rpm / 60.0 * (*times.last().unwrap() - times[0]) as f64;
    assert!(
        (turned - spun).abs() < 1e-4 * spun,
        "{turned} turns for {spun}"
    );
}

/// The caliber's roll turns as its A turns it, the rest of the machine in
/// its own frame: at each key the part's turn is the block's A, and the
/// wheel's centre stands where the slides put it, (Z, Y, X), whatever A is
/// (the chain `Rz(-A) Tz(X) Tx(Z) Ty(Y) Rx(B)` with its first factor
/// taken by the roll).
#[test]
fn the_roll_turns_as_its_axis_turns_it() {
    let out = scratch("collisions", "roll-turn").join("out");
    let (code, _, err) = pilgrim(&["run", "scripts/caliber.rhai", "--out", s(&out), "--quiet"]);
    assert_eq!(code, 0, "{err}");
    let play = common::Playback::of(&out);
    let program: Value =
        serde_json::from_slice(&std::fs::read(out.join("program.json")).unwrap()).unwrap();
    let names: Vec<&str> = program["axes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["name"].as_str().unwrap())
        .collect();
    let col = |n: &str| names.iter().position(|&m| m == n).unwrap();
    let blocks = program["blocks"].as_array().unwrap();
    let (times, centres) = play.channel("wheel", "translation");
    assert_eq!(times.len(), play.keys.len());
    let (mut worst_turn, mut worst_centre, mut swept) = (0.0_f64, 0.0_f64, (f64::MAX, f64::MIN));
    for (i, &(k, t)) in play.keys.iter().enumerate() {
        assert_eq!(times[i], t);
        let v = |n: &str| blocks[k]["values"][col(n)].as_f64().unwrap();
        let a = v("A").to_radians();
        let turn = play.spin_at(t);
        let off = (turn - a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        worst_turn = worst_turn.max(off.abs());
        let want = [v("Z"), v("Y"), v("X")];
        for j in 0..3 {
            worst_centre = worst_centre.max((centres[i][j] as f64 - want[j]).abs());
        }
        swept = (swept.0.min(a), swept.1.max(a));
    }
    assert!(
        worst_turn < 1e-5,
        "the roll's turn strays {worst_turn} rad from A"
    );
    assert!(
        worst_centre < 1e-3,
        "the wheel strays {worst_centre} mm from its slides"
    );
    // The roll does turn: A sweeps the groove.
    assert!(swept.1 - swept.0 > 1.0, "{swept:?}");
    for body in ["caliber", "arbor", "collar_front", "collar_back"] {
        assert!(
            play.turning.iter().any(|b| b == body),
            "{body}: {:?}",
            play.turning
        );
    }
}

/// The worm turns with its spindle, M3, and in every thread block the
/// cutter's point stays on one helix of the worm as the lead ties the turn
/// to the travel: the point in the part frame (the machine frame turned
/// back by the part's turn) keeps `z - lead * phi / 2 pi` from the block's
/// start to its end, a right-hand thread.
#[test]
fn the_worm_turns_under_the_cutter_as_the_lead_ties_them() {
    let out = scratch("collisions", "worm-turn").join("out");
    let (code, _, err) = pilgrim(&["run", "scripts/worm.rhai", "--out", s(&out), "--quiet"]);
    assert_eq!(code, 0, "{err}");
    let play = common::Playback::of(&out);
    let program: Value =
        serde_json::from_slice(&std::fs::read(out.join("program.json")).unwrap()).unwrap();
    let blocks = program["blocks"].as_array().unwrap();
    let (times, points) = play.channel("cutter", "translation");
    let (_, angles) = play.spin();
    assert!(
        angles.windows(2).all(|w| w[1] >= w[0]),
        "the spindle turns M3 throughout"
    );
    let at_key: std::collections::BTreeMap<usize, usize> = play
        .keys
        .iter()
        .enumerate()
        .map(|(i, &(k, t))| {
            assert_eq!(times[i], t);
            (k, i)
        })
        .collect();
    let tau = std::f64::consts::TAU;
    let helix = |i: usize, lead: f64| {
        let p = &points[i];
        let turn = play.spin_at(times[i]);
        // The point turned back by the part's turn.
        let (s, c) = (-turn).sin_cos();
        let (x, y) = (
            c * p[0] as f64 - s * p[1] as f64,
            s * p[0] as f64 + c * p[1] as f64,
        );
        p[2] as f64 - lead * y.atan2(x) / tau
    };
    let (mut threads, mut worst) = (0, 0.0_f64);
    for (k, b) in blocks.iter().enumerate() {
        let Some(lead) = b["motion"]["lead"].as_f64() else {
            continue;
        };
        let (Some(&i0), Some(&i1)) = (at_key.get(&(k - 1)), at_key.get(&k)) else {
            panic!("thread block {} has no keys at its ends", k + 1);
        };
        let d = helix(i1, lead) - helix(i0, lead);
        worst = worst.max(((d + lead / 2.0).rem_euclid(lead) - lead / 2.0).abs());
        threads += 1;
    }
    assert!(threads > 10, "{threads}");
    assert!(worst < 1e-3, "the cutter leaves its helix by {worst} mm");
}

/// Which axis turns the part is the machine's data: the caliber grinders'
/// A, the grinder's work spindle and the lathe's spindle say so, and a
/// machine file is held to it where it is read: a linear axis cannot, and
/// a rotary axis only as an Rz that nothing but turns and moves along Z
/// stand before in the chain (then the part's turn leads it); a chain that
/// only commutes those factors is the same machine and loads.
#[test]
fn an_axis_turns_the_part_only_as_the_chain_allows() {
    let (code, list, err) = pilgrim(&["machines"]);
    assert_eq!(code, 0, "{err}");
    for line in [
        "A   rotary   [-370, 370] deg, up to 3600 deg/min [turns the part]",
        "S   spindle  up to 630 rpm [turns the part]",
        "S   spindle  up to 3500 rpm [turns the part]",
        "S   spindle  up to 3000 rpm  wheel spindle",
    ] {
        assert!(list.contains(line), "{line}\n{list}");
    }
    let dir = scratch("collisions", "turns-part");
    let load = |name: &str, text: &str| {
        let file = dir.join(name);
        std::fs::write(&file, text).unwrap();
        pilgrim(&["machines", "--file", s(&file)])
    };
    let linear = machine_with(
        "LZ-250",
        &[(
            "moves = [0.0, 0.0, 1.0]\n",
            "moves = [0.0, 0.0, 1.0]\nturns_part = true\n",
        )],
    );
    let (code, _, err) = load("linear.toml", &linear);
    assert_ne!(code, 0);
    assert!(
        err.contains("axis X: turns_part cannot be set: a linear axis moves the part"),
        "{err}"
    );
    // Tz(X) Tx(Z) Rz(-A): the turn no longer leads.
    let rz = "[[chain]]\nfactor = \"rz\"\naxis = \"A\"\nscale = -1.0\n\n";
    let (tz, tx) = (
        "[[chain]]\nfactor = \"tz\"\naxis = \"X\"\n\n",
        "[[chain]]\nfactor = \"tx\"\naxis = \"Z\"\n\n",
    );
    let behind = machine_with(
        "LZ-250",
        &[(&format!("{rz}{tz}{tx}"), &format!("{tz}{tx}{rz}"))],
    );
    let (code, _, err) = load("behind.toml", &behind);
    assert_ne!(code, 0);
    assert!(
        err.contains("axis A: turns_part, but its factor is the tool chain's number 3, Rz"),
        "{err}"
    );
    let commuted = machine_with("LZ-250", &[(&format!("{rz}{tz}"), &format!("{tz}{rz}"))]);
    let (code, _, err) = load("commuted.toml", &commuted);
    assert_eq!(code, 0, "{err}");
}
