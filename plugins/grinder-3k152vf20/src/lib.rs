//! The 3K152VF20 mandrel grinder (seed 000, docs/math.md §2.3) as a pilgrim machine
//! plugin: table Z, wheelhead X, CNC steady rest U, work spindle; a
//! Sinumerik 840D control (the host's writer posts its programs).
//!
//! Its description ([`describe`]) is the one definition of the machine: its
//! axes and their signs, the wheel's chain and the steady rest's, and the
//! rest's constants. The part frame has Z along the mandrel's axis and X
//! radial (docs/architecture.md, conventions). Signs (the host checks them against the
//! chains whenever it loads the plugin):
//!
//! - `Z` +1 mm moves the wheel +1 mm along the part's axis relative to the
//!   part (ISO 841: the table physically carries the part the other way);
//! - `X` +1 mm moves the wheel's reference point 1 mm away from the axis;
//! - `U` +1 mm moves the rest's support centre 1 mm away from the axis, on
//!   the side opposite the wheel (the rest stands at 180 degrees).
//!
//! The tool frame's origin is the wheel's programmed point (the seed
//! programs the lowest point of the wheel's rounding); its axis is the
//! wheel's axis, parallel to the part's.
//!
//! The kinematics are closed-form: the wheel moves in the part's axial
//! section with its axis parallel to the part's, so `X = x - r_x` and
//! `Z = z - r_z` for a tracked point `(x, 0, z)` and the tool's reference
//! `r`. The steady rest's U is not solved but driven: the toolpath carries
//! it (the part family computes it on the current surface).
//!
//! Built as an rlib it is compiled into the `pilgrim` program (its entry,
//! [`pilgrim_plugin_grinder_3k152vf20`], goes through the same ABI as the
//! library's); built as a cdylib it is `libgrinder_3k152vf20.so`.

use pilgrim_plugin_abi::types::{
    Axis, AxisKind, BodyShape, BodySpec, FactorKind, FactorSpec, MachineInfo, Mount, Plane,
    PowerOn, ProgramSetup, Quantity, Radial, ToolSpec,
};
use pilgrim_plugin_abi::{check_axial_section, export_plugin, Plugin, PluginError};

/// How far off the axial section (y) or off the part's axis direction a
/// pose may be and still be the grinder's.
const POSE_TOL: f64 = 1e-9;

/// The machine's name.
pub const NAME: &str = "3K152VF20";

/// How a program starts and ends on the 3K152VF20: work offset G54, the
/// ZX plane, X in radius (the wheel's radial position, not a diameter),
/// coolant on while grinding. At the start the wheel (X) and the rest (U)
/// go to their clear positions first, then Z moves to the first block's
/// position and X comes in; U is brought in by the first block, after the
/// wheel. At the end the wheel backs off, then the rest.
fn setup() -> ProgramSetup {
    let group = |axes: &[&str]| axes.iter().map(|a| (*a).to_owned()).collect::<Vec<_>>();
    ProgramSetup {
        work_offset: Some(1),
        plane: Some(Plane::Zx),
        radial: Some(Radial::Radius),
        radial_axis: "X".into(),
        coolant: true,
        clear: [("X".to_owned(), 100.0), ("U".to_owned(), 150.0)]
            .into_iter()
            .collect(),
        start_clear: group(&["X", "U"]),
        approach: vec![group(&["Z"]), group(&["X"])],
        retract: vec![group(&["X"]), group(&["U"])],
        feed_group: vec![],
        // The 840D's reset values as the machine maker sets them
        // ($MC_GCODE_RESET_VALUES): the ZX plane, no cutter compensation,
        // metric, absolute, feed per minute, no settable work offset.
        power_on: PowerOn {
            g: vec![18, 40, 71, 90, 94, 500],
            ..PowerOn::default()
        },
    }
}

