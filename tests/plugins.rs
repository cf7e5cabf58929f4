//! Machine plugins loaded from shared libraries: the 3K152VF20 plugin
//! against its compiled-in self, and fixtures that break the ABI.

use pilgrim_kernel::machine::MachineKinematics;
use pilgrim_kernel::plugin::{PluginLoadError, PluginMachine};
use pilgrim_kernel::program::{build, PostProcessor, SharedPost};
use pilgrim_kernel::transform::ToolFrame;
use pilgrim_kernel::{equidistant, ClPoint, MandrelLaw, Motion, Pass, Side, Tool, Toolpath, Wheel};
use pilgrim_plugin_abi::{CAP_ABI_1_0, CAP_FORWARD, CAP_INVERSE};
use std::path::PathBuf;

use crate::common;
use common::{grinder as built_in, shared_lib as lib};

/// The fixture library under another name, selecting its entry. A copy is
/// made once and renamed into place: a library the process has mapped is
/// never written over.
fn fixture_as(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("pilgrim-plugins-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = format!(
        "{}{name}{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    );
    let to = dir.join(&file);
    if !to.exists() {
        let tmp = dir.join(format!("{file}.{:?}.tmp", std::thread::current().id()));
        std::fs::copy(lib("plugin_fixture"), &tmp).unwrap();
        std::fs::rename(&tmp, &to).unwrap();
    }
    to
}

/// Two passes of a 20 mm wheel rounding over a mandrel's working part,
/// with the steady rest's U alongside.
fn grinder_toolpath() -> Toolpath {
    let wheel = Wheel::new(500.0, 20.0, 50.0).unwrap();
    let law = MandrelLaw::new(38.0, 52.0, 400.0, 0.012, 2.3).unwrap();
    let e = equidistant(&law.profile(2.0, 100.0).unwrap(), 20.0, Side::Outside).unwrap();
    let mut tp = Toolpath::new(
        "mandrel",
        Tool::wheel("wheel 500x50 R20", 1, wheel),
        399.0,
        vec!["U".into()],
    );
    for (k, stock) in [0.1, 0.0].into_iter().enumerate() {
        let mut idx: Vec<usize> = (0..e.z.len()).collect();
        if k % 2 == 1 {
            idx.reverse();
        }
        tp.passes.push(Pass {
            name: format!("pass {}", k + 1),
            points: idx
                .iter()
                .map(|&i| ClPoint {
                    point: [e.x[i] + stock, 0.0, e.z[i]],
                    axis: [0.0, 0.0, 1.0],
                    motion: Motion::Linear,
                    feed: 2000.0,
                    aux: vec![e.x[i] - 20.0 + 25.0],
                })
                .collect(),
        });
    }
    tp
}

#[test]
fn grinder_plugin_loaded_gives_byte_identical_programs() {
    let built_in = built_in();
    let loaded = PluginMachine::load(lib("grinder_3k152vf20")).unwrap();
    assert_eq!(
        loaded.abi_version(),
        (pilgrim_plugin_abi::ABI_MAJOR, pilgrim_plugin_abi::ABI_MINOR)
    );
    assert_eq!(loaded.info(), built_in.info());
    assert_eq!(loaded.info(), &grinder_3k152vf20::describe());
    // The grinder solves Z and X, takes U from the toolpath, and leaves
    // posting to the host.
    assert_eq!(loaded.capabilities(), CAP_INVERSE | CAP_FORWARD);
    assert!(loaded.post_processor().is_none());
    assert_eq!(loaded.info().driven_axes, ["U"]);
    let tp = grinder_toolpath();
    let a = build(&tp, &built_in, "mandrel").unwrap();
    let b = build(&tp, &loaded, "mandrel").unwrap();
    assert_eq!(a, b);
    assert_eq!(
        a.axes.iter().map(|x| x.name.as_str()).collect::<Vec<_>>(),
        ["Z", "X", "U"]
    );
    for dialect in ["sinumerik", "cld"] {
        let text = SharedPost.post(&a, dialect).unwrap();
        assert!(text.len() > 1000);
    }
    // The programmed X is the wheel's lowest point: the rounding centre minus
    // R_s (after the machine's start blocks).
    let lead = pilgrim_kernel::program::start_blocks(&a.setup);
    assert_eq!(lead, 3);
    let x = a.column("X").unwrap();
    assert!((x[lead] - (tp.passes[0].points[0].point[0] - 20.0)).abs() < 1e-12);
    // Forward kinematics through the library returns the toolpath's points.
    let rows: Vec<f64> = a.blocks[lead..]
        .iter()
        .flat_map(|b| [b.values[0], b.values[1]])
        .collect();
    let mut poses = vec![];
    loaded
        .forward(&rows, &tp.tool.reference, &mut poses)
        .unwrap();
    for ((_, _, c), p) in tp.points().zip(poses.chunks(6)) {
        assert!((c.point[0] - p[0]).abs() < 1e-12 && (c.point[2] - p[2]).abs() < 1e-12);
    }
}

#[test]
fn another_abi_major_is_refused_naming_both() {
    for (name, major, minor) in [("other_abi", 99, 3), ("old_abi", 0, 9)] {
        let e = PluginMachine::load(fixture_as(name)).unwrap_err();
        assert!(
            matches!(e, PluginLoadError::Version { plugin_major, .. } if plugin_major == major),
            "{e}"
        );
        let text = e.to_string();
        assert!(
            text.contains(&format!("ABI {major}.{minor}"))
                && text.contains(&format!(
                    "pilgrim ABI {}.{}",
                    pilgrim_plugin_abi::ABI_MAJOR,
                    pilgrim_plugin_abi::ABI_MINOR
                )),
            "{text}"
        );
    }
}

/// A plugin built against ABI 1.0 (no capabilities field) loads, offering
/// what 1.0 required, whatever lies beyond its table.
#[test]
fn a_minor_older_plugin_loads() {
    let m = PluginMachine::load(fixture_as("abi_1_0")).unwrap();
    assert_eq!(m.abi_version(), (1, 0));
    assert_eq!(m.capabilities(), CAP_ABI_1_0);
    assert!(m.post_processor().is_some());
}

#[test]
fn broken_plugins_are_clear_errors() {
    let e = PluginMachine::load(fixture_as("null_table"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("returned no table"), "{e}");
    let e = PluginMachine::load(fixture_as("no_post"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("no 'post' entry"), "{e}");
    // A size that cuts an entry in half: the entry is not read, and missing.
    let e = PluginMachine::load(fixture_as("half_table"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("no 'free_buffer' entry (table of 60 bytes)"),
        "{e}"
    );
    let e = PluginMachine::load(fixture_as("bad_descriptor"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("bad machine descriptor"), "{e}");
    // A library of several entries, none named for its file.
    let e = PluginMachine::load(fixture_as("no_such_entry"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("none is named for its file (pilgrim_plugin_no_such_entry)"),
        "{e}"
    );
    let e = PluginMachine::load("/no/such/libplugin.so")
        .unwrap_err()
        .to_string();
    assert!(e.contains("/no/such/libplugin.so: No such file"), "{e}");
    // A complete ELF object that is no plugin (an executable): refused
    // from its bytes, before anything of it runs.
    let dir = std::env::temp_dir().join(format!("pilgrim-plugins-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let exe = dir.join("libtrue.so");
    std::fs::copy("/bin/true", &exe).unwrap();
    let e = PluginMachine::load(&exe).unwrap_err().to_string();
    assert!(
        e.contains("exports no function named pilgrim_plugin_*"),
        "{e}"
    );
}

/// A plugin whose construction panics is an error naming the panic, and
/// the host goes on.
#[test]
fn a_plugin_whose_default_panics_is_an_error() {
    for _ in 0..2 {
        let e = PluginMachine::load(fixture_as("default_panics"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("bad machine descriptor: the plugin panicked: the fixture cannot be built"),
            "{e}"
        );
    }
}

#[test]
fn a_panicking_plugin_returns_an_error_and_the_host_goes_on() {
    let m = PluginMachine::load(fixture_as("panics")).unwrap();
    let tool = ToolFrame::default();
    let mut out = vec![];
    m.inverse(&[10.0, 0.0, -5.0, 0.0, 0.0, 1.0], &tool, &mut out)
        .unwrap();
    assert_eq!(out, [20.0, -5.0]);
    let e = m
        .inverse(
            &[
                10.0, 0.0, -5.0, 0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
            ],
            &tool,
            &mut out,
        )
        .unwrap_err();
    assert!(
        e.message.contains("panicked") && e.message.contains("negative radius -1"),
        "{e}"
    );
    let e = m.forward(&[1.0, 2.0], &tool, &mut out).unwrap_err();
    assert!(e.message.contains("not offered"), "{e}");
    // The host goes on: the same plugin answers again.
    m.inverse(&[3.0, 0.0, 1.0, 0.0, 0.0, 1.0], &tool, &mut out)
        .unwrap();
    assert_eq!(out, [6.0, 1.0]);
    assert_eq!(m.info().name, "fixture-lathe");
    // It posts its own programs: the request reaches it as JSON.
    let tp = {
        let mut tp = Toolpath::new(
            "t",
            Tool::end_mill("m", 1, 6.0, 10.0).unwrap(),
            500.0,
            vec![],
        );
        tp.passes.push(Pass {
            name: "p".into(),
            points: vec![ClPoint {
                point: [10.0, 0.0, -5.0],
                axis: [0.0, 0.0, 1.0],
                motion: Motion::Rapid,
                feed: 0.0,
                aux: vec![],
            }],
        });
        tp
    };
    let program = build(&tp, &m, "t").unwrap();
    let text = m.post_processor().unwrap().post(&program, "fanuc").unwrap();
    assert_eq!(text, "%\n(1 BLOCKS IN FANUC)\n%\n");
}

/// A value beyond travel that kinematics does not see (the rest's U) is
/// caught by the program's checks, naming the block and the axis.
#[test]
fn rest_beyond_travel_names_the_block() {
    let mut tp = grinder_toolpath();
    tp.passes[1].points[4].aux[0] = 151.0;
    let first = tp.passes[0].points.len();
    let e = build(&tp, &built_in(), "mandrel").unwrap_err().to_string();
    assert_eq!(
        e,
        format!(
            "{} in \"pass 2\": axis U at 151.0000 mm is outside its travel [0, 150] mm",
            pilgrim_kernel::program::block_label("sinumerik", 3 + first + 4)
        )
    );
}

/// The caliber grinders load from their shared libraries as they are
/// compiled in: the same description, the same axes for the same poses.
#[test]
fn caliber_grinders_load_as_compiled_in() {
    use pilgrim_kernel::machine::MachineKinematics;
    use pilgrim_kernel::math::{Point3, Vec3};
    use pilgrim_kernel::transform::ToolFrame;
    for (lib, compiled) in [
        (
            "lz_250",
            PluginMachine::from_entry(
                "LZ-250",
                "pilgrim_plugin_lz_250",
                lz_250::pilgrim_plugin_lz_250,
            )
            .unwrap(),
        ),
        (
            "mannesmann",
            PluginMachine::from_entry(
                "Mannesmann",
                "pilgrim_plugin_mannesmann",
                mannesmann::pilgrim_plugin_mannesmann,
            )
            .unwrap(),
        ),
    ] {
        let loaded = PluginMachine::load(common::shared_lib(lib)).unwrap();
        assert_eq!(loaded.info(), compiled.info());
        let tool = ToolFrame {
            point: Point3::origin(),
            axis: Vec3::z(),
        };
        let poses: Vec<f64> = (0..20)
            .flat_map(|i| {
                let t = 0.1 * i as f64;
                [
                    150.0 * t.cos(),
                    150.0 * t.sin(),
                    5.0 * t,
                    0.0,
                    -0.1 * t.cos(),
                    1.0,
                ]
            })
            .collect();
        let (mut a, mut b) = (vec![], vec![]);
        loaded.inverse(&poses, &tool, &mut a).unwrap();
        compiled.inverse(&poses, &tool, &mut b).unwrap();
        assert_eq!(a, b, "{lib}");
    }
    // The lathe: poses in the axial section.
    let loaded = PluginMachine::load(common::shared_lib("fanuc_0i_tc")).unwrap();
    let compiled = PluginMachine::from_entry(
        "fanuc-0i-tc",
        "pilgrim_plugin_fanuc_0i_tc",
        fanuc_0i_tc::pilgrim_plugin_fanuc_0i_tc,
    )
    .unwrap();
    assert_eq!(loaded.info(), compiled.info());
    let tool = ToolFrame::default();
    let poses: Vec<f64> = (0..20)
        .flat_map(|i| [20.0 + i as f64, 0.0, 5.0 - 4.0 * i as f64, 0.0, 0.0, 1.0])
        .collect();
    let (mut a, mut b) = (vec![], vec![]);
    loaded.inverse(&poses, &tool, &mut a).unwrap();
    compiled.inverse(&poses, &tool, &mut b).unwrap();
    assert_eq!(a, b, "fanuc_0i_tc");
    assert_eq!(a[0], 40.0);
}

/// A plugin that posts its own programs is held to them: what it writes
/// is linted like the kernel's, and a program that is not the axis
/// program fails the run, naming the place, with no program written.
#[test]
fn a_plugins_own_program_is_linted() {
    let dir = common::scratch("plugins", "own-post");
    let script = dir.join("lathe.rhai");
    std::fs::write(
        &script,
        r#"
fn params() { #{} }
fn toolpath(p) {
    let tool = thread_cutter("cutter", 1, 2.0, 0.1, 20.0, 20.0, 5.0);
    let tp = new_toolpath("turn", tool, 200.0, []);
    tp.add_pass("cut", #{ x: [30.0, 25.0, 25.0], y: 0.0, z: [5.0, 5.0, -20.0], feed: 100.0 });
    tp
}
"#,
    )
    .unwrap();
    let out = dir.join("out");
    let (code, _, err) = common::pilgrim(&[
        "run",
        common::s(&script),
        "--machine",
        common::s(&fixture_as("bad_post")),
        "--out",
        common::s(&out),
        "--quiet",
    ]);
    assert_ne!(code, 0);
    // The fixture posts "%\n(3 BLOCKS IN FANUC)\n%\n": framing a block
    // to paste (which has none), no moves, no end.
    assert!(
        err.contains("lint of the fanuc program")
            && err.contains("line 1: '%': a tape's start or end"),
        "{err}"
    );
    // What failed is in the output, marked FAILED; no program is.
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(page.contains("FAILED") && page.contains("lint of the fanuc program"));
    assert!(!out.join("program.nc").exists() && !out.join("program.cld").exists());
}

/// `pilgrim` run with `args` and `env`, waited for at most `limit` (a
/// plugin's hang must not hang the test): exit code (`None`: ended by a
/// signal) and error stream, and the process's id.
fn pilgrim_bounded(
    args: &[&str],
    env: &[(&str, &std::path::Path)],
    limit: std::time::Duration,
) -> (Option<i32>, String, u32) {
    let m = common::measured(args, env, limit)
        .unwrap_or_else(|| panic!("pilgrim {args:?} did not end within {limit:?}"));
    (m.code, m.err, m.pid)
}

/// The processes still serving the library `lib`.
fn servers_of(lib: &std::path::Path) -> Vec<u32> {
    let mut found = vec![];
    for e in std::fs::read_dir("/proc").unwrap().flatten() {
        let Ok(pid) = e.file_name().to_string_lossy().parse::<u32>() else {
            continue;
        };
        let cmdline = std::fs::read(e.path().join("cmdline")).unwrap_or_default();
        let text = String::from_utf8_lossy(&cmdline);
        if text.contains("plugin-server") && text.contains(lib.to_str().unwrap()) {
            found.push(pid);
        }
    }
    found
}

const LIMIT: std::time::Duration = std::time::Duration::from_secs(300);

/// A plugin that aborts, crashes, exits or hangs in the middle of a run
/// (on a run's long batch; the checks at loading pass) cannot take the
/// host down: the run ends with exit status 1 and an error naming the
/// library, the call and what the plugin did, within the time bound; no
/// program is written, and no process of the plugin is left behind.
#[test]
fn a_plugin_cannot_take_the_host_down() {
    let dir = common::scratch("plugins", "faults");
    for (name, did) in [
        ("trap_abort", "crashed during inverse kinematics"),
        ("trap_segv", "crashed during inverse kinematics"),
        ("trap_exit", "ended its process during inverse kinematics"),
        (
            "trap_hang",
            "did not answer within 2 s during inverse kinematics",
        ),
    ] {
        let lib = fixture_as(name);
        let out = dir.join(name);
        let (code, err, _) = pilgrim_bounded(
            &[
                "run",
                "scripts/worm.rhai",
                "--machine",
                common::s(&lib),
                "--out",
                common::s(&out),
                "--quiet",
                "--plugin-seconds",
                "2",
            ],
            &[],
            LIMIT,
        );
        assert_eq!(code, Some(1), "{name}: {err}");
        assert!(
            err.contains(common::s(&lib)) && err.contains(did),
            "{name}: {err}"
        );
        let signal = match name {
            "trap_abort" => "SIGABRT",
            "trap_segv" => "SIGSEGV",
            "trap_exit" => "exit status 0",
            _ => "its process was stopped",
        };
        assert!(err.contains(signal), "{name}: {err}");
        assert!(!out.exists(), "{name}: an output was written");
        assert!(servers_of(&lib).is_empty(), "{name}: its process is left");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A plugin that hangs while it is loaded (in `describe`, or in the
/// forward kinematics the load tries) is stopped within the time bound,
/// and the error says which call.
#[test]
fn a_plugin_that_hangs_while_loading_is_stopped() {
    for (name, during) in [
        ("hang_describe", "during describe"),
        ("hang_forward", "during forward kinematics of 64 rows"),
    ] {
        let lib = fixture_as(name);
        let (code, err, _) = pilgrim_bounded(
            &["plugin-check", common::s(&lib), "--plugin-seconds", "2"],
            &[],
            LIMIT,
        );
        assert_eq!(code, Some(1), "{name}: {err}");
        assert!(
            err.contains(common::s(&lib)) && err.contains(during) && err.contains("within 2 s"),
            "{name}: {err}"
        );
        assert!(servers_of(&lib).is_empty(), "{name}: its process is left");
    }
}

/// What a plugin says is quoted short, escapes and all: a 50 MB error
/// message opening with escape sequences (OSC 52 writes the clipboard),
/// and text printed on its standard output (which cannot reach the
/// protocol), reach the terminal as at most a short, escaped excerpt.
#[test]
fn a_plugins_text_is_quoted_short() {
    let dir = common::scratch("plugins", "noisy");
    let lib = fixture_as("trap_noisy");
    let (code, err, _) = pilgrim_bounded(
        &[
            "run",
            "scripts/worm.rhai",
            "--machine",
            common::s(&lib),
            "--out",
            common::s(&dir.join("o")),
            "--quiet",
        ],
        &[],
        LIMIT,
    );
    assert_eq!(code, Some(1), "{err}");
    assert!(!err.contains('\u{1b}') && !err.contains('\u{7}'), "{err:?}");
    assert!(err.contains("\\u{1b}]52"), "{err}");
    assert!(err.len() < 2000, "{} bytes of error", err.len());
    std::fs::remove_dir_all(&dir).ok();
}

/// A library's load-time constructor runs in the child process that holds
/// it, never in `pilgrim` itself.
#[test]
fn constructors_run_only_in_the_child() {
    let dir = common::scratch("plugins", "ctor");
    let mark = dir.join("pid");
    let lib = fixture_as("constructor");
    let (code, err, host) = pilgrim_bounded(
        &["plugin-check", common::s(&lib)],
        &[("PILGRIM_FIXTURE_CONSTRUCTOR", &mark)],
        LIMIT,
    );
    assert_eq!(code, Some(0), "{err}");
    let ran_in: u32 = std::fs::read_to_string(&mark).unwrap().parse().unwrap();
    assert_ne!(ran_in, host, "the constructor ran in pilgrim itself");
    std::fs::remove_dir_all(&dir).ok();
}

/// `plugin-check` tries the kinematics over the travel: a forward solution
/// 10 um off the inverse, and an axis whose sign disagrees with the
/// declared chain, are reported (the worst difference, the axis) and the
/// plugin refused; a run refuses it before it programs anything.
#[test]
fn plugin_check_exercises_the_kinematics() {
    for (fixture, said) in [
        (
            "skewed",
            [
                "forward against the declared chain: worst 10.0000 um",
                "inverse then forward against the poses: worst 10.0000 um",
            ],
        ),
        (
            "flipped",
            [
                "axis Z moves the tool the other way than the declared chain says",
                "inverse then forward against the poses: worst 0.0000 um",
            ],
        ),
    ] {
        let (code, err, _) = pilgrim_bounded(
            &["plugin-check", common::s(&fixture_as(fixture))],
            &[],
            LIMIT,
        );
        assert_eq!(code, Some(1), "{fixture}: {err}");
        assert!(said.iter().all(|s| err.contains(s)), "{fixture}: {err}");
    }
    let dir = common::scratch("plugins", "skewed");
    let (code, err, _) = pilgrim_bounded(
        &[
            "run",
            "scripts/worm.rhai",
            "--machine",
            common::s(&fixture_as("skewed")),
            "--out",
            common::s(&dir.join("o")),
            "--quiet",
        ],
        &[],
        LIMIT,
    );
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("refuses to program with them"), "{err}");
    assert!(!dir.join("o").exists());
    // The real machines agree, and say so.
    let (code, out, err) = common::pilgrim(&["plugin-check", common::s(&lib("fanuc_0i_tc"))]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("kinematics over the travel") && out.contains("agree"),
        "{out}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The fixture library with its dynamic section's entry `tag` set to
/// `value`, as the file `lib<name>.so`.
fn with_dynamic(name: &str, tag: u64, value: impl Fn(&[(u64, u64)]) -> u64) -> PathBuf {
    use object::read::elf::{FileHeader, ProgramHeader};
    let mut bytes = std::fs::read(lib("plugin_fixture")).unwrap();
    let (at, entries) = {
        let header = object::elf::FileHeader64::<object::Endianness>::parse(&*bytes).unwrap();
        let endian = header.endian().unwrap();
        let dynamic = header
            .program_headers(endian, &*bytes)
            .unwrap()
            .iter()
            .find(|p| p.p_type(endian) == object::elf::PT_DYNAMIC)
            .unwrap();
        let at = dynamic.p_offset(endian) as usize;
        let n = dynamic.p_filesz(endian) as usize / 16;
        let entries: Vec<(u64, u64)> = (0..n)
            .map(|i| {
                let e = &bytes[at + 16 * i..at + 16 * i + 16];
                (
                    u64::from_le_bytes(e[..8].try_into().unwrap()),
                    u64::from_le_bytes(e[8..].try_into().unwrap()),
                )
            })
            .collect();
        (at, entries)
    };
    let i = entries.iter().position(|e| e.0 == tag).unwrap();
    let v = value(&entries);
    bytes[at + 16 * i + 8..at + 16 * i + 16].copy_from_slice(&v.to_le_bytes());
    let dir = common::scratch("plugins", &format!("dyn-{name}"));
    let path = dir.join(format!("lib{name}.so"));
    std::fs::write(&path, bytes).unwrap();
    path
}

/// A full-length library with one damaged pointer in its dynamic section:
/// pointing outside the library, it is refused from its bytes; pointing
/// at the wrong place inside it, the loader in the child process fails or
/// crashes, and `plugin-check` and a run end with a clear error naming the
/// library, never a crash of their own.
#[test]
fn a_damaged_dynamic_section_is_a_clear_error() {
    use object::elf::{DT_GNU_HASH, DT_INIT_ARRAY, DT_RELA, DT_STRTAB, DT_SYMTAB};
    let outside = |_: &[(u64, u64)]| 0x7fff_0000_0000u64;
    for (tag, name) in [
        (DT_STRTAB, "DT_STRTAB"),
        (DT_SYMTAB, "DT_SYMTAB"),
        (DT_RELA, "DT_RELA"),
    ] {
        let path = with_dynamic("panics", tag.0 as u64, outside);
        let (code, err, _) = pilgrim_bounded(&["plugin-check", common::s(&path)], &[], LIMIT);
        assert_eq!(code, Some(1), "{name}: {err}");
        assert!(
            err.contains(&format!(
                "dynamic section's {name} points outside the library"
            )),
            "{err}"
        );
    }
    // Inside the library, at the wrong table.
    let find = |entries: &[(u64, u64)], tag: object::elf::DynamicTag| {
        entries.iter().find(|e| e.0 == tag.0 as u64).unwrap().1
    };
    for (tag, to) in [
        (DT_SYMTAB, DT_STRTAB),
        (DT_GNU_HASH, DT_STRTAB),
        (DT_STRTAB, DT_SYMTAB),
        (DT_INIT_ARRAY, DT_RELA),
        (DT_RELA, DT_SYMTAB),
    ] {
        let path = with_dynamic("panics", tag.0 as u64, |e| find(e, to));
        for args in [
            vec!["plugin-check", common::s(&path)],
            vec!["machines", "--only-files", "--plugin", common::s(&path)],
        ] {
            let (code, err, _) = pilgrim_bounded(&args, &[], LIMIT);
            assert_eq!(code, Some(1), "{tag:?} -> {to:?} {args:?}: {err}");
            assert!(err.contains(common::s(&path)), "{err}");
            assert!(err.lines().count() < 12 && err.len() < 3000, "{err}");
        }
    }
}
