//! Touch-probe plans: the probing poses of a kinematics calibration with a touch probe and a
//! calibration sphere, what they will determine, and how many positions per rotary axis a
//! target uncertainty needs (`docs/probe-plan.md`).
//!
//! **The poses.** As the controllers' own cycles measure (each rotary axis stepped over its
//! range with the others standing still): for every rotary axis, `N` positions of its turn
//! ([`simulation::generator`]'s `turn-R` interval: its range cut by the clearance rule's tilt,
//! the other rotary axes at their rest values). A full turn is divided into `N` equal steps
//! (`from + k·360°/N`, `k = 0 … N−1`: the end of a full turn is its start); a partial range
//! is divided into `N − 1` equal steps with both ends measured
//! (`from + k·(to − from)/(N − 1)`). The linear axes put the nominal tip centre on the nominal
//! sphere centre (nominal inverse kinematics at the plan's kinematic parameters).
//!
//! **The pattern** is the one the probing programs and the simulation use
//! ([`simulation::probe::approach_directions`], defined in the probe's frame): at the `i`-th
//! pose kept it is turned into the bed frame by the pose's nominal tool rotation and the
//! azimuth offset [`PatternAzimuth::Cycled`] gives pose `i` ([`PatternTurn`]), so the plan's
//! poses, written as a path and probed in that order (`rtest path --probe`,
//! `rtest simulate --probe`), are probed with the hits planned here.
//!
//! **Strokes, ranges and reach.** A pose is kept when its commands and the commands of each of
//! the nine hits of the pattern at the pose (at `R_sphere + r_tip`, the tip centres at the
//! latch) are within every axis's stroke and range and every hit can be probed
//! ([`simulation::probe::unreachable`]: none below the sphere's equator seen along the tool
//! axis, which the pattern turning with the probe never is, none within
//! [`simulation::probe::STEM_CLEARANCE_DEG`] of the sphere's stem); otherwise it is
//! **skipped**, with the reason (the hit and the axis or the rule), and the plan goes on with
//! the others. A plan with no pose left is refused.
//!
//! **The readings.** Each pose is one reading of the error vector `e` (tool frame, mm), as a
//! probe record gives it ([`crate::probe`]): the centre of the sphere fit of the pose's hits.
//! The pattern turns with the probe, so the centre's covariance in the tool frame is the
//! pattern's own, `C` (the free-radius fit's, [`RadiusMode::Free`] with the calibrated radius,
//! of the nine exact hits under the probe's σ, in the probe's frame), turned by the pose's
//! azimuth offset about the stylus: `R_z(φ₀)·C·R_z(φ₀)ᵀ`, the same at every pose to rounding
//! (the pattern is four-fold symmetric about the stylus). Each pose also carries its hits'
//! responses to pre-travel ([`crate::probe::pretravel_responses`] of the pattern at the pose),
//! as a probe record's poses do, so a model with the probe's lobing (`PRE@harmonic:3`) is
//! predicted too.
//!
//! **The prediction** is that of the campaign of one record (label [`PROBE_RECORD`], its own
//! sphere set-up, not zeroed) whose samples are the poses with those covariances, by
//! [`predict_with_covariances`]: the design matrix of the campaign fit and the weighting it
//! applies to readings with covariances, under an optional `zero:` constraint.
//!
//! **The valuation number** of a determined parameter is its target divided by its predicted
//! standard uncertainty ([`valuations`]); of a rotary axis, the least among the determined
//! parameters of interest that belong to it ([`axis_valuations`]). The controllers grade theirs:
//! at least [`NEEDED_VALUATION`] is needed, [`DESIRABLE_VALUATION`] or more desirable.
//! [`choose_per_axis`] finds the least `N` in [`MIN_PER_AXIS`]`..=`[`MAX_PER_AXIS`] whose every
//! determined parameter of interest has at least the valuation asked for.

use super::choose::{Targets, interest};
use super::predict::{Prediction, predict_with_covariances};
use crate::campaign::design::{Design, design_matrix};
use crate::campaign::names::single_record_names;
use crate::least_squares::{Constraint, EstimateError, Tolerances};
use crate::sphere::{Latch, RadiusMode, SphereFitOptions, fit_sphere};
use model_spec::units::short;
use model_spec::{AxisId, Machine};
use nalgebra::Matrix3;
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::exact::VirtualMachine;
use simulation::generator::{self, Clearance, TestKind};
use simulation::model::{Effect, Model};
use simulation::probe::{PatternAzimuth, PatternTurn, PoseFrame, approach_directions};
use simulation::record::{PreTravelResponse, Record, Sample};

