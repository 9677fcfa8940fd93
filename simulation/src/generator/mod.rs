//! R-test paths for any machine: the test catalogue of a machine, the generation of a test's
//! samples, the clearance rule, the stroke and range checks (docs/paths.md).
//!
//! - [`tests`] lists a machine's tests: `turn-R` for every rotary axis `R` (it turns over its
//!   range, a full turn where the range allows it, the others at rest), `pair-R-S` for every
//!   two rotary axes (the primary turns, the secondary follows `base + a·(1 − cos φ)`), and on
//!   machines whose rotary axes are A and C the seed's `K1`, `K2`, `K4`;
//! - [`generate`] makes one test's record: rotary commands in steps, the linear axes following
//!   the ball by the nominal tool-centre-point inverse kinematics at the kinematic parameters
//!   given (the ball position among them), sample `i` at `t = i·period`; every sample within
//!   the strokes and ranges, within the clearance rule ([`clearance`]), with the nest on the
//!   ball. A sample that is not is an error naming it: nothing is clipped.
//!
//! Every test `T` has two versions of the same poses in another order: `T-rev`, reversed (times
//! from 0 again), and `T-back`, there and back in one record (the turning point once): an error
//! of an axis that moves monotonically in time in `T` and a drift in time cannot be told apart
//! on `T` alone; on `T` with `T-rev`, or on `T-back`, they can ([`Order`], [`lookup_test`]).
//!
//! Files: [`catalogue`] (the tests and their sweeps), [`clearance`] (the rule),
//! [`mod@sweep`] (samples and checks).

pub mod catalogue;
pub mod clearance;
pub mod sweep;

pub use catalogue::{
    DEFAULT_PAIR_STEP_DEG, DEFAULT_STEP_DEG, Follower, Order, SEED_TESTS, Sweep, TestKind,
    TestSpec, with_orders,
};
pub use clearance::{Clearance, ball_height_mm};

use crate::exact::ExactError;
use crate::paths::SAMPLE_PERIOD_S;
use crate::record::Record;
use model_spec::Machine;
use model_spec::pose::OutsideLimits;
use model_spec::units::{compact, short};
use std::fmt;

/// The most samples a generated test may have (a step of 0.0036° over a full turn).
pub const MAX_SAMPLES: usize = 100_000;

/// How a test is generated.
#[derive(Clone, Debug, PartialEq)]
pub struct GeneratorOptions {
    /// The step of the primary (turning) axis, degrees, finite and above 0; `None`: the test's
    /// own ([`DEFAULT_STEP_DEG`] for turns and K1, K2; [`DEFAULT_PAIR_STEP_DEG`] for pairs and
    /// K4). The step used is the span divided by the whole number of steps, so that both ends
    /// are sampled: at most this.
    pub step_deg: Option<f64>,
    /// Time between two samples, s, finite and above 0 (default [`SAMPLE_PERIOD_S`]).
    pub period_s: f64,
    /// The clearance rule.
    pub clearance: Clearance,
}

impl Default for GeneratorOptions {
    fn default() -> Self {
        GeneratorOptions {
            step_deg: None,
            period_s: SAMPLE_PERIOD_S,
            clearance: Clearance::default(),
        }
    }
}

/// Where a sample is, for messages: the test, the sample, its time and rotary pose.
#[derive(Clone, Debug, PartialEq)]
pub struct SamplePlace {
    /// The test.
    pub test: String,
    /// The sample, 0-based (messages count from 1).
    pub sample: usize,
    /// The samples of the test.
    pub samples: usize,
    /// Its time, s.
    pub t_s: f64,
    /// Its rotary commands for people (`A = 0°, C = 12°`).
    pub pose: String,
}

impl fmt::Display for SamplePlace {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "test {}, sample {} of {} (t = {} s; {})",
            self.test,
            self.sample + 1,
            self.samples,
            short(self.t_s),
            self.pose
        )
    }
}

