//! What the diagnosis report says of a campaign (`rtest diagnose --data a.csv,b.csv` or
//! `--campaign FILE`): the `campaign` field of [`super::DiagnosisReport`], absent for one
//! record.
//!
//! ```json
//! "campaign": {"records": [{"label": "k4", "data": "k4.csv", "setup": "k4", "samples": 241,
//!                           "residual_rms_before_um": 0.948, "residual_rms_after_um": 0.498,
//!                           "outliers": [{"line": 57, "direction": "y", "residual_um": 9.1}]}],
//!              "held_out": [{"name": "k2", "setup": "k2", "setup_fitted": false}],
//!              "notes": ["…"]}
//! ```

use super::{NonFinite, finite};
use crate::diagnosis::campaign::CampaignPart;
use model_spec::units::UM_PER_MM;
use serde::{Deserialize, Serialize};

/// An outlier of a fitted record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CampaignOutlierReport {
    /// The line of the record's file; absent when the record was not read from a file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line: Option<usize>,
    /// The sample (0-based) in its record.
    pub sample: usize,
    /// `x`, `y` or `z`.
    pub direction: String,
    /// The base fit's residual there, µm.
    pub residual_um: f64,
}

/// One fitted record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CampaignDiagnosisRecord {
    /// Its label.
    pub label: String,
    /// Its file.
    pub data: String,
    /// Its set-up's label.
    pub setup: String,
    /// Its samples, outliers included.
    pub samples: usize,
    /// Its residual RMS under the base model, µm (outliers left out).
    pub residual_rms_before_um: f64,
    /// Under the extended model, µm.
    pub residual_rms_after_um: f64,
    /// Its outliers, left out of every fit and test.
    pub outliers: Vec<CampaignOutlierReport>,
}

/// One held-out record's set-up.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CampaignHeldOut {
    /// Its name.
    pub name: String,
    /// Its set-up's label.
    pub setup: String,
    /// Whether its set-up was fitted (else its set-up errors were refitted on it, the machine's
    /// values held).
    pub setup_fitted: bool,
}

/// The campaign part of a diagnosis report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CampaignDiagnosisReport {
    /// The fitted records.
    pub records: Vec<CampaignDiagnosisRecord>,
    /// The held-out records' set-ups.
    pub held_out: Vec<CampaignHeldOut>,
    /// What differs from a single record's diagnosis.
    pub notes: Vec<String>,
}

impl CampaignDiagnosisReport {
    /// The report of `part`, `data` the fitted records' files and `held` the held-out records'
    /// names, in order.
    ///
    /// # Errors
    /// [`NonFinite`] for an RMS or residual that is not finite.
    pub fn new(
        part: &CampaignPart,
        data: &[String],
        held: &[String],
    ) -> Result<CampaignDiagnosisReport, NonFinite> {
        let records = part
            .records
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let f = |w: &str| format!("campaign.records[{i}].{w}");
                Ok(CampaignDiagnosisRecord {
                    label: r.label.clone(),
                    data: data.get(i).cloned().unwrap_or_default(),
                    setup: r.setup.clone(),
                    samples: r.samples,
                    residual_rms_before_um: finite(
                        || f("residual_rms_before_um"),
                        r.rms.0 * UM_PER_MM,
                    )?,
                    residual_rms_after_um: finite(
                        || f("residual_rms_after_um"),
                        r.rms.1 * UM_PER_MM,
                    )?,
                    outliers: r
                        .outliers
                        .iter()
                        .map(|o| {
                            Ok(CampaignOutlierReport {
                                line: o.line,
                                sample: o.sample,
                                direction: ["x", "y", "z"][o.direction.min(2)].into(),
                                residual_um: finite(
                                    || f("outliers.residual_um"),
                                    o.residual_mm * UM_PER_MM,
                                )?,
                            })
                        })
                        .collect::<Result<_, NonFinite>>()?,
                })
            })
            .collect::<Result<_, NonFinite>>()?;
        Ok(CampaignDiagnosisReport {
            records,
            held_out: part
                .held_out_setups
                .iter()
                .zip(held)
                .map(|((setup, fitted), name)| CampaignHeldOut {
                    name: name.clone(),
                    setup: setup.clone(),
                    setup_fitted: *fitted,
                })
                .collect(),
            notes: vec![
                "every record is fitted with its own kinematic parameters, its set-up's errors and its own zero; the machine's errors are shared".into(),
                "a candidate's columns are those the campaign gives it (one per record for a drift of the R-test's zero), and its F-test counts them all".into(),
                "scanned parameters (period:P, step:V, exp:TAU) keep the grid value they were selected at: the fine profile is not made on campaigns".into(),
                "a held-out record on a set-up that was not fitted has its set-up errors (and its zero when zeroed) refitted on it, the machine's values held: its residual is after those".into(),
                "the lack-of-fit test fits each fitted record's draws with that record's own columns alone: it errs towards `not down to the noise`".into(),
            ],
        })
    }
}
