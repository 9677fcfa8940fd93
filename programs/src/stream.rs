//! A simulated R-test log: the exact virtual machine runs a measurement program's timing plan
//! with a [`Truth`], and the R-test streams its readings at a fixed rate, from before the
//! program starts to after it ends. For tests and examples of `rtest segment`
//! ([`crate::segment`]).
//!
//! - **Timeline.** The log starts [`StreamOptions::lead_s`] before the program (the offset the
//!   segmentation must find) and ends [`StreamOptions::tail_s`] after it. The machine rests at
//!   the first pose before the program and at the last after it, and follows the plan: it
//!   rests from each pose's `arrive_s` to its `depart_s`, and moves to the next pose in the
//!   planned time times [`StreamOptions::move_time_factor`] (a machine slower or faster than
//!   the plan assumes; the times after drift accordingly).
//! - **Motion.** Every axis moves along the straight line between two poses: with a smooth
//!   start and stop (`s = 3u² − 2u³` of the time fraction `u`) from rest to rest in a static
//!   plan, at constant speed through the poses of a continuous one. Between two poses the nest
//!   leaves the ball by the chord of the rotary motion, which shows in the readings as it does
//!   on a real machine.
//! - **Readings.** At each instant the readings are those of [`simulation::simulate`]
//!   at the commanded pose: the truth's errors at the pose (its time bases evaluated at the
//!   program time, normalised over the span from the first to the last measuring window's
//!   middle, `exp:TAU` from the first window's middle, `rate` and `warmup:TAU` from the
//!   program's start, the plan's time 0, and at their value there, 0, in the lead before it;
//!   `velocity` terms at the axes' velocities of the moment), the exact error vector,
//!   the instrument terms and sensor offsets, then the truth's noise per reading (σ, AR(1)
//!   with φ per log row) and its zeroing at the log's first row. At rest the readings are
//!   exactly those the static simulation gives at the same pose.
//!
//! The log is written row by row (`t_s` or `t_abs_s`, then `dx_um,dy_um,dz_um`, each the
//! shortest decimal that reads back to the same value); nothing is held.

use crate::measure::{PlanKind, TimingPlan};
use model_spec::units::format_scaled;
use model_spec::{Machine, Side};
use simulation::exact::VirtualMachine;
use simulation::model::{Basis, BasisContext};
use simulation::readings::{SimulateError, simulate};
use simulation::record::motion_directions;
use simulation::rng::Rng;
use simulation::truth::Truth;
use std::io::Write;

/// How the simulated log is taken.
#[derive(Clone, Debug, PartialEq)]
pub struct StreamOptions {
    /// The R-test's sampling rate, Hz, above 0. Default 100 Hz.
    pub rate_hz: f64,
    /// The log runs this long before the program starts, s, ≥ 0. Default 5 s.
    pub lead_s: f64,
    /// The log runs this long after the program ends, s, ≥ 0. Default 5 s.
    pub tail_s: f64,
    /// The real duration of every move over the planned one, above 0. Default 1.
    pub move_time_factor: f64,
    /// Write `t_abs_s`, Unix time from this second (the log's first row), instead of `t_s`
    /// from 0. Default `None`.
    pub unix_start: Option<u64>,
}

impl Default for StreamOptions {
    fn default() -> Self {
        StreamOptions {
            rate_hz: 100.0,
            lead_s: 5.0,
            tail_s: 5.0,
            move_time_factor: 1.0,
            unix_start: None,
        }
    }
}

/// What was written.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StreamSummary {
    /// Rows written.
    pub rows: usize,
    /// The program's start on the log's clock, s (Unix seconds with `unix_start`).
    pub program_start_s: f64,
    /// The program's real duration (moves scaled), s.
    pub program_s: f64,
}

