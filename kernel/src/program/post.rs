//! The post-processor: one writer, dialects as data.
//!
//! A [`Dialect`] is a small set of settings (block numbers, comment style,
//! motion words, decimals, header and footer templates) on the one shared
//! writer, [`post`]. The G-code dialects write modal words (a word only when
//! its value changes; the first block writes every axis); the APT-style CL
//! file (ISO 4343 flavour) writes `GOTO/` records with all of the machine's
//! coordinates. Numbers have fixed decimals and never read `-0.000`; the
//! output depends on nothing but the program (no dates), so the same
//! program gives the same bytes.
//!
//! | dialect | file | numbers | comments | motion |
//! |---|---|---|---|---|
//! | `sinumerik` (840D) | `.mpf`, `%_N_<NAME>_MPF` | `N1`.. before the moves, move `i` (from 0) is `N(10 + 10 i)` | `; text` | `G0 G1 G33 K<lead> SF=<start>` |
//! | `fanuc` (0i) | `.nc`, `%` `O<number>` ... `%` (number 0: a block to paste after the tool call) | none (5-digit N would overflow) | `(TEXT)` | `G00 G01 G32 F<lead> Q<start, 0.001 deg>` |
//! | `linuxcnc` | `.ngc`, `%` ... `%` | as Sinumerik | `(text)` | `G0 G1 G33 K<lead>`, `G76 P Z I J R K Q H` for a threading cycle's blocks |
//! | `cld` (APT) | `.cld` | none | `PPRINT/text` | `RAPID`, `FEDRAT/`, `GOTO/` |
//!
//! The machine's [`ProgramSetup`] becomes words of the dialect: the work
//! offset (`G54`..`G59`), the plane (`G17`..`G19`), radius or diameter
//! programming (`DIAMOF`/`DIAMON` on Sinumerik; a comment on Fanuc, where
//! it is a parameter of the control), coolant (`M8`/`M9`, `COOLNT/`).
//! Every block of the program is written, in order, with the number
//! [`super::block_label`] gives it: a block that moves nothing writes its
//! first axis again; an axis a block keeps ([`super::Block::keep`]) is not
//! written (it stays where it stands). The CL file carries every
//! coordinate of each record: a kept axis reads the value the approach
//! brings it to.

use super::{AxisProgram, Plane, ProgramSetup, Radial};
use crate::math::fixed;
use crate::toolpath::Motion;

/// What writes a program as text in a dialect: the kernel's shared writer
/// ([`SharedPost`]), or a machine plugin's own post-processor.
pub trait PostProcessor {
    /// The program's text in `dialect` (`sinumerik`, `fanuc`, `cld`).
    ///
    /// # Failures
    /// An unknown dialect; a block that cannot be written.
    fn post(&self, program: &AxisProgram, dialect: &str) -> Result<String, PostError>;
}

/// The kernel's shared writer with the dialects of [`DIALECTS`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SharedPost;

impl PostProcessor for SharedPost {
    fn post(&self, program: &AxisProgram, dialect: &str) -> Result<String, PostError> {
        post_by_name(program, dialect)
    }
}

/// How blocks are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// Word-address G-code, modal.
    GCode,
    /// APT-style CL records.
    Apt,
}

/// The settings of one output format. Templates may use `{NAME}`,
/// `{ONUM}` (four digits), `{MACHINE}`, `{TOOL}`, `{TOOL2}` (two digits),
/// `{TOOLNAME}`, `{S}` (rpm), `{VERSION}`, and the machine's setup:
/// `{SETUP}` (work offset, plane and radial words), `{COOLANT}` and
/// `{COOLANT_OFF}`. A line that fills to nothing is left out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dialect {
    /// The dialect's name, as `--control` and machine files say it.
    pub name: &'static str,
    /// The file extension.
    pub extension: &'static str,
    /// G-code or APT.
    pub style: Style,
    /// Text before and after a comment.
    pub comment: (&'static str, &'static str),
    /// Whether comments are upper-cased (Fanuc).
    pub upper_comments: bool,
    /// The first move's block number and the step, or `None` for no
    /// numbers. The preamble's blocks count `1, 2, ..` up to below the
    /// first; the footer's go on after the last move's.
    pub numbering: Option<(u64, u64)>,
    /// Lines before the program, unnumbered.
    pub header: &'static [&'static str],
    /// Blocks before the first move, numbered.
    pub preamble: &'static [&'static str],
    /// Blocks after the last move, numbered.
    pub footer: &'static [&'static str],
    /// Lines after the program, unnumbered.
    pub trailer: &'static [&'static str],
    /// Word of a rapid move.
    pub rapid: &'static str,
    /// Word of a linear move.
    pub linear: &'static str,
    /// Word of a thread move.
    pub thread: &'static str,
    /// Address of a thread's lead.
    pub lead: &'static str,
    /// Decimals of axis values (mm and degrees alike: 0.001).
    pub decimals: usize,
    /// Decimals of feeds.
    pub feed_decimals: usize,
    /// Decimals of leads.
    pub lead_decimals: usize,
    /// The words of radius and diameter programming, or `None` where the
    /// control sets it by a parameter: then a comment says which the
    /// program assumes.
    pub radial_words: Option<(&'static str, &'static str)>,
    /// Coolant on and off.
    pub coolant: (&'static str, &'static str),
    /// The instruction naming the axes the feed is the path of
    /// ([`ProgramSetup::feed_group`]: `FGROUP` on Sinumerik), or `None`.
    pub feed_group: Option<&'static str>,
    /// Whether every thread block writes its lead (LinuxCNC: `K` is not
    /// modal for G33) or only where it changes.
    pub lead_every_block: bool,
    /// How a thread block's start angle is written, or `None` where the
    /// control has no word for it (then a program with one is refused,
    /// and a multi-start thread shifts its starts along Z instead).
    pub thread_start: Option<ThreadStart>,
    /// The threading cycle the dialect writes for a run of blocks one
    /// makes ([`super::cycle`]), or `None`: the blocks are written one by
    /// one (as they are for a cycle of another form).
    pub thread_cycle: Option<WrittenCycle>,
    /// What the lint reads in a program of this dialect beyond the words
    /// above: the codes it writes, how the program names itself, the
    /// tool word's form.
    pub reading: Reading,
}

