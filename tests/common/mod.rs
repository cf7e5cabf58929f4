//! Shared by the integration tests: the plugins' shared libraries.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// The directory of this build's artifacts (target/<profile>).
#[allow(dead_code)]
pub fn artifact_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    exe.parent().and_then(Path::parent).unwrap().to_owned()
}

/// The path of shared library `name` (file `lib<name>.so` on Linux), built
/// first: `cargo test` builds a dependency's rlib only, so the tests ask
/// cargo for the cdylibs of the plugin crates, once per test process, in
/// the profile of the running tests (always, so a changed plugin is never
/// stale; an up-to-date build takes a fraction of a second).
#[allow(dead_code)]
pub fn shared_lib(name: &str) -> PathBuf {
    static BUILT: OnceLock<()> = OnceLock::new();
    BUILT.get_or_init(|| {
        // Libraries loaded in this process are held by `pilgrim
        // plugin-server` child processes, as the program holds them.
        pilgrim_kernel::plugin::configure(
            Some(env!("CARGO_BIN_EXE_pilgrim").into()),
            pilgrim_kernel::plugin::Bounds::default(),
        );
        let dir = artifact_dir();
        let mut cmd = std::process::Command::new(env!("CARGO"));
        // The workspace's libraries, programs and tests, as `cargo test
        // --workspace` selects them: the same features, so nothing is
        // built a second time with others (only the cdylibs are new).
        cmd.args(["build", "--workspace", "--lib", "--bins", "--tests"])
            .current_dir(env!("CARGO_MANIFEST_DIR"));
        if dir.file_name().is_some_and(|n| n == "release") {
            cmd.arg("--release");
        }
        let status = cmd.status().expect("cargo runs");
        assert!(
            status.success(),
            "building the plugins' shared libraries failed"
        );
    });
    let p = artifact_dir().join(format!(
        "{}{name}{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    ));
    assert!(p.exists(), "{} was not built", p.display());
    p
}

/// The 3K152VF20 compiled into the tests, through the plugin ABI as the
/// program has it.
#[allow(dead_code)]
pub fn grinder() -> pilgrim_kernel::plugin::PluginMachine {
    pilgrim_kernel::plugin::PluginMachine::from_entry(
        "3K152VF20",
        "pilgrim_plugin_grinder_3k152vf20",
        grinder_3k152vf20::pilgrim_plugin_grinder_3k152vf20,
    )
    .unwrap()
}

/// The family's parameters: its defaults, then `NAME=VALUE` pairs (as
/// `--set` gives them), on a machine with `constants`.
#[allow(dead_code)]
pub fn params_on(
    family: &dyn pilgrim_kernel::PartFamily,
    constants: &std::collections::BTreeMap<String, f64>,
    sets: &[(&str, &str)],
) -> pilgrim_kernel::Params {
    params_from(family, constants, None, sets)
}

/// The `pilgrim` program run in `dir` with `args`: exit code, stdout,
/// stderr.
#[allow(dead_code)]
pub fn pilgrim_in(dir: &Path, args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_pilgrim"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The repository's root (where `pilgrim` runs in the README's commands).
#[allow(dead_code)]
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// `pilgrim` run in the repository's root.
#[allow(dead_code)]
pub fn pilgrim(args: &[&str]) -> (i32, String, String) {
    pilgrim_in(root(), args)
}

/// A fresh scratch directory `pilgrim-<suite>-<pid>-<name>` for one test.
/// The first call of a test process removes the scratch directories of
/// test processes that have ended (their `<pid>` no longer runs), so that
/// runs do not pile up their outputs in the temporary directory; a
/// finished run's files stay until the next run, to be looked at.
#[allow(dead_code)]
pub fn scratch(suite: &str, name: &str) -> PathBuf {
    static SWEPT: std::sync::Once = std::sync::Once::new();
    SWEPT.call_once(remove_ended_scratch);
    let d = std::env::temp_dir().join(format!("pilgrim-{suite}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Removes the `pilgrim-<suite>-<pid>-<name>` directories (and the
/// `.failed`, `.verify` beside them) whose process has ended: its pid is
/// not in `/proc`. Nothing else is touched.
fn remove_ended_scratch() {
    let Ok(entries) = std::fs::read_dir(std::env::temp_dir()) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let Some(rest) = name.strip_prefix("pilgrim-") else {
            continue;
        };
        // The first all-digit part is the pid (suites hold no digits).
        let Some(pid) = rest
            .split('-')
            .find(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()))
        else {
            continue;
        };
        let is_dir = e.file_type().is_ok_and(|t| t.is_dir());
        if is_dir && !Path::new("/proc").join(pid).exists() {
            let _ = std::fs::remove_dir_all(e.path());
        }
    }
}

/// A default run of `scripts/<job>.rhai` into a fresh scratch directory
/// of `suite` named `name`: the run's directory, which must pass.
#[allow(dead_code)]
pub fn default_run(suite: &str, job: &str, name: &str) -> PathBuf {
    let out = scratch(suite, name).join(job);
    let (code, _, err) = pilgrim(&[
        "run",
        &format!("scripts/{job}.rhai"),
        "--out",
        s(&out),
        "-q",
    ]);
    assert_eq!(code, 0, "{err}");
    out
}

/// Every file under `dir` whose name ends in `.ext`, sorted.
#[allow(dead_code)]
pub fn files_with_ext(dir: &Path, ext: &str) -> Vec<PathBuf> {
    fn walk(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(&p, ext, out);
            } else if p.extension().is_some_and(|x| x == ext) {
                out.push(p);
            }
        }
    }
    let mut out = vec![];
    walk(dir, ext, &mut out);
    out.sort();
    out
}

/// A path as the text an argument takes.
#[allow(dead_code)]
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The family's parameters: its defaults, then the TOML file `file` of
/// `scripts/examples/` (if any), then `NAME=VALUE` pairs, on a machine
/// with `constants`.
#[allow(dead_code)]
pub fn params_from(
    family: &dyn pilgrim_kernel::PartFamily,
    constants: &std::collections::BTreeMap<String, f64>,
    file: Option<&str>,
    sets: &[(&str, &str)],
) -> pilgrim_kernel::Params {
    let mut sources = Vec::new();
    if let Some(f) = file {
        sources.push(pilgrim_kernel::ParamSource::Toml {
            label: f.into(),
            text: std::fs::read_to_string(root().join("scripts/examples").join(f)).unwrap(),
        });
    }
    sources.push(pilgrim_kernel::ParamSource::Pairs {
        label: "--set".into(),
        pairs: sets
            .iter()
            .map(|(k, v)| ((*k).to_owned(), (*v).to_owned()))
            .collect(),
    });
    pilgrim_kernel::params::resolve(family.params(), constants, &sources).unwrap()
}

/// Where the function `f`, unimodal on `[a, b]`, is smallest, to within
/// `(b - a) 0.618^iterations` (golden sections).
#[allow(dead_code)]
pub fn golden_min(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64, iterations: usize) -> f64 {
    for _ in 0..iterations {
        let (m1, m2) = (a + 0.382 * (b - a), a + 0.618 * (b - a));
        if f(m1) < f(m2) {
            b = m2;
        } else {
            a = m1;
        }
    }
    0.5 * (a + b)
}

/// Where each named node of a run's `scene.glb` stands: a function of the
/// node's name giving its translation (panics naming a node it lacks).
#[allow(dead_code)]
pub fn scene_nodes(dir: &Path) -> impl Fn(&str) -> [f32; 3] {
    let doc = gltf::Gltf::from_slice(&std::fs::read(dir.join("scene.glb")).unwrap()).unwrap();
    move |name: &str| {
        doc.nodes()
            .find(|n| n.name() == Some(name))
            .unwrap_or_else(|| panic!("no node {name}"))
            .transform()
            .decomposed()
            .0
    }
}

/// A run's `report.json`, read.
#[allow(dead_code)]
pub fn report_of(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("report.json")).unwrap()).unwrap()
}

