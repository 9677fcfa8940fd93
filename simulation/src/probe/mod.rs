//! Simulated touch-probe hits: the exact virtual machine with a [`Truth`] probing a calibration
//! sphere at a sequence of poses (`docs/probe-simulation.md`).
//!
//! **Frames and points.** Everything is in the bed (machine) frame of the description. The
//! tool point is the probe's tip centre (the tool chain's end), the workpiece point the
//! sphere's centre (the work chain's end: the ball position `Xw, Yw, Zw` and its set-up errors
//! `XOW YOW ZOW`). The gap `P_tool − P_work` is the tip centre seen from the sphere's centre;
//! a tip of radius `r_tip` touches a sphere of radius `R_sphere` when
//! `‖gap‖ = R_eff = R_sphere + r_tip`. Nominal: every error zero, the plan's parameters.
//!
//! **A pose.** The rotary commands of a pose are kept; the linear ones come from the nominal
//! tool-centre-point inverse kinematics (the nominal tip centre on the nominal sphere centre).
//! With the rotary axes still, the nominal gap is affine in the linear commands, `A·q + b`,
//! the columns of `A` (bed frame, mm/mm) from the exact chains ([`PoseFrame`], the nominal
//! frame the programs, the plans and the reading of probe records share).
//!
//! **The pattern.** The nine approach directions of [`approach_directions`] are defined in the
//! probe's (tool) frame and turned into the bed frame at every pose by its nominal tool
//! rotation and an azimuth offset about the stylus ([`PatternTurn`]: `n = R_tool·R_z(φ₀)·d`,
//! `φ₀` by [`ProbeSettings::azimuth`] and the pose's index); on a table-table machine at
//! azimuth 0 they are the bed-frame directions bit for bit.
//!
//! **A hit.** For each approach direction `n` of the pattern at the pose the probe starts where the nominal gap is `−n·(R_eff + CLEARANCE_MM)` and
//! moves so that the nominal gap changes by `s·n`: the linear commands change by `s·A⁻¹·n`.
//! The contact is the `s` where the actual gap, with the truth's errors evaluated at the
//! commands there (and the motion, times and velocities of the approach) and the tip centre
//! off the tool point by the truth's zero offsets (below), has the norm `R_eff`
//! (a safeguarded Newton iteration). The probe latches `δ + ε` later along the approach: `δ` its pre-travel
//! ([`PreTravel`], in the probe's frame), `ε` Gaussian noise of σ `noise_mm` (one standard
//! normal draw of [`Rng::new`]`(seed)` per hit, in hit order; none when σ is 0). The latched
//! commands are those at `s + δ + ε` on the same line of commands: the nominal gap moved by
//! `(δ + ε)·n`; the actual tip moves by that plus the change of the errors over `δ + ε`, a
//! second-order difference (`δ` times the errors' gradient along the approach: about 1e-5 of
//! `δ` on the test truths).
//!
//! **Directions of motion.** The sequence of moves is: for every hit, the approach (from the
//! start point to the latch), the retract (back to the start point), then a straight move to
//! the next hit's start point (at a new pose, with the rotary axes). At the latch an axis
//! that moves in the approach moves in the sign of its command change; an axis at rest keeps
//! the direction of its last move (of the retract or the move before); before its first move
//! an axis has the direction of its first move, as [`crate::record::motion_directions`] says.
//! Moves smaller than [`MOVE_EPS`] are no moves. So a truth's `reversal` terms act as real
//! backlash does.
//!
//! **Clock.** [`latch_time_s`]: a hit cycle takes [`HIT_CYCLE_S`], a pose change
//! [`POSE_CHANGE_S`], a latch comes [`APPROACH_S`] after its approach starts. `τ` of the
//! truth's `time:K` terms runs from −1 at the first latch to 1 at the last.
//!
//! **The truth's zero offsets and instrument terms.** The truth's `dx0 dy0 dz0` (a probe's
//! `px0 py0 pz0`) put the tip centre off the tool point by `(dx0, dy0, dz0)` in the actual
//! tool frame, `P_tip = P_tool + R_tool·o`: the probe's length and centring errors. A sphere
//! fit then reads `e + o`, as an R-test reads its zero offsets. The R-test's instrument terms
//! (`SXX` …) act on sensor readings a probe has not, and its reading noise (σ, φ, zeroing) is
//! not the probe's: the simulation does not use them ([`unused_terms`] names the terms for a
//! note).

