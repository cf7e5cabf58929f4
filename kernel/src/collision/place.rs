//! Where the machine's bodies stand for given axis values: the one
//! placement the collision check and the scene share. A body on the part
//! frame by its own chain; a body on the tool by the tool's chain, then
//! from the tool's spindle centre by its chain of constants; a body at one
//! of the part's ends from there.

use super::CollisionError;
use crate::machine::{bodies_of, Machine, MachineInfo, Mount, Solid};
use crate::math::{Mat4, Real, Vec3};
use crate::transform::Chain;
use std::collections::BTreeMap;

/// What places a body.
#[derive(Debug, Clone)]
pub(super) enum Carrier {
    /// The tool's chain, then this constant motion.
    Tool(Mat4),
    /// Its own chain, over these columns of the axis values.
    Chain(Chain, Vec<usize>),
    /// Nothing: it stands here in the part frame.
    Fixed(Mat4),
}

/// A body of the machine with a solid, and how it is placed.
#[derive(Debug, Clone)]
pub struct PlacedBody {
    /// Its name.
    pub name: String,
    /// Its solid, sizes resolved.
    pub solid: Solid,
    /// It rides the part (it has an approach feed: a steady rest).
    pub rides: bool,
    /// The axes that move it relative to the part, sorted.
    pub moved_by: Vec<String>,
    /// The machine constants that place and size it (a body on the tool:
    /// the tool chain's too), for a collision's message.
    pub constants: Vec<String>,
    /// For a body standing at an end of the part (a chuck, a tailstock):
    /// which end, and its z (mm).
    pub held_at: Option<(&'static str, Real)>,
    pub(super) carrier: Carrier,
}

/// The machine's bodies placed for axis values (a row over
/// [`Placement::axes`]).
#[derive(Debug, Clone)]
pub struct Placement {
    axes: Vec<String>,
    tool: Option<(Chain, Vec<usize>)>,
    /// The tool chain's factors that are the part's own turn (Rz of axes
    /// that turn the part, [`crate::machine::Axis::turns_part`], among the
    /// factors that commute with them at the chain's lead).
    part_turn: Vec<usize>,
    /// A spindle carries the part: it turns at the program's S.
    pub spindle_turns_part: bool,
    /// The bodies that have a solid and can be placed.
    pub bodies: Vec<PlacedBody>,
    /// Bodies left out, and why.
    pub notes: Vec<String>,
}

/// What the run's tool and part bring to the machine's bodies: where the
/// tool's spindle centre is, whether it cuts inside a bore, its own sizes
/// of the bodies that ride with it, whether the part's end is free.
#[derive(Debug, Clone, Default)]
pub struct Holding {
    /// The tool's spindle centre in the tool frame.
    pub tool_centre: Vec3,
    /// The tool cuts inside a bore: the bodies for such tools hold it.
    pub inside: bool,
    /// The tool's name, for a message about its sizes.
    pub tool: String,
    /// The tool's own sizes of the bodies riding with it
    /// ([`crate::tool::Tool::bodies`]).
    pub tool_bodies: BTreeMap<String, Real>,
    /// The part is held at its start alone: bodies at its end are away.
    pub free_end: bool,
}

impl Holding {
    /// What `tool` brings, and the part's end free where `free_end`.
    pub fn of(tool: &crate::tool::Tool, free_end: bool) -> Self {
        Self {
            tool_centre: tool.spindle_centre(),
            inside: tool.cuts_inside(),
            tool: tool.name.clone(),
            tool_bodies: tool.bodies.clone(),
            free_end,
        }
    }
}

impl Placement {
    /// The bodies of the machine `info` with a solid, for a program over
    /// `program_axes`, held as `holding` says (the bodies there for a
    /// tool that cuts inside a bore where it does, from outside otherwise:
    /// a body's `reach`; the tool's own sizes of the bodies riding with
    /// it in place of the machine's), the part's solids from `part_z.0`
    /// to `part_z.1` along its axis (none: bodies at its ends are left
    /// out).
    ///
    /// # Failures
    /// A description that does not compile (it did when loaded); a size
    /// the tool gives that is not one of the bodies riding with it.
    pub fn new(
        info: &MachineInfo,
        program_axes: &[String],
        holding: &Holding,
        part_z: Option<(Real, Real)>,
    ) -> Result<Self, CollisionError> {
        let held = with_tool_sizes(info, holding)?;
        let info: &MachineInfo = &held;
        let (tool_centre, inside) = (holding.tool_centre, holding.inside);
        let tool_chain = if info.chain.is_empty() {
            None
        } else {
            Some(Machine::from_info(info.clone())?.chain().clone())
        };
        let tool_axes: Vec<String> = tool_chain
            .as_ref()
            .map(|c| c.axis_names().to_vec())
            .unwrap_or_default();
        let mut used = tool_axes.clone();
        let mut bodies = Vec::new();
        let mut notes = Vec::new();
        for body in bodies_of(info)? {
            let spec = body.spec();
            let Some(shape) = &spec.shape else {
                continue;
            };
            if !spec.reach.holds(inside) {
                continue;
            }
            let solid = Solid::of(shape, &info.constants)?;
            let own = || {
                body.chain()
                    .matrix(&vec![0.0; body.chain().dof()])
                    .map_err(CollisionError::from)
            };
            let mut held_at = None;
            let (carrier, moved_by) = match spec.mount {
                Mount::Part => {
                    let names = body.chain().axis_names().to_vec();
                    if let Some(a) = names.iter().find(|a| !program_axes.contains(a)) {
                        notes.push(format!(
                            "body {}: the program does not drive its axis {a}: left out",
                            spec.name
                        ));
                        continue;
                    }
                    used.extend(names.iter().cloned());
                    (Carrier::Chain(body.chain().clone(), Vec::new()), names)
                }
                Mount::Tool => {
                    if tool_chain.is_none() {
                        notes.push(format!(
                            "body {}: the machine states no tool chain to carry it: left out",
                            spec.name
                        ));
                        continue;
                    }
                    (
                        Carrier::Tool(Mat4::new_translation(&tool_centre) * own()?),
                        tool_axes.clone(),
                    )
                }
                Mount::PartEnd if holding.free_end => {
                    notes.push(format!(
                        "body {}: the part is held at its start alone (its end free): away",
                        spec.name
                    ));
                    continue;
                }
                Mount::PartStart | Mount::PartEnd => {
                    let Some((lo, hi)) = part_z else {
                        notes.push(format!(
                            "body {} stands at the part's end, and the run has no part: left out",
                            spec.name
                        ));
                        continue;
                    };
                    let z = if spec.mount == Mount::PartStart {
                        lo
                    } else {
                        hi
                    };
                    held_at = Some((if z == lo { "start" } else { "end" }, z));
                    (
                        Carrier::Fixed(Mat4::new_translation(&Vec3::new(0.0, 0.0, z)) * own()?),
                        Vec::new(),
                    )
                }
            };
            let mut constants = spec.constants();
            if spec.mount == Mount::Tool {
                constants.extend(pilgrim_plugin_abi::types::chain_constants(&info.chain));
            }
            bodies.push(PlacedBody {
                name: spec.name.clone(),
                solid,
                rides: spec.approach_feed.is_some(),
                moved_by: sorted(&moved_by),
                constants,
                held_at,
                carrier,
            });
        }
        // The axis values every carrier reads, in the machine's order.
        let axes: Vec<String> = info
            .axes
            .iter()
            .filter(|a| used.contains(&a.name))
            .map(|a| a.name.clone())
            .collect();
        let col = |n: &String| axes.iter().position(|m| m == n).unwrap_or(0);
        for b in &mut bodies {
            if let Carrier::Chain(chain, cols) = &mut b.carrier {
                *cols = chain.axis_names().iter().map(col).collect();
            }
        }
        let tool = tool_chain.map(|c| {
            let cols = c.axis_names().iter().map(col).collect();
            (c, cols)
        });
        let part_turn = tool.as_ref().map_or_else(Vec::new, |(c, _)| {
            crate::machine::part_turn_factors(c, info)
        });
        let spindle_turns_part = info
            .axes
            .iter()
            .any(|a| a.kind == crate::machine::AxisKind::Spindle && a.turns_part);
        Ok(Self {
            axes,
            tool,
            part_turn,
            spindle_turns_part,
            bodies,
            notes,
        })
    }

