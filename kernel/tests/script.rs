//! Part families in Rhai: the contract, limits, errors, parameters.

use pilgrim_kernel::family::FamilyError;
use pilgrim_kernel::params::{resolve, ParamError, ParamSource};
use pilgrim_kernel::program::build;
use pilgrim_kernel::script::{Access, Limits, ScriptFamily};
use pilgrim_kernel::{ChainMachine, Machine, Params, PartFamily};
use std::path::Path;

fn demo() -> ScriptFamily {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scripts/examples/mill_circle.rhai");
    ScriptFamily::load(&path, &Limits::default(), &Access::default()).unwrap()
}

/// The family's parameters from an optional TOML file `(name, text)` and
/// `--set` pairs.
fn values(
    fam: &dyn PartFamily,
    file: Option<(&str, &str)>,
    sets: &[(&str, &str)],
) -> Result<Params, ParamError> {
    let mut sources: Vec<ParamSource> = file
        .map(|(label, text)| ParamSource::Toml {
            label: label.into(),
            text: text.into(),
        })
        .into_iter()
        .collect();
    sources.push(ParamSource::Pairs {
        label: "--set".into(),
        pairs: sets
            .iter()
            .map(|(k, v)| ((*k).to_owned(), (*v).to_owned()))
            .collect(),
    });
    resolve(fam.params(), &Default::default(), &sources)
}

#[test]
fn demo_family_runs_to_a_program() {
    let fam = demo();
    let names: Vec<&str> = fam.params().iter().map(|p| p.name.as_str()).collect();
    assert!(
        names.contains(&"radius") && names.contains(&"turn_table"),
        "{names:?}"
    );
    let defaults = values(&fam, None, &[]).unwrap();
    let tp = fam.toolpath(&defaults).unwrap();
    assert_eq!(tp.point_count(), 2 + 1 + 361 + 1);
    let mill = ChainMachine::new(Machine::builtin("vertical-mill").unwrap());
    let prog = build(&tp, &mill, "mill_circle").unwrap();
    assert_eq!(
        prog.axes
            .iter()
            .map(|a| a.name.as_str())
            .collect::<Vec<_>>(),
        ["X", "Y", "Z", "C"]
    );
    // Seed 003's example: X stays at R + D/2 = 45 while the table turns
    // (after the machine's two start blocks and the toolpath's three).
    let lead = pilgrim_kernel::program::start_blocks(&prog.setup) + 3;
    assert_eq!(lead, 5);
    let x = prog.column("X").unwrap();
    let c = prog.column("C").unwrap();
    for (k, b) in prog.blocks.iter().enumerate().skip(lead).take(361) {
        assert!((x[k] - 45.0).abs() < 1e-6, "block {k}: X {}", x[k]);
        assert!(
            (c[k] - 360.0 * (k - lead) as f64 / 360.0).abs() < 1e-9,
            "block {k}: C {}",
            c[k]
        );
        assert!(b.values[1].abs() < 1e-6);
    }
    // With the table still, X and Y trace the circle and C stays 0.
    let still = values(&fam, None, &[("turn_table", "false")]).unwrap();
    let prog = build(&fam.toolpath(&still).unwrap(), &mill, "m").unwrap();
    let (x, y) = (prog.column("X").unwrap(), prog.column("Y").unwrap());
    assert!(prog.column("C").unwrap().iter().all(|c| *c == 0.0));
    for k in lead..lead + 361 {
        assert!((x[k].hypot(y[k]) - 45.0).abs() < 1e-6);
    }
    let checks = fam.checks(&values(&fam, None, &[]).unwrap()).unwrap();
    assert_eq!(checks.len(), 2);
    assert!(checks.iter().all(|c| c.ok));
}

