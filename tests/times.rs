//! Honest times: the cycle time with every move ramped within the axes'
//! acceleration, per pass and in all, beside the time at the programmed
//! feeds. Checked against what must hold whatever the model's details: a
//! ramped move is never faster than at its feed; a machine that states no
//! acceleration runs every move at its feed (the two times agree but for
//! the threads' waits for the spindle's one-revolution signal); a
//! slower-accelerating machine takes longer, a faster one comes nearer the
//! programmed time.

use crate::common;

use common::{pilgrim, s, scratch};
use serde_json::Value;

/// The worm's default job on the lathe as the machine file `text` (or the
/// plugin) describes it: its report's `times`.
fn worm_times(tag: &str, text: Option<String>) -> Value {
    let dir = scratch("times", tag);
    let out = dir.join("out");
    let mut args = vec!["run", "scripts/worm.rhai", "--out", s(&out), "--quiet"];
    let file = dir.join("lathe.toml");
    if let Some(text) = text {
        std::fs::write(&file, text).unwrap();
        args.extend(["--machine", s(&file)]);
    }
    let (code, _, err) = pilgrim(&args);
    assert_eq!(code, 0, "{tag}: {err}");
    let r: Value = common::report_of(&out);
    assert_eq!(r["cycle_time_min"].as_f64().unwrap(), {
        let t = r["times"]["accelerated_min"].as_f64().unwrap();
        (t * 1e4).round() / 1e4
    });
    r["times"].clone()
}

fn lathe(edit: impl Fn(&str) -> String) -> String {
    let (code, text, err) = pilgrim(&["machines", "--toml", "fanuc-0i-tc"]);
    assert_eq!(code, 0, "{err}");
    edit(&text)
}

fn min(t: &Value, key: &str) -> f64 {
    t[key].as_f64().unwrap()
}

#[test]
fn a_ramped_program_is_never_faster_than_its_feeds_and_slower_as_the_axes_are() {
    let t = worm_times("plugin", None);
    // Each of the 78 thread passes waits half a turn at 100 rpm for the
    // spindle's one-revolution signal.
    let sync_min = t["thread_sync_s"].as_f64().unwrap() / 60.0;
    assert!((sync_min * 60.0 - 78.0 * 0.3).abs() < 1e-9, "{t}");
    let (fed, ramped) = (
        min(&t, "programmed_min"),
        min(&t, "accelerated_min") - sync_min,
    );
    // 78 thread passes, each starting and ending at rest: seconds more.
    assert!(ramped > fed && ramped < 1.2 * fed, "{t}");
    let passes = t["passes"].as_array().unwrap();
    assert_eq!(passes.len(), 78);
    let (mut sum_fed, mut sum_ramped) = (0.0, 0.0);
    for p in passes {
        let (a, b) = (min(p, "programmed_min"), min(p, "accelerated_min"));
        assert!(b >= a - 1e-12, "{p}");
        sum_fed += a;
        sum_ramped += b;
    }
    // The passes hold every block but the program's start and end.
    assert!(sum_fed <= fed + 1e-9 && sum_ramped <= ramped + sync_min + 1e-9);
    assert!(t.get("unramped_axes").is_none(), "{t}");

    // Stating no acceleration: every move at its feed, rapids at their
    // slowest axis's top speed: the two times agree but for the waits.
    let free = worm_times(
        "free",
        Some(lathe(|text| {
            text.lines()
                .filter(|l| !l.starts_with("max_accel"))
                .collect::<Vec<_>>()
                .join("\n")
        })),
    );
    assert!(
        (min(&free, "accelerated_min") - sync_min - min(&free, "programmed_min")).abs() < 1e-9,
        "{free}"
    );
    assert_eq!(free["unramped_axes"], serde_json::json!(["X", "Z"]));
    assert!((min(&free, "programmed_min") - fed).abs() < 1e-12);

    // A tenth of the acceleration takes longer; a hundred times as much
    // comes within a tenth of the extra time of the programmed time.
    let scaled = |k: f64, tag: &str| {
        worm_times(
            tag,
            Some(lathe(|text| {
                text.replace("max_accel = 6000.0", &format!("max_accel = {}", 6000.0 * k))
                    .replace("max_accel = 3000.0", &format!("max_accel = {}", 3000.0 * k))
            })),
        )
    };
    let slow = scaled(0.1, "slow");
    assert!(min(&slow, "accelerated_min") - sync_min > ramped, "{slow}");
    let quick = scaled(100.0, "quick");
    let extra = min(&quick, "accelerated_min") - sync_min - fed;
    assert!(extra > 0.0 && extra < 0.1 * (ramped - fed), "{quick}");
}
