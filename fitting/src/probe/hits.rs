//! A probe hits file turned into a record: a sphere fit per pose, its centre as the pose's
//! reading of the error vector.

use super::pose::pose_frame;
use crate::sphere::{Latch, RadiusMode, SphereFit, SphereFitError, SphereFitOptions, fit_sphere};
use formats::csv::CsvError;
use formats::probe::{ProbeHits, ProbeInstrument, ProbePose};
use model_spec::Machine;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use simulation::exact::VirtualMachine;
use simulation::probe::{PoseFrame, PreTravel, approach_in_probe_frame};
use simulation::record::{PreTravelResponse, Record, Sample};

/// What reading a probe record needs besides its hits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeSettings {
    /// The stylus tip's radius, mm.
    pub tip_radius_mm: f64,
    /// The calibration sphere's calibrated radius, mm.
    pub sphere_radius_mm: f64,
    /// The probe's noise σ along the approach, mm, when declared.
    pub noise_mm: Option<f64>,
    /// The pre-travel declared for the probe, removed from every hit before the fit.
    pub declared: PreTravel,
    /// The largest magnitude of a reading's component, mm (as for R-test records).
    pub max_reading_mm: f64,
    /// The largest distance of a latched tip centre from the nominal sphere (`R_eff` about the
    /// nominal centre), mm: beyond it the hit is not on this sphere at this pose.
    pub off_sphere_mm: f64,
}

impl ProbeSettings {
    /// The settings of `probe` (its radii, σ and declared pre-travel), with the reading limit
    /// `max_reading_mm` (mm); a hit may be [`OFF_SPHERE_MM`] off the nominal sphere.
    pub fn of(probe: &ProbeInstrument, max_reading_mm: f64) -> Self {
        let lobing = probe.lobing_um.unwrap_or([0.0, 0.0]);
        ProbeSettings {
            tip_radius_mm: probe.tip_radius_mm,
            sphere_radius_mm: probe.sphere_radius_mm,
            noise_mm: probe.noise_um.map(|u| u * 1e-3),
            declared: PreTravel {
                constant_mm: probe.pre_travel_um.unwrap_or(0.0) * 1e-3,
                lobing_mm: [lobing[0] * 1e-3, lobing[1] * 1e-3],
            },
            max_reading_mm,
            off_sphere_mm: OFF_SPHERE_MM,
        }
    }

    /// `R_eff = R_sphere + r_tip`, mm.
    pub fn effective_radius_mm(&self) -> f64 {
        self.sphere_radius_mm + self.tip_radius_mm
    }
}

/// The default largest distance of a hit from the nominal sphere, mm (0.5 mm: far above any
/// error of a machine worth calibrating, far below a wrong sphere, pose or parameter).
pub const OFF_SPHERE_MM: f64 = 0.5;

/// One pose of a probe record, fitted.
#[derive(Clone, Debug, PartialEq)]
pub struct PoseFit {
    /// The pose's label.
    pub label: String,
    /// Its nominal commands (`Machine::axes` order; mm, rad): the rotary axes as probed, the
    /// linear axes putting the tip centre on the sphere's centre.
    pub commands: Vec<f64>,
    /// The line of its first hit (1-based; 0 when not read from a file).
    pub line: usize,
    /// The sphere fit, bed frame, about the nominal sphere centre (mm).
    pub fit: SphereFit,
    /// The pose's reading `e = −R_tool0ᵀ·c`, tool frame, mm.
    pub reading_mm: [f64; 3],
    /// Its covariance, tool frame, mm².
    pub covariance_mm2: [[f64; 3]; 3],
    /// Per hit, the change of the reading per mm of that hit's pre-travel (tool frame, mm/mm):
    /// the first-order response of the free sphere fit.
    pub pretravel_gain: Vec<Vector3<f64>>,
    /// Per hit, its approach direction in the probe's (tool) frame.
    pub approach_tool: Vec<Vector3<f64>>,
}

/// A probe record: the record the pipeline fits (with each pose's response to its hits'
/// pre-travel, [`Record::probe`]), with the fit of every pose.
#[derive(Clone, Debug)]
pub struct ProbeRecord {
    /// One sample per pose: nominal commands, the time of its first hit, the reading, its
    /// covariance, the line of its first hit.
    pub record: Record,
    /// Per pose, its sphere fit, in record order.
    pub poses: Vec<PoseFit>,
    /// The probe's σ the covariances use, mm.
    pub noise_mm: f64,
    /// The σ the fits' residuals give, pooled over the poses (`√(Σ r² / Σ dof)`), mm, when
    /// some pose has more hits than unknowns: the check of the declared σ.
    pub sigma_posterior_mm: Option<f64>,
    /// The constant pre-travel the fitted radii show beyond the declared one, `R_eff − R_fit`
    /// weighted over the poses, with its standard uncertainty (mm).
    pub pre_travel_mm: (f64, f64),
}

