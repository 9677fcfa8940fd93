//! A reader of the programs rtest writes for the machine (`docs/measurement-programs.md`,
//! `docs/probe-programs.md`): it reads a program's own words, dialect by dialect, and sorts its
//! blocks into the steps of the sequence, so that the order can be checked: setup (machine
//! coordinates) → clearance → orientation → approach → stop → measuring moves → retract → end
//! for an R-test measurement program; setup → log opened → clearance → orientation → stop →
//! per pose the rotary axes, then per hit positioning, pre-touch, probing move, the latch read
//! and logged, retract → log closed → end for a touch-probe program.
//!
//! It is not [`formats::nc::parse_program`], which reads the programs `rtest compensate`
//! corrects and refuses `G53`: this one reads what rtest's own programs hold (`G53`, `G10 L2`,
//! `G54`, `G92.1`, `M91`, `M19`, `M0`, `STOP`, dwells; the probing blocks `G38.2`, `G31`,
//! `TCH PROBE 0`; the logs `(PROBEOPEN …)`/`(PROBECLOSE)`, `POPEN`/`DPRNT[…]`/`PCLOS`,
//! `FN 16: F-PRINT`; the skip position read into a macro variable, `#31=#5061`, and the
//! alarm raised when it is the end of the move, `IF[…]THEN#3000=…`) and says, for each move,
//! whether it runs in machine coordinates, whether it is a rapid, and the pose after it. The
//! programs are read back with it before they are written; the tests read every program with
//! it.
//!
//! How a block is sorted:
//!
//! - before the first move: [`Step::Setup`] (modes, `G10 L2`, `G54`, `G92.1`,
//!   `FUNCTION RESET TCPM`, `M127`), [`Step::Spindle`] (`M5`);
//! - `M19` (`L M19`): [`Step::Orient`]; `M0` (`STOP`): [`Step::Stop`]; `M2`, `M30`,
//!   `END PGM`: [`Step::End`]; a dwell (`G4`, cycle 9): [`Step::Dwell`]; another M function:
//!   [`Step::Marker`];
//! - the probing blocks: [`Step::Probe`]; the log: [`Step::LogOpen`], [`Step::Log`],
//!   [`Step::LogClose`]; the skip position read: [`Step::Latch`]; its check: [`Step::Check`];
//! - a move before the orientation and the stop: [`Step::Clearance`]; after the orientation
//!   and before the stop: [`Step::Approach`];
//! - in a program without a probing block, a move after the stop and up to the last dwell:
//!   [`Step::Measure`]; after the last dwell: [`Step::Retract`];
//! - in a program with probing blocks, a move after the stop that names a rotary axis:
//!   [`Step::Pose`]; the last move before a probing block: [`Step::PreTouch`]; the first move
//!   after one: [`Step::Retract`]; any other: [`Step::Position`].
//!
//! A word the reader does not know is an error naming the line and the word.

mod gcode;
mod heidenhain;
mod sort;

use formats::nc::{Dialect, NcError};
use formats::poses::AxisWord;

/// What a block does in the sequence of a program.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// Modes and coordinate systems, before the first move.
    Setup,
    /// The spindle stopped (`M5`).
    Spindle,
    /// A move before the spindle's orientation: to the clearance, the rotary axes there.
    Clearance,
    /// The spindle oriented (`M19`).
    Orient,
    /// A move after the orientation, before the stop: the approach of the first pose.
    Approach,
    /// The program stop (`M0`, `STOP`).
    Stop,
    /// A move after the stop, up to the last dwell: to a measuring pose.
    Measure,
    /// A dwell.
    Dwell,
    /// Another M function (a marker of the measuring window).
    Marker,
    /// A move after the last dwell: off the ball and to the clearance; in a probing program,
    /// the first move after a probing block: back to the pre-touch point.
    Retract,
    /// The end of the program.
    End,
    /// A probing program: a move after the stop that turns a rotary axis (to a pose's angles,
    /// or past them to arrive from one side).
    Pose,
    /// A probing program: any other move after the stop (to the clearance, over the sphere,
    /// between the hits at the safe height).
    Position,
    /// A probing program: the last move before a probing block (to the pre-touch point).
    PreTouch,
    /// A probing block: `G38.2` (LinuxCNC), `G31` (ISO), `TCH PROBE 0.0`/`0.1` (Heidenhain).
    Probe,
    /// The probe's log opened: `(PROBEOPEN file)` (LinuxCNC), `POPEN` (ISO).
    LogOpen,
    /// A latched position written to the log: `DPRNT[…]` (ISO), `FN 16: F-PRINT` (Heidenhain).
    Log,
    /// The probe's log closed: `(PROBECLOSE)` (LinuxCNC), `PCLOS` (ISO).
    LogClose,
    /// The skip position read into a macro variable (ISO `#31=#5061`).
    Latch,
    /// The alarm raised when the probe did not trip (ISO `IF[…]THEN#3000=…`).
    Check,
}

