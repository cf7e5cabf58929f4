//! The universal chain against the product of its factors and the closed
//! form of MATH §1; the mill example (S003-4); inverse kinematics round trips.

use pilgrim_kernel::transform::FactorGeometry;
use pilgrim_kernel::{
    assert_near, Chain, FactorKind, IkOptions, Machine, Mat4, Point3, Target, ToolFrame, Vec3,
};
use proptest::prelude::*;
use std::f64::consts::PI;

/// MATH §1's corrected expansion of the universal matrix, entry by entry.
/// `q` in the seed's order: a b c phi a1 b1 c1 theta a2 b2 c2 psi a3 b3 c3.
fn closed_form(q: &[f64; 15]) -> Mat4 {
    let [a, b, c, phi, a1, b1, c1, theta, a2, b2, c2, psi, a3, b3, c3] = *q;
    let (sf, cf) = phi.sin_cos();
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = psi.sin_cos();
    let u = a1 + a * cf - b * sf;
    let v = b2 + b1 + a * sf + b * cf;
    let w = c2 + (c1 + c) * ct;
    Mat4::new(
        cf * ct,
        -sf * ct,
        st,
        a3 + a2 + u * ct + (c1 + c) * st,
        sf * cp + sp * st * cf,
        cf * cp - sf * sp * st,
        -sp * ct,
        b3 + v * cp + u * sp * st - w * sp,
        sf * sp - st * cf * cp,
        sf * st * cp + sp * cf,
        cp * ct,
        c3 + v * sp - u * st * cp + w * cp,
        0.0,
        0.0,
        0.0,
        1.0,
    )
}

fn params() -> impl Strategy<Value = [f64; 15]> {
    let t = -500.0..500.0f64;
    let r = -2.0 * PI..2.0 * PI;
    (
        (
            t.clone(),
            t.clone(),
            t.clone(),
            r.clone(),
            t.clone(),
            t.clone(),
            t.clone(),
            r.clone(),
        ),
        (t.clone(), t.clone(), t.clone(), r, t.clone(), t.clone(), t),
    )
        .prop_map(
            |((a, b, c, phi, a1, b1, c1, th), (a2, b2, c2, psi, a3, b3, c3))| {
                [a, b, c, phi, a1, b1, c1, th, a2, b2, c2, psi, a3, b3, c3]
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 10_000, ..ProptestConfig::default() })]

    /// 10,000 draws: the chain's fast evaluation, the plain product of the
    /// fifteen factor matrices and MATH §1's expansion agree to 1e-12
    /// (rotation entries absolutely; translation entries relative to the
    /// size of the translations, which is what rounding allows).
    #[test]
    fn universal_chain_is_the_product_and_the_expansion(q in params()) {
        let chain = Chain::universal();
        let fast = chain.matrix(&q).unwrap();
        let product = chain.matrix_by_product(&q).unwrap();
        let expansion = closed_form(&q);
        let by_hand = [
            (FactorKind::Tx, q[12]), (FactorKind::Ty, q[13]), (FactorKind::Tz, q[14]), (FactorKind::Rx, q[11]),
            (FactorKind::Tx, q[8]), (FactorKind::Ty, q[9]), (FactorKind::Tz, q[10]), (FactorKind::Ry, q[7]),
            (FactorKind::Tx, q[4]), (FactorKind::Ty, q[5]), (FactorKind::Tz, q[6]), (FactorKind::Rz, q[3]),
            (FactorKind::Tx, q[0]), (FactorKind::Ty, q[1]), (FactorKind::Tz, q[2]),
        ]
        .iter()
        .fold(Mat4::identity(), |m, (k, v)| m * k.matrix(*v));
        let scale = 1.0 + q.iter().enumerate().filter(|(i, _)| ![3, 7, 11].contains(i)).map(|(_, v)| v.abs()).sum::<f64>();
        for m in [&product, &expansion, &by_hand] {
            for r in 0..4 {
                for c in 0..4 {
                    let tol = if c == 3 { 1e-12 * scale } else { 1e-12 };
                    prop_assert!((fast[(r, c)] - m[(r, c)]).abs() <= tol,
                        "entry ({r},{c}): {} vs {}", fast[(r, c)], m[(r, c)]);
                }
            }
        }
    }
}

/// S003-4: the vertical mill (X, Y, Z, C) maps a cylindrical end mill's edge
/// `(R cos beta, R sin beta, Z1)` to the formed surface's points.
#[test]
fn mill_example_reproduces_the_end_mill_points() {
    let mill = Machine::builtin("vertical-mill").unwrap();
    let chain = mill.chain();
    assert_eq!(chain.axis_names(), ["X", "Y", "Z", "C"]);
    let universal = Chain::universal();
    let r = 8.0;
    for k in 0..200 {
        let t = k as f64;
        let (a, b, c, phi) = (
            50.0 * (0.3 * t).sin(),
            30.0 * (0.7 * t).cos(),
            -20.0 + 0.1 * t,
            0.05 * t - 3.0,
        );
        let beta = 0.37 * t;
        let z1 = 0.25 * t;
        let edge = Point3::new(r * beta.cos(), r * beta.sin(), z1);
        let seed = Point3::new(
            r * (phi + beta).cos() + a * phi.cos() - b * phi.sin(),
            r * (phi + beta).sin() + a * phi.sin() + b * phi.cos(),
            z1 + c,
        );
        let machine_point = chain.apply(&[a, b, c, phi], &edge).unwrap();
        // The same through the universal chain with only a, b, c, phi set.
        let mut q = [0.0; 15];
        q[..4].copy_from_slice(&[a, b, c, phi]);
        let universal_point = universal.apply(&q, &edge).unwrap();
        for p in [machine_point, universal_point] {
            assert!((p - seed).norm() < 1e-12, "k = {k}: {p} vs {seed}");
        }
    }
}