/// Reads `hits` (from `file`) of a probe on machine `m` at kinematic parameters `params` (mm):
/// one sphere fit per pose (free radius, checked against the calibrated one), its centre the
/// pose's reading (module documentation).
///
/// # Errors
/// [`CsvError::Format`] naming `file`, the line of the hit or pose and why: no declared σ, a
/// pose the nominal inverse kinematics cannot reach, a hit off the nominal sphere, a refused
/// sphere fit (with the rule and the hit), a reading beyond the limit.
pub fn probe_record(
    file: &str,
    m: &Machine,
    params: &[f64],
    hits: &ProbeHits,
    settings: &ProbeSettings,
) -> Result<ProbeRecord, CsvError> {
    let at = |line: usize, message: String| CsvError::Format {
        file: file.to_string(),
        line,
        column: None,
        message,
    };
    let first_line = hits
        .poses
        .first()
        .and_then(|p| p.hits.first())
        .map_or(0, |h| h.line);
    let Some(noise_mm) = settings.noise_mm else {
        return Err(at(
            first_line,
            "the probe instrument declares no noise_um: the sphere fits' refusal rule (largest residual above max(4σ, 5 µm)) and the centres' covariances need the probe's σ along the approach (its repeatability, µm)".into(),
        ));
    };
    let vm = VirtualMachine::new(m);
    let mut poses = Vec::with_capacity(hits.poses.len());
    let mut record = Record::default();
    for pose in &hits.poses {
        let fitted = fit_pose(&vm, params, pose, settings, noise_mm)
            .map_err(|(l, msg)| at(l, format!("pose `{}`: {msg}", pose.label)))?;
        let first = &pose.hits[0];
        if let Some(why) = reading_beyond("fitted centre", fitted.reading_mm, settings) {
            return Err(at(first.line, format!("pose `{}`: {why}", pose.label)));
        }
        record.samples.push(Sample {
            commands: fitted.commands.clone(),
            t: first.t_s,
            motion: vec![1; m.axes.len()],
            timed: true,
        });
        record.measured.push(fitted.reading_mm);
        record.covariance.push(fitted.covariance_mm2);
        record.lines.push(first.line);
        record.probe.push(
            fitted
                .pretravel_gain
                .iter()
                .zip(&fitted.approach_tool)
                .map(|(g, n)| response(g, n))
                .collect(),
        );
        poses.push(fitted);
    }
    let (rss, dof) = poses.iter().fold((0.0, 0usize), |(s, d), p| {
        (
            s + p.fit.residuals_mm.iter().map(|r| r * r).sum::<f64>(),
            d + p.fit.dof,
        )
    });
    set_rotary_motion(m, &mut record);
    let sigma_posterior_mm = (dof > 0).then(|| (rss / dof as f64).sqrt());
    Ok(ProbeRecord {
        record,
        pre_travel_mm: pre_travel(&poses, settings),
        poses,
        noise_mm,
        sigma_posterior_mm,
    })
}

/// The direction of motion of every rotary axis at each pose: that of its last move between
/// poses (an axis at rest keeps it; before its first move, the direction of that move), so
/// that a rotary axis's reversal (backlash) term sees the poses approached from either side.
/// Linear axes get +1: the hits of a pose approach the sphere along both directions of every
/// linear axis, so a linear axis's backlash moves the hits, not the centre (the H matrix
/// refuses a linear axis's reversal on probe records).
pub(super) fn set_rotary_motion(m: &Machine, record: &mut Record) {
    let commands: Vec<Vec<f64>> = record.samples.iter().map(|s| s.commands.clone()).collect();
    let motion = simulation::record::motion_directions(&commands);
    for (s, dirs) in record.samples.iter_mut().zip(motion) {
        for (a, d) in dirs.into_iter().enumerate() {
            s.motion[a] = if m.axes[a].kind == model_spec::AxisKind::Rotary {
                d
            } else {
                1
            };
        }
    }
}

