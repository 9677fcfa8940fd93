//! Measurement programs: the NC program that drives the machine through the poses of an
//! R-test path while the R-test streams its readings, and the sample-timing plan that says
//! when the machine is at each pose (`docs/measurement-programs.md`).
//!
//! [`measurement_program`] writes the program in one of three dialects ([`Dialect::Iso`]
//! (Fanuc-type), [`Dialect::LinuxCnc`], [`Dialect::Heidenhain`]) and in one of two modes, in
//! one sequence:
//!
//! 1. the header: what the program assumes and what the operator checks, in the order the
//!    program runs;
//! 2. the modes, machine coordinates (ISO: `G53` rapids and a `G54` set to zero for the feed
//!    moves; LinuxCNC: `G53` on every move; Heidenhain: `M91` on every positioning block), the
//!    spindle stopped;
//! 3. the clearance: the clearance axis (the tool axis at 0°) to its clearance position, then
//!    the rotary axes to the first pose's angles there;
//! 4. the spindle oriented (`M19`), the approach: a rapid to [`MeasureOptions::approach_mm`]
//!    above the first pose along the tool axis, a feed onto the ball;
//! 5. a program stop (`M0`, `STOP`) for the operator to check the nest on the ball: the program
//!    clock of the plan starts when the program resumes;
//! 6. the measuring poses, **static** ([`StaticTiming`]: for each pose a straight move of all
//!    axes, then a dwell of the settle time and the measuring window, optionally an M function
//!    between the two and a comment marking the measurement) or **continuous**
//!    ([`ContinuousTiming`]: a dwell at the first pose (the lead-in), straight feed moves
//!    through the poses without stopping, a dwell at the last (the lead-out));
//! 7. the retract: a feed off the ball along the tool axis, a rapid of the clearance axis to
//!    the clearance; the end.
//!
//! Measuring moves are straight lines in the axis commands with tool centre point control off:
//! the nest leaves the ball between two poses by the chord of the rotary motion, which is
//! checked on the nominal machine against [`MeasureOptions::max_gap_mm`]. Their durations are
//! set by the program where the dialect can: ISO and LinuxCNC feed moves are in inverse time
//! (`G93`: `F` is 1/the block time in minutes), so each block takes the time the plan computes,
//! whatever the control makes of five-axis feeds. Heidenhain conversational has no inverse
//! time: `F` is in mm/min, and the plan assumes the control applies it to the block's combined
//! move with degrees counted as mm (no `M116`, tool centre point control off).
//!
//! The poses are written with [`MeasureOptions::decimals`] decimals (rounded to nearest); the
//! program is read back by [`crate::reader`] before it is returned: its blocks in the order
//! above, every move in machine coordinates, and its measuring poses exactly the written ones,
//! which the plan holds.
//!
//! Files: `motion` (move durations, the nest's gap along a move), `approach` (the clearance,
//! the approach and the retract along the tool axis), `text` (the dialects' blocks), `header`
//! (the assumptions and checks stated in the program), `timing` (the moves' feeds and
//! durations, the plan's rows), `build` (the program), `plan` (the plan, its CSV written and
//! read).

mod approach;
mod build;
mod header;
mod motion;
mod plan;
mod text;
mod timing;

use formats::nc::{Dialect, NcError};
use model_spec::{AxisKind, Machine};
pub use plan::{PLAN_TIMES, PlanKind, PlanRow, TimingPlan, format_plan, parse_plan, read_plan};

/// The longest approach along the tool axis, mm ([`MeasureOptions::approach_mm`]).
pub const MAX_APPROACH_MM: f64 = 500.0;

/// The rates of one axis the timing plan assumes, in the axis's unit (mm or degrees).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisRates {
    /// The speed of feed moves: the axis that needs the longest time at its feed sets the
    /// block's time. mm/min or degrees/min, above 0.
    pub feed_per_min: f64,
    /// The speed of rapid moves (static programs with [`StaticMotion::Rapid`]). mm/min or
    /// degrees/min, above 0.
    pub rapid_per_min: f64,
    /// The acceleration of the axis for the trapezoid of a move from rest: mm/s² or
    /// degrees/s²; 0: neglected.
    pub acceleration_per_s2: f64,
}

