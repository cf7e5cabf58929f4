//! `report.html`: a run on one self-contained page.
//!
//! Opened from disk with no server and no network: the verdict, then the
//! machine and its program side by side (the 3-D scene, `scene.glb` as a
//! data URI in `<model-viewer>`, Google's web component over three.js,
//! played along the program; every line of the program in a pane that
//! follows the player), then the summary, the verification's figures and
//! where the worst is, every plot with its marks (the pass the player is
//! in, the worst places to click), the parameters. The viewer's pinned
//! release is inlined from `kernel/assets/model-viewer/` with its
//! licences. The page's parts talk through two events on `document`:
//! `pilgrim-block` (the player is at a block: the listing and the marks
//! follow) and `pilgrim-go` (a row, line or mark asks the player to go to
//! a block).
//!
//! The HTML is written here by hand: a few tables and figures need no
//! template engine, and [`escape`] is the one rule every text obeys.

use crate::math::fixed;
use crate::report::Report;
use base64::Engine;
use std::fmt::Write;

/// `<model-viewer>` 4.4.0 (npm `@google/model-viewer`, Apache-2.0; it
/// bundles three.js, MIT, and lit, BSD-3-Clause, whose licence headers the
/// file keeps). CI holds it equal to the npm release (`.ci/page`).
const MODEL_VIEWER: &str = include_str!("../../assets/model-viewer/model-viewer.min.js");

/// The viewer's name and version, as the page credits it.
pub const VIEWER: &str = "@google/model-viewer 4.4.0";

use crate::html::{escape, row, row_at};

/// The largest `scene.glb` a page embeds (bytes). Past it the page would
/// take tens of seconds to open, or fail to, in a browser; the scene is
/// written beside it at its full resolution all the same.
pub const MAX_EMBEDDED_SCENE_BYTES: usize = 32 << 20;

/// What the page is made of besides the report.
pub struct PageInputs<'a> {
    /// The run's report.
    pub report: &'a Report,
    /// The plots (file name, SVG text), in the order the run made them.
    pub plots: Vec<(&'a str, &'a [u8])>,
    /// The program the page lists: its file name and text (the control's
    /// program a run wrote, or the file it verified); none where the run
    /// failed and wrote none.
    pub program: Option<(&'a str, &'a str)>,
    /// `scene.glb`, and the part's bounding box in the part frame (mm),
    /// where the camera points.
    pub scene: Option<(&'a [u8], [f64; 3], [f64; 3])>,
}

impl<'a> PageInputs<'a> {
    /// The scene the page embeds: [`Self::scene`] within
    /// [`MAX_EMBEDDED_SCENE_BYTES`].
    fn embedded_scene(&self) -> Option<(&'a [u8], [f64; 3], [f64; 3])> {
        self.scene.filter(|s| s.0.len() <= MAX_EMBEDDED_SCENE_BYTES)
    }
}

/// The verification's figures, and where the worst is: each entry of the
/// report drawn by its kind ([`crate::families`]); an entry of a kind the
/// kernel does not carry has its figures in the verdict only.
fn verification(out: &mut String, r: &Report) {
    for (key, entry) in &r.verifications {
        if let Some(kind) = crate::families::kind(key) {
            let label = |b: usize| r.block_label(b);
            let drawn = (kind.section)(entry, &label).and_then(|h| {
                crate::judged::judged_section(entry, &label).map(|j| format!("{h}{j}"))
            });
            match drawn {
                Ok(html) => out.push_str(&html),
                Err(e) => {
                    let _ = writeln!(
                        out,
                        "<p>The {} entry could not be read: {}</p>",
                        escape(key),
                        escape(&e.to_string())
                    );
                }
            }
        }
    }
}

/// The verdict at the top of the page: passed (each figure as a share of
/// its tolerance), failed (what, where, and that no program was written,
/// or, verifying the user's file, that it does not verify) or not
/// verified (the family declares no verification).
fn banner(out: &mut String, r: &Report) {
    use crate::verdict::Status;
    let v = &r.verdict;
    let (class, head) = match v.status {
        Status::Passed => ("passed", "PASSED: every check and figure held"),
        Status::Failed if r.program_file.is_some() => {
            ("failed", "FAILED: the program does not verify")
        }
        Status::Failed => ("failed", "FAILED: no program was written"),
        Status::NotVerified => (
            "unverified",
            "NOT VERIFIED: the family declares no verification, so nothing says this program makes the part",
        ),
    };
    let _ = writeln!(
        out,
        "<div class=\"banner {class}\" id=\"verdict\"><b>{head}</b>"
    );
    findings(out, "", "", &v.failures);
    if !v.figures.is_empty() {
        out.push_str("<table id=\"figures\"><tr><th>figure</th><th>value</th><th>tolerance</th><th>of the tolerance</th><th>where</th></tr>\n");
        for f in &v.figures {
            row_at(
                out,
                f.block,
                &[
                    escape(&f.name),
                    format!("{} {}", fixed(f.value, 5), escape(&f.unit)),
                    format!("{} {}", fixed(f.tolerance, 5), escape(&f.unit)),
                    format!(
                        "{}{}%",
                        if f.holds() { "" } else { "FAILED " },
                        fixed(100.0 * f.share(), 1)
                    ),
                    escape(&f.place),
                ],
            );
        }
        out.push_str("</table>\n");
    }
    findings(out, " class=\"warn\"", "warning: ", &v.warnings);
    out.push_str("</div>\n");
}