/// Why a log could not be simulated.
#[derive(Debug, thiserror::Error)]
pub enum StreamError {
    /// The truth does not fit the machine, or the plan's poses.
    #[error(transparent)]
    Simulate(#[from] SimulateError),
    /// An option out of range, or a plan that does not pass its check.
    #[error("{0}")]
    Options(String),
    /// The log could not be written.
    #[error("cannot write the simulated log: {0}")]
    Io(#[from] std::io::Error),
}

/// The real timeline of `plan`: per pose its arrival and departure, s on the program clock.
fn timeline(plan: &TimingPlan, factor: f64) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(plan.rows.len());
    let mut t = 0.0;
    for (i, r) in plan.rows.iter().enumerate() {
        if i > 0 {
            t += (r.arrive_s - plan.rows[i - 1].depart_s) * factor;
        }
        let arrive = t;
        t += r.depart_s - r.arrive_s;
        out.push((arrive, t));
    }
    out
}

/// Writes the simulated log of `plan` run on machine `m` with `truth` to `out` (see the module
/// documentation).
///
/// # Errors
/// [`StreamError::Options`] for options out of range or a plan that fails
/// [`TimingPlan::check`]; [`StreamError::Simulate`] when the truth does not fit `m` or the
/// plan's poses; [`StreamError::Io`] when `out` fails.
pub fn write_stream<W: Write>(
    m: &Machine,
    truth: &Truth,
    plan: &TimingPlan,
    opts: &StreamOptions,
    mut out: W,
) -> Result<StreamSummary, StreamError> {
    let positive = |x: f64| x.is_finite() && x > 0.0;
    let at_least_0 = |x: f64| x.is_finite() && x >= 0.0;
    if !positive(opts.rate_hz)
        || !at_least_0(opts.lead_s)
        || !at_least_0(opts.tail_s)
        || !positive(opts.move_time_factor)
    {
        return Err(StreamError::Options(format!(
            "stream options out of range: rate {} Hz and move time factor {} above 0, lead {} s and tail {} s at least 0",
            opts.rate_hz, opts.move_time_factor, opts.lead_s, opts.tail_s
        )));
    }
    plan.check()
        .map_err(|(i, why)| StreamError::Options(format!("plan row {}: {why}", i + 1)))?;
    // The static simulation checks the truth against the machine and the poses.
    simulate(m, truth, &plan.record())?;
    let rows = &plan.rows;
    let n = rows.len();
    let times = timeline(plan, opts.move_time_factor);
    let commands: Vec<Vec<f64>> = rows.iter().map(|r| r.commands.clone()).collect();
    let directions = motion_directions(&commands);
    let middle = |i: usize| times[i].0 + (rows[i].middle_s() - rows[i].arrive_s);
    let (first, last) = (middle(0), middle(n - 1));
    let smooth = plan.kind == PlanKind::Static;
    let timed = truth
        .model
        .terms
        .iter()
        .any(|t| t.basis.of_time() || t.basis == Basis::Velocity);
    let end = times[n - 1].1;
    let total = opts.lead_s + end + opts.tail_s;
    let count = (total * opts.rate_hz).floor() as usize + 1;
    let vm = VirtualMachine::new(m);
    let n_axes = m.axes.len();
    let gain = truth.instrument();
    let (noise, phi) = (truth.noise_mm, truth.noise_phi);
    let innovation = noise * (1.0 - phi * phi).sqrt();
    let mut rng = Rng::new(truth.seed);
    let mut errors = vec![0.0; m.catalogue.len()];
    let mut offsets = [0.0; 3];
    let mut q = vec![0.0; n_axes];
    let mut velocity = vec![0.0; n_axes];
    let mut motion = vec![1i8; n_axes];
    let mut previous = [0.0; 3];
    let mut zero: Option<[f64; 3]> = None;
    let mut cached: Option<(usize, [f64; 3])> = None;
    let mut row = 0usize;
    let mut line = String::with_capacity(96);
    writeln!(
        out,
        "{},dx_um,dy_um,dz_um",
        if opts.unix_start.is_some() {
            "t_abs_s"
        } else {
            "t_s"
        }
    )?;
    for k in 0..count {
        let t_log = k as f64 / opts.rate_hz;
        let t = t_log - opts.lead_s;
        while row + 1 < n && t >= times[row + 1].0 {
            row += 1;
        }
        // At rest at `row` (before the program: at the first pose), or moving to the next.
        let rest = t <= times[row].1 || row + 1 == n;
        if rest {
            q.copy_from_slice(&commands[row]);
            velocity.fill(0.0);
            motion.copy_from_slice(&directions[row]);
        } else {
            let (from, to) = (&commands[row], &commands[row + 1]);
            let duration = times[row + 1].0 - times[row].1;
            let u = ((t - times[row].1) / duration).clamp(0.0, 1.0);
            let (s, ds) = if smooth {
                (u * u * (3.0 - 2.0 * u), 6.0 * u * (1.0 - u) / duration)
            } else {
                (u, 1.0 / duration)
            };
            for a in 0..n_axes {
                let d = to[a] - from[a];
                q[a] = from[a] + s * d;
                velocity[a] = d * ds / 1000.0;
                motion[a] = if d > 0.0 {
                    1
                } else if d < 0.0 {
                    -1
                } else {
                    directions[row][a]
                };
            }
        }
        let clean = match cached {
            Some((r, v)) if rest && !timed && r == row => v,
            _ => {
                let cx = BasisContext {
                    commands: &q,
                    motion: &motion,
                    tau: if last > first {
                        2.0 * (t - first) / (last - first) - 1.0
                    } else {
                        0.0
                    },
                    elapsed_s: t - first,
                    since_start_s: t.max(0.0),
                    velocity: &velocity,
                    reading: [0.0; 3],
                };
                truth.evaluate_into(m, &cx, &mut errors, &mut offsets);
                let value = |id: usize| errors[id];
                let tool = vm.transform_with(Side::Tool, &q, &truth.params, &value);
                let work = vm.transform_with(Side::Work, &q, &truth.params, &value);
                let gap = tool.translation.vector - work.translation.vector;
                let p = tool.rotation.inverse_transform_vector(&gap);
                let d = [p.x, p.y, p.z];
                let read =
                    |i: usize| d[i] + (0..3).map(|j| gain[i][j] * d[j]).sum::<f64>() + offsets[i];
                let v = [read(0), read(1), read(2)];
                if rest {
                    cached = Some((row, v));
                }
                v
            }
        };
        let mut r = clean;
        if noise > 0.0 {
            for (v, e) in r.iter_mut().zip(&mut previous) {
                *e = if k == 0 || phi == 0.0 {
                    noise * rng.normal()
                } else {
                    phi * *e + innovation * rng.normal()
                };
                *v += *e;
            }
        }
        if truth.zeroed {
            let z = *zero.get_or_insert(r);
            for (v, z) in r.iter_mut().zip(z) {
                *v -= z;
            }
        }
        line.clear();
        match opts.unix_start {
            Some(base) => {
                let whole = t_log.floor();
                let micros = ((t_log - whole) * 1e6).round() as u64;
                let (whole, micros) = if micros >= 1_000_000 {
                    (whole as u64 + 1, micros - 1_000_000)
                } else {
                    (whole as u64, micros)
                };
                line += &format!("{}.{micros:06}", base + whole);
            }
            None => line += &format_scaled(t_log, 0),
        }
        for v in r {
            line.push(',');
            line += &format_scaled(v, 3);
        }
        line.push('\n');
        out.write_all(line.as_bytes())?;
    }
    out.flush()?;
    Ok(StreamSummary {
        rows: count,
        program_start_s: opts.unix_start.map_or(0.0, |b| b as f64) + opts.lead_s,
        program_s: end,
    })
}