/// Leaves a run's models for the external checkers of `.ci/run`.
#[allow(dead_code)]
pub fn leave_for_checkers(dir: &Path, tag: &str) {
    let exe = std::env::current_exe().unwrap();
    let check = exe.ancestors().nth(3).unwrap().join("mesh-check");
    std::fs::create_dir_all(&check).unwrap();
    // Every body the run wrote (the part's, the tool's, the machine's), as
    // its report lists them, and the scene.
    let report: serde_json::Value = report_of(dir);
    let files = report["bodies"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|b| b["file"].as_str().map(str::to_owned))
        .chain(["scene.glb".to_owned()]);
    for f in files {
        if dir.join(&f).exists() {
            std::fs::copy(dir.join(&f), check.join(format!("{tag}-{f}"))).unwrap();
        }
    }
}

/// Leaves a run's `report.html` for `.ci/run`'s headless-Chromium check
/// (`.ci/page/check.js`), which keeps its screenshot beside it.
#[allow(dead_code)]
pub fn leave_page_for_chromium(dir: &Path, tag: &str) {
    let exe = std::env::current_exe().unwrap();
    let check = exe.ancestors().nth(3).unwrap().join("page-check");
    std::fs::create_dir_all(&check).unwrap();
    std::fs::copy(
        dir.join("report.html"),
        check.join(format!("{tag}-report.html")),
    )
    .unwrap();
}

