//! Refinement of a first-order identification against the exact machine.
//!
//! The H matrix is the first-order model: gains at zero error. On a real (or exactly simulated)
//! machine with errors of tens of µm and µrad, the readings also hold second-order terms —
//! products of two errors with a lever arm, about 1e-3 µm on the seed machine — which bias a
//! purely linear fit by the same order. The refinement removes that bias by Gauss–Newton
//! iteration with H as the Jacobian:
//!
//! ```text
//! v ← v̂ (the linear estimate)
//! repeat: r = y − exact(v);  Δ = H⁺ r  (same scaling, rank and constraint as the fit);  v ← v + Δ
//! ```
//!
//! where `exact(v)` is the virtual machine ([`simulation::readings`]) with the model's
//! terms at the values `v` (a kinematic offset's value added to its symbol's length). `v` is the whole minimum-norm solution, undetermined parameters
//! included (one representative of each confounded group, as in `H·v`); they get no reported
//! value. The iteration contracts by the ratio of the second-order to the first-order terms
//! (about 1e-4), so two or three steps reach rounding. With zeroed readings the sensor offsets
//! are terms of the model like any other, so the prediction is `exact(v) + d0` exactly as the
//! linear model has it.
//!
//! A step is measured by the largest change of the prediction it makes, `‖H·Δ‖∞` (mm), and the
//! iteration has converged when a step moves the prediction by less than
//!
//! ```text
//! max(1e-6 µm, 1e-6·σ, rounding floor)
//! ```
//!
//! ([`RefineOptions::tolerance_mm`], [`RefineOptions::relative`]; σ the noise model's σ under a
//! noise model, else the first-order fit's residual RMS): a change a million times below the
//! noise moves no value by a meaningful amount, while the exact prediction's own rounding can
//! keep later steps at 1e-9 µm to 1e-7 µm on noisy records of some hundred samples. The
//! rounding floor is `64·ε·κ·‖y‖∞` of an ill-conditioned fit (a least-squares solution is
//! rounded by about ε·κ relative); under a noise model κ is multiplied by the whitening's
//! amplification `a = (1 + φ)/√(1 − φ²)`, and the floor is at least `64·ε·a·L`, L the largest
//! coordinate of the machine and the path (mm): the exact prediction is rounded at that scale,
//! and whitening with φ near 1 no longer averages it away. Otherwise, after
//! [`RefineOptions::max_iterations`] steps (8), it has not converged: a slow or diverging
//! iteration (noisy readings of a few samples give first-order values far from any machine,
//! where the second-order terms are no longer small), which is reported as such, never as a
//! result.
//!
//! After convergence the fit's residual, σ̂, uncertainties and covariance are those of the exact
//! residual; the identifiability analysis is unchanged (it depends on H only).
//!
//! Under a noise model ([`IdentifyOptions::noise`](crate::IdentifyOptions::noise)) the ordinary refinement comes first;
//! the noise model is chosen from its exact residual ([`crate::choose_noise`]), then
//! the iteration continues from its solution with every correction the generalized
//! least-squares one (`Δ = (W·H)⁺·W·r`, [`crate::least_squares_whitened`]), and the
//! uncertainties are the whitened fit's. A record with covariances (read through an
//! instrument) has every correction weighted by them as well
//! ([`crate::identify::fit_rows`]).

use crate::factored::{RowsFactored, check_readings_of};
use crate::hmatrix::HMatrixError;
use crate::noise::NoiseModel;
use crate::noise::SampleWhitening;
use crate::{EstimateError, Fit, Tolerances};
use model_spec::Machine;
use nalgebra::{DMatrix, DVector};
use simulation::model::Model;
use simulation::readings::{SimulateError, simulate};
use simulation::record::Record;
use simulation::truth::Truth;

/// The rounding floor of a refinement step, in units of `ε·κ·‖y‖∞` (ε the machine epsilon, κ
/// the condition number of the scaled H, `y` the readings): measured on ill-conditioned fits of
/// a few samples, the steps settle at 5–20 of these units; 64 leaves a margin.
pub const ROUNDING_FLOOR_FACTOR: f64 = 64.0;

/// The absolute tolerance of a refinement step by default: 1e-6 µm (mm).
pub const TOLERANCE_MM: f64 = 1e-9;

