//! The reader `verify` and the run's read-back share, held to what the
//! control does with a program one edit away from one pilgrim wrote: a
//! code's decimals, a tool or work offset, Fanuc's single modal F and its
//! per-block Q, numbers without a decimal point, the setup words a program
//! must state. Each edit is verified or refused as the control would run
//! it, never passed as something else.

use crate::common::{pilgrim, s, scratch};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// A program pilgrim wrote, and how `verify` is asked about its edits.
#[derive(Clone)]
struct Written {
    dir: PathBuf,
    text: String,
    ext: &'static str,
    /// `verify`'s arguments after the file.
    args: Vec<String>,
}

impl Written {
    /// `verify` of `text` saved as `name` beside the run.
    fn verify(&self, name: &str, text: &str) -> (i32, String, String) {
        let file = self.dir.join(format!("{name}.{}", self.ext));
        std::fs::write(&file, text).unwrap();
        let mut args = vec!["verify".to_owned(), s(&file).to_owned()];
        args.extend(self.args.iter().cloned());
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        pilgrim(&args)
    }

    /// `verify` of the program with `from` replaced (once) by `to`.
    fn edited(&self, name: &str, from: &str, to: &str) -> (i32, String, String) {
        assert!(self.text.contains(from), "{from} not in the program");
        self.verify(name, &self.text.replacen(from, to, 1))
    }
}

/// A default run of `script` (with `extra` arguments) into `dir`, its
/// program in `ext`, and the arguments that verify a file of it.
fn written(dir: &Path, script: &str, ext: &'static str, extra: &[&str]) -> Written {
    let out = dir.join(ext);
    let mut args = vec!["run", script, "--out", s(&out), "-q"];
    args.extend(extra);
    let (code, _, err) = pilgrim(&args);
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read_to_string(out.join(format!("program.{ext}"))).unwrap();
    let mut verify = vec!["--family".to_owned(), script.to_owned(), "-q".to_owned()];
    let mut it = extra.iter();
    while let Some(a) = it.next() {
        if *a == "--machine" || *a == "--set" {
            verify.push((*a).to_owned());
            verify.push(it.next().unwrap().to_string());
        }
    }
    Written {
        dir: dir.to_owned(),
        text,
        ext,
        args: verify,
    }
}

/// The 3K152VF20 with a LinuxCNC control, as a machine file in `dir`.
fn linuxcnc_grinder(dir: &Path) -> PathBuf {
    let (code, toml, err) = pilgrim(&["machines", "--toml", "3K152VF20"]);
    assert_eq!(code, 0, "{err}");
    assert!(toml.contains("control = \"sinumerik\""), "{toml}");
    let file = dir.join("grinder-linuxcnc.toml");
    std::fs::write(&file, crate::common::with_control(&toml, "linuxcnc")).unwrap();
    file
}

/// Asserts `verify` refused, naming `word`.
fn refused(said: (i32, String, String), word: &str, case: &str) {
    let (code, out, err) = said;
    assert_eq!(code, 1, "{case}: not refused: {out}{err}");
    assert!(
        err.contains(word),
        "{case}: the refusal names not {word}: {err}"
    );
}

/// The mandrel's Sinumerik program, the same on LinuxCNC, the worm's whole
/// Fanuc program: run once for all the tests here (the runs are the
/// defaults', the same for each), their edits verified in a folder of the
/// test's own (`name`).
fn three(name: &str) -> (Written, Written, Written) {
    static RUNS: OnceLock<(Written, Written, Written)> = OnceLock::new();
    let (mpf, ngc, nc) = RUNS.get_or_init(|| {
        let dir = scratch("reader", "runs");
        let machine = linuxcnc_grinder(&dir);
        let mpf = written(&dir, "scripts/mandrel.rhai", "mpf", &[]);
        let ngc = written(
            &dir,
            "scripts/mandrel.rhai",
            "ngc",
            &["--machine", s(&machine)],
        );
        let nc = written(&dir, "scripts/worm.rhai", "nc", &["--program-number", "1"]);
        (mpf, ngc, nc)
    });
    let dir = scratch("reader", name);
    let here = |w: &Written| Written {
        dir: dir.clone(),
        ..w.clone()
    };
    (here(mpf), here(ngc), here(nc))
}

