//! A [`Sweep`] made into samples: the rotary commands of every sample, the linear axes that
//! follow the ball (nominal tool-centre-point inverse kinematics at the kinematic parameters
//! given), and the checks every sample must pass: strokes and ranges, the tilt of the clearance
//! rule, the nest on the ball.

use super::catalogue::{Sweep, TestKind, TestSpec};
use super::clearance::{Clearance, TILT_TOLERANCE_DEG, TiltGauge, round_inward};
use super::{GeneratorError, SampleError, SamplePlace, SampleProblem};
use crate::exact::VirtualMachine;
use crate::paths::record_from_commands;
use crate::record::Record;
use model_spec::pose::PoseError;
use model_spec::{AxisKind, Machine};

/// The largest distance between the nominal tool point and the nominal workpiece point at a
/// generated sample, mm: the inverse kinematics puts them together to rounding (1e-12 mm and
/// below); beyond this the computation failed.
pub const ON_BALL_ROUNDING_MM: f64 = 1e-6;

/// The number of equal steps of at most `step_deg` over `span_deg` (degrees, both above 0): the
/// quotient when it is a whole number to within 1e-9 of itself, else the next whole number; at
/// least 1.
pub fn steps(span_deg: f64, step_deg: f64) -> usize {
    let r = span_deg / step_deg;
    let n = if (r - r.round()).abs() <= 1e-9 * r.max(1.0) {
        r.round()
    } else {
        r.ceil()
    };
    // `as` saturates; the caller bounds the count before it is used.
    (n as usize).max(1)
}

/// The commands in degrees (per sample, one per axis; linear axes 0) of `sweep` in `n` equal
/// steps, the follower's excursion scaled by `scale` (1: as planned).
///
/// Sample `i` has the primary at `from + i·(to − from)/n` (the last exactly at `to`), the
/// follower at `base + scale·amplitude·(1 − cos φ)` with `φ = (360°·(p − from)/(to − from))`
/// converted to radians, and every other rotary axis at its fixed value.
pub(crate) fn degrees(sweep: &Sweep, n: usize, scale: f64) -> Vec<Vec<f64>> {
    let span = sweep.span_deg();
    let h = span / n as f64;
    let turns = 360.0 / span;
    (0..=n)
        .map(|i| {
            let mut q = sweep.fixed_deg.clone();
            let p = if i == n {
                sweep.to_deg
            } else {
                sweep.from_deg + i as f64 * h
            };
            q[sweep.primary] = p;
            if let Some(f) = &sweep.follower {
                let phase = ((p - sweep.from_deg) * turns).to_radians();
                q[f.axis] = f.base_deg + scale * f.amplitude_deg * (1.0 - phase.cos());
            }
            q
        })
        .collect()
}

/// Degrees to commands (rad for rotary axes; linear entries 0, filled later).
fn to_commands(m: &Machine, deg: &[f64]) -> Vec<f64> {
    deg.iter()
        .zip(&m.axes)
        .map(|(&d, a)| match a.kind {
            AxisKind::Rotary => d.to_radians(),
            AxisKind::Linear => 0.0,
        })
        .collect()
}

/// The first sample (index) of `poses` (degrees) whose tilt exceeds the rule, with the tilt.
fn first_tilted(
    m: &Machine,
    gauge: &TiltGauge,
    poses: &[Vec<f64>],
    max_tilt_deg: f64,
) -> Option<(usize, f64)> {
    poses.iter().enumerate().find_map(|(i, d)| {
        let tilt = gauge.tilt_deg(&to_commands(m, d));
        (tilt > max_tilt_deg + TILT_TOLERANCE_DEG).then_some((i, tilt))
    })
}

/// The rotary commands (degrees) of the pair test `spec` in `n` steps, its follower's
/// excursion reduced, where the two axes together would tilt the tool axis too far, to the
/// largest fraction (1e-6° of excursion, by bisection) that keeps every sample within the rule.
fn pair_degrees(
    m: &Machine,
    gauge: &TiltGauge,
    spec: &TestSpec,
    n: usize,
    clearance: &Clearance,
) -> Vec<Vec<f64>> {
    let poses = degrees(&spec.sweep, n, 1.0);
    let Some(f) = spec.sweep.follower else {
        return poses;
    };
    if spec.kind != TestKind::Pair
        || first_tilted(m, gauge, &poses, clearance.max_tilt_deg).is_none()
    {
        return poses;
    }
    let fits = |scale: f64| {
        first_tilted(
            m,
            gauge,
            &degrees(&spec.sweep, n, scale),
            clearance.max_tilt_deg,
        )
        .is_none()
    };
    let (mut ok, mut bad) = (0.0, 1.0);
    for _ in 0..48 {
        let mid = 0.5 * (ok + bad);
        if fits(mid) {
            ok = mid;
        } else {
            bad = mid;
        }
    }
    // The excursion on a 1e-6° grid, towards zero.
    let excursion = 2.0 * f.amplitude_deg * ok;
    let grid = round_inward(excursion.abs(), false).copysign(excursion);
    let scale = if f.amplitude_deg == 0.0 {
        0.0
    } else {
        grid / (2.0 * f.amplitude_deg)
    };
    degrees(&spec.sweep, n, scale)
}