/// The fewest positions per rotary axis (three points fix a circle).
pub const MIN_PER_AXIS: usize = 3;
/// The most positions per rotary axis: the bound of [`choose_per_axis`]'s search (a
/// controller's calibration cycle measures a handful of positions per axis).
pub const MAX_PER_AXIS: usize = 12;
/// The valuation number the controllers need at least.
pub const NEEDED_VALUATION: f64 = 2.0;
/// The valuation number the controllers call desirable.
pub const DESIRABLE_VALUATION: f64 = 4.0;
/// The label of the planned probe record (its set-up columns are `XOW[probe]`, …).
pub const PROBE_RECORD: &str = "probe";

/// The probe and the sphere of a plan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeSetup {
    /// The stylus tip's radius, mm.
    pub tip_radius_mm: f64,
    /// The calibration sphere's calibrated radius, mm.
    pub sphere_radius_mm: f64,
    /// The probe's noise σ along the approach, mm.
    pub noise_mm: f64,
}

impl ProbeSetup {
    /// `R_eff = R_sphere + r_tip`, mm: the radius of the tip centres at the latch.
    pub fn effective_radius_mm(&self) -> f64 {
        self.sphere_radius_mm + self.tip_radius_mm
    }
}

/// Why a probe plan cannot be made or predicted.
#[derive(Debug, thiserror::Error)]
pub enum ProbePlanError {
    /// The probe's numbers do not make a sphere fit (a radius or σ not above 0).
    #[error("the probe: {0}")]
    Probe(String),
    /// The number of positions per rotary axis is out of its bounds.
    #[error(
        "{0} positions per rotary axis: from {MIN_PER_AXIS} to {MAX_PER_AXIS} (three fix a circle; more than 12 is beyond what this planner searches)"
    )]
    PerAxis(usize),
    /// The machine has no rotary axis to step.
    #[error(
        "machine {0} has no rotary axis: a kinematics calibration with a probe steps the rotary axes"
    )]
    NoRotaryAxis(String),
    /// The kinematic parameters do not fit the machine.
    #[error(transparent)]
    Generator(#[from] generator::GeneratorError),
    /// Every pose is out of a stroke or cannot be reached.
    #[error(
        "no pose is left: every one of the {count} poses is out of a stroke or range or cannot be reached (first: {first})"
    )]
    NoPose {
        /// The poses tried.
        count: usize,
        /// The first pose's reason.
        first: String,
    },
    /// The design matrix or the prediction failed (too few readings for the parameters, a bad
    /// constraint, a covariance that cannot whiten).
    #[error(transparent)]
    Estimate(#[from] EstimateError),
}

/// The interval a rotary axis is stepped over: its `turn-R` interval.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisSweep {
    /// The rotary axis.
    pub axis: AxisId,
    /// Its first position, degrees.
    pub from_deg: f64,
    /// Its last position of the interval, degrees (for a full turn, `from + 360`, not measured).
    pub to_deg: f64,
    /// `true` when the interval is a full turn.
    pub full_turn: bool,
    /// Every axis's command while it steps (degrees for the other rotary axes, their rest
    /// values; linear axes 0, they follow the sphere).
    pub fixed_deg: Vec<f64>,
}

impl AxisSweep {
    /// The `n` positions of the axis, degrees: `from + k·360/n` for a full turn,
    /// `from + k·(to − from)/(n − 1)` otherwise (both ends), `k = 0 … n−1`.
    pub fn angles_deg(&self, n: usize) -> Vec<f64> {
        let span = self.to_deg - self.from_deg;
        (0..n)
            .map(|k| {
                if self.full_turn {
                    self.from_deg + k as f64 * 360.0 / n as f64
                } else if k + 1 == n {
                    self.to_deg
                } else {
                    self.from_deg + k as f64 * span / (n - 1).max(1) as f64
                }
            })
            .collect()
    }
}

/// The sweeps of `m`'s rotary axes (ISO order of the generator's turns) under `clearance`.
///
/// # Errors
/// [`ProbePlanError::NoRotaryAxis`] for a machine without one.
pub fn sweeps(m: &Machine, clearance: &Clearance) -> Result<Vec<AxisSweep>, ProbePlanError> {
    let out: Vec<AxisSweep> = generator::tests_with(m, clearance)
        .into_iter()
        .filter(|t| t.kind == TestKind::Turn)
        .map(|t| AxisSweep {
            axis: t.sweep.primary,
            from_deg: t.sweep.from_deg,
            to_deg: t.sweep.to_deg,
            full_turn: t.sweep.span_deg() >= 360.0 - 1e-9,
            fixed_deg: t.sweep.fixed_deg.clone(),
        })
        .collect();
    if out.is_empty() {
        return Err(ProbePlanError::NoRotaryAxis(m.name.clone()));
    }
    Ok(out)
}