/// The player of the scene's animation: play and pause, a speed, and a
/// slider over its keys (the blocks' ends, sampled where there are many),
/// the block and time shown. It starts at the pose block.
fn player(out: &mut String, r: &Report) {
    if r.playback.is_empty() {
        return;
    }
    let keys: Vec<String> = r
        .playback
        .iter()
        .map(|(k, t)| {
            format!(
                "[{},{},{k}]",
                // A JSON string that cannot end the script: no '<'.
                serde_json::to_string(&r.block_label(*k))
                    .unwrap_or_default()
                    .replace('<', "\\u003c"),
                // As the animation holds it (seeking past its end would
                // start it again).
                t
            )
        })
        .collect();
    let pose = r.pose_block.map_or(0, |b| b - 1);
    let start = r
        .playback
        .iter()
        .rposition(|(k, _)| *k <= pose)
        .unwrap_or(0);
    let _ = writeln!(
        out,
        "<div class=\"player\"><button id=\"play\" type=\"button\">play</button> <label>speed <select id=\"speed\"><option value=\"1\">1x</option><option value=\"10\">10x</option><option value=\"100\" selected>100x</option><option value=\"1000\">1000x</option></select></label> <input id=\"scrub\" type=\"range\" min=\"0\" max=\"{}\" value=\"{start}\" step=\"1\" aria-label=\"the program's blocks\"> <span id=\"at\"></span></div>\n<script type=\"application/json\" id=\"keys\">[{}]</script>\n<script>{PLAYER}</script>",
        keys.len() - 1,
        keys.join(",")
    );
}

/// The player's script: the keys' blocks and times from the page, the
/// animation played, paused and sought through `<model-viewer>`'s API.
const PLAYER: &str = "(() => {
  const mv = document.getElementById('scene');
  const keys = JSON.parse(document.getElementById('keys').textContent);
  const scrub = document.getElementById('scrub');
  const at = document.getElementById('at');
  const play = document.getElementById('play');
  const speed = document.getElementById('speed');
  // Each key shown: its block and time, and the block told to the page
  // (the listing's line, the plots' marks): the key's, or the one asked
  // for where the keys sample the blocks.
  const show = (i, block) => {
    at.textContent = keys[i][0] + ', ' + keys[i][1].toFixed(1) + ' s';
    document.dispatchEvent(new CustomEvent('pilgrim-block', {detail: block === undefined ? keys[i][2] : block}));
  };
  const keyAt = t => { let lo = 0, hi = keys.length - 1; while (lo < hi) { const m = (lo + hi + 1) >> 1; if (keys[m][1] <= t + 1e-6) lo = m; else hi = m - 1; } return lo; };
  // The viewer's clock wraps at the animation's end: the last key is shown
  // a tenth of a millisecond before it.
  const seek = (i, block) => { mv.currentTime = Math.min(keys[i][1], mv.duration > 0 ? mv.duration - 1e-4 : Infinity); show(i, block); };
  let shown = -1;
  const tick = () => { const i = keyAt(mv.currentTime); scrub.value = i; if (i !== shown) { shown = i; show(i); } if (!mv.paused) requestAnimationFrame(tick); else play.textContent = 'play'; };
  const stop = () => { mv.pause(); play.textContent = 'play'; };
  scrub.addEventListener('input', () => { stop(); seek(+scrub.value); });
  speed.addEventListener('change', () => { mv.timeScale = +speed.value; });
  play.addEventListener('click', () => {
    if (mv.paused) { mv.timeScale = +speed.value; mv.play({repetitions: 1}); play.textContent = 'pause'; requestAnimationFrame(tick); }
    else stop();
  });
  mv.addEventListener('load', () => { mv.animationName = 'the program'; mv.pause(); seek(+scrub.value); });
  // A block named anywhere on the page (a row, a line, a plot's mark)
  // takes the player to the first key at or after it, the listing to the
  // block itself.
  document.addEventListener('pilgrim-go', e => {
    let i = keys.findIndex(k => k[2] >= e.detail);
    if (i < 0) i = keys.length - 1;
    stop(); scrub.value = i; seek(i, e.detail);
  });
  document.addEventListener('pilgrim-listed', () => show(+scrub.value));
  show(+scrub.value);
})();";

