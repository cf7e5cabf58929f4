//! Tools and toolpaths for scripts: wheels and cutters, and the toolpath a
//! family builds pass by pass.

use super::bind_offset::rounding_radius;
use crate::binding::floats::{err, kernel, len_of, number, Column};
use crate::binding::tool_number;
use crate::math::Real;
use crate::program::cycle::FanucThreadCycle;
use crate::tool::{Tool, ToolShape, Wheel};
use crate::toolpath::{ClPoint, CycleWords, Motion, Pass, Toolpath};
use rhai::plugin::*;
use rhai::{Array, EvalAltResult, Map};
use std::cell::RefCell;
use std::rc::Rc;

/// A toolpath under construction, shared by handle.
pub type ToolpathHandle = Rc<RefCell<Toolpath>>;

/// Tools.
#[export_module]
pub mod tool_api {
    use super::*;

    /// A grinding wheel tool: `diameter`, rounding radius, `width` (mm); the
    /// toolpath tracks its rounding's centre, the machine programs its lowest point.
    #[rhai_fn(return_raw)]
    pub fn wheel_tool(
        name: &str,
        number: i64,
        diameter: Real,
        rounding_radius: Real,
        width: Real,
    ) -> Result<Tool, Box<EvalAltResult>> {
        let number = tool_number(name, number)?;
        let w = kernel(Wheel::new(diameter, rounding_radius, width))?;
        Ok(Tool::wheel(name, number, w))
    }

    /// An end mill tracked at its tip centre.
    #[rhai_fn(return_raw)]
    pub fn end_mill(
        name: &str,
        number: i64,
        diameter: Real,
        length: Real,
    ) -> Result<Tool, Box<EvalAltResult>> {
        let number = tool_number(name, number)?;
        kernel(Tool::end_mill(name, number, diameter, length))
    }

    /// The tool's name.
    #[rhai_fn(get = "name", pure)]
    pub fn tool_name(t: &mut Tool) -> String {
        t.name.clone()
    }

    /// The wheel's rounding radius R_s (mm); an error for another tool.
    #[rhai_fn(get = "rounding_radius", pure, return_raw)]
    pub fn tool_rounding(t: &mut Tool) -> Result<Real, Box<EvalAltResult>> {
        rounding_radius(t)
    }

    /// The tool's diameter (mm): a wheel's outer diameter, a cutter's.
    #[rhai_fn(get = "diameter", pure, return_raw)]
    pub fn tool_diameter(t: &mut Tool) -> Result<Real, Box<EvalAltResult>> {
        match t.shape {
            ToolShape::Wheel(w) => Ok(w.diameter),
            ToolShape::EndMill { diameter, .. } => Ok(diameter),
            ToolShape::Insert { .. } | ToolShape::ThreadCutter(_) => {
                err(format!("tool '{}' has no diameter", t.name))
            }
        }
    }

    /// The wheel's width (mm); an error for another tool.
    #[rhai_fn(get = "width", pure, return_raw)]
    pub fn tool_width(t: &mut Tool) -> Result<Real, Box<EvalAltResult>> {
        match t.shape {
            ToolShape::Wheel(w) => Ok(w.width),
            _ => err(format!("tool '{}' is not a grinding wheel", t.name)),
        }
    }
}

/// Building toolpaths.
#[export_module]
pub mod toolpath_api {
    use super::*;

