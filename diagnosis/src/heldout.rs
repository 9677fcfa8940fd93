//! Held-out records: what the base and the extended model predict there, with only what the
//! fits determined, each record with its own set-up.
//!
//! - **Values.** A held-out record takes the machine's errors from the fit; its set-up's errors
//!   from the fit when its set-up was fitted (the same set-up label: the ball not moved), else
//!   they are **refitted** on the record itself with every other value held; its own
//!   parameters (its zero when its readings were zeroed, the drifts of a recording) are always
//!   refitted: they are the state of that recording
//!   ([`fitting::campaign::validate_record`]). Its residual is then after those
//!   parameters, and the report names them.
//! - **Estimable predictions.** A fit of a rank-deficient model determines combinations of its
//!   parameters, not every parameter. The prediction uses the values the fit gave, and for the
//!   parameters it could not determine the minimum-norm solution (which carries exactly the
//!   determined combinations: its undetermined part is zero). Setting undetermined values to
//!   0, as a plain validation does, would throw away the combinations the fit did determine.
//! - **What the prediction needs.** With `N` the null space of the fit's scaled H and `B` the
//!   held-out record's columns of the same parameters (scaled alike), a null direction `n`
//!   changes the held-out prediction by `B·n`, less what the refitted columns take of it: the
//!   fit cannot say what that part is. When it exceeds [`NEEDS_TOLERANCE`] times the largest
//!   column norm of `B`, the held-out record needs an undetermined combination, and the
//!   confounded groups `n` involves are named; that record's RMS is then not the model's error
//!   and does not count in the gain.
//! - **Outliers** of the held-out record (from the base prediction's residual,
//!   [`super::outliers`]) are listed and left out of both RMS.

use super::DiagnoseError;
use super::outliers::{self, Outlier};
use super::select::Span;
use fitting::campaign::design::block;
use fitting::campaign::{
    CampaignIdentification, CampaignValues, RecordValidation, record_plan, validate_record,
};
use fitting::hmatrix::GainSource;
use fitting::validate::{ValidateError, ValidateOptions, statistics};
use model_spec::Machine;
use nalgebra::{DMatrix, DVector};
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::model::Term;

/// Relative size of `‖B·n‖` above which a held-out record needs a null direction of the fit.
pub const NEEDS_TOLERANCE: f64 = 1e-6;

/// One held-out record's gain.
#[derive(Clone, Debug, PartialEq)]
pub struct HeldOut {
    /// Its label in the held-out campaign.
    pub name: String,
    /// Its set-up's label.
    pub setup: String,
    /// Whether its set-up was fitted (its set-up errors come from the fit); otherwise they were
    /// refitted on it.
    pub setup_fitted: bool,
    /// Whether its readings were zeroed at the first sample.
    pub zeroed: bool,
    /// Its kinematic parameters, mm (symbol order).
    pub params: Vec<f64>,
    /// Its samples, outliers included.
    pub samples: usize,
    /// The parameters of the extended model refitted on it (`XOW[k2]`, `dx0[k2]`); none when
    /// every value came from the fit.
    pub refitted: Vec<String>,
    /// Readings counted in the RMS (three per sample, outliers' samples left out).
    pub readings: usize,
    /// Residual RMS of the base model's prediction, mm (outliers left out).
    pub before_rms: f64,
    /// Residual RMS of the extended model's prediction, mm (outliers left out).
    pub after_rms: f64,
    /// Isolated readings far outside the base prediction's residual, left out of both RMS.
    pub outliers: Vec<Outlier>,
    /// Confounded groups of the base fit (parameter names) its prediction needs: when not
    /// empty, `before_rms` is not the base model's error.
    pub undetermined_before: Vec<Vec<String>>,
    /// The same for the extended fit.
    pub undetermined_after: Vec<Vec<String>>,
    /// The extended model's residual per sample, mm (outliers included).
    pub residual_after: Vec<[f64; 3]>,
    /// The base model's residual per sample, mm (outliers included).
    pub residual_before: Vec<[f64; 3]>,
}

impl HeldOut {
    /// The extended model's residual without the outliers' samples: 3 rows per sample, mm.
    pub fn residual_after_without_outliers(&self) -> nalgebra::DVector<f64> {
        let drop = outliers::samples(&self.outliers);
        nalgebra::DVector::from_iterator(
            3 * (self.residual_after.len() - drop.len()),
            (0..self.residual_after.len())
                .filter(|i| !drop.contains(i))
                .flat_map(|i| self.residual_after[i]),
        )
    }