/// Each pass's time at its feeds and with the axes' acceleration.
fn pass_times(out: &mut String, r: &Report) {
    let Some(t) = &r.times else {
        return;
    };
    if t.passes.is_empty() {
        return;
    }
    out.push_str(&format!(
        "<h2>Times</h2>\n<p>Click a pass to see its start. Each pass at its programmed feeds and with every move ramped within the axes' acceleration, blending corners as far as one interpolation cycle ({} ms) of acceleration allows.{}{}</p>\n<table><tr><th>pass</th><th>at the feeds (s)</th><th>with acceleration (s)</th></tr>\n",
        fixed(1000.0 * t.ipo_cycle_s, 1),
        if t.thread_sync_s > 0.0 {
            format!(
                " Each thread waits at its start for the spindle's one-revolution signal, half a turn on average: {} s in all.",
                fixed(t.thread_sync_s, 1)
            )
        } else {
            String::new()
        },
        if t.unramped_axes.is_empty() {
            String::new()
        } else {
            format!(
                " The machine states no acceleration for {}: taken as reaching its speed at once.",
                escape(&t.unramped_axes.join(", "))
            )
        }
    ));
    for p in &t.passes {
        row_at(
            out,
            Some(p.first_block),
            &[
                escape(&p.pass),
                fixed(60.0 * p.programmed_min, 1),
                fixed(60.0 * p.accelerated_min, 1),
            ],
        );
    }
    out.push_str("</table>\n");
}

/// The collision check: each pair's smallest clearance, nearest first.
fn clearances(out: &mut String, r: &Report) {
    let Some(c) = &r.collisions else {
        return;
    };
    out.push_str(&format!(
        "<h2>Clearances</h2>\n<p>Click a row to see its block. Every pair of bodies the program moves relative to each other, checked along every move ({} places; measured again before two bodies can close {:.0} % of the last distance or {} mm; the part as its envelope of revolution at its largest). The smallest clearance of each pair, nearest first, sought again every {} mm of the two bodies' motion over the moves either side of where it was found; <i>at least</i> is the least the distance can have been anywhere between two measurements:</p>\n<table id=\"clearances\"><tr><th>bodies</th><th>clearance (mm)</th><th>at least (mm)</th><th>at block</th></tr>\n",
        c.samples,
        100.0 * crate::collision::REMEASURE,
        c.step_mm,
        crate::collision::FINE
    ));
    let mut pairs: Vec<_> = c.clearances.iter().collect();
    pairs.sort_by(|a, b| a.clearance_mm.total_cmp(&b.clearance_mm));
    for p in pairs {
        row_at(
            out,
            Some(p.block_index - 1),
            &[
                format!("{} / {}", escape(&p.bodies[0]), escape(&p.bodies[1])),
                crate::math::fixed(p.clearance_mm, 3),
                crate::math::fixed(p.at_least_mm, 3),
                escape(&p.block),
            ],
        );
    }
    out.push_str("</table>\n");
    for n in &c.notes {
        out.push_str(&format!("<p class=\"warn\">{}</p>\n", escape(n)));
    }
}

/// A list of findings, each its rule, its block and what it says.
fn findings(out: &mut String, class: &str, prefix: &str, list: &[crate::verdict::Finding]) {
    if list.is_empty() {
        return;
    }
    let _ = writeln!(out, "<ul{class}>");
    for f in list {
        // A finding at a block or a line takes the listing (and the
        // player) there.
        let at = match (f.block_index, f.line) {
            (Some(b), _) => format!(" data-block=\"{}\"", b.saturating_sub(1)),
            (None, Some(l)) => format!(" data-line=\"{l}\""),
            _ => String::new(),
        };
        let _ = writeln!(
            out,
            "<li{at}>{prefix}<b>{}</b>{}: {}</li>",
            escape(&f.rule),
            f.block
                .as_ref()
                .filter(|b| !f.message.contains(b.as_str()))
                .map_or(String::new(), |b| format!(" at {}", escape(b))),
            escape(&f.message)
        );
    }
    out.push_str("</ul>\n");
}

