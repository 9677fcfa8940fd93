//! The refit of a validation, one for a record and for a re-check's records: the parameters
//! the identification gives no value for on a record (a new set-up's errors, its own zero) and,
//! in a re-check, named machine parameters (one value over every record), fitted on the
//! records' readings with every other value held. First order on the readings minus the
//! prediction at the held values, each sample weighted by its covariance when the records were
//! read through an instrument, then refined against the exact machine by Gauss–Newton when the
//! prediction is exact.

use super::{Prepared, Refitted};
use crate::identify::{check_readings, fit_rows};
use crate::least_squares::{Constraint, Fit, Tolerances};
use crate::noise::NoiseChoice;
use crate::refine::{GaussNewton, IdentifyError, RefineOptions, gauss_newton};
use crate::validate::ValidateError;
use model_spec::Machine;
use nalgebra::{DMatrix, DVector};

/// What a refit found.
pub(crate) struct HeldRefit {
    /// Per record, its refitted columns with their unknowns: `(column, unknown)`; the shared
    /// unknowns come first, in the order asked, then every record's own, in record order.
    pub places: Vec<Vec<(usize, usize)>>,
    /// How many unknowns are shared.
    pub shared: usize,
    /// The fit of the unknowns (uncertainties at the residual's scale).
    pub fit: Fit,
    /// The σ̂ of the whitened residual (about 1 when the covariances are right), when the rows
    /// were weighted by covariances.
    pub weighted_sigma: Option<f64>,
    /// Whether the rows were weighted by the samples' covariances.
    pub weighted: bool,
}

impl HeldRefit {
    /// Per record, every column's value with the unknowns at `x` (mm, rad).
    pub(crate) fn values(&self, prepared: &[Prepared], x: &[f64]) -> Vec<Vec<f64>> {
        values_at(prepared, &self.places, x)
    }

    /// The own parameters of record `r` refitted (not the shared ones), their uncertainties
    /// times `std_factor`.
    pub(crate) fn refitted(
        &self,
        prepared: &[Prepared],
        r: usize,
        std_factor: f64,
    ) -> Vec<Refitted> {
        self.places[r]
            .iter()
            .filter(|&&(_, u)| u >= self.shared)
            .map(|&(k, u)| {
                prepared[r].refitted(
                    k,
                    self.fit.values[u],
                    self.fit.std[u].map(|s| s * std_factor),
                )
            })
            .collect()
    }
}

/// Per record, its values with its refitted columns at the unknowns `x` (at 0 beyond `x`: an
/// empty `x` gives the values held, the refitted columns 0).
fn values_at(prepared: &[Prepared], places: &[Vec<(usize, usize)>], x: &[f64]) -> Vec<Vec<f64>> {
    prepared
        .iter()
        .zip(places)
        .map(|(p, place)| {
            let mut v = p.v.clone();
            for &(k, u) in place {
                v[k] = x.get(u).copied().unwrap_or(0.0);
            }
            v
        })
        .collect()
}

/// Refits the records `prepared` (made ready under one identification's values): the layout
/// columns `shared` (one unknown over every record, with its name) and every record's columns
/// without a value; `None` when there is nothing to refit. `what` names the refit in errors
/// (`record `k1``, `the re-check`).
///
/// # Errors
/// Records some read through an instrument and some not; fewer readings than unknowns plus
/// one; a fit that fails; an exact prediction that fails; a refinement that does not converge.
pub(crate) fn refit_held(
    m: &Machine,
    prepared: &[Prepared],
    shared: &[(usize, String)],
    exact: bool,
    what: &str,
) -> Result<Option<HeldRefit>, ValidateError> {
    let failed = |e: IdentifyError| ValidateError::Shape(format!("{what}: {e}"));
    let mut names: Vec<String> = shared.iter().map(|(_, n)| n.clone()).collect();
    let mut places: Vec<Vec<(usize, usize)>> = Vec::with_capacity(prepared.len());
    for p in prepared {
        let mut place = Vec::new();
        for (k, s) in p.plan.sources.iter().enumerate() {
            match s {
                Some(c) => {
                    if let Some(u) = shared.iter().position(|(j, _)| j == c) {
                        place.push((k, u));
                    }
                }
                None => {
                    place.push((k, names.len()));
                    names.push(p.plan.names[k].clone());
                }
            }
        }
        places.push(place);
    }
    if names.is_empty() {
        return Ok(None);
    }
    let rows: Vec<usize> = prepared.iter().map(|p| p.r.record.samples.len()).collect();
    check_readings(rows.iter().sum(), names.len())?;
    let n_rows: usize = prepared.iter().map(|p| p.y.len()).sum();
    let mut h = DMatrix::<f64>::zeros(n_rows, names.len());
    let mut y = DVector::<f64>::zeros(n_rows);
    let mut held = DVector::<f64>::zeros(n_rows);
    let mut at = 0;
    for ((p, place), v) in prepared
        .iter()
        .zip(&places)
        .zip(values_at(prepared, &places, &[]))
    {
        let n = p.y.len();
        for &(k, u) in place {
            h.view_mut((at, u), (n, 1)).copy_from(&p.h.column(k));
        }
        y.rows_mut(at, n).copy_from(&p.y);
        held.rows_mut(at, n)
            .copy_from(&p.predict(m, &v, exact).map_err(failed)?);
        at += n;
    }
    let records: Vec<_> = prepared.iter().map(|p| p.r).collect();
    let weights = super::super::whitening_of(&records, &NoiseChoice::Instrument)
        .map_err(|e| ValidateError::Shape(format!("{what}: {e}")))?;
    let tol = Tolerances::default();
    let first = fit_rows(
        &h,
        &(&y - &held),
        &names,
        &Constraint::None,
        &tol,
        None,
        &rows,
        weights.as_ref(),
    )?;
    let (fit, weighted_sigma) = if exact {
        let problem = GaussNewton {
            h: &h,
            y: &y,
            layout: &rows,
            tolerances: &tol,
            noise: None,
            coordinates: prepared
                .iter()
                .map(|p| p.coordinates())
                .fold(1.0f64, f64::max),
            weights: weights.as_ref(),
            factored: None,
        };
        let mut predict = |x: &[f64]| -> Result<DVector<f64>, IdentifyError> {
            let mut out = DVector::<f64>::zeros(n_rows);
            let mut at = 0;
            for (p, v) in prepared.iter().zip(values_at(prepared, &places, x)) {
                let q = p.predict(m, &v, true)?;
                out.rows_mut(at, q.len()).copy_from(&q);
                at += q.len();
            }
            Ok(out)
        };
        let (fit, sigma, refinement) =
            gauss_newton(&problem, &first.0, &RefineOptions::default(), &mut predict)
                .map_err(failed)?;
        if !refinement.converged {
            return Err(failed(IdentifyError::NotConverged {
                iterations: refinement.iterations,
                last_step_mm: refinement.steps_mm.last().copied().unwrap_or(0.0),
                tolerance_mm: refinement.tolerance_mm,
            }));
        }
        (fit, sigma)
    } else {
        first
    };
    Ok(Some(HeldRefit {
        places,
        shared: shared.len(),
        fit,
        weighted_sigma,
        weighted: weights.is_some(),
    }))
}
