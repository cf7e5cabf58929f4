//! What a script's `fn verify(p)` declares, read: a family's form (each
//! family's folder reads its own map: `families::FAMILIES`), or a
//! verification of the script's own on a replay the kernel makes
//! (`#{ replay: "radius_over_angle", ... , judge }`); either may name a
//! `judge`, the script's function the kernel calls once with the replayed
//! part, pass by pass, in whole arrays, whose figures and findings the
//! run treats as a built-in verification's ([`crate::judged`]). On the
//! radius-over-angle replay, `nominal` names the script's function giving
//! the nominal radius over angle: the part is then measured and corrected
//! as a built-in family's (`pilgrim compensate`: `r_mm` at `angle_deg`,
//! the correction `dr_mm`), the finish's predicted radius made by the
//! kernel. The host
//! knows no family's form: it matches the map's keys against them.

use super::Script;
use crate::binding::floats::{number, Floats};
use crate::compensate::{Nominal, Quantity, PREDICTED};
use crate::family::{ReplayContext, Replayed, ReplayedPass, Verification, Verified, Verifier};
use crate::judged::{Judged, JudgedFigure, JudgedFinding, Tables, WithJudged};
use crate::profile::Profile;
use crate::replay::polar::{replay_polar, PolarPart, PolarRequest};
use crate::replay::VerifyError;
use rhai::{Array, Dynamic, Map};
use std::collections::BTreeMap;

/// The replays a script's own verification may ask for (`replay:`).
pub const REPLAYS: [&str; 1] = ["radius_over_angle"];

/// The keys of a script's own verification on the radius-over-angle replay.
const POLAR_KEYS: [&str; 6] = ["replay", "z", "angles", "blank", "judge", "nominal"];

/// The quantity a measurement of a part replayed as radius over angle
/// holds: its radius (`r_mm`) at `angle_deg`, its correction `dr_mm`.
const POLAR_RADIUS: [(&str, f64); 1] = [("r_mm", 1.0)];

/// The keys a judge's result may hold.
const RESULT_KEYS: [&str; 3] = ["figures", "findings", "tables"];

/// The keys of a figure a judge returns.
const FIGURE_KEYS: [&str; 6] = ["name", "value", "tolerance", "unit", "place", "block"];

/// The keys of a finding a judge returns.
const FINDING_KEYS: [&str; 3] = ["rule", "message", "block"];