/// The quirks of a dialect a reader of its programs must know, as data:
/// a new control is a [`Dialect`] value, and the lint (`lint.rs`) holds no
/// control's name.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reading {
    /// The G codes the dialect writes; the lint refuses any other.
    pub g_codes: &'static [u32],
    /// The M codes it writes.
    pub m_codes: &'static [u32],
    /// The M code that ends a program (M30; LinuxCNC's M2).
    pub end_code: u32,
    /// How the program's first line names it, before and after the name
    /// (`%_N_` and `_MPF` on Sinumerik), if it does.
    pub name_line: Option<(&'static str, &'static str)>,
    /// Whether a whole program's second line is its number, `O` and four
    /// digits, which is not an ISO word (Fanuc).
    pub number_line: bool,
    /// Whether the tool word carries the offset's number after the tool's,
    /// two digits each (Fanuc's `T0303`).
    pub tool_and_offset: bool,
    /// The word selecting the tool's offset, written with the tool call
    /// and passed over by the reader (Sinumerik's `D1`), if any.
    pub offset_word: Option<char>,
    /// Whether a thread block needs constant spindle speed (G97) in force.
    pub thread_needs_constant_speed: bool,
    /// The G codes a program must state before its first move (units,
    /// absolute or incremental, the feed's mode, no cutter compensation):
    /// the reader never assumes the control's power-on state, which a
    /// machine's parameters set.
    pub setup_codes: &'static [u32],
    /// The G codes that select a work offset, the one in force at power-on
    /// first: the first a program selects is its part zero, a switch to
    /// another is refused.
    pub work_offsets: &'static [u32],
    /// The unit of an axis value written without a decimal point (Fanuc's
    /// least input increment, 0.001 mm, with decimal-point input off as the
    /// control leaves the factory), or `None`: a whole number of mm.
    pub least_input: Option<f64>,
    /// Addresses refused without their decimal point (Fanuc's F, which a
    /// parameter scales).
    pub point_needed: &'static str,
    /// Addresses refused with a decimal point (Fanuc's start angle Q, a
    /// whole number of 0.001 deg).
    pub no_point: &'static str,
    /// Whether the control reads a G or M code to its tenths (LinuxCNC:
    /// `G1.0` is G1, `G33.1` another code); elsewhere a code is a whole
    /// number and a point in it is refused (`G1.0` on Sinumerik).
    pub code_tenths: bool,
    /// The modal groups of G codes a machine may state in force at
    /// power-on ([`super::PowerOn`]), each group's codes as its manual
    /// lists them (whether or not the reader reads them): a machine states
    /// at most one of each.
    pub modal_groups: &'static [&'static [u32]],
    /// The G-code systems the reader follows, where the control has
    /// several (a Fanuc lathe's A; `&[]`: the control has none).
    pub systems: &'static [&'static str],
    /// What codes and addresses the reader refuses mean on this control
    /// (`G90` is a turning cycle on a Fanuc lathe in system A, absolute
    /// dimensions elsewhere; its `U` an incremental X), for the refusal to
    /// say: never another dialect's meaning.
    pub meanings: &'static [(&'static str, &'static str)],
    /// The G codes read in a program read as it stands beyond
    /// [`Reading::g_codes`] (a shop's cycles and arcs, which pilgrim does
    /// not write): a lint refuses them.
    pub read_g_codes: &'static [u32],
    /// How the dialect's `G76` threading cycle is read, if it has one.
    pub g76: Option<G76Form>,
    /// Whether `G92` is the simple threading cycle (Fanuc's system A).
    pub g92_thread: bool,
    /// The language a program read as it stands may be written in beyond
    /// plain blocks (variables, jumps, loops, subprograms), or `None`. A
    /// lint (a program pilgrim wrote) reads plain blocks only.
    pub macros: Option<MacroReading>,
    /// How a program read as it stands may give a circular move (G2, G3
    /// among [`Reading::read_g_codes`]), or `None`: the reader refuses arcs.
    pub arcs: Option<ArcReading>,
    /// The addresses a dwell (`G4`, in a block of its own) gives its time
    /// by, each with its unit, as the control's manual reads them; `&[]`:
    /// the reader refuses a dwell.
    pub dwell: &'static [(char, DwellUnit)],
    /// How the spindle's speed clamp under constant surface speed (`G96`,
    /// its `S` in m/min) is written, where the reader reads `G96`.
    pub speed_clamp: Option<SpeedClamp>,
}

/// How a dialect writes the clamp of the spindle's speed under constant
/// surface speed ([`Reading::speed_clamp`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpeedClamp {
    /// `G50 S` in a block of its own (Fanuc's, Haas's lathes; G50 with an
    /// axis, a coordinate system setting, refused).
    G50,
    /// `D` in the `G96` block (LinuxCNC).
    DWithG96,
    /// `LIMS=` (Sinumerik).
    Lims,
}

/// The unit of a dwell's address ([`Reading::dwell`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DwellUnit {
    /// Seconds (LinuxCNC's `P`, Sinumerik's `F`).
    Seconds,
    /// Milliseconds, a whole number without a decimal point (Fanuc's `P`:
    /// a point in it is refused).
    Milliseconds,
    /// Seconds with a decimal point, milliseconds (the least input
    /// increment, 0.001 s) without one (Fanuc's `X` and `U`, Haas's `P`).
    SecondsByPoint,
    /// Turns of the spindle at the speed in force (Sinumerik's `S`).
    Revolutions,
}

/// How a dialect's circular interpolation (G2 clockwise, G3
/// counter-clockwise, in the lathe's plane G18 of Z and X) is read: the
/// centre by I (along X, on radius) and K (along Z), each from the arc's
/// start, or by the words below ([`super::reader`]'s `arcs`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcReading {
    /// The word giving the arc's radius (Sinumerik's `CR=`: negative for
    /// an arc of more than a half turn), if the control reads one.
    pub radius: Option<&'static str>,
    /// The word giving the arc's opening angle in degrees (`AR=`), if any.
    pub angle: Option<&'static str>,
}

/// The threading cycle a dialect writes where a program's blocks are one's
/// moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WrittenCycle {
    /// LinuxCNC's one block `G76 P Z I J R K Q H` (the program's `cycles`).
    Linuxcnc,
    /// Fanuc's two blocks `G76 P(m)(r)(a) Q R` and `G76 X Z P Q F` (the
    /// program's `fanuc_cycles`).
    FanucTwoBlock,
}

/// The threading cycle dialect `d` writes for the run of blocks from `k`
/// of `program`, if one starts there: how many blocks it makes and its
/// blocks' text (Fanuc's the least input's whole numbers in `P` and `Q`:
/// a dialect of another increment writes the moves).
fn cycle_at(program: &AxisProgram, d: &Dialect, k: usize) -> Option<(usize, Vec<String>)> {
    match d.thread_cycle? {
        WrittenCycle::Linuxcnc => {
            let span = program.cycles.iter().find(|s| s.first == k)?;
            Some((
                span.count,
                vec![format!("G76 {}", super::cycle::words(&span.cycle))],
            ))
        }
        WrittenCycle::FanucTwoBlock => {
            let unit = 10f64.powi(-(super::cycle::FANUC_DECIMALS as i32));
            if d.reading.least_input != Some(unit) {
                return None;
            }
            let span = program.fanuc_cycles.iter().find(|s| s.first == k)?;
            Some((span.count, super::cycle::fanuc_blocks(&span.cycle).to_vec()))
        }
    }
}

/// The form of a dialect's `G76` threading cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum G76Form {
    /// LinuxCNC's one block `G76 P Z I J R K Q H` ([`super::cycle::expand`]).
    LinuxCnc,
    /// Fanuc's two blocks `G76 P(m)(r)(a) Q R` then `G76 X Z R P Q F`
    /// ([`super::cycle::expand_fanuc`]), by the control's rules.
    FanucTwoBlock(super::cycle::FanucRules),
    /// The one block `G76 X Z I K D A P F` of the Fanuc 10/11/15-T and
    /// Haas lathes, the same law ([`super::cycle::expand_fanuc`]): the
    /// least cut, the finishing allowance and the chamfer are the
    /// control's settings, which the machine states among its constants
    /// ([`ONE_BLOCK_SETTINGS`]).
    OneBlock,
}

/// The machine constants a one-block G76 takes from the control's
/// settings (Haas's settings 99, 86, 95 and 96), each with what it is.
pub const ONE_BLOCK_SETTINGS: [(&str, &str); 4] = [
    (
        "thread_min_cut",
        "the least depth a roughing pass adds (mm)",
    ),
    (
        "thread_finish_allowance",
        "the finishing pass's allowance (mm)",
    ),
    (
        "thread_chamfer_leads",
        "the pull-out's length at the thread's end, in leads",
    ),
    (
        "thread_chamfer_deg",
        "the pull-out's angle from the axis (deg)",
    ),
];