impl AxisRates {
    /// The default rates of an axis of kind `kind`: linear 2000 mm/min feed, 10000 mm/min
    /// rapid, 1000 mm/s²; rotary 1800 degrees/min (5 rpm) feed, 7200 degrees/min rapid,
    /// 1800 degrees/s². Moderate values of five-axis machining centres: give the machine's own.
    pub fn default_for(kind: AxisKind) -> AxisRates {
        match kind {
            AxisKind::Linear => AxisRates {
                feed_per_min: 2000.0,
                rapid_per_min: 10_000.0,
                acceleration_per_s2: 1000.0,
            },
            AxisKind::Rotary => AxisRates {
                feed_per_min: 1800.0,
                rapid_per_min: 7200.0,
                acceleration_per_s2: 1800.0,
            },
        }
    }
}

/// How a static program moves between poses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StaticMotion {
    /// Feed moves of all axes together, each block timed by the program (ISO `G93` inverse
    /// time; Heidenhain `F` in mm/min). The default.
    Feed,
    /// Rapid moves (ISO `G0`, Heidenhain `FMAX`) at [`AxisRates::rapid_per_min`]. On an ISO
    /// control `G0` must be interpolated (all axes in a straight line; a Fanuc parameter):
    /// with each axis at its own speed the nest would leave the ball far more than the plan's
    /// gap check assumes.
    Rapid,
}

/// The timing of a static program: for each pose a move, then a dwell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StaticTiming {
    /// Time from the end of the move to the start of the measuring window, s, ≥ 0 (written in
    /// whole ms). Default 1 s.
    pub settle_s: f64,
    /// The measuring window, s, ≥ 0.001 (written in whole ms). Default 2 s.
    pub window_s: f64,
    /// How the machine moves between poses. Default [`StaticMotion::Feed`].
    pub motion: StaticMotion,
    /// An M function written between the settle dwell and the window dwell (to switch an output
    /// that marks the window, for example). Its handshake time with the machine's PLC is not in
    /// the plan. Default none.
    pub marker_m: Option<u16>,
    /// A comment `SAMPLE <n>` at the end of each window's dwell block. Default `false`.
    pub marker_comment: bool,
}

impl Default for StaticTiming {
    fn default() -> Self {
        StaticTiming {
            settle_s: 1.0,
            window_s: 2.0,
            motion: StaticMotion::Feed,
            marker_m: None,
            marker_comment: false,
        }
    }
}

/// The timing of a continuous program: a lead-in dwell at the first pose, feed moves through
/// the poses at [`AxisRates::feed_per_min`], a lead-out dwell at the last pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContinuousTiming {
    /// The R-test's sampling rate, Hz (stated in the header; the shortest block must last at
    /// least one sampling period). Default 100 Hz.
    pub sample_rate_hz: f64,
    /// The lead-in and lead-out dwells, s, ≥ 0.001 (written in whole ms): the still periods by
    /// which the run is found in the readings. Default 2 s.
    pub lead_s: f64,
}

impl Default for ContinuousTiming {
    fn default() -> Self {
        ContinuousTiming {
            sample_rate_hz: 100.0,
            lead_s: 2.0,
        }
    }
}

/// Static or continuous.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MeasureMode {
    /// The poses are measured at rest.
    Static(StaticTiming),
    /// The poses are measured on the fly.
    Continuous(ContinuousTiming),
}