/// What a script's `fn verify(p)` declared, read; `Err(message)` says what
/// is wrong, naming what is accepted.
pub(super) fn read(script: &Script, params: Map, m: Map) -> Result<Verification, String> {
    let forms: Vec<_> = crate::families::script_api()
        .filter_map(|g| g.verify.as_ref())
        .collect();
    let judge_of = |m: &mut Map| -> Result<Option<String>, String> {
        match m.remove("judge") {
            None => Ok(None),
            Some(j) => {
                let name = j.into_string().map_err(|t| {
                    format!("fn verify(p): judge must be the name of the script's function judging the replayed part, fn name(p, part), not {t}")
                })?;
                if !script.has_fn(&name, 2) {
                    return Err(format!(
                        "fn verify(p): judge '{name}' names no fn {name}(p, part) in the script"
                    ));
                }
                Ok(Some(name))
            }
        }
    };
    let every_form = || {
        let mut all = vec![format!(
            "#{{ replay: \"{}\", z, angles, blank, judge, nominal }}",
            REPLAYS.join("\" | \"")
        )];
        all.extend(forms.iter().map(|f| f.form.to_owned()));
        format!(
            "fn verify(p) must return one of: {} (each may add judge: the name of fn judge(p, part))",
            all.join("; ")
        )
    };
    let unknown = |m: &Map, keys: &[&str]| -> Result<(), String> {
        match m
            .keys()
            .find(|k| !keys.contains(&k.as_str()) && k.as_str() != "judge")
        {
            Some(k) => Err(format!(
                "fn verify(p): unknown key '{k}' (this form's keys: {}, judge)",
                keys.join(", ")
            )),
            None => Ok(()),
        }
    };
    let mut m = m;
    if let Some(kind) = m.get("replay") {
        unknown(&m, &POLAR_KEYS)?;
        let kind = kind.clone().into_string().unwrap_or_default();
        if !REPLAYS.contains(&kind.as_str()) {
            return Err(format!(
                "fn verify(p): replay '{kind}' is not one the kernel makes (replays: {})",
                REPLAYS.join(", ")
            ));
        }
        let judge = judge_of(&mut m)?.ok_or_else(|| {
            "fn verify(p): a verification of the script's own needs judge, the name of fn judge(p, part) that gives its figures".to_owned()
        })?;
        let num = |k: &str, default: Option<f64>| match (m.get(k), default) {
            (Some(v), _) => number(v).ok_or_else(|| format!("fn verify(p): {k} must be a number")),
            (None, Some(d)) => Ok(d),
            (None, None) => Err(format!(
                "fn verify(p): {k} is missing (keys: {})",
                POLAR_KEYS.join(", ")
            )),
        };
        let angles = num("angles", Some(3600.0))?;
        if angles.fract() != 0.0 || angles < 3.0 {
            return Err(format!(
                "fn verify(p): angles = {angles} must be a whole number of at least 3"
            ));
        }
        let request = PolarRequest {
            z: num("z", Some(0.0))?,
            angles: angles as usize,
            blank: num("blank", None)?,
        };
        let nominal = match m.get("nominal") {
            None => None,
            Some(n) => Some(polar_nominal(script, &params, n, &request)?),
        };
        return Ok(Verification::new(ScriptRequest {
            script: script.clone(),
            params,
            judge,
            replay: Replay::Polar(request),
            nominal,
        }));
    }
    let Some(form) = forms.iter().find(|f| m.contains_key(f.key)) else {
        return Err(every_form());
    };
    unknown(&m, form.keys)?;
    let judge = judge_of(&mut m)?;
    let base = (form.read)(&m).map_err(|e| e.unwrap_or_else(every_form))?;
    Ok(match judge {
        None => base,
        Some(judge) => Verification::new(ScriptRequest {
            script: script.clone(),
            params,
            judge,
            replay: Replay::Base(base),
            nominal: None,
        }),
    })
}

/// A verification a script judges.
#[derive(Debug)]
struct ScriptRequest {
    script: Script,
    params: Map,
    judge: String,
    replay: Replay,
    /// On the radius-over-angle replay, the nominal radius over angle
    /// (0 to 360 deg) the script names, which a measurement is held
    /// against; none: the part is not measured.
    nominal: Option<Profile>,
}

/// The replay a script's judgement reads.
#[derive(Debug)]
enum Replay {
    /// The kernel's replay of radius over angle, judged alone.
    Polar(PolarRequest),
    /// A built-in verification, with the script's figures beside its own.
    Base(Verification),
}

impl Verifier for ScriptRequest {
    fn verify(&self, ctx: &ReplayContext<'_>) -> Result<Verified, VerifyError> {
        match &self.replay {
            Replay::Polar(request) => {
                let polar = replay_polar(ctx.program, ctx.machine, ctx.tool, ctx.passes, request)?;
                let part = polar_replayed(&polar, request);
                let mut judged = self.judge(&part, ctx.program.blocks.len())?;
                if let Some(nominal) = &self.nominal {
                    let table = polar_predicted(&polar, nominal)?;
                    judged.tables.insert(PREDICTED.into(), table);
                }
                Ok(Verified {
                    outcome: Box::new(judged),
                    stock: None,
                    part: Some(part),
                })
            }
            Replay::Base(base) => {
                let mut verified = base.verifier().verify(ctx)?;
                let part = verified.part.clone().ok_or_else(|| {
                    VerifyError::Contract(format!(
                        "fn verify(p): judge '{}' reads the replayed part, which the {} verification does not give",
                        self.judge,
                        verified.outcome.key()
                    ))
                })?;
                let judged = self.judge(&part, ctx.program.blocks.len())?;
                verified.outcome = Box::new(WithJudged {
                    base: verified.outcome,
                    judged,
                });
                Ok(verified)
            }
        }
    }