/// The machine and its program side by side under the verdict: the 3-D
/// view with its player, and the program's every line in a pane that
/// follows the player's block ([`listing`]).
fn twin(out: &mut String, inputs: &PageInputs<'_>) {
    let r = inputs.report;
    out.push_str("<section class=\"twin\">\n<div class=\"view\">\n");
    match inputs.embedded_scene() {
        Some((glb, lo, hi)) => {
            // The scene's root lays the part's axis horizontal (its Z to
            // glTF's X, its X away from the viewer) and scales mm to m:
            // (X, Y, Z) -> (Z, Y, -X) / 1000.
            let c = [
                0.5 * (lo[0] + hi[0]),
                0.5 * (lo[1] + hi[1]),
                0.5 * (lo[2] + hi[2]),
            ];
            let target = format!(
                "{}m {}m {}m",
                fixed(c[2] / 1e3, 6),
                fixed(c[1] / 1e3, 6),
                fixed(-c[0] / 1e3, 6)
            );
            // Far enough that the box fills the view.
            let size = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
            let radius = fixed(1.2 * size / 1e3, 4);
            let _ = writeln!(
                out,
                "<h2>The machine at the pose block</h2>\n<model-viewer id=\"scene\" alt=\"the part, the tool and the machine's bodies at the pose block\" src=\"data:model/gltf-binary;base64,{}\" loading=\"eager\" camera-controls interaction-prompt=\"none\" camera-target=\"{target}\" camera-orbit=\"0deg 75deg {radius}m\" min-camera-orbit=\"auto auto 0.01m\" shadow-intensity=\"0\"></model-viewer>",
                base64::engine::general_purpose::STANDARD.encode(glb)
            );
            player(out, r);
            let _ = writeln!(
                out,
                "<p class=\"hint\">Drag to orbit, wheel or pinch to zoom, right-drag to pan; the camera frames the tool where it meets the part, from the operator's side. {VIEWER}.</p>"
            );
        }
        None => match inputs.scene {
            Some((glb, _, _)) => {
                let _ = writeln!(
                    out,
                    "<h2>3-D</h2>\n<p>The 3-D view is left out of this page: scene.glb is {:.1} MB, more than the {} MB a page embeds. Open scene.glb beside it in a glTF viewer, or give the part a coarser mesh tolerance.</p>",
                    glb.len() as f64 / (1024.0 * 1024.0),
                    MAX_EMBEDDED_SCENE_BYTES >> 20
                );
            }
            None => out.push_str(
                "<h2>3-D</h2>\n<p>No 3-D models: the family has no <code>fn part(p)</code>.</p>\n",
            ),
        },
    }
    out.push_str("</div>\n<div class=\"program\">\n");
    listing(out, r, inputs.program);
    out.push_str("</div>\n</section>\n");
}

/// The program's text, every line, gzipped into the page with the line
/// each block stands on (the browser's `DecompressionStream` opens it):
/// a pane that draws the lines in view, scrolls to the player's block and
/// highlights it, and takes the player to a line's block when clicked.
fn listing(out: &mut String, r: &Report, program: Option<(&str, &str)>) {
    let Some((file, text)) = program else {
        out.push_str("<h2>Program</h2>\n<p>None: the run failed, and writes no program a control could load (<code>program.json</code> and <code>report.csv</code> hold the axis program it would have been).</p>\n");
        return;
    };
    let _ = writeln!(
        out,
        "<h2>Program: {} ({} lines)</h2>",
        escape(file),
        text.lines().count()
    );
    // Each block's line after the one before's: mostly 1, which packs well.
    let steps: Vec<i64> = r
        .program_lines
        .iter()
        .scan(0, |before, &l| {
            Some(l as i64 - std::mem::replace(before, l as i64))
        })
        .collect();
    // The lines the verdict's failures stand on, marked.
    let mut marks: Vec<usize> = (r.verdict.failures.iter())
        .filter_map(|f| match (f.block_index, f.line) {
            (Some(b), _) => r.program_lines.get(b.checked_sub(1)?).copied(),
            (None, l) => l,
        })
        .collect();
    marks.sort_unstable();
    marks.dedup();
    // What the reading expanded: the pane names each such block's source.
    let runs: Vec<(usize, usize, String)> = (r.program_expansions.iter())
        .map(|x| (x.first, x.last, x.describe()))
        .collect();
    let payload = serde_json::json!({ "text": text, "steps": steps, "marks": marks, "runs": runs })
        .to_string();
    // Level 3: within 15 % of the best size at a tenth of its time (the
    // caliber's program, in zlib: 0.74 MB in 40 ms, 0.64 MB in 0.5 s).
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::new(3));
    let packed = std::io::Write::write_all(&mut gz, payload.as_bytes())
        .and_then(|()| gz.finish())
        .unwrap_or_default();
    let _ = writeln!(
        out,
        "<p id=\"source\" aria-live=\"polite\"></p>\n<div id=\"listing\" tabindex=\"0\" aria-label=\"the program\"><div class=\"rows\"></div></div>\n<script type=\"application/octet-stream\" id=\"program\">{}</script>\n<script>{LISTING}</script>",
        base64::engine::general_purpose::STANDARD.encode(packed)
    );
    expanded(out, r);
}

/// The most runs the table of expansions lists; the rest are counted.
const EXPANSION_ROWS: usize = 100;

