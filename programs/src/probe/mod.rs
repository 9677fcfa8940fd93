//! Touch-probe calibration programs and their logs (`docs/probe-programs.md`): the NC program
//! that probes a calibration sphere at every pose of a test, in the dialects of the R-test
//! measurement programs, its **probe plan** (a CSV written beside it: the pose, the planned
//! contact and the approach direction of every hit, what the control's log lacks), and the
//! control's log of the latched positions turned into the probe hits CSV of
//! [`formats::probe`] with that plan.
//!
//! **The program.** At every pose the rotary axes turn at the clearance; then, for every hit
//! of the pattern ([`default_pattern`], defined in the probe's frame and turned into the bed
//! frame by the pose's nominal tool rotation and an azimuth offset about the stylus that
//! changes from pose to pose, [`ProbeOptions::azimuth`]), the probe moves over the hit at the safe height above the sphere, down to the **pre-touch point**
//! (the nominal tip centre [`ProbeOptions::pretouch_mm`] outside the sphere of radius
//! `R_eff = sphere radius + tip radius`), probes towards the centre to
//! [`ProbeOptions::overtravel_mm`] beyond the nominal contact (LinuxCNC `G38.2`, an error if it
//! does not trip; ISO `G31`, the skip position read from `#5061`–`#5063` and an alarm when it
//! is the end of the move; Heidenhain touch probe cycle 0 along the machine axis nearest the
//! normal, its result in `Q115`–`Q117`), logs the latched position (LinuxCNC
//! `(PROBEOPEN …)`, ISO `DPRNT`, Heidenhain `FN 16: F-PRINT`), returns to the pre-touch point
//! and rises to the safe height. Between poses the tool-axis slide retracts to the clearance.
//! The nominal centre is where the nominal inverse kinematics puts the tool point on the ball
//! of the machine description (the sphere's centre, the probe's tip centre); a direction in the
//! bed frame becomes axis commands through the nominal linear map at the pose. With
//! [`ProbeOptions::backlash_overshoot_deg`] every pose is probed twice, its rotary axes
//! arriving from below and from above.
//!
//! **The log.** [`read_probe_log`] reads a control's log (LinuxCNC's nine numbers per probe
//! trip, ISO `DPRNT` lines, Heidenhain `FN 16` lines) and [`hits_from_log`] matches its trips,
//! in order, with the plan's hits: the count must match, every latched position must lie
//! within [`LogOptions::max_deviation_mm`] of its planned contact, and the log's rotary axes
//! (LinuxCNC) must be the plan's. The hits take the plan's pose labels, rotary angles,
//! approach directions and nominal times.
//!
//! Files: `geometry` (the pose's frame and the hits' points), `text` (the dialects' blocks),
//! `header` (what the operator checks), `build` (the program), `check` (its read-back), `plan`
//! (the probe plan CSV), `log` (the controls' logs), `hits` (log and plan to hits).

mod build;
mod check;
mod geometry;
mod header;
mod hits;
mod log;
mod plan;
mod sequence;
mod text;

pub use build::probe_program;
pub use check::{check_order, hit_steps};
pub use hits::{LogOptions, hits_from_log};
pub use log::{LoggedTrip, parse_probe_log, read_probe_log};
pub use plan::{
    PLAN_COLUMNS, PlannedHit, ProbePlan, format_probe_plan, parse_probe_plan, read_probe_plan,
};

use crate::measure::AxisRates;
use formats::nc::{Dialect, NcError};
use model_spec::Machine;
pub use simulation::probe::PatternAzimuth;

/// One hit of a pattern, relative to the sphere's centre, in the probe's (tool) frame: at every
/// pose it is turned into the bed frame by the pose's nominal tool rotation and the azimuth
/// offset [`ProbeOptions::azimuth`] gives the pose (`simulation::probe::PatternTurn`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatternHit {
    /// The unit vector from the centre to the contact (the outward normal there).
    pub point: [f64; 3],
    /// The approach direction, unit: the inward normal, `-point`, for a hit aimed at the
    /// centre.
    pub approach: [f64; 3],
}