    fn nominal(&self) -> Option<crate::compensate::Nominal> {
        match &self.replay {
            Replay::Polar(_) => self.nominal.as_ref().map(|n| Nominal {
                coordinate: "angle_deg",
                range: (0.0, 360.0),
                quantities: vec![Quantity {
                    name: "radius".into(),
                    values: &POLAR_RADIUS,
                    select: None,
                    nominal: n.clone(),
                    along: true,
                    key: "dr_mm".into(),
                    // The script's judge holds the part: its figures say.
                    tolerance: None,
                }],
            }),
            Replay::Base(base) => base.nominal(),
        }
    }

    /// A built-in form's warnings (its nominal's), the judge added or not.
    fn warnings(&self) -> Vec<crate::verdict::Finding> {
        match &self.replay {
            Replay::Polar(_) => Vec::new(),
            Replay::Base(base) => base.verifier().warnings(),
        }
    }
}

/// The nominal radius over angle a script's own verification on the
/// radius-over-angle replay names (`nominal: "name"`): its `fn name(p,
/// angle_deg)` called once with the replay's angles and 360 deg closing
/// the turn, which gives the radius at each (mm).
fn polar_nominal(
    script: &Script,
    params: &Map,
    d: &Dynamic,
    request: &PolarRequest,
) -> Result<Profile, String> {
    let name = d.clone().into_string().map_err(|t| {
        format!("fn verify(p): nominal must be the name of the script's function giving the nominal radius at the angles it is given, fn name(p, angle_deg), not {t}")
    })?;
    if !script.has_fn(&name, 2) {
        return Err(format!(
            "fn verify(p): nominal '{name}' names no fn {name}(p, angle_deg) in the script"
        ));
    }
    let mut at = request.angles_deg();
    at.push(360.0);
    let by = format!("{}: fn {name}(p, angle_deg)", script.file);
    let got = script
        .call(
            &name,
            (params.clone(), Dynamic::from(Floats::new(at.clone()))),
        )
        .map_err(|e| e.to_string())?;
    let radius = crate::binding::floats::numbers(&got, &by).map_err(|e| e.to_string())?;
    if radius.len() != at.len() || radius.iter().any(|r| !(r.is_finite() && *r > 0.0)) {
        return Err(format!(
            "{by}: must return a radius above 0 (mm) at each of the {} angles it is given, not {} values",
            at.len(),
            radius.len()
        ));
    }
    Profile::new(at, radius.to_vec()).map_err(|e| format!("{by}: {e}"))
}

/// The part the finish leaves ([`PREDICTED`]): the last cutting pass's
/// radius less the `nominal` at each of the replay's angles (`angle_deg`,
/// `dr_mm`), and at 360 deg the turn closed.
fn polar_predicted(
    part: &PolarPart,
    nominal: &Profile,
) -> Result<BTreeMap<String, Vec<f64>>, VerifyError> {
    let Some(finish) = part.passes.iter().rev().find(|p| p.cuts) else {
        return Ok(BTreeMap::new());
    };
    let mut at = part.angle_deg.clone();
    let mut radius = finish.radius.clone();
    if let Some(&first) = radius.first() {
        at.push(360.0);
        radius.push(first);
    }
    let want = nominal.eval_many(&at)?;
    let dr = radius.iter().zip(&want).map(|(r, w)| r - w).collect();
    Ok(BTreeMap::from([
        ("angle_deg".to_owned(), at),
        ("dr_mm".to_owned(), dr),
    ]))
}