/// The runs of blocks the reading expanded (cycles, loops, subprograms),
/// each with the lines it was read from: a row takes the player to its
/// first block.
fn expanded(out: &mut String, r: &Report) {
    let runs = &r.program_expansions;
    if runs.is_empty() {
        return;
    }
    out.push_str("<h3>Expanded from cycles, loops and subprograms</h3>\n<table class=\"expanded\"><tr><th>Blocks</th><th>Moves</th><th>Read from</th></tr>\n");
    for x in runs.iter().take(EXPANSION_ROWS) {
        let blocks = match x.first == x.last {
            true => r.block_label(x.first),
            false => format!("{} to {}", r.block_label(x.first), r.block_label(x.last)),
        };
        let _ = writeln!(
            out,
            "<tr data-block=\"{}\"><td>{}</td><td>{}</td><td>{}</td></tr>",
            x.first,
            escape(&blocks),
            x.last - x.first + 1,
            escape(&x.describe())
        );
    }
    out.push_str("</table>\n");
    if runs.len() > EXPANSION_ROWS {
        let _ = writeln!(out, "<p>and {} more.</p>", runs.len() - EXPANSION_ROWS);
    }
}

/// The listing's script: the text and lines unpacked, the lines in view
/// drawn (52k lines stay light), the player's block followed.
const LISTING: &str = "(() => {
  const pane = document.getElementById('listing');
  const rows = pane.querySelector('.rows');
  const packed = Uint8Array.from(atob(document.getElementById('program').textContent), c => c.charCodeAt(0));
  const H = 17;
  let lines = [], blockLine = [], now = -1, marked = new Set();
  const draw = () => {
    const first = Math.max(0, Math.floor(pane.scrollTop / H) - 10);
    const last = Math.min(lines.length, first + Math.ceil(pane.clientHeight / H) + 20);
    const width = String(lines.length).length;
    rows.replaceChildren(...lines.slice(first, last).map((l, k) => {
      const d = document.createElement('div');
      const n = first + k + 1;
      d.textContent = String(n).padStart(width) + '  ' + l;
      d.dataset.line = n;
      d.style.top = (n - 1) * H + 'px';
      if (n === now) d.className = 'now';
      else if (marked.has(n)) d.className = 'fail';
      return d;
    }));
  };
  pane.addEventListener('scroll', () => requestAnimationFrame(draw));
  // A line named (a failure's): highlighted and scrolled into the pane.
  const goLine = n => {
    now = n;
    if (n > 0) pane.scrollTop = (n - 1) * H - pane.clientHeight / 2;
    draw();
  };
  document.addEventListener('pilgrim-line', e => goLine(e.detail));
  // A block named where no player follows it (a failed reading's page).
  document.addEventListener('pilgrim-go', e => { if (!document.getElementById('scene')) goLine(blockLine[e.detail] || -1); });
  // The player's block: its line highlighted and scrolled into the pane.
  const source = document.getElementById('source');
  let runs = [];
  document.addEventListener('pilgrim-block', e => {
    now = blockLine[e.detail] || -1;
    const run = runs.find(x => x[0] <= e.detail && e.detail <= x[1]);
    source.textContent = run ? 'This move: ' + (e.detail - run[0] + 1) + ' of ' + (run[1] - run[0] + 1) + ', read from ' + run[2] : '';
    pane.dataset.block = e.detail;
    if (now > 0) {
      const y = (now - 1) * H;
      if (y < pane.scrollTop || y > pane.scrollTop + pane.clientHeight - H) pane.scrollTop = y - pane.clientHeight / 2;
    }
    draw();
  });
  // A line clicked: the block it holds, or the one before it.
  rows.addEventListener('click', e => {
    const n = +(e.target.closest('[data-line]') || {dataset: {}}).dataset.line;
    let lo = 0, hi = blockLine.length - 1;
    if (!n || hi < 0 || blockLine[0] > n) return;
    while (lo < hi) { const m = (lo + hi + 1) >> 1; if (blockLine[m] <= n) lo = m; else hi = m - 1; }
    document.dispatchEvent(new CustomEvent('pilgrim-go', {detail: lo}));
  });
  new Response(new Blob([packed]).stream().pipeThrough(new DecompressionStream('gzip'))).json().then(p => {
    lines = p.text.split('\\n');
    if (lines[lines.length - 1] === '') lines.pop();
    let l = 0;
    blockLine = p.steps.map(d => (l += d));
    marked = new Set(p.marks || []);
    runs = p.runs || [];
    document.body.dataset.marked = marked.size;
    rows.style.height = lines.length * H + 'px';
    document.body.dataset.listing = lines.length;
    draw();
    document.dispatchEvent(new CustomEvent('pilgrim-listed'));
  }).catch(e => console.error('the program listing did not open', e));
})();";