/// The tolerance of a refinement step relative to the noise by default: a step that moves the
/// prediction by less than 1e-6 of the noise's σ has converged.
pub const RELATIVE_TOLERANCE: f64 = 1e-6;

/// How far to refine (`RefineOptions::default()`, then set the fields wanted).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct RefineOptions {
    /// Most Gauss–Newton steps.
    pub max_iterations: usize,
    /// Converged when a correction moves the prediction by less than this (mm), or by less than
    /// [`RefineOptions::relative`] times the noise's σ, or than the rounding floor
    /// ([`ROUNDING_FLOOR_FACTOR`]), whichever is largest.
    pub tolerance_mm: f64,
    /// The tolerance relative to the noise's σ (the noise model's, else the first-order fit's
    /// residual RMS): unitless.
    pub relative: f64,
}

impl RefineOptions {
    /// The defaults: at most 8 steps, down to max(1e-6 µm, 1e-6·σ).
    pub fn new() -> RefineOptions {
        RefineOptions::default()
    }

    /// With at most `n` Gauss–Newton steps.
    pub fn max_iterations(mut self, n: usize) -> RefineOptions {
        self.max_iterations = n;
        self
    }

    /// Converged when no correction moves the prediction by more than `mm`, nor by more than
    /// the relative tolerance times σ.
    pub fn tolerance_mm(mut self, mm: f64) -> RefineOptions {
        self.tolerance_mm = mm;
        self
    }

    /// With the tolerance `r` relative to the noise's σ (0: the absolute tolerance alone).
    pub fn relative(mut self, r: f64) -> RefineOptions {
        self.relative = r;
        self
    }
}

impl Default for RefineOptions {
    fn default() -> Self {
        RefineOptions {
            max_iterations: 8,
            tolerance_mm: TOLERANCE_MM,
            relative: RELATIVE_TOLERANCE,
        }
    }
}

/// What the refinement did.
#[derive(Clone, Debug, PartialEq)]
pub struct Refinement {
    /// Steps taken.
    pub iterations: usize,
    /// Per step, the largest change of the prediction at any reading: `‖H·Δ‖∞` (mm).
    pub steps_mm: Vec<f64>,
    /// The tolerance the steps were compared with: the largest of
    /// [`RefineOptions::tolerance_mm`], [`RefineOptions::relative`] times the noise's σ and the
    /// rounding floor of the fit (mm).
    pub tolerance_mm: f64,
    /// `true` when the last step was below the tolerance. `false` when the iteration limit was
    /// reached first (a slow or diverging iteration): the values are then not an
    /// identification, and callers must not report them as one.
    pub converged: bool,
    /// Residual RMS of the linear fit and of the refined one (mm, over 3N rows).
    pub rms_mm: (f64, f64),
}

impl Refinement {
    /// Nothing when the refinement converged, else [`IdentifyError::NotConverged`] with its
    /// last step: its values are no identification.
    pub(crate) fn converged(&self) -> Result<(), IdentifyError> {
        if self.converged {
            return Ok(());
        }
        Err(IdentifyError::NotConverged {
            iterations: self.iterations,
            last_step_mm: self.steps_mm.last().copied().unwrap_or(0.0),
            tolerance_mm: self.tolerance_mm,
        })
    }

    /// This ordinary refinement followed by the converged generalized one `whitened`: the
    /// steps of both, the first-order RMS of the ordinary linear fit, the refined RMS of the
    /// last.
    pub(crate) fn followed_by(self, whitened: &Refinement) -> Refinement {
        let mut steps_mm = self.steps_mm;
        steps_mm.extend(&whitened.steps_mm);
        Refinement {
            iterations: steps_mm.len(),
            steps_mm,
            tolerance_mm: whitened.tolerance_mm,
            converged: true,
            rms_mm: (self.rms_mm.0, whitened.rms_mm.1),
        }
    }
}

