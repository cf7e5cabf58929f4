//! The mandrel program against the physical process (issue 11), replayed
//! independently from the text a control reads: the wheel's true section
//! (flat and roundings), the part turning at S while the table feeds F
//! (the helical ridge of f = F / S per revolution), the control's straight
//! lines between blocks, the values as written. The simulation here shares
//! no code with the kernel's: wheel positions are placed along each move
//! every 0.05 mm, the surface under the steady rest is the blank's polyline
//! lowered by each pass's swept wheel raised by its ridge, and the drop of
//! the support is found by a grid search refined by golden sections.

use pilgrim_kernel::program::{build, PostProcessor, SharedPost};
use pilgrim_kernel::script::{Access, Limits, ScriptFamily};
use pilgrim_kernel::{Params, PartFamily, PartGeometry};
use std::collections::BTreeMap;
use std::path::Path;

use crate::common;
use common::grinder;

fn family() -> ScriptFamily {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/mandrel.rhai");
    ScriptFamily::load(&path, &Limits::default(), &Access::default()).unwrap()
}

/// The family's parameters: its defaults, then the TOML file `file` of
/// `scripts/examples/` (if any), then `sets`.
fn params(fam: &ScriptFamily, file: Option<&str>, sets: &[(&str, &str)]) -> Params {
    common::params_from(fam, &BTreeMap::new(), file, sets)
}

fn float(p: &Params, name: &str) -> f64 {
    match &p[name] {
        pilgrim_kernel::ParamValue::Float(v) => *v,
        pilgrim_kernel::ParamValue::Int(v) => *v as f64,
        other => panic!("{name} is {other:?}"),
    }
}

/// A block as the program writes it: Z, X, U (mm) and F (mm/min), modal
/// words carried over.
#[derive(Debug, Clone, Copy)]
struct Blk {
    z: f64,
    x: f64,
    u: f64,
    f: f64,
}

/// The program's text read as a control would: the spindle speed and the
/// blocks of each group (split at the comments after the first block).
struct Written {
    spindle: f64,
    groups: Vec<(String, Vec<Blk>)>,
}

fn read_program(text: &str) -> Written {
    let mut at = Blk {
        z: f64::NAN,
        x: f64::NAN,
        u: f64::NAN,
        f: f64::NAN,
    };
    let (mut spindle, mut started) = (f64::NAN, false);
    let mut groups: Vec<(String, Vec<Blk>)> = Vec::new();
    for line in text.lines() {
        if let Some(c) = line.strip_prefix("; ") {
            if started {
                groups.push((c.to_owned(), vec![]));
            }
            continue;
        }
        if !line.starts_with('N') {
            continue;
        }
        let mut moved = false;
        for w in line.split_whitespace().skip(1) {
            let v = |w: &str| w[1..].parse::<f64>().unwrap();
            match w.as_bytes()[0] {
                b'Z' => (at.z, moved) = (v(w), true),
                b'X' => (at.x, moved) = (v(w), true),
                b'U' => (at.u, moved) = (v(w), true),
                b'F' => at.f = v(w),
                b'S' => spindle = v(w),
                _ => {}
            }
        }
        if moved {
            started = true;
            if let Some(g) = groups.last_mut() {
                g.1.push(at);
            }
        }
    }
    Written { spindle, groups }
}

/// The wheel's axial section: roundings of radius `r` either side of a
/// flat `flat` wide; X programs its lowest point, Z the middle of the flat.
#[derive(Debug, Clone, Copy)]
struct Section {
    r: f64,
    flat: f64,
}

impl Section {
    /// The lowest x of the wheel at z, the wheel at (cz, cx).
    fn lower(&self, cz: f64, cx: f64, z: f64) -> f64 {
        let d = (z - cz).abs() - self.flat / 2.0;
        if d <= 0.0 {
            cx
        } else if d < self.r {
            cx + self.r - (self.r * self.r - d * d).sqrt()
        } else {
            f64::INFINITY
        }
    }

    /// The ridge between touches f apart on a straight generatrix of a
    /// tapered part: the rounding's (on a slope the flat stands off).
    fn ridge(&self, f: f64) -> f64 {
        let half = f / 2.0;
        self.r - (self.r * self.r - half * half).sqrt()
    }
}

/// Wheel positions along a pass, every 0.05 mm or closer, in the order the
/// wheel reaches them; `end[k]`: how many are placed once block k is reached.
struct Sweep {
    z: Vec<f64>,
    x: Vec<f64>,
    end: Vec<usize>,
    up: bool,
    ridge: f64,
}

