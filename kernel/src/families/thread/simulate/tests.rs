//! The simulation's tests: threads of each profile cut and held.

use super::*;
use crate::families::thread::{plan, FlankOrder, PlanSettings};
use crate::families::thread::{standards, Hand, ThreadCutter, ThreadProfile, ThreadSection};
use crate::machine::{ChainMachine, Machine};
use crate::program::{AxisProgram, Block, ProgramAxis};
use crate::replay::VerifyError;
use crate::toolpath::Motion;

/// An external M20 6g cut with a 60 degree cutter to the plan's depths,
/// the section aimed `aim` mm below the basic pitch diameter: the
/// lathe's program of plain thread blocks.
fn cut_m20(aim: Real) -> Result<ThreadCheck, VerifyError> {
    let profile = standards::metric(20.0, 2.5, false, "6g", 1, Hand::Right).unwrap();
    cut(&profile, aim, FlankOrder::Alternating)
}

/// `profile` cut `aim` mm into the material from its basic pitch
/// diameter (an external thread's smaller, an internal's larger) by a
/// cutter of its own flanks and root space, the roughing passes on
/// `order`'s flanks: the tip towards the axis from above an external
/// thread, away from it from inside an internal thread's bore.
fn cut(profile: &ThreadProfile, aim: Real, order: FlankOrder) -> Result<ThreadCheck, VerifyError> {
    cut_towards(profile, aim, order, -1.0)
}

/// [`cut`], the thread blocks towards -Z (`towards` -1, from 5 mm
/// beyond the face) or +Z (+1, from 5 mm beyond the thread's far
/// end), each start at its start angle.
fn cut_towards(
    profile: &ThreadProfile,
    aim: Real,
    order: FlankOrder,
    towards: Real,
) -> Result<ThreadCheck, VerifyError> {
    cut_by(profile, aim, order, towards, |t| {
        ThreadCutter::new(t.root_space(), 0.15, t.flanks[0], t.flanks[1], 3.0).unwrap()
    })
}

/// [`cut_towards`] by the cutter `make` makes for the aimed section.
fn cut_by(
    profile: &ThreadProfile,
    aim: Real,
    order: FlankOrder,
    towards: Real,
    make: fn(&ThreadSection) -> ThreadCutter,
) -> Result<ThreadCheck, VerifyError> {
    // The blank turned to the middle of the crest's band.
    let s = profile.section.opening();
    let t = &ThreadSection {
        crest_diameter: profile.limits.crest.middle(),
        ..profile
            .section
            .aimed(profile.section.pitch_diameter - s * aim)
    };
    let cutter = make(t);
    let settings = PlanSettings {
        roughing_passes: None,
        min_depth: 0.05,
        finish_depth: 0.03,
        finish_passes: 2,
        order,
        axial_step: 0.5,
        starts_by_depth: true,
    };
    let passes = plan(t, &cutter, &settings).unwrap();
    // A worm's long lead slower, and its deep space's edges further
    // out, S1 within the run-in before the face.
    let (length, rpm, run_in) = if t.lead() > 6.0 {
        (30.0, 60.0, 5.0 + t.depth())
    } else {
        (30.0, 300.0, 5.0)
    };
    let c0 = if towards < 0.0 {
        run_in
    } else {
        -length - run_in
    };
    let r_crest = t.crest_diameter / 2.0;
    let mut blocks = Vec::new();
    let block = |motion, x: Real, z: Real, feed: Real| Block {
        motion,
        values: vec![2.0 * x, z],
        feed,
        spindle: None,
        comment: None,
        keep: vec![],
        number: None,
        line: None,
        dwell_s: 0.0,
    };
    let clear = r_crest + s;
    for p in &passes {
        let r = r_crest - s * p.cumulative;
        let zs = c0 + p.offset;
        let ze = if towards < 0.0 {
            -length - run_in
        } else {
            run_in
        };
        blocks.push(block(Motion::Rapid, clear, zs, 0.0));
        blocks.push(block(Motion::Rapid, r, zs, 0.0));
        blocks.push(block(
            Motion::Thread {
                lead: t.lead(),
                start_deg: 360.0 * Real::from(p.start) / Real::from(t.starts),
            },
            r,
            ze,
            t.lead() * rpm,
        ));
        blocks.push(block(Motion::Rapid, clear, ze, 0.0));
    }
    let axis = |n: &str| ProgramAxis {
        name: n.into(),
        unit: "mm".into(),
    };
    let program = AxisProgram {
        name: "THREAD".into(),
        number: 1,
        machine: "fanuc-0i-tc".into(),
        control: "fanuc".into(),
        tool_number: 1,
        tool_name: "thread insert 60".into(),
        spindle_rpm: rpm,
        decimals: None,
        axes: vec![axis("X"), axis("Z")],
        blocks,
        setup: Default::default(),
        cycles: Vec::new(),
        fanuc_cycles: Vec::new(),
    };
    let lathe = ChainMachine::new(Machine::from_info(fanuc_0i_tc::describe()).unwrap());
    let req = ThreadRequest {
        section: t.clone(),
        flank_margin: 0.1,
        length,
        space_centre: c0,
        tolerances: ThreadTolerances {
            form: 0.01,
            thickness: 1.0,
            diameter: 1.0,
            position: 0.01,
            flank_angle: 0.1f64.to_radians(),
            lead: 0.01,
        },
        limits: Some(profile.limits.clone()),
        part: "thread",
        outside_diameter: None,
        pitch_shift: Vec::new(),
        place_shift: Vec::new(),
    };
    simulate(&program, &lathe, &Default::default(), &cutter, &req)
}