/// Why a pose's reading `e` (tool frame, mm), from its `what` (`fitted centre`, `centre`), is
/// beyond the settings' limit in some direction: not a small error of the machine; `None`
/// within it.
pub(super) fn reading_beyond(what: &str, e: [f64; 3], settings: &ProbeSettings) -> Option<String> {
    let k = (0..3).find(|&k| e[k].abs() > settings.max_reading_mm)?;
    Some(format!(
        "the {what} gives a reading of {:.3} µm along {}, beyond the limit of {} µm: not a small error of the machine (a wrong sphere position, kinematic parameter or pose)",
        e[k] * 1e3,
        ["x", "y", "z"][k],
        settings.max_reading_mm * 1e3
    ))
}

/// The constant pre-travel the radii show: per pose `R_eff − R_fit` with the fit's radius
/// uncertainty, weighted (mm, and its standard uncertainty).
fn pre_travel(poses: &[PoseFit], settings: &ProbeSettings) -> (f64, f64) {
    let (mut sw, mut swx) = (0.0, 0.0);
    for p in poses {
        let s = p.fit.radius_std_mm.unwrap_or(f64::INFINITY);
        let w = 1.0 / (s * s);
        sw += w;
        swx += w * (settings.effective_radius_mm() - p.fit.effective_radius_mm);
    }
    if sw > 0.0 {
        (swx / sw, 1.0 / sw.sqrt())
    } else {
        (0.0, f64::INFINITY)
    }
}

/// The fit of one pose, or the line and why it is refused.
fn fit_pose(
    vm: &VirtualMachine<'_>,
    params: &[f64],
    pose: &ProbePose,
    settings: &ProbeSettings,
    noise_mm: f64,
) -> Result<PoseFit, (usize, String)> {
    let first = &pose.hits[0];
    let geometry = pose_frame(vm, &first.axes, params).map_err(|e| (first.line, e.to_string()))?;
    let r_eff = settings.effective_radius_mm();
    let mut latches = Vec::with_capacity(pose.hits.len());
    let mut approach_tool = Vec::with_capacity(pose.hits.len());
    for h in &pose.hits {
        let n = Vector3::from(h.direction);
        let n_tool = geometry.to_tool(&n);
        let g = geometry.gap(vm, &h.axes, params);
        let off = g.norm() - r_eff;
        if off.abs() > settings.off_sphere_mm {
            return Err((
                h.line,
                format!(
                    "the hit's tip centre is {:.3} mm from the nominal sphere centre, {:.3} mm off the sphere of radius R_sphere + r_tip = {} mm (limit {} mm): not a hit on this sphere at this pose (the sphere's position, the kinematic parameters, the probe's length or the radii are wrong)",
                    g.norm(),
                    off,
                    r_eff,
                    settings.off_sphere_mm
                ),
            ));
        }
        // A hit that pre-travelled by δ latched δ·n beyond the contact.
        let delta = settings.declared.along(geometry.tool_rotation.matrix(), &n);
        latches.push(Latch {
            tip_mm: g - delta * n,
            approach: n,
        });
        approach_tool.push(n_tool);
    }
    let options = SphereFitOptions {
        radius: RadiusMode::Free {
            calibrated_mm: Some(settings.sphere_radius_mm),
        },
        tip_radius_mm: settings.tip_radius_mm,
        noise_mm,
    };
    let fit = fit_sphere(&latches, &options).map_err(|e| refusal(pose, &e))?;
    let c = fit.centre_mm;
    let reading = -geometry.to_tool(&c);
    let r = geometry.tool_rotation.matrix();
    let cov: Matrix3<f64> = r.transpose() * fit.covariance_mm2 * r;
    let approaches: Vec<Vector3<f64>> = latches.iter().map(|l| l.approach).collect();
    let pretravel_gain = tool_gains(&geometry, &approaches);
    Ok(PoseFit {
        label: pose.label.clone(),
        commands: geometry.commands.clone(),
        line: first.line,
        reading_mm: [reading.x, reading.y, reading.z],
        covariance_mm2: [
            [cov[(0, 0)], cov[(0, 1)], cov[(0, 2)]],
            [cov[(1, 0)], cov[(1, 1)], cov[(1, 2)]],
            [cov[(2, 0)], cov[(2, 1)], cov[(2, 2)]],
        ],
        fit,
        pretravel_gain,
        approach_tool,
    })
}