/// Why an identification failed: its first-order fit, or its refinement against the exact
/// machine.
#[derive(Debug, thiserror::Error)]
pub enum IdentifyError {
    /// The H matrix could not be built.
    #[error(transparent)]
    HMatrix(#[from] HMatrixError),
    /// The correction could not be solved.
    #[error(transparent)]
    Estimate(#[from] EstimateError),
    /// The exact prediction failed.
    #[error(transparent)]
    Simulate(#[from] SimulateError),
    /// The refinement did not converge in the steps allowed: the values are no identification.
    #[error(
        "the refinement against the exact machine did not converge: {iterations} Gauss-Newton steps, the last moved the prediction by {:.3e} µm (tolerance {:.1e} µm)",
        last_step_mm * 1e3,
        tolerance_mm * 1e3
    )]
    NotConverged {
        /// Steps taken.
        iterations: usize,
        /// The last step's largest change of the prediction, mm.
        last_step_mm: f64,
        /// The tolerance, mm.
        tolerance_mm: f64,
    },
    /// A step produced a non-finite value: the iteration diverged.
    #[error(
        "the refinement against the exact machine diverged to non-finite values at step {iterations}"
    )]
    NotFinite {
        /// The step at which it happened.
        iterations: usize,
    },
}

/// The exact machine's error vector (mm, tool frame) at every sample of `record` with the
/// model's terms at `values` (mm, rad; `None` as 0) and kinematic parameters `params` (mm).
/// No noise and no zeroing: sensor offsets in the model add as they are. A kinematic offset's
/// value is the change of its symbol: the exact chain runs with `params` plus the changes
/// ([`crate::offsets::apply_kinematic_offsets`]).
pub fn exact_prediction(
    m: &Machine,
    model: &Model,
    values: &[Option<f64>],
    record: &Record,
    params: &[f64],
) -> Result<Vec<[f64; 3]>, SimulateError> {
    let (model, values, params) = crate::offsets::apply_kinematic_offsets(model, values, params);
    let truth = Truth {
        source: "<identified model>".into(),
        description: String::new(),
        params,
        model,
        coefficients: values.iter().map(|v| v.unwrap_or(0.0)).collect(),
        noise_mm: 0.0,
        noise_phi: 0.0,
        seed: 0,
        zeroed: false,
    };
    Ok(simulate(m, &truth, record)?.measured)
}

/// The exact machine's readings (mm, in the rows of the system) from every parameter's value in
/// column order (mm, rad).
pub(crate) type ExactPrediction<'a> = dyn FnMut(&[f64]) -> Result<DVector<f64>, IdentifyError> + 'a;

/// A Gauss–Newton refinement's system: the first-order H (the Jacobian), the readings, and what
/// sets the rounding floor.
pub(crate) struct GaussNewton<'a> {
    /// The H matrix (mm per unit of each parameter).
    pub h: &'a DMatrix<f64>,
    /// The readings (mm).
    pub y: &'a DVector<f64>,
    /// Samples per record, in row order (for the whitening).
    pub layout: &'a [usize],
    /// Rank and identifiability tolerances.
    pub tolerances: &'a Tolerances,
    /// The noise model of generalized corrections; `None`: ordinary least squares.
    pub noise: Option<&'a NoiseModel>,
    /// The largest coordinate of the machine and the paths (mm, at least 1): the scale at which
    /// the exact prediction is rounded.
    pub coordinates: f64,
    /// The per-sample whitening of records read through an instrument; `None`: none.
    pub weights: Option<&'a SampleWhitening>,
    /// The factorisations of `h` for these fits ([`RowsFactored::new`] with the arguments
    /// above), when the caller has them; `None`: made at the first fit.
    pub factored: Option<&'a RowsFactored<'a>>,
}