/// A metric thread simulated from its program: cut to the basic
/// profile its pitch diameter is the basic 18.376 mm and beyond 6g's
/// upper limit (18.334), named; aimed into the band (0.1 mm down: the
/// cutter's pitch line as much deeper) it measures 0.1 mm less and
/// holds; its flanks at 30 degrees.
#[test]
fn a_metric_thread_is_held_to_its_pitch_diameter() {
    let basic = cut_m20(0.0).unwrap();
    let d2 = basic.starts[0].pitch_diameter;
    assert!((d2 - 18.376).abs() < 2e-3, "{d2}");
    assert!(basic
        .verified()
        .is_err_and(|e| e.to_string().contains("start 1: pitch diameter 18.37")
            && e.to_string().contains("(ISO 965-1 6g)")));
    let aimed = cut_m20(0.1).unwrap();
    let d2 = aimed.starts[0].pitch_diameter;
    assert!((d2 - 18.276).abs() < 2e-3, "{d2}");
    let held = aimed.verified().unwrap();
    for a in [
        held.starts[0].left_angle_deg,
        held.starts[0].right_angle_deg,
    ] {
        assert!((a - 30.0).abs() < 0.05, "{a}");
    }
    // Over wires: the best wire 0.57735 P (1.4434 mm) laid against the
    // cut flanks measures what the formula gives at the pitch
    // diameter measured, within 1 um, inside what 6g allows (M moves
    // with the pitch diameter one for one at 60 degrees, the lead angle's
    // share changing by 0.04 um over the band).
    let wire = held.wire.unwrap();
    assert!((wire - 2.5 / 3f64.sqrt()).abs() < 1e-12, "{wire}");
    let m = held.starts[0].over_wires.unwrap();
    let section =
        crate::families::thread::standards::metric(20.0, 2.5, false, "6g", 1, Hand::Right)
            .unwrap()
            .section;
    let want = section.over_wires(wire, d2).unwrap();
    assert!((m - want).abs() < 1e-3, "M {m} vs {want}");
    let [lo, hi] = held.over_wires_limits.unwrap();
    assert!(
        lo < m && m < hi && (hi - lo - 0.17).abs() < 0.1e-3,
        "{lo} {m} {hi}"
    );
}

