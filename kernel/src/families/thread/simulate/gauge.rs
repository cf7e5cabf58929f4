//! The gauges of the finished section: the pitch diameter, the
//! measurement over wires, the flanks' angles and form, the root and crest.

use super::{
    extreme_top, space_edges, thread_middle, vertical_top, StartProfile, ThreadRequest, INSIDE,
};
use crate::families::thread::{ThreadCutter, ThreadSection};
use crate::math::Real;
use crate::replay::VerifyError;
use crate::tolerance::DERIVATIVE_STEP;
use crate::verdict::Finding;
use geo::MultiPolygon;

/// A diameter of the section from a radius of the simulation's, which is
/// negative for an internal thread's twin.
pub(super) fn diameter(r: Real) -> Real {
    2.0 * r.abs()
}

/// A thread's limits in rho = -r, or back (its own inverse): each band
/// negated, least first.
pub(super) fn mirrored_limits(
    l: &crate::families::thread::ThreadLimits,
) -> crate::families::thread::ThreadLimits {
    let band = |b: &crate::families::thread::Limits| crate::families::thread::Limits {
        min: -b.max,
        max: -b.min,
    };
    crate::families::thread::ThreadLimits {
        pitch_diameter: band(&l.pitch_diameter),
        crest: band(&l.crest),
        root: band(&l.root),
        source: l.source.clone(),
    }
}

/// The diameter where the space round `c` is as wide as the basic
/// section's at its pitch diameter, between the radii `band` (from the cut
/// root, where it stands above the band's start; bisection on the space's
/// width, which grows towards the crest; 0 if it is not within the band).
pub(super) fn pitch_diameter(
    m: &MultiPolygon<Real>,
    t: &ThreadSection,
    c: Real,
    band: (Real, Real),
) -> Real {
    let width = |r: Real| space_edges(m, r, c).map(|(a, b)| b - a);
    let (mut lo, mut hi) = band;
    // Where the cut's root stands above the band's start (the passes'
    // depths rounded to the program's digit), the band starts at it.
    if width(lo).is_none() {
        if let Some(root) = vertical_top(m, c) {
            lo = lo.max(root + INSIDE);
        }
    }
    let (Some(w_lo), Some(w_hi)) = (width(lo), width(hi)) else {
        return 0.0;
    };
    let want = t.space_at_pitch;
    if !(w_lo <= want && want <= w_hi) {
        return 0.0;
    }
    // 50 halvings take a band of millimetres below 1e-12 mm.
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        match width(mid) {
            Some(w) if w < want => lo = mid,
            Some(_) => hi = mid,
            None => return 0.0,
        }
    }
    lo + hi
}

/// The least-squares slope `b` of `z = a + b r`.
pub(super) fn slope(samples: &[(Real, Real)]) -> Real {
    line(samples)[1]
}

/// The least-squares line `z = a + b r`: `[a, b]`.
pub(super) fn line(samples: &[(Real, Real)]) -> [Real; 2] {
    let n = samples.len() as Real;
    let (mr, mz) = samples
        .iter()
        .fold((0.0, 0.0), |(a, b), (r, z)| (a + r / n, b + z / n));
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (r, z) in samples {
        sxy += (r - mr) * (z - mz);
        sxx += (r - mr) * (r - mr);
    }
    let b = sxy / sxx;
    [mz - b * mr, b]
}

/// The radii the flanks of section `w` are measured at: 21, `margin`
/// clear of the root's fillet and the tip's edge.
pub(super) fn flank_radii(w: &ThreadSection, margin: Real, cutter: &ThreadCutter) -> Vec<Real> {
    let r_lo = w.root_diameter / 2.0 + 2.0 * cutter.nose_radius + margin;
    let r_hi = w.crest_diameter / 2.0 - margin;
    (0..21)
        .map(|j| r_lo + (r_hi - r_lo) * j as Real / 20.0)
        .collect()
}

/// The nominal flanks' angles the measured ones are held to (deg, the
/// flank towards -Z first): straight flanks' own; curved flanks' (ZN, ZI)
/// least-squares lines over the `radii` they are measured at, as the
/// measured angles are taken.
pub(super) fn nominal_flanks_deg(w: &ThreadSection, radii: &[Real]) -> [Real; 2] {
    if w.form.is_axial() {
        return w.flanks.map(Real::to_degrees);
    }
    let side = |k: usize, sign: Real| -> Vec<(Real, Real)> {
        radii.iter().map(|&r| (r, sign * w.reach(r)[k])).collect()
    };
    [
        (-slope(&side(0, -1.0))).atan().to_degrees(),
        slope(&side(1, 1.0)).atan().to_degrees(),
    ]
}