/// The 3K152VF20's description: axes, chains, constants, capabilities.
pub fn describe() -> MachineInfo {
    let mut u = Axis::linear(
        "U",
        0.0,
        150.0,
        2000.0,
        [-1.0, 0.0, 0.0],
        "steady rest: radial position of the support's centre, opposite the wheel",
    );
    u.body = Some("rest".into());
    // A cylindrical grinder's slides accelerate gently: the table (Z) and
    // the wheelhead (X) at 0.5 m/s², the rest's light slide at 1 m/s².
    let u = u.accelerating(1000.0);
    MachineInfo {
        name: NAME.into(),
        description:
            "3K152VF20 CNC cylindrical grinder with a CNC steady rest (U) for cold-pilger mandrels"
                .into(),
        control: "sinumerik".into(),
        axes: vec![
            Axis::linear(
                "Z",
                -20.0,
                1050.0,
                6000.0,
                [0.0, 0.0, 1.0],
                "table, along the part's axis (wheel relative to part)",
            )
            .accelerating(500.0),
            Axis::linear(
                "X",
                -5.0,
                220.0,
                3000.0,
                [1.0, 0.0, 0.0],
                "wheelhead infeed: radial position of the wheel's programmed point",
            )
            .accelerating(500.0),
            u,
            Axis {
                name: "S".into(),
                kind: AxisKind::Spindle,
                min: 0.0,
                max: 630.0,
                max_feed: 630.0,
                programmed: false,
                description: "work spindle (the seed runs S1 = 399 rpm)".into(),
                moves: None,
                turns: None,
                body: None,
                max_accel: None,
                turns_part: true,
            },
        ],
        solved_axes: vec!["Z".into(), "X".into()],
        constants: [
            // z_r = z_k + B (mm): the rest stands 180 mm before the wheel along Z.
            ("rest_offset_b".to_owned(), -180.0),
            // Radius R_o of the rest's support in the axial section (mm).
            // U programs the support's centre (the seed, docs/math.md §2.3).
            ("rest_radius".to_owned(), 25.0),
            // The process (kernel/src/process.rs): the wheel moves into the
            // stock (a plunge, the infeed at a pass's reversal) at most at
            // 2 mm/min, a cylindrical grinder's radial infeed in hardened
            // steel; a rapid stops 0.5 mm off the material as it
            // approaches it; a finishing pass takes at most 0.03 mm; the
            // rest comes onto the turning part at 100 mm/min.
            ("infeed_feed".to_owned(), 2.0),
            ("rapid_clearance".to_owned(), 0.5),
            ("finish_stock".to_owned(), 0.03),
            ("rest_approach_feed".to_owned(), 100.0),
            // The machine's bodies (mm), a 3K152VF20's as built for a
            // wheel of up to 600 x 80 mm: the guard over 200 degrees of
            // the wheel, its inner radius clear of the largest wheel; the
            // flanges that clamp the wheel; the wheelhead behind them; the
            // rest's arm behind its roller; a 250 mm chuck gripping the
            // mandrel's tail over `chuck_grip`; the tailstock's centre and
            // quill beyond the part's far end.
            ("guard_inner".to_owned(), 310.0),
            ("guard_outer".to_owned(), 330.0),
            ("guard_width".to_owned(), 110.0),
            ("hub_radius".to_owned(), 160.0),
            ("hub_width".to_owned(), 100.0),
            ("rest_arm_length".to_owned(), 300.0),
            ("rest_arm_width".to_owned(), 40.0),
            ("chuck_radius".to_owned(), 125.0),
            ("chuck_length".to_owned(), 110.0),
            ("chuck_grip".to_owned(), 40.0),
            ("centre_radius".to_owned(), 10.0),
            ("centre_length".to_owned(), 50.0),
            ("quill_radius".to_owned(), 40.0),
            ("quill_length".to_owned(), 150.0),
        ]
        .into_iter()
        .collect(),
        // The grinder's programs carry 0.1 um (its axes' resolution):
        // mandrels are ground to microns, and 0.001 mm steps would be
        // coarser than the tolerance.
        program_decimals: Some(4),
        driven_axes: vec!["U".into()],
        setup: setup(),
        bodies: bodies(),
        chain: vec![
            FactorSpec::axis(FactorKind::Tz, "Z"),
            FactorSpec::axis(FactorKind::Tx, "X"),
        ],
        tool: ToolSpec::default(),
        // The 840D's feeds below 1 mm/min are not a grinding feed.
        min_feed: Some(1.0),
    }
}

fn c(name: &str) -> Quantity {
    Quantity::Constant(name.into())
}