    /// `true` when both predictions use only what the fits determined, so that the change of
    /// RMS is the extension's gain.
    pub fn estimable(&self) -> bool {
        self.undetermined_before.is_empty() && self.undetermined_after.is_empty()
    }
}

/// The values a prediction uses: every column's minimum-norm solution (the fit's values where
/// it has them; the determined combinations carried where it does not).
pub fn estimable(ident: &CampaignIdentification) -> CampaignValues {
    let mut v = CampaignValues::of(ident);
    v.values = ident
        .fit
        .values
        .iter()
        .zip(&ident.fit.solution)
        .map(|(v, s)| Some(v.unwrap_or(*s)))
        .collect();
    v
}

/// The exact predictions of `ident` on every record of `held` (see the module documentation).
///
/// # Errors
/// A record the fit's values cannot predict (named).
pub fn predict(
    m: &Machine,
    ident: &CampaignIdentification,
    held: &Campaign,
) -> Result<Vec<RecordValidation>, ValidateError> {
    let values = estimable(ident);
    let mut opts = ValidateOptions::default();
    opts.exact = true;
    held.records
        .iter()
        .map(|r| validate_record(m, &values, r, &opts))
        .collect()
}

/// Record `r`'s columns of `ident`'s parameters (mm per unit; one per parameter of the fit,
/// zero where the record's prediction does not use it), and the span of its refitted columns.
fn record_columns(
    m: &Machine,
    ident: &CampaignIdentification,
    r: &CampaignRecord,
) -> Result<(DMatrix<f64>, Span), DiagnoseError> {
    let values = estimable(ident);
    let plan = record_plan(m, &values, r)?;
    let mut source = GainSource::new(m, &plan.model.errors(), &r.params)?;
    let h = block(m, &plan.model, &r.record, &mut source, plan.clock)?;
    let rows = h.nrows();
    let mut b = DMatrix::zeros(rows, ident.fit.names.len());
    let mut refit = Vec::new();
    for (k, s) in plan.sources.iter().enumerate() {
        match s {
            Some(c) => {
                let mut target = b.column_mut(*c);
                target += h.column(k);
            }
            None => refit.push(k),
        }
    }
    let refit_span = Span::of_groups(rows, 0..refit.len(), &|i| {
        h.columns(refit[i], 1).into_owned()
    });
    Ok((b, refit_span))
}

/// The confounded groups of `ident` (by name) the prediction on held-out record `r` needs: a
/// null direction of the fit that changes the prediction, once the record's refitted columns
/// have taken what they can.
///
/// # Errors
/// A record whose columns cannot be built.
pub fn needed_groups(
    m: &Machine,
    ident: &CampaignIdentification,
    r: &CampaignRecord,
) -> Result<Vec<Vec<String>>, DiagnoseError> {
    let fit = &ident.fit;
    let null = &fit.identifiability.null_space;
    if null.ncols() == 0 {
        return Ok(Vec::new());
    }
    let (mut b, refit_span) = record_columns(m, ident, r)?;
    for j in 0..b.ncols() {
        let mut c = b.column_mut(j);
        c /= fit.column_norms[j];
    }
    let scale = (0..b.ncols())
        .map(|j| b.column(j).norm())
        .fold(0.0, f64::max);
    let mut groups: Vec<usize> = Vec::new();
    for k in 0..null.ncols() {
        let n = null.column(k);
        let moved = refit_span.project_out(&(&b * n));
        if moved.norm() <= NEEDS_TOLERANCE * scale {
            continue;
        }
        for (g, members) in fit.identifiability.confounded.iter().enumerate() {
            if members.iter().any(|&j| n[j].abs() > NEEDS_TOLERANCE) && !groups.contains(&g) {
                groups.push(g);
            }
        }
    }
    groups.sort_unstable();
    Ok(groups
        .iter()
        .map(|&g| {
            fit.identifiability.confounded[g]
                .iter()
                .map(|&j| fit.names[j].clone())
                .collect()
        })
        .collect())
}