/// The finished profile at every start, and what of it fails against the
/// nominal (a start whose space is not there is not measured further).
pub(super) fn measure(
    m: &MultiPolygon<Real>,
    req: &ThreadRequest,
    cutter: &ThreadCutter,
    lead_error: Real,
) -> (Vec<StartProfile>, Vec<Finding>) {
    let fail = |m: String| Finding::new("verification", VerifyError::Failed(m).to_string());
    let mut failures = Vec::new();
    let mut out = Vec::new();
    for k in 0..req.section.starts {
        match measure_start(m, req, cutter, k, lead_error) {
            Ok((p, worst_at, angles)) => {
                failures.extend(
                    start_faults(req, &p, worst_at, angles)
                        .into_iter()
                        .map(fail),
                );
                out.push(p);
            }
            Err(e) => failures.push(fail(e)),
        }
    }
    (out, failures)
}

/// Start `k`'s place in the window (modulo the lead).
fn start_centre(req: &ThreadRequest, k: u32) -> Real {
    let w = &req.section;
    let place = w.hand.start_place(i64::from(k), w.starts);
    req.space_centre + Real::from(place) * w.pitch + req.start_shift(k)
}

/// Start `k`'s space in `m` at radius `r`, or why not.
fn space_of(m: &MultiPolygon<Real>, k: u32, c: Real, r: Real) -> Result<(Real, Real), String> {
    space_edges(m, r, c).ok_or_else(|| {
        format!(
            "start {}: no space cut at diameter {:.3} (the thread's space is not there)",
            k + 1,
            diameter(r)
        )
    })
}

/// Start `k`'s finished profile, the radii where its flanks' form is
/// worst (left, right), and its aimed flanks' angles there (deg); the
/// lead's error over the thread, `lead_error`, for its functional pitch
/// diameter.
///
/// # Failures
/// Its space, or the next start's at the pitch line, not there.
fn measure_start(
    m: &MultiPolygon<Real>,
    req: &ThreadRequest,
    cutter: &ThreadCutter,
    k: u32,
    lead_error: Real,
) -> Result<(StartProfile, [Real; 2], [Real; 2]), String> {
    let w = &req.section;
    let (r_a, r1) = (w.crest_diameter / 2.0, w.pitch_diameter / 2.0);
    let c = start_centre(req, k);
    // The start's aimed space, moved by its correction, and the radii
    // its flanks are measured at.
    let aimed = req.start_section(k);
    let radii = flank_radii(&aimed, req.flank_margin, cutter);
    let (mut left, mut right) = (Vec::new(), Vec::new());
    let (mut form, mut worst_at) = ([0.0 as Real; 2], [0.0; 2]);
    for &r in &radii {
        let (zl, zr) = space_of(m, k, c, r)?;
        left.push((r, zl));
        right.push((r, zr));
        let reach = aimed.reach(r);
        let d = [
            (zl - (c - reach[0])) * w.flanks[0].cos(),
            ((c + reach[1]) - zr) * w.flanks[1].cos(),
        ];
        for side in 0..2 {
            if d[side].abs() > form[side].abs() {
                form[side] = d[side];
                worst_at[side] = r;
            }
        }
    }
    let (zl, zr) = space_of(m, k, c, r1)?;
    // The space after the last start's is start 0's, one lead on.
    let next = if k + 1 == w.starts {
        space_edges(m, r1, req.space_centre).map(|(a, _)| a + w.lead())
    } else {
        space_edges(m, r1, c + w.pitch).map(|(a, _)| a)
    };
    let next =
        next.ok_or_else(|| format!("start {}: no space after it at the pitch line", k + 1))?;
    let reach = aimed.reach(r1);
    let p = StartProfile {
        start: k,
        // The pitch line's middle stands off the root's by half the
        // flanks' difference over the depth between them.
        position_error: 0.5 * (zl + zr) - c - 0.5 * (reach[1] - reach[0]),
        thickness: next - zr,
        left_angle_deg: (-slope(&left)).atan().to_degrees(),
        right_angle_deg: slope(&right).atan().to_degrees(),
        left_form: form[0],
        right_form: form[1],
        // The space's bottom: its lowest point between the flanks at the
        // pitch line (not where the tip's centre stood: a buttress's nose
        // arc on its 7 degree corner reaches deeper).
        root_diameter: 2.0 * extreme_top(m, zl, zr, true).unwrap_or(0.0),
        // The crest's top, from the flank to the thread's middle (the last
        // start's at the window's end: 1 um inside it).
        tip_diameter: 2.0
            * extreme_top(m, zr, c + thread_middle(w)[1] - 1e-3, false).unwrap_or(0.0),
        // Searched over the straight flanks: from where the nose's
        // arc meets them to the crest.
        pitch_diameter: pitch_diameter(
            m,
            w,
            c,
            (
                aimed.root_diameter / 2.0
                    + cutter.nose_radius * (1.0 - w.flanks[0].min(w.flanks[1]).sin())
                    + INSIDE,
                r_a - INSIDE,
            ),
        ),
        over_wires: (req.limits.as_ref())
            .and(w.best_wire())
            .and_then(|wire| w.over_flanks(wire, w.pitch_diameter, line(&left), line(&right))),
        functional_pitch_diameter: functional_pitch_diameter(&aimed, c, &left, &right, lead_error),
    };
    Ok((p, worst_at, nominal_flanks_deg(&aimed, &radii)))
}