#[test]
fn unknown_and_bad_parameters_are_named() {
    let fam = demo();
    let e = values(&fam, None, &[("radiuss", "3")]).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("unknown parameter 'radiuss' from --set"),
        "{text}"
    );
    assert!(
        text.contains("radius, spindle, tool_diameter, turn_table"),
        "{text}"
    );
    let e = values(&fam, None, &[("radius", "big")])
        .unwrap_err()
        .to_string();
    assert_eq!(e, "parameter 'radius' from --set: 'big' is not a number");
    let e = values(&fam, Some(("p.toml", "points = 1.5")), &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("parameter 'points' from p.toml: expected a whole number, got 1.5"),
        "{e}"
    );
    let e = values(&fam, Some(("p.toml", "radius = nan")), &[])
        .unwrap_err()
        .to_string();
    assert!(e.contains("not a finite number"), "{e}");
    let v = values(&fam, Some(("p.toml", "radius = 30")), &[("depth", "2")]).unwrap();
    assert_eq!(v["radius"].to_string(), "30");
    assert_eq!(v["depth"].to_string(), "2");
}

fn family(src: &str) -> Result<ScriptFamily, FamilyError> {
    ScriptFamily::from_source(src, "t.rhai", &Limits::default(), &Access::default())
}

const HEAD: &str = "fn params() { #{ n: #{ value: 3, unit: \"\", doc: \"n\" } } }\n";

#[test]
fn syntax_errors_and_runtime_errors_carry_file_line_column() {
    let e = family("fn params() { #{ }\nfn toolpath(p) { let x = ; }").unwrap_err();
    let FamilyError::At {
        file, line, column, ..
    } = &e
    else {
        panic!("{e}")
    };
    assert_eq!((file.as_str(), *line), ("t.rhai", 2));
    assert!(*column > 0, "{e}");
    let src = format!("{HEAD}fn toolpath(p) {{\n  let t = linspace(0.0, 1.0, 1);\n  t\n}}");
    let fam = family(&src).unwrap();
    let e = fam.toolpath(&values(&fam, None, &[]).unwrap()).unwrap_err();
    let text = e.to_string();
    assert!(text.starts_with("t.rhai:3:"), "{text}");
    assert!(text.contains("linspace needs at least 2 points"), "{text}");
    let e = family("fn toolpath(p) { 1 }").unwrap_err().to_string();
    assert!(e.contains("defines fn params()"), "{e}");
}

#[test]
fn endless_loop_is_stopped() {
    let src = format!("{HEAD}fn toolpath(p) {{\n  let i = 0;\n  loop {{ i += 1; }}\n}}");
    let limits = Limits {
        max_operations: 200_000,
        ..Limits::default()
    };
    let fam = ScriptFamily::from_source(&src, "loop.rhai", &limits, &Access::default()).unwrap();
    let e = fam
        .toolpath(&values(&fam, None, &[]).unwrap())
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("loop.rhai: "), "{e}");
    assert!(
        e.contains("operation limit and was stopped (an endless loop?) (in fn toolpath)"),
        "{e}"
    );
    let src = format!("{HEAD}fn f(x) {{ f(x + 1) }}\nfn toolpath(p) {{ f(0) }}");
    let e = family(&src).unwrap();
    let e = e
        .toolpath(&values(&e, None, &[]).unwrap())
        .unwrap_err()
        .to_string();
    assert!(e.contains("nest too deep"), "{e}");
}