/// A move of a program.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    /// A rapid (`G0`, `FMAX`).
    pub rapid: bool,
    /// In machine coordinates: `G53` or `M91` in the block, or (ISO, LinuxCNC) the coordinate
    /// system `G54` in force after `G10 L2 P1` set every axis of it to 0. A Heidenhain
    /// `TCH PROBE 0.1` block is not: its position is in the active preset's coordinates.
    pub machine: bool,
    /// Inverse time (`G93`) in force.
    pub inverse_time: bool,
    /// The `F` number in force (`None` before the first, and for a rapid).
    pub feed: Option<f64>,
    /// The axes the block names (indices into the axis words).
    pub named: Vec<usize>,
    /// Every axis after the block (mm, degrees, in the order of the axis words); NaN for an
    /// axis no block has named yet. After a probing block, the programmed end of the probing
    /// move (G-code; the machine stops earlier, where the probe trips) or the position the
    /// cycle starts from and returns to (Heidenhain `TCH PROBE 0.1`).
    pub pose: Vec<f64>,
}

/// What a probing block does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProbeKind {
    /// LinuxCNC `G38.2`: a straight probe to the block's end point, an error if the probe does
    /// not trip.
    StraightProbe,
    /// ISO `G31`: the skip function, a straight move to the block's end point that stops where
    /// the skip signal comes (none: the end point).
    Skip,
    /// Heidenhain touch probe cycle 0 `REFERENCE PLANE`: from the position of its `0.1` block
    /// along one axis in one direction, the result in a Q parameter.
    ReferencePlane {
        /// The probing axis (an index into the axis words).
        axis: usize,
        /// Probing towards + (`X+`) rather than − (`X-`).
        positive: bool,
        /// The Q parameter of the result.
        result: u32,
        /// The cycle's block: 0 for `TCH PROBE 0.0` (the definition), 1 for `TCH PROBE 0.1`
        /// (the position).
        part: u8,
    },
}

/// A probing block.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeMove {
    /// Which.
    pub kind: ProbeKind,
    /// The probing feed in force, mm/min (`None` for the Heidenhain cycle, whose feed is the
    /// touch probe table's).
    pub feed: Option<f64>,
}

/// A block of a program (a line that is not only a comment).
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    /// 1-based line.
    pub line: usize,
    /// Its step in the sequence.
    pub step: Step,
    /// The move, for a block that moves (a probing block too, but `TCH PROBE 0.0`).
    pub motion: Option<Motion>,
    /// A dwell's time, s.
    pub dwell_s: Option<f64>,
    /// The M functions of the block.
    pub m_codes: Vec<u32>,
    /// The comment on the block's line, or (LinuxCNC) the `(MSG,…)` line just before it.
    pub comment: Option<String>,
    /// The probing block's kind and feed.
    pub probe: Option<ProbeMove>,
    /// The statement of a log, latch or check block as written (without its comment): the
    /// file of `(PROBEOPEN file)`, `DPRNT[…]`, `FN 16: F-PRINT a / b`, `#31=#5061`,
    /// `IF[…]THEN#3000=101`; `POPEN`, `PCLOS`, `PROBECLOSE`.
    pub statement: Option<String>,
}

/// A program as read: its blocks in order.
#[derive(Clone, Debug, PartialEq)]
pub struct ReadProgram {
    /// The blocks, in the order of the file.
    pub blocks: Vec<Block>,
}

impl ReadProgram {
    /// The steps in order, a run of blocks of one step given once, dwells and markers taken
    /// as part of the measuring: `[Setup, Spindle, Clearance, Orient, Approach, Stop, Measure,
    /// Retract, End]` for a measurement program rtest writes.
    pub fn steps(&self) -> Vec<Step> {
        let mut out: Vec<Step> = Vec::new();
        for b in &self.blocks {
            let s = match b.step {
                Step::Dwell | Step::Marker => Step::Measure,
                s => s,
            };
            if out.last() != Some(&s) {
                out.push(s);
            }
        }
        out
    }

