//! The passes (docs/math.md §4.3, §4.4 with the corrections of issue 13): the
//! roughing law of decreasing infeed with its minimum depth, the flank
//! each pass cuts on, the finishing passes, the universal cutter's axial
//! steps, and the order of the starts.

use super::ThreadCutter;
use crate::families::thread::ThreadSection;
use crate::input::InputError;
use crate::math::Real;
use serde::Serialize;

/// The most passes a plan may have (all starts together): beyond it the
/// depth law or the axial step is certainly mistyped.
pub const MAX_PASSES: usize = 20_000;

/// The cumulative depths of the roughing passes (mm, increasing, the last
/// `h_r`): the law `D_i = h_r sqrt(i / n)` (equal chip areas for a sharp V
/// tool). A pass the law makes thinner than `a_min` is raised to `a_min`
/// and the passes go on until `h_r` is reached; the last pass is what
/// remains, no deeper than `a_min` once the raising began (the seed's
/// condition; it may be thinner). With `n` of
/// `None` the seed's rational number of passes: the least `n` whose law
/// makes the last pass no deeper than `a_min`.
///
/// # Failures
/// `h_r` or `a_min` not positive, `a_min` above `h_r`, `n` of 0 or more
/// than [`MAX_PASSES`].
pub fn roughing_depths(h_r: Real, n: Option<usize>, a_min: Real) -> Result<Vec<Real>, InputError> {
    crate::math::positive("roughing depth", h_r)?;
    crate::math::positive("minimum depth of cut a_min", a_min)?;
    if a_min > h_r {
        return Err(InputError::out_of_range(
            "minimum depth of cut a_min",
            a_min,
            format!("at most the roughing depth {h_r:.4} mm"),
        ));
    }
    let n = match n {
        Some(n) if n == 0 || n > MAX_PASSES => {
            return Err(InputError::out_of_range(
                "roughing passes n",
                n as f64,
                format!("from 1 to {MAX_PASSES} (0 asks for the rational number: leave it out)"),
            ))
        }
        Some(n) => n,
        None => rational_passes(h_r, a_min),
    };
    let law = |i: usize| h_r * ((i as Real).sqrt() - ((i - 1) as Real).sqrt()) / (n as Real).sqrt();
    let mut out = Vec::new();
    let mut d = 0.0;
    let mut i = 1;
    while d < h_r {
        let a = law(i).max(a_min);
        d = (d + a).min(h_r);
        // Within rounding of the depth: the depth.
        if h_r - d < crate::tolerance::SAME_LENGTH {
            d = h_r;
        }
        out.push(d);
        i += 1;
    }
    Ok(out)
}

/// The seed's rational number of passes: the least `n` whose last pass by
/// the law, `h_r (1 - sqrt(1 - 1/n))`, is no deeper than `a_min`.
pub fn rational_passes(h_r: Real, a_min: Real) -> usize {
    (1..=MAX_PASSES)
        .find(|&n| h_r * (1.0 - (1.0 - 1.0 / n as Real).sqrt()) <= a_min)
        .unwrap_or(MAX_PASSES)
}

/// The universal cutter's axial offset to each flank (docs/math.md §4.4):
/// `a_1z = (P_z / z1 - S_a1 - S_a1r) / 2`, the space at the pitch line
/// less `S_a1r`, the cutter's width at the pitch line when its tip is at
/// the root.
pub fn axial_offset(t: &ThreadSection, c: &ThreadCutter) -> Real {
    let s_a1r = c.width_at((t.pitch_diameter / 2.0 - t.root_diameter / 2.0).abs());
    (t.space_at_pitch - s_a1r) / 2.0
}