/// What [`measurement_program`] writes, and the assumptions of its plan.
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq)]
pub struct MeasureOptions {
    /// The program's language.
    pub dialect: Dialect,
    /// Static or continuous, and its timing.
    pub mode: MeasureMode,
    /// One per axis of the machine, in [`Machine::axes`] order.
    pub rates: Vec<AxisRates>,
    /// Decimals of the axis words, 0 to [`formats::nc::MAX_DECIMALS`]. Default 4 (0.0001 mm,
    /// 0.0001°).
    pub decimals: usize,
    /// The test's name, for the header (`K4`, a file name). Default empty.
    pub test_name: String,
    /// The program number: ISO `O` number, Heidenhain `RTEST<number>`; 1 to 9999. Default 1000.
    pub program_number: u32,
    /// The feed of the approach onto the ball at the first pose and of the retract off it at
    /// the last, along the tool axis, mm/min (feed per minute). Above 0. Default 500 mm/min.
    pub approach_feed_mm_min: f64,
    /// How far above the first pose, along the tool axis, the rapid of the approach ends and
    /// the feed onto the ball starts; the retract feeds as far off the last pose. mm, above 0
    /// and at most [`MAX_APPROACH_MM`]. Default 30 mm: beyond the reach of an R-test's sensors
    /// below the ball's centre.
    pub approach_mm: f64,
    /// The clearance position of the clearance axis (the linear axis along the tool axis with
    /// every rotary axis at 0), mm in machine coordinates: the program goes there first and
    /// last, and turns the rotary axes there. Default `None`: the end of that axis's stroke
    /// away from the ball, as the machine description gives it.
    pub clearance_mm: Option<f64>,
    /// The largest distance between the nest and the ball allowed along a move on the nominal
    /// machine, mm. Above 0. Default 0.5 mm.
    pub max_gap_mm: f64,
    /// The kinematic parameters the poses were planned with (mm, symbol order: the ball
    /// position among them), stated in the header and used for the nest-ball gap along the
    /// moves. Default: the machine's defaults.
    pub params: Vec<f64>,
}

impl MeasureOptions {
    /// The default options of a program for machine `m` in `dialect` and `mode` (see the
    /// fields), the rates of [`AxisRates::default_for`].
    pub fn new(m: &Machine, dialect: Dialect, mode: MeasureMode) -> MeasureOptions {
        MeasureOptions {
            dialect,
            mode,
            rates: m
                .axes
                .iter()
                .map(|a| AxisRates::default_for(a.kind))
                .collect(),
            decimals: 4,
            test_name: String::new(),
            program_number: 1000,
            approach_feed_mm_min: 500.0,
            approach_mm: 30.0,
            clearance_mm: None,
            max_gap_mm: 0.5,
            params: m.default_parameters(),
        }
    }
}

/// A measurement program and its plan.
#[derive(Clone, Debug, PartialEq)]
pub struct MeasurementProgram {
    /// The program's text.
    pub text: String,
    /// When the machine is at each pose (the poses as the program commands them).
    pub plan: TimingPlan,
    /// Per axis (in [`Machine::axes`] order), the largest |written − given| command: mm or
    /// degrees. What the program's resolution costs.
    pub rounding: Vec<f64>,
    /// The largest distance between the nest and the ball along the moves, nominal machine, mm.
    pub largest_gap_mm: f64,
}

/// Why a measurement program cannot be written.
#[derive(Debug, thiserror::Error)]
pub enum MeasureError {
    /// An option out of range, or rates that are not one per axis.
    #[error("{0}")]
    Options(String),
    /// A pose that cannot be written: wrong number of commands, not finite, outside the
    /// strokes once rounded, beyond the axis words' range.
    #[error("pose at {place}: {message}")]
    Pose {
        /// Where the pose came from (`line 12` of its file, or `sample 12`).
        place: String,
        /// What is wrong.
        message: String,
    },
    /// A move that cannot be made as planned: the nest leaves the ball, a feed word out of
    /// range, a block shorter than the R-test's sampling period.
    #[error("move from the pose at {from} to the next: {message}")]
    Move {
        /// Where its first pose came from.
        from: String,
        /// What is wrong.
        message: String,
    },
    /// The written program does not read back as the poses (a machine whose axis letter is a
    /// word of the dialect, for example).
    #[error("the written program does not read back: {0}")]
    ReadBack(NcError),
}

pub use build::measurement_program;
pub use header::plan_comments;
