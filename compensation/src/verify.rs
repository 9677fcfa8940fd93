//! Checking a compensation on the exact virtual machine: the machine's own error at poses, with
//! the true errors of a truth, as it is ([`machine_error_rms`]) and as an R-test on a new ball
//! set-up sees it, its set-up errors fitted ([`setup_refitted`]).

use fitting::hmatrix::{GainSource, HMatrixError, h_matrix};
use model_spec::basis::BasisContext;
use model_spec::{ErrorKind, Machine};
use nalgebra::{DVector, Vector3};
use simulation::exact::VirtualMachine;
use simulation::model::Model;
use simulation::paths::record_from_commands;
use simulation::truth::Truth;

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
    rms(&machine_error_vectors(m, truth, poses))
}

/// The machine's own error at each of `poses` (commands in mm and rad, with the kinematic
/// parameters of each): the tool point minus the workpiece point in the tool frame, mm, on the
/// exact virtual machine with the errors of `truth` (set-up errors left out,
/// [`machine_errors_at`]).
pub fn machine_error_vectors(
    m: &Machine,
    truth: &Truth,
    poses: &[(&[f64], &[f64])],
) -> Vec<Vector3<f64>> {
    let vm = VirtualMachine::new(m);
    poses
        .iter()
        .map(|(q, params)| {
            vm.error_vector(q, params, &machine_errors_at(m, truth, q))
                .position
        })
        .collect()
}

/// `√(Σ ‖e‖² / 3N)` of error vectors (their unit), 0 for none.
fn rms(errors: &[Vector3<f64>]) -> f64 {
    let sum: f64 = errors.iter().map(|e| e.norm_squared()).sum();
    (sum / (3.0 * errors.len().max(1) as f64)).sqrt()
}

/// The machine's own error at poses as an R-test on a new ball set-up sees it.
#[derive(Clone, Debug, PartialEq)]
pub struct SetupRefitted {
    /// RMS over the three directions of the machine's own error ([`machine_error_rms`]), mm.
    pub rms: f64,
    /// RMS over the three directions of what remains after the set-up's terms were fitted to
    /// it, mm.
    pub refitted_rms: f64,
    /// The fitted values of the set-up's columns (mm, rad; the minimum-norm least-squares
    /// solution where the poses cannot separate them), in the column order of the set-up's
    /// model.
    pub values: Vec<f64>,
}

/// The machine's own error at the commanded poses `commands` (mm and rad) of one ball set-up at
/// kinematic parameters `params` (mm), on the exact virtual machine with the errors of `truth`
/// (its set-up errors left out, [`machine_errors_at`]), and what remains of it after the terms
/// of `setup` (the model's set-up errors of the ball, `XOW YOW ZOW` and whatever else the model
/// has of a set-up) are fitted to it by least squares: what an R-test on a ball set up anew
/// reads once its set-up errors are identified with the machine's values held, as `validate`
/// does for a new set-up. The set-up terms' gains are first order, at the poses and `params`;
/// terms of a time basis see the poses as samples 1 s apart.
///
/// # Errors
/// [`HMatrixError`] when `setup`'s gains cannot be computed on `m` at `params`.
pub fn setup_refitted(
    m: &Machine,
    truth: &Truth,
    setup: &Model,
    commands: &[Vec<f64>],
    params: &[f64],
) -> Result<SetupRefitted, HMatrixError> {
    let poses: Vec<(&[f64], &[f64])> = commands.iter().map(|q| (q.as_slice(), params)).collect();
    let errors = machine_error_vectors(m, truth, &poses);
    let before = rms(&errors);
    if setup.terms.is_empty() || errors.is_empty() {
        return Ok(SetupRefitted {
            rms: before,
            refitted_rms: before,
            values: vec![0.0; setup.width()],
        });
    }
    let times = (0..commands.len()).map(|i| i as f64).collect();
    let record = record_from_commands(commands.to_vec(), times);
    let mut source = GainSource::new(m, &setup.errors(), params)?;
    let h = h_matrix(m, setup, &record, &mut source)?;
    let y = DVector::from_iterator(
        3 * errors.len(),
        errors.iter().flat_map(|e| e.iter().copied()),
    );
    let scale = DVector::from_iterator(
        h.ncols(),
        h.column_iter().map(|c| match c.norm() {
            n if n > 0.0 => n,
            _ => 1.0,
        }),
    );
    let mut scaled = h.clone();
    for (j, mut c) in scaled.column_iter_mut().enumerate() {
        c /= scale[j];
    }
    let svd = scaled.svd(true, true);
    let tol = svd.singular_values.max() * 1e-12 * (h.nrows().max(h.ncols()) as f64);
    let x = svd
        .solve(&y, tol)
        .expect("U and V are computed")
        .component_div(&scale);
    let remains = &y - &h * &x;
    let refitted: Vec<Vector3<f64>> = remains
        .as_slice()
        .chunks_exact(3)
        .map(|c| Vector3::new(c[0], c[1], c[2]))
        .collect();
    Ok(SetupRefitted {
        rms: before,
        refitted_rms: rms(&refitted),
        values: x.iter().copied().collect(),
    })
}
