//! The prediction: what a fit of a planned campaign would give, for a stated reading noise,
//! before anything is measured.
//!
//! The campaign's design matrix `H` ([`design_matrix`]: the records' H matrices stacked, each at
//! its own kinematic parameters, its set-up and zero columns where they belong) depends on the
//! poses only. With the reading noise `e` of covariance `Σ` (a [`NoiseModel`]: per direction σ
//! and, for AR(1) noise, φ; records and directions independent), the generalized
//! least-squares estimate of the determined parameters has the covariance
//!
//! ```text
//! Cov(p̂) = S⁻¹·V_r·Σ_r⁻²·V_rᵀ·S⁻¹       of the whitened, column-scaled  W·H·S⁻¹ = U·Σ·Vᵀ
//! ```
//!
//! `W` the prewhitening of the noise model ([`NoiseModel::whiten_matrix`]: Prais–Winsten per
//! record and direction, divided by σ; for white noise `W = I/σ`), `S` the column norms of
//! `W·H`, `r` the rank. This is the covariance an identification reports under that noise
//! model (docs/identification.md §5, §13) with its σ̂ at its expected value, 1 in whitened
//! units. It is computed by the identification's own least squares: the whitened `H` as the
//! reduced system of [`least_squares_reduced`] with a right-hand side of zero and a residual
//! sum of squares equal to the degrees of freedom, which makes σ̂ exactly 1.
//!
//! As in an identification, the rank, the singular values, the condition number and what is
//! determined are those of the ordinary `H` (the poses' geometry; [`least_squares`] with the
//! default tolerances); the whitened system must agree on them. A parameter the plan cannot
//! determine gets no uncertainty.
//!
//! A campaign whose readings carry their own covariance `Σ_i` (one 3 × 3 per sample,
//! [`simulation::record::Record::covariance`]: a touch-probe campaign, whose readings are
//! sphere centres fitted from the probe's hits) is predicted by [`predict_with_covariances`]:
//! each sample's three rows are whitened by `L_i⁻¹` (`Σ_i = L_i·L_iᵀ`), the weighting the
//! campaign fit applies to such records ([`crate::campaign::whitening`]), and the covariances
//! declare the noise, so `Cov(p̂) = (Hᵀ·Σ⁻¹·H)⁻¹` on the determined parameters, optionally under
//! a [`Constraint::Zero`] (the named parameters fixed to 0, as the fit fixes them; they get no
//! uncertainty and count as not determined).

use crate::campaign::Owner;
use crate::campaign::design::Solved;
use crate::campaign::design::{Design, Layout, design_matrix};
use crate::campaign::fit::to_layout_order;
use crate::identifiability::NearPair;
use crate::identify::check_readings;
use crate::least_squares::{
    Constraint, EstimateError, Tolerances, least_squares, least_squares_reduced,
};
use crate::noise::{NoiseChoice, NoiseError, NoiseModel, NoiseSource, SampleWhitening};
use model_spec::Machine;
use nalgebra::{DMatrix, DVector};
use simulation::campaign::Campaign;
use simulation::model::Model;

/// What a fit of a planned campaign would give (layout order: [`Layout::columns`]).
/// Internal units: mm (translational errors, set-up errors, sensor offsets), rad (angular
/// errors), ms (`velocity` lags).
#[derive(Clone, Debug, PartialEq)]
pub struct Prediction {
    /// Which column belongs to whom.
    pub layout: Layout,
    /// Column names ([`Layout::names`]): `XOC`, `XOW[K4]`, `dx0[K1]`.
    pub names: Vec<String>,
    /// Samples over all records.
    pub samples: usize,
    /// Numerical rank of the column-scaled H.
    pub rank: usize,
    /// Singular values of the column-scaled H, descending.
    pub singular_values: Vec<f64>,
    /// `σ_max / σ_r` of the column-scaled H; `None` when the rank is 0.
    pub condition: Option<f64>,
    /// Whether the plan determines each column (not a column a constraint fixes to 0).
    pub determined: Vec<bool>,
    /// Groups of columns the plan cannot separate (indices), each ascending.
    pub confounded: Vec<Vec<usize>>,
    /// Determined pairs whose estimates would correlate beyond 0.99.
    pub near_confounded: Vec<NearPair>,
    /// Predicted standard uncertainty per column (mm, rad, ms); `None` where the plan does not
    /// determine it.
    pub std: Vec<Option<f64>>,
    /// Predicted covariance (mm², mm·rad, rad²); NaN in rows and columns of undetermined
    /// parameters.
    pub covariance: DMatrix<f64>,
    /// The reading noise assumed.
    pub noise: NoiseModel,
}

impl Prediction {
    /// The column called `name`, if any.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// The owner of column `j`.
    pub fn owner(&self, j: usize) -> Owner {
        self.layout.columns[j].owner
    }
}