/// A code whose decimals the control reads (`G91.000010` is G91 on
/// LinuxCNC: every later move incremental) or that is another code than
/// its integer part (`G33.1`, rigid tapping) is refused naming it, in every
/// dialect; the harmless spellings of the codes pilgrim writes (`G01`, and
/// `G1.0` on LinuxCNC, which reads codes to their tenths) are read as the
/// codes they are; Sinumerik and Fanuc read codes as whole numbers, and a
/// point in one is refused.
#[test]
fn codes_are_read_with_their_decimals() {
    let (mpf, ngc, nc) = three("decimals");
    for (w, setup) in [
        (&mpf, "N1 G90 G94 G71\n"),
        (&ngc, "N1 G21 G40 G90 G94 G97\n"),
        (&nc, "G21 G40 G97 G98\n"),
    ] {
        let first = setup.trim_end();
        for code in [
            "G91.000010",
            "G20.000010",
            "M9.000010",
            "G92.000010",
            "G59.300010",
            "G33.1",
            "G0.1",
            "G1.5",
            "M3.5",
            "G94.1",
        ] {
            let said = w.edited(code, setup, &format!("{first} {code}\n"));
            refused(said, code, &format!("{} {code}", w.ext));
        }
    }
    // A move's code spelled with its zeros is the same code; a point in
    // it only where the control reads codes to their tenths (LinuxCNC).
    for (w, from, to) in [
        (&mpf, "N50 G1 U", "N50 G01 U"),
        (&ngc, " G1 ", " G01.0 "),
        (&nc, "G00 X300.000", "G0 X300.000"),
    ] {
        let (code, _, err) = w.edited("zeros", from, to);
        assert_eq!(code, 0, "{}: {err}", w.ext);
    }
    for (w, from, to, word) in [
        (&mpf, "N50 G1 U", "N50 G01.000 U", "G01.000"),
        (&nc, "G00 X300.000", "G00.0 X300.000", "G00.0"),
    ] {
        refused(
            w.edited("point", from, to),
            word,
            &format!("{} point", w.ext),
        );
    }
}

/// A tool offset other than the one the program's tool call selects (the
/// model's tool), or one cancelled, is refused: Sinumerik's `D0`, `D2`,
/// `D99`; Fanuc's `T0100` (offset cancelled) and `T0105`; and so is
/// another tool (`T2`, `T0202`).
#[test]
fn another_tool_offset_is_refused() {
    let (mpf, _, nc) = three("offsets");
    for d in ["D0", "D2", "D99"] {
        refused(mpf.edited(d, "N3 T1 D1\n", &format!("N3 T1 {d}\n")), d, d);
        // Anywhere among the moves.
        refused(
            mpf.edited(d, "N50 G1 U", &format!("N45 {d}\nN50 G1 U")),
            d,
            d,
        );
    }
    for t in ["T0100", "T0105"] {
        refused(nc.edited(t, "T0101\n", &format!("{t}\n")), t, t);
    }
    // Another tool: its own offsets and shape, not the one modelled.
    refused(mpf.edited("T2", "N3 T1 D1\n", "N3 T2 D1\n"), "T2", "T2");
    refused(nc.edited("T0202", "T0101\n", "T0202\n"), "T0202", "T0202");
}