/// How many steps the search for a GO gauge's axial place takes: each
/// keeps two thirds of the bracket ([`crate::math::least_by_thirds`]).
const GAUGE_PLACE_STEPS: usize = 120;

/// The least a flank's place may move per millimetre of pitch diameter
/// for a GO gauge to be fitted by its pitch diameter alone: a flank along
/// the radial (a square thread's) does not move, and has no functional
/// pitch diameter.
const LEAST_FLANK_SHIFT: Real = 1e-6;

/// The functional (virtual) pitch diameter of a start, as a GO gauge
/// feels it: the pitch diameter of the perfect mating thread (the aimed
/// section's form, its pitch exact) that just fits the start's space at
/// every radius its flanks were measured at (`left`, `right`: `(r, z)`
/// of the space's flanks, centred on `c`), the space also displaced by up
/// to `lead_error` along the thread (the programmed lead's error: a
/// gauge engages the whole length). The gauge's tooth narrows with its
/// pitch diameter at each flank by that flank's shift per millimetre of
/// pitch diameter (tan a / 2 for a straight flank); its axial place is
/// free and chosen for the least diameter (a convex search: the most of
/// lines in it). For straight flanks this is `d2 + 2 (uL + uR) / (tan
/// aL + tan aR)` with `uL`, `uR` the flanks' largest intrusions into the
/// aimed space; the lead's share `|dP| cot a` on a symmetric thread (ISO
/// 1502's `f_P`), the flanks' angles and form theirs. None where a flank
/// does not move with the pitch diameter.
fn functional_pitch_diameter(
    aimed: &ThreadSection,
    c: Real,
    left: &[(Real, Real)],
    right: &[(Real, Real)],
    lead_error: Real,
) -> Option<Real> {
    let (d0, h) = (aimed.pitch_diameter, DERIVATIVE_STEP);
    let (wide, narrow) = (aimed.aimed(d0 - h), aimed.aimed(d0 + h));
    // (uL, uR, the flanks' shifts per mm of pitch diameter) at each radius
    // and each place along the thread.
    let mut rows = Vec::with_capacity(2 * left.len());
    for (&(r, zl), &(_, zr)) in left.iter().zip(right) {
        let (reach, w, n) = (aimed.reach(r), wide.reach(r), narrow.reach(r));
        let shift = [0, 1].map(|k| (w[k] - n[k]) / (2.0 * h));
        if shift.iter().any(|v| !(*v > LEAST_FLANK_SHIFT)) {
            return None;
        }
        let (ul, ur) = (zl - (c - reach[0]), (c + reach[1]) - zr);
        for along in [0.0, lead_error] {
            rows.push((ul + along, ur - along, shift));
        }
    }
    if rows.is_empty() {
        return None;
    }
    let need = |s: Real| {
        rows.iter()
            .map(|(ul, ur, k)| ((ul - s) / k[0]).max((ur + s) / k[1]))
            .fold(Real::NEG_INFINITY, Real::max)
    };
    let span = rows
        .iter()
        .map(|r| r.0.abs() + r.1.abs())
        .fold(1.0, Real::max);
    let place = crate::math::least_by_thirds(-span, span, GAUGE_PLACE_STEPS, need);
    Some(d0 + need(place))
}