/// An internal M30x2 6H cut from inside its bore: its pitch diameter
/// measured from the cut as a gauge takes it (the simulation in rho =
/// -r, turned back), held to 6H's 28.701 to 28.925 mm; cut 0.05 mm
/// short of the basic it is refused naming the limit; the major (the
/// root) beyond its least, the minor (the bore) within its band; the
/// measurement between balls inside what 6H allows.
#[test]
fn an_internal_thread_is_cut_and_held_from_inside_its_bore() {
    let nut = standards::metric(30.0, 2.0, true, "6H", 1, Hand::Right).unwrap();
    let check = cut(&nut, 0.1, FlankOrder::Alternating).unwrap();
    assert!(check.internal, "{:?}", check.failures);
    assert!(!check.starts.is_empty(), "{:?}", check.failures);
    let s = &check.starts[0];
    assert!((s.pitch_diameter - 28.801).abs() < 2e-3, "{s:?}");
    for a in [s.left_angle_deg, s.right_angle_deg] {
        assert!((a - 30.0).abs() < 0.05, "{a}");
    }
    let l = check.limits.clone().unwrap();
    assert!((l.pitch_diameter.min - 28.701).abs() < 1e-3, "{l:?}");
    assert!((l.pitch_diameter.max - 28.925).abs() < 1e-3, "{l:?}");
    assert!(s.root_diameter >= l.root.min, "{s:?} {l:?}");
    assert!(l.crest.holds(s.tip_diameter, 1e-9), "{s:?} {l:?}");
    // Between balls: the pitch diameter less the wires' reach.
    let wire = check.wire.unwrap();
    let m = s.over_wires.unwrap();
    let want = nut.section.over_wires(wire, s.pitch_diameter).unwrap();
    assert!(
        (m - want).abs() < 1e-3 && m < s.pitch_diameter,
        "M {m} vs {want}"
    );
    let [lo, hi] = check.over_wires_limits.unwrap();
    assert!(lo < m && m < hi, "{lo} {m} {hi}");
    // The section's surface is the nut's inside.
    assert!(
        (check.radius_at(check.window.0 + 0.25) - s.tip_diameter / 2.0).abs() < 0.05,
        "{}",
        check.radius_at(check.window.0 + 0.25)
    );
    let _ = check.clone().verified().unwrap();
    // Its part: a nut of 45 mm round the thread, closed, its volume
    // between the cylinders' at its root and at its crest.
    let solid = crate::families::thread::thread_solid(&check, 30.0, 0.01, Some(45.0)).unwrap();
    solid.check_closed().unwrap();
    let tube = |r: Real| std::f64::consts::PI * (22.5f64.powi(2) - r * r) * 30.0;
    let v = solid.volume();
    assert!(
        tube(s.root_diameter / 2.0) < v && v < tube(s.tip_diameter / 2.0),
        "{} < {v} < {}",
        tube(s.root_diameter / 2.0),
        tube(s.tip_diameter / 2.0)
    );
    let (lo, hi) = solid.bounds();
    assert!(
        (hi[0] - 22.5).abs() < 1e-9 && (lo[2] + 30.0).abs() < 1e-9,
        "{lo:?} {hi:?}"
    );
    assert!(crate::families::thread::thread_solid(&check, 30.0, 0.01, Some(28.0)).is_err());
    // Its STEP: the nut's faces close a solid of the mesh's volume
    // (the mesh's chords inside the helical surface by at most 0.01).
    let sweep =
        crate::families::thread::ThreadSweep::new(&check, 30.0, 2.5e-4, Some(45.0)).unwrap();
    let fit = crate::step::swept_step("nut", "a nut", &sweep, 1e-3).unwrap();
    assert!(
        (fit.volume - v).abs() < 0.01 * 30.0 * 100.0,
        "{} vs {v}",
        fit.volume
    );
    let short = cut(&nut, -0.05, FlankOrder::Alternating).unwrap();
    let e = short.verified().unwrap_err().to_string();
    assert!(
        e.contains("start 1: pitch diameter 28.65")
            && e.contains("outside 28.7010 to 28.9250 mm (ISO 965-1 6H)"),
        "{e}"
    );
}