/// Why a test cannot be listed or generated.
#[derive(Debug, thiserror::Error)]
pub enum GeneratorError {
    /// The machine has no rotary axis, hence no R-test test.
    #[error(
        "machine {machine} has no rotary axis, so it has no R-test test (the tests turn rotary axes): give a path as a CSV file"
    )]
    NoRotaryAxis {
        /// The machine.
        machine: String,
    },
    /// No test of that name.
    #[error("machine {machine} has no test `{}` (its tests: {})", model_spec::text::quoted_start(name), tests.join(", "))]
    UnknownTest {
        /// The machine.
        machine: String,
        /// The name asked for.
        name: String,
        /// The machine's tests.
        tests: Vec<String>,
    },
    /// Not one kinematic parameter per symbol (a programming error, reported).
    #[error("machine {machine} has {expected} kinematic symbols, {found} parameters were given")]
    ParamCount {
        /// The machine.
        machine: String,
        /// Its number of symbols.
        expected: usize,
        /// The parameters given.
        found: usize,
    },
    /// A kinematic parameter that is not finite or beyond the largest length of a machine.
    #[error(
        "kinematic parameter {symbol} = {} mm: {why}",
        compact(*value)
    )]
    Param {
        /// The symbol.
        symbol: String,
        /// Its value, mm.
        value: f64,
        /// What is wrong.
        why: String,
    },
    /// An option out of its domain.
    #[error("{option} = {}: {why}", compact(*value))]
    Option {
        /// The option (`step`, `period`, `max tilt`, `min ball height`).
        option: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        why: &'static str,
    },
    /// The ball stands too low above the table for the nest.
    #[error(
        "the ball centre stands {} mm above the face of {table}, less than the {} mm the nest needs (the minimum ball height of the clearance rule): raise the ball",
        short(*height_mm),
        short(*min_mm)
    )]
    BallTooLow {
        /// `the C table`, `the table (bed frame)`.
        table: String,
        /// The ball's height, mm.
        height_mm: f64,
        /// The least height, mm.
        min_mm: f64,
    },
    /// More samples than [`MAX_SAMPLES`].
    #[error(
        "test {test}: a step of {}° over {}° gives more than {max} samples, the most a test may have",
        compact(*step_deg),
        short(*span_deg)
    )]
    TooManySamples {
        /// The test.
        test: String,
        /// The primary's span, degrees.
        span_deg: f64,
        /// The step asked for, degrees.
        step_deg: f64,
        /// [`MAX_SAMPLES`].
        max: usize,
    },
    /// The primary axis of a test cannot turn: the clearance rule and its range leave it one
    /// angle.
    #[error(
        "test {test}: axis {axis} cannot turn: its range and the clearance rule leave it only {}°",
        short(*at_deg)
    )]
    NoRoom {
        /// The test.
        test: String,
        /// The axis.
        axis: String,
        /// The one angle left, degrees.
        at_deg: f64,
    },
    /// A sample that breaks a check (boxed: the other variants stay small).
    #[error("{0}")]
    Sample(Box<SampleError>),
}

/// A sample of a test that breaks a check: where, and what.
#[derive(Debug, thiserror::Error)]
#[error("{at}: {problem}")]
pub struct SampleError {
    /// The sample.
    pub at: SamplePlace,
    /// What is wrong there.
    pub problem: SampleProblem,
}

/// What is wrong at a sample.
#[derive(Debug, thiserror::Error)]
pub enum SampleProblem {
    /// The tool axis tilts too far from the table normal.
    #[error(
        "the tool axis tilts {}° from the table normal, more than the {}° of the clearance rule",
        short(*tilt_deg),
        short(*max_deg)
    )]
    Tilt {
        /// Its tilt, degrees.
        tilt_deg: f64,
        /// The largest tilt, degrees.
        max_deg: f64,
    },
    /// An axis out of its stroke or range: the first in axis order, with the value and the
    /// limits (mm or degrees).
    #[error("{0}")]
    Limits(OutsideLimits),
    /// The inverse kinematics has no solution.
    #[error("{0}")]
    Ik(ExactError),
    /// The inverse kinematics left the nest off the ball (a failed computation).
    #[error(
        "the inverse kinematics leaves the nest {} mm from the ball, beyond rounding",
        compact(*gap_mm)
    )]
    OffBall {
        /// The distance, mm.
        gap_mm: f64,
    },
    /// A computed command that is not finite (a failed computation).
    #[error("{0}")]
    NotFinite(String),
}