/// A work offset switched before the finish (another part zero) is
/// refused naming it, in every dialect.
#[test]
fn a_work_offset_switched_is_refused() {
    let (mpf, ngc, nc) = three("work-offsets");
    for code in ["G55", "G56", "G57", "G58", "G59"] {
        let at = mpf.text.find("; pass 4").unwrap();
        let text = format!("{}N2615 {code}\n{}", &mpf.text[..at], &mpf.text[at..]);
        refused(mpf.verify(code, &text), code, &format!("mpf {code}"));
        let at = ngc.text.find("(pass 4").unwrap();
        let text = format!("{}N2615 {code}\n{}", &ngc.text[..at], &ngc.text[at..]);
        refused(ngc.verify(code, &text), code, &format!("ngc {code}"));
        let at = nc.text.rfind("(PASS ").unwrap();
        let text = format!("{}{code}\n{}", &nc.text[..at], &nc.text[at..]);
        refused(nc.verify(code, &text), code, &format!("nc {code}"));
    }
}

/// Fanuc has one modal F: a feed written on a G01 is the lead of the next
/// G32 that writes none (`F2.` on a M20x2.5 cuts lead 2.0); its start angle
/// Q holds for its own block (on a rapid it starts no thread); a number
/// without a decimal point is in the least input unit (`X64` is 0.064 mm
/// on a 0i-TC, whose decimal-point input is off as it leaves the factory).
#[test]
fn fanucs_modal_words_are_read_as_fanuc_reads_them() {
    let dir = scratch("reader", "fanuc");
    let thread = written(
        &dir,
        "scripts/thread.rhai",
        "nc",
        &["--program-number", "1"],
    );
    let retract = thread
        .text
        .lines()
        .skip_while(|l| !l.starts_with("G32"))
        .nth(1)
        .unwrap()
        .to_owned();
    assert!(retract.starts_with("G00 X"), "{retract}");
    let x = retract.trim_start_matches("G00 ");
    let (code, said, err) = thread.edited(
        "shared-f",
        &format!("{retract}\n"),
        &format!("G01 {x} F2.\n{retract}\n"),
    );
    assert_eq!(code, 1, "verified at lead 2.5: {said}");
    assert!(err.contains("lead 2"), "{err}");
    // Q on the rapid before a pass of the second start.
    let worm = written(&dir, "scripts/worm.rhai", "nc", &["--program-number", "1"]);
    let g32 = worm
        .text
        .lines()
        .find(|l| l.starts_with("G32") && l.contains(" Q"))
        .unwrap()
        .to_owned();
    let (before, q) = g32.split_once(" Q").unwrap();
    let at = worm.text.find(&format!("{g32}\n")).unwrap();
    let start = worm.text[..at].trim_end().rfind('\n').unwrap() + 1;
    let rapid = worm.text[start..at].trim_end().to_owned();
    let text = format!(
        "{}{rapid} Q{q}\n{before}\n{}",
        &worm.text[..start],
        &worm.text[at + g32.len() + 1..]
    );
    refused(
        worm.verify("carried-q", &text),
        &format!("Q{q}"),
        "carried Q",
    );
    // X without its decimal point.
    let (code, said, err) = worm.edited("no-point", "G00 X300.000", "G00 X300");
    assert_eq!(code, 1, "X300 read as 300 mm: {said}");
    assert!(err.contains("in \"START\""), "{err}");
}