/// A left hand, two starts (M20x5(P2.5)-6g-LH): cut towards +Z with
/// the spindle in M3, each start at its angle, both starts' pitch
/// diameters hold 6g, and each start is found where its angle puts it
/// (start 2 a pitch towards -Z of start 1 in the section at angle 0).
/// Cut towards -Z, each block is refused naming the hand it cuts. Its
/// solid winds left: the section at +90 degrees is the one at 0
/// shifted a quarter lead towards -Z.
#[test]
fn a_left_hand_is_cut_towards_the_tailstock() {
    let lh = standards::metric(20.0, 2.5, false, "6g", 2, Hand::Left).unwrap();
    let check = cut_towards(&lh, 0.1, FlankOrder::Alternating, 1.0).unwrap();
    assert_eq!(check.hand, Hand::Left);
    let check = check.verified().unwrap();
    assert_eq!(check.starts.len(), 2);
    for s in &check.starts {
        assert!((s.pitch_diameter - 18.276).abs() < 2e-3, "{s:?}");
        assert!(s.position_error.abs() < 1e-3, "{s:?}");
    }
    // Every pass cut the start its angle names, at its own space.
    for p in &check.passes {
        assert!(p.offset.abs() < 1.0, "{p:?}");
    }
    assert!(check.passes.iter().any(|p| p.start == 1));
    let wrong = cut_towards(&lh, 0.1, FlankOrder::Alternating, -1.0).unwrap();
    let e = wrong.verified().unwrap_err().to_string();
    assert!(
        e.contains("towards -Z (the chuck) with the spindle in M3 cuts a right-hand helix, and the thread is left-handed"),
        "{e}"
    );
    // The solid: a vertex at angle phi lies on the section at 0
    // shifted by -lead phi / 2 pi (a right hand's, +).
    let solid = crate::families::thread::thread_solid(&check, 30.0, 0.01, None).unwrap();
    solid.check_closed().unwrap();
    let (w0, lead) = check.window;
    let mut worst: Real = 0.0;
    for p in &solid.positions {
        let (r, phi) = (p[0].hypot(p[1]), p[1].atan2(p[0]));
        if r > 1.0 && p[2] < -1.0 && p[2] > -29.0 {
            let z = p[2] + lead * phi / std::f64::consts::TAU;
            worst = worst.max((check.radius_at(w0 + (z - w0).rem_euclid(lead)) - r).abs());
        }
    }
    assert!(worst < 0.02, "{worst}");
    let sweep = crate::families::thread::ThreadSweep::new(&check, 30.0, 2.5e-4, None).unwrap();
    use crate::step::Sections;
    let q = sweep.point(0, 0.5, 0.5);
    let phi = q[1].atan2(q[0]);
    let z = q[2] + lead * phi / std::f64::consts::TAU;
    let r = q[0].hypot(q[1]);
    assert!(
        (check.radius_at(w0 + (z - w0).rem_euclid(lead)) - r).abs() < 0.02,
        "{r}"
    );
}

/// A 7/45 buttress of `diameter` inches, 8 threads per inch, external,
/// its load flank towards the chuck, its limits stated (pitch diameter
/// 0.1 mm, crest 0.2, root 0.3).
fn buttress_8_tpi(diameter: Real) -> ThreadProfile {
    let stated = standards::StatedLimits {
        pitch_allowance: 0.0,
        pitch_tolerance: 0.1,
        crest_tolerance: 0.2,
        root_tolerance: 0.3,
    };
    let (load, hand) = (standards::LoadFlank::TowardsChuck, Hand::Right);
    standards::buttress(diameter, 8.0, false, load, 1, hand, stated).unwrap()
}

/// A 7/45 buttress (1-8, its load flank the space's towards +Z), its
/// roughing passes on the load flank: each flank holds its own angle,
/// 45 and 7 degrees, and the pitch diameter its aim within its stated
/// band.
#[test]
fn a_buttress_holds_its_two_flank_angles() {
    let profile = buttress_8_tpi(1.0);
    let check = cut(&profile, 0.05, FlankOrder::Right)
        .unwrap()
        .verified()
        .unwrap();
    let s = &check.starts[0];
    assert!(
        (s.left_angle_deg - 45.0).abs() < 0.05,
        "{}",
        s.left_angle_deg
    );
    assert!(
        (s.right_angle_deg - 7.0).abs() < 0.05,
        "{}",
        s.right_angle_deg
    );
    let want = profile.section.pitch_diameter - 0.05;
    assert!(
        (s.pitch_diameter - want).abs() < 2e-3,
        "{} vs {want}",
        s.pitch_diameter
    );
    assert_eq!(check.nominal_flanks_deg.map(Real::round), [45.0, 7.0]);
    // The verdict's flank-angle figure takes each flank against its
    // own angle (it once took both against the left's 45 degrees,
    // and the 7 degree flank stood 38 degrees off).
    let (figures, _) = check.findings();
    let angle = figures.iter().find(|f| f.name == "flank angle").unwrap();
    assert!(angle.value.abs() < 0.05, "{angle:?}");
}