/// The covariance of the fitted centre of the pattern's nine exact hits in the probe's frame
/// (at azimuth 0; on a table-table machine the bed frame), mm²: free radius, checked against
/// the calibrated one, under the probe's σ.
///
/// # Errors
/// [`ProbePlanError::Probe`] when the fit refuses (a radius or σ not above 0).
pub fn pattern_covariance(probe: &ProbeSetup) -> Result<Matrix3<f64>, ProbePlanError> {
    let r = probe.effective_radius_mm();
    let latches: Vec<Latch> = approach_directions()
        .into_iter()
        .map(|n| Latch {
            tip_mm: -n * r,
            approach: n,
        })
        .collect();
    let options = SphereFitOptions {
        radius: RadiusMode::Free {
            calibrated_mm: Some(probe.sphere_radius_mm),
        },
        tip_radius_mm: probe.tip_radius_mm,
        noise_mm: probe.noise_mm,
    };
    let ok = [probe.tip_radius_mm, probe.sphere_radius_mm, probe.noise_mm]
        .iter()
        .all(|x| x.is_finite() && *x > 0.0);
    if !ok {
        return Err(ProbePlanError::Probe(format!(
            "tip radius {} mm, sphere radius {} mm, σ {} mm: each must be a finite number above 0",
            probe.tip_radius_mm, probe.sphere_radius_mm, probe.noise_mm
        )));
    }
    let fit = fit_sphere(&latches, &options).map_err(|e| ProbePlanError::Probe(e.to_string()))?;
    Ok(fit.covariance_mm2)
}

/// One planned pose.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedPose {
    /// Its label: the stepped axis's letter and its angle (`C90`, `B-45`).
    pub label: String,
    /// The stepped rotary axis.
    pub axis: AxisId,
    /// Its position, degrees.
    pub angle_deg: f64,
    /// The commands (`Machine::axes` order; mm, rad).
    pub commands: Vec<f64>,
    /// The reading's covariance, tool frame, mm².
    pub covariance_mm2: [[f64; 3]; 3],
    /// Per hit of the pattern at the pose, the reading's response to its pre-travel
    /// ([`crate::probe::pretravel_responses`]): what a model's `PRE@harmonic:K` is made of.
    pub pretravel: Vec<PreTravelResponse>,
}

/// A pose left out, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct SkippedPose {
    /// Its label.
    pub label: String,
    /// The stepped rotary axis.
    pub axis: AxisId,
    /// Its position, degrees.
    pub angle_deg: f64,
    /// Why: the axis out of its stroke or range (and at which hit), or the inverse kinematics.
    pub reason: String,
}

/// The poses of a plan of `per_axis` positions per rotary axis.
#[derive(Clone, Debug, PartialEq)]
pub struct ProbePoses {
    /// Positions per rotary axis.
    pub per_axis: usize,
    /// The sweeps.
    pub sweeps: Vec<AxisSweep>,
    /// The poses kept, axis by axis, in measuring order.
    pub poses: Vec<PlannedPose>,
    /// The poses skipped.
    pub skipped: Vec<SkippedPose>,
}