/// A control's macro language ([`super::macros`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MacroLanguage {
    /// Fanuc's custom macro B.
    Fanuc,
    /// LinuxCNC's rs274ngc.
    Rs274,
    /// Sinumerik's NC language.
    Sinumerik,
}

impl MacroLanguage {
    /// Its name in messages.
    pub fn name(self) -> &'static str {
        match self {
            Self::Fanuc => "Fanuc macro B",
            Self::Rs274 => "rs274ngc (LinuxCNC)",
            Self::Sinumerik => "Sinumerik",
        }
    }
}

/// How a dialect's macro language is read ([`super::macros`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MacroReading {
    /// The language.
    pub language: MacroLanguage,
    /// The files a call opens beside the program, tried in order: `{O}`
    /// is a called program's number in four digits (`M98 P12`: `0012`),
    /// `{N}` its number as written, `{NAME}` its name as the call writes
    /// it, `{name}` in lower case.
    pub files: &'static [&'static str],
    /// Whether a subprogram call's repetitions stand before the program's
    /// four digits in P (the 0i's `M98 P0041234`: O1234 four times);
    /// otherwise P is the program's number and L the repetitions.
    pub repeats_in_p: bool,
    /// The first line of a subprogram's file that names it, before and
    /// after the name (Sinumerik's `%_N_KONTUR_SPF`), if any.
    pub sub_name_line: Option<(&'static str, &'static str)>,
}

/// The word of a thread block's spindle start angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThreadStart {
    /// The address (`Q`, `SF=`).
    pub address: &'static str,
    /// Units per degree (Fanuc's Q counts 0.001 deg, no decimal point).
    pub scale: f64,
    /// Decimals written.
    pub decimals: usize,
    /// Whether the word stays in force (Sinumerik's SF) or holds for its
    /// block only (Fanuc's Q, 0 when absent).
    pub modal: bool,
}

/// Siemens Sinumerik 840D part program (`.MPF`).
pub const SINUMERIK: Dialect = Dialect {
    name: "sinumerik",
    extension: "mpf",
    style: Style::GCode,
    comment: ("; ", ""),
    upper_comments: false,
    numbering: Some((10, 10)),
    header: &[
        "%_N_{NAME}_MPF",
        ";$PATH=/_N_MPF_DIR",
        "; {NAME} for {MACHINE}, written by pilgrim {VERSION}",
        "; tool T{TOOL}: {TOOLNAME}",
    ],
    preamble: &[
        "G90 G94 G71",
        "{SETUP}",
        "T{TOOL} D1",
        "S{S} M3",
        "{COOLANT}",
    ],
    footer: &["{COOLANT_OFF}", "M5", "M30"],
    trailer: &[],
    rapid: "G0",
    linear: "G1",
    thread: "G33",
    lead: "K",
    decimals: 3,
    feed_decimals: 1,
    lead_decimals: 4,
    radial_words: Some(("DIAMOF", "DIAMON")),
    coolant: ("M8", "M9"),
    feed_group: Some("FGROUP"),
    lead_every_block: false,
    thread_start: Some(ThreadStart {
        address: "SF=",
        scale: 1.0,
        decimals: 3,
        modal: true,
    }),
    thread_cycle: None,
    reading: Reading {
        g_codes: &[0, 1, 17, 18, 19, 33, 54, 55, 56, 57, 58, 59, 71, 90, 94],
        m_codes: &[3, 5, 8, 9, 30],
        end_code: 30,
        name_line: Some(("%_N_", "_MPF")),
        number_line: false,
        tool_and_offset: false,
        offset_word: Some('D'),
        thread_needs_constant_speed: false,
        setup_codes: &[90, 94, 71],
        work_offsets: &[54, 55, 56, 57, 58, 59],
        least_input: None,
        point_needed: "",
        no_point: "",
        code_tenths: false,
        // G9 and G60, exact stop (the replay's path through every
        // block's end point): read as the verification models them.
        read_g_codes: &[2, 3, 4, 9, 60, 96, 97],
        g76: None,
        g92_thread: false,
        // Programming Manual, Fundamentals, "List of G functions": group 6
        // (plane), 7 (cutter radius compensation), 8 (settable work
        // offset, G500 none), 13 (inch/metric), 14 (absolute/incremental),
        // 15 (feed type).
        modal_groups: &[
            &[17, 18, 19],
            &[40, 41, 42],
            &[500, 54, 55, 56, 57, 58, 59],
            &[70, 71, 700, 710],
            &[90, 91],
            &[93, 94, 95, 96, 97],
        ],
        systems: &[],
        // Programming Manual, Fundamentals.
        meanings: &[
            ("G2", "circular interpolation clockwise"),
            ("G3", "circular interpolation counter-clockwise"),
            ("G4", "a dwell"),
            ("G70", "inch dimensions"),
            ("G91", "incremental dimensions"),
            ("G93", "inverse-time feed"),
            ("G95", "feed per revolution"),
            ("G96", "constant cutting speed"),
            ("G500", "the settable work offsets cancelled"),
            ("G41", "cutter radius compensation left"),
            ("G42", "cutter radius compensation right"),
            ("M0", "a programmed stop"),
            ("M4", "the spindle counter-clockwise"),
            ("M17", "the end of a subprogram"),
            (
                "G64",
                "continuous-path mode, its corners blended off the programmed points",
            ),
            (
                "G641",
                "continuous-path mode with smoothing by distance (ADIS)",
            ),
            (
                "G642",
                "continuous-path mode with smoothing within the axes' tolerances",
            ),
            (
                "G643",
                "continuous-path mode with smoothing within the block",
            ),
            (
                "G644",
                "continuous-path mode with smoothing by the axes' dynamics",
            ),
        ],
        macros: Some(MacroReading {
            language: MacroLanguage::Sinumerik,
            files: &[
                "{NAME}.SPF",
                "{NAME}.spf",
                "{name}.spf",
                "{NAME}.MPF",
                "{NAME}.mpf",
            ],
            repeats_in_p: false,
            sub_name_line: Some(("%_N_", "_SPF")),
        }),
        // Programming Manual, Fundamentals, "Circular interpolation": the
        // centre by I and K, the radius by CR=, the opening angle by AR=.
        arcs: Some(ArcReading {
            radius: Some("CR="),
            angle: Some("AR="),
        }),
        // Programming Manual, Fundamentals, "Dwell time (G4)": in seconds
        // by F, in turns of the master spindle by S, in a block of its own.
        dwell: &[('F', DwellUnit::Seconds), ('S', DwellUnit::Revolutions)],
        // "Constant cutting rate (G96/G961/G962, G97/G971/G972, G973,
        // LIMS, SCC)": S in m/min, LIMS= the upper speed limit.
        speed_clamp: Some(SpeedClamp::Lims),
    },
};