/// Roots at the space's bottom, crests at their top: a 7/45 buttress's
/// root is where the simulated space is deepest (its nose arc on the 7
/// degree corner), not where the finishing tip's centre stood, and its
/// crest the thread's highest point; both sought here over a grid of the
/// finished section one lead long (one start: one space, one thread).
#[test]
fn roots_are_measured_at_the_spaces_bottom() {
    let profile = buttress_8_tpi(2.0);
    // The cutter as the family's script makes it: the tip the space at
    // the root, the nose the largest the tip holds between the flanks
    // (0.9 of it), the standard's rounding at most.
    let check = cut_by(&profile, 0.05, FlankOrder::Right, -1.0, |t| {
        let inset = |a: Real| (1.0 - a.sin()) / a.cos();
        let tip = t.root_space();
        let nose = t
            .root_radius
            .min(0.9 * tip / (inset(t.flanks[0]) + inset(t.flanks[1])));
        ThreadCutter::new(tip, nose, t.flanks[0], t.flanks[1], 3.0).unwrap()
    })
    .unwrap()
    .verified()
    .unwrap();
    let (z0, lead) = check.window;
    let n = 40_000;
    let tops: Vec<Real> = (1..n)
        .filter_map(|i| {
            super::section::vertical_top(&check.section, z0 + lead * i as Real / n as Real)
        })
        .collect();
    let deepest = 2.0 * tops.iter().copied().fold(Real::INFINITY, Real::min);
    let highest = 2.0 * tops.iter().copied().fold(Real::NEG_INFINITY, Real::max);
    let s = &check.starts[0];
    assert!(
        (s.root_diameter - deepest).abs() < 0.2e-3,
        "root {} where the space is deepest at {deepest}",
        s.root_diameter
    );
    assert!(
        (s.tip_diameter - highest).abs() < 0.2e-3,
        "tip {} where the thread is highest at {highest}",
        s.tip_diameter
    );
}

/// The least pitch diameter of a perfect GO gauge's tooth (the aimed
/// form at that pitch diameter, over the radii `band`) that fits the
/// finished section's space centred near `c` without cutting into it,
/// its axial place free: sought here with polygon booleans (the tooth
/// against the material), by bisection on the diameter at each place and
/// a search over the places.
fn go_gauge_fit(check: &ThreadCheck, aimed: &ThreadSection, c: Real, band: [Real; 2]) -> Real {
    use geo::{Area, BooleanOps};
    let fits = |d: Real, s: Real| {
        let g = aimed.aimed(d);
        let ([a0, b0], [a1, b1]) = (g.reach(band[0]), g.reach(band[1]));
        let tooth = super::poly(&[
            [c + s - a0, band[0]],
            [c + s + b0, band[0]],
            [c + s + b1, band[1]],
            [c + s - a1, band[1]],
        ]);
        let tooth = geo::MultiPolygon::new(vec![tooth]);
        check.section.intersection(&tooth).unsigned_area() < 1e-12
    };
    let least_at = |s: Real| {
        let (mut lo, mut hi) = (aimed.pitch_diameter - 0.3, aimed.pitch_diameter + 0.3);
        for _ in 0..48 {
            let m = 0.5 * (lo + hi);
            if fits(m, s) {
                hi = m;
            } else {
                lo = m;
            }
        }
        hi
    };
    least_at(crate::math::least_by_thirds(-0.1, 0.1, 48, least_at))
}