#[test]
fn files_only_beside_the_input_files() {
    let dir = std::env::temp_dir().join(format!("pilgrim-script-{}", std::process::id()));
    let inside = dir.join("in");
    std::fs::create_dir_all(&inside).unwrap();
    std::fs::write(inside.join("t.csv"), "z,x\n0,1\n1,2\n2,3\n").unwrap();
    std::fs::write(dir.join("secret.csv"), "z,x\n0,1\n").unwrap();
    let access = Access {
        input_dirs: vec![inside.clone()],
        ..Access::default()
    };
    let src = format!("{HEAD}fn toolpath(p) {{ let t = read_table(\"t.csv\"); if t.x.len != 3 {{ throw \"bad\"; }} read_table(\"../secret.csv\") }}");
    let fam = ScriptFamily::from_source(&src, "f.rhai", &Limits::default(), &access).unwrap();
    let e = fam
        .toolpath(&values(&fam, None, &[]).unwrap())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("../secret.csv: not a readable file beside the script or the parameter file"),
        "{e}"
    );
    let e = family("fn params() { #{} }\nimport \"x\" as y;\nfn toolpath(p) {}")
        .map(|f| f.toolpath(&Default::default()));
    assert!(matches!(e, Err(_) | Ok(Err(_))));
    std::fs::remove_dir_all(&dir).ok();
}

/// The universal chain in a script: the mill example of S003-4.
#[test]
fn transforms_in_scripts_follow_the_universal_chain() {
    let src = format!(
        "{HEAD}fn toolpath(p) {{\n\
           let a = universal_deg([3.0, 4.0, 5.0, 90.0, 1.0, 2.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);\n\
           let b = tx(1.0) * ty(2.0) * tz(0.5) * rz_deg(90.0) * tx(3.0) * ty(4.0) * tz(5.0);\n\
           let r = 8.0; let beta = linspace(0.0, 6.0, 7);\n\
           let pa = a.apply(cos(beta) * r, sin(beta) * r, filled(7, 2.0));\n\
           let pb = b.apply(cos(beta) * r, sin(beta) * r, [2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0]);\n\
           let tp = new_toolpath(\"t\", end_mill(\"m\", 1, 6.0, 10.0), 1000.0, []);\n\
           tp.add_pass(\"a\", #{{ x: pa.x, y: pa.y, z: pa.z, feed: 100.0 }});\n\
           tp.add_pass(\"b\", #{{ x: pb.x, y: pb.y, z: pb.z, feed: 100.0 }});\n\
           tp\n}}"
    );
    let fam = family(&src).unwrap();
    let tp = fam.toolpath(&values(&fam, None, &[]).unwrap()).unwrap();
    // r0 = (R cos(phi+beta) + a1 + a cos phi - b sin phi, R sin(phi+beta) + b1 + a sin phi + b cos phi, Z + c1 + c)
    let phi = std::f64::consts::FRAC_PI_2;
    for pass in &tp.passes {
        for (k, c) in pass.points.iter().enumerate() {
            let beta = k as f64;
            let expect = [
                8.0 * (phi + beta).cos() + 1.0 + 3.0 * phi.cos() - 4.0 * phi.sin(),
                8.0 * (phi + beta).sin() + 2.0 + 3.0 * phi.sin() + 4.0 * phi.cos(),
                2.0 + 0.5 + 5.0,
            ];
            for i in 0..3 {
                assert!(
                    (c.point[i] - expect[i]).abs() < 1e-12,
                    "{} point {k}: {:?} vs {expect:?}",
                    pass.name,
                    c.point
                );
            }
        }
    }
    let e = family(&format!(
        "{HEAD}fn toolpath(p) {{ universal_deg([1.0, 2.0]) }}"
    ))
    .unwrap();
    let text = e
        .toolpath(&values(&e, None, &[]).unwrap())
        .unwrap_err()
        .to_string();
    assert!(
        text.contains("universal_deg needs 15 values, got 2"),
        "{text}"
    );
}

