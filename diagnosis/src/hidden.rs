//! What a model lacks according to a known truth (simulations only): the truth's terms the
//! model does not have, how much they move the readings, and the bias they put into the
//! model's identified values. A diagnosis works from the data alone; this is the check of a
//! diagnosis against the truth it could not see.

use fitting::refine::exact_prediction;
use fitting::{IdentifyError, IdentifyOptions, identify};
use model_spec::Machine;
use simulation::campaign::Campaign;
use simulation::model::Model;
use simulation::record::Record;
use simulation::truth::Truth;

/// The truth's terms a model lacks, and what they do.
#[derive(Clone, Debug, PartialEq)]
pub struct HiddenTerms {
    /// The truth's terms that are not in the model.
    pub model: Model,
    /// Their coefficients (mm or rad), one per column.
    pub values: Vec<Option<f64>>,
    /// Per record given, the RMS of their effect alone on the readings (mm, over 3N readings).
    pub rms_mm: Vec<f64>,
    /// The shift they put into the model's first-order values on the fitted record (one per
    /// model column, mm or rad; `None` where the model has no value); `None` when nothing is
    /// hidden.
    pub bias: Option<Vec<Option<f64>>>,
}

/// The terms of `truth` that `model` lacks, their effect on each of `records` and the bias
/// they put into `model` identified on `fitted` (noise-free, first order).
///
/// # Errors
/// A prediction or the fit of the bias that fails.
pub fn hidden_terms(
    m: &Machine,
    truth: &Truth,
    model: &Model,
    fitted: &Record,
    records: &[&Record],
) -> Result<HiddenTerms, IdentifyError> {
    let hidden = Model {
        terms: truth
            .model
            .terms
            .iter()
            .filter(|t| !model.terms.contains(t))
            .copied()
            .collect(),
    };
    let values: Vec<Option<f64>> = hidden
        .terms
        .iter()
        .flat_map(|t| truth.coefficient(t).unwrap_or(&[]).to_vec())
        .map(Some)
        .collect();
    let mut rms_mm = Vec::with_capacity(records.len());
    for r in records {
        let p = exact_prediction(m, &hidden, &values, r, &truth.params)?;
        let ss: f64 = p.iter().flat_map(|v| v.iter()).map(|x| x * x).sum();
        rms_mm.push((ss / (3 * p.len()).max(1) as f64).sqrt());
    }
    let bias = if hidden.terms.is_empty() {
        None
    } else {
        let measured = exact_prediction(m, &hidden, &values, fitted, &truth.params)?;
        let alone = Record {
            samples: fitted.samples.clone(),
            measured,
            covariance: fitted.covariance.clone(),
            lines: fitted.lines.clone(),
            probe: fitted.probe.clone(),
        };
        let campaign = Campaign::of_record(alone, m.default_parameters(), false);
        let ident = identify(m, model, &campaign, &IdentifyOptions::default())?;
        ident.single_record(m).map(|one| one.fit.values)
    };
    Ok(HiddenTerms {
        model: hidden,
        values,
        rms_mm,
        bias,
    })
}
