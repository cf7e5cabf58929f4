//! A two-axis CNC lathe with a Fanuc 0i-TC control (seed 004, docs/math.md §4) as
//! a pilgrim machine plugin: cross slide X on diameter, carriage Z, main
//! spindle; worm threads cut in many passes with single thread blocks
//! (G32). The host's writer posts its programs in the `fanuc` dialect.
//!
//! Its description ([`describe`]) is the one definition of the machine
//! (`pilgrim machines --toml fanuc-0i-tc` writes it as a machine file).
//! Part frame: Z along the spindle's axis, X
//! radial (docs/architecture.md, conventions). Signs:
//!
//! - `X` on diameter: +1 mm moves the tool 0.5 mm away from the axis;
//! - `Z` +1 mm moves the tool +1 mm along the axis, away from the chuck.
//!
//! The tool frame's origin is the tool's tracked point (a thread cutter's
//! tip centre), its axis the part's. The kinematics are closed-form: the
//! tool moves in the axial section, `X = 2 (x - r_x)`, `Z = z - r_z`.
//!
//! Its constant `servo_time_constant` (s) is the carriage's servo time
//! constant T, which sets a thread's acceleration and deceleration lengths
//! (docs/math.md §4.2); its Z axis's `max_feed` bounds lead x rpm of a thread.

use pilgrim_plugin_abi::types::{
    Axis, AxisKind, BodyShape, BodySpec, FactorKind, FactorSpec, MachineInfo, Mount, Plane,
    PowerOn, ProgramSetup, Quantity, Radial, Reach, ToolSpec,
};
use pilgrim_plugin_abi::{check_axial_section, export_plugin, Plugin, PluginError};

/// How far off the axial section (y) or off the part's axis direction a
/// pose may be and still be the lathe's.
const POSE_TOL: f64 = 1e-9;

/// The machine's name.
pub const NAME: &str = "fanuc-0i-tc";

/// How a program starts and ends: G54, the ZX plane, X on diameter (a
/// parameter of the control: the program says so in a comment), coolant
/// on; X clears to diameter 300 first, then Z comes to the start; at the
/// end X backs off.
fn setup() -> ProgramSetup {
    ProgramSetup {
        work_offset: Some(1),
        plane: Some(Plane::Zx),
        radial: Some(Radial::Diameter),
        radial_axis: "X".into(),
        coolant: true,
        clear: [("X".to_owned(), 300.0)].into_iter().collect(),
        start_clear: vec!["X".into()],
        approach: vec![vec!["Z".into()]],
        retract: vec![vec!["X".into()]],
        feed_group: vec![],
        // The 0i-TC as it leaves the factory (Operator's Manual, "G code
        // list": the codes marked as in force at power-on; parameters
        // 3401 DPI = 0, 3402 FPM = 0): G-code system A, the ZX plane,
        // metric, no tool nose compensation, G54, constant rpm, feed per
        // revolution (G99: a program feeding per minute states G98), an
        // axis number without its point in 0.001 mm.
        power_on: PowerOn {
            g: vec![18, 21, 40, 54, 97, 99],
            no_point: Some(0.001),
            system: Some("A".into()),
        },
    }
}

