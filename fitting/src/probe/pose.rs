//! The nominal frame of a probing pose read from a file: its axes in file units (mm, degrees)
//! turned into the one nominal frame of `simulation::probe` ([`PoseFrame`]).

use model_spec::AxisKind;
use simulation::exact::{ExactError, VirtualMachine};
use simulation::probe::PoseFrame;

/// The nominal frame of the pose whose rotary axes stand at `axes` (`Machine::axes` order,
/// rotary in degrees; linear entries ignored), with the kinematic parameters `params` (mm).
///
/// # Errors
/// When the nominal inverse kinematics has no unique answer at that pose.
pub fn pose_frame(
    vm: &VirtualMachine<'_>,
    axes: &[f64],
    params: &[f64],
) -> Result<PoseFrame, ExactError> {
    let pose: Vec<f64> = vm
        .machine()
        .axes
        .iter()
        .zip(axes)
        .map(|(a, &x)| match a.kind {
            AxisKind::Linear => 0.0,
            AxisKind::Rotary => x.to_radians(),
        })
        .collect();
    PoseFrame::at(vm, &pose, params)
}