/// The marks over a plot, drawn over its picture: each pass's line
/// (lit while the player is in its blocks) and the places that take the
/// player to their block.
fn marks(m: &crate::chart::Marks) -> String {
    let mut out = format!(
        "<svg class=\"marks\" viewBox=\"0 0 {} {}\" preserveAspectRatio=\"none\">",
        m.size[0], m.size[1]
    );
    let points = |p: &[[f32; 2]]| {
        p.iter()
            .map(|q| format!("{},{}", q[0], q[1]))
            .collect::<Vec<_>>()
            .join(" ")
    };
    for p in &m.passes {
        let _ = write!(
            out,
            "<{} class=\"pass\" data-first=\"{}\" data-end=\"{}\" points=\"{}\"/>",
            if p.closed { "polygon" } else { "polyline" },
            p.blocks[0],
            p.blocks[1],
            points(&p.points)
        );
    }
    for p in &m.places {
        let _ = write!(
            out,
            "<circle class=\"place\" data-block=\"{}\" cx=\"{}\" cy=\"{}\" r=\"11\"><title>{}: click to see its block</title></circle>",
            p.block,
            p.at[0],
            p.at[1],
            escape(&p.label)
        );
    }
    out.push_str("</svg>");
    out
}

/// The page's text.
pub fn report_html(inputs: &PageInputs<'_>) -> String {
    let r = inputs.report;
    let mut out = String::with_capacity(
        MODEL_VIEWER.len() + inputs.embedded_scene().map_or(0, |s| s.0.len() * 4 / 3) + 200_000,
    );
    let title = format!(
        "pilgrim: {}{} on {}{}",
        r.program_file
            .as_ref()
            .map_or(String::new(), |f| format!("{f} verified against ")),
        r.script,
        r.machine,
        if r.verdict.failed() { " (FAILED)" } else { "" }
    );
    let _ = write!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n<style>\n{}</style>\n</head>\n<body>\n<h1>{}</h1>\n",
        escape(&title),
        STYLE,
        escape(&title)
    );
    let _ = writeln!(
        out,
        "<p class=\"sub\">pilgrim {}; control {}; machine given as {}.</p>",
        escape(&r.pilgrim),
        escape(&r.control),
        escape(&r.machine_spec)
    );
    if let Some(c) = &r.corrected_by {
        let _ = writeln!(
            out,
            "<p class=\"sub corrected\">A corrected program: {}.</p>",
            escape(c)
        );
    }
    banner(&mut out, r);
    twin(&mut out, inputs);
    summary(&mut out, r);
    verification(&mut out, r);
    warnings_and_checks(&mut out, r);
    clearances(&mut out, r);
    pass_times(&mut out, r);
    plots_and_parameters(&mut out, inputs);
    scripts(&mut out, inputs);
    out.push_str("</body>\n</html>\n");
    out
}

/// The summary's table: passes, points, blocks, the cycle time, the 3-D
/// pose and the files.
fn summary(out: &mut String, r: &Report) {
    out.push_str("<h2>Summary</h2>\n<table>\n");
    for (k, v) in [
        (
            "passes",
            format!("{} ({} cutting)", r.passes, r.cutting_passes),
        ),
        ("toolpath points", r.points.to_string()),
        ("blocks", r.blocks.to_string()),
        (
            "cycle time",
            match &r.times {
                Some(t) => format!(
                    "{} min with the axes' acceleration ({} min at the programmed feeds, {:+.1} %)",
                    fixed(t.accelerated_min, 2),
                    fixed(t.programmed_min, 2),
                    if t.programmed_min > 0.0 {
                        100.0 * (t.accelerated_min / t.programmed_min - 1.0)
                    } else {
                        0.0
                    }
                ),
                None => format!("{} min", fixed(r.cycle_time_min, 2)),
            },
        ),
        (
            "3-D pose",
            r.pose_block.map_or("none".into(), |b| {
                format!(
                    "{}block {b} ({})",
                    if r.pose_along < 1.0 {
                        format!("{}% of the way through ", fixed(100.0 * r.pose_along, 0))
                    } else {
                        String::new()
                    },
                    r.block_label(b - 1)
                )
            }),
        ),
        ("files", r.files.join(", ")),
    ] {
        row(out, &[k.into(), escape(&v)]);
    }
    out.push_str("</table>\n");
}

/// The family's warnings and its checks.
fn warnings_and_checks(out: &mut String, r: &Report) {
    if !r.warnings.is_empty() {
        out.push_str("<h2>Warnings</h2>\n<ul class=\"warn\">\n");
        for w in &r.warnings {
            let _ = writeln!(out, "<li>{}</li>", escape(w));
        }
        out.push_str("</ul>\n");
    }
    out.push_str("<h2>Checks</h2>\n<table><tr><th>check</th><th></th><th>detail</th></tr>\n");
    for c in &r.checks {
        row(
            out,
            &[
                escape(&c.name),
                if c.ok { "ok" } else { "FAILED" }.into(),
                escape(&c.detail),
            ],
        );
    }
    out.push_str("</table>\n");
}