impl GeneratorError {
    /// `true` for a computation that failed (not a property of the input): the nest left off
    /// the ball, a non-finite pose.
    pub fn is_computation(&self) -> bool {
        match self {
            GeneratorError::Sample(e) => matches!(
                e.problem,
                SampleProblem::OffBall { .. } | SampleProblem::NotFinite(_)
            ),
            _ => false,
        }
    }
}

/// The tests of machine `m` under the default clearance rule (see [`tests_with`]).
pub fn tests(m: &Machine) -> Vec<TestSpec> {
    tests_with(m, &Clearance::default())
}

/// The tests of machine `m` under the clearance rule `clearance`: the seed's K1, K2, K4 first
/// (machines whose rotary axes are A and C), then `turn-R` for every rotary axis and
/// `pair-R-S` for every two, in ISO axis order. Empty for a machine without rotary axes.
pub fn tests_with(m: &Machine, clearance: &Clearance) -> Vec<TestSpec> {
    catalogue::catalogue(m, clearance)
}

/// The tests of machine `m` under the clearance rule `clearance` with their reversed and
/// there-and-back versions: `T`, `T-rev`, `T-back` for every test `T` of [`tests_with`].
pub fn tests_with_orders(m: &Machine, clearance: &Clearance) -> Vec<TestSpec> {
    with_orders(&tests_with(m, clearance))
}

/// The test called `name` (without regard to case) among `tests`.
pub fn find_test<'t>(tests: &'t [TestSpec], name: &str) -> Option<&'t TestSpec> {
    let name = name.trim();
    tests.iter().find(|t| t.name.eq_ignore_ascii_case(name))
}

/// The test called `name` (without regard to case) among `tests` or, for `T-rev` and `T-back`
/// with `T` among `tests`, its reversed or there-and-back version ([`TestSpec::in_order`]).
pub fn lookup_test(tests: &[TestSpec], name: &str) -> Option<TestSpec> {
    if let Some(t) = find_test(tests, name) {
        return Some(t.clone());
    }
    let name = name.trim();
    let lower = name.to_ascii_lowercase();
    [Order::Reversed, Order::ThereAndBack]
        .into_iter()
        .find_map(|order| {
            let stem = lower.strip_suffix(order.suffix())?;
            let base = find_test(tests, &name[..stem.len()])?;
            (base.order == Order::Forward).then(|| base.in_order(order))
        })
}

/// The longest time between two samples of a generated test, s (an hour).
pub const MAX_PERIOD_S: f64 = 3600.0;

/// Checks the options: a finite step above 0, a period above 0 and at most [`MAX_PERIOD_S`], a largest tilt from 0
/// to 180°, a finite least ball height of at least 0.
///
/// # Errors
/// [`GeneratorError::Option`] naming the first that is not.
pub fn check_options(opts: &GeneratorOptions) -> Result<(), GeneratorError> {
    let bad = |option, value, why| Err(GeneratorError::Option { option, value, why });
    if let Some(s) = opts.step_deg
        && !(s.is_finite() && s > 0.0)
    {
        return bad(
            "step",
            s,
            "the step must be a finite number of degrees above 0",
        );
    }
    if !(opts.period_s.is_finite() && opts.period_s > 0.0 && opts.period_s <= MAX_PERIOD_S) {
        return bad(
            "period",
            opts.period_s,
            "the time between samples must be a number of seconds above 0 and at most 3600",
        );
    }
    let tilt = opts.clearance.max_tilt_deg;
    if !(0.0..=180.0).contains(&tilt) {
        return bad(
            "max tilt",
            tilt,
            "the largest tilt of the tool axis from the table normal is an angle from 0 to 180 degrees",
        );
    }
    let h = opts.clearance.min_ball_height_mm;
    if !(h.is_finite() && (0.0..=model_spec::limits::MAX_LENGTH_MM).contains(&h)) {
        return bad(
            "min ball height",
            h,
            "the least height of the ball above the table is a finite length from 0 to 100000 mm",
        );
    }
    Ok(())
}

