//! How the corrected program differs from the first: its lines counted
//! as multisets, its path compared pass by pass, and the chart of how far
//! each pass moved.

use super::Tables;
use crate::program::{AxisProgram, ProgramPass};
use serde::Serialize;
use std::collections::BTreeMap;

/// How the program changed: its lines kept, added and removed, and how
/// far its path moved. Lines are counted as multisets, not aligned: a
/// corrected target may place its blocks anew (the mandrel's are spaced to
/// its profile), so which block became which is not known, and an
/// aligning diff (Myers') takes the product of the lines and the changes,
/// 20 s for a caliber's 52,000 blocks nearly all moved; the path is
/// compared instead, block by block.
#[derive(Debug, Clone, Serialize)]
pub struct ProgramChange {
    /// The program's file.
    pub file: String,
    /// Lines the same (each as often as both have it).
    pub lines_kept: usize,
    /// Lines the corrected program has that the first had not.
    pub lines_added: usize,
    /// Lines the first had that the corrected has not.
    pub lines_removed: usize,
    /// How far the tool's path moved, per axis: each block of the
    /// corrected program against the original's path in the same pass
    /// (its nearest point on the pass's polyline in the axes' space); none
    /// where the passes or axes differ.
    pub path_moved: Option<BTreeMap<String, f64>>,
    /// The corrected program's blocks that stand more than
    /// [`MOVED`] mm off the original's path (in the axes' space); none
    /// where the passes or axes differ.
    pub blocks_moved: Option<usize>,
}

/// A block this far off the original program's path (mm, in the axes'
/// space: 0.1 um, the programs' last digit) has moved.
pub const MOVED: f64 = 1e-4;

/// The program's lines from `before` to `after` (`file`'s), counted as
/// multisets (see [`ProgramChange`]).
pub(super) fn change(file: &str, before: &str, after: &str) -> ProgramChange {
    let mut count: std::collections::HashMap<&str, i64> = std::collections::HashMap::new();
    for l in before.lines() {
        *count.entry(l).or_default() += 1;
    }
    let mut kept = 0;
    for l in after.lines() {
        if let Some(n) = count.get_mut(l).filter(|n| **n > 0) {
            *n -= 1;
            kept += 1;
        }
    }
    ProgramChange {
        file: file.to_owned(),
        lines_kept: kept,
        lines_added: after.lines().count() - kept,
        lines_removed: before.lines().count() - kept,
        path_moved: None,
        blocks_moved: None,
    }
}

/// How far each axis of `after`'s blocks stands from `before`'s path in
/// the same pass (see [`ProgramChange::path_moved`]). Both programs run
/// along their passes the same way, so each block's nearest segment is
/// sought near the one before's ([`WINDOW`] segments either side): the
/// work grows with the blocks, not with their square (a caliber's 52,000).
pub(super) fn path_moved(
    before: &AxisProgram,
    before_passes: &[ProgramPass],
    after: &AxisProgram,
    after_passes: &[ProgramPass],
) -> Option<Moved> {
    if before.axes != after.axes || before_passes.len() != after_passes.len() {
        return None;
    }
    let n = after.axes.len();
    let mut by_pass: Vec<Vec<f64>> = Vec::with_capacity(after_passes.len());
    let mut blocks = 0;
    for (p, q) in before_passes.iter().zip(after_passes) {
        let mut line: Vec<&[f64]> = before
            .blocks
            .get(p.blocks.clone())?
            .iter()
            .map(|b| b.values.as_slice())
            .collect();
        if line.len() == 1 {
            line.push(line[0]);
        }
        let (moved, n_moved) = pass_moved(&line, after.blocks.get(q.blocks.clone())?, n);
        blocks += n_moved;
        by_pass.push(moved);
    }
    let names: Vec<String> = after.axes.iter().map(|a| a.name.clone()).collect();
    let largest = (0..n)
        .map(|i| by_pass.iter().map(|m| m[i]).fold(0.0, f64::max))
        .collect::<Vec<f64>>();
    Some(Moved {
        largest: names.iter().cloned().zip(largest).collect(),
        blocks,
        axes: names,
        by_pass,
    })
}