/// The functional pitch diameter, as a GO gauge feels it: an M20 cut by a
/// cutter whose flanks stand half a degree wider than the thread's (the
/// flanks' angles off, the space opened towards the crest) measures its
/// simple pitch diameter where the space is P/2 wide, and a functional
/// one larger, where a perfect gauge's tooth found by polygon booleans
/// against the finished section just fits (within 0.3 um); a cut to the
/// thread's own angles has the two within a micrometre.
#[test]
fn the_functional_pitch_diameter_is_where_a_perfect_gauge_fits() {
    let profile = standards::metric(20.0, 2.5, false, "6g", 1, Hand::Right).unwrap();
    let opening = profile.section.opening();
    let aimed = ThreadSection {
        crest_diameter: profile.limits.crest.middle(),
        ..profile
            .section
            .aimed(profile.section.pitch_diameter - opening * 0.1)
    };
    let band = [
        aimed.root_diameter / 2.0 + 2.0 * 0.15 + 0.1,
        aimed.crest_diameter / 2.0 - 0.1,
    ];
    for (wider_deg, apart) in [(0.0, 1e-3), (0.5, 1.0)] {
        let check = if wider_deg == 0.0 {
            cut(&profile, 0.1, FlankOrder::Alternating).unwrap()
        } else {
            cut_by(&profile, 0.1, FlankOrder::Alternating, -1.0, |t| {
                let wider = 0.5f64.to_radians();
                let f = [t.flanks[0] + wider, t.flanks[1] + wider];
                ThreadCutter::new(t.root_space(), 0.15, f[0], f[1], 3.0).unwrap()
            })
            .unwrap()
        };
        let s = &check.starts[0];
        let functional = s.functional_pitch_diameter.unwrap();
        let (z0, lead) = check.window;
        let c = z0 + (5.0 - z0).rem_euclid(lead);
        let fitted = go_gauge_fit(&check, &aimed, c, band);
        assert!(
            (functional - fitted).abs() < 0.3e-3,
            "{wider_deg}: functional {functional}, the gauge fits at {fitted} (window {z0} + {lead}, c {c})"
        );
        let over = functional - s.pitch_diameter;
        if wider_deg == 0.0 {
            assert!(over.abs() < apart, "{over}");
        } else {
            assert!(over > 5e-3 && over < apart, "{over}");
        }
    }
}

/// A start whose simple pitch diameter lies inside 6g's band but whose
/// GO gauge would not go on (the cutter's flanks half a degree wide,
/// which opens the space 28 um; the section aimed 20 um over the band's
/// top, so the simple one lies 8 um under it) fails by its functional
/// pitch diameter,
/// named with the limit, and by nothing of the simple one.
#[test]
fn a_go_gauge_that_does_not_go_on_fails_the_start() {
    let profile = standards::metric(20.0, 2.5, false, "6g", 1, Hand::Right).unwrap();
    let aim = profile.section.pitch_diameter - profile.limits.pitch_diameter.max - 0.02;
    let check = cut_by(&profile, aim, FlankOrder::Alternating, -1.0, |t| {
        let wider = 0.5f64.to_radians();
        let f = [t.flanks[0] + wider, t.flanks[1] + wider];
        ThreadCutter::new(t.root_space(), 0.15, f[0], f[1], 3.0).unwrap()
    })
    .unwrap();
    let s = &check.starts[0];
    let max = profile.limits.pitch_diameter.max;
    assert!(s.pitch_diameter < max, "{}", s.pitch_diameter);
    assert!(s.functional_pitch_diameter.unwrap() > max);
    let texts: Vec<String> = check.failures.iter().map(|f| f.message.clone()).collect();
    assert!(
        texts
            .iter()
            .any(|t| t.contains("start 1: functional pitch diameter")
                && t.contains(&format!("maximum-material limit {max:.4} mm"))),
        "{texts:?}"
    );
    assert!(
        !texts.iter().any(|t| t.contains("start 1: pitch diameter")),
        "{texts:?}"
    );
}

