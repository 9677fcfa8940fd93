//! The lack-of-fit test of the extended model on every record ([`super::adequacy`]) and what
//! remains where it fails ([`super::unexplained`]): what the diagnosis hands them.
//!
//! Each fitted record's residual is tested with its own columns of the extended design (its
//! owners': shared, its set-up's, its own); each held-out record's residual after the extended
//! model's prediction. With one fitted record the bootstrap carries the fit's own uncertainty
//! into the held-out predictions (each draw's fit predicts them, through the held-out records'
//! columns of the parameters they take from the fit). With several, each fitted record's
//! draws are fitted with that record's own columns alone (a joint fit of the draws is not
//! made), so that their residuals are a little smaller than the joint fit's and the test errs
//! towards "not down to the noise", and the held-out draws are the noise alone. A held-out
//! record's refitted parameters (a new set-up's errors, its own zero and drifts) are not
//! refitted in the draws: a few columns out of three per sample, which makes the draws larger
//! by about that share and the test a little more lenient there.

use super::adequacy::{self, Adequacy};
use super::columns::Columns;
use super::heldout::HeldOut;
use super::jump;
use super::unexplained::{self, Unexplained};
use super::weights::Weights;
use super::{DiagnoseError, DiagnoseOptions, outliers};
use fitting::campaign::CampaignIdentification;
use fitting::campaign::design::{Owner, block};
use fitting::hmatrix::GainSource;
use fitting::noise::{NoiseModel, NoiseSource};
use fitting::with_offsets;
use model_spec::Machine;
use nalgebra::DMatrix;
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::model::Model;
use simulation::record::Record;

/// What the test needs of a diagnosis.
pub(super) struct Inputs<'a> {
    /// The machine.
    pub m: &'a Machine,
    /// The options (α, seed, draws).
    pub o: &'a DiagnoseOptions,
    /// The noise model.
    pub noise: &'a NoiseModel,
    /// The noise model the selection whitened with (φ raised when estimated).
    pub whitening: &'a NoiseModel,
    /// Whether the noise model was estimated from the records.
    pub estimated: bool,
    /// The selection's columns.
    pub cols: &'a Columns,
    /// The groups of the extended model (base terms, then the plausible findings' coarse
    /// candidates).
    pub groups: &'a [usize],
    /// The same as a model, in the same order.
    pub as_candidates: &'a Model,
    /// The fitted records, outliers left out.
    pub cleaned: &'a Campaign,
    /// The base model's fit (its residual on the fitted records is described too when the
    /// extended model fails).
    pub base_fit: &'a CampaignIdentification,
    /// The extended model's fit.
    pub extended_fit: &'a CampaignIdentification,
    /// The held-out records.
    pub held_out: &'a Campaign,
    /// Their gains.
    pub validation: &'a [HeldOut],
    /// The per-sample weights.
    pub weights: &'a Weights,
}

/// The columns of `model` (the fitted record's groups, in order) on held-out record `rec`
/// (outliers left out) for the parameters it takes from the fit of the one fitted record; zero
/// for those refitted on it. `owners` gives the owner of each of the fitted record's columns.
fn predicted_columns(
    m: &Machine,
    model: &Model,
    owners: &[(usize, Owner)],
    setup_fitted: bool,
    rec: &CampaignRecord,
    record: &Record,
) -> Result<DMatrix<f64>, DiagnoseError> {
    let own = if rec.zeroed {
        with_offsets(model)
    } else {
        model.clone()
    };
    let mut source = GainSource::new(m, &own.errors(), &rec.params)?;
    let h = block(m, &own, record, &mut source, None)?;
    let mut out = DMatrix::zeros(h.nrows(), owners.len());
    // Column k of `own` is (term, component) of the model's columns in order; the fitted
    // record's columns follow the same terms in the same order.
    for (k, &(column, owner)) in owners.iter().enumerate() {
        let taken = match owner {
            Owner::Shared => true,
            Owner::Setup(_) => setup_fitted,
            Owner::Record(_) => false,
        };
        if taken {
            out.set_column(k, &h.column(column));
        }
    }
    Ok(out)
}