/// Each side step's planned area, the area it removes: the planned
/// passes of one start cut in order from the space's section (the blank
/// from the tip radius down) with polygon booleans, as the simulation cuts
/// the program ([`super::simulate`]); a side step of a universal cutter
/// takes only what the passes before it left at the root's corners and on
/// the flanks, not its width times the depth.
fn side_step_areas(t: &ThreadSection, c: &ThreadCutter, steps: &mut [PlannedPass]) {
    use geo::{Area, BooleanOps, MultiPolygon};
    if !steps.iter().any(|p| p.kind == PassKind::Side) {
        return;
    }
    // In depth below the crest: the areas are an internal thread's too.
    let r_a = t.crest_diameter / 2.0;
    let deepest = steps.iter().map(|p| p.cumulative).fold(0.0, Real::max);
    let half = t.pitch / 2.0;
    let mut material = MultiPolygon::new(vec![super::simulate::rect(
        -half,
        half,
        r_a - deepest - 1.0,
        r_a,
    )]);
    for p in steps.iter_mut() {
        let tip = r_a - p.cumulative;
        let section: Vec<[Real; 2]> = c
            .section(p.cumulative + 1.0)
            .iter()
            .map(|q| [q[0] + p.offset, q[1] + tip])
            .collect();
        let cutter = MultiPolygon::new(vec![super::simulate::poly(&section)]);
        if p.kind == PassKind::Side {
            p.planned_area = material.intersection(&cutter).unsigned_area();
        }
        material = material.difference(&cutter);
    }
}

/// Which flanks the roughing passes cut on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FlankOrder {
    /// Now the left, now the right (the seed's).
    Alternating,
    /// The left flank only.
    Left,
    /// The right flank only.
    Right,
    /// Straight in, centred on the space.
    Radial,
}

impl FlankOrder {
    /// The order called `name` (`alternating`, `left`, `right`, `radial`).
    ///
    /// # Failures
    /// Another name (the message names it).
    pub fn parse(name: &str) -> Result<Self, crate::input::InputError> {
        Ok(match name {
            "alternating" => Self::Alternating,
            "left" => Self::Left,
            "right" => Self::Right,
            "radial" => Self::Radial,
            other => {
                return Err(crate::input::InputError::BadText {
                    what: "flank order".into(),
                    value: format!("'{other}'"),
                    reason: "is not alternating, left, right or radial".into(),
                })
            }
        })
    }
}

/// The flank a pass cuts on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Flank {
    /// The left flank (towards -z).
    Left,
    /// The right flank (towards +z).
    Right,
    /// Both, centred.
    Radial,
}

/// What a pass is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PassKind {
    /// Roughing by the law.
    Rough,
    /// A finishing pass, radial.
    Finish,
    /// A finishing pass stepped along the axis (the universal cutter).
    Side,
}

/// One planned thread pass.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PlannedPass {
    /// What it is for.
    pub kind: PassKind,
    /// The start it cuts (from 0).
    pub start: u32,
    /// Its depth of cut (mm): the infeed since the last pass's depth.
    pub depth: Real,
    /// Its cumulative depth below the tip radius (mm).
    pub cumulative: Real,
    /// The cutter's axial offset from the space's centre (mm, + towards +z).
    pub offset: Real,
    /// The flank it cuts on.
    pub flank: Flank,
    /// The chip area the plan expects (mm^2): for a roughing or finishing
    /// pass a radial infeed of this cutter from the last depth (the law's
    /// area), for a side step the area it removes beside the passes before
    /// it at its start (`side_step_areas`).
    pub planned_area: Real,
}

/// How the passes are laid out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanSettings {
    /// Roughing passes by the law, or `None` for the rational number.
    pub roughing_passes: Option<usize>,
    /// The least depth of cut (mm).
    pub min_depth: Real,
    /// Depth of each finishing pass (mm).
    pub finish_depth: Real,
    /// Number of finishing passes (0: none).
    pub finish_passes: usize,
    /// The roughing passes' flanks.
    pub order: FlankOrder,
    /// The largest axial step of the universal cutter's offset (mm).
    pub axial_step: Real,
    /// Every start at each depth before the next (`true`), or each start
    /// completely before the next.
    pub starts_by_depth: bool,
}

