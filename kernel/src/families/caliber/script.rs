//! The caliber's groove for scripts (docs/math.md §3): the groove from its tables,
//! its points, normals and sections, the scallop between passes, the pass
//! angles, and the seed's wheel pose. Angles are radians, as everywhere in
//! the script API; the tables give theta in degrees.

use crate::binding::floats::{kernel, number, numbers, Floats};
use crate::binding::{ApiGroup, VerifyForm};
use crate::families::caliber::{self, EdgeKind, Groove, SeedPose};
use crate::family::Verification;
// The Rhai `Solid`: a mesh and the exact body it was meshed from.
use crate::family::Swept as Solid;
use crate::math::Real;
use crate::profile::{Profile, Smoothing, Table};
use crate::tool::{Tool, Wheel};
use rhai::plugin::*;
use rhai::{Array, EvalAltResult};

/// The caliber's groove, scallop and pass angles, the seed's pose.
#[export_module]
pub mod caliber_api {
    use super::*;

    /// The groove of a roll of radius `roll_radius` (mm) from one table:
    /// the columns of theta (degrees), depth Hp and width B (mm), named by
    /// header, letter or number; errors name file, row and column.
    #[rhai_fn(return_raw)]
    pub fn groove(
        roll_radius: Real,
        table: Table,
        theta: &str,
        depth: &str,
        width: &str,
    ) -> Result<Groove, Box<EvalAltResult>> {
        groove_two(roll_radius, table.clone(), table, theta, depth, width)
    }

    /// The node (row, from 0) in the middle of the sizing section (the
    /// longest run of one depth): the smoothing's default anchor.
    #[rhai_fn(get = "sizing_middle", pure)]
    pub fn sizing_middle(g: &mut Groove) -> i64 {
        g.sizing_middle() as i64
    }

    /// The groove with both tables smoothed (docs/math.md §3.2): `iterations` of
    /// the three-point rule (0: none, reported all the same), rebuilt from
    /// row `anchor` (from 0). `#{ groove, hp, b }`: `hp` and `b` are the
    /// smoothings (`.change`, `.max_change`, `.max_change_z`,
    /// `.d1_before`, `.d1_after`, `.d2_before`, `.d2_after`).
    #[rhai_fn(pure, return_raw)]
    pub fn smoothed(
        g: &mut Groove,
        iterations: i64,
        anchor: i64,
    ) -> Result<rhai::Map, Box<EvalAltResult>> {
        smoothed_holding(g, iterations, anchor, Array::new())
    }

    /// [`smoothed`] holding the rows `held`, `[first, last]` (from 0),
    /// exactly: the sizing section, which sets the tube's finished size
    /// (docs/math.md §3.2); `[]` holds none. The anchor must lie inside them.
    #[rhai_fn(name = "smoothed", pure, return_raw)]
    pub fn smoothed_holding(
        g: &mut Groove,
        iterations: i64,
        anchor: i64,
        held: Array,
    ) -> Result<rhai::Map, Box<EvalAltResult>> {
        if !(0..=10_000).contains(&iterations) || anchor < 0 {
            return Err(format!(
                "smoothed: iterations = {iterations} must be from 0 to 10000, anchor = {anchor} not negative"
            )
            .into());
        }
        let rows: Vec<i64> = held.iter().filter_map(|v| v.as_int().ok()).collect();
        let held = match rows.as_slice() {
            [] => None,
            &[a, b] if a >= 0 && b >= 0 => Some((a as usize, b as usize)),
            _ => {
                return Err(format!(
                    "smoothed: the held rows must be [first, last] (from 0) or [], not {held:?}"
                )
                .into())
            }
        };
        let (groove, hp, b) = kernel(g.smoothed(iterations as usize, anchor as usize, held))?;
        let mut m = rhai::Map::new();
        m.insert("groove".into(), Dynamic::from(groove));
        m.insert("hp".into(), Dynamic::from(hp));
        m.insert("b".into(), Dynamic::from(b));
        Ok(m)
    }

    /// The groove with its tables interpolated between rows by `name`:
    /// `"monotone"` (Fritsch–Carlson: no overshoot, a constant stretch
    /// stays flat), `"parabolic"` (cubic Hermite with the slopes of the
    /// parabola through each row and its neighbours), `"linear"` or
    /// `"natural"` (the natural cubic spline).
    #[rhai_fn(pure, return_raw)]
    pub fn interpolated(g: &mut Groove, name: &str) -> Result<Groove, Box<EvalAltResult>> {
        let mode = crate::binding::interpolation(name)?;
        Ok(g.clone().with_interpolation(mode))
    }