/// How far each axis of `blocks` stands from the polyline `line` (a pass of
/// the first program, `n` axes), the largest per axis, and how many
/// blocks stand more than [`MOVED`] off it.
fn pass_moved(line: &[&[f64]], blocks: &[crate::program::Block], n: usize) -> (Vec<f64>, usize) {
    let mut moved: Vec<f64> = vec![0.0; n];
    let mut count = 0;
    // Each segment's direction and squared length, once per pass.
    let dirs: Vec<(Vec<f64>, f64)> = line
        .windows(2)
        .map(|w| {
            let d: Vec<f64> = w[1].iter().zip(w[0]).map(|(b, a)| b - a).collect();
            let l2 = d.iter().map(|x| x * x).sum();
            (d, l2)
        })
        .collect();
    let mut near: usize = 0;
    for b in blocks {
        let v = &b.values;
        // Where on segment k the block's nearest point lies (0 to 1),
        // and the squared distance to it; no allocation per segment.
        let nearest = |k: usize| {
            let (a, (d, l2)) = (line[k], &dirs[k]);
            let t = if *l2 > 0.0 {
                let dot: f64 = v.iter().zip(a).zip(d).map(|((v, a), d)| (v - a) * d).sum();
                (dot / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let dist2: f64 = v
                .iter()
                .zip(a)
                .zip(d)
                .map(|((v, a), d)| (v - a - d * t).powi(2))
                .sum();
            (t, dist2)
        };
        let (lo, hi) = (
            near.saturating_sub(WINDOW),
            (near + WINDOW + 1).min(dirs.len()),
        );
        // The last block's segment first; a segment whose start lies
        // farther than its length beyond the best so far cannot be
        // nearer (nor tie), and is passed over. The same segment as a
        // search of every one in the window.
        let first = near.clamp(lo, hi.saturating_sub(1));
        let mut best = (first, nearest(first));
        for k in lo..hi {
            let from: f64 = v.iter().zip(line[k]).map(|(v, a)| (v - a).powi(2)).sum();
            let reach = best.1 .1.sqrt() + dirs[k].1.sqrt();
            if from > reach * reach * (1.0 + crate::tolerance::LIMIT_SLACK) {
                continue;
            }
            let got = nearest(k);
            if got.1 < best.1 .1 || (got.1 == best.1 .1 && k < best.0) {
                best = (k, got);
            }
        }
        let (k, (t, dist2)) = best;
        near = k;
        count += usize::from(dist2.sqrt() > MOVED);
        for (i, m) in moved.iter_mut().enumerate() {
            *m = m.max((v[i] - line[k][i] - dirs[k].0[i] * t).abs());
        }
    }
    (moved, count)
}

/// How far a corrected program's path moved from the first's
/// ([`path_moved`]).
#[derive(Debug, Clone)]
pub(super) struct Moved {
    /// The largest move of each axis.
    pub(super) largest: BTreeMap<String, f64>,
    /// The blocks moved more than [`MOVED`].
    pub(super) blocks: usize,
    /// The axes, in the program's order.
    axes: Vec<String>,
    /// Each pass's largest move per axis (mm), in that order.
    by_pass: Vec<Vec<f64>>,
}

/// The table `compensation_moves` of `moved` (each pass's largest move
/// per axis, um) added to `tables`, and its chart.
pub(super) fn moves_chart(moved: &Moved, tables: &mut Tables) -> crate::toolpath::PlotSpec {
    const TABLE: &str = "compensation_moves";
    let mut table = BTreeMap::from([(
        "pass".to_owned(),
        (1..=moved.by_pass.len()).map(|k| k as f64).collect(),
    )]);
    let mut y = Vec::new();
    for (i, axis) in moved.axes.iter().enumerate() {
        let column = format!("{axis}_um");
        table.insert(
            column.clone(),
            moved.by_pass.iter().map(|m| 1e3 * m[i]).collect(),
        );
        y.push(column);
    }
    tables.insert(TABLE.into(), table);
    crate::toolpath::PlotSpec {
        file: TABLE.into(),
        title: format!(
            "How far the corrected program's path moved from the first's, each pass's largest per axis ({} blocks moved more than {} um)",
            moved.blocks,
            1e3 * MOVED
        ),
        table: TABLE.into(),
        x: "pass".into(),
        y,
        x_label: "pass".into(),
        y_label: "moved, um (deg on a rotary axis: mdeg)".into(),
    }
}

/// How many segments either side of the last block's nearest one a block's
/// nearest is sought among.
const WINDOW: usize = 64;