/// Refines the first-order fit `start` of `problem` against the exact machine's `predict`ion
/// (mm, the rows of `problem.y`, from every parameter's value in column order) by Gauss–Newton
/// iteration (see the module documentation). Returns the final fit (values the refined ones,
/// determined as in `start`), the σ̂ of the whitened residual under a noise model, and what the
/// iteration did.
pub(crate) fn gauss_newton(
    problem: &GaussNewton,
    start: &Fit,
    opts: &RefineOptions,
    predict: &mut ExactPrediction,
) -> Result<(Fit, Option<f64>, Refinement), IdentifyError> {
    let GaussNewton {
        h,
        y,
        layout,
        tolerances,
        noise,
        coordinates,
        weights,
        factored: given,
    } = *problem;
    // The fit of a residual: ordinary, or generalized under the noise model, rows weighted by
    // the samples' covariances when there are any (`fit_rows`). H is the same at every step:
    // it is factorised once, at the first fit (unless the caller has done it).
    let mut factored: Option<RowsFactored> = None;
    let mut fit_of = |r: &DVector<f64>| -> Result<(Fit, Option<f64>), EstimateError> {
        check_readings_of(h, r, &start.names)?;
        let f = match (given, &mut factored) {
            (Some(f), _) => f,
            (None, Some(f)) => &*f,
            (None, none) => &*none.insert(RowsFactored::for_readings(
                h,
                r,
                &start.names,
                &start.constraint,
                tolerances,
                noise,
                layout,
                weights,
            )?),
        };
        f.fit(h, r)
    };
    let rows = y.len().max(1) as f64;
    let linear_rms = (start.rss / rows).sqrt();
    // The rounding floor of a correction: relative rounding of the least-squares solution is
    // about ε·κ, so its prediction cannot settle below a multiple of ε·κ·‖y‖∞. A step below
    // the floor is rounding, not a correction.
    // Whitening multiplies the condition by up to (1 + φ)/√(1 − φ²) (the Prais–Winsten
    // filter's gain at the highest frequency over its gain at the lowest), and the exact
    // prediction's own rounding enters the whitened correction amplified alike: with φ near 1
    // a generalized refinement settles about an order of magnitude above the ordinary floor.
    let amplification = noise.map_or(1.0, |n| {
        n.phi
            .iter()
            .map(|&p| (1.0 + p) / (1.0 - p * p).max(f64::MIN_POSITIVE).sqrt())
            .fold(1.0, f64::max)
    });
    let kappa = start.condition.unwrap_or(1.0) * amplification;
    // Under a noise model the exact prediction's own rounding (ε times the machine's
    // coordinates, mm) is whitened too, and a correction cannot settle below it.
    let prediction_floor = if noise.is_some() {
        ROUNDING_FLOOR_FACTOR * f64::EPSILON * amplification * coordinates
    } else {
        0.0
    };
    let floor = (ROUNDING_FLOOR_FACTOR * f64::EPSILON * kappa * y.amax()).max(prediction_floor);
    // The noise's scale: the noise model's σ (RMS over the directions), else the first-order
    // fit's residual RMS.
    let sigma = noise.map_or(linear_rms, |n| {
        (n.sigma_mm.iter().map(|s| s * s).sum::<f64>() / 3.0).sqrt()
    });
    let tolerance = opts.tolerance_mm.max(opts.relative * sigma).max(floor);
    // Iterate on the whole minimum-norm solution, undetermined parameters included: it is what
    // the linear model's prediction is made of. Which values are reported is decided at the end.
    let mut x = start.solution.clone();
    let mut steps = Vec::new();
    let mut converged = false;
    let mut residual = |x: &[f64]| -> Result<DVector<f64>, IdentifyError> { Ok(y - predict(x)?) };
    for _ in 0..opts.max_iterations {
        let r = residual(&x)?;
        let (correction, _) = fit_of(&r)?;
        for (v, d) in x.iter_mut().zip(&correction.solution) {
            *v += d;
        }
        // The largest change of the prediction at any reading.
        let step = (h * DVector::from_column_slice(&correction.solution)).amax();
        if !step.is_finite() || x.iter().any(|v| !v.is_finite()) {
            return Err(IdentifyError::NotFinite {
                iterations: steps.len() + 1,
            });
        }
        steps.push(step);
        if step <= tolerance {
            converged = true;
            break;
        }
    }
    // The fit of the exact residual at the refined solution: the same H, so the same rank,
    // identifiability and unit covariance; σ̂, uncertainties and residual now those of the
    // exact model. Its own correction is below the tolerance and is not added.
    let r = residual(&x)?;
    let refined_rms = (r.norm_squared() / rows).sqrt();
    let (mut fit, whitened_sigma) = fit_of(&r)?;
    fit.values = fit
        .values
        .iter()
        .zip(&x)
        .map(|(has, &v)| has.map(|_| v))
        .collect();
    fit.solution = x;
    Ok((
        fit,
        whitened_sigma,
        Refinement {
            tolerance_mm: tolerance,
            iterations: steps.len(),
            steps_mm: steps,
            converged,
            rms_mm: (linear_rms, refined_rms),
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::least_squares::least_squares;
    use crate::{Constraint, Tolerances};

    /// A linear system of 40 rows and 2 parameters, readings `H·[3, −2] + r` with `r` a
    /// residual of RMS `sigma` (mm) orthogonal to nothing in particular.
    fn system(sigma: f64) -> (DMatrix<f64>, DVector<f64>) {
        let h = DMatrix::from_fn(40, 2, |i, j| ((i + 1) as f64 * (j + 1) as f64 * 0.37).sin());
        let r = DVector::from_fn(40, |i, _| sigma * ((i as f64) * 1.7).cos() * 2f64.sqrt());
        let y = &h * DVector::from_column_slice(&[3.0, -2.0]) + r;
        (h, y)
    }

    /// Refines the first-order fit of `system(sigma)` against an "exact" prediction that is
    /// `H·x` plus a jitter of `jitter` mm whose sign flips at every evaluation: the rounding of
    /// an exact machine, which keeps every correction at about the jitter's size.
    fn refine_jittered(sigma: f64, jitter: f64, opts: &RefineOptions) -> Refinement {
        let (h, y) = system(sigma);
        let names = vec!["a".to_string(), "b".to_string()];
        let tol = Tolerances::default();
        let start = least_squares(&h, &y, &names, &Constraint::None, &tol).unwrap();
        let problem = GaussNewton {
            h: &h,
            y: &y,
            layout: &[y.len() / 3],
            tolerances: &tol,
            noise: None,
            coordinates: 1.0,
            weights: None,
            factored: None,
        };
        let mut calls = 0usize;
        let shape = DVector::from_fn(40, |i, _| if i % 2 == 0 { 1.0 } else { 0.3 });
        let mut predict = |x: &[f64]| -> Result<DVector<f64>, IdentifyError> {
            calls += 1;
            let sign = if calls.is_multiple_of(2) { 1.0 } else { -1.0 };
            Ok(&h * DVector::from_column_slice(x) + &shape * (sign * jitter))
        };
        gauss_newton(&problem, &start, opts, &mut predict)
            .unwrap()
            .2
    }

    #[test]
    fn a_step_below_a_millionth_of_a_micrometre_has_converged() {
        // Steps that settle at a few 1e-12 mm (3e-9 µm): rounding, converged by default.
        let r = refine_jittered(0.5e-3, 1e-11, &RefineOptions::default());
        assert!(r.converged, "{r:?}");
        assert!(r.iterations <= 2, "{r:?}");
        assert_eq!(r.tolerance_mm, TOLERANCE_MM);
        // The same steps against the former 1e-12 mm: never converged.
        let strict = RefineOptions::default().tolerance_mm(1e-12).relative(0.0);
        let r = refine_jittered(0.5e-3, 1e-11, &strict);
        assert!(!r.converged, "{r:?}");
        assert_eq!(r.iterations, 8);
    }

    #[test]
    fn the_tolerance_grows_with_the_noise() {
        // Residual RMS 1 mm: the tolerance is 1e-6 mm, and steps of about 7e-8 mm converge.
        let r = refine_jittered(1.0, 2e-7, &RefineOptions::default());
        assert!(r.converged, "{r:?}");
        assert!((r.tolerance_mm - 1e-6).abs() < 2e-8, "{r:?}");
        // The same steps on 0.5 µm of noise are 500 times the tolerance: not converged.
        let r = refine_jittered(0.5e-3, 2e-7, &RefineOptions::default());
        assert!(!r.converged, "{r:?}");
        assert_eq!(r.tolerance_mm, TOLERANCE_MM);
    }

    #[test]
    fn a_crawling_iteration_does_not_converge() {
        // Steps of about 1e-6 mm (1e-3 µm) never settle: eight steps, not converged.
        let r = refine_jittered(0.5e-3, 5e-6, &RefineOptions::default());
        assert!(!r.converged, "{r:?}");
        assert_eq!(r.iterations, 8);
        assert!(r.steps_mm.iter().all(|s| *s > 5e-7), "{r:?}");
    }
}