    /// The sizing section's rows `[first, last]` (from 0): the longest
    /// run of rows of one depth and width; `[]` if there is none.
    #[rhai_fn(get = "sizing_rows", pure)]
    pub fn sizing_rows(g: &mut Groove) -> Array {
        g.sizing_rows().map_or_else(Array::new, |(a, b)| {
            vec![(a as i64).into(), (b as i64).into()]
        })
    }

    /// The rows `[first, last]` (from 0) whose angles lie within
    /// `[from_deg, to_deg]`: a sizing section given by its angles.
    #[rhai_fn(pure, return_raw)]
    pub fn rows_between(
        g: &mut Groove,
        from_deg: Real,
        to_deg: Real,
    ) -> Result<Array, Box<EvalAltResult>> {
        let (a, b) = kernel(g.rows_between(from_deg, to_deg))?;
        Ok(vec![(a as i64).into(), (b as i64).into()])
    }

    /// The change the smoothing made at every row (after minus before, mm).
    #[rhai_fn(get = "change", pure)]
    pub fn change(s: &mut Smoothing) -> Floats {
        Floats::new(s.change.clone())
    }

    /// The first differences before smoothing (one per interval).
    #[rhai_fn(get = "d1_before", pure)]
    pub fn d1_before(s: &mut Smoothing) -> Floats {
        Floats::new(s.d1_before.clone())
    }
    /// The first differences after smoothing.
    #[rhai_fn(get = "d1_after", pure)]
    pub fn d1_after(s: &mut Smoothing) -> Floats {
        Floats::new(s.d1_after.clone())
    }
    /// The second differences before smoothing (one per interior row).
    #[rhai_fn(get = "d2_before", pure)]
    pub fn d2_before(s: &mut Smoothing) -> Floats {
        Floats::new(s.d2_before.clone())
    }
    /// The second differences after smoothing.
    #[rhai_fn(get = "d2_after", pure)]
    pub fn d2_after(s: &mut Smoothing) -> Floats {
        Floats::new(s.d2_after.clone())
    }

    /// The depth table Hp(theta) as a profile (theta in rad, mm).
    #[rhai_fn(get = "depth", pure)]
    pub fn depth(g: &mut Groove) -> Profile {
        g.depth().clone()
    }

    /// The width table B(theta) as a profile (theta in rad, mm).
    #[rhai_fn(get = "width", pure)]
    pub fn width(g: &mut Groove) -> Profile {
        g.width().clone()
    }

    /// The tables' angles (deg), one per row.
    #[rhai_fn(get = "theta_deg", pure)]
    pub fn theta_deg(g: &mut Groove) -> Floats {
        Floats::new(g.depth().z().iter().map(|t| t.to_degrees()).collect())
    }

    /// A wheel for the caliber grinders: largest radius `r_k0`, rounded
    /// across its width by `r_k` (a torus: the width is `2 r_k`), tracked
    /// at its centre with its axis along +Z (the machines' tool frame).
    #[rhai_fn(return_raw)]
    pub fn caliber_wheel(
        name: &str,
        number: i64,
        r_k0: Real,
        r_k: Real,
    ) -> Result<Tool, Box<EvalAltResult>> {
        let number = crate::binding::tool_number(name, number)?;
        let w = kernel(Wheel::new(2.0 * r_k0, r_k, 2.0 * r_k))?;
        Ok(Tool::wheel_at_centre(name, number, w))
    }

    /// The pass at `psi` (rad) along the whole groove, for a wheel of
    /// largest radius `r_k0` and rounding `r_k`, at a uniform `step` (rad)
    /// of the roll's turn: the exact pose at every block, the wheel's plane
    /// along the contact's trajectory, its axis square to the radius
    /// through the contact (`cross`: a machine with the cross axis Y) or
    /// through its centre (a 4-axis machine). Columns: `x`, `y`, `z` (the
    /// wheel's centre), `i`, `j`, `k` (its axis), `nx`, `ny`, `nz` (the
    /// groove's normal at the contact, out of the material), `theta` (the
    /// contact's, rad), `turn` (rad), `seed_centre` (mm) and `seed_axis`
    /// (rad), how far the seed's model is from each pose.
    #[rhai_fn(pure, return_raw)]
    pub fn pass(
        g: &mut Groove,
        psi: Real,
        step: Real,
        r_k0: Real,
        r_k: Real,
        cross: bool,
    ) -> Result<rhai::Map, Box<EvalAltResult>> {
        let plane = super::swivel_plane(cross);
        let poses = kernel(caliber::pass_poses(g, psi, step, r_k0, r_k, plane))?;
        Ok(super::pass_map(&poses))
    }

