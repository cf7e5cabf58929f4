//! The machine's bodies checked for collisions along the whole program:
//! the tool, the bodies the machine describes (a guard, a wheelhead, a
//! steady rest's arm, a chuck, a tailstock) and the part, each placed by
//! its chain at every sample of every move as the control interpolates it
//! (the axes in straight lines from one block's end to the next), and the
//! distance of every pair that must not touch measured with parry's
//! queries (GJK on convex shapes, a bounding-volume tree on the part's
//! mesh).
//!
//! **Which pairs.** Two bodies are checked when the program can move one
//! relative to the other: when the axes that move them differ. So a guard
//! and its wheel (both moved by the wheel's axes), a rest's roller and its
//! arm, a chuck and the part it holds (moved by none) are not; the wheel
//! and the rest's arm, the guard and the part, the cutter and the chuck
//! are. Two pairs touch by design and are left to other checks: the tool
//! and the part (the family's verification measures the cut), and a body
//! that rides the part (a steady rest's roller, which has an approach feed:
//! the process checks keep it on the surface).
//!
//! **The part** is taken at its largest: the part body of the greatest
//! volume (the blank where the family gives one), as its envelope of
//! revolution about its axis (a stack of cylinders as wide as the mesh,
//! rings where the axis lies outside it, as in a nut's bore, when the
//! tool cuts inside a bore:
//! [`shapes::envelope`]). A clearance to it is smaller than to the part at
//! that moment by at most the stock, the groove or thread not yet cut, and
//! twice the mesh tolerance.
//!
//! **Along the moves.** Each move is cut into pieces that turn any body by
//! at most [`MAX_TURN`], so that a piece's ends bound how far each body's
//! farthest point moves over it (its shift and its turn at its reach, to
//! first order). How far a pair may have closed over a piece is the two
//! bodies' motions together, or, if less, the motion of one in the
//! other's frame; where that other is a solid of revolution (a cylinder,
//! the part's envelope, a wheel), with its turn about its own axis taken
//! out, since turning a body about its axis of revolution changes no
//! distance to it. So a wheel and its guard riding round a roll, its
//! arbor and its collars (the caliber's A axis) close only by what the
//! turn leaves: the default caliber's pairs are measured 3,800 times
//! rather than 154,000. A pair is measured again before the two can have
//! closed [`REMEASURE`] of the distance measured last, or [`STEP`] mm,
//! never all of it: so no contact is missed, and between measurements the
//! pair stayed at least 75 % of the last distance less one step. Inside a
//! piece, a pair is measured at places at most [`STEP`] mm of motion
//! apart. The least the distance can have been between measurements (the
//! last measured less how far the two may have closed since) is each
//! pair's `at_least_mm`.
//!
//! **The smallest clearance** of each pair is then sought again over the
//! moves either side of where the sweep found it, coarse to fine: places
//! across the move at most 4 mm of the two bodies' motion apart, then the
//! span about the nearest cut again until places stand [`FINE`] mm apart.
//! The one reported is within half of that of the nearest the two come
//! there (a smooth minimum much closer), unless two separate near places
//! within one move lie closer than the coarse spacing and the farther is
//! followed; it is not the sweep's nearest sample.
//!
//! Written here rather than taken whole from a library: the pairs, the
//! sampling and the kinematic placement are the kernel's own (its chains
//! and its programs); the geometric queries are parry's.

pub mod place;
pub mod shapes;

pub use place::{Holding, PlacedBody, Placement};

use crate::machine::MachineInfo;
use crate::math::{Mat4, Real};
use crate::mesh::TriMesh;
use crate::program::{axis_rows, block_name, AxisProgram};
use crate::tool::Tool;
use crate::verdict::Finding;
use serde::{Deserialize, Serialize};
use shapes::Shaped;

/// The rule a collision breaks.
pub const COLLISION: &str = "bodies clear of each other";

/// The most any body moves between two samples of a move (mm).
pub const STEP: Real = 1.0;

/// The most any body turns between two samples of a move (rad).
pub const MAX_TURN: Real = 0.02;

/// The most samples of one move: a move longer than `STEP * MAX_SAMPLES`
/// is sampled coarser, and the report's largest step says so.
pub const MAX_SAMPLES: usize = 20_000;