/// Checks a run's `report.html` against the run's own files: the summary's
/// figures, every plot (its data URI decoding to the file's bytes) with
/// its marks, the listing (the program's text, every line, and a line
/// for each block), the 3-D scene (its data URI decoding to `scene.glb`),
/// nothing fetched from anywhere, and the page within `max_mb` MB.
#[allow(dead_code)]
pub fn check_page(dir: &Path, program_file: &str, max_mb: f64) {
    use base64::Engine;
    let page = std::fs::read_to_string(dir.join("report.html")).unwrap();
    assert!(
        page.len() as f64 <= max_mb * 1e6,
        "the page is {} bytes, more than {max_mb} MB",
        page.len()
    );
    let report: serde_json::Value = report_of(dir);
    let b64 = base64::engine::general_purpose::STANDARD;
    // The data URI after `marker`, decoded.
    let uri = |marker: &str| -> Vec<u8> {
        let at = page.find(marker).unwrap_or_else(|| panic!("no {marker}")) + marker.len();
        let end = at + page[at..].find('"').unwrap();
        b64.decode(&page[at..end]).unwrap()
    };
    assert!(page.starts_with("<!DOCTYPE html>"));
    assert!(page.contains(&format!(
        "<td>blocks</td><td>{}</td>",
        report["blocks"].as_u64().unwrap()
    )));
    let svgs: Vec<&str> = report["files"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|f| f.as_str())
        .filter(|f| f.ends_with(".svg"))
        .collect();
    for f in &svgs {
        let svg = uri(&format!(
            "<img alt=\"{f}\" src=\"data:image/svg+xml;base64,"
        ));
        assert_eq!(svg, std::fs::read(dir.join(f)).unwrap(), "{f}");
    }
    assert_eq!(page.matches("<figure>").count(), svgs.len());
    let glb = uri("src=\"data:model/gltf-binary;base64,");
    assert_eq!(glb, std::fs::read(dir.join("scene.glb")).unwrap());
    // The listing: the program's text as written, and each block's line
    // a line of the text that holds a move (its N where it has one).
    let program = std::fs::read_to_string(dir.join(program_file)).unwrap();
    let marker = "<script type=\"application/octet-stream\" id=\"program\">";
    let at = page.find(marker).expect("a listing") + marker.len();
    let packed = b64
        .decode(&page[at..at + page[at..].find('<').unwrap()])
        .unwrap();
    let mut json = String::new();
    std::io::Read::read_to_string(&mut flate2::read::GzDecoder::new(&packed[..]), &mut json)
        .unwrap();
    let listing: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(listing["text"].as_str().unwrap(), program);
    let lines: Vec<&str> = program.lines().collect();
    let mut line = 0;
    let steps = listing["steps"].as_array().unwrap();
    assert_eq!(steps.len() as u64, report["blocks"].as_u64().unwrap());
    for s in steps {
        line += s.as_i64().unwrap();
        assert!(line >= 1 && line as usize <= lines.len(), "line {line}");
        let text = lines[line as usize - 1];
        assert!(!text.starts_with(';') && !text.starts_with('('), "{text}");
    }
    // Every plot's marks over it.
    if let Some(marks) = report.get("marks").and_then(|m| m.as_object()) {
        assert_eq!(page.matches("<svg class=\"marks\"").count(), marks.len());
        for (file, m) in marks {
            assert!(svgs.contains(&file.as_str()), "{file}");
            for p in m["places"].as_array().into_iter().flatten() {
                assert!(page.contains(&format!(
                    "<circle class=\"place\" data-block=\"{}\"",
                    p["block"]
                )));
            }
        }
    }
    let escape = |l: &str| {
        l.replace('&', "&amp;")
            .replace('<', "&lt;")
            .replace('>', "&gt;")
    };
    for (name, p) in report["parameters"].as_object().unwrap() {
        assert!(page.contains(&format!("<td>{name}</td>")), "{name}");
        let unit = p["unit"].as_str().unwrap();
        assert!(
            page.contains(&format!("<td>{}</td></tr>", escape(unit))),
            "{unit}"
        );
    }
    for bad in ["src=\"http", "href=\"http", "<link ", "src=\"//"] {
        assert!(!page.contains(bad), "the page fetches: {bad}");
    }
}