    /// The wheel's poses stepping over at the contact's `theta` from the
    /// pass at `psi_from` to the pass at `psi_to` (rad), ends left out, as
    /// many as keep the rounding's centre within `sag` (mm) of the straight
    /// moves between them (on an edge's convex rounding a straight step
    /// over would cut a chord into it): a pass's map, possibly empty.
    #[rhai_fn(pure, return_raw)]
    #[allow(clippy::too_many_arguments)]
    pub fn step_over(
        g: &mut Groove,
        theta: Real,
        psi_from: Real,
        psi_to: Real,
        r_k0: Real,
        r_k: Real,
        cross: bool,
        sag: Real,
    ) -> Result<rhai::Map, Box<EvalAltResult>> {
        let plane = super::swivel_plane(cross);
        let poses = kernel(caliber::step_over(
            g,
            theta,
            (psi_from, psi_to),
            r_k0,
            r_k,
            plane,
            sag,
        ))?;
        Ok(super::pass_map(&poses))
    }

    /// [`pass`] for every angle of `psis` (rad), computed on two threads:
    /// an array of the passes' maps, in the order of `psis`.
    #[rhai_fn(pure, return_raw)]
    pub fn passes(
        g: &mut Groove,
        psis: Floats,
        step: Real,
        r_k0: Real,
        r_k: Real,
        cross: bool,
    ) -> Result<Array, Box<EvalAltResult>> {
        let plane = super::swivel_plane(cross);
        let psis: Vec<Real> = psis.0.to_vec();
        let g: &Groove = g;
        let run = |list: &[Real]| -> Result<Vec<Vec<caliber::PassPose>>, String> {
            list.iter()
                .map(|&psi| {
                    caliber::pass_poses(g, psi, step, r_k0, r_k, plane).map_err(|e| e.to_string())
                })
                .collect()
        };
        let half = psis.len() / 2;
        let (deadline, cancel) = (crate::budget::current(), crate::budget::current_cancel());
        let (a, b) = std::thread::scope(|s| {
            let h = s.spawn(|| {
                crate::budget::with_cancel(cancel, || {
                    crate::budget::with_deadline(deadline, || run(&psis[half..]))
                })
            });
            let a = run(&psis[..half]);
            (
                a,
                h.join()
                    .unwrap_or_else(|_| Err("a pass's thread failed".into())),
            )
        });
        Ok(a?
            .into_iter()
            .chain(b?)
            .map(|p| Dynamic::from(super::pass_map(&p)))
            .collect())
    }

    /// The roll's sector with its groove as a closed solid: the rim `width`
    /// wide from radius `hub` to the periphery, meshed with chords within
    /// `tol` (mm) for `caliber.stl`, and exact for `caliber.step`.
    #[rhai_fn(pure, return_raw)]
    pub fn caliber_solid(
        g: &mut Groove,
        width: Real,
        hub: Real,
        tol: Real,
    ) -> Result<Solid, Box<EvalAltResult>> {
        let roll = kernel(caliber::Roll::new(g, width, hub))?;
        let mesh = kernel(roll.mesh(tol))?;
        Ok(Solid {
            mesh,
            body: crate::family::SweptBody::new(roll),
        })
    }

    /// The groove from two tables: Hp from `depth_table`, B from
    /// `width_table`, each with its column of theta (deg) named `theta`;
    /// the two must give the same angles (an error names the rows that
    /// differ).
    #[rhai_fn(name = "groove", return_raw)]
    pub fn groove_two(
        roll_radius: Real,
        depth_table: Table,
        width_table: Table,
        theta: &str,
        depth: &str,
        width: &str,
    ) -> Result<Groove, Box<EvalAltResult>> {
        kernel(Groove::from_tables(
            roll_radius,
            (&depth_table, theta, depth),
            (&width_table, theta, width),
        ))
    }