/// The pose of sample `i` for messages: the rotary axes in degrees (`A = 0°, C = 12°`).
fn pose_text(m: &Machine, deg: &[f64]) -> String {
    let mut rotary: Vec<usize> = m.rotary_axes().collect();
    rotary.sort_by_key(|&a| model_spec::catalogue::iso_rank(&m.axes[a].name));
    rotary
        .iter()
        .map(|&a| {
            format!(
                "{} = {}°",
                m.axes[a].name,
                model_spec::units::short(deg[a] + 0.0)
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The record of test `spec` of machine `m` in steps of at most `step_deg` (degrees), samples
/// `period_s` apart (s), at kinematic parameters `params` (mm, validated by the caller), checked
/// against `clearance`, the strokes and ranges, and the nest on the ball at every sample.
///
/// # Errors
/// The first sample that breaks a check ([`GeneratorError::Sample`]),
/// [`GeneratorError::NoRoom`] or [`GeneratorError::TooManySamples`].
pub(crate) fn generate(
    m: &Machine,
    spec: &TestSpec,
    params: &[f64],
    step_deg: f64,
    period_s: f64,
    clearance: &Clearance,
) -> Result<Record, GeneratorError> {
    let span = spec.sweep.span_deg();
    if span.is_nan() || span <= 0.0 {
        return Err(GeneratorError::NoRoom {
            test: spec.name.clone(),
            axis: m.axes[spec.sweep.primary].name.clone(),
            at_deg: spec.sweep.from_deg,
        });
    }
    let n = steps(span, step_deg);
    if spec.order.samples(n) > super::MAX_SAMPLES {
        return Err(GeneratorError::TooManySamples {
            test: spec.name.clone(),
            span_deg: span,
            step_deg,
            max: super::MAX_SAMPLES,
        });
    }
    let gauge = TiltGauge::new(m);
    let poses = spec
        .order
        .arrange(pair_degrees(m, &gauge, spec, n, clearance));
    let vm = VirtualMachine::new(m);
    let place = |i: usize, deg: &[f64]| SamplePlace {
        test: spec.name.clone(),
        sample: i,
        samples: poses.len(),
        t_s: i as f64 * period_s,
        pose: pose_text(m, deg),
    };
    let fail = |i: usize, deg: &[f64], problem| {
        GeneratorError::Sample(Box::new(SampleError {
            at: place(i, deg),
            problem,
        }))
    };
    let mut commands = Vec::with_capacity(poses.len());
    for (i, deg) in poses.iter().enumerate() {
        let mut q = to_commands(m, deg);
        let tilt = gauge.tilt_deg(&q);
        if tilt > clearance.max_tilt_deg + TILT_TOLERANCE_DEG {
            let max_deg = clearance.max_tilt_deg;
            return Err(fail(
                i,
                deg,
                SampleProblem::Tilt {
                    tilt_deg: tilt,
                    max_deg,
                },
            ));
        }
        vm.tool_centre_point_ik(&mut q, params)
            .map_err(|e| fail(i, deg, SampleProblem::Ik(e)))?;
        match m.check_pose(&q) {
            Ok(()) => {}
            Err(PoseError::OutsideLimits(limit)) => {
                return Err(fail(i, deg, SampleProblem::Limits(limit)));
            }
            Err(e) => return Err(fail(i, deg, SampleProblem::NotFinite(e.to_string()))),
        }
        let gap_mm = vm.nominal_error_vector(&q, params).position.norm();
        if gap_mm.is_nan() || gap_mm > ON_BALL_ROUNDING_MM {
            return Err(fail(i, deg, SampleProblem::OffBall { gap_mm }));
        }
        commands.push(q);
    }
    let times = (0..commands.len()).map(|i| i as f64 * period_s).collect();
    Ok(record_from_commands(commands, times))
}