/// Leaves a run's STEP file `name.step` for `.ci/run`'s FreeCAD check
/// (`.ci/freecad_check.py`) with the volume it must have: `volume` mm^3
/// within `allowed`, found by the test independently of the kernel's fit.
#[allow(dead_code)]
pub fn leave_step_for_freecad(dir: &Path, tag: &str, name: &str, volume: f64, allowed: f64) {
    let exe = std::env::current_exe().unwrap();
    let check = exe.ancestors().nth(3).unwrap().join("mesh-check");
    std::fs::create_dir_all(&check).unwrap();
    let file = check.join(format!("{tag}-{name}.step"));
    std::fs::copy(dir.join(format!("{name}.step")), &file).unwrap();
    let expected = serde_json::json!({ "volume_mm3": volume, "allowed_mm3": allowed });
    std::fs::write(
        check.join(format!("{tag}-{name}.step.json")),
        expected.to_string(),
    )
    .unwrap();
}

/// Checks a run's fitted STEP solid `name` against the volume a test found
/// independently: `report.json` says it lies within the run's STEP
/// tolerance of the body, and its volume is `want` within that tolerance
/// times `area` (an upper bound of the solid's surface); then leaves the
/// file for FreeCAD with the same figure.
#[allow(dead_code)]
pub fn check_fitted_solid(dir: &Path, tag: &str, name: &str, want: f64, area: f64) {
    let report: serde_json::Value = report_of(dir);
    let solid = report["solids"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["name"] == name)
        .unwrap_or_else(|| panic!("no solid {name} in report.json"));
    let tol = report["step_tolerance_mm"].as_f64().unwrap();
    assert!(solid["deviation_mm"].as_f64().unwrap() <= tol, "{solid}");
    let got = solid["volume_mm3"].as_f64().unwrap();
    assert!(
        (got - want).abs() <= tol * area,
        "{name}: {got} vs {want} +- {}",
        tol * area
    );
    leave_step_for_freecad(dir, tag, name, want, tol * area);
}

/// The volume of the body of revolution of `profile` and its lateral area
/// (mm^3, mm^2), by Simpson's rule on 20,000 stretches of the profile's own
/// curve: a test's oracle for solids made from it.
#[allow(dead_code)]
pub fn revolution_volume_and_area(profile: &pilgrim_kernel::Profile) -> (f64, f64) {
    let m = 20_000;
    let (a, b) = profile.z_range();
    let h = (b - a) / m as f64;
    let zs: Vec<f64> = (0..=m).map(|k| a + h * k as f64).collect();
    let xs = profile.eval_many(&zs).unwrap();
    let squares: Vec<f64> = xs.iter().map(|x| x * x).collect();
    let area: f64 = xs
        .windows(2)
        .map(|p| 0.5 * (p[0] + p[1]) * h.hypot(p[1] - p[0]))
        .sum();
    let pi = std::f64::consts::PI;
    (
        pi * pilgrim_kernel::math::simpson(&squares, h),
        2.0 * pi * area,
    )
}

/// Leaves a run's LinuxCNC program and its axis program for `.ci/run`'s
/// check with LinuxCNC's own `rs274` interpreter (`.ci/rs274_check.py`).
#[allow(dead_code)]
pub fn leave_for_rs274(dir: &Path, tag: &str) {
    let exe = std::env::current_exe().unwrap();
    let check = exe
        .ancestors()
        .nth(3)
        .unwrap()
        .join("linuxcnc-check")
        .join(tag);
    std::fs::create_dir_all(&check).unwrap();
    for f in ["program.ngc", "program.json"] {
        std::fs::copy(dir.join(f), check.join(f)).unwrap();
    }
}

/// How a run of pilgrim ended and what it took: its exit code (`None` when
/// a signal ended it), its error stream, its process id, its peak resident
/// memory (its own high-water mark, read from `/proc` while it runs:
/// `wait4`'s `ru_maxrss` also counts the test process's, whose memory the
/// child shares until it starts pilgrim) and its CPU time, as the system
/// accounts them (`wait4`), not as a clock in the test sees them.
#[allow(dead_code)]
pub struct Measured {
    pub code: Option<i32>,
    pub err: String,
    pub pid: u32,
    pub peak_mb: f64,
    pub cpu_seconds: f64,
}