/// The poses of `per_axis` positions on each of `sweeps` of `m` at the kinematic parameters
/// `params` (mm), with the pattern covariance `pattern_covariance` ([`pattern_covariance`],
/// probe frame, mm²) of a probe of effective radius `effective_radius_mm` (module
/// documentation: kept or skipped, the pattern turned pose by pose).
///
/// # Errors
/// [`ProbePlanError::PerAxis`] out of bounds; [`ProbePlanError::NoPose`] when every pose is
/// skipped.
pub fn probe_poses(
    m: &Machine,
    params: &[f64],
    sweeps: &[AxisSweep],
    per_axis: usize,
    effective_radius_mm: f64,
    pattern_covariance: &Matrix3<f64>,
) -> Result<ProbePoses, ProbePlanError> {
    if !(MIN_PER_AXIS..=MAX_PER_AXIS).contains(&per_axis) {
        return Err(ProbePlanError::PerAxis(per_axis));
    }
    let vm = VirtualMachine::new(m);
    let (mut poses, mut skipped) = (Vec::new(), Vec::new());
    for s in sweeps {
        for angle in s.angles_deg(per_axis) {
            let label = format!("{}{}", m.axes[s.axis].name, short(angle));
            let mut axes = s.fixed_deg.clone();
            axes[s.axis] = angle;
            let azimuth_rad = PatternAzimuth::Cycled.offset_rad(poses.len());
            match pose_at(&vm, params, &axes, azimuth_rad, effective_radius_mm) {
                Ok((geometry, pattern)) => {
                    let pretravel = crate::probe::pretravel_responses(
                        &geometry,
                        &pattern.approach_directions(),
                    );
                    let (sin, cos) = azimuth_rad.sin_cos();
                    let turn = Matrix3::new(cos, -sin, 0.0, sin, cos, 0.0, 0.0, 0.0, 1.0);
                    let c = turn * pattern_covariance * turn.transpose();
                    poses.push(PlannedPose {
                        label,
                        axis: s.axis,
                        angle_deg: angle,
                        commands: geometry.commands,
                        covariance_mm2: std::array::from_fn(|i| std::array::from_fn(|j| c[(i, j)])),
                        pretravel,
                    });
                }
                Err(reason) => skipped.push(SkippedPose {
                    label,
                    axis: s.axis,
                    angle_deg: angle,
                    reason,
                }),
            }
        }
    }
    if poses.is_empty() {
        return Err(ProbePlanError::NoPose {
            count: skipped.len(),
            first: skipped
                .first()
                .map(|s| format!("{}: {}", s.label, s.reason))
                .unwrap_or_default(),
        });
    }
    Ok(ProbePoses {
        per_axis,
        sweeps: sweeps.to_vec(),
        poses,
        skipped,
    })
}

/// The pose whose rotary axes stand at `axes` (degrees), probed with the pattern turned by
/// its nominal tool rotation and `azimuth_rad` (rad) about the stylus at `R_eff` =
/// `effective_radius_mm`, or why it is skipped: the inverse kinematics, an axis out of its
/// stroke or range at the centre or at a hit, a hit the probe cannot reach
/// ([`simulation::probe::unreachable`] at [`simulation::probe::STEM_CLEARANCE_DEG`]).
fn pose_at(
    vm: &VirtualMachine<'_>,
    params: &[f64],
    axes: &[f64],
    azimuth_rad: f64,
    effective_radius_mm: f64,
) -> Result<(PoseFrame, PatternTurn), String> {
    let m = vm.machine();
    let frame = crate::probe::pose_frame(vm, axes, params).map_err(|e| e.to_string())?;
    if let Some(o) = m.outside_limits(&frame.commands).first() {
        return Err(format!("{o} at the sphere's centre"));
    }
    let turn = PatternTurn::new(frame.tool_rotation.matrix(), azimuth_rad);
    for (h, n) in turn.approach_directions().iter().enumerate() {
        let point = -n;
        if let Some(why) = simulation::probe::unreachable(
            &point,
            &frame.tool_axis(),
            &frame.table_normal,
            simulation::probe::STEM_CLEARANCE_DEG,
        ) {
            return Err(format!("hit {} of the pattern: {why}", h + 1));
        }
        let q = frame.commands_at(&(point * effective_radius_mm));
        if let Some(o) = m.outside_limits(&q).first() {
            return Err(format!("{o} at hit {} of the pattern", h + 1));
        }
    }
    Ok((frame, turn))
}

/// The record of `poses`: one sample per pose (its commands, `t` its index in s, timed), no
/// readings, the poses' covariances and their hits' responses to pre-travel.
pub fn planned_record(poses: &ProbePoses, axes: usize) -> Record {
    let mut r = Record::default();
    for (i, p) in poses.poses.iter().enumerate() {
        r.samples.push(Sample {
            commands: p.commands.clone(),
            t: i as f64,
            motion: vec![1; axes],
            timed: true,
        });
        r.covariance.push(p.covariance_mm2);
        r.probe.push(p.pretravel.clone());
    }
    r
}

/// A probe plan made and predicted.
#[derive(Clone, Debug)]
pub struct ProbePlan {
    /// The poses.
    pub poses: ProbePoses,
    /// The campaign of one record ([`PROBE_RECORD`]).
    pub campaign: Campaign,
    /// Its design matrix.
    pub design: Design,
    /// The constraint, with the record's own names made the campaign's (`ZOW[probe]`).
    pub constraint: Constraint,
    /// Its prediction.
    pub prediction: Prediction,
}