fn lcg(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// Random reachable poses of the five-axis Mannesmann chain: IK from the
/// machine's home finds axis values whose pose is the target's.
#[test]
fn ik_round_trips_fk_on_the_mannesmann_chain() {
    let m = Machine::from_info(mannesmann::describe()).unwrap();
    let chain = m.chain();
    assert_eq!(chain.axis_names(), ["X", "Z", "Y", "A", "B"]);
    // The rounding centre of a wheel of radius 60, in the wheel's plane.
    let tool = ToolFrame {
        point: Point3::new(-60.0, 0.0, 0.0),
        axis: Vec3::z(),
    };
    let opts = IkOptions::default();
    let mut s = 7u64;
    let mut worst: f64 = 0.0;
    for k in 0..1000 {
        let q = [
            -100.0 + 200.0 * lcg(&mut s),
            200.0 + 300.0 * lcg(&mut s),
            -50.0 + 100.0 * lcg(&mut s),
            (-180.0 + 360.0 * lcg(&mut s)).to_radians(),
            (-40.0 + 80.0 * lcg(&mut s)).to_radians(),
        ];
        let pose = chain.pose(&q, &tool).unwrap();
        let target = Target::pose(pose.point, pose.axis);
        let sol = m
            .inverse(&target, &tool, None, &opts)
            .unwrap_or_else(|e| panic!("pose {k} from {q:?}: {e}"));
        let back = chain.pose(&sol.q, &tool).unwrap();
        let err = (back.point - pose.point).norm();
        worst = worst.max(err);
        assert!(err <= opts.tol_pos, "pose {k}: position error {err}");
        assert!(
            (back.axis - pose.axis).norm() <= opts.tol_dir,
            "pose {k}: axis error"
        );
        m.check_travel(&["X", "Z", "Y", "A", "B"], &sol.q).unwrap();
    }
    assert!(worst < 1e-7);
}

/// The vertical mill: position and axis targets (the axis is always +Z, the
/// turn C and X/Y trade off: any solution reaching the pose is right).
#[test]
fn ik_round_trips_fk_on_the_vertical_mill() {
    let m = Machine::builtin("vertical-mill").unwrap();
    let chain = m.chain();
    let tool = ToolFrame {
        point: Point3::new(6.0, 0.0, 0.0),
        axis: Vec3::z(),
    };
    let mut s = 99u64;
    for k in 0..300 {
        let q = [
            -150.0 + 300.0 * lcg(&mut s),
            -150.0 + 300.0 * lcg(&mut s),
            -300.0 + 300.0 * lcg(&mut s),
            (-180.0 + 360.0 * lcg(&mut s)).to_radians(),
        ];
        let pose = chain.pose(&q, &tool).unwrap();
        let sol = m
            .inverse(
                &Target::pose(pose.point, pose.axis),
                &tool,
                None,
                &IkOptions::default(),
            )
            .unwrap_or_else(|e| panic!("pose {k}: {e}"));
        let back = chain.pose(&sol.q, &tool).unwrap();
        assert!((back.point - pose.point).norm() <= 1e-7, "pose {k}");
        assert_near!(back.axis.z, 1.0, 1e-12);
    }
}

/// Targets the chain cannot reach, or reaches only outside travel, are
/// refused with the error naming why.
#[test]
fn ik_refuses_unreachable_and_out_of_travel_targets() {
    let m = Machine::from_info(lz_250::describe()).unwrap();
    let tool = ToolFrame::default();
    // The LZ-250 has no Y: a wheel axis tilted about X with the centre at
    // A = 0 needs Y = 0; asking for a wheel axis along the radius is impossible.
    let e = m
        .inverse(
            &Target::pose(Point3::new(300.0, 0.0, 0.0), Vec3::x()),
            &tool,
            None,
            &IkOptions::default(),
        )
        .unwrap_err();
    assert!(e.to_string().contains("unreachable"), "{e}");
    // A centre 900 mm from the roll's axis is beyond Z's 600 mm travel.
    let e = m
        .inverse(
            &Target::pose(Point3::new(900.0, 0.0, 0.0), Vec3::z()),
            &tool,
            None,
            &IkOptions::default(),
        )
        .unwrap_err();
    assert!(e.to_string().contains("axis Z would need 900"), "{e}");
}