const SPACING: f64 = 0.02;

impl Sweep {
    fn new(blocks: &[Blk], section: Section, rpm: f64) -> Self {
        let (mut z, mut x, mut end) = (vec![blocks[0].z], vec![blocks[0].x], vec![1]);
        let mut feed: f64 = 0.0;
        for w in blocks.windows(2) {
            let (a, b) = (w[0], w[1]);
            let n = ((b.z - a.z).hypot(b.x - a.x) / SPACING).ceil().max(1.0) as usize;
            for i in 1..=n {
                let s = i as f64 / n as f64;
                z.push(a.z + s * (b.z - a.z));
                x.push(a.x + s * (b.x - a.x));
            }
            end.push(z.len());
            feed = feed.max(b.f);
        }
        let up = blocks[blocks.len() - 1].z >= blocks[0].z;
        Self {
            z,
            x,
            end,
            up,
            ridge: section.ridge(feed / rpm),
        }
    }

    /// The crest the first `n` positions leave at z (infinite where none
    /// reaches within `reach`), the wheel at `extra` too if given.
    fn crest(&self, n: usize, extra: Option<(f64, f64)>, z: f64, reach: f64, s: Section) -> f64 {
        let zs = &self.z[..n];
        let range = if self.up {
            zs.partition_point(|&c| c < z - reach)..zs.partition_point(|&c| c <= z + reach)
        } else {
            zs.partition_point(|&c| c > z + reach)..zs.partition_point(|&c| c >= z - reach)
        };
        let mut v = f64::INFINITY;
        for i in range {
            v = v.min(s.lower(self.z[i], self.x[i], z));
        }
        if let Some((ez, ex)) = extra {
            v = v.min(s.lower(ez, ex, z));
        }
        v + self.ridge
    }
}

/// The blank's polyline at z (clamped to its range).
fn polyline(z: &[f64], x: &[f64], q: f64) -> f64 {
    if q <= z[0] {
        return x[0];
    }
    if q >= z[z.len() - 1] {
        return x[x.len() - 1];
    }
    let i = z.partition_point(|&v| v < q).max(1);
    x[i - 1] + (q - z[i - 1]) / (z[i] - z[i - 1]) * (x[i] - x[i - 1])
}

/// The surface under the rest: the blank's polyline lowered by the crests
/// of the passes done.
struct Surface {
    bz: Vec<f64>,
    bx: Vec<f64>,
    done: Vec<Sweep>,
    reach: f64,
    section: Section,
}

impl Surface {
    /// At z, with the first `n` positions of the pass `current` placed and
    /// the wheel at `extra`.
    fn at(&self, current: &Sweep, n: usize, extra: Option<(f64, f64)>, z: f64) -> f64 {
        let mut v = polyline(&self.bz, &self.bx, z);
        for d in &self.done {
            v = v.min(d.crest(d.z.len(), None, z, self.reach, self.section));
        }
        v.min(current.crest(n, extra, z, self.reach, self.section))
    }
}

/// The highest centre x of a circle of radius `ro` at `zr` lying on
/// `surface` over `[lo, hi]`: a grid of 0.05 mm, then golden sections on
/// every local maximum near the best.
fn drop(surface: &dyn Fn(f64) -> f64, zr: f64, ro: f64, lo: f64, hi: f64) -> f64 {
    let (a, b) = ((zr - ro).max(lo), (zr + ro).min(hi));
    let g = |z: f64| surface(z) + (ro * ro - (z - zr).powi(2)).max(0.0).sqrt();
    let n = ((b - a) / 0.05).ceil() as usize;
    let zs: Vec<f64> = (0..=n).map(|i| a + (b - a) * i as f64 / n as f64).collect();
    let v: Vec<f64> = zs.iter().map(|&z| g(z)).collect();
    let best = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mut out = best;
    for i in 0..=n {
        let local = (i == 0 || v[i] >= v[i - 1]) && (i == n || v[i] >= v[i + 1]);
        if !local || v[i] < best - 0.05 {
            continue;
        }
        let (l, r) = (zs[i.saturating_sub(1)], zs[(i + 1).min(n)]);
        out = out.max(g(common::golden_min(|z| -g(z), l, r, 60)));
    }
    out
}

