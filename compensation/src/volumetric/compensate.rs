//! The corrected commands: `u_c` such that the predicted tool point at `u_c` is the nominal
//! tool point at `u`, `u_c + du(u_c) = u` (the seed's compensation with `−du`, Fig. 5, solved
//! at the corrected command rather than at the commanded one).
//!
//! The fixed point `u_c = u − du(u_c)` is iterated from `u_c = u` until no command changes by
//! [`TOLERANCE_MM`] or more. The change shrinks by the slope of `du` (of the order of 1e-4 for
//! errors of tens of µm over hundreds of mm) at every step, so three evaluations of `du`
//! suffice on realistic machines (docs/volumetric.md gives the measured count).
//!
//! A corrected command can be a few µm outside the measured range when the commanded one is at
//! its end; `du` is then read at the end of the range (the error changes by the slope of `du`
//! times those µm, below 1e-3 µm for realistic errors).

use super::VolumetricError;
use super::model::VolumetricModel;
use model_spec::units::compact;
use model_spec::{AxisId, Machine};
use nalgebra::Vector3;

/// The iteration stops when no command changes by this much, mm (1e-6 µm).
pub const TOLERANCE_MM: f64 = 1e-9;

/// The most evaluations of `du` for one pose before the correction is declared not to converge.
pub const MAX_ITERATIONS: usize = 50;

/// A corrected pose.
#[derive(Clone, Debug, PartialEq)]
pub struct Corrected {
    /// The commanded pose ([`Machine::axes`] order), mm.
    pub commanded: Vec<f64>,
    /// The corrected commands ([`Machine::axes`] order), mm.
    pub commands: Vec<f64>,
    /// The predicted error at the corrected commands, mm (what the correction cancels).
    pub du: Vector3<f64>,
    /// Evaluations of `du` until the last change was below [`TOLERANCE_MM`].
    pub iterations: usize,
}

/// The corrected commands of the commanded pose `commands` ([`Machine::axes`] order, mm),
/// without checking the strokes.
///
/// # Errors
/// [`VolumetricError::OutOfRange`] when a commanded position is outside its measured range;
/// [`VolumetricError::Computation`] for a predicted error beyond ±1000 µm or an iteration that
/// does not converge in [`MAX_ITERATIONS`].
pub fn correct(model: &VolumetricModel, commands: &[f64]) -> Result<Corrected, VolumetricError> {
    model.check_range(commands)?;
    let mut uc = commands.to_vec();
    let mut last_change = f64::INFINITY;
    for it in 1..=MAX_ITERATIONS {
        let du = model.du_held(&uc)?;
        let shift = model.commands_for(&du);
        let next: Vec<f64> = commands.iter().zip(&shift).map(|(u, s)| u - s).collect();
        last_change = next
            .iter()
            .zip(&uc)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        uc = next;
        if last_change < TOLERANCE_MM {
            let du = model.du_held(&uc)?;
            return Ok(Corrected {
                commanded: commands.to_vec(),
                commands: uc,
                du,
                iterations: it,
            });
        }
    }
    Err(VolumetricError::Computation(format!(
        "the corrected command of the pose {} does not converge: after {MAX_ITERATIONS} steps it still changes by {} µm",
        pose_text(model, commands),
        compact(last_change * 1e3)
    )))
}

/// [`correct`], and the corrected commands checked against the strokes of `m`.
///
/// # Errors
/// As [`correct`]; [`VolumetricError::OffStroke`] for the first axis (machine order) whose
/// corrected command is outside its stroke.
pub fn correct_within_strokes(
    model: &VolumetricModel,
    m: &Machine,
    commands: &[f64],
) -> Result<Corrected, VolumetricError> {
    let c = correct(model, commands)?;
    let tol = model_spec::pose::LIMIT_TOLERANCE;
    for (a, axis) in m.axes.iter().enumerate() {
        let [lo, hi] = axis.limits;
        let q = c.commands[a];
        if q < lo - tol || q > hi + tol {
            return Err(VolumetricError::OffStroke {
                axis: axis.name.clone(),
                commanded: commands[a],
                corrected: q,
                stroke: axis.limits,
            });
        }
    }
    Ok(c)
}

/// `X = 1 mm, Y = 2 mm, Z = 3 mm` in chain order.
fn pose_text(model: &VolumetricModel, commands: &[f64]) -> String {
    model
        .chain()
        .iter()
        .map(|&a: &AxisId| {
            format!(
                "{} = {} mm",
                model.axis_name(a).unwrap_or("?"),
                compact(commands[a])
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}