/// Over wires with the lead angle, from the cut: a Tr40x7 and a
/// two-start Tr40x14(P7), each start's measurement over its best wires
/// laid against the cut flanks within 1 um of ASME B1.2's lead-corrected
/// formula at the pitch diameter measured, the lead angle's share 24.3 and
/// 97 um over the axial section's figure (12 % and 49 % of a 0.2 mm
/// band).
#[test]
fn over_wires_carry_the_lead_angle_on_every_start() {
    use crate::families::thread::wires::lead_corrected;
    let stated = standards::StatedLimits {
        pitch_allowance: 0.0,
        pitch_tolerance: 0.2,
        crest_tolerance: 0.3,
        root_tolerance: 0.5,
    };
    for (starts, share) in [(1, 24.3e-3), (2, 97.0e-3)] {
        let profile =
            standards::trapezoidal(40.0, 7.0, false, starts, Hand::Right, stated).unwrap();
        let check = cut(&profile, 0.1, FlankOrder::Alternating)
            .unwrap()
            .verified()
            .unwrap();
        let (t, wire) = (&profile.section, check.wire.unwrap());
        assert_eq!(check.starts.len(), starts as usize);
        for s in &check.starts {
            let m = s.over_wires.unwrap();
            let (half, d2) = (t.flanks[0], s.pitch_diameter);
            let formula = lead_corrected(half, t.space_at_pitch, d2, t.lead(), wire);
            let axial = lead_corrected(half, t.space_at_pitch, d2, 0.0, wire);
            assert!(
                (m - formula).abs() < 1e-3,
                "start {}: M {m} vs {formula}",
                s.start + 1
            );
            assert!(
                (m - axial - share).abs() < 1e-3,
                "start {}: {}",
                s.start + 1,
                m - axial
            );
        }
        let [lo, hi] = check.over_wires_limits.unwrap();
        assert!(check
            .starts
            .iter()
            .all(|s| (lo..=hi).contains(&s.over_wires.unwrap())));
    }
}

/// A ZI worm's flanks are curves in the axial section (its axial angle
/// turns from 18.2 to 21.2 degrees over the depth): a straight cutter
/// on their tangent at the pitch line leaves them tens of micrometres
/// off, refused naming the flank's form; the form cutter ground to them
/// cuts them within a micrometre, its angles those of the curve's
/// line. A ZN worm's form cutter (its flanks nearly straight) leaves
/// the ZI worm's curve as the straight one does.
#[test]
fn a_zi_worm_is_held_to_its_curved_flanks() {
    use crate::families::thread::{WormProfile, WormSizes};
    let worm = |profile| {
        WormSizes::with_profile(5.0, 2, 50.0, 0.2, 20f64.to_radians(), None, profile)
            .unwrap()
            .profile(0.05, 0.02)
    };
    let zi = worm(WormProfile::ZI);
    let form = |t: &ThreadSection| {
        ThreadCutter::ground_to(t.form, t.root_diameter / 2.0, 0.15, 13.0).unwrap()
    };
    let check = cut_by(&zi, 0.0, FlankOrder::Radial, -1.0, form).unwrap();
    let worst = check
        .starts
        .iter()
        .map(|s| s.left_form.abs().max(s.right_form.abs()))
        .fold(0.0, Real::max);
    assert!(worst < 1e-3, "{worst}");
    let nominal = check.nominal_flanks_deg;
    for s in &check.starts {
        assert!((s.left_angle_deg - nominal[0]).abs() < 5e-3, "{s:?}");
        assert!((s.right_angle_deg - nominal[1]).abs() < 5e-3, "{s:?}");
    }
    check.clone().verified().unwrap();
    // The curve's line over the measured band is steeper than its
    // tangent at the root, less steep than its tangent at the tip.
    let at = |r: Real| zi.section.form.axial_angle(r).unwrap().to_degrees();
    assert!(
        at(19.0) < nominal[1] && nominal[1] < at(30.0),
        "{nominal:?}"
    );
    // A straight cutter on the curve's tangent at the pitch line (the
    // space's width there, no side steps) leaves the curve either side.
    let straight = |t: &ThreadSection| {
        let a = t.flanks[0];
        let tip = t.space_at_pitch - (t.pitch_diameter - t.root_diameter) * a.tan();
        ThreadCutter::new(tip, 0.15, a, a, 13.0).unwrap()
    };
    let e = cut_by(&zi, 0.0, FlankOrder::Radial, -1.0, straight)
        .unwrap()
        .verified()
        .unwrap_err()
        .to_string();
    assert!(e.contains("flank: material left"), "{e}");
    // The ZN worm's cutter in the ZI worm's space cuts beyond it.
    let e = cut_by(&zi, 0.0, FlankOrder::Radial, -1.0, |_| {
        let a = 20f64.to_radians();
        let zn = WormSizes::with_profile(5.0, 2, 50.0, 0.2, a, None, WormProfile::ZN).unwrap();
        ThreadCutter::ground_to(zn.section().form, 19.0, 0.15, 13.0).unwrap()
    })
    .unwrap()
    .verified()
    .unwrap_err()
    .to_string();
    assert!(e.contains("start 1, left flank: material left"), "{e}");
}