/// Fanuc 0i (lathe, G-code system A: absolute by axis address, feed per
/// minute). A program numbered 0 is the seed's block to paste after the
/// tool call (no `%`, no `O` number, no T word); a numbered one is a whole
/// program.
pub const FANUC: Dialect = Dialect {
    name: "fanuc",
    extension: "nc",
    style: Style::GCode,
    comment: ("(", ")"),
    upper_comments: true,
    numbering: None,
    header: &[
        "{WHOLE}%",
        "{WHOLE}O{ONUM} ({NAME})",
        "({MACHINE}, WRITTEN BY PILGRIM {VERSION})",
        "{BLOCK}(TO FOLLOW THE CALL OF TOOL T{TOOL2}: {TOOLNAME})",
        "{WHOLE}(TOOL T{TOOL2}: {TOOLNAME})",
    ],
    preamble: &[
        "G21 G40 G97 G98",
        "{SETUP}",
        "{WHOLE}T{TOOL2}{TOOL2}",
        "S{S} M03",
        "{COOLANT}",
    ],
    footer: &["{COOLANT_OFF}", "M05", "M30"],
    trailer: &["{WHOLE}%"],
    rapid: "G00",
    linear: "G01",
    thread: "G32",
    lead: "F",
    decimals: 3,
    feed_decimals: 1,
    lead_decimals: 4,
    radial_words: None,
    coolant: ("M08", "M09"),
    feed_group: None,
    lead_every_block: false,
    thread_start: Some(ThreadStart {
        address: "Q",
        scale: 1000.0,
        decimals: 0,
        modal: false,
    }),
    thread_cycle: Some(WrittenCycle::FanucTwoBlock),
    reading: Reading {
        g_codes: &[
            0, 1, 18, 17, 19, 21, 32, 40, 54, 55, 56, 57, 58, 59, 76, 97, 98,
        ],
        m_codes: &[3, 5, 8, 9, 30],
        end_code: 30,
        name_line: None,
        number_line: true,
        tool_and_offset: true,
        offset_word: None,
        thread_needs_constant_speed: true,
        setup_codes: &[21, 40, 98],
        work_offsets: &[54, 55, 56, 57, 58, 59],
        least_input: Some(0.001),
        point_needed: "F",
        no_point: "Q",
        code_tenths: false,
        // Read in a shop's program: the simple threading cycle (0i-TC
        // Operator's Manual, "Threading cycle (G92)"); the multiple one
        // ("Multiple threading cycle (G76)") pilgrim writes too.
        read_g_codes: &[4, 50, 92, 96],
        g76: Some(G76Form::FanucTwoBlock(super::cycle::FanucRules {
            chamfer_deg: 45.0,
        })),
        g92_thread: true,
        // 0i-TC Operator's Manual, "G code list" (system A): group 16
        // (plane), 06 (inch/metric), 07 (tool nose radius compensation),
        // 14 (work coordinate system), 02 (constant surface speed), 05
        // (feed per minute/revolution). Systems B and C give G90..G99 other
        // meanings (absolute/incremental, G94/G95 feeds, return levels).
        modal_groups: &[
            &[17, 18, 19],
            &[20, 21],
            &[40, 41, 42],
            &[54, 55, 56, 57, 58, 59],
            &[96, 97],
            &[98, 99],
        ],
        systems: &["A"],
        // 0i-TC Operator's Manual, "G code list", system A.
        meanings: &[
            ("G2", "circular interpolation clockwise"),
            ("G3", "circular interpolation counter-clockwise"),
            ("G4", "a dwell"),
            ("G20", "inch input"),
            ("G41", "tool nose radius compensation left"),
            ("G42", "tool nose radius compensation right"),
            (
                "G50",
                "a coordinate system setting or the spindle's speed clamp",
            ),
            ("G70", "the finishing cycle"),
            ("G71", "the stock removal cycle in turning"),
            ("G72", "the stock removal cycle in facing"),
            ("G76", "the multiple threading cycle"),
            (
                "G90",
                "the outer or inner diameter cutting cycle (system A)",
            ),
            ("G92", "the threading cycle (system A)"),
            ("G94", "the end face turning cycle (system A)"),
            ("G96", "constant surface speed"),
            ("G99", "feed per revolution"),
            ("M98", "a subprogram call"),
            ("M99", "the end of a subprogram"),
            ("U", "X incremental, in G-code system A"),
            ("W", "Z incremental, in G-code system A"),
        ],
        macros: Some(MacroReading {
            language: MacroLanguage::Fanuc,
            files: &["O{O}", "O{O}.nc", "O{O}.NC", "{O}.nc", "{N}.nc"],
            repeats_in_p: true,
            sub_name_line: None,
        }),
        arcs: None,
        // 0i-TC Operator's Manual, "Dwell (G04)": X or U in seconds with a
        // decimal point (else in the least input increment, 0.001 s), P in
        // milliseconds without one; G99's dwell in turns (a parameter)
        // does not arise, G98 the setup's feed.
        dwell: &[
            ('X', DwellUnit::SecondsByPoint),
            ('U', DwellUnit::SecondsByPoint),
            ('P', DwellUnit::Milliseconds),
        ],
        // "Constant surface speed control (G96, G97)": S in m/min, the
        // clamp by G50 S ("Spindle speed clamp").
        speed_clamp: Some(SpeedClamp::G50),
    },
};

/// LinuxCNC (lathe configuration): `%`-framed, spindle-synchronised `G33`
/// moves with `K` the distance per turn, `G7`/`G8` diameter or radius
/// mode. G33 starts at the spindle's index: no start angle (a multi-start
/// thread shifts its starts along Z).
pub const LINUXCNC: Dialect = Dialect {
    name: "linuxcnc",
    extension: "ngc",
    style: Style::GCode,
    comment: ("(", ")"),
    upper_comments: false,
    numbering: Some((10, 10)),
    header: &[
        "%",
        "({NAME} for {MACHINE}, written by pilgrim {VERSION})",
        "(tool T{TOOL}: {TOOLNAME})",
    ],
    preamble: &["G21 G40 G90 G94 G97", "{SETUP}", "S{S} M3", "{COOLANT}"],
    footer: &["{COOLANT_OFF}", "M5", "M2"],
    trailer: &["%"],
    rapid: "G0",
    linear: "G1",
    thread: "G33",
    lead: "K",
    decimals: 3,
    feed_decimals: 1,
    lead_decimals: 4,
    radial_words: Some(("G8", "G7")),
    coolant: ("M8", "M9"),
    feed_group: None,
    lead_every_block: true,
    thread_start: None,
    thread_cycle: Some(WrittenCycle::Linuxcnc),
    reading: Reading {
        g_codes: &[
            0, 1, 7, 8, 17, 18, 19, 21, 33, 40, 54, 55, 56, 57, 58, 59, 76, 90, 94, 97,
        ],
        m_codes: &[2, 3, 5, 8, 9],
        end_code: 2,
        name_line: None,
        number_line: false,
        tool_and_offset: false,
        offset_word: None,
        thread_needs_constant_speed: true,
        setup_codes: &[21, 40, 90, 94],
        work_offsets: &[54, 55, 56, 57, 58, 59],
        least_input: None,
        point_needed: "",
        no_point: "",
        code_tenths: true,
        // G61, exact path mode (the replay's path through every block's
        // end point): read as the verification models it.
        read_g_codes: &[4, 61, 96],
        g76: Some(G76Form::LinuxCnc),
        g92_thread: false,
        // G-code reference, "Modal groups": 2 (plane), 6 (units), 7
        // (cutter compensation), 12 (coordinate system), 3 (distance), 5
        // (feed rate mode), lathe diameter/radius and spindle speed modes.
        modal_groups: &[
            &[17, 18, 19],
            &[20, 21],
            &[40, 41, 42],
            &[54, 55, 56, 57, 58, 59],
            &[90, 91],
            &[93, 94, 95],
            &[96, 97],
            &[7, 8],
        ],
        systems: &[],
        // G-code reference, "G Codes".
        meanings: &[
            ("G2", "an arc clockwise"),
            ("G3", "an arc counter-clockwise"),
            ("G4", "a dwell"),
            ("G20", "inch units"),
            ("G33.1", "rigid tapping (it reverses the spindle)"),
            ("G61.1", "exact stop mode"),
            (
                "G64",
                "path blending, its corners cut off the programmed points",
            ),
            ("G41", "cutter compensation left"),
            ("G42", "cutter compensation right"),
            ("G91", "incremental distance"),
            ("G92", "a coordinate system offset"),
            ("G93", "inverse-time feed"),
            ("G95", "feed per revolution"),
            ("G96", "constant surface speed"),
            ("G98", "the canned cycles' return to the initial level"),
            ("G99", "the canned cycles' return to the R level"),
        ],
        macros: Some(MacroReading {
            language: MacroLanguage::Rs274,
            files: &["{name}.ngc", "{NAME}.ngc", "{name}.NGC"],
            repeats_in_p: false,
            sub_name_line: None,
        }),
        arcs: None,
        // G-code reference, "G4 Dwell": P in seconds.
        dwell: &[('P', DwellUnit::Seconds)],
        // "G96, G97 Spindle Control Mode": G96 D(max rpm) S(m/min).
        speed_clamp: Some(SpeedClamp::DWithG96),
    },
};