mod contact;
mod frame;
mod pattern;
mod reach;

pub use contact::{CONTACT_TOLERANCE_MM, MAX_CONTACT_ITERATIONS};
pub use frame::PoseFrame;
pub use pattern::{
    APPROACH_S, AZIMUTH_CYCLE_DEG, CLEARANCE_MM, HIT_CYCLE_S, PATTERN_HITS, POSE_CHANGE_S,
    PROBING_FEED_MM_PER_S, PatternAzimuth, PatternTurn, PreTravel, approach_directions,
    approach_in_probe_frame, latch_time_s, run_time_s,
};
pub use reach::{STEM_CLEARANCE_DEG, below_equator, near_stem, unreachable};

use crate::exact::{ExactError, VirtualMachine};
use crate::model::{BasisContext, Effect};
use crate::rng::Rng;
use crate::truth::Truth;
use contact::{Approach, ContactFailure};
use model_spec::Machine;
use model_spec::pose::PoseError;
use model_spec::units::short;
use nalgebra::Vector3;

/// A command change smaller than this (mm or rad) is no move, for the directions of motion.
pub const MOVE_EPS: f64 = 1e-9;

/// The probe and its sphere, as the simulation uses them (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeSettings {
    /// The stylus tip's radius `r_tip`, mm (above 0).
    pub tip_radius_mm: f64,
    /// The calibration sphere's radius `R_sphere`, mm (above 0).
    pub sphere_radius_mm: f64,
    /// The probe's pre-travel (mm).
    pub pre_travel: PreTravel,
    /// The probe's noise σ along the approach, mm (0: exact hits).
    pub noise_mm: f64,
    /// The seed of the noise generator.
    pub seed: u64,
    /// How the pattern turns about the stylus from pose to pose.
    pub azimuth: PatternAzimuth,
}

impl ProbeSettings {
    /// `R_eff = R_sphere + r_tip`, mm.
    pub fn effective_radius_mm(&self) -> f64 {
        self.sphere_radius_mm + self.tip_radius_mm
    }
}

/// One simulated hit.
#[derive(Clone, Debug, PartialEq)]
pub struct SimulatedHit {
    /// The approach direction, unit, bed frame.
    pub approach: Vector3<f64>,
    /// The commands at the start point of the approach (mm, rad).
    pub start: Vec<f64>,
    /// The commands at the exact contact (mm, rad).
    pub contact: Vec<f64>,
    /// The latched commands (mm, rad): the contact's plus `(pre_travel_mm + noise_mm)` along
    /// the approach.
    pub latched: Vec<f64>,
    /// The direction of motion of every axis at the latch (+1 or −1).
    pub motion: Vec<i8>,
    /// The velocity of every axis during the approach (mm/ms, rad/ms; the rotary axes 0).
    pub velocity: Vec<f64>,
    /// The time of the latch, s ([`latch_time_s`]).
    pub t_s: f64,
    /// τ of the latch over the run, in [−1, 1].
    pub tau: f64,
    /// The time since the first latch, s.
    pub elapsed_s: f64,
    /// The pre-travel of this approach, mm.
    pub pre_travel_mm: f64,
    /// The noise drawn for this hit, mm.
    pub noise_mm: f64,
    /// The distance from the start point to the contact along the approach, mm (about
    /// [`CLEARANCE_MM`]).
    pub contact_distance_mm: f64,
    /// Iterations of the contact solve.
    pub iterations: usize,
}

impl SimulatedHit {
    /// The context the truth's errors are evaluated in at the latch (at `commands`).
    pub fn context<'a>(&'a self, commands: &'a [f64]) -> BasisContext<'a> {
        BasisContext {
            commands,
            motion: &self.motion,
            tau: self.tau,
            elapsed_s: self.elapsed_s,
            since_start_s: self.t_s,
            velocity: &self.velocity,
            reading: [0.0; 3],
        }
    }
}

/// The hits of one pose.
#[derive(Clone, Debug, PartialEq)]
pub struct SimulatedPose {
    /// The pose's nominal frame: its commands (the nominal tip centre on the nominal sphere
    /// centre), tool rotation and linear map.
    pub frame: PoseFrame,
    /// The turn of the pattern into the bed frame at the pose.
    pub turn: PatternTurn,
    /// The hits, in the pattern's order.
    pub hits: Vec<SimulatedHit>,
}