    /// A new, empty toolpath for `part` with `tool` at `spindle_rpm`; every point
    /// will carry the auxiliary values named in `aux_names` (e.g. `["U"]`).
    #[rhai_fn(return_raw)]
    pub fn new_toolpath(
        part: &str,
        tool: Tool,
        spindle_rpm: Real,
        aux_names: Array,
    ) -> Result<ToolpathHandle, Box<EvalAltResult>> {
        kernel(crate::names::check_name("part name", part))?;
        let names = aux_names
            .iter()
            .map(|d| {
                d.clone()
                    .into_string()
                    .map_err(|t| format!("auxiliary names must be strings, not {t}"))
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Rc::new(RefCell::new(Toolpath::new(
            part,
            tool,
            spindle_rpm,
            names,
        ))))
    }

    /// Holds the part at its start alone (a short part in the chuck): the
    /// machine's bodies that stand at the part's end (a tailstock) are
    /// away, for the collision check and the scene.
    ///
    /// ```rhai
    /// if p.length < 5.0 * t.crest_diameter { tp.free_end(); }
    /// ```
    #[rhai_fn(name = "free_end")]
    pub fn free_end(tp: &mut ToolpathHandle) {
        tp.borrow_mut().free_end = true;
    }

    /// Notes a figure about the toolpath for the run's report.
    #[rhai_fn(name = "note", return_raw)]
    pub fn note(
        tp: &mut ToolpathHandle,
        name: &str,
        value: Real,
    ) -> Result<(), Box<EvalAltResult>> {
        kernel(crate::names::check_name("note name", name))?;
        crate::math::finite(&format!("note {name}"), value).map_err(|e| e.to_string())?;
        tp.borrow_mut().notes.insert(name.to_owned(), value);
        Ok(())
    }

    /// Adds a table for the run's report: `columns` maps names to columns
    /// of numbers, all of one length.
    ///
    /// ```rhai
    /// tp.table("passes", #{ psi_deg: [-10.0, 0.0, 10.0], blocks: [281, 281, 281] });
    /// ```
    #[rhai_fn(name = "table", return_raw)]
    pub fn table(
        tp: &mut ToolpathHandle,
        name: &str,
        columns: rhai::Map,
    ) -> Result<(), Box<EvalAltResult>> {
        kernel(crate::names::check_name("table name", name))?;
        let mut t = std::collections::BTreeMap::new();
        let mut len = None;
        for (k, v) in columns {
            kernel(crate::names::check_name("column name", &k))?;
            let col = crate::binding::floats::numbers(&v, &format!("table {name}, column {k}"))?;
            if let Some(v) = col.iter().find(|v| !v.is_finite()) {
                return Err(format!("table {name}, column {k}: {v} is not a finite number").into());
            }
            if *len.get_or_insert(col.len()) != col.len() {
                return Err(format!(
                    "table {name}: column {k} has {} values, another {}",
                    col.len(),
                    len.unwrap_or(0)
                )
                .into());
            }
            t.insert(k.to_string(), col.to_vec());
        }
        tp.borrow_mut().tables.insert(name.to_owned(), t);
        Ok(())
    }

    /// Asks the run to draw a chart `<file>.svg` from a table: `spec` holds
    /// `file`, `title`, `table`, `x` (a column), `y` (an array of columns),
    /// `x_label` and `y_label` (with units).
    #[rhai_fn(name = "plot", return_raw)]
    pub fn plot(tp: &mut ToolpathHandle, spec: rhai::Map) -> Result<(), Box<EvalAltResult>> {
        let text = |k: &str| -> Result<String, Box<EvalAltResult>> {
            let t = spec
                .get(k)
                .and_then(|d| d.clone().into_string().ok())
                .ok_or_else(|| format!("plot: '{k}' must be a string"))?;
            kernel(crate::names::check_text(&format!("plot {k}"), &t))?;
            Ok(t)
        };
        let y = spec
            .get("y")
            .and_then(|d| d.clone().try_cast::<rhai::Array>())
            .ok_or("plot: 'y' must be an array of column names")?
            .into_iter()
            .map(|d| {
                d.into_string()
                    .map_err(|_| "plot: 'y' must hold names".into())
            })
            .collect::<Result<Vec<String>, Box<EvalAltResult>>>()?;
        let file = text("file")?;
        if !crate::files::is_plain_name(&file) {
            return Err(format!(
                "plot: file '{}' is not a plain name",
                crate::files::excerpt(&file)
            )
            .into());
        }
        tp.borrow_mut().plots.push(crate::toolpath::PlotSpec {
            file,
            title: text("title")?,
            table: text("table")?,
            x: text("x")?,
            y,
            x_label: text("x_label")?,
            y_label: text("y_label")?,
        });
        Ok(())
    }

    /// Adds a warning: the run goes on, and says it (the report's
    /// `warnings`, the summary).
    #[rhai_fn(return_raw)]
    pub fn warn(tp: &mut ToolpathHandle, text: &str) -> Result<(), Box<EvalAltResult>> {
        kernel(crate::names::check_text("warning", text))?;
        tp.borrow_mut().warnings.push(text.to_owned());
        Ok(())
    }

    /// Number of points so far.
    #[rhai_fn(get = "point_count", pure)]
    pub fn point_count(tp: &mut ToolpathHandle) -> i64 {
        tp.borrow().point_count() as i64
    }

    /// Appends a pass. `data` holds columns (Floats, arrays, or one number
    /// for all points): `x`, `y`, `z` (the tracked point, mm), `feed`
    /// (mm/min; not for rapids), and optionally `motion` ("linear",
    /// "rapid", "thread"; one for all points, or an array of one per
    /// point), `lead` (mm, threads), `start` (deg, the spindle's angle a
    /// thread starts at), `i`, `j`, `k` (the tool's
    /// axis, default 0, 0, 1), `aux` (a map of the toolpath's auxiliary
    /// names to columns).
    ///
    /// ```rhai
    /// tp.add_pass("contour", #{ x: xs, y: ys, z: -5.0, feed: 600.0 });
    /// ```
    #[rhai_fn(return_raw)]
    pub fn add_pass(
        tp: &mut ToolpathHandle,
        name: &str,
        data: Map,
    ) -> Result<(), Box<EvalAltResult>> {
        const KEYS: [&str; 11] = [
            "x", "y", "z", "feed", "motion", "lead", "start", "i", "j", "k", "aux",
        ];
        kernel(crate::names::check_name("pass name", name))?;
        if let Some(k) = data.keys().find(|k| !KEYS.contains(&k.as_str())) {
            return err(format!(
                "add_pass: unknown key '{k}' (keys: {})",
                KEYS.join(", ")
            ));
        }
        let get = |k: &str| data.get(k).cloned();
        let n = ["x", "y", "z"]
            .iter()
            .find_map(|k| get(k).as_ref().and_then(len_of))
            .ok_or("add_pass: x, y or z must be an array of the pass's points")?;
        let col = |k: &str, default: Option<Real>| -> Result<Column, Box<EvalAltResult>> {
            match (get(k), default) {
                (Some(d), _) => Column::read(&d, n, k),
                (None, Some(v)) => Ok(Column::Scalar(v)),
                (None, None) => err(format!("add_pass: missing '{k}'")),
            }
        };
        let thread = || -> Result<Motion, Box<EvalAltResult>> {
            let lead = get("lead")
                .as_ref()
                .and_then(number)
                .ok_or("add_pass: a thread needs a number 'lead'")?;
            let start_deg = match get("start") {
                Some(s) => number(&s).ok_or("add_pass: 'start' must be a number (deg)")?,
                None => 0.0,
            };
            Ok(Motion::Thread { lead, start_deg })
        };
        let motion_of = |name: &str| -> Result<Motion, Box<EvalAltResult>> {
            match name {
                "linear" => Ok(Motion::Linear),
                "rapid" => Ok(Motion::Rapid),
                "thread" => thread(),
                other => err(format!(
                    "add_pass: motion must be linear, rapid or thread, not '{other}'"
                )),
            }
        };
        let motions: Vec<Motion> = match get("motion") {
            None => vec![Motion::Linear; n],
            Some(m) if m.is_array() => {
                let a = m.cast::<Array>();
                if a.len() != n {
                    return err(format!(
                        "add_pass: motion has {} entries for {n} points",
                        a.len()
                    ));
                }
                a.into_iter()
                    .map(|v| {
                        v.into_string()
                            .map_err(|t| {
                                format!("add_pass: a motion must be a string, not {t}").into()
                            })
                            .and_then(|s| motion_of(&s))
                    })
                    .collect::<Result<_, Box<EvalAltResult>>>()?
            }
            Some(m) => {
                let name = m
                    .into_string()
                    .map_err(|t| format!("add_pass: motion must be a string, not {t}"))?;
                vec![motion_of(&name)?; n]
            }
        };
        let all_rapid = motions.iter().all(|m| *m == Motion::Rapid);
        let (x, y, z) = (col("x", None)?, col("y", None)?, col("z", None)?);
        let feed = col("feed", all_rapid.then_some(0.0))?;
        let (i, j, k) = (
            col("i", Some(0.0))?,
            col("j", Some(0.0))?,
            col("k", Some(1.0))?,
        );
        let mut t = tp.borrow_mut();
        let aux_map = match get("aux") {
            Some(a) => a
                .try_cast::<Map>()
                .ok_or("add_pass: aux must be a map of columns")?,
            None => Map::new(),
        };
        if let Some(extra) = aux_map
            .keys()
            .find(|a| !t.aux_names.iter().any(|n| n == a.as_str()))
        {
            return err(format!(
                "add_pass: '{extra}' is not one of the toolpath's auxiliary names ({})",
                t.aux_names.join(", ")
            ));
        }
        let aux = t
            .aux_names
            .iter()
            .map(|a| match aux_map.get(a.as_str()) {
                Some(d) => Column::read(d, n, &format!("aux.{a}")),
                None => err(format!("add_pass: missing aux.{a}")),
            })
            .collect::<Result<Vec<_>, Box<EvalAltResult>>>()?;
        let points = (0..n)
            .map(|p| ClPoint {
                point: [x.at(p), y.at(p), z.at(p)],
                axis: [i.at(p), j.at(p), k.at(p)],
                motion: motions[p],
                feed: feed.at(p),
                aux: aux.iter().map(|c| c.at(p)).collect(),
            })
            .collect();
        t.passes.push(Pass {
            name: name.to_owned(),
            points,
        });
        Ok(())
    }

    /// Appends the passes a control's threading cycle makes from the
    /// toolpath's last point (its drive line), in the axial plane (y 0, X
    /// the program's on diameter where `diameter`, the tracked point's x
    /// then half of it): LinuxCNC's G76, its words in `words` (`p` the
    /// lead, `z`, `i`, `j`, `r`, `k`, `q`, `h` as the cycle's; see the
    /// kernel's `program::cycle`), each rounded as a program writes it.
    /// `diameter` must say how the machine programs X: building the
    /// program checks every move against the cycle as the machine's setup
    /// programs it, and refuses a mismatch, naming the block. A program
    /// for a control that has the cycle writes it as one block; any
    /// other, as its moves. Each cycle pass is named `name n`, the
    /// cycle's last move `name end`. Returns each pass's depth below the
    /// crest (radial, mm) and its start's shift along Z (mm), as maps
    /// `#{ depth, shift }`.
    #[rhai_fn(return_raw)]
    pub fn add_thread_cycle(
        tp: &mut ToolpathHandle,
        name: &str,
        words: Map,
        diameter: bool,
    ) -> Result<Array, Box<EvalAltResult>> {
        const KEYS: [&str; 8] = ["p", "z", "i", "j", "r", "k", "q", "h"];
        let word = cycle_word("add_thread_cycle", name, &words, &KEYS)?;
        let h = word("h")?;
        if !(h >= 0.0 && h.fract() == 0.0 && h <= 1000.0) {
            return err(format!(
                "add_thread_cycle: h = {h}: the spring passes must be a whole number from 0 to 1000"
            ));
        }
        let cycle = crate::program::cycle::as_written(&crate::program::cycle::ThreadCycle {
            pitch: word("p")?,
            z: word("z")?,
            i: word("i")?,
            j: word("j")?,
            r: word("r")?,
            k: word("k")?,
            q: word("q")?,
            h: h as u32,
        });
        let crest_from = cycle.i;
        let scale = if diameter { 2.0 } else { 1.0 };
        cycle_passes(
            tp,
            "add_thread_cycle",
            name,
            diameter,
            &|start| crate::program::cycle::expand(&cycle, start, diameter, None),
            &|start, x| (x - (start[0] + crest_from)).abs() / scale,
            CycleWords::Linuxcnc(cycle.clone()),
        )
    }

    /// The threading cycle a program for `control` (a dialect's name, as
    /// a parameter reading the machine's control gives it) writes as a
    /// cycle: `"linuxcnc"` (LinuxCNC's G76, [`add_thread_cycle`]),
    /// `"fanuc"` (Fanuc's two-block G76, [`add_fanuc_thread_cycle`]), or
    /// `""`: none, the moves are written as blocks.
    pub fn written_thread_cycle(control: &str) -> String {
        use crate::program::post::WrittenCycle;
        match crate::program::post::dialect(control).and_then(|d| d.thread_cycle) {
            Some(WrittenCycle::Linuxcnc) => "linuxcnc".into(),
            Some(WrittenCycle::FanucTwoBlock) => "fanuc".into(),
            None => String::new(),
        }
    }

    /// Appends the passes Fanuc's two-block threading cycle makes from the
    /// toolpath's last point (its drive line), as [`add_thread_cycle`]
    /// does LinuxCNC's: its words in `words` (`m` the finishing passes,
    /// `a` the tool's angle in degrees (80, 60, 55, 30, 29 or 0), `dd_min`
    /// the least cut, `d` the finishing allowance, `x` the thread's end at
    /// its full height as the program writes X, `z` its end, `k` the
    /// thread's height, `dd` the first cut's depth, `f` the lead; lengths
    /// radial in mm), each rounded as its blocks write it; no chamfer (the
    /// thread runs out over the toolpath's own run-out), no taper. A
    /// program for a control of Fanuc's kind writes the cycle as its two
    /// `G76` blocks; any other, as its moves. Each pass is named `name n`.
    /// Returns each pass's depth below the crest (radial, mm) and its
    /// start's shift along Z (mm), as maps `#{ depth, shift }`.
    #[rhai_fn(return_raw)]
    pub fn add_fanuc_thread_cycle(
        tp: &mut ToolpathHandle,
        name: &str,
        words: Map,
        diameter: bool,
    ) -> Result<Array, Box<EvalAltResult>> {
        const KEYS: [&str; 9] = ["m", "a", "dd_min", "d", "x", "z", "k", "dd", "f"];
        let word = cycle_word("add_fanuc_thread_cycle", name, &words, &KEYS)?;
        let m = word("m")?;
        if !((1.0..=99.0).contains(&m) && m.fract() == 0.0) {
            return err(format!(
                "add_fanuc_thread_cycle: m = {m}: the finishing passes must be a whole number from 1 to 99"
            ));
        }
        let a = word("a")?;
        if ![80.0, 60.0, 55.0, 30.0, 29.0, 0.0].contains(&a) {
            return err(format!(
                "add_fanuc_thread_cycle: a = {a}: Fanuc's G76 takes the tool's angle 80, 60, 55, 30, 29 or 0 deg"
            ));
        }
        let cycle = crate::program::cycle::fanuc_as_written(&FanucThreadCycle {
            finishes: m as u32,
            chamfer_tenths: 0,
            angle_deg: a,
            min_cut: word("dd_min")?,
            allowance: word("d")?,
            x: word("x")?,
            z: word("z")?,
            taper: 0.0,
            height: word("k")?,
            first: word("dd")?,
            lead: word("f")?,
            constant_depth: false,
        });
        let scale = if diameter { 2.0 } else { 1.0 };
        cycle_passes(
            tp,
            "add_fanuc_thread_cycle",
            name,
            diameter,
            &|start| {
                crate::program::cycle::expand_fanuc(
                    &cycle,
                    start,
                    diameter,
                    &crate::program::cycle::OWN_FANUC_RULES,
                )
            },
            &|_, x| cycle.height - (x - cycle.x).abs() / scale,
            CycleWords::FanucTwoBlock(cycle),
        )
    }
}

/// The reader of the words `words` of a cycle binding (`binding`, for
/// messages; `name` the passes' name, checked) whose keys are `keys`: each
/// key's number, or a refusal naming it.
///
/// # Failures
/// A bad pass name or a key not among `keys`.
#[allow(clippy::type_complexity)]
fn cycle_word<'a>(
    binding: &'a str,
    name: &str,
    words: &'a Map,
    keys: &[&str],
) -> Result<impl Fn(&str) -> Result<Real, Box<EvalAltResult>> + 'a, Box<EvalAltResult>> {
    kernel(crate::names::check_name("pass name", name))?;
    if let Some(k) = words.keys().find(|k| !keys.contains(&k.as_str())) {
        return err(format!(
            "{binding}: unknown key '{k}' (keys: {})",
            keys.join(", ")
        ));
    }
    Ok(move |k: &str| -> Result<Real, Box<EvalAltResult>> {
        words
            .get(k)
            .and_then(number)
            .ok_or_else(|| format!("{binding}: '{k}' must be a number").into())
    })
}