/// The default pattern as [`PatternHit`]s: the nine hits of
/// `simulation::probe::approach_directions` (probe frame; the point hit is `−approach`), the
/// pattern the simulation and the plans use.
pub fn default_pattern() -> Vec<PatternHit> {
    simulation::probe::approach_directions()
        .iter()
        .map(|n| PatternHit {
            point: [-n.x, -n.y, -n.z],
            approach: [n.x, n.y, n.z],
        })
        .collect()
}

/// The longest stroke a probing move may have beyond the contact, and the largest pre-touch
/// distance and safe height, mm.
pub const MAX_DISTANCE_MM: f64 = 50.0;

/// The largest overshoot of the rotary axes when each pose is probed from both sides,
/// degrees.
pub const MAX_OVERSHOOT_DEG: f64 = 30.0;

/// The largest angle between a Heidenhain cycle-0 approach (along one axis) and the hit's
/// normal, degrees: beyond it the probe slides along the sphere rather than pushing into it.
pub const MAX_OBLIQUE_DEG: f64 = 60.0;

/// What [`probe_program`] writes.
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq)]
pub struct ProbeOptions {
    /// The program's language.
    pub dialect: Dialect,
    /// The hits at every pose, in order, in the probe's frame
    /// ([`default_pattern`]: `simulation::probe::approach_directions`, the simulation's). At
    /// least one.
    pub pattern: Vec<PatternHit>,
    /// How the pattern turns about the stylus from pose to pose (by the pose's index in the
    /// record; both passes of a pose with [`ProbeOptions::backlash_overshoot_deg`] alike).
    /// Default [`PatternAzimuth::Cycled`].
    pub azimuth: PatternAzimuth,
    /// The sphere's calibrated radius, mm, above 0.
    pub sphere_radius_mm: f64,
    /// The stylus tip's radius, mm, above 0: the tip centre touches the sphere at
    /// `R_eff = sphere_radius_mm + tip_radius_mm` from its centre.
    pub tip_radius_mm: f64,
    /// How far outside the sphere (tip centre from `R_eff`) each probing move starts, mm, above
    /// 0 and at most [`MAX_DISTANCE_MM`]. Default 2 mm.
    pub pretouch_mm: f64,
    /// How far beyond the nominal contact a probing move goes before it gives up, mm, above 0,
    /// below `R_eff` and at most [`MAX_DISTANCE_MM`] (ISO, LinuxCNC; the Heidenhain cycle's is
    /// the probe table's DIST). Default 2 mm.
    pub overtravel_mm: f64,
    /// The height of the moves between the hits above the sphere's top (the tip centre's
    /// `R_eff` along the tool axis), mm, above [`ProbeOptions::pretouch_mm`] and at most
    /// [`MAX_DISTANCE_MM`]. Default 10 mm.
    pub safe_mm: f64,
    /// The probing feed, mm/min, above 0 (ISO, LinuxCNC `F`; Heidenhain: the probe table's,
    /// stated in the header). Default 100 mm/min.
    pub probe_feed_mm_min: f64,
    /// The feed of the moves near the sphere (over it at the safe height, down to the pre-touch
    /// point, back and up), mm/min, above 0. Default 1000 mm/min.
    pub position_feed_mm_min: f64,
    /// Decimals of the axis words, 0 to [`formats::nc::MAX_DECIMALS`]. Default 4.
    pub decimals: usize,
    /// The program number (ISO `O`, Heidenhain `RTEST<number>`), 1 to 9999. Default 2000.
    pub program_number: u32,
    /// The test's name, for the header. Default empty.
    pub test_name: String,
    /// The clearance position of the tool-axis slide, mm in machine coordinates (default: the
    /// end of its stroke away from the sphere).
    pub clearance_mm: Option<f64>,
    /// The kinematic parameters (mm, symbol order): the sphere's centre is the ball position,
    /// the probe's tip centre the tool point.
    pub params: Vec<f64>,
    /// Probe every pose twice, the rotary axes arriving from below (coming from the angle minus
    /// this overshoot, degrees) and then from above: the difference of the two centres shows
    /// their backlash. Above 0 and at most [`MAX_OVERSHOOT_DEG`]. Default `None`.
    pub backlash_overshoot_deg: Option<f64>,
    /// No hit closer than this to the sphere's stem (along the table normal, below the
    /// sphere), degrees between the contact's normal and the stem's axis, 0 to 90. Default 30°.
    pub stem_clearance_deg: f64,
    /// The name of the log on the control (LinuxCNC `(PROBEOPEN <name>.txt)`; Heidenhain
    /// `FN 16: F-PRINT <name>.A / <name>.TXT`): letters, digits, `-` and `_`, 1 to 32
    /// characters. Default `rtest-probe`.
    pub log_name: String,
    /// One per axis, in [`Machine::axes`] order: the rapid rates of the nominal times.
    pub rates: Vec<AxisRates>,
}