/// What a plan is made of besides the number of positions.
#[derive(Clone, Copy, Debug)]
pub struct ProbePlanInputs<'a> {
    /// The machine.
    pub machine: &'a Machine,
    /// The model.
    pub model: &'a Model,
    /// The kinematic parameters, mm (symbol order).
    pub params: &'a [f64],
    /// The clearance rule the rotary intervals follow.
    pub clearance: &'a Clearance,
    /// The probe.
    pub probe: &'a ProbeSetup,
    /// Parameters fixed to 0 (or none).
    pub constraint: &'a Constraint,
    /// Rank tolerances.
    pub tol: &'a Tolerances,
}

impl ProbePlanInputs<'_> {
    /// The plan of `per_axis` positions per rotary axis, made and predicted.
    ///
    /// # Errors
    /// Bad parameters, probe or number of positions; no pose left; a design or prediction that
    /// fails (too few readings for the model's parameters, an unknown constrained name).
    pub fn plan(&self, per_axis: usize) -> Result<ProbePlan, ProbePlanError> {
        let m = self.machine;
        generator::check_params(m, self.params)?;
        if !(MIN_PER_AXIS..=MAX_PER_AXIS).contains(&per_axis) {
            return Err(ProbePlanError::PerAxis(per_axis));
        }
        let covariance = pattern_covariance(self.probe)?;
        // The pattern's equator hits (across the stylus) come within 90° − tilt of the
        // sphere's stem when the tool or the table tilts: tilts beyond 90° − the stem
        // clearance would skip the end poses.
        let clearance = Clearance {
            max_tilt_deg: self
                .clearance
                .max_tilt_deg
                .min(90.0 - simulation::probe::STEM_CLEARANCE_DEG),
            ..*self.clearance
        };
        let sweeps = sweeps(m, &clearance)?;
        let poses = probe_poses(
            m,
            self.params,
            &sweeps,
            per_axis,
            self.probe.effective_radius_mm(),
            &covariance,
        )?;
        let record = planned_record(&poses, m.axes.len());
        let campaign = Campaign::new(vec![CampaignRecord::new(
            PROBE_RECORD,
            record,
            self.params.to_vec(),
            PROBE_RECORD,
            false,
        )])
        .map_err(|e| EstimateError::Shape(e.to_string()))?;
        let design = design_matrix(m, self.model, &campaign)?;
        let constraint = single_record_names(m, self.model, &campaign, self.constraint.clone());
        let prediction = predict_with_covariances(&design, &campaign, &constraint, self.tol)?;
        Ok(ProbePlan {
            poses,
            campaign,
            design,
            constraint,
            prediction,
        })
    }
}

/// Per column of `p`, its valuation number `target / std` (the predicted standard uncertainty
/// in the unit people see against [`Targets::of`] that unit); `None` where it is not
/// determined.
pub fn valuations(m: &Machine, p: &Prediction, targets: &Targets) -> Vec<Option<f64>> {
    (0..p.names.len())
        .map(|j| {
            let term = &p.layout.columns[j].term;
            let std = p.std[j].filter(|_| p.determined[j])?;
            Some(targets.of(term.unit(m)) / (std * term.display_factor(m)))
        })
        .collect()
}

/// The valuation of one rotary axis.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisValuation {
    /// The rotary axis.
    pub axis: AxisId,
    /// Its columns of interest (its component and location errors), determined or not.
    pub columns: Vec<usize>,
    /// The least valuation among them and the column that has it; `None` when none is
    /// determined.
    pub least: Option<(usize, f64)>,
}

/// Per rotary axis of `m` (ISO order: A, B, C, then by letter), the least valuation among the parameters of interest
/// of `p` that belong to it (`values` from [`valuations`]).
pub fn axis_valuations(m: &Machine, p: &Prediction, values: &[Option<f64>]) -> Vec<AxisValuation> {
    let wanted = interest(p);
    let mut axes: Vec<AxisId> = m.rotary_axes().collect();
    axes.sort_by_key(|&a| model_spec::catalogue::iso_rank(&m.axes[a].name));
    axes.into_iter()
        .map(|axis| {
            let columns: Vec<usize> = wanted
                .iter()
                .copied()
                .filter(|&j| match p.layout.columns[j].term.effect {
                    Effect::Error(id) => m.catalogue[id].axis() == Some(axis),
                    _ => false,
                })
                .collect();
            let least = columns
                .iter()
                .filter_map(|&j| values[j].map(|v| (j, v)))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            AxisValuation {
                axis,
                columns,
                least,
            }
        })
        .collect()
}