/// The plots with their marks, the parameters and the figures the family
/// noted.
fn plots_and_parameters(out: &mut String, inputs: &PageInputs<'_>) {
    let r = inputs.report;
    let b64 = base64::engine::general_purpose::STANDARD;
    if !inputs.plots.is_empty() {
        out.push_str("<h2>Plots</h2>\n");
        for (name, svg) in &inputs.plots {
            let _ = writeln!(
                out,
                "<figure><div class=\"plot\"><img alt=\"{0}\" src=\"data:image/svg+xml;base64,{1}\">{2}</div><figcaption>{0}</figcaption></figure>",
                escape(name),
                b64.encode(svg),
                r.marks.get(*name).map_or(String::new(), marks)
            );
        }
    }
    out.push_str("<h2>Parameters</h2>\n<table><tr><th>name</th><th>value</th><th>unit</th></tr>\n");
    for (name, p) in &r.parameters {
        let value = serde_json::to_string(&p.value).unwrap_or_default();
        row(out, &[escape(name), escape(&value), escape(&p.unit)]);
    }
    out.push_str("</table>\n");
    if !r.notes.is_empty() {
        out.push_str("<h2>Figures the family noted</h2>\n<table>\n");
        for (k, v) in &r.notes {
            row(out, &[escape(k), format!("{v}")]);
        }
        out.push_str("</table>\n");
    }
}

/// The page's scripts: whatever names a block takes the player there; the
/// 3-D viewer where the page embeds a scene.
fn scripts(out: &mut String, inputs: &PageInputs<'_>) {
    // Whatever names a block (a table's row, a plot's mark) takes the
    // player there, and the view to the machine.
    out.push_str("<script>\ndocument.querySelectorAll('[data-block]').forEach(el => el.addEventListener('click', () => {\n  document.dispatchEvent(new CustomEvent('pilgrim-go', {detail: +el.dataset.block}));\n  document.querySelector('.twin').scrollIntoView({block: 'start'});\n}));\ndocument.querySelectorAll('[data-line]').forEach(el => el.addEventListener('click', () => {\n  document.dispatchEvent(new CustomEvent('pilgrim-line', {detail: +el.dataset.line}));\n  document.querySelector('.twin').scrollIntoView({block: 'start'});\n}));\n// The pass the player is in, lit on the plots that mark passes.\nconst passMarks = [...document.querySelectorAll('.marks .pass')];\ndocument.addEventListener('pilgrim-block', e => passMarks.forEach(m => m.classList.toggle('now', +m.dataset.first <= e.detail && e.detail < +m.dataset.end)));\n</script>\n");
    if inputs.embedded_scene().is_some() {
        // The state of the 3-D view for whoever watches the page (and the
        // headless check): data-model on <body> becomes "loaded" or "error".
        out.push_str(
            "<script>\nconst viewer = document.getElementById('scene');\n\
             viewer.addEventListener('load', () => { document.body.dataset.model = 'loaded'; });\n\
             viewer.addEventListener('error', (e) => { document.body.dataset.model = 'error'; console.error('scene.glb did not load', e.detail); });\n\
             </script>\n<script type=\"module\">\n",
        );
        // The bundle holds no "</script"; were a release to, this keeps
        // the element closed where it should be.
        out.push_str(&MODEL_VIEWER.replace("</script", "<\\/script"));
        out.push_str("\n</script>\n");
    }
}

/// The page of a run from its files (name, bytes): the plots (`.svg`),
/// the program it lists (`program`: its name and text, none where the run
/// wrote none) and `scene.glb`, the camera framing `part_box` (mm:
/// [`super::scene::contact_box`]).
pub(crate) fn page_of(
    report: &Report,
    files: &[(String, Vec<u8>)],
    program: Option<(&str, &str)>,
    part_box: Option<([f64; 3], [f64; 3])>,
) -> String {
    report_html(&PageInputs {
        report,
        plots: files
            .iter()
            .filter(|f| f.0.ends_with(".svg"))
            .map(|f| (f.0.as_str(), f.1.as_slice()))
            .collect(),
        program,
        scene: files
            .iter()
            .find(|f| f.0 == "scene.glb")
            .map(|f| f.1.as_slice())
            .zip(part_box)
            .map(|(glb, (lo, hi))| (glb, lo, hi)),
    })
}

/// The control's program among a run's `files`, as the page lists it:
/// `program.<extension>` and its text.
pub(crate) fn written_program<'a>(
    files: &'a [(String, Vec<u8>)],
    extension: &str,
) -> Option<(&'a str, &'a str)> {
    let name = format!("program.{extension}");
    files
        .iter()
        .find(|f| f.0 == name)
        .and_then(|f| Some((f.0.as_str(), std::str::from_utf8(&f.1).ok()?)))
}