/// Checks the kinematic parameters `params` (mm, one per symbol): finite and within the
/// largest length of a machine description.
///
/// # Errors
/// [`GeneratorError::ParamCount`] or [`GeneratorError::Param`] naming the first bad one.
pub fn check_params(m: &Machine, params: &[f64]) -> Result<(), GeneratorError> {
    if params.len() != m.symbols.len() {
        return Err(GeneratorError::ParamCount {
            machine: m.name.clone(),
            expected: m.symbols.len(),
            found: params.len(),
        });
    }
    let max = model_spec::limits::MAX_LENGTH_MM;
    for (s, &x) in m.symbols.iter().zip(params) {
        let why = if !x.is_finite() {
            "not a finite number"
        } else if x.abs() > max {
            "beyond ±100000 mm (100 m), the largest length of a machine description"
        } else {
            continue;
        };
        return Err(GeneratorError::Param {
            symbol: s.name.clone(),
            value: x,
            why: why.to_string(),
        });
    }
    Ok(())
}

/// The record of test `name` (see [`tests`]; without regard to case) of machine `m` at the
/// kinematic parameters `params` (mm, one per symbol in [`Machine::symbols`] order; the ball
/// position among them), generated with `opts`: commands in mm and rad, no readings, sample `i`
/// at `t = i·opts.period_s`.
///
/// # Errors
/// [`GeneratorError::NoRotaryAxis`], [`GeneratorError::UnknownTest`] (listing the machine's
/// tests), bad options or parameters, and what [`generate_test`] finds.
pub fn generate(
    m: &Machine,
    name: &str,
    params: &[f64],
    opts: &GeneratorOptions,
) -> Result<Record, GeneratorError> {
    check_options(opts)?;
    let all = tests_with(m, &opts.clearance);
    if all.is_empty() {
        return Err(GeneratorError::NoRotaryAxis {
            machine: m.name.clone(),
        });
    }
    let Some(spec) = lookup_test(&all, name) else {
        return Err(GeneratorError::UnknownTest {
            machine: m.name.clone(),
            name: name.trim().to_string(),
            tests: all.iter().map(|t| t.name.clone()).collect(),
        });
    };
    generate_test(m, &spec, params, opts)
}

/// The record of test `spec` (from [`tests_with`] for `m`) at the kinematic parameters
/// `params` (mm, one per symbol), generated with `opts` (see [`generate`]); for callers that
/// generate many tests or ball positions from one catalogue.
///
/// # Errors
/// Bad options or parameters; [`GeneratorError::BallTooLow`] when the ball stands lower above
/// the table than the clearance rule asks; [`GeneratorError::TooManySamples`]; the first sample
/// that breaks a check ([`GeneratorError::Sample`]: out of a stroke or range, tilted beyond the
/// rule, where the inverse kinematics has no solution or leaves the nest off the ball).
pub fn generate_test(
    m: &Machine,
    spec: &TestSpec,
    params: &[f64],
    opts: &GeneratorOptions,
) -> Result<Record, GeneratorError> {
    check_options(opts)?;
    check_params(m, params)?;
    let height = ball_height_mm(m, params);
    if height.is_nan() || height < opts.clearance.min_ball_height_mm {
        return Err(GeneratorError::BallTooLow {
            table: clearance::table_name(m),
            height_mm: height,
            min_mm: opts.clearance.min_ball_height_mm,
        });
    }
    let step = opts.step_deg.unwrap_or(spec.sweep.default_step_deg);
    sweep::generate(m, spec, params, step, opts.period_s, &opts.clearance)
}