    /// The groove with its edges rounded into the periphery by the radii
    /// (mm) in `column` of `table`, whose column `theta` (deg) gives the
    /// groove's angles; errors name file, row and column.
    #[rhai_fn(name = "rounded", pure, return_raw)]
    pub fn rounded_from(
        g: &mut Groove,
        table: Table,
        theta: &str,
        column: &str,
    ) -> Result<Groove, Box<EvalAltResult>> {
        edge_from(g, EdgeKind::Rounding, &table, theta, column)
    }

    /// The groove corrected by `table` (`pilgrim compensate`'s
    /// `correction.csv`): its columns `theta_deg`, `dhp_mm` and `db_mm`
    /// added to the depth and the width; errors name file, row and column.
    #[rhai_fn(pure, return_raw)]
    pub fn corrected(g: &mut Groove, table: Table) -> Result<Groove, Box<EvalAltResult>> {
        let column = |c: &str| kernel(table.column(c));
        kernel(
            g.clone()
                .corrected(&column("theta_deg")?, &column("dhp_mm")?, &column("db_mm")?),
        )
    }

    /// The groove with its edges rounded into the periphery by `radius`
    /// (mm) all round.
    #[rhai_fn(pure, return_raw)]
    pub fn rounded(g: &mut Groove, radius: Real) -> Result<Groove, Box<EvalAltResult>> {
        edge_all_along(g, EdgeKind::Rounding, radius)
    }

    /// The groove with its edges chamfered at 45 deg into the periphery
    /// by the legs (mm) in `column` of `table`, whose column `theta` (deg)
    /// gives the groove's angles; errors name file, row and column.
    #[rhai_fn(name = "chamfered", pure, return_raw)]
    pub fn chamfered_from(
        g: &mut Groove,
        table: Table,
        theta: &str,
        column: &str,
    ) -> Result<Groove, Box<EvalAltResult>> {
        edge_from(g, EdgeKind::Chamfer, &table, theta, column)
    }

    /// The groove with its edges chamfered `leg` x 45 deg (mm) all round.
    #[rhai_fn(pure, return_raw)]
    pub fn chamfered(g: &mut Groove, leg: Real) -> Result<Groove, Box<EvalAltResult>> {
        edge_all_along(g, EdgeKind::Chamfer, leg)
    }

    /// The edge: `"sharp"`, `"rounding"` or `"chamfer"`.
    #[rhai_fn(get = "edge_kind", pure)]
    pub fn edge_kind(g: &mut Groove) -> String {
        match g.edge() {
            None => "sharp",
            Some((EdgeKind::Rounding, _)) => "rounding",
            Some((EdgeKind::Chamfer, _)) => "chamfer",
        }
        .into()
    }

    /// The edge's size at each row (mm: the rounding's radius, the
    /// chamfer's leg); `[]` for sharp edges.
    #[rhai_fn(get = "edge_size", pure)]
    pub fn edge_size(g: &mut Groove) -> Floats {
        Floats::new(g.edge().map_or_else(Vec::new, |(_, e)| e.x().to_vec()))
    }

    /// The groove's point `[x, y, z]` at `(theta, psi)` in the roll's frame.
    #[rhai_fn(pure, return_raw)]
    pub fn point(g: &mut Groove, theta: Real, psi: Real) -> Result<Array, Box<EvalAltResult>> {
        let p = kernel(g.point(theta, psi))?;
        Ok(vec![p.x.into(), p.y.into(), p.z.into()])
    }

    /// The groove's unit normal at `(theta, psi)`, out of the material.
    #[rhai_fn(pure, return_raw)]
    pub fn normal(g: &mut Groove, theta: Real, psi: Real) -> Result<Array, Box<EvalAltResult>> {
        let n = kernel(g.normal(theta, psi))?;
        Ok(vec![n.x.into(), n.y.into(), n.z.into()])
    }

    /// The smallest radius of curvature of the groove's sections (mm).
    #[rhai_fn(get = "min_curvature_radius", pure, return_raw)]
    pub fn min_curvature_radius(g: &mut Groove) -> Result<Real, Box<EvalAltResult>> {
        Ok(kernel(g.min_curvature_radius())?.0)
    }

