//! The seeds' machines (their plugin crates' descriptors) and the data
//! built-in: each loads (which checks its stated signs against its chain),
//! their geometry is the seeds', and bad files (the lathe's, written from
//! its descriptor) are refused with the key and line named.

use pilgrim_kernel::machine::{machine_file, BUILTIN_MACHINES};
use pilgrim_kernel::{assert_near, AxisKind, Machine, MachineError, Point3, ToolFrame};

#[test]
fn every_machine_loads_and_states_every_sign() {
    let mut machines: Vec<Machine> = BUILTIN_MACHINES
        .iter()
        .map(|name| Machine::builtin(name).unwrap_or_else(|e| panic!("{name}: {e}")))
        .collect();
    for info in [
        grinder_3k152vf20::describe(),
        lz_250::describe(),
        mannesmann::describe(),
        fanuc_0i_tc::describe(),
    ] {
        machines.push(Machine::from_info(info).unwrap());
    }
    for m in &machines {
        let name = m.name();
        for a in m.axes() {
            match a.kind {
                AxisKind::Linear => assert!(a.moves.is_some(), "{name} {}", a.name),
                AxisKind::Rotary => assert!(a.turns.is_some(), "{name} {}", a.name),
                AxisKind::Spindle => assert!(!a.programmed),
            }
        }
    }
    assert!(Machine::builtin("Vertical-Mill").is_ok());
    let e = Machine::builtin("planer").unwrap_err();
    assert!(e.to_string().contains("built-ins: vertical-mill"), "{e}");
}

#[test]
fn caliber_grinders_turn_the_roll_and_swivel_the_wheel_as_stated() {
    for info in [lz_250::describe(), mannesmann::describe()] {
        let m = Machine::from_info(info).unwrap();
        let c = m.chain();
        let mut q = vec![0.0; c.dof()];
        q[c.axis_index("Z").unwrap()] = 200.0;
        q[c.axis_index("A").unwrap()] = 90f64.to_radians();
        // The roll turned +90 deg: the wheel is at -90 deg round it.
        let p = c.pose(&q, &ToolFrame::default()).unwrap();
        assert_near!(p.point.x, 0.0, 1e-12);
        assert_near!(p.point.y, -200.0, 1e-12);
        // A +10 deg swivel at A = 0 tilts the wheel's axis toward -Y.
        q[c.axis_index("A").unwrap()] = 0.0;
        q[c.axis_index("B").unwrap()] = 10f64.to_radians();
        let p = c.pose(&q, &ToolFrame::default()).unwrap();
        assert_near!(p.axis.y, -(10f64.to_radians().sin()), 1e-12);
    }
    assert!(lz_250::describe().axes.iter().all(|a| a.name != "Y"));
    assert!(mannesmann::describe().axes.iter().any(|a| a.name == "Y"));
}

#[test]
fn lathe_programs_diameter() {
    let m = Machine::from_info(fanuc_0i_tc::describe()).unwrap();
    assert_eq!(m.chain().axis_names(), ["X", "Z"]);
    let p = m.chain().apply(&[100.0, -30.0], &Point3::origin()).unwrap();
    assert_eq!(p, Point3::new(50.0, 0.0, -30.0));
    assert_eq!(m.control(), "fanuc");
}

/// The Fanuc lathe's machine file, written from its plugin's descriptor.
fn lathe_text() -> String {
    machine_file(&fanuc_0i_tc::describe(), "the fanuc-0i-tc crate")
}

/// Line (from 1) of the first line of `text` containing `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

fn file_error(text: &str) -> (usize, String) {
    match Machine::from_toml_str(text, "m.toml").unwrap_err() {
        MachineError::File {
            line,
            message,
            file,
            ..
        } => {
            assert_eq!(file, "m.toml");
            (line, message)
        }
        other => panic!("not a file error: {other}"),
    }
}

#[test]
fn bad_machine_files_name_the_key_and_line() {
    // (edit of the lathe's file: from, to; the line the error must name, by a
    // piece of its text, or None for any line; a piece of the message)
    let cases: [(&str, &str, Option<&str>, &str); 11] = [
        // A wrong stated sign.
        (
            "moves = [0.5, 0.0, 0.0]",
            "moves = [-0.5, 0.0, 0.0]",
            Some("moves = [-0.5"),
            "axis X: moves = [-0.5, 0, 0] but the chain moves it by [0.5",
        ),
        // A missing limit, named at its axis.
        (
            "max_feed = 12000.0\n",
            "",
            Some("name = \"X\""),
            "axis X (linear) needs key 'max_feed'",
        ),
        // An undeclared axis in the chain.
        (
            "axis = \"Z\"",
            "axis = \"W\"",
            Some("axis = \"W\""),
            "'W', which is not declared",
        ),
        // Reversed travel.
        (
            "max = 400.0",
            "max = -400.0",
            Some("max = -400.0"),
            "travel max must exceed min",
        ),
        // Degrees on a linear axis, an unknown key, a syntax error, infinity.
        (
            "min = -10.0",
            "min_deg = -10.0",
            Some("min_deg"),
            "'min_deg' does not apply to a linear axis",
        ),
        ("min = -10.0", "minimum = -10.0", Some("minimum"), "minimum"),
        ("max = 400.0", "max = 400.0.0", Some("400.0.0"), ""),
        (
            "max = 400.0",
            "max = inf",
            Some("max = inf"),
            "not a finite number",
        ),
        // A rotary factor on a linear axis, and a spindle bound in the chain.
        (
            "factor = \"tz\"\naxis = \"Z\"",
            "factor = \"rz\"\naxis = \"Z\"",
            None,
            "axis Z is linear but factor rz needs a rotary axis",
        ),
        ("axis = \"Z\"", "axis = \"S\"", None, "axis S is spindle"),
        // A feed that is not positive.
        (
            "max_feed = 12000.0",
            "max_feed = -1.0",
            Some("name = \"X\""),
            "axis X: the maximum feed must be > 0",
        ),
    ];
    for (from, to, at, expected) in cases {
        let text = lathe_text().replacen(from, to, 1);
        assert_ne!(text, lathe_text(), "the edit {from:?} did not apply");
        let (line, msg) = file_error(&text);
        if let Some(piece) = at {
            assert_eq!(line, line_of(&text, piece), "{to:?}: {msg}");
        }
        assert!(msg.contains(expected), "{to:?}: {msg}");
    }
}

#[test]
fn machine_files_load_from_disk_and_say_which_file_is_missing() {
    let dir = std::env::temp_dir().join(format!("pilgrim-machines-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("lathe.toml");
    std::fs::write(&path, lathe_text()).unwrap();
    let m = Machine::from_file(&path).unwrap();
    assert_eq!(m.name(), "fanuc-0i-tc");
    let e = Machine::from_file(dir.join("none.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("none.toml"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}
