//! One pose of a machine from the axis positions a person gives: every rotary axis given, the
//! linear axes left out filled by the nominal tool-centre-point inverse kinematics (so that the
//! tool point is on the workpiece point, as at every R-test sample), and the pose checked
//! against the machine's strokes and ranges.

use super::exact::{ExactError, nominal_error_vector, tool_centre_point_ik};
use model_spec::{AxisId, AxisKind, Machine};

/// A pose ready for evaluation.
#[derive(Clone, Debug, PartialEq)]
pub struct Pose {
    /// Per axis, in axis order: linear mm, rotary rad.
    pub commands: Vec<f64>,
    /// Per axis, as people read it: linear mm, rotary degrees (as given, not converted back).
    pub shown: Vec<f64>,
    /// Per axis: `true` when the value came from the inverse kinematics.
    pub from_ik: Vec<bool>,
    /// Per kinematic symbol, mm.
    pub params: Vec<f64>,
    /// The distance between the nominal tool point and the nominal workpiece point, mm: 0 to
    /// rounding when the inverse kinematics filled the linear axes. Beyond
    /// [`ON_BALL_TOLERANCE_MM`] the gain functions evaluated here are not the first-order gains
    /// of the chain (those are taken where the two points coincide).
    pub gap_mm: f64,
}

impl Pose {
    /// A note for people when the pose is off the workpiece point by more than
    /// [`ON_BALL_TOLERANCE_MM`], else `None`.
    pub fn off_ball_note(&self) -> Option<String> {
        (self.gap_mm > ON_BALL_TOLERANCE_MM).then(|| {
            format!(
                "Note: this pose puts the nominal tool point {} mm from the nominal workpiece point: the numbers are the gain functions evaluated here, which are the first-order gains of the chain only where the two points coincide (leave the linear axes out to have them filled by the inverse kinematics).",
                model_spec::units::short(self.gap_mm)
            )
        })
    }
}

/// The largest distance between the nominal tool point and the nominal workpiece point at a
/// pose where gains are evaluated or a sample is taken, mm: the gains are the first-order
/// gains where the two coincide (the sensor nest on the ball).
pub const ON_BALL_TOLERANCE_MM: f64 = 0.5;

/// Why a pose cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum PoseError {
    /// A rotary axis is not given.
    #[error(
        "rotary axis {0} is missing (give every rotary axis in degrees; linear axes may be left to the inverse kinematics)"
    )]
    MissingRotary(String),
    /// The inverse kinematics has no solution.
    #[error("cannot fill the missing linear axes by inverse kinematics: {0} (give every axis)")]
    Ik(ExactError),
    /// An axis outside its stroke or range.
    #[error("{0}")]
    OffStroke(model_spec::pose::PoseError),
}

/// The pose with the axis positions `given` (axis id, linear mm or rotary degrees) at the
/// kinematic parameters `params` (mm): every rotary axis must be there; missing linear axes
/// are filled by the nominal inverse kinematics. Unless `allow_off_stroke`, every axis must be
/// within its stroke or range.
///
/// # Errors
/// [`PoseError`].
pub fn complete(
    m: &Machine,
    given: &[(AxisId, f64)],
    params: Vec<f64>,
    allow_off_stroke: bool,
) -> Result<Pose, PoseError> {
    let n = m.axes.len();
    let (mut commands, mut shown, mut seen) = (vec![0.0; n], vec![0.0; n], vec![false; n]);
    for &(i, x) in given {
        commands[i] = match m.axes[i].kind {
            AxisKind::Linear => x,
            AxisKind::Rotary => x.to_radians(),
        };
        shown[i] = x;
        seen[i] = true;
    }
    if let Some(i) = m.rotary_axes().find(|&i| !seen[i]) {
        return Err(PoseError::MissingRotary(m.axes[i].name.clone()));
    }
    let from_ik: Vec<bool> = seen.iter().map(|s| !s).collect();
    if from_ik.iter().any(|&f| f) {
        let mut ik = commands.clone();
        tool_centre_point_ik(m, &mut ik, &params).map_err(PoseError::Ik)?;
        for i in 0..n {
            if from_ik[i] {
                commands[i] = ik[i];
                shown[i] = ik[i];
            }
        }
    }
    if !allow_off_stroke {
        m.check_pose(&commands).map_err(PoseError::OffStroke)?;
    }
    let gap_mm = nominal_error_vector(m, &commands, &params).position.norm();
    Ok(Pose {
        commands,
        shown,
        from_ik,
        params,
        gap_mm,
    })
}