/// The lathe's description: axes, chain, constants.
pub fn describe() -> MachineInfo {
    // X in program units, on diameter: travel and feed in diameter.
    let x = Axis::linear(
        "X",
        -10.0,
        400.0,
        12000.0,
        [0.5, 0.0, 0.0],
        "cross slide, on diameter",
    )
    // A turning centre's slides at 0.3 g: 3 m/s² radially, 6 on diameter.
    .accelerating(6000.0);
    let mut tx = FactorSpec::axis(FactorKind::Tx, "X");
    tx.scale = 0.5;
    MachineInfo {
        name: NAME.into(),
        description: "two-axis CNC lathe, Fanuc 0i-TC, X on diameter".into(),
        control: "fanuc".into(),
        axes: vec![
            x,
            Axis::linear(
                "Z",
                -750.0,
                150.0,
                10000.0,
                [0.0, 0.0, 1.0],
                "carriage, along the spindle's axis (program zero at the part's face)",
            )
            .accelerating(3000.0),
            Axis {
                name: "S".into(),
                kind: AxisKind::Spindle,
                min: 0.0,
                max: 3500.0,
                max_feed: 3500.0,
                programmed: false,
                description: "main spindle".into(),
                moves: None,
                turns: None,
                body: None,
                max_accel: None,
                turns_part: true,
            },
        ],
        solved_axes: vec!["X".into(), "Z".into()],
        constants: [
            // The carriage's servo time constant T (s), usually 0.033 s.
            ("servo_time_constant".to_owned(), 0.033),
            // The process (the kernel's process rules): a tool moves into
            // the stock at most at 100 mm/min (a plunge; a thread enters
            // at its lead); a rapid stops 1 mm off the material as it
            // approaches it; a finishing pass takes at most 0.2 mm.
            ("infeed_feed".to_owned(), 100.0),
            ("rapid_clearance".to_owned(), 1.0),
            ("finish_stock".to_owned(), 0.2),
            // The machine's bodies (mm), a 0i-TC turning centre's: a
            // 25 mm square holder whose shank starts `holder_gap` behind
            // the tip (a blade that reaches a module-5 worm's 11 mm
            // depth, and 5 mm more), the turret's disc behind it, a 200 mm chuck whose
            // jaws stand `chuck_gap` beyond the part's start (room for the
            // thread's run-out and the holder), the tailstock's centre and
            // quill at the part's end: a slender (extended-point) centre, a
            // cone from the 4 mm radius of the part's centre hole to 15 mm
            // at the quill 40 mm behind it, so that a thread's approach
            // beyond the part's face passes it.
            ("holder_gap".to_owned(), 16.0),
            ("holder_length".to_owned(), 80.0),
            ("holder_section".to_owned(), 25.0),
            ("turret_radius".to_owned(), 120.0),
            ("turret_width".to_owned(), 90.0),
            ("chuck_radius".to_owned(), 100.0),
            ("chuck_length".to_owned(), 100.0),
            ("chuck_gap".to_owned(), 30.0),
            ("centre_radius".to_owned(), 4.0),
            ("centre_end_radius".to_owned(), 15.0),
            ("centre_length".to_owned(), 40.0),
            ("quill_radius".to_owned(), 35.0),
            ("quill_length".to_owned(), 150.0),
            // A tool that cuts inside a bore rides a 16 mm boring bar, its
            // axis `bar_tip` behind the tip (the insert reaches 2 mm
            // beyond the bar: an M30's 1.2 mm depth and room), 70 mm out
            // of the turret (4.4 diameters: a steel bar's reach); the
            // tailstock is away, the bar coming from that side.
            ("bar_radius".to_owned(), 8.0),
            ("bar_tip".to_owned(), 10.0),
            ("bar_length".to_owned(), 70.0),
        ]
        .into_iter()
        .collect(),
        program_decimals: None,
        driven_axes: vec![],
        setup: setup(),
        bodies: bodies(),
        chain: vec![FactorSpec::axis(FactorKind::Tz, "Z"), tx],
        tool: ToolSpec::default(),
        min_feed: Some(1.0),
    }
}

/// The lathe's bodies: for a tool that cuts from outside, the holder and
/// the turret (on the tool, from its tip outward) and the tailstock at the
/// part's end; for one inside a bore, the boring bar (from its tip back
/// along +Z) and the turret at its end; the chuck at the part's start.
fn bodies() -> Vec<BodySpec> {
    let c = |name: &str| Quantity::Constant(name.into());
    let k = |f: FactorKind, name: &str| FactorSpec::constant(f, name);
    let half = |f: FactorKind, name: &str, sign: f64| FactorSpec::scaled(f, name, 0.5 * sign);
    vec![
        BodySpec::mounted(
            "holder",
            "the cutter's holder, its shank radial behind the tip",
            Mount::Tool,
            vec![
                k(FactorKind::Tx, "holder_gap"),
                half(FactorKind::Tx, "holder_length", 1.0),
            ],
            BodyShape::Block {
                size: [c("holder_length"), c("holder_section"), c("holder_section")],
            },
        )
        .for_tools(Reach::Outside),
        BodySpec::mounted(
            "turret",
            "the turret's disc carrying the holder",
            Mount::Tool,
            vec![
                k(FactorKind::Tx, "holder_gap"),
                k(FactorKind::Tx, "holder_length"),
                k(FactorKind::Tx, "turret_radius"),
            ],
            BodyShape::Cylinder {
                radius: c("turret_radius"),
                length: c("turret_width"),
            },
        )
        .for_tools(Reach::Outside),
        BodySpec::mounted(
            "boring_bar",
            "the boring bar, its axis bar_tip behind the tip, from the tip's plane back along +Z",
            Mount::Tool,
            vec![
                FactorSpec::scaled(FactorKind::Tx, "bar_tip", -1.0),
                half(FactorKind::Tz, "bar_length", 1.0),
            ],
            BodyShape::Cylinder {
                radius: c("bar_radius"),
                length: c("bar_length"),
            },
        )
        .for_tools(Reach::Inside),
        BodySpec::mounted(
            "bar_turret",
            "the turret's disc holding the boring bar at its rim",
            Mount::Tool,
            vec![
                FactorSpec::scaled(FactorKind::Tx, "bar_tip", -1.0),
                k(FactorKind::Tx, "turret_radius"),
                k(FactorKind::Tz, "bar_length"),
                half(FactorKind::Tz, "turret_width", 1.0),
            ],
            BodyShape::Cylinder {
                radius: c("turret_radius"),
                length: c("turret_width"),
            },
        )
        .for_tools(Reach::Inside),
        BodySpec::mounted(
            "chuck",
            "the chuck, its jaws chuck_gap beyond the part's start",
            Mount::PartStart,
            vec![
                FactorSpec::scaled(FactorKind::Tz, "chuck_gap", -1.0),
                half(FactorKind::Tz, "chuck_length", -1.0),
            ],
            BodyShape::Cylinder {
                radius: c("chuck_radius"),
                length: c("chuck_length"),
            },
        ),
        BodySpec::mounted(
            "tailstock_centre",
            "the tailstock's centre, its point in the part's end",
            Mount::PartEnd,
            vec![half(FactorKind::Tz, "centre_length", 1.0)],
            BodyShape::Cone {
                radius: c("centre_radius"),
                end_radius: c("centre_end_radius"),
                length: c("centre_length"),
            },
        )
        .for_tools(Reach::Outside),
        BodySpec::mounted(
            "tailstock_quill",
            "the tailstock's quill behind its centre",
            Mount::PartEnd,
            vec![
                k(FactorKind::Tz, "centre_length"),
                half(FactorKind::Tz, "quill_length", 1.0),
            ],
            BodyShape::Cylinder {
                radius: c("quill_radius"),
                length: c("quill_length"),
            },
        )
        .for_tools(Reach::Outside),
    ]
}

