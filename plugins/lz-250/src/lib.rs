//! The LZ-250 caliber grinder (seed 001, docs/math.md §3.5) as a pilgrim machine
//! plugin: the roll turns (A = theta) and moves along its axis (X) and
//! radially (Z); the wheel swivels (B = epsilon) about the radial axis.
//! Four controlled axes; a Sinumerik control (the host's writer posts its
//! programs). Its kinematics ([`CaliberKinematics`]) serve the Mannesmann
//! grinder too, which adds the cross axis Y.
//!
//! The part frame: Z along the roll's axis, X radial, the groove's section
//! at theta = 0 in the XZ plane. The chain, tool frame to part frame:
//! `Rz(-A) Tz(X) Tx(Z) [Ty(Y)] Rx(B)`. Signs (the host checks them against
//! the chain whenever it loads the plugin):
//!
//! - `A` +1 deg turns the roll +1 deg about its axis (right-handed), so the
//!   wheel turns -1 deg about +Z relative to the roll;
//! - `X` +1 mm moves the wheel +1 mm along the roll's axis relative to it;
//! - `Z` +1 mm moves the wheel's centre 1 mm away from the roll's axis;
//! - `Y` (Mannesmann) +1 mm moves the wheel +1 mm along +Y, tangent to the
//!   roll at the wheel;
//! - `B` +1 deg swivels the wheel +1 deg about the radial axis.
//!
//! The tool frame's origin is the wheel's centre, its axis the wheel's
//! axis (parallel to the roll's at B = 0).
//!
//! Inverse kinematics are closed-form. A wheel pose has five freedoms (a
//! torus is symmetric about its axis); the Mannesmann's five axes reach
//! every pose whose axis is not radial: A turns the roll until the wheel's
//! axis has no radial part, B swivels it, X, Z and Y place the centre. The
//! LZ-250 has no Y: A turns the roll until the tracked point lies in the
//! plane of the roll's axis and the radius, so the point is placed exactly,
//! and B swivels the wheel's axis as near the asked one as the machine
//! allows: the radial part of the axis it cannot give (the angle between
//! the two is [`CaliberKinematics::axis_error`]). The family asks for
//! reachable poses; the verification says what any difference costs.

pub mod kinematics;

pub use kinematics::CaliberKinematics;

use pilgrim_plugin_abi::types::{
    Axis, AxisKind, BodyShape, BodySpec, FactorKind, FactorSpec, MachineInfo, Mount, Plane,
    PowerOn, ProgramSetup, Quantity, Radial, ToolSpec,
};
use pilgrim_plugin_abi::{export_plugin, Plugin, PluginError};

/// The machine's name.
pub const NAME: &str = "LZ-250";