/// What the replay of the rest found.
#[derive(Debug, Default)]
struct RestReplay {
    /// Largest |U - exact drop| at a block (mm).
    at_blocks: f64,
    /// Largest gap and press of U's straight line between blocks (mm).
    gap: f64,
    press: f64,
    blocks: usize,
    between: usize,
    /// Whether a support's window held the blank's stock step.
    crossed_step: bool,
    /// Where the worst at a block and between blocks are: (pass from 1,
    /// block of the pass from 0, z).
    worst_block: (usize, usize, f64),
    worst_between: (usize, usize, f64),
}

/// The default job's program on the 3K152VF20 with `file` and `sets`,
/// its rest replayed on the simulated surface.
fn replay_rest(file: Option<&str>, sets: &[(&str, &str)]) -> (RestReplay, Params) {
    let fam = family();
    let values = params(&fam, file, sets);
    let tp = fam.toolpath(&values).unwrap();
    let (b, ro) = (float(&values, "rest_b"), float(&values, "rest_r"));
    let program = build(&tp, &grinder(), "mandrel").unwrap();
    let text = SharedPost.post(&program, "sinumerik").unwrap();
    let written = read_program(&text);
    let section = Section {
        r: float(&values, "rounding_r"),
        flat: (float(&values, "wheel_w") - 2.0 * float(&values, "rounding_r")).max(0.0),
    };
    let blank = fam
        .part(&values)
        .unwrap()
        .into_iter()
        .find(|b| b.name == "blank")
        .unwrap();
    let PartGeometry::Revolution(blank) = blank.geometry else {
        panic!("the blank is a body of revolution")
    };
    let (bz, bx) = (blank.z().to_vec(), blank.x().to_vec());
    let (lo, hi) = (bz[0], bz[bz.len() - 1]);
    let step_z = -float(&values, "overrun");
    let tol = float(&values, "rest_tol");
    let passes: Vec<&Vec<Blk>> = written
        .groups
        .iter()
        .filter(|g| g.0.starts_with("pass "))
        .map(|g| &g.1)
        .collect();
    assert!(passes.len() >= 4);
    // The wheel's lowest point at z is within `reach` of its position there:
    // the foot of a rounding on a path of slope s is R s / sqrt(1 + s^2)
    // off, and the path's slope under the rest is measured.
    let mut slope: f64 = 0.0;
    for p in &passes {
        for w in p.windows(2) {
            if w[0].z + b < hi && (w[1].z - w[0].z).abs() > 1e-3 {
                slope = slope.max(((w[1].x - w[0].x) / (w[1].z - w[0].z)).abs());
            }
        }
    }
    assert!(slope < 0.2, "path slope {slope} under the rest");
    let reach = section.r * slope / (1.0 + slope * slope).sqrt() + section.flat / 2.0 + 1.0;
    let mut out = RestReplay::default();
    let mut sim = Surface {
        bz,
        bx,
        done: Vec::new(),
        reach,
        section,
    };
    for (j, blocks) in passes.into_iter().enumerate() {
        let sweep = Sweep::new(blocks, section, written.spindle);
        for (k, blk) in blocks.iter().enumerate() {
            let zr = blk.z + b;
            if (zr - step_z).abs() < ro {
                out.crossed_step = true;
            }
            let at = |z| sim.at(&sweep, sweep.end[k], None, z);
            let exact = drop(&at, zr, ro, lo, hi);
            if (blk.u - exact).abs() > out.at_blocks {
                out.at_blocks = (blk.u - exact).abs();
                out.worst_block = (j + 1, k, blk.z);
            }
            out.blocks += 1;
            if k == 0 {
                continue;
            }
            // Between blocks: the control's straight line of every axis.
            let prev = blocks[k - 1];
            let n = ((blk.z - prev.z).abs() / 2.0).ceil().max(2.0) as usize;
            for i in 1..n {
                let s = i as f64 / n as f64;
                let (z, x) = (prev.z + s * (blk.z - prev.z), prev.x + s * (blk.x - prev.x));
                let placed = sweep.end[k - 1]
                    + ((sweep.end[k] - sweep.end[k - 1]) as f64 * s).floor() as usize;
                let at = |q| sim.at(&sweep, placed, Some((z, x)), q);
                let exact = drop(&at, z + b, ro, lo, hi);
                let line = prev.u + s * (blk.u - prev.u);
                if (line - exact).abs() > out.gap.max(out.press) {
                    out.worst_between = (j + 1, k, z);
                }
                out.gap = out.gap.max(line - exact);
                out.press = out.press.max(exact - line);
                out.between += 1;
            }
        }
        sim.done.push(sweep);
    }
    assert!(
        out.gap <= tol + 1e-4 && out.press <= tol + 1e-4,
        "between blocks U strays from the surface (rest tolerance {tol} mm): {out:?}"
    );
    (out, values)
}