/// A program that leaves a modal group to the control's power-on state
/// gets the state the machine states for it, and is refused naming the
/// word it must state where the machine states none or one the
/// verification does not model: the 3K152VF20 is in G90 G94 G71 at
/// power-on (a program without them verifies), the lathe in G21 G40 but
/// feed per revolution, G99 (without G98, `F100` would be 100 mm a turn);
/// the LinuxCNC grinder's file states none, so a program on it states
/// G21, G40, G90 and G94 (no cutter compensation left on from a program
/// before), and so does one on the 3K152VF20 once its file states none.
#[test]
fn the_power_on_state_is_the_machines() {
    let (mpf, ngc, nc) = three("power-on");
    let without = |line: &str, word: &str| -> String {
        let kept: Vec<&str> = line.split(' ').filter(|w| *w != word).collect();
        kept.join(" ")
    };
    for (w, line, words) in [
        (
            &ngc,
            "N1 G21 G40 G90 G94 G97",
            ["G21", "G40", "G90", "G94"].as_slice(),
        ),
        (&nc, "G21 G40 G97 G98", &["G98"]),
    ] {
        for word in words {
            refused(
                w.edited(word, line, &without(line, word)),
                word,
                &format!("{} without {word}", w.ext),
            );
        }
    }
    let (_, _, err) = nc.edited("g99", "G21 G40 G97 G98", "G21 G40 G97");
    assert!(err.contains("G99 at power-on"), "{err}");
    // What the machine states at power-on, the program may leave out, and
    // the figures stay.
    for (w, line, words) in [
        (&mpf, "N1 G90 G94 G71", ["G90", "G94", "G71"].as_slice()),
        (&nc, "G21 G40 G97 G98", &["G21", "G40", "G97"]),
    ] {
        let (code, out, err) = w.verify("as-written", &w.text);
        assert_eq!(code, 0, "{out}{err}");
        for word in words {
            let (code2, out2, err2) = w.edited(word, line, &without(line, word));
            assert_eq!(code2, 0, "{} without {word}: {out2}{err2}", w.ext);
            assert_eq!(
                out2.replace(&format!("{word}.{}", w.ext), ""),
                out.replace(&format!("as-written.{}", w.ext), ""),
                "{} without {word}: other figures",
                w.ext
            );
        }
    }
    // The 3K152VF20 whose file states no power-on state.
    let (code, toml, err) = pilgrim(&["machines", "--toml", "3K152VF20"]);
    assert_eq!(code, 0, "{err}");
    assert!(toml.contains("[setup.power_on]"), "{toml}");
    let file = mpf.dir.join("unstated.toml");
    let toml = crate::common::with_control(&toml, "linuxcnc");
    std::fs::write(
        &file,
        toml.replace("control = \"linuxcnc\"", "control = \"sinumerik\""),
    )
    .unwrap();
    let unstated = Written {
        args: [
            "--family",
            "scripts/mandrel.rhai",
            "-q",
            "--machine",
            s(&file),
        ]
        .map(str::to_owned)
        .to_vec(),
        dir: mpf.dir.clone(),
        text: mpf.text.clone(),
        ext: "mpf",
    };
    let (code, out, err) = unstated.verify("unstated-as-written", &mpf.text);
    assert_eq!(code, 0, "{out}{err}");
    let line = "N1 G90 G94 G71";
    for word in ["G90", "G94", "G71"] {
        let said = unstated.edited(&format!("unstated-{word}"), line, &without(line, word));
        assert!(said.2.contains("does not state"), "{}", said.2);
        refused(
            said,
            word,
            &format!("mpf without {word}, no power-on state"),
        );
    }
}