/// The axes and chain of a caliber grinder, with the cross axis Y if
/// `cross`: the one definition both machines' descriptions use.
pub fn caliber_grinder(name: &str, description: &str, cross: bool) -> MachineInfo {
    // The slides accelerate at 0.8 m/s², the roll's turn (a heavy roll on
    // its arbor) at 720 deg/s², the wheel's swivel at 360 deg/s².
    let mut axes = vec![
        Axis::linear(
            "X",
            -150.0,
            150.0,
            3000.0,
            [0.0, 0.0, 1.0],
            "along the roll's axis (wheel relative to roll)",
        )
        .accelerating(800.0),
        Axis::linear(
            "Z",
            0.0,
            600.0,
            2000.0,
            [1.0, 0.0, 0.0],
            "radial: the wheel centre's distance from the roll's axis",
        )
        .accelerating(800.0),
    ];
    if cross {
        axes.push(
            Axis::linear(
                "Y",
                -60.0,
                60.0,
                2000.0,
                [0.0, 1.0, 0.0],
                "across: perpendicular to the roll's axis and radius",
            )
            .accelerating(800.0),
        );
    }
    axes.push(
        Axis::rotary_deg(
            "A",
            370.0,
            3600.0,
            [0.0, 0.0, -1.0],
            "roll turn theta about its axis",
        )
        .accelerating(720.0)
        .turning_part(),
    );
    axes.push(
        Axis::rotary_deg(
            "B",
            45.0,
            1800.0,
            [1.0, 0.0, 0.0],
            "wheel swivel epsilon about the radial axis",
        )
        .accelerating(360.0),
    );
    axes.push(Axis {
        name: "S".into(),
        kind: AxisKind::Spindle,
        min: 0.0,
        max: 3000.0,
        max_feed: 3000.0,
        programmed: false,
        description: "wheel spindle".into(),
        moves: None,
        turns: None,
        body: None,
        max_accel: None,
        turns_part: false,
    });
    let solved: Vec<String> = axes
        .iter()
        .filter(|a| a.kind != AxisKind::Spindle)
        .map(|a| a.name.clone())
        .collect();
    let mut chain = vec![
        FactorSpec {
            scale: -1.0,
            ..FactorSpec::axis(FactorKind::Rz, "A")
        },
        FactorSpec::axis(FactorKind::Tz, "X"),
        FactorSpec::axis(FactorKind::Tx, "Z"),
    ];
    if cross {
        chain.push(FactorSpec::axis(FactorKind::Ty, "Y"));
    }
    chain.push(FactorSpec::axis(FactorKind::Rx, "B"));
    let mut approach = vec!["X".to_owned()];
    if cross {
        approach.push("Y".into());
    }
    approach.extend(["A".to_owned(), "B".to_owned()]);
    MachineInfo {
        name: name.into(),
        description: description.into(),
        control: "sinumerik".into(),
        axes,
        solved_axes: solved,
        // The process (the kernel's process rules): the wheel moves into
        // the stock at most at 2 mm/min; a rapid stops 0.5 mm off the
        // material as it approaches it; a finishing pass takes at most
        // 0.1 mm (each pass of a groove grinds its strip's whole
        // allowance, the seed's process).
        constants: [
            ("infeed_feed".to_owned(), 2.0),
            ("rapid_clearance".to_owned(), 0.5),
            ("finish_stock".to_owned(), 0.1),
            // The machine's bodies (mm), as built for wheels of up to
            // 280 mm and rolls of up to 400 mm: the guard over half the
            // wheel, open toward the roll; the spindle's housing beside the
            // wheel; the arbor through the roll and the collars clamping
            // it at both faces.
            ("guard_inner".to_owned(), 145.0),
            ("guard_outer".to_owned(), 160.0),
            ("guard_width".to_owned(), 50.0),
            ("housing_radius".to_owned(), 60.0),
            ("housing_length".to_owned(), 200.0),
            ("housing_gap".to_owned(), 35.0),
            ("arbor_radius".to_owned(), 70.0),
            ("arbor_length".to_owned(), 800.0),
            ("collar_radius".to_owned(), 100.0),
            ("collar_length".to_owned(), 40.0),
        ]
        .into_iter()
        .collect(),
        program_decimals: None,
        driven_axes: vec![],
        bodies: bodies(),
        chain,
        tool: ToolSpec::default(),
        min_feed: Some(1.0),
        // G54, the ZX plane, Z (the wheel's radial position) in radius,
        // coolant, F the roll's turn in deg/min; the wheel backs off to Z 600 first, then the roll, the
        // table (and the cross slide) and the swivel come to the start; at
        // the end the wheel backs off again.
        setup: ProgramSetup {
            work_offset: Some(1),
            plane: Some(Plane::Zx),
            radial: Some(Radial::Radius),
            radial_axis: "Z".into(),
            coolant: true,
            clear: [("Z".to_owned(), 600.0)].into_iter().collect(),
            start_clear: vec!["Z".into()],
            approach: vec![approach],
            retract: vec![vec!["Z".into()]],
            // F is the roll's turn in deg/min (FGROUP(A)).
            feed_group: vec!["A".into()],
            // The 840D's reset values as the machine maker sets them
            // ($MC_GCODE_RESET_VALUES): the ZX plane, no cutter compensation,
            // metric, absolute, feed per minute, no settable work offset.
            power_on: PowerOn {
                g: vec![18, 40, 71, 90, 94, 500],
                ..PowerOn::default()
            },
        },
    }
}