/// A simulated probe run.
#[derive(Clone, Debug, PartialEq)]
pub struct ProbeRun {
    /// The poses, in order.
    pub poses: Vec<SimulatedPose>,
    /// The time of the run, s ([`run_time_s`]).
    pub duration_s: f64,
}

impl ProbeRun {
    /// The number of hits, all poses together.
    pub fn hit_count(&self) -> usize {
        self.poses.iter().map(|p| p.hits.len()).sum()
    }
}

/// The label of pose `i` (0-based) of a run: `p1`, `p2`, … (the pose of the path's sample
/// `i + 1`).
pub fn pose_label(i: usize) -> String {
    format!("p{}", i + 1)
}

/// Why a probe run could not be simulated.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ProbeError {
    /// The settings are not a probe (radius not above 0, noise or pre-travel not finite …).
    #[error("probe: {0}")]
    Settings(String),
    /// The truth does not fit the machine.
    #[error("truth {source_name} does not fit machine {machine}: {why}")]
    Truth {
        /// The truth's source.
        source_name: String,
        /// The machine.
        machine: String,
        /// What does not fit.
        why: String,
    },
    /// No pose, or a pose that is not one command per axis.
    #[error("{0}")]
    Poses(String),
    /// The inverse kinematics fails at a pose.
    #[error("pose {label}: {source}", label = pose_label(*pose))]
    Kinematics {
        /// The pose (0-based).
        pose: usize,
        /// Why.
        source: ExactError,
    },
    /// A start point or a latch beyond an axis's limits.
    #[error("pose {label}, hit {hit_no} (approach {dir}): the {what} {source}", label = pose_label(*pose), hit_no = hit + 1, dir = direction(approach))]
    Limits {
        /// The pose (0-based).
        pose: usize,
        /// The hit within the pose (0-based).
        hit: usize,
        /// Its approach direction (bed frame).
        approach: Vector3<f64>,
        /// `start point` or `latch`.
        what: &'static str,
        /// The axis and its limits.
        source: PoseError,
    },
    /// The contact could not be found.
    #[error("pose {label}, hit {hit_no} (approach {dir}): {why}", label = pose_label(*pose), hit_no = hit + 1, dir = direction(approach))]
    Contact {
        /// The pose (0-based).
        pose: usize,
        /// The hit within the pose (0-based).
        hit: usize,
        /// Its approach direction (bed frame).
        approach: Vector3<f64>,
        /// Why.
        why: String,
    },
}

/// `(x, y, z)` of a direction, compactly, for messages.
fn direction(n: &Vector3<f64>) -> String {
    let c = |x: f64| short((x * 1e6).round() / 1e6 + 0.0);
    format!("({}, {}, {})", c(n.x), c(n.y), c(n.z))
}

/// The terms of `truth` a probe simulation does not use, by name (empty when it has none):
/// every term that is neither a machine error nor a zero offset (the R-test's instrument
/// terms).
pub fn unused_terms(m: &Machine, truth: &Truth) -> Vec<String> {
    truth
        .model
        .terms
        .iter()
        .filter(|t| !matches!(t.effect, Effect::Error(_) | Effect::SensorOffset(_)))
        .map(|t| t.effect.name(m))
        .collect()
}