    /// The tables' range of theta (rad) as `[from, to]`.
    #[rhai_fn(get = "theta_range", pure)]
    pub fn theta_range(g: &mut Groove) -> Array {
        let (a, b) = g.theta_range();
        vec![a.into(), b.into()]
    }

    /// The pass angles psi (rad) across the groove for a rounding `r_k`,
    /// at most `dpsi` apart out to `psi_max`: `#{ psi, scallop }`, the
    /// scallop (mm) the step leaves in the widest section.
    #[rhai_fn(pure, return_raw)]
    pub fn pass_angles(
        g: &mut Groove,
        r_k: Real,
        dpsi: Real,
        psi_max: Real,
    ) -> Result<rhai::Map, Box<EvalAltResult>> {
        let (psi, rz) = kernel(g.pass_angles(r_k, dpsi, psi_max))?;
        let mut m = rhai::Map::new();
        m.insert("psi".into(), Dynamic::from(Floats::new(psi)));
        m.insert("scallop".into(), rz.into());
        Ok(m)
    }

    /// The scallop (mm) two rounding circles of radius `r_k` leave `dpsi`
    /// apart in a section circle of radius `section_radius` (docs/math.md §3.3).
    #[rhai_fn(return_raw)]
    pub fn scallop_height(
        section_radius: Real,
        r_k: Real,
        dpsi: Real,
    ) -> Result<Real, Box<EvalAltResult>> {
        kernel(caliber::scallop_height(section_radius, r_k, dpsi))
    }

    /// The largest step `dpsi` (rad) whose scallop is at most `rz` mm.
    #[rhai_fn(return_raw)]
    pub fn step_for_scallop(
        section_radius: Real,
        r_k: Real,
        rz: Real,
    ) -> Result<Real, Box<EvalAltResult>> {
        kernel(caliber::step_for_scallop(section_radius, r_k, rz))
    }

    /// The seed's pose of a wheel (largest radius `r_k0`, rounding `r_k`)
    /// on the pass at `psi`, at `theta` (docs/math.md §3.4): `.x_k`, `.z_k`,
    /// `.psi_1`, `.mu`, `.dtheta`, `.epsilon`, `.dtheta_1`, ...
    #[rhai_fn(pure, return_raw)]
    pub fn seed_pose(
        g: &mut Groove,
        theta: Real,
        psi: Real,
        r_k0: Real,
        r_k: Real,
    ) -> Result<SeedPose, Box<EvalAltResult>> {
        kernel(caliber::seed_pose(g, theta, psi, r_k0, r_k))
    }

    /// The contact point's position along the roll's axis (mm).
    #[rhai_fn(get = "x_a", pure)]
    pub fn x_a(p: &mut SeedPose) -> Real {
        p.x_a
    }
    /// The contact point's depth from the periphery (mm).
    #[rhai_fn(get = "z_a", pure)]
    pub fn z_a(p: &mut SeedPose) -> Real {
        p.z_a
    }
    /// The section's normal angle at the contact (rad).
    #[rhai_fn(get = "psi_1", pure)]
    pub fn psi_1(p: &mut SeedPose) -> Real {
        p.psi_1
    }
    /// The rounding centre along the roll's axis (mm).
    #[rhai_fn(get = "x_k", pure)]
    pub fn x_k(p: &mut SeedPose) -> Real {
        p.x_k
    }
    /// The rounding centre's depth (mm).
    #[rhai_fn(get = "z_k", pure)]
    pub fn z_k(p: &mut SeedPose) -> Real {
        p.z_k
    }
    /// The pressure angle mu (rad).
    #[rhai_fn(get = "mu", pure)]
    pub fn mu(p: &mut SeedPose) -> Real {
        p.mu
    }
    /// The roll angle's correction (rad).
    #[rhai_fn(get = "dtheta", pure)]
    pub fn dtheta(p: &mut SeedPose) -> Real {
        p.dtheta
    }
    /// The swivel epsilon (rad).
    #[rhai_fn(get = "epsilon", pure)]
    pub fn epsilon(p: &mut SeedPose) -> Real {
        p.epsilon
    }
    /// The rounding centre along the axis with the swivel (mm).
    #[rhai_fn(get = "x_k_swivelled", pure)]
    pub fn x_k_swivelled(p: &mut SeedPose) -> Real {
        p.x_k_swivelled
    }
    /// The roll angle's swivel correction (rad).
    #[rhai_fn(get = "dtheta_1", pure)]
    pub fn dtheta_1(p: &mut SeedPose) -> Real {
        p.dtheta_1
    }
}

