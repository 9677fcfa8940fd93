//! The records of a diagnosis report: every record, fitted or held out, with its set-up, its
//! kinematic parameters, its residual before and after and what was refitted on it; the
//! findings dropped; and what differs when several records were fitted.

use super::{NonFinite, finite};
use diagnosis::Diagnosis;
use model_spec::Machine;
use model_spec::units::UM_PER_MM;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// One record of the diagnosis, fitted or held out.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RecordReport {
    /// Its label (names its own parameters: `dx0[k4]`).
    pub label: String,
    /// Its file.
    pub data: String,
    /// `fitted` or `held out`.
    pub role: String,
    /// Its set-up's label (records on one set-up share the ball's set-up errors).
    pub setup: String,
    /// Whether its set-up was fitted: always for a fitted record; for a held-out record, whether
    /// its set-up errors come from the fit (else they were refitted on it).
    pub setup_fitted: bool,
    /// Whether its readings were zeroed at the first sample.
    pub zeroed: bool,
    /// Its samples, outliers included.
    pub samples: usize,
    /// Its kinematic parameters, mm.
    pub params: BTreeMap<String, f64>,
    /// Its residual RMS under the base model, µm (outliers left out; a held-out record: the
    /// prediction's).
    pub residual_rms_before_um: f64,
    /// Under the extended model, µm.
    pub residual_rms_after_um: f64,
    /// The extended model's parameters refitted on a held-out record (a new set-up's errors,
    /// its own zero and drifts); absent when none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub refitted: Vec<String>,
}

/// A finding left out because the fit of the extended model with it did not converge.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DroppedReport {
    /// `NAME@BASIS`.
    pub term: String,
    /// The refinement's failure.
    pub why: String,
}

/// Every record of `d`: the fitted ones, then the held-out ones, with their files.
pub(super) fn records(
    m: &Machine,
    d: &Diagnosis,
    file_of: &dyn Fn(&str) -> String,
) -> Result<Vec<RecordReport>, NonFinite> {
    let params = |p: &[f64]| -> BTreeMap<String, f64> {
        m.symbols
            .iter()
            .zip(p)
            .map(|(s, v)| (s.name.clone(), *v))
            .collect()
    };
    let um =
        |i: usize, what: &str, v: f64| finite(|| format!("records[{i}].{what}"), v * UM_PER_MM);
    let mut out = Vec::with_capacity(d.records.len() + d.validation.len());
    for (i, r) in d.records.iter().enumerate() {
        out.push(RecordReport {
            label: r.label.clone(),
            data: file_of(&r.label),
            role: "fitted".into(),
            setup: r.setup.clone(),
            setup_fitted: true,
            zeroed: r.zeroed,
            samples: r.samples,
            params: params(&r.params),
            residual_rms_before_um: um(i, "residual_rms_before_um", r.rms.0)?,
            residual_rms_after_um: um(i, "residual_rms_after_um", r.rms.1)?,
            refitted: Vec::new(),
        });
    }
    for h in &d.validation {
        let i = out.len();
        out.push(RecordReport {
            label: h.name.clone(),
            data: file_of(&h.name),
            role: "held out".into(),
            setup: h.setup.clone(),
            setup_fitted: h.setup_fitted,
            zeroed: h.zeroed,
            samples: h.samples,
            params: params(&h.params),
            residual_rms_before_um: um(i, "residual_rms_before_um", h.before_rms)?,
            residual_rms_after_um: um(i, "residual_rms_after_um", h.after_rms)?,
            refitted: h.refitted.clone(),
        });
    }
    Ok(out)
}

/// What a reader should know of how `d` was made when several records were fitted.
pub(super) fn notes(d: &Diagnosis) -> Vec<String> {
    if d.records.len() < 2 {
        return Vec::new();
    }
    vec![
        "a candidate's F-test counts every column the campaign gives it (one per record for a drift of the R-test's zero, one per set-up for a set-up error)".into(),
        "the lack-of-fit test fits each fitted record's draws with that record's own columns alone, and draws the held-out records' noise without the fit's uncertainty: it errs towards `not down to the noise` on the fitted records".into(),
    ]
}
