//! Checking a compensation on the exact virtual machine: the machine's own error at poses, with
//! the true errors of a truth.

use crate::simulation::exact::VirtualMachine;
use crate::simulation::truth::Truth;
use model_spec::basis::BasisContext;
use model_spec::{ErrorKind, Machine};

/// The true machine errors at a pose (catalogue order, mm and rad), the set-up errors of the
/// ball left out: where the ball sits on the table is not the machine's doing, and
/// compensation leaves it alone.
pub fn machine_errors_at(m: &Machine, truth: &Truth, commands: &[f64]) -> Vec<f64> {
    let motion = vec![1i8; m.axes.len()];
    let cx = BasisContext {
        commands,
        motion: &motion,
        tau: 0.0,
        elapsed_s: 0.0,
        since_start_s: 0.0,
        velocity: &[],
        reading: [0.0; 3],
    };
    let mut e = truth.error_values(m, &cx);
    for (v, term) in e.iter_mut().zip(&m.catalogue) {
        if matches!(term.kind, ErrorKind::Setup { .. }) {
            *v = 0.0;
        }
    }
    e
}

/// The RMS over the three directions (`√(Σ r² / 3N)`, as `validate` reports it; mm) of the
/// machine's own error, tool point minus workpiece point in the tool frame, at `poses`
/// (commands in mm and rad, with the kinematic parameters of each) on the exact virtual machine
/// with the errors of `truth` (set-up errors left out, [`machine_errors_at`]).
pub fn machine_error_rms(m: &Machine, truth: &Truth, poses: &[(&[f64], &[f64])]) -> f64 {
    let vm = VirtualMachine::new(m);
    let sum: f64 = poses
        .iter()
        .map(|(q, params)| {
            vm.error_vector(q, params, &machine_errors_at(m, truth, q))
                .position
                .norm_squared()
        })
        .sum();
    (sum / (3.0 * poses.len().max(1) as f64)).sqrt()
}