/// The whole plan: every pass in the order cut, all starts.
///
/// # Failures
/// A form cutter ([`ThreadCutter::ground_to`]) on any flank order but
/// radial; the finishing stock at or beyond the thread's height; a roughing law
/// that cannot be laid out ([`roughing_depths`]); a non-positive axial
/// step; more passes than [`MAX_PASSES`].
pub fn plan(
    t: &ThreadSection,
    c: &ThreadCutter,
    s: &PlanSettings,
) -> Result<Vec<PlannedPass>, InputError> {
    let h = t.depth();
    crate::math::finite("finishing depth", s.finish_depth)?;
    let stock = s.finish_depth * s.finish_passes as Real;
    if s.finish_depth < 0.0 || !(stock < h) {
        return Err(InputError::out_of_range(
            "finishing depth x passes (mm)",
            stock,
            format!("from 0 to below the thread's height h1 = {h:.4} mm"),
        ));
    }
    if c.ground.is_some() && s.order != FlankOrder::Radial {
        return Err(InputError::BadText {
            what: "flank order".into(),
            value: format!("\"{:?}\"", s.order).to_lowercase(),
            reason: "is refused for a form cutter ground to curved flanks (ZN, ZI): it plunges straight in, flank order radial (moved along a flank, its curve would cross the flank's)".into(),
        });
    }
    let rough = roughing_depths(h - stock, s.roughing_passes, s.min_depth)?;
    let mut steps = rough_steps(t, c, s.order, &rough);
    let last = rough.last().copied().unwrap_or(0.0);
    let sides = side_count(t, c, s.axial_step)?;
    finish_steps(t, c, s, (last, sides), &mut steps);
    side_step_areas(t, c, &mut steps);
    let z1 = t.starts;
    if steps.len() * z1 as usize > MAX_PASSES {
        return Err(InputError::out_of_range(
            "passes (all starts)",
            (steps.len() * z1 as usize) as f64,
            format!("at most {MAX_PASSES}"),
        ));
    }
    let mut out = Vec::with_capacity(steps.len() * z1 as usize);
    if s.starts_by_depth {
        for p in &steps {
            out.extend((0..z1).map(|k| PlannedPass { start: k, ..*p }));
        }
    } else {
        for k in 0..z1 {
            out.extend(steps.iter().map(|p| PlannedPass { start: k, ..*p }));
        }
    }
    Ok(out)
}

/// The chip's area between the depths `d0` and `d1` of cutter `c`'s
/// section.
fn area(c: &ThreadCutter, d0: Real, d1: Real) -> Real {
    c.tip_width * (d1 - d0) + 0.5 * (c.left_angle.tan() + c.right_angle.tan()) * (d1 * d1 - d0 * d0)
}

/// The roughing passes at one start to the depths `rough`, on the flanks
/// `order` gives: on a flank the cutter's edge stands on that flank's
/// final line.
fn rough_steps(
    t: &ThreadSection,
    c: &ThreadCutter,
    order: FlankOrder,
    rough: &[Real],
) -> Vec<PlannedPass> {
    let h = t.depth();
    let tan = |flank: Flank| match flank {
        Flank::Left => t.flanks[0].tan(),
        Flank::Right | Flank::Radial => t.flanks[1].tan(),
    };
    let mut steps: Vec<PlannedPass> = Vec::new();
    let mut last = 0.0;
    for (i, &d) in rough.iter().enumerate() {
        let flank = match order {
            FlankOrder::Alternating if i % 2 == 0 => Flank::Left,
            FlankOrder::Alternating | FlankOrder::Right => Flank::Right,
            FlankOrder::Left => Flank::Left,
            FlankOrder::Radial => Flank::Radial,
        };
        let e = (h - d) * tan(flank);
        steps.push(PlannedPass {
            kind: PassKind::Rough,
            start: 0,
            depth: d - last,
            cumulative: d,
            offset: match flank {
                Flank::Left => -e,
                Flank::Right => e,
                Flank::Radial => 0.0,
            },
            flank,
            planned_area: area(c, last, d),
        });
        last = d;
    }
    steps
}

/// How many side steps a universal cutter takes to each flank (its axial
/// offset over `axial_step`); none for a full-profile cutter.
///
/// # Failures
/// A step not positive, or so small it would make more than
/// [`MAX_PASSES`].
fn side_count(t: &ThreadSection, c: &ThreadCutter, axial_step: Real) -> Result<usize, InputError> {
    let a1z = axial_offset(t, c);
    if a1z <= crate::tolerance::SAME_LENGTH {
        return Ok(0);
    }
    crate::math::positive("axial step of the universal cutter", axial_step)?;
    let n = (a1z / axial_step).ceil();
    if n > MAX_PASSES as Real {
        return Err(InputError::out_of_range(
            "axial step of the universal cutter",
            axial_step,
            format!(
                "at least a_1z / {MAX_PASSES} = {:.6} mm",
                a1z / MAX_PASSES as Real
            ),
        ));
    }
    Ok(n as usize)
}