/// APT-style cutter-location file (ISO 4343 flavour) in machine coordinates.
pub const CLD: Dialect = Dialect {
    name: "cld",
    extension: "cld",
    style: Style::Apt,
    comment: ("PPRINT/", ""),
    upper_comments: false,
    numbering: None,
    header: &[
        "PARTNO/{NAME}",
        "MACHIN/{MACHINE}",
        "PPRINT/written by pilgrim {VERSION}",
        "UNITS/MM",
        "LOADTL/{TOOL}",
        "SPINDL/{S},RPM,CLW",
        "{COOLANT}",
    ],
    preamble: &[],
    footer: &["{COOLANT_OFF}", "SPINDL/OFF", "FINI"],
    trailer: &[],
    rapid: "RAPID",
    linear: "",
    thread: "",
    lead: "",
    decimals: 3,
    feed_decimals: 3,
    lead_decimals: 4,
    radial_words: None,
    coolant: ("COOLNT/ON", "COOLNT/OFF"),
    feed_group: None,
    lead_every_block: false,
    thread_start: None,
    // Records, not G-code: the lint reads them by their own rules.
    thread_cycle: None,
    reading: Reading {
        g_codes: &[],
        m_codes: &[],
        end_code: 0,
        name_line: None,
        number_line: false,
        tool_and_offset: false,
        offset_word: None,
        thread_needs_constant_speed: false,
        setup_codes: &[],
        work_offsets: &[],
        least_input: None,
        point_needed: "",
        no_point: "",
        code_tenths: false,
        read_g_codes: &[],
        g76: None,
        g92_thread: false,
        modal_groups: &[],
        systems: &[],
        meanings: &[],
        macros: None,
        arcs: None,
        dwell: &[],
        speed_clamp: None,
    },
};

/// The ISO G code selecting plane `p` (G17, G18, G19).
pub fn plane_code(p: Plane) -> u32 {
    match p {
        Plane::Xy => 17,
        Plane::Zx => 18,
        Plane::Yz => 19,
    }
}

/// A Haas lathe (and a Fanuc 10/11/15-T): Fanuc's words and programs
/// (system A), its threading cycle the one-block `G76 X Z I K D A P F`
/// (Haas Lathe Operator's Manual, "G76 Threading Cycle, Multiple Pass";
/// the least cut, the finishing allowance and the chamfer its settings,
/// which the machine states). pilgrim writes Fanuc's words, a threading
/// cycle's moves as blocks.
pub const HAAS: Dialect = Dialect {
    name: "haas",
    reading: Reading {
        g76: Some(G76Form::OneBlock),
        // Haas Lathe Operator's Manual, "G-codes": G92 is the threading
        // cycle there too.
        meanings: FANUC.reading.meanings,
        // pilgrim writes the one-block G76's moves (its settings are the
        // machine's), so the cycle is read in a shop's program only.
        g_codes: &[0, 1, 18, 17, 19, 21, 32, 40, 54, 55, 56, 57, 58, 59, 97, 98],
        read_g_codes: &[4, 50, 76, 92, 96],
        // Haas Lathe Operator's Manual, "G04 Dwell": P in seconds with a
        // decimal point, in milliseconds without one.
        dwell: &[('P', DwellUnit::SecondsByPoint)],
        ..FANUC.reading
    },
    thread_cycle: None,
    ..FANUC
};

/// Every dialect.
pub const DIALECTS: [&Dialect; 5] = [&SINUMERIK, &FANUC, &HAAS, &LINUXCNC, &CLD];

/// The dialect called `name`.
pub fn dialect(name: &str) -> Option<&'static Dialect> {
    DIALECTS
        .iter()
        .copied()
        .find(|d| d.name.eq_ignore_ascii_case(name))
}

/// Errors writing a program.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PostError {
    /// The run's time limit passed while this was being done.
    #[error(transparent)]
    OverTime(#[from] crate::budget::OverTime),
    /// No dialect of that name.
    #[error(
        "no post-processor dialect '{name}' (dialects: sinumerik, fanuc, haas, linuxcnc, cld)"
    )]
    UnknownDialect {
        /// The name asked for.
        name: String,
    },
    /// A block that cannot be written.
    #[error("{block}: {message}")]
    BadBlock {
        /// The block, as the program names it ([`super::block_name`]).
        block: String,
        /// What is wrong.
        message: String,
    },
    /// A plugin's post-processor failed.
    #[error("post-processor: {0}")]
    Plugin(String),
}

/// [`post`] with the dialect named.
///
/// # Failures
/// An unknown dialect; as [`post`].
pub fn post_by_name(program: &AxisProgram, name: &str) -> Result<String, PostError> {
    let d = dialect(name).ok_or_else(|| PostError::UnknownDialect {
        name: name.to_owned(),
    })?;
    post(program, d)
}

struct Writer<'a> {
    d: &'a Dialect,
    out: String,
    /// The next block's number and the step to the one after.
    next: Option<(u64, u64)>,
}

impl Writer<'_> {
    fn line(&mut self, text: &str) {
        self.out.push_str(text);
        self.out.push('\n');
    }

    fn block(&mut self, text: &str) {
        match self.next {
            Some((n, step)) => {
                self.out.push_str(&format!("N{n} {text}\n"));
                self.next = Some((n + step, step));
            }
            None => self.line(text),
        }
    }

    /// Passes over `n` numbers (the moves a cycle's one block makes).
    fn skip(&mut self, n: usize) {
        if let Some((next, step)) = self.next {
            self.next = Some((next + step * n as u64, step));
        }
    }

    /// Numbers the blocks from `first` by `step` (if the dialect numbers).
    fn number_from(&mut self, first: u64, step: u64) {
        if self.next.is_some() {
            self.next = Some((first, step));
        }
    }

    fn comment(&mut self, text: &str) {
        let (open, close) = self.d.comment;
        self.line(&format!("{open}{}{close}", comment_text(self.d, text)));
    }
}