/// The machine's bodies: the steady rest (its roller rides the part, its
/// arm behind it), the wheel's guard, flanges and wheelhead (on the
/// wheel's spindle, at the wheel's centre), the chuck at the part's start
/// and the tailstock at its end.
fn bodies() -> Vec<BodySpec> {
    let tz = |v: f64| FactorSpec::value(FactorKind::Tz, v);
    let tx = |v: f64| FactorSpec::value(FactorKind::Tx, v);
    vec![
        BodySpec {
            name: "rest".into(),
            description: "steady rest support (circle of radius rest_radius in the axial section)"
                .into(),
            label: "steady rest: support centre".into(),
            // The support's centre travels with the wheel along Z at the
            // offset B (z_r = z_k + B, docs/math.md §2.3), at 180 degrees round the
            // part.
            chain: vec![
                FactorSpec::axis(FactorKind::Tz, "Z"),
                FactorSpec::constant(FactorKind::Tz, "rest_offset_b"),
                FactorSpec::value(FactorKind::Rz, 180f64.to_radians()),
                FactorSpec::axis(FactorKind::Tx, "U"),
            ],
            shape: Some(BodyShape::Roller {
                radius: Quantity::Constant("rest_radius".into()),
                length: Quantity::Value(40.0),
            }),
            // The rest rides the part: it comes onto the turning part at
            // this speed, never at rapid.
            approach_feed: Some(Quantity::Constant("rest_approach_feed".into())),
            mount: Mount::Part,
            reach: Default::default(),
        },
        // The arm carrying the roller: from the roller's back, away from
        // the part (the rest's frame has +X away from the axis).
        BodySpec {
            name: "rest_arm".into(),
            description: "steady rest's arm behind its roller".into(),
            label: String::new(),
            chain: vec![
                FactorSpec::axis(FactorKind::Tz, "Z"),
                FactorSpec::constant(FactorKind::Tz, "rest_offset_b"),
                FactorSpec::value(FactorKind::Rz, 180f64.to_radians()),
                FactorSpec::axis(FactorKind::Tx, "U"),
                FactorSpec::constant(FactorKind::Tx, "rest_radius"),
                tx(5.0),
                FactorSpec::scaled(FactorKind::Tx, "rest_arm_length", 0.5),
            ],
            shape: Some(BodyShape::Block {
                size: [
                    c("rest_arm_length"),
                    Quantity::Value(60.0),
                    c("rest_arm_width"),
                ],
            }),
            approach_feed: None,
            mount: Mount::Part,
            reach: Default::default(),
        },
        BodySpec::mounted(
            "guard",
            "wheel guard over 200 degrees, open toward the part",
            Mount::Tool,
            vec![tz(0.0)],
            BodyShape::Guard {
                inner: c("guard_inner"),
                outer: c("guard_outer"),
                width: c("guard_width"),
                cover_deg: 200.0,
            },
        ),
        BodySpec::mounted(
            "hub",
            "wheel flanges clamping the wheel on its spindle",
            Mount::Tool,
            vec![tz(0.0)],
            BodyShape::Cylinder {
                radius: c("hub_radius"),
                length: c("hub_width"),
            },
        ),
        BodySpec::mounted(
            "wheelhead",
            "wheelhead housing behind the wheel, carrying its spindle",
            Mount::Tool,
            vec![tx(560.0), tz(0.0)],
            BodyShape::Block {
                size: [
                    Quantity::Value(400.0),
                    Quantity::Value(500.0),
                    Quantity::Value(400.0),
                ],
            },
        ),
        BodySpec::mounted(
            "chuck",
            "headstock chuck gripping the mandrel's tail over chuck_grip",
            Mount::PartStart,
            vec![
                FactorSpec::constant(FactorKind::Tz, "chuck_grip"),
                FactorSpec::scaled(FactorKind::Tz, "chuck_length", -0.5),
            ],
            BodyShape::Cylinder {
                radius: c("chuck_radius"),
                length: c("chuck_length"),
            },
        ),
        BodySpec::mounted(
            "tailstock_centre",
            "tailstock centre in the mandrel's end",
            Mount::PartEnd,
            vec![FactorSpec::scaled(FactorKind::Tz, "centre_length", 0.5)],
            BodyShape::Cylinder {
                radius: c("centre_radius"),
                length: c("centre_length"),
            },
        ),
        BodySpec::mounted(
            "tailstock_quill",
            "tailstock quill behind its centre",
            Mount::PartEnd,
            vec![
                FactorSpec::constant(FactorKind::Tz, "centre_length"),
                FactorSpec::scaled(FactorKind::Tz, "quill_length", 0.5),
            ],
            BodyShape::Cylinder {
                radius: c("quill_radius"),
                length: c("quill_length"),
            },
        ),
    ]
}