/// The passes a threading cycle makes (`expand` from the toolpath's last
/// point, `[X, Z]` as the program writes them), appended to `tp` as its
/// passes of four moves (a shorter rest: `name end`) and recorded as the
/// cycle `words`; each pass's depth below the crest (`depth` of the
/// start and its cut's X, radial) and its start's shift along Z, as maps
/// `#{ depth, shift }`. `binding` names the caller in messages.
#[allow(clippy::type_complexity)]
fn cycle_passes(
    tp: &mut ToolpathHandle,
    binding: &str,
    name: &str,
    diameter: bool,
    expand: &dyn Fn(
        [Real; 2],
    )
        -> Result<Vec<crate::program::cycle::CycleMove>, crate::program::ProgramFault>,
    depth: &dyn Fn([Real; 2], Real) -> Real,
    words: CycleWords,
) -> Result<Array, Box<EvalAltResult>> {
    let mut t = tp.borrow_mut();
    if !t.aux_names.is_empty() {
        return err(format!("{binding}: a toolpath with auxiliary values cannot hold a cycle (its moves carry none)"));
    }
    let Some(last) = t.passes.last().and_then(|p| p.points.last()).cloned() else {
        return err(format!("{binding}: the toolpath has no point yet: the cycle starts where its last pass ends (the drive line)"));
    };
    let scale = if diameter { 2.0 } else { 1.0 };
    let start = [last.point[0] * scale, last.point[2]];
    let moves = expand(start).map_err(|m| format!("{binding}: {m}"))?;
    let spindle = t.spindle_rpm;
    let point = |m: &crate::program::cycle::CycleMove| ClPoint {
        point: [m.x / scale, 0.0, m.z],
        axis: [0.0, 0.0, 1.0],
        motion: m.motion,
        feed: match m.motion {
            Motion::Thread { lead, .. } => lead * spindle,
            _ => 0.0,
        },
        aux: Vec::new(),
    };
    let first_pass = t.passes.len();
    let mut depths = Array::new();
    let mut passes = Vec::new();
    for (n, four) in moves.chunks(4).enumerate() {
        let Some(cut) = four
            .iter()
            .find(|m| matches!(m.motion, Motion::Thread { .. }))
            .filter(|_| four.len() == 4)
        else {
            passes.push(Pass {
                name: format!("{name} end"),
                points: four.iter().map(point).collect(),
            });
            continue;
        };
        let mut d = Map::new();
        d.insert("depth".into(), depth(start, cut.x).into());
        d.insert("shift".into(), (four[0].z - start[1]).into());
        depths.push(d.into());
        passes.push(Pass {
            name: format!("{name} {}", n + 1),
            points: four.iter().map(point).collect(),
        });
    }
    t.cycles.push(crate::toolpath::PassCycle {
        first_pass,
        passes: passes.len(),
        cycle: words,
    });
    t.passes.extend(passes);
    Ok(depths)
}