    /// The axes a row of values gives, in order.
    pub fn axes(&self) -> &[String] {
        &self.axes
    }

    /// The axes that move the tool, sorted; `None` when the machine states
    /// no tool chain.
    pub fn tool_axes(&self) -> Option<Vec<String>> {
        self.tool.as_ref().map(|(c, _)| sorted(c.axis_names()))
    }

    /// The tool frame for the axis values `q` (identity without a chain).
    ///
    /// # Failures
    /// A value that is not finite.
    pub fn tool_frame(&self, q: &[Real]) -> Result<Mat4, CollisionError> {
        match &self.tool {
            Some((c, cols)) => {
                let tq: Vec<Real> = cols.iter().map(|&i| q[i]).collect();
                Ok(c.matrix(&tq)?)
            }
            None => Ok(Mat4::identity()),
        }
    }

    /// How far the machine's axes have turned the part about its axis
    /// (Z) at the axis values `q` (rad, right-handed, from where the part
    /// frame stands on the machine at zero): the inverse of the tool
    /// chain's leading turns of the part; 0 when none. The spindle's turn
    /// is not in `q` ([`Self::spindle_turns_part`]).
    pub fn part_turn(&self, q: &[Real]) -> Real {
        let Some((c, cols)) = &self.tool else {
            return 0.0;
        };
        self.part_turn
            .iter()
            .map(|&k| match c.factors()[k].value {
                crate::transform::FactorValue::Axis {
                    axis,
                    scale,
                    offset,
                } => -(scale * q[cols[axis]] + offset),
                crate::transform::FactorValue::Const(v) => -v,
            })
            .sum()
    }