/// The Fanuc lathe.
#[derive(Debug, Clone, Default)]
pub struct Lathe;

impl Plugin for Lathe {
    fn describe(&self) -> MachineInfo {
        describe()
    }

    /// Rows of `[X, Z]` (the solved axes' order), X on diameter.
    fn inverse(&self, poses: &[f64], tool: &[f64; 6], out: &mut [f64]) -> Result<(), PluginError> {
        for (i, (p, q)) in poses
            .chunks_exact(6)
            .zip(out.chunks_exact_mut(2))
            .enumerate()
        {
            check_axial_section(i, p, tool, POSE_TOL, "tool")?;
            q[0] = 2.0 * (p[0] - tool[0]);
            q[1] = p[2] - tool[2];
        }
        Ok(())
    }

    fn forward(&self, axes: &[f64], tool: &[f64; 6], out: &mut [f64]) -> Result<(), PluginError> {
        for (q, p) in axes.chunks_exact(2).zip(out.chunks_exact_mut(6)) {
            p.copy_from_slice(&[
                0.5 * q[0] + tool[0],
                tool[1],
                q[1] + tool[2],
                tool[3],
                tool[4],
                tool[5],
            ]);
        }
        Ok(())
    }
}

export_plugin!(pilgrim_plugin_fanuc_0i_tc, Lathe);

#[cfg(test)]
mod tests {
    use super::*;
    use pilgrim_kernel::machine::{ChainMachine, Machine, MachineKinematics};
    use pilgrim_kernel::math::{Point3, Vec3};
    use pilgrim_kernel::transform::ToolFrame;

    /// The closed form agrees with the description's chain solved
    /// numerically, both ways; X is twice the radius.
    #[test]
    fn closed_form_matches_the_chain() {
        let chain = ChainMachine::new(Machine::from_info(describe()).unwrap());
        let tool = ToolFrame {
            point: Point3::new(0.0, 0.0, 0.0),
            axis: Vec3::z(),
        };
        let t6 = [0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
        let poses: Vec<f64> = (0..20)
            .flat_map(|i| {
                [
                    19.0 + 0.5 * i as f64,
                    0.0,
                    5.0 - 3.0 * i as f64,
                    0.0,
                    0.0,
                    1.0,
                ]
            })
            .collect();
        let mut a = vec![0.0; 40];
        Lathe.inverse(&poses, &t6, &mut a).unwrap();
        let mut b = vec![];
        chain.inverse(&poses, &tool, &mut b).unwrap();
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-7, "{x} vs {y}");
        }
        assert_eq!(a[0], 38.0);
        let mut back = vec![0.0; 120];
        Lathe.forward(&a, &t6, &mut back).unwrap();
        for (x, y) in back.iter().zip(&poses) {
            assert!((x - y).abs() < 1e-12);
        }
        let mut bad = poses.clone();
        bad[6 * 3 + 1] = 0.5;
        let e = Lathe.inverse(&bad, &t6, &mut a).unwrap_err();
        assert_eq!(e.row, Some(3));
    }
}