/// The finishing passes after the roughing's `last` depth, each followed
/// by `sides` side steps to each flank (after the roughing where there is
/// no finishing pass), added to `steps`.
fn finish_steps(
    t: &ThreadSection,
    c: &ThreadCutter,
    s: &PlanSettings,
    (mut last, sides): (Real, usize),
    steps: &mut Vec<PlannedPass>,
) {
    let a1z = axial_offset(t, c);
    let side_steps = |steps: &mut Vec<PlannedPass>, d: Real| {
        for (sign, flank) in [(-1.0, Flank::Left), (1.0, Flank::Right)] {
            for k in 1..=sides {
                steps.push(PlannedPass {
                    kind: PassKind::Side,
                    start: 0,
                    depth: 0.0,
                    cumulative: d,
                    offset: sign * a1z * k as Real / sides as Real,
                    flank,
                    planned_area: a1z / sides as Real * d,
                });
            }
        }
    };
    for _ in 1..=s.finish_passes {
        let d = last + s.finish_depth;
        steps.push(PlannedPass {
            kind: PassKind::Finish,
            start: 0,
            depth: s.finish_depth,
            cumulative: d,
            offset: 0.0,
            flank: Flank::Radial,
            planned_area: area(c, last, d),
        });
        last = d;
        side_steps(steps, d);
    }
    if s.finish_passes == 0 {
        side_steps(steps, last);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::families::thread::WormSizes;

    /// D_i = h sqrt(i / n) where no pass falls below a_min.
    #[test]
    fn the_law_of_decreasing_infeed() {
        let d = roughing_depths(10.8, Some(12), 0.01).unwrap();
        assert_eq!(d.len(), 12);
        for (i, v) in d.iter().enumerate() {
            assert!((v - 10.8 * ((i + 1) as f64 / 12.0).sqrt()).abs() < 1e-12);
        }
        assert_eq!(*d.last().unwrap(), 10.8);
    }

    /// A pass the law makes thinner than a_min is raised to a_min; the
    /// passes go on to the depth; none is thinner than a_min.
    #[test]
    fn the_minimum_depth_rule() {
        let (h, n, a_min) = (10.8, 60, 0.3);
        let d = roughing_depths(h, Some(n), a_min).unwrap();
        let cuts: Vec<f64> = std::iter::once(d[0])
            .chain(d.windows(2).map(|w| w[1] - w[0]))
            .collect();
        let (last, before) = cuts.split_last().unwrap();
        assert!(before.iter().all(|a| *a >= a_min - 1e-12), "{cuts:?}");
        // The seed's condition: the last pass no deeper than a_min.
        assert!(*last > 0.0 && *last <= a_min + 1e-12, "{last}");
        assert_eq!(*d.last().unwrap(), h);
        // Fewer passes than n: the thin ones were raised.
        assert!(d.len() < n, "{}", d.len());
        // The law holds until it falls below a_min, then a_min.
        let law = |i: f64| h * (i.sqrt() - (i - 1.0).sqrt()) / (n as f64).sqrt();
        let k = (1..=n).find(|&i| law(i as f64) < a_min).unwrap();
        for i in 1..k {
            assert!((cuts[i - 1] - law(i as f64)).abs() < 1e-12);
        }
        for c in &cuts[k - 1..cuts.len() - 1] {
            assert!((c - a_min).abs() < 1e-12, "{c}");
        }
        // a_min above the depth is refused, naming it.
        let e = roughing_depths(0.2, Some(3), 0.5).unwrap_err().to_string();
        assert!(e.contains("a_min") && e.contains("0.5"), "{e}");
    }

    /// The rational number: the least n whose last pass is at most a_min.
    #[test]
    fn the_rational_number_of_passes() {
        let n = rational_passes(10.8, 0.1);
        let last = |n: usize| 10.8 * (1.0 - (1.0 - 1.0 / n as f64).sqrt());
        assert!(last(n) <= 0.1 && last(n - 1) > 0.1, "{n}");
        assert_eq!(n, 55);
        assert_eq!(
            roughing_depths(10.8, None, 0.1).unwrap(),
            roughing_depths(10.8, Some(n), 0.1).unwrap()
        );
    }

    /// a_1z: the formula, and for a cutter of the worm's flank angle, half
    /// the difference of the widths at the root.
    #[test]
    fn the_universal_cutters_offset() {
        let a = 20f64.to_radians();
        let w = WormSizes::new(5.0, 2, 50.0, 0.2, a, None).unwrap();
        let c = ThreadCutter::new(2.0, 0.2, a, a, 15.0).unwrap();
        let s_a1r = 2.0 + 2.0 * 6.0 * a.tan();
        let by_formula = (w.lead() / 2.0 - w.thickness - s_a1r) / 2.0;
        assert!((axial_offset(&w.section(), &c) - by_formula).abs() < 1e-12);
        assert!((axial_offset(&w.section(), &c) - (w.root_space() - 2.0) / 2.0).abs() < 1e-12);
        let s = PlanSettings {
            roughing_passes: Some(20),
            min_depth: 0.1,
            finish_depth: 0.1,
            finish_passes: 2,
            order: FlankOrder::Alternating,
            axial_step: 0.2,
            starts_by_depth: true,
        };
        let p = plan(&w.section(), &c, &s).unwrap();
        let side: Vec<_> = p.iter().filter(|p| p.kind == PassKind::Side).collect();
        // ceil(0.743 / 0.2) = 4 steps each way, at both finishing depths, both starts.
        assert_eq!(side.len(), 4 * 2 * 2 * 2);
        assert!(side
            .iter()
            .all(|p| p.offset.abs() <= axial_offset(&w.section(), &c) + 1e-12));
        assert!(side.windows(2).all(|q| q[0].start != q[1].start
            || (q[0].offset - q[1].offset).abs() <= 0.2 + 1e-12
            || q[1].offset.abs() <= 0.2 + 1e-12));
        // Starts by depth: start 0 then 1 at each position.
        assert_eq!((p[0].start, p[1].start), (0, 1));
        assert_eq!(p[0].cumulative, p[1].cumulative);
        assert!((p.last().unwrap().cumulative - w.height()).abs() < 1e-12);
        // The alternating roughing passes put the edge on the flank's final line.
        assert_eq!(p[0].flank, Flank::Left);
        assert!((p[0].offset + (w.height() - p[0].cumulative) * a.tan()).abs() < 1e-12);
        assert_eq!(p[2].flank, Flank::Right);
    }

    /// A form cutter ground to curved flanks plunges radially: any flank
    /// order but radial is refused, naming it.
    #[test]
    fn a_form_cutter_plunges_straight_in() {
        use crate::families::thread::{WormProfile, WormSizes};
        let a = 20f64.to_radians();
        let w = WormSizes::with_profile(5.0, 2, 50.0, 0.2, a, None, WormProfile::ZI).unwrap();
        let t = w.section();
        let c = ThreadCutter::ground_to(t.form, w.root_radius(), 0.3, 13.0).unwrap();
        let mut s = PlanSettings {
            roughing_passes: None,
            min_depth: 0.15,
            finish_depth: 0.05,
            finish_passes: 2,
            order: FlankOrder::Alternating,
            axial_step: 0.5,
            starts_by_depth: true,
        };
        let e = plan(&t, &c, &s).unwrap_err().to_string();
        assert!(
            e.contains("flank order \"alternating\" is refused for a form cutter"),
            "{e}"
        );
        s.order = FlankOrder::Radial;
        let passes = plan(&t, &c, &s).unwrap();
        // Its width at the pitch line is the space's: no side steps.
        assert!(passes
            .iter()
            .all(|p| p.offset == 0.0 && p.kind != PassKind::Side));
        assert!(axial_offset(&t, &c).abs() < 1e-12);
    }
}