/// How the controllers grade a valuation number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Grade {
    /// Below [`NEEDED_VALUATION`].
    Insufficient,
    /// At least [`NEEDED_VALUATION`], below [`DESIRABLE_VALUATION`].
    Sufficient,
    /// At least [`DESIRABLE_VALUATION`].
    Desirable,
}

impl Grade {
    /// The grade of valuation `v`.
    pub fn of(v: f64) -> Grade {
        if v >= DESIRABLE_VALUATION {
            Grade::Desirable
        } else if v >= NEEDED_VALUATION {
            Grade::Sufficient
        } else {
            Grade::Insufficient
        }
    }

    /// The grade in words (`below 2`, `2 or more`, `4 or more`).
    pub fn words(self) -> &'static str {
        match self {
            Grade::Insufficient => "below 2",
            Grade::Sufficient => "2 or more",
            Grade::Desirable => "4 or more",
        }
    }
}

/// One number of positions tried by [`choose_per_axis`].
#[derive(Clone, Debug, PartialEq)]
pub struct Tried {
    /// Positions per rotary axis.
    pub per_axis: usize,
    /// The least valuation among the determined parameters of interest and its column;
    /// `None` when the prediction had too few readings or nothing of interest is determined.
    pub least: Option<(usize, f64)>,
}

/// What [`choose_per_axis`] found.
#[derive(Clone, Debug)]
pub struct Choice {
    /// The plan chosen: the least `N` that meets the valuation, else [`MAX_PER_AXIS`].
    pub plan: ProbePlan,
    /// Whether its every determined parameter of interest has the valuation asked for.
    pub met: bool,
    /// Every `N` tried, from [`MIN_PER_AXIS`], up to the one chosen.
    pub tried: Vec<Tried>,
    /// The determined parameters of interest below the valuation in the plan chosen (columns).
    pub below: Vec<usize>,
}

/// The columns of interest of `p` determined with a valuation below `min_valuation`, and the
/// least valuation among the determined ones.
pub fn below(
    m: &Machine,
    p: &Prediction,
    targets: &Targets,
    min_valuation: f64,
) -> (Vec<usize>, Option<(usize, f64)>) {
    let values = valuations(m, p, targets);
    let wanted = interest(p);
    let low = wanted
        .iter()
        .copied()
        .filter(|&j| values[j].is_some_and(|v| v < min_valuation))
        .collect();
    let least = wanted
        .iter()
        .filter_map(|&j| values[j].map(|v| (j, v)))
        .min_by(|a, b| a.1.total_cmp(&b.1));
    (low, least)
}

/// The least number of positions per rotary axis, from [`MIN_PER_AXIS`] to [`MAX_PER_AXIS`],
/// that leaves no parameter of interest confounded and gives every determined one a valuation
/// of at least `min_valuation` against `targets`; [`MAX_PER_AXIS`] with `met` false when none has. A number whose
/// campaign has too few readings for the model's parameters does not meet it.
///
/// # Errors
/// As [`ProbePlanInputs::plan`], except too few readings below [`MAX_PER_AXIS`].
pub fn choose_per_axis(
    inputs: &ProbePlanInputs<'_>,
    targets: &Targets,
    min_valuation: f64,
) -> Result<Choice, ProbePlanError> {
    let m = inputs.machine;
    let mut tried = Vec::new();
    let mut n = MIN_PER_AXIS;
    loop {
        match inputs.plan(n) {
            Err(ProbePlanError::Estimate(EstimateError::TooFewReadings { .. }))
                if n < MAX_PER_AXIS =>
            {
                tried.push(Tried {
                    per_axis: n,
                    least: None,
                });
            }
            Err(e) => return Err(e),
            Ok(plan) => {
                let (low, least) = below(m, &plan.prediction, targets, min_valuation);
                tried.push(Tried { per_axis: n, least });
                // A parameter of interest the poses leave confounded is not met either (more
                // positions may separate it: a pose skipped at a range's end, say).
                let wanted = super::choose::interest(&plan.prediction);
                let confounded = plan
                    .prediction
                    .confounded
                    .iter()
                    .flatten()
                    .any(|j| wanted.contains(j));
                let met = low.is_empty() && least.is_some() && !confounded;
                if met || n >= MAX_PER_AXIS {
                    return Ok(Choice {
                        plan,
                        met,
                        tried,
                        below: low,
                    });
                }
            }
        }
        n += 1;
    }
}