/// A caliber grinder's bodies: the wheel's guard and its spindle's
/// housing (on the wheel's centre, the tool frame), the arbor through the
/// roll, the collars at the roll's faces.
fn bodies() -> Vec<BodySpec> {
    let c = |name: &str| Quantity::Constant(name.into());
    let centred = vec![FactorSpec::value(FactorKind::Tz, 0.0)];
    let collar = BodyShape::Cylinder {
        radius: c("collar_radius"),
        length: c("collar_length"),
    };
    vec![
        BodySpec::mounted(
            "guard",
            "wheel guard over half the wheel, open toward the roll",
            Mount::Tool,
            centred.clone(),
            BodyShape::Guard {
                inner: c("guard_inner"),
                outer: c("guard_outer"),
                width: c("guard_width"),
                cover_deg: 180.0,
            },
        ),
        BodySpec::mounted(
            "housing",
            "wheel spindle's housing beside the wheel",
            Mount::Tool,
            vec![
                FactorSpec::constant(FactorKind::Tz, "housing_gap"),
                FactorSpec::scaled(FactorKind::Tz, "housing_length", 0.5),
            ],
            BodyShape::Cylinder {
                radius: c("housing_radius"),
                length: c("housing_length"),
            },
        ),
        BodySpec::mounted(
            "arbor",
            "arbor through the roll",
            Mount::Part,
            centred,
            BodyShape::Cylinder {
                radius: c("arbor_radius"),
                length: c("arbor_length"),
            },
        ),
        BodySpec::mounted(
            "collar_front",
            "collar clamping the roll at its front face",
            Mount::PartStart,
            vec![FactorSpec::scaled(FactorKind::Tz, "collar_length", -0.5)],
            collar.clone(),
        ),
        BodySpec::mounted(
            "collar_back",
            "collar clamping the roll at its back face",
            Mount::PartEnd,
            vec![FactorSpec::scaled(FactorKind::Tz, "collar_length", 0.5)],
            collar,
        ),
    ]
}

/// The LZ-250's description.
pub fn describe() -> MachineInfo {
    CaliberGrinder::<false>.describe()
}

/// A caliber grinder as a plugin: the LZ-250 (`CROSS = false`) or, with
/// the cross axis Y, the Mannesmann (`CROSS = true`, exported by the
/// `mannesmann` crate).
#[derive(Debug, Clone, Copy, Default)]
pub struct CaliberGrinder<const CROSS: bool>;

impl<const CROSS: bool> Plugin for CaliberGrinder<CROSS> {
    fn describe(&self) -> MachineInfo {
        if CROSS {
            caliber_grinder(
                "Mannesmann",
                "Mannesmann caliber grinder: roll turn A, axial X, radial Z, cross Y, wheel swivel B",
                true,
            )
        } else {
            caliber_grinder(
                NAME,
                "LZ-250 caliber grinder: roll turn A, axial X, radial Z, wheel swivel B",
                false,
            )
        }
    }

    /// Rows of `[X, Z, A, B]`, or `[X, Z, Y, A, B]` with the cross axis.
    fn inverse(&self, poses: &[f64], tool: &[f64; 6], out: &mut [f64]) -> Result<(), PluginError> {
        CaliberKinematics { cross: CROSS }.inverse(poses, tool, out)
    }

    fn forward(&self, axes: &[f64], tool: &[f64; 6], out: &mut [f64]) -> Result<(), PluginError> {
        CaliberKinematics { cross: CROSS }.forward(axes, tool, out)
    }
}

export_plugin!(pilgrim_plugin_lz_250, CaliberGrinder<false>);