/// A machine's power-on state is checked against its control: codes of
/// the dialect's modal groups, one per group; a decimal-point parameter
/// only where the control has one, above 0 and at most 1 mm; the G-code
/// system the reader follows. With calculator-type input (`no_point =
/// 1`), `X300` is 300 mm.
#[test]
fn a_machines_power_on_state_is_checked_and_followed() {
    let dir = scratch("reader", "power-on-data");
    let (code, toml, err) = pilgrim(&["machines", "--toml", "fanuc-0i-tc"]);
    assert_eq!(code, 0, "{err}");
    let stated = "g = [18, 21, 40, 54, 97, 99]\nno_point = 0.001\nsystem = \"A\"";
    assert!(toml.contains(stated), "{toml}");
    for (case, with, words) in [
        (
            "two-feeds",
            "g = [18, 21, 40, 54, 97, 98, 99]",
            ["G98", "G99", "one modal group"].as_slice(),
        ),
        ("unknown", "g = [18, 33]", &["G33", "modal group"]),
        (
            "system-b",
            "system = \"B\"",
            &["system = \"B\"", "system A"],
        ),
        ("no-point-0", "no_point = 0.0", &["no_point = 0"]),
    ] {
        let file = dir.join(format!("{case}.toml"));
        std::fs::write(&file, toml.replace(stated, with)).unwrap();
        let (code, out, err) = pilgrim(&["machines", "--only-files", "--file", s(&file)]);
        assert_eq!(code, 1, "{case}: {out}");
        for w in words {
            assert!(err.contains(w), "{case}: {w} not in {err}");
        }
    }
    // No decimal-point parameter on Sinumerik.
    let (_, grinder, _) = pilgrim(&["machines", "--toml", "3K152VF20"]);
    assert!(grinder.trim_end().ends_with("500]"), "{grinder}");
    let file = dir.join("sinumerik-no-point.toml");
    std::fs::write(&file, format!("{grinder}no_point = 0.001\n")).unwrap();
    let (code, _, err) = pilgrim(&["machines", "--only-files", "--file", s(&file)]);
    assert_eq!(code, 1);
    assert!(
        err.contains("no_point") && err.contains("sinumerik"),
        "{err}"
    );
    // Calculator-type input: X300 is 300 mm, and the program verifies.
    let file = dir.join("calculator.toml");
    std::fs::write(&file, toml.replace("no_point = 0.001", "no_point = 1.0")).unwrap();
    let nc = written(
        &dir,
        "scripts/worm.rhai",
        "nc",
        &["--program-number", "1", "--machine", s(&file)],
    );
    let (code, out, err) = nc.edited("calculator", "G00 X300.000", "G00 X300");
    assert_eq!(code, 0, "X300 with calculator-type input: {out}{err}");
}

/// `w`'s verification with the offsets table `toml` (saved as `name`).
fn with_offsets(w: &Written, name: &str, toml: &str) -> Written {
    let file = w.dir.join(format!("{name}.toml"));
    std::fs::write(&file, toml).unwrap();
    let mut args = w.args.clone();
    args.extend(["--offsets".to_owned(), s(&file).to_owned()]);
    Written {
        dir: w.dir.clone(),
        text: w.text.clone(),
        ext: w.ext,
        args,
    }
}