/// Simulates the probe `probe` on machine `m` (planned with the kinematic parameters
/// `nominal_params`, mm) with the truth `truth` at `poses` (one command vector per pose, mm and
/// rad; the rotary entries are kept, the linear ones replaced by the inverse kinematics). See
/// the module documentation.
///
/// # Errors
/// [`ProbeError`]: settings that are not a probe, a truth that does not fit `m`, no pose, the
/// inverse kinematics failing at a pose, a start point or latch beyond an axis's limits, a
/// contact not found (the errors larger than [`CLEARANCE_MM`] or than `R_eff`, or a solve not
/// converged).
pub fn simulate_probe(
    m: &Machine,
    nominal_params: &[f64],
    truth: &Truth,
    poses: &[Vec<f64>],
    probe: &ProbeSettings,
) -> Result<ProbeRun, ProbeError> {
    check(m, nominal_params, truth, poses, probe)?;
    let vm = VirtualMachine::new(m);
    let r = probe.effective_radius_mm();
    // The nominal frame, the pattern's turn and per hit the start point and command step of
    // every pose.
    let mut geometry = Vec::with_capacity(poses.len());
    for (p, given) in poses.iter().enumerate() {
        let frame = PoseFrame::at(&vm, given, nominal_params)
            .map_err(|source| ProbeError::Kinematics { pose: p, source })?;
        let turn = PatternTurn::new(frame.tool_rotation.matrix(), probe.azimuth.offset_rad(p));
        let mut hits = Vec::with_capacity(PATTERN_HITS);
        for (k, n) in turn.approach_directions().iter().enumerate() {
            let start = frame.commands_at(&(-n * (r + CLEARANCE_MM)));
            let step = frame.command_change(n);
            let start_ok = m.check_pose(&start);
            if let Err(source) = start_ok {
                return Err(ProbeError::Limits {
                    pose: p,
                    hit: k,
                    approach: *n,
                    what: "start point",
                    source,
                });
            }
            hits.push((*n, start, step));
        }
        geometry.push((frame, turn, hits));
    }
    let motion = directions_at_latches(m, &geometry);
    let total = poses.len() * PATTERN_HITS;
    let (t_first, t_last) = (latch_time_s(0, 0), latch_time_s(poses.len() - 1, total - 1));
    let mut rng = Rng::new(probe.seed);
    let mut out = Vec::with_capacity(poses.len());
    let mut k_all = 0;
    for (p, (frame, turn, starts)) in geometry.into_iter().enumerate() {
        let mut hits = Vec::with_capacity(PATTERN_HITS);
        for (k, (n, start, step)) in starts.into_iter().enumerate() {
            let t_s = latch_time_s(p, k_all);
            let tau = if t_last > t_first {
                2.0 * (t_s - t_first) / (t_last - t_first) - 1.0
            } else {
                0.0
            };
            let velocity: Vec<f64> = step
                .iter()
                .map(|d| d * PROBING_FEED_MM_PER_S / 1000.0)
                .collect();
            let approach = Approach {
                vm: &vm,
                truth,
                start: &start,
                step: &step,
                approach: n,
                motion: &motion[k_all],
                velocity: &velocity,
                times: [tau, t_s - t_first, t_s],
                radius_mm: r,
            };
            let fail = |why: String| ProbeError::Contact {
                pose: p,
                hit: k,
                approach: n,
                why,
            };
            let (s, iterations) = approach
                .contact(r + CLEARANCE_MM)
                .map_err(|e| fail(failure(e)))?;
            let delta = probe.pre_travel.along(frame.tool_rotation.matrix(), &n);
            let noise = if probe.noise_mm > 0.0 {
                probe.noise_mm * rng.normal()
            } else {
                0.0
            };
            let mut contact = vec![0.0; m.axes.len()];
            approach.commands_at(s, &mut contact);
            let mut latched = vec![0.0; m.axes.len()];
            approach.commands_at(s + delta + noise, &mut latched);
            if let Err(source) = m.check_pose(&latched) {
                return Err(ProbeError::Limits {
                    pose: p,
                    hit: k,
                    approach: n,
                    what: "latch",
                    source,
                });
            }
            hits.push(SimulatedHit {
                approach: n,
                motion: motion[k_all].clone(),
                start,
                contact,
                latched,
                velocity,
                t_s,
                tau,
                elapsed_s: t_s - t_first,
                pre_travel_mm: delta,
                noise_mm: noise,
                contact_distance_mm: s,
                iterations,
            });
            k_all += 1;
        }
        out.push(SimulatedPose { frame, turn, hits });
    }
    Ok(ProbeRun {
        poses: out,
        duration_s: run_time_s(poses.len(), total),
    })
}

/// The message of a contact not found.
fn failure(e: ContactFailure) -> String {
    let um = |x: f64| model_spec::units::format_scaled(x, 3);
    match e {
        ContactFailure::StartsInside(d) => format!(
            "the start point, {CLEARANCE_MM} mm outside the nominal sphere, is {} µm inside the actual sphere: the machine's errors move the sphere by more than the clearance",
            um(d + 0.0)
        ),
        ContactFailure::NeverTouches(d) => format!(
            "the probe reaches the nominal sphere centre without touching: the tip centre is {d} mm from the actual sphere centre there, beyond R_eff; the machine's errors move the sphere by more than its radius"
        ),
        ContactFailure::NotConverged(step) => format!(
            "the contact did not converge in {MAX_CONTACT_ITERATIONS} iterations (last step {step:e} mm)"
        ),
    }
}