/// Runs pilgrim in the repository's root with `args` and the environment
/// `env` added, killed after `limit` (then `None`).
// The child is reaped by `wait4`, which clippy does not see.
#[allow(dead_code, clippy::zombie_processes)]
pub fn measured(
    args: &[&str],
    env: &[(&str, &Path)],
    limit: std::time::Duration,
) -> Option<Measured> {
    use std::io::Read;
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_pilgrim"));
    cmd.current_dir(root())
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped());
    for (k, v) in env {
        cmd.env(k, v);
    }
    let mut child = cmd.spawn().unwrap();
    let mut stderr = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut err = String::new();
        stderr.read_to_string(&mut err).ok();
        err
    });
    let pid = child.id();
    let start = std::time::Instant::now();
    // `spawn` returns once the child has started pilgrim: its memory is
    // pilgrim's alone from then on.
    let hwm_kb = || -> Option<f64> {
        let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
        let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
        line.split_whitespace().nth(1)?.parse().ok()
    };
    let mut peak_kb: f64 = 0.0;
    loop {
        peak_kb = peak_kb.max(hwm_kb().unwrap_or(0.0));
        let mut status = 0;
        // SAFETY: an all-zero rusage is valid; wait4 fills it.
        let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
        // SAFETY: the child's pid, valid pointers to locals.
        let got =
            unsafe { libc::wait4(pid as libc::pid_t, &mut status, libc::WNOHANG, &mut usage) };
        if got == pid as libc::pid_t {
            let seconds = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
            return Some(Measured {
                code: libc::WIFEXITED(status).then(|| libc::WEXITSTATUS(status)),
                err: reader.join().unwrap(),
                pid,
                peak_mb: peak_kb / 1024.0,
                cpu_seconds: seconds(usage.ru_utime) + seconds(usage.ru_stime),
            });
        }
        if start.elapsed() > limit {
            child.kill().ok();
            child.wait().ok();
            return None;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
}

/// A channel of an animation: its key times and the values at them.
pub type Channel = (Vec<f32>, Vec<Vec<f32>>);

/// A run's animation, as `scene.glb` holds it and the page plays it.
#[allow(dead_code)]
pub struct Playback {
    /// Per node and channel path (`translation`, `rotation`): the key times
    /// and the values at them.
    pub channels: std::collections::BTreeMap<(String, String), Channel>,
    /// The page's player keys: each key's block (from 0) and time (s).
    pub keys: Vec<(usize, f32)>,
    /// The bodies that turn with the part (the children of its turn's node).
    pub turning: Vec<String>,
}

#[allow(dead_code)]
impl Playback {
    /// The animation of the run in `dir` (its `scene.glb` and the keys of
    /// its `report.html`).
    pub fn of(dir: &Path) -> Self {
        use gltf::animation::util::ReadOutputs;
        let glb = std::fs::read(dir.join("scene.glb")).unwrap();
        let doc = gltf::Gltf::from_slice(&glb).unwrap();
        let blob = doc.blob.clone().unwrap();
        let animation = doc.animations().next().expect("an animation");
        let mut channels = std::collections::BTreeMap::new();
        for channel in animation.channels() {
            let node = channel.target().node().name().unwrap().to_owned();
            let reader = channel.reader(|_| Some(&blob[..]));
            let times: Vec<f32> = reader.read_inputs().unwrap().collect();
            let (path, values): (&str, Vec<Vec<f32>>) = match reader.read_outputs().unwrap() {
                ReadOutputs::Translations(t) => ("translation", t.map(|v| v.to_vec()).collect()),
                ReadOutputs::Rotations(r) => {
                    ("rotation", r.into_f32().map(|v| v.to_vec()).collect())
                }
                _ => panic!("a channel of another kind"),
            };
            channels.insert((node, path.to_owned()), (times, values));
        }
        let turning = doc
            .nodes()
            .find(|n| n.name() == Some("part turn"))
            .map(|n| n.children().map(|c| c.name().unwrap().to_owned()).collect())
            .unwrap_or_default();
        let page = std::fs::read_to_string(dir.join("report.html")).unwrap();
        let start = page
            .find("<script type=\"application/json\" id=\"keys\">")
            .expect("the player's keys");
        let text = &page[start..];
        let text = &text[text.find('>').unwrap() + 1..text.find("</script>").unwrap()];
        let rows: Vec<serde_json::Value> = serde_json::from_str(text).unwrap();
        let keys = rows
            .iter()
            .map(|r| {
                (
                    r[2].as_u64().unwrap() as usize,
                    r[1].as_f64().unwrap() as f32,
                )
            })
            .collect();
        Self {
            channels,
            keys,
            turning,
        }
    }

    /// A node's channel (`translation` or `rotation`): times and values.
    pub fn channel(&self, node: &str, path: &str) -> &Channel {
        self.channels
            .get(&(node.to_owned(), path.to_owned()))
            .unwrap_or_else(|| panic!("no {path} of {node} in the animation"))
    }

    /// The part's turn at its keys: times, and angles about +Z (rad),
    /// unwrapped from the quaternions (each step the short way).
    pub fn spin(&self) -> (Vec<f32>, Vec<f64>) {
        let (times, q) = self.channel("part turn", "rotation");
        let mut angles: Vec<f64> = Vec::with_capacity(q.len());
        for v in q {
            assert!(
                v[0].abs() < 1e-6 && v[1].abs() < 1e-6,
                "a turn not about Z: {v:?}"
            );
            let a = 2.0 * (v[2] as f64).atan2(v[3] as f64);
            let a = match angles.last() {
                Some(&last) => last + (a - last + PI).rem_euclid(TAU) - PI,
                None => a,
            };
            angles.push(a);
        }
        (times.clone(), angles)
    }

    /// The part's turn at the time `t` of one of its keys (rad).
    pub fn spin_at(&self, t: f32) -> f64 {
        let (times, angles) = self.spin();
        let i = times
            .iter()
            .position(|&s| s == t)
            .unwrap_or_else(|| panic!("no key of the part's turn at {t} s"));
        angles[i]
    }
}

use std::f64::consts::{PI, TAU};

/// The value of address `a` in a block's words (`X12.5`).
pub fn word(code: &str, a: char) -> Option<f64> {
    code.split_whitespace()
        .find(|w| w.starts_with(a) && w[1..].parse::<f64>().is_ok())
        .map(|w| w[1..].parse().unwrap())
}

#[allow(dead_code)]
/// A machine file `toml` (as `pilgrim machines --toml` writes it) with its
/// control changed to `control`: the power-on state, which is the old
/// control's (its modal groups, its parameters), is taken out unless the
/// control stays, so the program must state its setup itself.
pub fn with_control(toml: &str, control: &str) -> String {
    let mut out = String::with_capacity(toml.len());
    let mut skipping = false;
    let mut same = false;
    for line in toml.lines() {
        if let Some(v) = line.strip_prefix("control = ") {
            same = v == format!("{control:?}");
            out.push_str(&format!("control = {control:?}\n"));
            continue;
        }
        if line.starts_with('[') {
            skipping = line == "[setup.power_on]";
        }
        if !skipping {
            out.push_str(line);
            out.push('\n');
        }
    }
    if same {
        toml.to_owned()
    } else {
        out
    }
}

/// The Rust text a message to a user holds, if any: a debug print of an
/// option or a result (`Some(`, `None`, `Ok(`, `Err(`), of a parser's
/// error (`Unexpected {`), or a type's path (`::`). One pass over the
/// bytes: the mutation test asks it of every one of its millions of
/// refusals.
pub fn rust_text(message: &str) -> Option<&'static str> {
    let b = message.as_bytes();
    let before = |i: usize, w: &str| {
        i >= w.len()
            && &b[i - w.len()..i] == w.as_bytes()
            && (i == w.len() || !b[i - w.len() - 1].is_ascii_alphanumeric())
    };
    for (i, &c) in b.iter().enumerate() {
        match c {
            b'(' if before(i, "Some") => return Some("Some("),
            b'(' if before(i, "Ok") => return Some("Ok("),
            b'(' if before(i, "Err") => return Some("Err("),
            b'{' if before(i, "Unexpected ") => return Some("Unexpected {"),
            b':' if b.get(i + 1) == Some(&b':') => return Some("::"),
            b'e' if before(i + 1, "None")
                && !b.get(i + 1).is_some_and(|n| n.is_ascii_alphanumeric()) =>
            {
                return Some("None")
            }
            _ => {}
        }
    }
    None
}