/// Words LinuxCNC acts on at the start of a comment (`(MSG,..)` shows a
/// message, `(PROBEOPEN f)` and `(LOGOPEN,f)` open files, `(PY,..)` runs
/// Python, `(ABORT,..)` stops, `(AXIS,..)` drives the GUI, `(DEBUG,..)`,
/// `(PRINT,..)` and `(LOG,..)` print): a comment of pilgrim's never
/// starts with one ([`comment_text`]), and the lint refuses one that does.
pub const ACTIVE_COMMENTS: [&str; 8] = [
    "MSG", "DEBUG", "PRINT", "LOG", "PROBE", "ABORT", "PY", "AXIS",
];

/// Whether a comment's text would make `d`'s control act: on LinuxCNC it
/// starts (case and leading spaces aside) with one of [`ACTIVE_COMMENTS`]
/// followed by what makes it an instruction: a comma (`MSG,`, `PY,`,
/// spaces before it allowed), or a probe's or log's word of its own
/// (`PROBEOPEN`, `PROBECLOSE`, `LOGOPEN`, `LOGCLOSE`, `LOGAPPEND`). A name
/// that only begins like one (`pyramid`, `logo`, `printer`) is text.
pub fn is_active_comment(d: &Dialect, text: &str) -> bool {
    d.name == LINUXCNC.name && {
        let t = text.trim_start().to_ascii_uppercase();
        [
            "PROBEOPEN",
            "PROBECLOSE",
            "LOGOPEN",
            "LOGCLOSE",
            "LOGAPPEND",
        ]
        .iter()
        .any(|k| t.starts_with(k))
            || ACTIVE_COMMENTS.iter().any(|k| {
                t.strip_prefix(k)
                    .is_some_and(|rest| rest.trim_start().starts_with(','))
            })
    }
}