/// How well the fit `ident` determines a change `dp` of its prediction of record `r` (mm, one
/// `[x, y, z]` per sample: what the terms `terms` added to the model change there): `Some(0)`
/// when the prediction needs a null direction of the fit that moves a parameter of `terms` (the
/// fit lacks the record that determines them); otherwise `dp`, after the record's refitted
/// columns, over the standard uncertainty of the fit's prediction along it, `‖dp‖² / √(wᵀ·Σ·w)`
/// with `w = Bᵀ·dp`, `B` the record's columns of the fit's parameters and `Σ` their covariance
/// (the parameters with a value; for one term added alone, about its value over its standard
/// uncertainty). `None` when `dp` is nothing or the fit gives no covariance.
///
/// # Errors
/// A record whose columns cannot be built.
pub fn determined_sd(
    m: &Machine,
    ident: &CampaignIdentification,
    r: &CampaignRecord,
    terms: &[Term],
    dp: &[[f64; 3]],
) -> Result<Option<f64>, DiagnoseError> {
    let fit = &ident.fit;
    let (b, refit_span) = record_columns(m, ident, r)?;
    let scaled = DMatrix::from_fn(b.nrows(), b.ncols(), |i, j| b[(i, j)] / fit.column_norms[j]);
    let scale = (0..b.ncols())
        .map(|j| scaled.column(j).norm())
        .fold(0.0, f64::max);
    let null = &fit.identifiability.null_space;
    for k in 0..null.ncols() {
        let n = null.column(k);
        let moves = (0..n.len())
            .any(|j| n[j].abs() > NEEDS_TOLERANCE && terms.contains(&ident.layout.columns[j].term));
        if moves && refit_span.project_out(&(&scaled * n)).norm() > NEEDS_TOLERANCE * scale {
            return Ok(Some(0.0));
        }
    }
    let d = refit_span.project_out(&DVector::from_iterator(
        b.nrows(),
        dp.iter().flat_map(|x| x.iter().copied()),
    ));
    let det: Vec<usize> = (0..fit.names.len())
        .filter(|&j| fit.values[j].is_some())
        .collect();
    let w: Vec<f64> = det.iter().map(|&j| b.column(j).dot(&d)).collect();
    let mut var = 0.0;
    for (a, &i) in det.iter().enumerate() {
        for (c, &j) in det.iter().enumerate() {
            var += w[a] * fit.covariance[(i, j)] * w[c];
        }
    }
    Ok(if var.is_finite() && var > 0.0 {
        Some(d.norm_squared() / var.sqrt())
    } else {
        None
    })
}

/// RMS of `residual` without the samples of `drop`, mm.
fn rms_without(residual: &[[f64; 3]], drop: &[usize]) -> f64 {
    let kept: Vec<[f64; 3]> = (0..residual.len())
        .filter(|i| !drop.contains(i))
        .map(|i| residual[i])
        .collect();
    statistics(&kept, &vec![[0.0; 3]; kept.len()])
        .1
        .measured_rms
}

/// The gain on every record of `held`: the base predictions `before` ([`predict`]) and the
/// extended ones, outliers left out, undetermined needs named.
///
/// # Errors
/// A prediction that cannot be made.
pub fn held_out_gain(
    m: &Machine,
    base: &CampaignIdentification,
    before: &[RecordValidation],
    extended: &CampaignIdentification,
    held: &Campaign,
) -> Result<Vec<HeldOut>, DiagnoseError> {
    let after = predict(m, extended, held)?;
    let mut out = Vec::with_capacity(held.records.len());
    for ((rec, b), a) in held.records.iter().zip(before).zip(after) {
        let found = outliers::find_in(&rec.record, &b.validation.residual);
        let drop = outliers::samples(&found);
        out.push(HeldOut {
            name: rec.label.clone(),
            setup: rec.setup.clone(),
            setup_fitted: a.setup_fitted,
            zeroed: rec.zeroed,
            params: rec.params.clone(),
            samples: rec.record.samples.len(),
            refitted: a.refitted.iter().map(|r| r.name.clone()).collect(),
            readings: 3 * (rec.record.samples.len() - drop.len()),
            before_rms: rms_without(&b.validation.residual, &drop),
            after_rms: rms_without(&a.validation.residual, &drop),
            residual_after: a.validation.residual,
            residual_before: b.validation.residual.clone(),
            outliers: found,
            undetermined_before: needed_groups(m, base, rec)?,
            undetermined_after: needed_groups(m, extended, rec)?,
        });
    }
    Ok(out)
}