/// A pass's poses as the map of columns `pass` returns.
fn pass_map(poses: &[caliber::PassPose]) -> rhai::Map {
    use rhai::Dynamic;
    let col = |f: &dyn Fn(&caliber::PassPose) -> Real| {
        Dynamic::from(Floats::new(poses.iter().map(f).collect()))
    };
    let mut m = rhai::Map::new();
    m.insert("x".into(), col(&|p| p.wheel.centre.x));
    m.insert("y".into(), col(&|p| p.wheel.centre.y));
    m.insert("z".into(), col(&|p| p.wheel.centre.z));
    m.insert("i".into(), col(&|p| p.wheel.axis.x));
    m.insert("j".into(), col(&|p| p.wheel.axis.y));
    m.insert("k".into(), col(&|p| p.wheel.axis.z));
    m.insert("nx".into(), col(&|p| p.normal.x));
    m.insert("ny".into(), col(&|p| p.normal.y));
    m.insert("nz".into(), col(&|p| p.normal.z));
    m.insert("theta".into(), col(&|p| p.theta));
    m.insert("turn".into(), col(&|p| p.turn));
    m.insert("seed_centre".into(), col(&|p| p.seed_centre_error));
    m.insert("seed_axis".into(), col(&|p| p.seed_axis_error));
    m
}

/// The groove with its edges of `kind` sized by `column` of `table` (the
/// groove's angles in its column `theta`).
fn edge_from(
    g: &Groove,
    kind: EdgeKind,
    table: &Table,
    theta: &str,
    column: &str,
) -> Result<Groove, Box<EvalAltResult>> {
    kernel(g.clone().with_edge_from(kind, table, theta, column))
}

/// The groove with its edges of `kind` and `size` (mm) all along.
fn edge_all_along(g: &Groove, kind: EdgeKind, size: Real) -> Result<Groove, Box<EvalAltResult>> {
    let sizes = vec![size; g.depth().len()];
    kernel(g.clone().with_edge(kind, &sizes))
}

/// The plane a caliber wheel's axis keeps: the contact's with the cross
/// axis, the wheel centre's without.
fn swivel_plane(cross: bool) -> caliber::SwivelPlane {
    if cross {
        caliber::SwivelPlane::Contact
    } else {
        caliber::SwivelPlane::Wheel
    }
}

/// The caliber's part of the script API, as the reference lists it.
pub(crate) const SCRIPT_API: ApiGroup = ApiGroup {
    title: "Calibers: the groove, passes, the seed's pose (`Groove`, `SeedPose`)",
    types: |e| {
        e.register_type_with_name::<Groove>("Groove")
            .register_type_with_name::<SeedPose>("SeedPose");
    },
    register: |e, _| {
        e.register_global_module(rhai::exported_module!(caliber_api).into());
    },
    verify: Some(VerifyForm {
        key: "groove",
        form: "#{ groove, psi, tolerance, grid_theta, grid_per_step, patch_gap } (and optionally stock, the allowance)",
        keys: &[
            "groove",
            "psi",
            "tolerance",
            "grid_theta",
            "grid_per_step",
            "patch_gap",
            "stock",
        ],
        read: verification,
    }),
};

/// The groove's request from the map of a script's `fn verify(p)`.
fn verification(m: &rhai::Map) -> Result<Verification, Option<String>> {
    let num = |k: &str| m.get(k).and_then(number).ok_or(None);
    let groove = m
        .get("groove")
        .and_then(|g| g.clone().try_cast::<Groove>())
        .ok_or(None)?;
    let psi = m
        .get("psi")
        .and_then(|d| numbers(d, "psi").ok())
        .ok_or(None)?;
    let per = num("grid_per_step")?;
    if !(1.0..=1000.0).contains(&per) {
        return Err(Some(format!(
            "fn verify(p): grid_per_step = {per} must be from 1 to 1000"
        )));
    }
    Ok(Verification::new(caliber::GrooveRequest {
        groove,
        psi: psi.to_vec(),
        tolerance: num("tolerance")?,
        grid_theta: num("grid_theta")?,
        grid_per_step: per as usize,
        patch_gap: num("patch_gap")?,
        stock: match m.get("stock") {
            None => None,
            Some(_) => Some(num("stock")?),
        },
    }))
}