    /// Body `i`'s frame in the part frame, the tool frame being `tool`.
    ///
    /// # Failures
    /// A value that is not finite.
    pub fn body_frame(&self, i: usize, q: &[Real], tool: &Mat4) -> Result<Mat4, CollisionError> {
        Ok(match &self.bodies[i].carrier {
            Carrier::Tool(m) => tool * m,
            Carrier::Chain(chain, cols) => {
                let bq: Vec<Real> = cols.iter().map(|&c| q[c]).collect();
                chain.matrix(&bq)?
            }
            Carrier::Fixed(m) => *m,
        })
    }
}

fn sorted(names: &[String]) -> Vec<String> {
    let mut v = names.to_vec();
    v.sort();
    v
}

/// The machine `info` with the tool's own sizes of the bodies riding with
/// it in place of the machine's constants of those names.
///
/// # Failures
/// A size named for a constant that no body riding with the tool (for
/// its reach) is sized or placed by, or that another body or the tool's
/// chain also reads: the message names the tool and the constants it may
/// give.
fn with_tool_sizes<'a>(
    info: &'a MachineInfo,
    holding: &Holding,
) -> Result<std::borrow::Cow<'a, MachineInfo>, CollisionError> {
    if holding.tool_bodies.is_empty() {
        return Ok(std::borrow::Cow::Borrowed(info));
    }
    let mut riding = std::collections::BTreeSet::new();
    let mut others = std::collections::BTreeSet::new();
    others.extend(pilgrim_plugin_abi::types::chain_constants(&info.chain));
    for body in &info.bodies {
        if body.mount == Mount::Tool && body.reach.holds(holding.inside) {
            riding.extend(body.constants());
        } else {
            others.extend(body.constants());
        }
    }
    let allowed: Vec<&String> = riding.difference(&others).collect();
    let mut held = info.clone();
    for (name, value) in &holding.tool_bodies {
        if !allowed.contains(&name) {
            return Err(CollisionError::ToolSizes {
                tool: holding.tool.clone(),
                constant: name.clone(),
                allowed: allowed
                    .iter()
                    .map(|s| s.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        }
        held.constants.insert(name.clone(), *value);
    }
    Ok(std::borrow::Cow::Owned(held))
}