/// The lack-of-fit test of the extended model and what remains where it fails; `Err(why)`
/// when there is no noise model independent of the fit or no test was asked for.
///
/// # Errors
/// Columns of a held-out record that cannot be built, or weights that do not whiten.
pub(super) fn test(
    i: &Inputs,
) -> Result<(Result<Adequacy, String>, Vec<Unexplained>), DiagnoseError> {
    let Inputs {
        m,
        o,
        noise,
        whitening,
        estimated,
        cols,
        groups,
        as_candidates,
        cleaned,
        base_fit,
        extended_fit,
        held_out,
        validation,
        weights,
    } = *i;
    match &noise.source {
        NoiseSource::Residual { why } => return Ok((Err(why.clone()), Vec::new())),
        _ if o.adequacy_draws == 0 => {
            return Ok((Err("not asked for (no bootstrap draws)".into()), Vec::new()));
        }
        _ => {}
    }
    // The fitted records: residuals and their own columns, whitened per sample.
    let mut residual = extended_fit.fit.residual.clone();
    weights.fitted_vector(&mut residual)?;
    let columns = cols.columns_of(groups);
    let mut h_fitted = cols.h_raw.select_columns(&columns);
    weights.fitted_matrix(&mut h_fitted)?;
    let mut fitted_residuals = Vec::with_capacity(cleaned.records.len());
    let mut blocks = Vec::with_capacity(cleaned.records.len());
    let mut at = 0;
    for (r, rec) in cleaned.records.iter().enumerate() {
        let rows = 3 * rec.record.samples.len();
        fitted_residuals.push(residual.rows(at, rows).into_owned());
        blocks.push(cols.record_block(&h_fitted, &columns, r));
        at += rows;
    }
    // The held-out records: residuals after the extended model (outliers left out) and, with
    // one fitted record, their columns of the parameters taken from its fit.
    let single = cleaned.records.len() == 1;
    let owners: Vec<(usize, Owner)> = if single {
        columns
            .iter()
            .enumerate()
            .map(|(k, &j)| (k, cols.layout.columns[cols.order[j]].owner))
            .collect()
    } else {
        Vec::new()
    };
    let mut held = Vec::with_capacity(validation.len());
    let mut predicted = Vec::with_capacity(validation.len());
    for (h, rec) in validation.iter().zip(&held_out.records) {
        let kept = rec.record.without(&outliers::samples(&h.outliers));
        let mut r = h.residual_after_without_outliers();
        weights.held_vector(&kept, &mut r)?;
        held.push(r);
        if single {
            let mut p = predicted_columns(m, as_candidates, &owners, h.setup_fitted, rec, &kept)?;
            weights.held_matrix(&kept, &mut p)?;
            predicted.push(Some(p));
        } else {
            predicted.push(None);
        }
    }
    let mut residuals: Vec<adequacy::Residual> = cleaned
        .records
        .iter()
        .enumerate()
        .map(|(r, rec)| adequacy::Residual {
            name: &rec.label,
            residual: &fitted_residuals[r],
            fitted: Some(&blocks[r]),
            predicted: None,
            zeroed: false,
        })
        .collect();
    residuals.extend(
        validation
            .iter()
            .zip(held.iter().zip(&predicted))
            .map(|(h, (r, p))| adequacy::Residual {
                name: &h.name,
                residual: r,
                fitted: None,
                predicted: p.as_ref(),
                zeroed: false,
            }),
    );
    // Drawn with φ raised as for the selection: an estimate of φ that runs low would make the
    // draws too tame and the test too eager.
    let a = adequacy::adequacy(
        whitening,
        estimated,
        &residuals,
        o.alpha,
        o.seed,
        o.adequacy_draws,
    )
    .map_err(|e| e.to_string());
    let described = match &a {
        Ok(a) => {
            let mut records: Vec<(&str, &Record, Vec<[f64; 3]>)> = cleaned
                .records
                .iter()
                .enumerate()
                .map(|(r, rec)| {
                    (
                        rec.label.as_str(),
                        &rec.record,
                        extended_fit.record_residual(r),
                    )
                })
                .collect();
            records.extend(
                validation
                    .iter()
                    .zip(&held_out.records)
                    .map(|(h, rec)| (h.name.as_str(), &rec.record, h.residual_after.clone())),
            );
            let mut described = unexplained::describe_failures(m, a, &records, o.alpha);
            // The findings may have absorbed on the fitted records what the held-out records
            // then mispredict: the base model's residual there is described where it is, as a
            // jump in time of the set-up or the zero where it is one ([`jump`]); and so it is
            // when the extended model holds a jump, which leaves the noise.
            let jumped = as_candidates
                .terms
                .iter()
                .any(|t| t.basis.jump_at().is_some());
            let jumps = if a.consistent_with_noise && !jumped {
                Vec::new()
            } else {
                jump::find(m, cleaned, cols, weights, whitening, o.alpha, &|r| {
                    base_fit.record_residual(r)
                })?
            };
            let base: Vec<(&str, &Record, Vec<[f64; 3]>)> = cleaned
                .records
                .iter()
                .enumerate()
                .map(|(r, rec)| (rec.label.as_str(), &rec.record, base_fit.record_residual(r)))
                .collect();
            let rest: Vec<Unexplained> = unexplained::describe_base(m, a, &base)
                .into_iter()
                .filter(|u| {
                    !jumps
                        .iter()
                        .any(|j| j.data == u.data && j.direction == u.direction)
                })
                .collect();
            described.extend(jumps);
            described.extend(rest);
            described
        }
        Err(_) => Vec::new(),
    };
    Ok((a, described))
}