/// Share of the last distance two bodies may close before it is measured
/// again.
pub const REMEASURE: Real = 0.25;

/// The motion (mm, the two bodies' together) between the places each
/// pair is measured again over the moves on both sides of its smallest
/// clearance: so the smallest reported is within half of it of the
/// nearest the two come there.
pub const FINE: Real = 0.02;

/// The most places across a move where one pair's smallest clearance is
/// sought first (a move turning more is sought coarser than
/// [`MAX_TURN`]).
pub const MAX_FINE: usize = 4000;

/// The solids the run gives the check besides the machine's bodies.
#[derive(Debug, Clone, Copy)]
pub struct Solids<'a> {
    /// The tool: its name, itself, and its mesh in its own frame (the
    /// machine's tool frame) if it has one.
    pub tool: Option<(&'a str, &'a Tool, Option<&'a TriMesh>)>,
    /// The part at its largest: its name and mesh in the part frame.
    pub part: Option<(&'a str, &'a TriMesh)>,
    /// The meshes' chordal tolerance (mm): the part's envelope is as much
    /// wider.
    pub tolerance: Real,
    /// The family's parameters that restate a machine constant, as
    /// (constant, parameter): a collision names them beside the constants.
    pub restated: &'a [(String, String)],
}

/// The smallest clearance of one pair along the program.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Clearance {
    /// The two bodies.
    pub bodies: [String; 2],
    /// The smallest distance measured between them (mm; 0 where they
    /// touch or overlap).
    pub clearance_mm: Real,
    /// The least the distance can have been anywhere along the program
    /// (mm): between two places a pair is measured, the two close at most
    /// as far as their motion, which the sweep bounds (0 in a report
    /// written before it was).
    #[serde(default)]
    pub at_least_mm: Real,
    /// The block where it is, as the program numbers it.
    pub block: String,
    /// That block's index (from 1).
    pub block_index: usize,
}

/// What the collision check found (in `report.json` as `collisions`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Collisions {
    /// Every pair checked, with its smallest clearance, in the order the
    /// bodies are declared (the tool, the machine's bodies, the part).
    pub clearances: Vec<Clearance>,
    /// A collision of each pair that has one, at its first block (the
    /// report's verdict carries them).
    #[serde(skip)]
    pub findings: Vec<Finding>,
    /// The most any body moves between two places where a pair is
    /// measured (mm).
    pub step_mm: Real,
    /// How much wider than the part its envelope is, at most (mm).
    pub part_envelope_mm: Real,
    /// Places along the program the bodies were put at.
    pub samples: usize,
    /// Distance queries made.
    pub queries: usize,
    /// Bodies left out, and why.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