/// The shop's offset table (`--offsets`) gives the tool and work offsets
/// the reader refuses without it, and the verification follows their
/// shifts: `D2` with no shift verifies, `D2` 20 um lower in X gouges the
/// finish by 20 um and fails naming the deviation; a `G55` before the
/// finish likewise; a word the table does not give is still refused,
/// naming the table; Fanuc's `T0102`; an axis the machine has not is
/// refused naming it.
#[test]
fn an_offsets_table_gives_other_offsets_and_their_shifts() {
    let (mpf, _, nc) = three("offsets-table");
    let (code, out, err) = with_offsets(&mpf, "d2-zero", "[tool]\nD2 = { X = 0.0 }\n").edited(
        "d2-zero",
        "N3 T1 D1\n",
        "N3 T1 D2\n",
    );
    assert_eq!(code, 0, "D2 with no shift: {out}{err}");
    let lower = with_offsets(&mpf, "d2-lower", "[tool]\nD2 = { X = -0.02 }\n");
    let (code, _, err) = lower.edited("d2-lower", "N3 T1 D1\n", "N3 T1 D2\n");
    assert_eq!(code, 1, "D2 20 um lower passed: {err}");
    assert!(err.contains("strays -0.02"), "{err}");
    // A word the table does not give.
    let (code, _, err) = lower.edited("d3", "N3 T1 D1\n", "N3 T1 D3\n");
    assert_eq!(code, 1);
    assert!(err.contains("D3") && err.contains("--offsets"), "{err}");
    // A work offset before the finish.
    let at = mpf.text.find("; pass 4").unwrap();
    let switched = format!("{}N2615 G55\n{}", &mpf.text[..at], &mpf.text[at..]);
    let g55 = with_offsets(&mpf, "g55-zero", "[work]\nG55 = { Z = 0.0 }\n");
    let (code, out, err) = g55.verify("g55-zero", &switched);
    assert_eq!(code, 0, "G55 with no shift: {out}{err}");
    let g55 = with_offsets(&mpf, "g55-lower", "[work]\nG55 = { X = -0.02 }\n");
    let (code, _, err) = g55.verify("g55-lower", &switched);
    assert_eq!(code, 1, "G55 20 um lower passed: {err}");
    assert!(err.contains("strays -0.02"), "{err}");
    let (code, _, err) = g55.verify("g56", &switched.replace("N2615 G55", "N2615 G56"));
    assert_eq!(code, 1);
    assert!(err.contains("G56") && err.contains("--offsets"), "{err}");
    // Fanuc's offset 02 of tool 01.
    let t0102 = with_offsets(&nc, "t0102", "[tool]\nT0102 = { X = 0.0, Z = 0.0 }\n");
    let (code, out, err) = t0102.edited("t0102", "T0101\n", "T0102\n");
    assert_eq!(code, 0, "T0102 with no shift: {out}{err}");
    // A shift that takes an axis past its travel: refused where it goes.
    let (code, _, err) = with_offsets(&mpf, "far", "[tool]\nD2 = { U = 900.0 }\n").edited(
        "far",
        "N3 T1 D1\n",
        "N3 T1 D2\n",
    );
    assert_eq!(code, 1);
    assert!(
        err.contains("with the offsets' shift") && err.contains("outside the axis's travel"),
        "{err}"
    );
    // An axis the machine has not.
    let (code, _, err) = with_offsets(&mpf, "q", "[tool]\nD2 = { Q = 0.1 }\n").edited(
        "q",
        "N3 T1 D1\n",
        "N3 T1 D2\n",
    );
    assert_eq!(code, 1);
    assert!(err.contains("D2.Q") && err.contains("3K152VF20"), "{err}");
}

/// A code is refused with what it means on its own control, never
/// another's: on a Fanuc lathe in system A `G90`, `G92`, `G94` are the
/// turning, threading and facing cycles, `G50` a coordinate setting or
/// speed clamp and `W` an incremental Z; on Sinumerik `G91` is incremental dimensions and `G95`
/// feed per revolution; on LinuxCNC `G98` a canned cycle's return level
/// and `G92` a coordinate system offset.
#[test]
fn a_refused_code_is_named_with_its_dialects_meaning() {
    let (mpf, ngc, nc) = three("meanings");
    for (w, after, code, meaning) in [
        (&nc, "T0101\n", "G90", "cutting cycle (system A) on fanuc"),
        (
            &nc,
            "T0101\n",
            "G94",
            "end face turning cycle (system A) on fanuc",
        ),
        (&nc, "T0101\n", "G50", "coordinate system setting"),
        (
            &nc,
            "G00 X300.000\n",
            "W-5.",
            "Z incremental, in G-code system A",
        ),
        (
            &mpf,
            "N3 T1 D1\n",
            "G91",
            "incremental dimensions on sinumerik",
        ),
        (
            &mpf,
            "N3 T1 D1\n",
            "G95",
            "feed per revolution on sinumerik",
        ),
        (
            &ngc,
            "N1 G21 G40 G90 G94 G97\n",
            "G98",
            "return to the initial level on linuxcnc",
        ),
        (
            &ngc,
            "N1 G21 G40 G90 G94 G97\n",
            "G92",
            "coordinate system offset on linuxcnc",
        ),
    ] {
        // The code added to a block before the moves.
        let with = format!("{} {code}\n", after.trim_end());
        let (code_, _, err) = w.edited(&format!("{}-{code}", w.ext), after, &with);
        assert_eq!(code_, 1, "{code} on {}", w.ext);
        assert!(
            err.contains(code) && err.contains(meaning),
            "{code} on {}: {err}",
            w.ext
        );
    }
}