/// The page's style: readable on screen and on A4.
const STYLE: &str = "body { font: 14px/1.45 system-ui, sans-serif; margin: 24px auto; max-width: 1100px; padding: 0 16px; color: #1b1f24; }
h1 { font-size: 22px; margin-bottom: 2px; }
h2 { font-size: 17px; margin-top: 28px; border-bottom: 1px solid #ccd; }
.sub { color: #556; margin-top: 0; }
.verdict { font-size: 15px; }
.banner { border: 2px solid; border-radius: 6px; padding: 8px 12px; margin: 12px 0; }
.banner.passed { border-color: #2e7d32; background: #edf7ee; }
.banner.failed { border-color: #c62828; background: #fdecea; }
.banner.unverified { border-color: #b26a00; background: #fff4e0; }
table { border-collapse: collapse; margin: 6px 0; }
td, th { border: 1px solid #ccd; padding: 3px 8px; text-align: left; vertical-align: top; }
th { background: #eef0f4; }
ul.warn li { color: #8a4b00; }
figure { margin: 12px 0; }
figure img { max-width: 100%; height: auto; border: 1px solid #ddd; display: block; }
.plot { position: relative; display: inline-block; max-width: 100%; }
.marks { position: absolute; left: 0; top: 0; width: 100%; height: 100%; pointer-events: none; }
.marks .pass { fill: none; stroke: none; }
.marks .pass.now { stroke: #111; stroke-width: 3; }
.marks polygon.pass.now { fill: rgba(255, 255, 255, 0.35); }
.marks .place { fill: transparent; stroke: #c62828; stroke-width: 2.5; pointer-events: all; cursor: pointer; }
.marks .place:hover { fill: rgba(198, 40, 40, 0.2); }
figcaption { color: #556; font-size: 12px; }
model-viewer { width: 100%; height: 400px; background: #20262e; display: block; }
.twin { display: grid; grid-template-columns: minmax(0, 3fr) minmax(0, 2fr); gap: 14px; align-items: start; }
.twin h2 { margin-top: 8px; }
.hint { color: #556; font-size: 12px; margin: 2px 0; }
#listing { position: relative; height: 438px; overflow: auto; background: #f6f7f9; border: 1px solid #dde; font: 12px/17px ui-monospace, monospace; }
#listing .rows { position: relative; min-width: 100%; }
#listing .rows div { position: absolute; left: 0; right: 0; height: 17px; padding: 0 6px; white-space: pre; cursor: pointer; }
#listing .rows div:hover { background: #eef3ff; }
#listing .rows div.now { background: #ffe08a; }
#listing .rows div.fail { background: #ffd0d0; }
.player { margin: 6px 0; display: flex; gap: 10px; align-items: center; }
.player input[type=range] { flex: 1; }
tr[data-block] { cursor: pointer; }
tr[data-block]:hover td { background: #eef3ff; }
@media print { model-viewer, .player, #listing { display: none; } .twin { display: block; } body { max-width: none; } }
";

#[cfg(test)]
mod tests {
    use super::*;

    /// A report with nothing in it but what `report.json` must hold.
    fn bare_report() -> Report {
        serde_json::from_value(serde_json::json!({
            "pilgrim": "0", "script": "s.rhai", "machine": "m", "machine_spec": "m",
            "control": "fanuc", "parameters": {}, "passes": 0, "points": 0, "blocks": 0,
            "cycle_time_min": 0.0, "files": [], "checks": [], "mesh_tolerance_mm": 0.01
        }))
        .unwrap()
    }

    /// A scene past the page's bound is left out of the page, which says
    /// so, how large it is and where the full one is; one within it is
    /// embedded with its viewer.
    #[test]
    fn a_scene_too_large_for_a_page_is_named_not_embedded() {
        let r = bare_report();
        let page = |glb: &[u8]| {
            report_html(&PageInputs {
                report: &r,
                plots: vec![],
                program: None,
                scene: Some((glb, [0.0; 3], [1.0; 3])),
            })
        };
        let small = page(b"glTF");
        assert!(small.contains("<model-viewer id=\"scene\""));
        let large = page(&vec![0u8; MAX_EMBEDDED_SCENE_BYTES + 1]);
        assert!(!large.contains("<model-viewer") && !large.contains("data:model/gltf-binary"));
        assert!(
            large.contains("scene.glb is 32.0 MB, more than the 32 MB a page embeds"),
            "{}",
            &large[large.find("<h2>3-D").unwrap_or(0)..][..400]
        );
        assert!(large.len() < 2 * 1024 * 1024, "{}", large.len());
    }

    #[test]
    fn text_is_escaped() {
        assert_eq!(
            escape("<a href=\"x\">'&'</a>"),
            "&lt;a href=&quot;x&quot;&gt;&#39;&amp;&#39;&lt;/a&gt;"
        );
    }
}