/// U at every block equals the exact drop on the surface simulated from
/// the program's text (ridges included) within 0.1 um, and between blocks
/// the control's straight line keeps within the rest tolerance: the
/// default job (whose rest crosses the blank's stock step), and with the
/// rest's offset B set to -150 mm (the machine's chain follows).
#[test]
fn the_rest_rides_the_simulated_surface() {
    for sets in [vec![], vec![("rest_b", "-150")]] {
        let (r, _) = replay_rest(None, &sets);
        eprintln!("{sets:?}: {r:?}");
        assert!(
            r.crossed_step,
            "{sets:?}: the rest never crossed the stock step"
        );
        assert!(r.blocks > 200 && r.between > 500, "{sets:?}: {r:?}");
        assert!(
            r.at_blocks <= 1e-4,
            "{sets:?}: U off by {} mm at a block",
            r.at_blocks
        );
    }
}

/// The same on the large example mandrel (six passes, a 30 mm support).
#[test]
fn the_rest_rides_the_large_mandrel() {
    let (r, _) = replay_rest(Some("mandrel-large.toml"), &[]);
    eprintln!("{r:?}");
    assert!(r.crossed_step && r.blocks > 200, "{r:?}");
    assert!(
        r.at_blocks <= 1e-4,
        "U off by {} mm at a block",
        r.at_blocks
    );
}

/// The job's program and its verification (the kernel's replay) for `sets`,
/// to the family's tolerance or `tolerance`.
fn verified(
    sets: &[(&str, &str)],
    tolerance: Option<f64>,
) -> (pilgrim_kernel::verify::GrindingCheck, String, Params) {
    let fam = family();
    let values = params(&fam, None, sets);
    let tp = fam.toolpath(&values).unwrap();
    let machine = grinder();
    let program = build(&tp, &machine, "mandrel").unwrap();
    let v = fam
        .verification(&values)
        .unwrap()
        .unwrap()
        .into_profile()
        .unwrap();
    let pilgrim_kernel::ToolShape::Wheel(wheel) = tp.tool.shape else {
        panic!("a wheel")
    };
    let check = pilgrim_kernel::verify::check_grinding(
        &program,
        &machine,
        &tp.tool.reference,
        &wheel,
        &tp.passes,
        &v.profile,
        v.blank.as_deref(),
        (v.from, v.to),
        tolerance.unwrap_or(v.tolerance),
    )
    .unwrap();
    (
        check,
        SharedPost.post(&program, "sinumerik").unwrap(),
        values,
    )
}

/// The helical ridge: a pass at F = 2000 mm/min and S = 399 rpm (f = 5.01
/// mm) leaves about f^2 / (8 R_s) = 157 um between its touches; the
/// replay on the generatrices finds it above the nominal (the highest of 8
/// generatrices is within h / 4 of the crest), and reports the pass's feed
/// per revolution from the program's words. (Its cut, 0.2 mm, is deeper
/// than the ridge: the surface before it does not clip the crests.)
#[test]
fn the_ridge_of_a_pass_is_f_squared_over_8_r() {
    // Verified to 0.2 mm: the blocks keep the default 1 um.
    let (check, _, _) = verified(
        &[("finish_feed", "2000"), ("cuts", "[0.1, 0.2]")],
        Some(0.2),
    );
    let finish = check.passes.last().unwrap();
    let f = 2000.0 / 399.0;
    assert!((finish.feed_per_rev_mm - f).abs() < 1e-9, "{finish:?}");
    let h = f * f / (8.0 * 20.0);
    assert!(
        (finish.ridge_mm - h).abs() < 0.01 * h,
        "{} vs {h}",
        finish.ridge_mm
    );
    let above = finish.deviation.max_above;
    assert!(
        above >= 0.75 * h && above <= h + 2e-3,
        "the replay's ridge {above} mm against f^2/8R = {h} mm"
    );
    // The default finish: the largest feed whose ridge keeps within 0.4 of
    // the tolerance, and the finish, ridges included, within it.
    let (check, _, _) = verified(&[], None);
    let finish = check.passes.last().unwrap();
    assert!(finish.ridge_mm <= 0.4e-3 + 1e-9, "{finish:?}");
    assert!(finish.deviation.max_abs <= 1e-3, "{finish:?}");
    assert!(
        finish.deviation.max_above >= 0.5 * finish.ridge_mm,
        "the finish's ridge is in the deviation: {finish:?}"
    );
    assert_eq!(check.generatrices, 8);
}