/// A pose's nominal frame, the pattern's turn and per hit its approach direction (bed frame),
/// start point and command step.
type PoseGeometry = (
    PoseFrame,
    PatternTurn,
    Vec<(Vector3<f64>, Vec<f64>, Vec<f64>)>,
);

/// The direction of motion of every axis at every latch, in hit order over the run (see the
/// module documentation): approach, retract, straight to the next start point.
fn directions_at_latches(m: &Machine, geometry: &[PoseGeometry]) -> Vec<Vec<i8>> {
    let n_axes = m.axes.len();
    // Every move in order, and the index of each hit's approach among them.
    let mut moves: Vec<Vec<f64>> = Vec::new();
    let mut approaches = Vec::new();
    let mut previous: Option<(&[f64], &[f64])> = None;
    for (_, _, hits) in geometry {
        for (_, start, step) in hits {
            if let Some((s0, d0)) = previous {
                moves.push(d0.iter().map(|d| -d * CLEARANCE_MM).collect());
                moves.push(start.iter().zip(s0).map(|(a, b)| a - b).collect());
            }
            approaches.push(moves.len());
            moves.push(step.iter().map(|d| d * CLEARANCE_MM).collect());
            previous = Some((start, step));
        }
    }
    let sign = |d: f64| (d.abs() > MOVE_EPS).then_some(if d > 0.0 { 1i8 } else { -1 });
    let mut current: Vec<i8> = (0..n_axes)
        .map(|a| moves.iter().find_map(|mv| sign(mv[a])).unwrap_or(1))
        .collect();
    let mut out = Vec::with_capacity(approaches.len());
    let mut next = approaches.iter().peekable();
    for (i, mv) in moves.iter().enumerate() {
        for (c, d) in current.iter_mut().zip(mv) {
            if let Some(s) = sign(*d) {
                *c = s;
            }
        }
        if next.peek() == Some(&&i) {
            out.push(current.clone());
            next.next();
        }
    }
    out
}

/// The checks of the inputs.
fn check(
    m: &Machine,
    nominal_params: &[f64],
    truth: &Truth,
    poses: &[Vec<f64>],
    probe: &ProbeSettings,
) -> Result<(), ProbeError> {
    let settings = |why: String| Err(ProbeError::Settings(why));
    let positive = |x: f64| x.is_finite() && x > 0.0;
    if !positive(probe.tip_radius_mm) || !positive(probe.sphere_radius_mm) {
        return settings(format!(
            "the tip radius ({} mm) and the sphere radius ({} mm) must be finite and above 0",
            probe.tip_radius_mm, probe.sphere_radius_mm
        ));
    }
    if !(probe.noise_mm.is_finite() && probe.noise_mm >= 0.0) {
        return settings(format!(
            "the noise σ ({} mm) must be finite and at least 0",
            probe.noise_mm
        ));
    }
    let PreTravel {
        constant_mm,
        lobing_mm: [c, s],
    } = probe.pre_travel;
    if ![constant_mm, c, s].iter().all(|x| x.is_finite()) {
        return settings("the pre-travel must be finite".into());
    }
    if constant_mm.abs() + c.hypot(s) >= CLEARANCE_MM {
        return settings(format!(
            "a pre-travel of up to {} mm reaches the clearance of {CLEARANCE_MM} mm",
            constant_mm.abs() + c.hypot(s)
        ));
    }
    if nominal_params.len() != m.symbols.len() {
        return Err(ProbeError::Poses(format!(
            "machine {}: {} kinematic parameters for {} symbols",
            m.name,
            nominal_params.len(),
            m.symbols.len()
        )));
    }
    if poses.is_empty() {
        return Err(ProbeError::Poses("no pose to probe".into()));
    }
    if let Some(i) = poses.iter().position(|q| q.len() != m.axes.len()) {
        return Err(ProbeError::Poses(format!(
            "pose {} has {} commands, machine {} has {} axes",
            pose_label(i),
            poses[i].len(),
            m.name,
            m.axes.len()
        )));
    }
    check_truth(m, truth)
}

/// The truth fits `m`: one parameter per symbol, one coefficient per model column, error
/// effects of its catalogue, terms valid on it.
fn check_truth(m: &Machine, truth: &Truth) -> Result<(), ProbeError> {
    let bad = |why: String| ProbeError::Truth {
        source_name: truth.source.clone(),
        machine: m.name.clone(),
        why,
    };
    truth.fits(m).map_err(bad)
}