impl ProbeOptions {
    /// The default options of a probing program of machine `m` in `dialect` on a sphere of
    /// radius `sphere_radius_mm` with a tip of radius `tip_radius_mm` (mm), `pattern` at every
    /// pose (see the fields).
    pub fn new(
        m: &Machine,
        dialect: Dialect,
        pattern: Vec<PatternHit>,
        sphere_radius_mm: f64,
        tip_radius_mm: f64,
    ) -> ProbeOptions {
        ProbeOptions {
            dialect,
            pattern,
            azimuth: PatternAzimuth::default(),
            sphere_radius_mm,
            tip_radius_mm,
            pretouch_mm: 2.0,
            overtravel_mm: 2.0,
            safe_mm: 10.0,
            probe_feed_mm_min: 100.0,
            position_feed_mm_min: 1000.0,
            decimals: 4,
            program_number: 2000,
            test_name: String::new(),
            clearance_mm: None,
            params: m.default_parameters(),
            backlash_overshoot_deg: None,
            stem_clearance_deg: 30.0,
            log_name: "rtest-probe".into(),
            rates: m
                .axes
                .iter()
                .map(|a| AxisRates::default_for(a.kind))
                .collect(),
        }
    }

    /// The effective radius `R_eff` (mm): where the tip centre touches the sphere.
    pub fn effective_radius_mm(&self) -> f64 {
        self.sphere_radius_mm + self.tip_radius_mm
    }
}

/// A probing program, its plan and (Heidenhain) the format file of its `FN 16`.
#[derive(Clone, Debug, PartialEq)]
pub struct ProbeProgram {
    /// The program's text.
    pub text: String,
    /// Every hit: its pose, planned contact, approach direction and nominal time.
    pub plan: ProbePlan,
    /// Heidenhain: the format file `<log_name>.A` the program's `FN 16` reads (to copy beside
    /// the program on the control); `None` in the other dialects.
    pub format_file: Option<String>,
    /// The number of poses probed (twice the test's with both directions).
    pub passes: usize,
    /// The nominal duration from the resume after the stop to the end, s.
    pub duration_s: f64,
}

/// Why a probing program cannot be written.
#[derive(Debug, thiserror::Error)]
pub enum ProbeError {
    /// An option out of range, a pattern that cannot be probed, a machine without three
    /// linear axes, a dialect that cannot log this machine's axes.
    #[error("{0}")]
    Options(String),
    /// A pose that cannot be probed: its inverse kinematics, a hit outside the strokes or too
    /// near the sphere's stem, an overshoot outside a rotary axis's range.
    #[error("pose at {place}: {message}")]
    Pose {
        /// Where the pose came from (`sample 12`, `line 12`).
        place: String,
        /// What is wrong.
        message: String,
    },
    /// The written program does not read back as written.
    #[error("the written program does not read back: {0}")]
    ReadBack(NcError),
}