/// A wheel 40 mm wide with roundings of 15 mm has a flat of 10 mm: the
/// toolpath and the verification use it, and the finish replayed here
/// from the program's text with the wheel's true section (flat and
/// roundings) stays within the tolerance of the nominal, ridges included.
#[test]
fn a_wheel_with_a_flat_grinds_within_tolerance() {
    let sets = [("rounding_r", "15")];
    let (check, text, values) = verified(&sets, None);
    assert!(check.passes.last().unwrap().deviation.max_abs <= 1e-3);
    let written = read_program(&text);
    let finish = &written
        .groups
        .iter()
        .rev()
        .find(|g| g.0.starts_with("pass "))
        .unwrap()
        .1;
    let section = Section {
        r: 15.0,
        flat: 10.0,
    };
    let sweep = Sweep::new(finish, section, written.spindle);
    let fam = family();
    let nominal = fam
        .call_with_params("ground_profile", &values)
        .unwrap()
        .cast::<pilgrim_kernel::Profile>();
    let to = float(&values, "l_r") + float(&values, "cone_len");
    let (mut below, mut above): (f64, f64) = (0.0, 0.0);
    let n = 20_000;
    for i in 0..=n {
        let z = to * i as f64 / n as f64;
        let crest = sweep.crest(sweep.z.len(), None, z, 16.0, section);
        let valley = crest - sweep.ridge;
        let p = nominal.eval(z).unwrap();
        below = below.min(valley - p);
        above = above.max(crest - p);
    }
    assert!(
        below >= -1e-3 && above <= 1e-3,
        "flat wheel: valleys {below} mm, crests {above} mm from the nominal"
    );
}

/// A machine axis the family must drive and does not is an error naming
/// the axis; nothing is left where it stood silently.
#[test]
fn a_family_that_leaves_u_alone_is_refused() {
    let fam = family();
    let mut tp = fam.toolpath(&params(&fam, None, &[])).unwrap();
    tp.aux_names.clear();
    for p in &mut tp.passes {
        for c in &mut p.points {
            c.aux.clear();
        }
    }
    let e = build(&tp, &grinder(), "mandrel").unwrap_err().to_string();
    assert!(
        e.contains("machine 3K152VF20 takes axis U from the toolpath, which does not drive it"),
        "{e}"
    );
}

/// The program's start and end are the machine's: G54, the ZX plane, X on
/// radius (DIAMOF) and coolant before the first move; the wheel and the
/// rest cleared before Z moves, the wheel brought in before the rest; at
/// the end the wheel backs off, then the rest, coolant and spindle stop.
/// Every block is written, numbered as the report's rows are.
#[test]
fn the_program_starts_and_ends_as_the_machine_says() {
    let (_, text, _) = verified(&[], None);
    let lines: Vec<&str> = text.lines().collect();
    let at = |s: &str| {
        lines
            .iter()
            .position(|l| l.ends_with(s))
            .unwrap_or_else(|| panic!("no line ending {s:?} in\n{text}"))
    };
    let setup = at("N2 G54 G18 DIAMOF");
    let first_move = lines.iter().position(|l| l.contains(" G0 ")).unwrap();
    assert!(setup < at("N5 M8") && at("N5 M8") < first_move);
    assert_eq!(lines[first_move - 1], "; start");
    assert_eq!(lines[first_move], "N10 G0 X100.0000 U150.0000");
    assert!(lines[first_move + 1].starts_with("N20 Z") && !lines[first_move + 1].contains('X'));
    assert!(lines[first_move + 2].starts_with("N30 X") && !lines[first_move + 2].contains('U'));
    assert_eq!(lines[first_move + 3], "; approach");
    assert!(lines[first_move + 4].starts_with("N40 U"));
    let n = lines.len();
    assert_eq!(lines[n - 6], "; end");
    assert!(lines[n - 5].ends_with(" X100.0000") && lines[n - 4].ends_with(" U150.0000"));
    assert!(
        lines[n - 3].ends_with(" M9")
            && lines[n - 2].ends_with(" M5")
            && lines[n - 1].ends_with(" M30")
    );
    // Block numbers: N(10 + 10 i) for block i, none skipped.
    let numbers: Vec<u64> = lines
        .iter()
        .filter_map(|l| l.strip_prefix('N'))
        .map(|l| l.split_whitespace().next().unwrap().parse().unwrap())
        .filter(|&n| n >= 10)
        .collect();
    for (i, n) in numbers.iter().enumerate() {
        assert_eq!(*n, 10 + 10 * i as u64);
    }
}