/// The radius-over-angle replay as whole columns: `angle_deg`,
/// `radius_mm` and `block` (the block from 0 that last cut at each angle,
/// -1 where none did).
fn polar_replayed(part: &PolarPart, request: &PolarRequest) -> Replayed {
    Replayed {
        what: format!(
            "the radius over angle at z = {} mm, {} angles",
            request.z, request.angles
        ),
        sampling_change: part.sampling_change,
        passes: part
            .passes
            .iter()
            .map(|p| ReplayedPass {
                name: p.name.clone(),
                blocks: p.blocks.clone(),
                cuts: p.cuts,
                columns: [
                    ("angle_deg".to_owned(), part.angle_deg.clone()),
                    ("radius_mm".to_owned(), p.radius.clone()),
                    (
                        "block".to_owned(),
                        p.block
                            .iter()
                            .map(|b| b.map_or(-1.0, |b| b as f64))
                            .collect(),
                    ),
                ]
                .into(),
            })
            .collect(),
    }
}

impl ScriptRequest {
    /// The script's judgement of `part`: `fn judge(p, part)` called once.
    fn judge(&self, part: &Replayed, blocks: usize) -> Result<Judged, VerifyError> {
        let passes: Array = part
            .passes
            .iter()
            .map(|p| {
                let mut m = Map::new();
                m.insert("name".into(), p.name.clone().into());
                m.insert(
                    "first_block".into(),
                    Dynamic::from_int(p.blocks.start as i64),
                );
                m.insert(
                    "last_block".into(),
                    Dynamic::from_int(p.blocks.end as i64 - 1),
                );
                m.insert("cuts".into(), p.cuts.into());
                for (k, v) in &p.columns {
                    m.insert(k.as_str().into(), Dynamic::from(Floats::new(v.clone())));
                }
                Dynamic::from_map(m)
            })
            .collect();
        let mut arg = Map::new();
        arg.insert("passes".into(), Dynamic::from_array(passes));
        arg.insert("what".into(), part.what.clone().into());
        arg.insert(
            "sampling_change_mm".into(),
            Dynamic::from_float(part.sampling_change),
        );
        let by = format!("{}: fn {}(p, part)", self.script.file, self.judge);
        let got = self
            .script
            .call(&self.judge, (self.params.clone(), arg))
            .map_err(|e| VerifyError::Contract(e.to_string()))?;
        let bad = |m: String| VerifyError::Contract(format!("{by}: {m}"));
        let m = got
            .try_cast::<Map>()
            .ok_or_else(|| bad("must return #{ figures, findings, tables }".into()))?;
        if let Some(k) = m.keys().find(|k| !RESULT_KEYS.contains(&k.as_str())) {
            return Err(bad(format!(
                "unknown key '{k}' in its result (keys: {})",
                RESULT_KEYS.join(", ")
            )));
        }
        let figures: Vec<JudgedFigure> = entries(m.get("figures"), "figures")
            .and_then(|a| a.iter().map(|f| figure(f, blocks)).collect())
            .map_err(bad)?;
        let findings: Vec<JudgedFinding> = entries(m.get("findings"), "findings")
            .and_then(|a| a.iter().map(|f| finding(f, blocks)).collect())
            .map_err(bad)?;
        let tables = tables(m.get("tables")).map_err(bad)?;
        if figures.is_empty() && findings.is_empty() {
            return Err(bad(
                "returned no figure and no finding: a judgement says something".into(),
            ));
        }
        Ok(Judged {
            by,
            replayed: part.what.clone(),
            sampling_change_mm: part.sampling_change,
            figures,
            findings,
            tables,
        })
    }
}

/// The array under `key` (none: empty).
fn entries(d: Option<&Dynamic>, key: &str) -> Result<Array, String> {
    match d {
        None => Ok(Array::new()),
        Some(d) => d
            .clone()
            .try_cast::<Array>()
            .ok_or_else(|| format!("{key} must be an array of maps")),
    }
}

