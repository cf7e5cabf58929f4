//! Random input, including NaN, infinities and huge values, never makes the
//! kernel panic: every bad value comes back as an error.

use pilgrim_kernel::families::revolution::rest;
use pilgrim_kernel::machine::{machine_file, BUILTIN_SOURCES};
use pilgrim_kernel::{
    drop_circle, equidistant, read_table_str, Bulge, CircleEnvelope, EllipseSection, IkOptions,
    Machine, MandrelLaw, Point3, Profile, ProfileBuilder, Side, Target, ToolFrame, Vec3,
};
use proptest::prelude::*;

fn real() -> impl Strategy<Value = f64> {
    prop_oneof![
        6 => -1e3..1e3f64,
        1 => any::<f64>(),
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(0.0),
        1 => Just(-0.0),
    ]
}

fn side() -> impl Strategy<Value = Side> {
    prop_oneof![Just(Side::Outside), Just(Side::Inside)]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]

    #[test]
    fn profiles_and_offsets_never_panic(
        z in prop::collection::vec(real(), 0..40),
        x in prop::collection::vec(real(), 0..40),
        sorted in any::<bool>(),
        r in real(), q in real(), k in 1usize..2000, it in 0usize..8, s in side(),
    ) {
        let mut z = z;
        if sorted {
            z.sort_by(f64::total_cmp);
        }
        let n = z.len().min(x.len());
        if let Ok(p) = Profile::new(z[..n].to_vec(), x[..n].to_vec()) {
            let _ = p.slopes();
            let _ = p.curvature();
            let _ = p.curvature_radius();
            let _ = p.arc_length();
            let _ = p.tangent_angles();
            let _ = p.eval(q);
            let (a, b) = p.z_range();
            let _ = p.resample_uniform((b - a) / k as f64);
            let _ = p.resample_by(&p.arc_length(), (b - a).abs() / k as f64);
            let _ = p.smooth_derivative(it, k % (n + 2));
            let _ = p.min_with(&p);
            if let Ok(e) = equidistant(&p, r, s) {
                if let Ok(env) = CircleEnvelope::new(&e.z, &e.x, r, s) {
                    let _ = env.eval_many(p.z());
                    let _ = env.eval(q);
                }
            }
            let _ = drop_circle(&p, q, r, s);
            let _ = rest::seed_u(&p, q, r);
            let _ = rest::exact_u(&p, q, r);
        }
        let _ = CircleEnvelope::new(&z[..n], &x[..n], r, s);
    }

    #[test]
    fn generators_never_panic(
        v in prop::collection::vec(real(), 8),
        step in real(),
        bulge in any::<bool>(),
        count in 0usize..50,
    ) {
        if let Ok(law) = MandrelLaw::new(v[0], v[1], v[2], v[3], v[4]) {
            if step.abs() > law.l_r / 5000.0 {
                let _ = law.profile(step, v[5]);
            }
        }
        if let Ok(e) = EllipseSection::new(v[0], v[1]) {
            let _ = e.depth_profile(v[2], count);
            let _ = e.radius(v[3]);
            let _ = e.normal_angle(v[3]);
        }
        let b = if bulge { Bulge::In } else { Bulge::Out };
        let _ = ProfileBuilder::start(v[0], v[1])
            .line_to(v[2], v[3])
            .arc_to(v[4], v[5], v[6], b)
            .cylinder(v[7])
            .build(step.abs().max(1e-3), 10.0);
    }

    #[test]
    fn inverse_kinematics_never_panics(p in prop::collection::vec(real(), 6), restarts in any::<bool>()) {
        let m = Machine::from_info(mannesmann::describe()).unwrap();
        let opts = IkOptions { restarts, max_iter: 30, ..IkOptions::default() };
        let target = Target::pose(Point3::new(p[0], p[1], p[2]), Vec3::new(p[3], p[4], p[5]));
        let _ = m.inverse(&target, &ToolFrame::default(), None, &opts);
        let _ = m.inverse(&Target::point(Point3::new(p[0], p[1], p[2])), &ToolFrame::default(), None, &opts);
        let _ = m.chain().poses(&p, &ToolFrame::default());
    }

    #[test]
    fn tables_never_panic(text in "[0-9a-z,;.\t\n#\" -]{0,200}") {
        if let Ok(t) = read_table_str(&text, "random.csv") {
            let _ = t.column("A");
            let _ = t.column("2");
            let _ = t.profile("A", "B");
        }
    }

    #[test]
    fn machine_files_never_panic(cut in 0usize..4000, insert in "\\PC{0,12}", which in 0usize..3) {
        let base = match which {
            0 => BUILTIN_SOURCES[0].1.to_owned(),
            1 => machine_file(&mannesmann::describe(), "the mannesmann crate"),
            _ => machine_file(&grinder_3k152vf20::describe(), "the 3K152VF20 crate"),
        };
        let base = base.as_str();
        let mut at = cut.min(base.len());
        while !base.is_char_boundary(at) {
            at -= 1;
        }
        let text = format!("{}{}{}", &base[..at], insert, &base[at..]);
        let _ = Machine::from_toml_str(&text, "random.toml");
        let _ = Machine::from_toml_str(&base[..at], "cut.toml");
    }
}