/// The segment builder, adaptive spacing and the rest's track from a
/// script give what the same kernel calls give from Rust.
#[test]
fn mandrel_building_blocks_in_scripts() {
    use pilgrim_kernel::families::revolution::rest::{track, RestSetup};
    use pilgrim_kernel::families::revolution::surface::{GroundSurface, WheelSection};
    use pilgrim_kernel::profile::{simplify_polyline, Polyline};
    use pilgrim_kernel::{equidistant, MandrelLaw, ProfileBuilder, Side};
    let src = format!(
        "{HEAD}fn toolpath(p) {{\n\
           let law = mandrel_law(38.0, 52.0, 400.0, 0.012, 2.3);\n\
           let part = profile_start(-350.0, 19.0 - 350.0 * 0.006).line_to(0.0, 19.0).law(law)\n\
                        .line_to(500.0, 26.0 + 100.0 * 0.0324).build(0.00001, 0.05);\n\
           let wheel = wheel_tool(\"w\", 1, 500.0, 20.0, 40.0);\n\
           let e = equidistant(part, wheel, \"outside\");\n\
           let k = e.path.simplified(0.0005);\n\
           let stock = ground_surface(profile_start(-700.0, 30.0).cylinder(1600.0).build(0.001, 1.0));\n\
           let rest = rest_track(stock, k, wheel, steady_rest(25.0, -150.0, 0.05, 0.002), 2000.0, 399.0);\n\
           let tp = new_toolpath(\"m\", wheel, 399.0, [\"U\"]);\n\
           tp.add_pass(\"finish\", #{{ x: rest.path.x, y: 0.0, z: rest.path.z, feed: 2000.0, aux: #{{ U: rest.centre_x }} }});\n\
           tp\n}}"
    );
    let fam = family(&src).unwrap();
    let tp = fam.toolpath(&values(&fam, None, &[]).unwrap()).unwrap();
    let law = MandrelLaw::new(38.0, 52.0, 400.0, 0.012, 2.3).unwrap();
    let part = ProfileBuilder::start(-350.0, 19.0 - 350.0 * 0.006)
        .line_to(0.0, 19.0)
        .law(law)
        .line_to(500.0, 26.0 + 100.0 * 0.0324)
        .build(0.00001, 0.05)
        .unwrap();
    let e = equidistant(&part, 20.0, Side::Outside).unwrap();
    let keep = simplify_polyline(&e.z, &e.x, 0.0005);
    let pass = &tp.passes[0].points;
    assert!(
        keep.len() < e.z.len() / 50,
        "{} of {}",
        keep.len(),
        e.z.len()
    );
    let stock = ProfileBuilder::start(-700.0, 30.0)
        .cylinder(1600.0)
        .build(0.001, 1.0)
        .unwrap();
    let (cz, cx): (Vec<f64>, Vec<f64>) = keep.iter().map(|&i| (e.z[i], e.x[i])).unzip();
    let setup = RestSetup {
        radius: 25.0,
        offset_b: -150.0,
        sample: 0.05,
        tolerance: 0.002,
    };
    let wheel = WheelSection {
        radius: 20.0,
        flat: 0.0,
    };
    let path = Polyline::new(cz, cx).unwrap();
    let t = track(
        &GroundSurface::new(stock),
        &path,
        wheel,
        2000.0,
        None,
        399.0,
        &setup,
    )
    .unwrap();
    // The script's pass is the track's path: the wheel's points and those
    // the rest added on its moves.
    assert_eq!(pass.len(), t.path.len());
    assert!(t.path.len() >= keep.len());
    for (c, (u, (z, x))) in pass
        .iter()
        .zip(t.centre_x.iter().zip(t.path.z.iter().zip(&t.path.x)))
    {
        assert_eq!((c.point[2], c.point[0], c.aux[0]), (*z, *x, *u));
    }
    let e = family(&format!(
        "{HEAD}fn toolpath(p) {{ profile_start(0.0, 1.0).arc_to(1.0, 1.0, 2.0, \"sideways\") }}"
    ))
    .unwrap();
    let text = e
        .toolpath(&values(&e, None, &[]).unwrap())
        .unwrap_err()
        .to_string();
    assert!(text.contains("\"out\" or \"in\""), "{text}");
}