/// Why the check could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CollisionError {
    /// The machine's description failed to compile (it did when loaded).
    #[error("the collision check: {0}")]
    Machine(#[from] crate::machine::MachineError),
    /// A body's shape whose sizes its machine's constants do not give.
    #[error("the collision check: {0}")]
    Body(#[from] crate::machine::BodyError),
    /// A chain that cannot be placed at a block's axis values.
    #[error("the collision check: {0}")]
    Chain(#[from] crate::transform::TransformError),
    /// The program lacks an axis a chain needs.
    #[error("the collision check: {0}")]
    Program(#[from] crate::program::ProgramFault),
    /// The check ran past the run's time budget.
    #[error(transparent)]
    OverTime(#[from] crate::budget::OverTime),
    /// A tool's own size of a body riding with it that no such body has.
    #[error("tool '{tool}' gives the machine's constant '{constant}', which sizes no body riding with it alone (it may give: {allowed})")]
    ToolSizes {
        /// The tool.
        tool: String,
        /// The constant named.
        constant: String,
        /// The constants it may give.
        allowed: String,
    },
}

/// Which solid an entity of the check is.
#[derive(Debug, Clone, Copy)]
enum Which {
    /// The tool, on the tool frame.
    Tool,
    /// The placement's body of this index.
    Body(usize),
    /// The part, on the part frame.
    Part,
}

#[derive(Debug, Clone)]
struct Entity {
    name: String,
    shaped: Shaped,
    reach: Real,
    /// How far the shape reaches from its own frame's origin (mm).
    own_reach: Real,
    which: Which,
    /// The axes that move it, sorted.
    moved_by: Vec<String>,
    /// It cuts the part (the tool) or rides it (a steady rest's roller).
    touches_part: bool,
    is_part: bool,
    /// The machine constants that place and size it.
    constants: Vec<String>,
    /// The end of the part it stands at, and that end's z.
    held_at: Option<(&'static str, Real)>,
}

/// What would resolve a collision of the two bodies: the constants that
/// place and size each (with the family's parameters that restate them),
/// where the part is held, the program's positions.
fn resolved_by(pair: [&Entity; 2], restated: &[(String, String)]) -> String {
    let named = |c: &String| match restated.iter().find(|(k, _)| k == c) {
        Some((_, p)) => format!("{c} (the family's {p})"),
        None => c.clone(),
    };
    let mut ways: Vec<String> = pair
        .iter()
        .filter(|e| !e.constants.is_empty())
        .map(|e| {
            let list: Vec<String> = e.constants.iter().map(named).collect();
            format!("the {}'s constants {}", e.name, list.join(", "))
        })
        .collect();
    for (end, z) in pair.iter().filter_map(|e| e.held_at) {
        ways.push(format!(
            "where the family's part {end}s (z = {} mm: the {} stands there)",
            crate::math::fixed(z, 3),
            if end == "start" {
                "chuck's grip"
            } else {
                "tailstock"
            }
        ));
    }
    if pair.iter().any(|e| e.is_part) {
        ways.push("the part's length or where the family puts its ends".into());
    }
    let last = "the program's positions";
    if ways.is_empty() {
        format!("change {last}")
    } else {
        format!("change {} or {last}", ways.join(", "))
    }
}

/// The part at its largest: of `parts`, the body of the greatest volume
/// (the blank where the family gives one).
pub fn part_at_largest(parts: &[(String, TriMesh)]) -> Option<(&str, &TriMesh)> {
    parts
        .iter()
        .max_by(|a, b| a.1.volume().total_cmp(&b.1.volume()))
        .map(|(n, m)| (n.as_str(), m))
}

/// Where a part's solid begins and ends along its axis (the part frame's
/// Z): where bodies on its ends stand.
pub fn part_z(mesh: &TriMesh) -> (Real, Real) {
    let (lo, hi) = mesh.bounds();
    (lo[2], hi[2])
}

/// One pair's record along the program.
#[derive(Debug, Clone)]
struct PairState {
    /// The smallest distance measured, and its block (from 0).
    min: Real,
    min_block: usize,
    /// The first block where the two touch.
    hit: Option<usize>,
    /// The least the distance can have been since the start.
    floor: Real,
    /// The distance measured last, and how far the two may have closed
    /// since (infinite before the first measurement).
    last: Real,
    closed: Real,
}

impl PairState {
    fn new() -> Self {
        Self {
            min: Real::INFINITY,
            min_block: 0,
            hit: None,
            floor: Real::INFINITY,
            last: 0.0,
            closed: Real::INFINITY,
        }
    }

    /// How far the two may close before they are measured again: a share
    /// of the last distance, or a step, never all of it.
    fn threshold(&self) -> Real {
        self.last.min((REMEASURE * self.last).max(STEP))
    }

    /// The least the distance can have been since the last measurement.
    fn closed_floor(&self) -> Real {
        if self.closed.is_finite() {
            self.last - self.closed
        } else {
            Real::INFINITY
        }
    }

    fn record(&mut self, d: Real, block: usize) {
        self.floor = self.floor.min(self.closed_floor()).min(d);
        self.last = d;
        self.closed = 0.0;
        if d < self.min {
            self.min = d;
            self.min_block = block;
        }
        if d <= 0.0 && self.hit.is_none() {
            self.hit = Some(block);
        }
    }
}

/// The largest distance a point of a body of `reach` moves between the
/// frames `a` and `b`, to first order in the turn; and the turn (rad).
fn motion(a: &Mat4, b: &Mat4, reach: Real) -> (Real, Real) {
    let ra = a.fixed_view::<3, 3>(0, 0);
    let rb = b.fixed_view::<3, 3>(0, 0);
    let cos = (((ra.transpose() * rb).trace() - 1.0) / 2.0).clamp(-1.0, 1.0);
    let turn = cos.acos();
    let shift = (b.fixed_view::<3, 1>(0, 3) - a.fixed_view::<3, 1>(0, 3)).norm();
    (shift + turn * reach, turn)
}

/// The inverse of a rigid motion.
fn rigid_inverse(m: &Mat4) -> Mat4 {
    let r = m.fixed_view::<3, 3>(0, 0).transpose();
    let t = -(r * m.fixed_view::<3, 1>(0, 3));
    let mut out = Mat4::identity();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
    out.fixed_view_mut::<3, 1>(0, 3).copy_from(&t);
    out
}

/// How one body of a pair stands toward the other, for how far the two
/// may have closed: the pair's `mover` (an entity) in the frame of its
/// `other`, and, where the other is a solid of revolution about `axis`,
/// turned back about that axis until the mover's origin lies on the
/// axis's plane with the other's first perpendicular. Turning a body
/// about its axis of revolution changes no distance to it, so a wheel
/// riding round a roll (with its arbor and collars) moves, for the pair,
/// only by what its turn leaves: the bound on closing does not count the
/// turn, which for a body far from the axis is most of its motion.
#[derive(Debug, Clone, Copy)]
struct Facing {
    mover: usize,
    other: usize,
    /// The other's axis of revolution and two perpendiculars of it, the
    /// second the first turned by 90 deg about it.
    axis: Option<[crate::math::Vec3; 3]>,
}

impl Facing {
    /// The pair `(i, j)`'s facing: toward the one that is a solid of
    /// revolution, the one fewer axes move where both are (a body on the
    /// part, which the part's frame holds still), else `i` in `j`'s frame.
    fn of((i, j): (usize, usize), entities: &[Entity]) -> Self {
        let (a, b) = (&entities[i], &entities[j]);
        let (mover, other) = match (a.shaped.axis, b.shaped.axis) {
            (Some(_), Some(_)) if a.moved_by.len() < b.moved_by.len() => (j, i),
            (Some(_), None) => (j, i),
            _ => (i, j),
        };
        let axis = entities[other].shaped.axis.map(|a| {
            let a = a.normalize();
            let e1 = if a.x.abs() < 0.9 {
                crate::math::Vec3::x()
            } else {
                crate::math::Vec3::y()
            };
            let e1 = (e1 - a * a.dot(&e1)).normalize();
            [a, e1, a.cross(&e1)]
        });
        Self { mover, other, axis }
    }

    /// The mover's frame as the pair sees it, the entities at `frames`.
    fn placed(&self, frames: &[Mat4]) -> Mat4 {
        let rel = rigid_inverse(&frames[self.other]) * frames[self.mover];
        let Some([a, e1, e2]) = self.axis else {
            return rel;
        };
        let o = rel.fixed_view::<3, 1>(0, 3).into_owned();
        let across = o - a * a.dot(&o);
        let rho = across.norm();
        if rho < crate::tolerance::SAME_LENGTH {
            return rel;
        }
        // The origin's angle phi about the axis, turned back by Rodrigues'
        // formula (cos and sin of -phi from the origin itself).
        let (c, s) = (across.dot(&e1) / rho, -across.dot(&e2) / rho);
        let k = crate::math::Mat3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0);
        let turn = crate::math::Mat3::identity() * c + k * s + (a * a.transpose()) * (1.0 - c);
        let mut back = Mat4::identity();
        back.fixed_view_mut::<3, 3>(0, 0).copy_from(&turn);
        back * rel
    }
}

/// Checks `program` (as the control reads it) on the machine `info`
/// describes, its bodies placed by `placement` (the one the scene shows),
/// for collisions between its bodies, the tool and the part: see the
/// [module docs](self).
///
/// # Failures
/// A program without an axis a chain needs, the time budget.
pub fn check(
    program: &AxisProgram,
    info: &MachineInfo,
    placement: &Placement,
    solids: Solids<'_>,
) -> Result<Collisions, CollisionError> {
    let mut out = Collisions {
        step_mm: STEP,
        part_envelope_mm: 2.0 * solids.tolerance,
        ..Collisions::default()
    };
    out.notes.extend(placement.notes.iter().cloned());
    let mut entities: Vec<Entity> = Vec::new();
    let entity = |name: &str, shaped: Shaped, which, moved_by, touches_part, is_part| Entity {
        name: name.to_owned(),
        reach: shaped.reach(),
        own_reach: {
            let s = shaped.shape.compute_local_bounding_sphere();
            s.center.length() + s.radius
        },
        shaped,
        which,
        moved_by,
        touches_part,
        is_part,
        constants: Vec::new(),
        held_at: None,
    };
    match (solids.tool, placement.tool_axes()) {
        (Some((name, tool, mesh)), Some(axes)) => {
            match shapes::tool(tool, mesh, tool.spindle_centre()) {
                Some(shaped) => entities.push(Entity {
                    constants: pilgrim_plugin_abi::types::chain_constants(&info.chain),
                    ..entity(name, shaped, Which::Tool, axes, true, false)
                }),
                None => out
                    .notes
                    .push(format!("the {name} has no solid: not checked")),
            }
        }
        (Some((name, ..)), None) => out.notes.push(format!(
            "the {name} is not checked: the machine states no tool chain to place it"
        )),
        (None, _) => {}
    }
    for (i, b) in placement.bodies.iter().enumerate() {
        entities.push(Entity {
            constants: b.constants.clone(),
            held_at: b.held_at,
            ..entity(
                &b.name,
                shapes::solid(&b.solid),
                Which::Body(i),
                b.moved_by.clone(),
                b.rides,
                false,
            )
        });
    }
    if let Some((name, mesh)) = solids.part {
        // The bore counts where the tool cuts inside it.
        let bore = solids.tool.is_some_and(|(_, t, _)| t.cuts_inside());
        if let Some(shaped) = shapes::envelope(mesh, solids.tolerance, bore) {
            entities.push(entity(name, shaped, Which::Part, Vec::new(), false, true));
        }
    }
    let pairs: Vec<(usize, usize)> = (0..entities.len())
        .flat_map(|i| (i + 1..entities.len()).map(move |j| (i, j)))
        .filter(|&(i, j)| {
            let (a, b) = (&entities[i], &entities[j]);
            a.moved_by != b.moved_by
                && !((a.is_part && b.touches_part) || (b.is_part && a.touches_part))
        })
        .collect();
    if pairs.is_empty() || program.blocks.is_empty() {
        return Ok(out);
    }
    let n = program.blocks.len();
    let names = placement.axes();
    let w = names.len();
    let rows = axis_rows(program, info, names, 0..n)?;
    // Entity `e`'s frame at the axis values `q`, the tool's frame `tool`.
    let frame_of = |e: &Entity, q: &[Real], tool: &Mat4| -> Result<Mat4, CollisionError> {
        let f = match e.which {
            Which::Tool => *tool,
            Which::Body(i) => placement.body_frame(i, q, tool)?,
            Which::Part => Mat4::identity(),
        };
        Ok(f * e.shaped.local)
    };
    let frames = |q: &[Real]| -> Result<Vec<Mat4>, CollisionError> {
        let tool = placement.tool_frame(q)?;
        entities.iter().map(|e| frame_of(e, q, &tool)).collect()
    };
    let lerp = |a: &[Real], b: &[Real], t: Real| -> Vec<Real> {
        a.iter().zip(b).map(|(x, y)| x + (y - x) * t).collect()
    };
    let mut state: Vec<PairState> = pairs.iter().map(|_| PairState::new()).collect();
    let queries = std::cell::Cell::new(0usize);
    // The pair (i, j)'s distance, its bodies at the frames `fi`, `fj`.
    let distance = |(i, j): (usize, usize), fi: &Mat4, fj: &Mat4| -> Real {
        queries.set(queries.get() + 1);
        parry3d_f64::query::distance(
            &shapes::pose(fi),
            &*entities[i].shaped.shape,
            &shapes::pose(fj),
            &*entities[j].shaped.shape,
        )
        .map_or(0.0, |d| d.distance)
    };
    let measure = |(i, j): (usize, usize), f: &[Mat4], block: usize, s: &mut PairState| {
        s.record(distance((i, j), &f[i], &f[j]), block);
    };
    let mut before = frames(&rows[0..w])?;
    for (&pair, s) in pairs.iter().zip(state.iter_mut()) {
        measure(pair, &before, 0, s);
    }
    let facing: Vec<Facing> = pairs.iter().map(|&p| Facing::of(p, &entities)).collect();
    let mut held: Vec<Mat4> = facing.iter().map(|f| f.placed(&before)).collect();
    let mut samples = 1usize;
    let mut ticker = crate::budget::Ticker::new("the collision check", 64);
    for k in 1..n {
        let (a, b) = (&rows[(k - 1) * w..k * w], &rows[k * w..(k + 1) * w]);
        if a == b {
            continue;
        }
        let end = frames(b)?;
        samples += 1;
        // Pieces of the move that turn little, so that a piece's motion is
        // bounded by its ends to first order.
        let turn = entities
            .iter()
            .zip(before.iter().zip(&end))
            .map(|(e, (f0, f1))| motion(f0, f1, e.reach).1)
            .fold(0.0, Real::max);
        let pieces = ((turn / MAX_TURN).ceil() as usize).clamp(1, MAX_SAMPLES);
        let mut piece_end = Some(end);
        for p in 1..=pieces {
            ticker.tick()?;
            let (t0, t1) = ((p - 1) as Real / pieces as Real, p as Real / pieces as Real);
            let after = if p == pieces {
                piece_end.take().unwrap_or_default()
            } else {
                samples += 1;
                frames(&lerp(a, b, t1))?
            };
            let moved: Vec<Real> = entities
                .iter()
                .zip(before.iter().zip(&after))
                .map(|(e, (f0, f1))| motion(f0, f1, e.reach).0)
                .collect();
            // The piece cut into steps of at most STEP, their frames made
            // once for the pairs that need to be measured inside it.
            let steps = ((moved.iter().fold(0.0, |m: Real, v| m.max(*v)) / STEP).ceil() as usize)
                .clamp(1, MAX_SAMPLES);
            let mut inside: Vec<Option<Vec<Mat4>>> = vec![None; steps];
            for (((&(i, j), s), f), held) in pairs
                .iter()
                .zip(state.iter_mut())
                .zip(&facing)
                .zip(&mut held)
            {
                // The two bodies' motions together, or one's toward the
                // other, whichever is less (a facing whose turn is not
                // small is no longer bounded by its ends to first order).
                let mut closing = moved[i] + moved[j];
                let now = f.placed(&after);
                let (toward, turn) = motion(held, &now, entities[f.mover].own_reach);
                *held = now;
                if turn <= 2.0 * MAX_TURN {
                    closing = closing.min(toward);
                }
                if s.closed + closing < s.threshold() {
                    s.closed += closing;
                    continue;
                }
                // The two cannot touch within the piece: measured at its end.
                if s.closed + closing < s.last {
                    measure((i, j), &after, k, s);
                    continue;
                }
                for (m, slot) in inside.iter_mut().enumerate() {
                    s.closed += closing / steps as Real;
                    if s.closed < s.threshold() {
                        continue;
                    }
                    let f = match slot {
                        Some(f) => f,
                        None if m + 1 == steps => &after,
                        None => {
                            samples += 1;
                            let t = t0 + (t1 - t0) * (m + 1) as Real / steps as Real;
                            slot.insert(frames(&lerp(a, b, t))?)
                        }
                    };
                    measure((i, j), f, k, s);
                }
            }
            before = after;
        }
    }
    // Each pair's smallest clearance sought over the moves on both sides
    // of where the sweep found it, every FINE of the two's motion.
    for (&(i, j), s) in pairs.iter().zip(state.iter_mut()) {
        s.floor = s.floor.min(s.closed_floor());
        if s.hit.is_some() {
            continue;
        }
        let found = s.min_block;
        for k in [found, found + 1] {
            if k == 0 || k >= n {
                continue;
            }
            let (a, b) = (&rows[(k - 1) * w..k * w], &rows[k * w..(k + 1) * w]);
            if a == b {
                continue;
            }
            ticker.tick()?;
            let (f0, f1) = (frames(a)?, frames(b)?);
            let (moved_i, turn_i) = motion(&f0[i], &f1[i], entities[i].reach);
            let (moved_j, turn_j) = motion(&f0[j], &f1[j], entities[j].reach);
            // Coarse to fine: places across the move (at least one every
            // 4 mm of motion, or per MAX_TURN of turn), then the span
            // about the nearest place cut again, until places stand at
            // most FINE apart.
            let moved = moved_i + moved_j;
            let mut places = ((moved / (4.0 * STEP)).ceil() as usize)
                .clamp(16, 256)
                .max((turn_i.max(turn_j) / MAX_TURN).ceil() as usize)
                .min(MAX_FINE);
            let (mut lo, mut hi) = (0.0, 1.0);
            loop {
                let mut best = (Real::INFINITY, 0);
                for m in 0..=places {
                    samples += 1;
                    // The pair's two frames only.
                    let t = lo + (hi - lo) * m as Real / places as Real;
                    let q = lerp(a, b, t);
                    let tool = placement.tool_frame(&q)?;
                    let (fi, fj) = (
                        frame_of(&entities[i], &q, &tool)?,
                        frame_of(&entities[j], &q, &tool)?,
                    );
                    let d = distance((i, j), &fi, &fj);
                    if d < best.0 {
                        best = (d, m);
                    }
                }
                if best.0 < s.min {
                    s.min = best.0;
                    s.min_block = k;
                }
                let spacing = (hi - lo) / places as Real;
                if moved * spacing <= FINE {
                    break;
                }
                let m = best.1 as Real;
                (lo, hi) = (
                    (lo + spacing * (m - 1.0)).max(0.0),
                    (lo + spacing * (m + 1.0)).min(1.0),
                );
                places = 16;
            }
        }
    }
    out.samples = samples;
    out.queries = queries.get();
    for (&(i, j), s) in pairs.iter().zip(&state) {
        let bodies = [entities[i].name.clone(), entities[j].name.clone()];
        out.clearances.push(Clearance {
            bodies: bodies.clone(),
            clearance_mm: s.min.max(0.0),
            at_least_mm: s.floor.min(s.min).max(0.0),
            block: block_name(program, s.min_block),
            block_index: s.min_block + 1,
        });
        if let Some(k) = s.hit {
            let f = frames(&rows[k * w..(k + 1) * w])?;
            let depth = parry3d_f64::query::contact(
                &shapes::pose(&f[i]),
                &*entities[i].shaped.shape,
                &shapes::pose(&f[j]),
                &*entities[j].shaped.shape,
                0.0,
            )
            .ok()
            .flatten()
            .map_or(0.0, |c| (-c.dist).max(0.0));
            out.findings.push(
                Finding::new(
                    COLLISION,
                    format!(
                        "{}: the {} and the {} collide (they overlap by {} mm there); {}",
                        block_name(program, k),
                        bodies[0],
                        bodies[1],
                        crate::math::fixed(depth, 3),
                        resolved_by([&entities[i], &entities[j]], solids.restated)
                    ),
                )
                .at(k, block_name(program, k)),
            );
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::{ChainMachine, Machine, MachineKinematics};
    use crate::program::{Block, ProgramAxis};
    use crate::toolpath::Motion;

    /// One move of the lathe's X and Z (X on diameter) from `a` to `b`,
    /// after a rapid to `a`.
    fn one_move(a: [Real; 2], b: [Real; 2]) -> AxisProgram {
        let mut p = crate::program::test_program();
        p.axes = ["X", "Z"]
            .map(|n| ProgramAxis {
                name: n.into(),
                unit: "mm".into(),
            })
            .to_vec();
        let block = |v: [Real; 2]| Block {
            motion: Motion::Linear,
            values: v.to_vec(),
            feed: 500.0,
            spindle: None,
            comment: None,
            keep: Vec::new(),
            number: None,
            line: None,
            dwell_s: 0.0,
        };
        p.blocks = vec![block(a), block(b)];
        p
    }

    /// A body circling a solid of revolution about its axis never comes
    /// nearer it: a caliber grinder's roll turning a whole turn under the
    /// wheel's housing, the roll's arbor turning with it. The bound on how
    /// far the two may close counts only what the turn leaves (nothing
    /// here but the rounding of each block's turn), so the least the
    /// distance can have been is the distance itself; the two bodies' own
    /// motions, summed, would have allowed a quarter of it.
    #[test]
    fn a_turn_about_a_solid_of_revolution_closes_nothing() {
        let info = lz_250::describe();
        let axes: Vec<String> = ["A", "X", "Z", "B"].map(str::to_owned).to_vec();
        let placement =
            Placement::new(&info, &axes, &Holding::default(), Some((-40.0, 40.0))).unwrap();
        let mut program = one_move([0.0, 0.0], [0.0, 0.0]);
        program.axes = axes
            .iter()
            .map(|n| ProgramAxis {
                name: n.clone(),
                unit: if n == "A" || n == "B" { "deg" } else { "mm" }.into(),
            })
            .collect();
        // X 0, the wheel's centre 300 mm off the roll's axis, B 0: A from 0
        // to 360 deg in 1 deg blocks.
        program.blocks = (0..=360)
            .map(|a| Block {
                motion: Motion::Linear,
                values: vec![a as Real, 0.0, 300.0, 0.0],
                feed: 500.0,
                spindle: None,
                comment: None,
                keep: Vec::new(),
                number: None,
                line: None,
                dwell_s: 0.0,
            })
            .collect();
        let solids = Solids {
            tool: None,
            part: None,
            tolerance: 0.01,
            restated: &[],
        };
        let found = check(&program, &info, &placement, solids).unwrap();
        let c = found
            .clearances
            .iter()
            .find(|c| c.bodies.contains(&"housing".into()) && c.bodies.contains(&"arbor".into()))
            .unwrap();
        assert!(c.clearance_mm > 1.0, "{c:?}");
        assert!(
            (c.at_least_mm - c.clearance_mm).abs() < 1e-3,
            "the floor {} below the clearance {}",
            c.at_least_mm,
            c.clearance_mm
        );
    }

    /// The smallest clearance reported is where the bodies come closest,
    /// not only where the sweep happened to measure: a holder passing a
    /// chuck's edge on a slant, against the distance measured every
    /// micrometre of the move. And no place along the move is nearer than
    /// the floor the report states.
    #[test]
    fn the_smallest_clearance_is_found_between_the_sweeps_samples() {
        let machine = ChainMachine::new(Machine::from_info(fanuc_0i_tc::describe()).unwrap());
        let axes = ["X".to_owned(), "Z".to_owned()];
        let placement = Placement::new(
            machine.info(),
            &axes,
            &Holding::default(),
            Some((-100.0, 0.0)),
        )
        .unwrap();
        // The tool's tip from radius 100 at z = -300 to radius 130 at z = 0:
        // the holder's edge passes the chuck's rim (radius 100, from z =
        // -230 to -130) on a slant.
        let program = one_move([200.0, -300.0], [260.0, 0.0]);
        let solids = Solids {
            tool: None,
            part: None,
            tolerance: 0.01,
            restated: &[],
        };
        let found = check(&program, machine.info(), &placement, solids).unwrap();
        let pair = |c: &&Clearance| {
            c.bodies.contains(&"holder".to_owned()) && c.bodies.contains(&"chuck".to_owned())
        };
        let c = found.clearances.iter().find(pair).unwrap();
        let index = |name: &str| {
            placement
                .bodies
                .iter()
                .position(|b| b.name == name)
                .unwrap()
        };
        let (h, k) = (index("holder"), index("chuck"));
        let shape = |i: usize| shapes::solid(&placement.bodies[i].solid);
        let (sh, sk) = (shape(h), shape(k));
        let truth = (0..=340_000)
            .map(|m| {
                let t = m as Real / 340_000.0;
                let q = [200.0 + 60.0 * t, -300.0 + 300.0 * t];
                let tool = placement.tool_frame(&q).unwrap();
                let fh = placement.body_frame(h, &q, &tool).unwrap() * sh.local;
                let fk = placement.body_frame(k, &q, &tool).unwrap() * sk.local;
                parry3d_f64::query::distance(
                    &shapes::pose(&fh),
                    &*sh.shape,
                    &shapes::pose(&fk),
                    &*sk.shape,
                )
                .unwrap()
            })
            .fold(Real::INFINITY, |m: Real, d| m.min(d.distance));
        assert!(truth > 1.0 && truth < 50.0, "{truth}");
        assert!(
            (c.clearance_mm - truth).abs() < FINE / 2.0,
            "reported {} mm, the move comes to {truth} mm",
            c.clearance_mm
        );
        assert!(c.at_least_mm <= truth, "{} > {truth}", c.at_least_mm);
    }
}