/// The 3K152VF20.
#[derive(Debug, Clone, Default)]
pub struct Grinder;

impl Plugin for Grinder {
    fn describe(&self) -> MachineInfo {
        describe()
    }

    /// Rows of `[Z, X]` (the solved axes' order).
    fn inverse(&self, poses: &[f64], tool: &[f64; 6], out: &mut [f64]) -> Result<(), PluginError> {
        for (i, (p, q)) in poses
            .chunks_exact(6)
            .zip(out.chunks_exact_mut(2))
            .enumerate()
        {
            check_axial_section(i, p, tool, POSE_TOL, "wheel")?;
            q[0] = p[2] - tool[2];
            q[1] = p[0] - tool[0];
        }
        Ok(())
    }

    fn forward(&self, axes: &[f64], tool: &[f64; 6], out: &mut [f64]) -> Result<(), PluginError> {
        for (q, p) in axes.chunks_exact(2).zip(out.chunks_exact_mut(6)) {
            p.copy_from_slice(&[
                q[1] + tool[0],
                tool[1],
                q[0] + tool[2],
                tool[3],
                tool[4],
                tool[5],
            ]);
        }
        Ok(())
    }
}

export_plugin!(pilgrim_plugin_grinder_3k152vf20, Grinder);

#[cfg(test)]
mod tests {
    use super::*;
    use pilgrim_kernel::machine::{ChainMachine, Machine, MachineKinematics};
    use pilgrim_kernel::math::{Point3, Vec3};
    use pilgrim_kernel::plugin::PluginMachine;
    use pilgrim_kernel::transform::ToolFrame;

    fn plugin() -> PluginMachine {
        PluginMachine::from_entry(
            NAME,
            "pilgrim_plugin_grinder_3k152vf20",
            pilgrim_plugin_grinder_3k152vf20,
        )
        .unwrap()
    }

    /// The closed form agrees with the description's chain solved
    /// numerically, both ways.
    #[test]
    fn closed_form_matches_the_chain() {
        let g = plugin();
        let chain = ChainMachine::new(Machine::from_info(describe()).unwrap());
        let tool = ToolFrame {
            point: Point3::new(20.0, 0.0, 3.0),
            axis: Vec3::z(),
        };
        let poses: Vec<f64> = (0..50)
            .flat_map(|i| [25.0 + 0.1 * i as f64, 0.0, 10.0 * i as f64, 0.0, 0.0, 1.0])
            .collect();
        let (mut a, mut b) = (vec![], vec![]);
        g.inverse(&poses, &tool, &mut a).unwrap();
        chain.inverse(&poses, &tool, &mut b).unwrap();
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-7, "{x} vs {y}");
        }
        let mut back = vec![];
        g.forward(&a, &tool, &mut back).unwrap();
        for (x, y) in back.iter().zip(&poses) {
            assert!((x - y).abs() < 1e-12);
        }
        let mut bad = poses.clone();
        bad[6 * 7 + 1] = 0.5;
        let e = g.inverse(&bad, &tool, &mut a).unwrap_err();
        assert_eq!(e.index, Some(7));
        assert!(
            e.message
                .contains("off the axial section the wheel moves in"),
            "{e}"
        );
    }

    /// The rest's chain: at Z + B along the axis, U from the axis on the far
    /// side; the description's signs hold (the host checked them).
    #[test]
    fn the_rest_moves_as_stated() {
        let m = Machine::from_info(describe()).unwrap();
        assert_eq!(m.chain().axis_names(), ["Z", "X"]);
        let p = m.chain().apply(&[250.0, 30.0], &Point3::origin()).unwrap();
        assert_eq!(p, Point3::new(30.0, 0.0, 250.0));
        let b = m.constant("rest_offset_b").unwrap();
        let rest = m.body_chain("rest").unwrap();
        assert_eq!(rest.axis_names(), ["Z", "U"]);
        let r = rest.apply(&[250.0, 40.0], &Point3::origin()).unwrap();
        assert!((r.x + 40.0).abs() < 1e-12 && r.y.abs() < 1e-12 && (r.z - 250.0 - b).abs() < 1e-12);
        assert!(m.constant("rest_radius").unwrap() > 0.0);
        assert_eq!(m.control(), "sinumerik");
        assert_eq!(plugin().info(), &describe());
    }
}