/// The API as a writer guesses it: arrays and Floats alike, typed results
/// whose misspelt property is an error where it is written, the profile's
/// value at a z (`x_at`, since `eval` is reserved), the wheel's dimensions
/// from its tool.
#[test]
fn the_api_takes_arrays_and_gives_typed_results() {
    let src = format!(
        "{HEAD}fn toolpath(p) {{\n\
           let a = profile([0.0, 1.0, 2.0], floats([1.0, 2.0, 3.0]));\n\
           if a.x_at(1.5) != 2.5 {{ throw `x_at ${{a.x_at(1.5)}}`; }}\n\
           let wheel = wheel_tool(\"w\", 1, 500.0, 20.0, 50.0);\n\
           if wheel.rounding_radius != 20.0 || wheel.width != 50.0 {{ throw \"tool\"; }}\n\
           let c = concat([1.0, 2.0], floats([3.0]));\n\
           if c.len != 3 {{ throw \"concat\"; }}\n\
           let e = equidistant(a, wheel, \"outside\");\n\
           e.slop\n\
         }}"
    );
    let fam = family(&src).unwrap();
    let e = fam
        .toolpath(&values(&fam, None, &[]).unwrap())
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("t.rhai:10:"), "{e}");
    assert!(e.contains("Unknown property 'slop'"), "{e}");
    // A wheel function given another tool says so.
    let src = format!(
        "{HEAD}fn toolpath(p) {{\n  let m = end_mill(\"m\", 1, 6.0, 10.0);\n  m.rounding_radius\n}}"
    );
    let fam = family(&src).unwrap();
    let e = fam
        .toolpath(&values(&fam, None, &[]).unwrap())
        .unwrap_err()
        .to_string();
    assert!(e.contains("tool 'm' is not a grinding wheel"), "{e}");
}

/// A table's columns are read by header when asked for: a column of notes
/// is fine, a misspelt column lists the table's.
#[test]
fn tables_are_read_column_by_column() {
    let dir = std::env::temp_dir().join(format!("pilgrim-table-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("t.csv"),
        "theta,Hp,note\n0,10,start\n10,9.5,reduction\n20,9,\n",
    )
    .unwrap();
    let access = Access {
        input_dirs: vec![dir.clone()],
        ..Access::default()
    };
    let src = format!(
        "{HEAD}fn toolpath(p) {{\n  let t = read_table(\"t.csv\");\n  if t.rows != 3 || t[\"Hp\"][1] != 9.5 {{ throw \"read\"; }}\n  t[\"depth\"]\n}}"
    );
    let fam = ScriptFamily::from_source(&src, "f.rhai", &Limits::default(), &access).unwrap();
    let e = fam
        .toolpath(&values(&fam, None, &[]).unwrap())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("depth") && e.contains("theta") && e.contains("note"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A script's `fn verify(p)` map is read by the family whose key it has
/// (the families' readers are registered from their folders): a map of no
/// form names every form, and a family's map names what is wrong in it.
#[test]
fn a_verify_map_names_what_is_wrong_with_it() {
    let message = |body: &str| {
        let src = format!("{HEAD}fn toolpath(p) {{ 0 }}\nfn verify(p) {{ {body} }}\n");
        let fam = family(&src).unwrap();
        fam.verification(&values(&fam, None, &[]).unwrap())
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    };
    let e = message("#{ depth: 1.0 }");
    assert!(
        e.contains("must return one of: #{ replay: \"radius_over_angle\"")
            && e.contains("; #{ profile, from, to, tolerance }")
            && e.contains("; #{ groove, psi,")
            && e.contains("; #{ worm, length,")
            && e.contains("; #{ thread_profile, length,"),
        "{e}"
    );
    let e = message(
        "#{ worm: worm(4.0, 1, 40.0, 0.2, 20.0, 0.0), length: 50.0, space_centre: 0.0, tolerance: #{ form: \"x\" } }",
    );
    assert!(
        e.contains("fn verify(p): tolerance.form must be a number"),
        "{e}"
    );
    let e = message("#{ worm: 1.0 }");
    assert!(e.contains("must return one of: "), "{e}");
}