/// A refused fit as the line of the hit it names (else the pose's first) and why, the hit
/// counted from 1 within the pose.
fn refusal(pose: &ProbePose, e: &SphereFitError) -> (usize, String) {
    let hit_at = |i: usize| {
        pose.hits.get(i).map_or(String::new(), |h| {
            format!("hit {} of the pose (line {})", i + 1, h.line)
        })
    };
    match e {
        SphereFitError::Residual {
            hit,
            residual_mm,
            limit_mm,
        } => {
            return (
                pose.hits.get(*hit).map_or(pose.hits[0].line, |h| h.line),
                format!(
                    "sphere fit refused (residual): {} is {:.3} µm off the fitted sphere (limit {:.3} µm = max(4σ, 5 µm)): a dirty hit (a chip or coolant on the sphere or the stylus), or a probe that latched on the way",
                    hit_at(*hit),
                    residual_mm * 1e3,
                    limit_mm * 1e3
                ),
            );
        }
        SphereFitError::Radius {
            fitted_mm,
            calibrated_mm,
            suspect,
        } => {
            return (
                suspect
                    .and_then(|i| pose.hits.get(i))
                    .map_or(pose.hits[0].line, |h| h.line),
                format!(
                    "sphere fit refused (radius): fitted sphere radius {fitted_mm:.6} mm, calibrated {calibrated_mm:.6} mm, {:.3} µm apart (limit {:.3} µm){}",
                    (fitted_mm - calibrated_mm) * 1e3,
                    crate::sphere::RADIUS_LIMIT_MM * 1e3,
                    suspect.map_or(
                        "; no single hit explains it: the tip's or the sphere's radius, or every hit, is off".to_string(),
                        |i| format!("; without {} the fit agrees", hit_at(i))
                    )
                ),
            );
        }
        _ => {}
    }
    (pose.hits[0].line, e.to_string())
}

/// Per hit of a pose of nominal frame `frame` whose approaches are `approaches` (unit, bed
/// frame, as aimed), how the pose's reading responds to the hit's pre-travel: what the term
/// `PRE@harmonic:K` of a model is made of, for a probe record ([`probe_record`]) and for a
/// planned pose alike.
pub fn pretravel_responses(
    frame: &PoseFrame,
    approaches: &[Vector3<f64>],
) -> Vec<PreTravelResponse> {
    tool_gains(frame, approaches)
        .iter()
        .zip(approaches)
        .map(|(g, n)| response(g, &frame.to_tool(n)))
        .collect()
}

/// The response of a hit whose reading gain is `gain` (tool frame, mm/mm) and whose approach
/// is `n_tool` (unit, tool frame).
fn response(gain: &Vector3<f64>, n_tool: &Vector3<f64>) -> PreTravelResponse {
    let (across, azimuth_rad) = approach_in_probe_frame(n_tool);
    PreTravelResponse {
        gain: [gain.x, gain.y, gain.z],
        across,
        azimuth_rad,
    }
}

/// Per hit, the change of the pose's reading (tool frame, mm per mm) when the hit latches
/// 1 mm farther along its approach: `−R_tool0ᵀ` times [`pretravel_gains`].
fn tool_gains(frame: &PoseFrame, approaches: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
    pretravel_gains(approaches)
        .into_iter()
        .map(|dc| -frame.to_tool(&dc))
        .collect()
}

/// Per hit, the fitted centre's first-order change (bed frame, mm per mm) when that hit
/// latches 1 mm farther along its approach (a pre-travel), the radius free: `Δx = (JᵀJ)⁻¹Jᵀ·e_i`
/// with the Jacobian rows `[n_iᵀ, −1]` of the residuals `‖p_i − c‖ − R` for hits aimed at the
/// centre (outward normal `u_i = −n_i`), whose residual a pre-travel δ changes by `−δ`.
/// Evaluated at the pattern as aimed (not at the latched points, which the machine's errors
/// move by microns): a response of the pattern alone, so two poses whose approaches are the
/// same in the tool frame get the same response to the digit, and what a pose set cannot
/// separate stays exactly confounded.
fn pretravel_gains(approaches: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
    let n = approaches.len();
    let mut j = DMatrix::zeros(n, 4);
    for (i, a) in approaches.iter().enumerate() {
        let u = -a.normalize();
        for k in 0..3 {
            j[(i, k)] = -u[k];
        }
        j[(i, 3)] = -1.0;
    }
    let jtj = j.transpose() * &j;
    let Some(inv) = jtj.try_inverse() else {
        return vec![Vector3::zeros(); n];
    };
    let pinv = inv * j.transpose();
    (0..n)
        .map(|i| {
            let mut dr = DVector::zeros(n);
            dr[i] = -1.0;
            let dx = -(&pinv * dr);
            Vector3::new(dx[0], dx[1], dx[2])
        })
        .collect()
}