/// A map entry of a judge's result, its keys checked against `keys`.
fn entry_map(d: &Dynamic, what: &str, keys: &[&str]) -> Result<Map, String> {
    let m = d
        .clone()
        .try_cast::<Map>()
        .ok_or_else(|| format!("a {what} must be a map #{{ {} }}", keys.join(", ")))?;
    if let Some(k) = m.keys().find(|k| !keys.contains(&k.as_str())) {
        return Err(format!(
            "unknown key '{k}' in a {what} (keys: {})",
            keys.join(", ")
        ));
    }
    Ok(m)
}

/// The text under `k`, checked as every text from outside is where it
/// enters ([`crate::names::check_text`]): it reaches the terminal, the
/// report and the page.
fn text(m: &Map, k: &str, what: &str) -> Result<String, String> {
    let t = m
        .get(k)
        .and_then(|v| v.clone().into_string().ok())
        .ok_or_else(|| format!("a {what}'s {k} must be text"))?;
    crate::names::check_text(&format!("a {what}'s {k}"), &t).map_err(|e| e.to_string())?;
    Ok(t)
}

/// The block (from 0) under `block`, if any, within the program's
/// `blocks`.
fn block(m: &Map, what: &str, blocks: usize) -> Result<Option<usize>, String> {
    let Some(v) = m.get("block") else {
        return Ok(None);
    };
    let b = number(v).ok_or_else(|| format!("a {what}'s block must be a number"))?;
    if b < 0.0 {
        return Ok(None);
    }
    if b.fract() != 0.0 || b >= blocks as f64 {
        return Err(format!(
            "a {what}'s block {b} is not one of the program's blocks (0 to {})",
            blocks.saturating_sub(1)
        ));
    }
    Ok(Some(b as usize))
}

/// A figure of a judge's result.
fn figure(d: &Dynamic, blocks: usize) -> Result<JudgedFigure, String> {
    let m = entry_map(d, "figure", &FIGURE_KEYS)?;
    let num = |k: &str| {
        m.get(k)
            .and_then(number)
            .ok_or_else(|| format!("a figure's {k} must be a number"))
    };
    let tolerance = num("tolerance")?;
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(format!(
            "a figure's tolerance must be positive, not {tolerance}"
        ));
    }
    Ok(JudgedFigure {
        name: text(&m, "name", "figure")?,
        value: num("value")?,
        tolerance,
        unit: text(&m, "unit", "figure")?,
        place: match m.get("place") {
            None => String::new(),
            Some(_) => text(&m, "place", "figure")?,
        },
        block: block(&m, "figure", blocks)?,
    })
}

/// A finding of a judge's result.
fn finding(d: &Dynamic, blocks: usize) -> Result<JudgedFinding, String> {
    let m = entry_map(d, "finding", &FINDING_KEYS)?;
    Ok(JudgedFinding {
        rule: text(&m, "rule", "finding")?,
        message: text(&m, "message", "finding")?,
        block: block(&m, "finding", blocks)?,
    })
}

/// The tables of a judge's result: a map of names to maps of columns.
fn tables(d: Option<&Dynamic>) -> Result<Tables, String> {
    let Some(d) = d else {
        return Ok(Tables::new());
    };
    let m = d
        .clone()
        .try_cast::<Map>()
        .ok_or("tables must be a map of names to maps of columns")?;
    m.into_iter()
        .map(|(name, cols)| {
            if !crate::files::is_plain_name(&name) {
                return Err(format!(
                    "table '{name}' must be a plain name (letters, digits, _ and -)"
                ));
            }
            let cols = cols
                .try_cast::<Map>()
                .ok_or_else(|| format!("table '{name}' must be a map of columns"))?;
            let cols = cols
                .into_iter()
                .map(|(c, v)| {
                    crate::names::check_name("a table's column", &c)
                        .map_err(|e| format!("table '{name}': {e}"))?;
                    crate::binding::floats::numbers(&v, &c)
                        .map(|v| (c.to_string(), v.to_vec()))
                        .map_err(|e| format!("table '{name}': {e}"))
                })
                .collect::<Result<_, _>>()?;
            Ok((name.to_string(), cols))
        })
        .collect()
}
