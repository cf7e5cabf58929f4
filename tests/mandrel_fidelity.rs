//! The mandrel program against the physical process, replayed
//! independently from the text a control reads: the wheel's true section
//! (flat and roundings), the part turning at S while the table feeds F
//! (the helical ridge of f = F / S per revolution), the control's straight
//! lines between blocks at each block's F (the infeed block included), the
//! values as written. The simulation here shares no code with the
//! kernel's: each pass is timed from its blocks, the wheel's section is
//! placed at the moments a generatrix passes under it for many spindle
//! phases, and the surface under the steady rest is the blank's polyline
//! lowered by each pass's highest generatrix (the spindle's phase between
//! passes is not in the program: a rest meets the highest); the drop of
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
pub(crate) struct Blk {
    pub(crate) z: f64,
    pub(crate) x: f64,
    pub(crate) u: f64,
    pub(crate) f: f64,
}

/// The program's text read as a control would: the spindle speed and the
/// blocks of each group (split at the comments after the first block).
pub(crate) struct Written {
    pub(crate) spindle: f64,
    pub(crate) groups: Vec<(String, Vec<Blk>)>,
}

pub(crate) fn read_program(text: &str) -> Written {
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
pub(crate) struct Section {
    pub(crate) r: f64,
    pub(crate) flat: f64,
}

impl Section {
    /// The lowest x of the wheel at z, the wheel at (cz, cx).
    pub(crate) fn lower(&self, cz: f64, cx: f64, z: f64) -> f64 {
        let d = (z - cz).abs() - self.flat / 2.0;
        if d <= 0.0 {
            cx
        } else if d < self.r {
            cx + self.r - (self.r * self.r - d * d).sqrt()
        } else {
            f64::INFINITY
        }
    }

    /// How far along z from its reference the section reaches.
    pub(crate) fn reach(&self) -> f64 {
        self.r + self.flat / 2.0
    }
}

/// A pass as the control moves the wheel: from where the block before it
/// left the wheel (its infeed starts there), every axis straight between
/// blocks at the block's F, Z and X against the time (minutes) each block
/// ends.
pub(crate) struct Pass {
    pub(crate) z: Vec<f64>,
    pub(crate) x: Vec<f64>,
    pub(crate) t: Vec<f64>,
}

impl Pass {
    pub(crate) fn new(before: Blk, blocks: &[Blk]) -> Self {
        let (mut z, mut x, mut t) = (vec![before.z], vec![before.x], vec![0.0]);
        for b in blocks {
            let (pz, px, pt) = (z[z.len() - 1], x[x.len() - 1], t[t.len() - 1]);
            z.push(b.z);
            x.push(b.x);
            t.push(pt + (b.z - pz).hypot(b.x - px) / b.f);
        }
        Self { z, x, t }
    }

    /// Where the pass is at time `t` (clamped to it): the move `k` (from
    /// point `k - 1` to `k`) and how far along it (0 to 1).
    pub(crate) fn segment_at(&self, t: f64) -> (usize, f64) {
        let k = self
            .t
            .partition_point(|&v| v < t)
            .clamp(1, self.t.len() - 1);
        (k, self.along(k, t))
    }

    /// How far along move `k` the pass is at time `t` (0 to 1).
    fn along(&self, k: usize, t: f64) -> f64 {
        let (t0, t1) = (self.t[k - 1], self.t[k]);
        if t1 > t0 {
            ((t - t0) / (t1 - t0)).clamp(0.0, 1.0)
        } else {
            1.0
        }
    }

    /// The wheel's reference at time `t` (clamped to the pass).
    pub(crate) fn at(&self, t: f64) -> (f64, f64) {
        let (k, s) = self.segment_at(t);
        self.point(k, s)
    }

    /// The wheel's reference a fraction `s` along move `k`.
    fn point(&self, k: usize, s: f64) -> (f64, f64) {
        (
            self.z[k - 1] + s * (self.z[k] - self.z[k - 1]),
            self.x[k - 1] + s * (self.x[k] - self.x[k - 1]),
        )
    }

    /// The first and last times the section reaches z (None: never).
    pub(crate) fn covers(&self, z: f64, reach: f64) -> Option<(f64, f64)> {
        let mut span: Option<(f64, f64)> = None;
        for k in 1..self.z.len() {
            let (z0, z1, t0, t1) = (self.z[k - 1], self.z[k], self.t[k - 1], self.t[k]);
            let (a, b) = if z1 == z0 {
                if (z0 - z).abs() > reach {
                    continue;
                }
                (0.0, 1.0)
            } else {
                let (p, q) = ((z - reach - z0) / (z1 - z0), (z + reach - z0) / (z1 - z0));
                (p.min(q).max(0.0), p.max(q).min(1.0))
            };
            if a <= b {
                let (ta, tb) = (t0 + a * (t1 - t0), t0 + b * (t1 - t0));
                span = Some(span.map_or((ta, tb), |(s, e)| (s.min(ta), e.max(tb))));
            }
        }
        span
    }

    /// At z, counting the wheel's touches up to `until`, with the part
    /// turning once every `period` minutes and `phases` generatrices evenly
    /// round it: the highest generatrix (the crest a rest meets, whatever
    /// the spindle's phase) and the lowest (the swept envelope). Infinite
    /// where some generatrix is never touched.
    pub(crate) fn cut(
        &self,
        s: Section,
        period: f64,
        phases: usize,
        z: f64,
        until: f64,
    ) -> (f64, f64) {
        self.cut_worn(s, period, phases, z, until, &|_| 0.0)
    }

    /// [`Pass::cut`] by a wheel worn by `wear(t)` (mm of its radius) at
    /// time `t` of the pass: its section stands that much higher.
    pub(crate) fn cut_worn(
        &self,
        s: Section,
        period: f64,
        phases: usize,
        z: f64,
        until: f64,
        wear: &dyn Fn(f64) -> f64,
    ) -> (f64, f64) {
        let Some((a, b)) = self.covers(z, s.reach()) else {
            return (f64::INFINITY, f64::INFINITY);
        };
        let b = b.min(until);
        let dt = period / phases as f64;
        let (first, last) = ((a / dt).ceil() as i64, (b / dt).floor() as i64);
        if last - first + 1 < phases as i64 {
            return (f64::INFINITY, f64::INFINITY);
        }
        let mut low = vec![f64::INFINITY; phases];
        // The touches in time order: the move under way is walked on to
        // (the move `segment_at` would find) and the generatrix counted
        // round, not searched and divided for afresh at each touch.
        let mut k = self.segment_at(first as f64 * dt).0;
        let mut i = first.rem_euclid(phases as i64) as usize;
        for m in first..=last {
            let t = m as f64 * dt;
            while k < self.t.len() - 1 && self.t[k] < t {
                k += 1;
            }
            let (cz, cx) = self.point(k, self.along(k, t));
            low[i] = low[i].min(s.lower(cz, cx + wear(t), z));
            i = if i + 1 == phases { 0 } else { i + 1 };
        }
        let crest = low.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let valley = low.iter().copied().fold(f64::INFINITY, f64::min);
        (crest, valley)
    }
}

/// How many generatrices a pass's crest is sampled on: the highest of them
/// lies within `2 h / n` of the crest over all phases (h: the rounding's
/// ridge at the pass's largest feed per revolution; the crest over phases
/// moves by at most `f^2 / R = 8 h` per revolution of phase), so the
/// sampling costs at most 0.1 um.
pub(crate) fn phases_for(pass: &Pass, s: Section, period: f64) -> usize {
    let mut f: f64 = 0.0;
    for k in 1..pass.t.len() {
        let dt = pass.t[k] - pass.t[k - 1];
        if dt > 0.0 {
            f = f.max((pass.z[k] - pass.z[k - 1]).abs() / dt * period);
        }
    }
    let h = s.r - (s.r * s.r - (f / 2.0).min(s.r).powi(2)).sqrt();
    ((2.0 * h / 1e-4).ceil() as usize).clamp(16, 4096)
}

/// A pass's crest on a grid of [`GRID`] mm over its reach, with the first
/// and last times the section reaches each point: where the pass has left
/// both ends of a cell the grid's line stands for it (the crest over phases
/// is flat along a steady pass), elsewhere it is sampled where asked.
struct Crest {
    pass: Pass,
    section: Section,
    period: f64,
    phases: usize,
    z0: f64,
    crest: Vec<f64>,
    first: Vec<f64>,
    last: Vec<f64>,
}

const GRID: f64 = 0.05;

impl Crest {
    fn new(pass: Pass, section: Section, rpm: f64) -> Self {
        let period = 1.0 / rpm;
        let phases = phases_for(&pass, section, period);
        let lo = pass.z.iter().copied().fold(f64::INFINITY, f64::min) - section.reach();
        let hi = pass.z.iter().copied().fold(f64::NEG_INFINITY, f64::max) + section.reach();
        let n = ((hi - lo) / GRID).ceil() as usize + 1;
        let (mut crest, mut first, mut last) = (vec![], vec![], vec![]);
        for i in 0..n {
            let z = lo + i as f64 * GRID;
            crest.push(pass.cut(section, period, phases, z, f64::INFINITY).0);
            let (a, b) = pass
                .covers(z, section.reach())
                .unwrap_or((f64::INFINITY, f64::INFINITY));
            first.push(a);
            last.push(b);
        }
        Self {
            pass,
            section,
            period,
            phases,
            z0: lo,
            crest,
            first,
            last,
        }
    }

    /// The crest at z, counting the touches up to `until`.
    fn at(&self, z: f64, until: f64) -> f64 {
        let u = (z - self.z0) / GRID;
        if !(u >= 0.0 && u <= (self.crest.len() - 1) as f64) {
            return f64::INFINITY;
        }
        let i = (u.floor() as usize).min(self.crest.len() - 2);
        if self.first[i].min(self.first[i + 1]) > until {
            return f64::INFINITY;
        }
        let (a, b) = (self.crest[i], self.crest[i + 1]);
        if self.last[i].max(self.last[i + 1]) > until || a.is_finite() != b.is_finite() {
            return self
                .pass
                .cut(self.section, self.period, self.phases, z, until)
                .0;
        }
        a + (u - i as f64) * (b - a)
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
/// of the passes done and of the pass in progress up to its time.
struct Surface {
    bz: Vec<f64>,
    bx: Vec<f64>,
    done: Vec<Crest>,
}

impl Surface {
    /// At z, the pass `current` cut up to `until`.
    fn at(&self, current: &Crest, until: f64, z: f64) -> f64 {
        let mut v = polyline(&self.bz, &self.bx, z);
        for d in &self.done {
            v = v.min(d.at(z, f64::INFINITY));
        }
        v.min(current.at(z, until))
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
    // Each pass with the block before it (where its infeed starts).
    let mut passes: Vec<(Blk, &[Blk])> = Vec::new();
    let mut before = None;
    for (name, blocks) in &written.groups {
        if name.starts_with("pass ") {
            passes.push((before.expect("a block before the first pass"), blocks));
        }
        before = blocks.last().copied().or(before);
    }
    assert!(passes.len() >= 4);
    let mut out = RestReplay::default();
    let mut sim = Surface {
        bz,
        bx,
        done: Vec::new(),
    };
    for (j, (before, blocks)) in passes.into_iter().enumerate() {
        let crest = Crest::new(Pass::new(before, blocks), section, written.spindle);
        // The time each block ends (the pass's point k + 1).
        let ends = crest.pass.t[1..].to_vec();
        for (k, blk) in blocks.iter().enumerate() {
            let zr = blk.z + b;
            if (zr - step_z).abs() < ro {
                out.crossed_step = true;
            }
            let at = |z| sim.at(&crest, ends[k], z);
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
                let z = prev.z + s * (blk.z - prev.z);
                let until = ends[k - 1] + s * (ends[k] - ends[k - 1]);
                let at = |q| sim.at(&crest, until, q);
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
        sim.done.push(crest);
    }
    assert!(
        out.gap <= tol + 1e-4 && out.press <= tol + 1e-4,
        "between blocks U strays from the surface (rest tolerance {tol} mm): {out:?}"
    );
    (out, values)
}

/// U at every block equals the exact drop on the surface simulated from
/// the program's text (ridges and infeeds included) within 1 um: the two
/// crests agree within 0.03 um where each is computed exactly, but the
/// kernel drops the support on its surface sampled every 0.05 mm (the
/// family's choice) and this replay reads its crests off a 0.05 mm grid;
/// where an infeed's last revolution bends the crest sharply (a pass's
/// first millimetres) that costs up to about half a micron. Between blocks
/// the control's straight line keeps within the rest tolerance: the
/// default job (whose rest crosses the blank's stock step), with the
/// rest's offset B set to -150 mm (the machine's chain follows), and with a
/// wheel whose roundings of 15 mm leave a 10 mm flat (whose crest is not
/// the rounding's ridge: the flat cuts it).
#[test]
fn the_rest_rides_the_simulated_surface() {
    for sets in [vec![], vec![("rest_b", "-150")], vec![("rounding_r", "15")]] {
        let (r, _) = replay_rest(None, &sets);
        eprintln!("{sets:?}: {r:?}");
        assert!(
            r.crossed_step,
            "{sets:?}: the rest never crossed the stock step"
        );
        assert!(r.blocks > 200 && r.between > 500, "{sets:?}: {r:?}");
        assert!(
            r.at_blocks <= 1e-3,
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
        r.at_blocks <= 1e-3,
        "U off by {} mm at a block",
        r.at_blocks
    );
}

/// The job's program and its verification (the kernel's replay) for `sets`,
/// to the family's tolerance or `tolerance`.
fn verified(
    sets: &[(&str, &str)],
    tolerance: Option<f64>,
) -> (
    pilgrim_kernel::families::revolution::GrindingCheck,
    String,
    Params,
) {
    verified_with(None, sets, tolerance)
}

/// [`verified`] with the parameters of `scripts/examples/<file>` first.
fn verified_with(
    file: Option<&str>,
    sets: &[(&str, &str)],
    tolerance: Option<f64>,
) -> (
    pilgrim_kernel::families::revolution::GrindingCheck,
    String,
    Params,
) {
    let fam = family();
    let values = params(&fam, file, sets);
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
    let check = pilgrim_kernel::families::revolution::check_grinding(
        &program,
        &machine,
        &tp.tool.reference,
        &wheel,
        &pilgrim_kernel::program::pass_blocks(&program, &tp.passes),
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
    assert!(check.generatrices >= 16, "{}", check.generatrices);
}

/// The finish reported is the worst the program leaves: the replay
/// doubles its generatrices until doubling moves the finish's worst by
/// less than 0.1 um, and on the large example mandrel (a finish at 3.1 mm
/// a revolution) the worst it reports is within 0.1 um of the finish's
/// crest over every spindle phase, simulated here from the program's text
/// (8 generatrices said 0.878 um where the crest stands at 0.937 um).
#[test]
fn the_finish_reported_is_the_worst_over_every_phase() {
    for file in [None, Some("mandrel-large.toml")] {
        let (check, text, values) = verified_with(file, &[], None);
        assert!(check.generatrices >= 16 && check.generatrices.is_multiple_of(8));
        assert!(
            check.sampling_change_mm < 1e-4 || check.generatrices == 128,
            "{file:?}: {} generatrices, the worst moved {} mm",
            check.generatrices,
            check.sampling_change_mm
        );
        let reported = check.passes.last().unwrap().deviation.max_above;
        let written = read_program(&text);
        let mut passes = written.groups.iter().filter(|g| g.0.starts_with("pass "));
        let finish = &passes.next_back().unwrap().1;
        let before = *passes.next_back().unwrap().1.last().unwrap();
        let r = float(&values, "rounding_r");
        let section = Section {
            r,
            flat: (float(&values, "wheel_w") - 2.0 * r).max(0.0),
        };
        let pass = Pass::new(before, finish);
        let period = 1.0 / written.spindle;
        let phases = phases_for(&pass, section, period);
        let nominal = family()
            .call_with_params("ground_profile", &values)
            .unwrap()
            .cast::<pilgrim_kernel::Profile>();
        let to = float(&values, "l_r") + float(&values, "cone_len");
        let n = 20_000;
        let crest = (0..=n)
            .map(|i| {
                let z = to * i as f64 / n as f64;
                pass.cut(section, period, phases, z, f64::INFINITY).0 - nominal.eval(z).unwrap()
            })
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(
            reported <= crest + 3e-5 && reported >= crest - 1e-4,
            "{file:?}: reported {reported} mm, the crest over every phase {crest} mm"
        );
    }
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
    let before = written
        .groups
        .iter()
        .rev()
        .skip_while(|g| !g.0.starts_with("pass "))
        .nth(1)
        .and_then(|g| g.1.last().copied())
        .unwrap();
    let pass = Pass::new(before, finish);
    let period = 1.0 / written.spindle;
    let phases = phases_for(&pass, section, period);
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
        let (crest, valley) = pass.cut(section, period, phases, z, f64::INFINITY);
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