/// The prediction of `model` of `m` on the planned `campaign` (records without readings) under
/// the reading noise `noise`, with the rank tolerances `tol`.
///
/// # Errors
/// A campaign or model that does not fit `m`, fewer readings than parameters plus one (the
/// plan could not be identified), an SVD that does not converge, a noise model that cannot
/// whiten or under which the whitened system has another rank.
pub fn predict(
    m: &Machine,
    model: &Model,
    campaign: &Campaign,
    noise: &NoiseModel,
    tol: &Tolerances,
) -> Result<Prediction, EstimateError> {
    let design = design_matrix(m, model, campaign)?;
    predict_design(&design, noise, tol)
}

/// The prediction of a campaign from its `design` matrix (see [`predict`]).
///
/// # Errors
/// As [`predict`].
pub fn predict_design(
    design: &Design,
    noise: &NoiseModel,
    tol: &Tolerances,
) -> Result<Prediction, EstimateError> {
    predict_rows(design, None, noise, &Constraint::None, tol)
}

/// The prediction of `campaign` from its `design` matrix when every record carries the
/// covariance of each reading (module documentation): `Cov(p̂) = (Hᵀ·Σ⁻¹·H)⁻¹` on what is
/// determined, under `constraint` (`Zero` names as the campaign's columns or, for a campaign of
/// one record, the record's own: `ZOW` for `ZOW[probe]`). The [`Prediction::noise`] is white
/// with σ the root mean variance of one component of the readings (the scale of the
/// per-sample whitening).
///
/// # Errors
/// As [`predict`]; [`EstimateError::Noise`] when a record carries no covariances or one is not
/// positive definite; an unknown name in the constraint.
pub fn predict_with_covariances(
    design: &Design,
    campaign: &Campaign,
    constraint: &Constraint,
    tol: &Tolerances,
) -> Result<Prediction, EstimateError> {
    let Some(weights) = crate::campaign::whitening(campaign, &NoiseChoice::Ordinary)? else {
        return Err(NoiseError::Whitening(
            "the campaign's records carry no covariance of their readings: predict it under a noise model (predict_design)".into(),
        )
        .into());
    };
    let noise = NoiseModel::white(weights.scale_mm, NoiseSource::Declared);
    predict_rows(design, Some(&weights), &noise, constraint, tol)
}

/// The prediction of `design`: rows whitened by the per-sample `weights` when given, then by
/// `noise`, under `constraint`.
fn predict_rows(
    design: &Design,
    weights: Option<&SampleWhitening>,
    noise: &NoiseModel,
    constraint: &Constraint,
    tol: &Tolerances,
) -> Result<Prediction, EstimateError> {
    noise.check()?;
    let samples: usize = design.rows.iter().sum();
    check_readings(samples, design.names.len())?;
    let Solved { h, names, order } = Solved::copied(design);
    let rows = h.nrows();
    let zero = DVector::zeros(rows);
    let ordinary = least_squares(&h, &zero, &names, constraint, tol)?;
    let mut hw = h;
    if let Some(w) = weights {
        w.whiten_matrix(&mut hw)?;
    }
    noise.whiten_matrix(&design.rows, &mut hw)?;
    let dof = ordinary.dof;
    let white = least_squares_reduced(&hw, &zero, &names, constraint, tol, rows, dof as f64)?;
    if white.rank != ordinary.rank
        || white.identifiability.determined != ordinary.identifiability.determined
    {
        return Err(NoiseError::RankChanged {
            ordinary: ordinary.rank,
            whitened: white.rank,
        }
        .into());
    }
    // σ̂ of the whitened system is √(dof/dof) = 1: its covariance is the predicted one.
    let mut fit = ordinary;
    fit.std = white.std;
    fit.covariance = white.covariance;
    fit.correlation = white.correlation;
    fit.identifiability.near_confounded = white.identifiability.near_confounded;
    let mut fit = to_layout_order(fit, &order);
    // A parameter fixed by the constraint is no estimate of the plan: not determined, no
    // uncertainty.
    for j in (0..fit.names.len()).filter(|&j| fit.fixed[j]) {
        fit.identifiability.determined[j] = false;
        fit.std[j] = None;
        for k in 0..fit.names.len() {
            fit.covariance[(j, k)] = f64::NAN;
            fit.covariance[(k, j)] = f64::NAN;
        }
    }
    if let Some(j) = (0..fit.names.len())
        .find(|&j| fit.identifiability.determined[j] && fit.std[j].is_none_or(|s| !s.is_finite()))
    {
        return Err(EstimateError::NotFinite(format!(
            "the predicted uncertainty of `{}`",
            fit.names[j]
        )));
    }
    Ok(Prediction {
        layout: design.layout.clone(),
        names: fit.names,
        samples,
        rank: fit.rank,
        singular_values: fit.singular_values,
        condition: fit.condition,
        determined: fit.identifiability.determined,
        confounded: fit.identifiability.confounded,
        near_confounded: fit.identifiability.near_confounded,
        std: fit.std,
        covariance: fit.covariance,
        noise: noise.clone(),
    })
}