/// What of start `p` fails against the nominal: its flanks' form (worst
/// at the radii `worst_at`) and angles (against `nominal_angles`), and its thickness and diameters (a
/// worm's against the nominal, a standard thread's against its limits),
/// its place.
fn start_faults(
    req: &ThreadRequest,
    p: &StartProfile,
    worst_at: [Real; 2],
    nominal_angles: [Real; 2],
) -> Vec<String> {
    let (w, tol) = (&req.section, &req.tolerances);
    let aimed = req.start_section(p.start);
    let s = p.start + 1;
    let mut faults = Vec::new();
    for (flank, form, r) in [
        ("left", p.left_form, worst_at[0]),
        ("right", p.right_form, worst_at[1]),
    ] {
        if form.abs() > tol.form {
            faults.push(format!(
                "start {s}, {flank} flank: {} {:.4} mm from the nominal flank at diameter {:.3} (tolerance {} mm)",
                if form > 0.0 { "material left" } else { "cut too deep" },
                form.abs(), diameter(r), tol.form
            ));
        }
    }
    for (flank, a, alpha) in [
        ("left", p.left_angle_deg, nominal_angles[0]),
        ("right", p.right_angle_deg, nominal_angles[1]),
    ] {
        if (a - alpha).abs() > tol.flank_angle.to_degrees() {
            faults.push(format!(
                "start {s}, {flank} flank: angle {a:.4} deg, nominal {alpha:.4} deg (tolerance {:.4} deg)",
                tol.flank_angle.to_degrees()
            ));
        }
    }
    match &req.limits {
        None => faults.extend(nominal_faults(req, p)),
        Some(l) => {
            faults.extend(limit_faults(w, l, &aimed, p));
            faults.extend(go_fault(w, l, &aimed, p));
        }
    }
    if p.position_error.abs() > tol.position {
        faults.push(format!(
            "start {s}: its space is {:.4} mm from its place (tolerance {} mm)",
            p.position_error, tol.position
        ));
    }
    faults
}

/// A worm's start `p` against its nominal thickness and diameters.
fn nominal_faults(req: &ThreadRequest, p: &StartProfile) -> Vec<String> {
    let (w, tol, s) = (&req.section, &req.tolerances, p.start + 1);
    let mut faults = Vec::new();
    let thickness = w.pitch - w.space_at_pitch;
    if (p.thickness - thickness).abs() > tol.thickness {
        faults.push(format!(
            "start {s}: axial thickness at the pitch line {:.4} mm, nominal {:.4} mm (tolerance {} mm)",
            p.thickness, thickness, tol.thickness
        ));
    }
    for (what, d, nominal) in [
        ("root diameter", p.root_diameter, w.root_diameter),
        ("tip diameter", p.tip_diameter, w.crest_diameter),
    ] {
        if (d - nominal).abs() > tol.diameter {
            faults.push(format!(
                "start {s}: {what} {:.4} mm, nominal {:.4} mm (tolerance {} mm)",
                d.abs(),
                nominal.abs(),
                tol.diameter
            ));
        }
    }
    faults
}

/// A standard thread's start `p` as its GO gauge takes it: its
/// functional pitch diameter within the maximum-material limit (an
/// external thread's greatest pitch diameter, a nut's least; the largest
/// here, where a nut is its twin in rho = -r), moved with a correction as
/// [`limit_faults`] moves the band.
fn go_fault(
    w: &ThreadSection,
    l: &crate::families::thread::ThreadLimits,
    aimed: &ThreadSection,
    p: &StartProfile,
) -> Option<String> {
    let functional = p.functional_pitch_diameter?;
    let by = aimed.pitch_diameter - w.pitch_diameter;
    (functional - by > l.pitch_diameter.max).then(|| {
        format!(
            "start {}: functional pitch diameter {:.4} mm beyond the maximum-material limit {:.4} mm: a GO gauge does not go on ({}; the simple pitch diameter {:.4} mm; the flanks' angles, form and the lead's error add the rest)",
            p.start + 1,
            functional.abs(),
            (l.pitch_diameter.max + by).abs(),
            l.source,
            p.pitch_diameter.abs()
        )
    })
}

/// A standard thread's start `p` against its limits `l`. A corrected
/// start's pitch and root diameters are held to the standard's band moved
/// by its correction (its `aimed` section's): the part is to come out in
/// the band when the measured error repeats.
fn limit_faults(
    w: &ThreadSection,
    l: &crate::families::thread::ThreadLimits,
    aimed: &ThreadSection,
    p: &StartProfile,
) -> Vec<String> {
    let s = p.start + 1;
    let by = aimed.pitch_diameter - w.pitch_diameter;
    let mut faults = Vec::new();
    for (what, v, d, by) in [
        ("pitch diameter", p.pitch_diameter, &l.pitch_diameter, by),
        ("root diameter", p.root_diameter, &l.root, by),
        ("crest diameter", p.tip_diameter, &l.crest, 0.0),
    ] {
        if !d.holds(v - by, 0.0) {
            let (lo, hi) = (d.min + by, d.max + by);
            let (lo, hi) = (lo.abs().min(hi.abs()), lo.abs().max(hi.abs()));
            let corrected = if by == 0.0 {
                String::new()
            } else {
                format!(
                    ", moved by {:+.4} mm for the correction",
                    by * w.pitch_diameter.signum()
                )
            };
            faults.push(format!(
                "start {s}: {what} {:.4} mm, outside {lo:.4} to {hi:.4} mm ({}{corrected})",
                v.abs(),
                l.source
            ));
        }
    }
    faults
}