/// `text` as a comment of `d` holds it: the one function every comment a
/// program carries goes through (pass names, the header's machine and
/// tool names, the writer's own notes). Names are checked where they enter
/// ([`crate::names`]); this writes them so that no text can close or break
/// the comment, or the block, whatever it holds: every character outside
/// the names' set ([`crate::names::is_name_char`]) becomes `_`, upper case
/// where the control wants it (Fanuc), and a comment LinuxCNC would act on
/// ([`is_active_comment`]) is prefixed with `_`.
pub fn comment_text(d: &Dialect, text: &str) -> String {
    let mut t: String = text
        .chars()
        .take(crate::names::MAX_NAME)
        .map(|c| {
            if crate::names::is_name_char(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    if d.upper_comments {
        t = t.to_uppercase();
    }
    if is_active_comment(d, &t) {
        t.insert(0, '_');
    }
    t
}

/// A template filled in for `p`; names go through [`comment_text`] (the
/// templates put them in comments only). A template starting
/// `{WHOLE}` is for a whole program only (`p.number` > 0), one starting
/// `{BLOCK}` for a block to paste only (number 0).
fn fill(template: &str, p: &AxisProgram, d: &Dialect) -> String {
    let (tool_name, machine) = (comment_text(d, &p.tool_name), comment_text(d, &p.machine));
    let template = match (
        template.strip_prefix("{WHOLE}"),
        template.strip_prefix("{BLOCK}"),
    ) {
        (Some(t), _) if p.number > 0 => t,
        (Some(_), _) => return String::new(),
        (_, Some(t)) if p.number == 0 => t,
        (_, Some(_)) => return String::new(),
        _ => template,
    };
    let (coolant_on, coolant_off) = if p.setup.coolant { d.coolant } else { ("", "") };
    template
        .replace("{SETUP}", &setup_words(&p.setup, d).join(" "))
        .replace("{COOLANT_OFF}", coolant_off)
        .replace("{COOLANT}", coolant_on)
        .replace("{NAME}", &p.name)
        .replace("{ONUM}", &format!("{:04}", p.number % 10000))
        .replace("{MACHINE}", &machine)
        .replace("{TOOL2}", &format!("{:02}", p.tool_number % 100))
        .replace("{TOOLNAME}", &tool_name)
        .replace("{TOOL}", &p.tool_number.to_string())
        .replace("{S}", &format!("{}", p.spindle_rpm.round() as i64))
        .replace("{VERSION}", crate::version::VERSION)
}

/// The words of `setup` in `d`: work offset, plane, radius or diameter
/// programming where the dialect has words for it.
fn setup_words(setup: &ProgramSetup, d: &Dialect) -> Vec<String> {
    if d.style == Style::Apt {
        return Vec::new();
    }
    let mut words = Vec::new();
    if let Some(n) = setup.work_offset {
        words.push(format!("G{}", 53 + u16::from(n)));
    }
    if let Some(p) = setup.plane {
        words.push(format!("G{}", plane_code(p)));
    }
    if let (false, Some(word)) = (setup.feed_group.is_empty(), d.feed_group) {
        words.push(format!("{word}({})", setup.feed_group.join(",")));
    }
    if let (Some(r), Some((radius, diameter))) = (setup.radial, d.radial_words) {
        words.push(
            match r {
                Radial::Radius => radius,
                Radial::Diameter => diameter,
            }
            .to_owned(),
        );
    }
    words
}

/// The comment that says how the radial axis is programmed, where the
/// dialect has no word for it.
fn radial_note(setup: &ProgramSetup, d: &Dialect) -> Option<String> {
    let r = setup.radial?;
    if d.radial_words.is_some() && d.style == Style::GCode {
        return None;
    }
    let axis = if setup.radial_axis.is_empty() {
        "X"
    } else {
        &setup.radial_axis
    };
    Some(match r {
        Radial::Radius => format!("{axis} on radius"),
        Radial::Diameter => format!("{axis} on diameter"),
    })
}

/// Writes `program` in `dialect`.
///
/// # Failures
/// A block whose number of values is not the number of axes, or a value or
/// feed that is not finite (named by block).
pub fn post(program: &AxisProgram, dialect: &Dialect) -> Result<String, PostError> {
    let d = dialect;
    let width = program.axes.len();
    for (i, b) in program.blocks.iter().enumerate() {
        let bad = |message: String| PostError::BadBlock {
            block: super::block_name(program, i),
            message,
        };
        if b.values.len() != width {
            return Err(bad(format!("{} values for {width} axes", b.values.len())));
        }
        if let Some(v) = b
            .values
            .iter()
            .chain([&b.feed])
            .chain(b.spindle.as_ref())
            .find(|v| !v.is_finite())
        {
            return Err(bad(format!("value {v} is not a finite number")));
        }
        // A dwell is read from a shop's program; pilgrim's toolpaths have
        // none, and a post that wrote one would need a lint that reads it.
        if b.dwell_s != 0.0 {
            return Err(bad(format!(
                "a dwell of {} s, which pilgrim's posts do not write",
                b.dwell_s
            )));
        }
    }
    let mut w = Writer {
        d,
        out: String::new(),
        next: d.numbering.map(|_| (1, 1)),
    };
    for h in d.header {
        let line = fill(h, program, d);
        if !line.is_empty() {
            w.line(&line);
        }
    }
    if let Some(note) = radial_note(&program.setup, d) {
        w.comment(&note);
    }
    let preamble: Vec<String> = d
        .preamble
        .iter()
        .map(|h| fill(h, program, d))
        .filter(|l| !l.trim().is_empty())
        .collect();
    for line in &preamble {
        w.block(line);
    }
    // The moves' numbers are their indices' (`block_label`); every
    // dialect's preamble fits below the first (a test checks it).
    if let Some((first, step)) = d.numbering {
        w.number_from(first, step);
    }
    let mut last_words: Vec<Option<String>> = vec![None; width];
    let mut last_motion: Option<&str> = None;
    let mut last_feed: Option<String> = None;
    // The preamble started the spindle at the program's speed.
    let mut last_spindle = program.spindle_rpm.round() as i64;
    let mut last_start: Option<String> = None;
    let mut ticker = crate::budget::Ticker::new("the post", 1024);
    // Blocks a threading cycle the dialect writes makes, up to here.
    let mut made_by_cycle = 0;
    for (k, b) in program.blocks.iter().enumerate() {
        ticker.tick()?;
        if k < made_by_cycle {
            continue;
        }
        if let (Some((count, texts)), Style::GCode) = (cycle_at(program, d, k), d.style) {
            let blocks = program.blocks.get(k..k + count).unwrap_or_default();
            if blocks.len() != count
                || count < texts.len()
                || blocks.iter().any(|b| b.spindle.is_some())
            {
                return Err(PostError::BadBlock {
                    block: super::name_in(d.name, &program.blocks, k),
                    message: format!(
                        "a threading cycle over {count} blocks, {}",
                        if blocks.len() != count {
                            "beyond the program's end"
                        } else {
                            "the spindle's speed changing in it"
                        }
                    ),
                });
            }
            if let Some(c) = &b.comment {
                w.comment(c);
            }
            for text in &texts {
                w.block(text);
            }
            // The cycle's own moves keep their numbers (move i is
            // N(first + i step)), and it leaves the tool at its last.
            w.skip(count - texts.len());
            let decimals = program.decimals.unwrap_or(d.decimals);
            for (slot, v) in last_words.iter_mut().zip(&blocks[count - 1].values) {
                *slot = Some(fixed(*v, decimals));
            }
            last_motion = Some("G76");
            made_by_cycle = k + count;
            continue;
        }
        if let Some(c) = &b.comment {
            w.comment(c);
        }
        let spindle = b
            .spindle
            .map(|s| s.round() as i64)
            .filter(|s| *s != last_spindle);
        if let Some(s) = spindle {
            last_spindle = s;
        }
        let decimals = program.decimals.unwrap_or(d.decimals);
        let values: Vec<String> = b.values.iter().map(|v| fixed(*v, decimals)).collect();
        match d.style {
            Style::Apt => {
                if let Some(s) = spindle {
                    w.line(&format!("SPINDL/{s},RPM,CLW"));
                }
                match b.motion {
                    Motion::Rapid => w.line("RAPID"),
                    Motion::Linear => {
                        let f = format!("FEDRAT/{},MMPM", fixed(b.feed, d.feed_decimals));
                        if last_feed.as_ref() != Some(&f) {
                            w.line(&f);
                            last_feed = Some(f);
                        }
                    }
                    Motion::Thread { lead, start_deg } => {
                        let f = format!("FEDRAT/{},MMPR", fixed(lead, d.lead_decimals));
                        if last_feed.as_ref() != Some(&f) {
                            w.line(&f);
                            last_feed = Some(f);
                        }
                        if start_deg != 0.0 {
                            w.comment(&format!("thread start {} deg", fixed(start_deg, 3)));
                        }
                    }
                }
                w.line(&format!("GOTO/{}", values.join(",")));
            }
            Style::GCode => {
                let motion = match b.motion {
                    Motion::Rapid => d.rapid,
                    Motion::Linear => d.linear,
                    Motion::Thread { .. } => d.thread,
                };
                let mut words = Vec::new();
                let mut first_written = None;
                for (k, v) in values.into_iter().enumerate() {
                    let name = &program.axes[k].name;
                    if b.keep.contains(name) {
                        continue;
                    }
                    if first_written.is_none() {
                        first_written = Some(format!("{name}{v}"));
                    }
                    if last_words[k].as_ref() != Some(&v) {
                        words.push(format!("{name}{v}"));
                        last_words[k] = Some(v);
                    }
                }
                if words.is_empty() {
                    // No axis moves: the block is still the program's (its
                    // number, its place in the report), so its first axis
                    // is written again.
                    words.extend(first_written);
                }
                if last_motion != Some(motion) {
                    words.insert(0, motion.to_owned());
                    last_motion = Some(motion);
                }
                let feed = match b.motion {
                    Motion::Rapid => None,
                    Motion::Linear => Some(format!("F{}", fixed(b.feed, d.feed_decimals))),
                    Motion::Thread { lead, .. } => {
                        Some(format!("{}{}", d.lead, fixed(lead, d.lead_decimals)))
                    }
                };
                if let Some(f) = feed {
                    let every = d.lead_every_block && matches!(b.motion, Motion::Thread { .. });
                    if every || last_feed.as_ref() != Some(&f) {
                        words.push(f.clone());
                        last_feed = Some(f);
                    }
                }
                if let Motion::Thread { start_deg, .. } = b.motion {
                    match d.thread_start {
                        Some(t) => {
                            let v = fixed(start_deg * t.scale, t.decimals);
                            let word = format!("{}{v}", t.address);
                            // A modal word stands at 0 until written.
                            let due = if t.modal {
                                let zero = format!("{}{}", t.address, fixed(0.0, t.decimals));
                                *last_start.get_or_insert(zero) != word
                            } else {
                                start_deg != 0.0
                            };
                            if due {
                                words.push(word.clone());
                                last_start = Some(word);
                            }
                        }
                        None if start_deg != 0.0 => {
                            return Err(PostError::BadBlock {
                                block: super::name_in(d.name, &program.blocks, k),
                                message: format!(
                                    "a thread start angle of {start_deg} deg, which {} cannot write (its thread starts at the spindle's index): shift the starts along Z instead",
                                    d.name
                                ),
                            })
                        }
                        None => {}
                    }
                }
                if let Some(s) = spindle {
                    words.push(format!("S{s}"));
                }
                w.block(&words.join(" "));
            }
        }
    }
    for f in d.footer {
        let line = fill(f, program, d);
        if !line.is_empty() {
            w.block(&line);
        }
    }
    for t in d.trailer {
        w.line(&fill(t, program, d));
    }
    Ok(w.out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn program() -> AxisProgram {
        crate::program::test_program()
    }

    /// LinuxCNC acts on a comment that opens with its word and a comma (or
    /// a probe's or log's word), never on a name that only begins like one.
    #[test]
    fn active_comments_are_instructions_not_names() {
        for (text, active) in [
            ("MSG, hello", true),
            (" msg ,hello", true),
            ("PY,import os", true),
            ("LOG,x", true),
            ("LOGOPEN,f", true),
            ("PROBEOPEN f", true),
            ("logclose", true),
            ("DEBUG,#1", true),
            ("PYRAMID for vertical-mill", false),
            ("LOGO for mill", false),
            ("PRINTER for mill", false),
            ("MESSAGE for mill", false),
            ("pass 1, stock 0.0 um", false),
        ] {
            assert_eq!(is_active_comment(&LINUXCNC, text), active, "{text}");
            assert!(!is_active_comment(&FANUC, text), "{text}");
        }
    }

    #[test]
    fn sinumerik_program() {
        let text = post(&program(), &SINUMERIK).unwrap();
        let expected = "%_N_DEMO_MPF\n;$PATH=/_N_MPF_DIR\n; DEMO for test-lathe, written by pilgrim VERSION\n\
; tool T3: thread insert 60\nN1 G90 G94 G71\nN2 T3 D1\nN3 S399 M3\n; pass 1\nN10 G0 X50.000 Z5.000\n\
N20 G1 X40.000 F100.0\nN30 Z0.000\nN40 X40.000\nN50 G33 Z-60.000 K6.3500\nN60 G0 X50.000\nN70 M5\nN80 M30\n";
        assert_eq!(text, expected.replace("VERSION", crate::version::VERSION));
    }

    #[test]
    fn fanuc_program() {
        let text = post(&program(), &FANUC).unwrap();
        let expected = "%\nO0007 (DEMO)\n(TEST-LATHE, WRITTEN BY PILGRIM VERSION)\n(TOOL T03: THREAD INSERT 60)\n\
G21 G40 G97 G98\nT0303\nS399 M03\n(PASS 1)\nG00 X50.000 Z5.000\nG01 X40.000 F100.0\nZ0.000\n\
X40.000\nG32 Z-60.000 F6.3500\nG00 X50.000\nM05\nM30\n%\n";
        assert_eq!(text, expected.replace("VERSION", crate::version::VERSION));
    }

    #[test]
    fn cld_program() {
        let text = post(&program(), &CLD).unwrap();
        let expected = "PARTNO/DEMO\nMACHIN/test-lathe\nPPRINT/written by pilgrim VERSION\nUNITS/MM\nLOADTL/3\n\
SPINDL/399,RPM,CLW\nPPRINT/pass 1\nRAPID\nGOTO/50.000,5.000\nFEDRAT/100.000,MMPM\nGOTO/40.000,5.000\n\
GOTO/40.000,0.000\nGOTO/40.000,0.000\nFEDRAT/6.3500,MMPR\nGOTO/40.000,-60.000\nRAPID\nGOTO/50.000,-60.000\n\
SPINDL/OFF\nFINI\n";
        assert_eq!(text, expected.replace("VERSION", crate::version::VERSION));
    }

    #[test]
    fn spindle_changes_are_written_where_they_happen() {
        let mut p = program();
        p.blocks[0].spindle = Some(399.0); // the preamble's speed: nothing new
        p.blocks[4].spindle = Some(120.0);
        let g = post(&p, &SINUMERIK).unwrap();
        assert!(g.contains("N10 G0 X50.000 Z5.000\n"), "{g}");
        assert!(g.contains("N50 G33 Z-60.000 K6.3500 S120\n"), "{g}");
        let a = post(&p, &CLD).unwrap();
        assert!(
            a.contains("GOTO/40.000,0.000\nSPINDL/120,RPM,CLW\nFEDRAT/6.3500,MMPR\n"),
            "{a}"
        );
    }

    /// A numbered Fanuc program is whole; number 0 is the block to paste
    /// after the tool call. A thread's start angle is Fanuc's Q (0.001 deg,
    /// its block only), Sinumerik's SF= (modal); LinuxCNC has no word for
    /// it and refuses, naming the block.
    #[test]
    fn thread_starts_and_program_kinds() {
        let mut p = program();
        p.number = 0;
        p.blocks[4].motion = Motion::Thread {
            lead: 6.35,
            start_deg: 180.0,
        };
        p.blocks.push(p.blocks[4].clone());
        let f = post(&p, &FANUC).unwrap();
        assert!(
            !f.contains('%') && !f.contains("O00") && !f.contains("T0303"),
            "{f}"
        );
        assert!(
            f.contains("(TO FOLLOW THE CALL OF TOOL T03: THREAD INSERT 60)\n"),
            "{f}"
        );
        assert!(f.contains("G32 Z-60.000 F6.3500 Q180000\n"), "{f}");
        assert!(f.contains("\nG32 X40.000 Q180000\n"), "{f}");
        let g = post(&p, &SINUMERIK).unwrap();
        assert!(g.contains("N50 G33 Z-60.000 K6.3500 SF=180.000\n"), "{g}");
        assert!(g.contains("N70 G33 X40.000\n"), "{g}");
        let e = post(&p, &LINUXCNC).unwrap_err().to_string();
        assert!(e.contains("N50") && e.contains("start angle of 180"), "{e}");
        p.blocks[4].motion = Motion::Thread {
            lead: 6.35,
            start_deg: 0.0,
        };
        p.blocks.pop();
        let l = post(&p, &LINUXCNC).unwrap();
        assert!(
            l.starts_with("%\n(DEMO for test-lathe") && l.ends_with("M2\n%\n"),
            "{l}"
        );
        assert!(l.contains("N50 G33 Z-60.000 K6.3500\n"), "{l}");
    }

    #[test]
    fn a_machine_may_program_finer() {
        let mut p = program();
        p.decimals = Some(4);
        let g = post(&p, &SINUMERIK).unwrap();
        assert!(
            g.contains("N10 G0 X50.0000 Z5.0000\n") && g.contains("N30 Z-0.0001\n"),
            "{g}"
        );
    }

    #[test]
    fn bad_blocks_and_dialects_are_named() {
        let mut p = program();
        p.blocks[2].values[1] = f64::NAN;
        assert_eq!(
            post(&p, &SINUMERIK).unwrap_err().to_string(),
            "block 3 in \"pass 1\": value NaN is not a finite number"
        );
        p.blocks[2].values.pop();
        assert!(post(&p, &CLD)
            .unwrap_err()
            .to_string()
            .contains("block 3 in \"pass 1\": 1 values for 2 axes"));
        assert!(post_by_name(&program(), "heidenhain")
            .unwrap_err()
            .to_string()
            .contains("'heidenhain'"));
    }

    fn with_setup() -> AxisProgram {
        let mut p = program();
        p.setup = ProgramSetup {
            work_offset: Some(1),
            plane: Some(Plane::Zx),
            radial: Some(Radial::Radius),
            coolant: true,
            ..ProgramSetup::default()
        };
        // A start block that moves X only: Z stays where it stands.
        p.blocks[0].keep = vec!["Z".into()];
        p
    }

    #[test]
    fn the_setup_becomes_words_of_each_dialect() {
        let g = post(&with_setup(), &SINUMERIK).unwrap();
        assert!(
g.contains("N1 G90 G94 G71\nN2 G54 G18 DIAMOF\nN3 T3 D1\nN4 S399 M3\nN5 M8\n; pass 1\nN10 G0 X50.000\nN20 G1 X40.000 Z5.000 F100.0\n"),
            "{g}"
        );
        assert!(
            g.ends_with("N60 G0 X50.000\nN70 M9\nN80 M5\nN90 M30\n"),
            "{g}"
        );
        let mut d = with_setup();
        d.setup.radial = Some(Radial::Diameter);
        assert!(post(&d, &SINUMERIK)
            .unwrap()
            .contains("N2 G54 G18 DIAMON\n"));
        let f = post(&with_setup(), &FANUC).unwrap();
        assert!(
            f.contains("(X ON RADIUS)\nG21 G40 G97 G98\nG54 G18\nT0303\nS399 M03\nM08\n"),
            "{f}"
        );
        assert!(f.ends_with("M09\nM05\nM30\n%\n"), "{f}");
        let a = post(&with_setup(), &CLD).unwrap();
        assert!(
            a.contains("SPINDL/399,RPM,CLW\nCOOLNT/ON\nPPRINT/X on radius\n"),
            "{a}"
        );
        assert!(a.ends_with("COOLNT/OFF\nSPINDL/OFF\nFINI\n"), "{a}");
    }

    #[test]
    fn every_preamble_fits_below_the_first_move() {
        let full = with_setup();
        for d in DIALECTS {
            if let Some((first, _)) = d.numbering {
                let blocks = d
                    .preamble
                    .iter()
                    .filter(|l| !fill(l, &full, d).is_empty())
                    .count() as u64;
                assert!(blocks < first, "{}: {blocks} blocks", d.name);
            }
        }
    }
}