    /// The moves of step `step`, in order.
    pub fn moves(&self, step: Step) -> Vec<&Motion> {
        self.blocks
            .iter()
            .filter(|b| b.step == step)
            .filter_map(|b| b.motion.as_ref())
            .collect()
    }

    /// The measuring poses: where the approach ends (the nest on the ball at the first pose)
    /// and the pose after each measuring move (mm, degrees).
    pub fn measuring_poses(&self) -> Vec<Vec<f64>> {
        let mut out: Vec<Vec<f64>> = self
            .moves(Step::Approach)
            .last()
            .map(|m| vec![m.pose.clone()])
            .unwrap_or_default();
        out.extend(self.moves(Step::Measure).iter().map(|m| m.pose.clone()));
        out
    }

    /// The blocks of step `step`.
    pub fn blocks_of(&self, step: Step) -> Vec<&Block> {
        self.blocks.iter().filter(|b| b.step == step).collect()
    }
}

/// What one line holds, before its step is known.
struct Raw {
    line: usize,
    motion: Option<Motion>,
    dwell_s: Option<f64>,
    dwell_block: bool,
    m_codes: Vec<u32>,
    end: bool,
    stop: bool,
    comment: Option<String>,
    probe: Option<ProbeMove>,
    /// A log, latch or check statement: its step and its text.
    special: Option<(Step, String)>,
}

impl Raw {
    /// A line `line` of nothing yet, with its comment.
    fn new(line: usize, comment: Option<String>) -> Raw {
        Raw {
            line,
            motion: None,
            dwell_s: None,
            dwell_block: false,
            m_codes: Vec::new(),
            end: false,
            stop: false,
            comment,
            probe: None,
            special: None,
        }
    }
}

/// The modal state of a G-code program.
struct GState {
    rapid: bool,
    /// `G38.2` is the motion mode in force (LinuxCNC: a block of axis words probes again).
    probing: bool,
    inverse_time: bool,
    feed: Option<f64>,
    /// `G10 L2 P1` set every axis to 0.
    p1_zero: bool,
    /// `G54` is in force.
    g54: bool,
}

/// The error of line `n` of `file` at word `word`.
fn block_error(file: &str, n: usize, word: &str, message: String) -> NcError {
    NcError::Block {
        file: file.to_string(),
        line: n,
        column: 1,
        word: (!word.is_empty()).then(|| word.to_string()),
        message,
    }
}

/// Reads program `text` (named `file` in messages) of `dialect`, for the axes `axes`: its
/// blocks and their steps (see the module documentation).
///
/// # Errors
/// [`NcError::Block`] for a word or block the reader does not know, a number it cannot read,
/// a `TCH PROBE 0.1` without its `0.0`; a move before every axis is known is not an error (its
/// pose holds NaN).
pub fn read_program(
    file: &str,
    text: &str,
    dialect: Dialect,
    axes: &[AxisWord],
) -> Result<ReadProgram, NcError> {
    let mut raws: Vec<Raw> = Vec::new();
    let mut pose = vec![f64::NAN; axes.len()];
    let mut g = GState {
        rapid: false,
        probing: false,
        inverse_time: false,
        feed: None,
        p1_zero: false,
        g54: false,
    };
    let mut cycle0: Option<ProbeKind> = None;
    let mut message: Option<String> = None;
    for (i, line) in text.lines().enumerate() {
        let n = i + 1;
        let err = |word: &str, message: String| block_error(file, n, word, message);
        let raw = match dialect {
            Dialect::Iso | Dialect::LinuxCnc => {
                gcode::line(n, line, dialect, axes, &mut pose, &mut g, &err)?
            }
            Dialect::Heidenhain => heidenhain::line(n, line, axes, &mut pose, &mut cycle0, &err)?,
        };
        match raw {
            Some(mut r) => {
                if r.comment.is_none() {
                    r.comment = message.take();
                }
                message = None;
                raws.push(r);
            }
            None => {
                let t = line.trim();
                if let Some(m) = t.strip_prefix("(MSG,").and_then(|m| m.strip_suffix(')')) {
                    message = Some(m.to_string());
                }
            }
        }
    }
    Ok(ReadProgram {
        blocks: sort::sort(raws, axes),
    })
}
