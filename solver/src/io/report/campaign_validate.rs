//! The campaign validation report (`rtest validate --json` with a campaign to predict, or the
//! values of a campaign identification): per record, the residual before (nominal machine) and
//! after (the identified values, with what was refitted on the record), and over all records.
//!
//! ```json
//! {"kind": "campaign", "machine": "seed-ac", "model": "reduced", "params": "ident.json",
//!  "prediction": "exact", "samples": 602, "measured_rms_um": …, "residual_rms_um": …, …,
//!  "per_direction": {"x": {…}, "y": {…}, "z": {…}},
//!  "records": [{"label": "k1", "data": "k1.csv", "setup": "b", "setup_fitted": false,
//!               "record_fitted": false, "samples": 361,
//!               "refitted": [{"name": "XOW[b]", "value": 3.1, "std": 0.02, "unit": "um"}, …],
//!               "measured_rms_um": …, …, "per_direction": {…},
//!               "unidentified_set_to_zero": []}, …]}
//! ```
//!
//! `refitted` lists the parameters fitted on the record itself (a set-up that was not fitted,
//! the record's own zero and drift), with every other value held: that record's residual is
//! after those parameters were fitted on it.

use super::validate::{DirectionReport, PerDirectionReport, direction};
use super::{NonFinite, finite_opt};
use crate::fitting::campaign::CampaignValidation;
use model_spec::Machine;
use serde::Serialize;

/// A parameter refitted on a validation record, in its unit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RefittedReport {
    /// Its name (`XOW[b]`, `dx0[k1]`).
    pub name: String,
    /// Its value on the record; `null` when the record cannot separate it.
    pub value: Option<f64>,
    /// Its standard uncertainty; `null` where there is no value.
    pub std: Option<f64>,
    /// `um`, `urad`, `ms` or `1`.
    pub unit: String,
}

/// One record of a campaign validation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RecordValidationReport {
    /// Its label.
    pub label: String,
    /// The measurement file.
    pub data: String,
    /// Its set-up's label.
    pub setup: String,
    /// Whether its set-up was fitted (its set-up values came from the identification).
    pub setup_fitted: bool,
    /// Whether the record itself was fitted (its own values came from the identification).
    pub record_fitted: bool,
    /// Its samples.
    pub samples: usize,
    /// The parameters fitted on this record, every other value held.
    pub refitted: Vec<RefittedReport>,
    /// Over its three directions.
    #[serde(flatten)]
    pub overall: DirectionReport,
    /// Per direction.
    pub per_direction: PerDirectionReport,
    /// Parameters without a value that the prediction set to 0.
    pub unidentified_set_to_zero: Vec<String>,
}

/// The campaign validation report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CampaignValidationReport {
    /// Always `campaign`.
    pub kind: String,
    /// Machine name.
    pub machine: String,
    /// The model's label.
    pub model: String,
    /// The identification report whose values were applied.
    pub params: String,
    /// `exact` or `first-order`.
    pub prediction: String,
    /// Samples over every record.
    pub samples: usize,
    /// Over every record and direction.
    #[serde(flatten)]
    pub overall: DirectionReport,
    /// Per direction, over every record.
    pub per_direction: PerDirectionReport,
    /// Per record.
    pub records: Vec<RecordValidationReport>,
}

/// Where the values and records of a campaign validation come from.
#[derive(Clone, Copy, Debug)]
pub struct CampaignValidationSource<'a> {
    /// The model's label.
    pub model: &'a str,
    /// The identification report file.
    pub params: &'a str,
    /// Per record, its measurement file.
    pub data: &'a [String],
    /// Exact prediction (`true`) or first order.
    pub exact: bool,
}

impl CampaignValidationReport {
    /// The report of `v` on machine `m`.
    ///
    /// # Errors
    /// [`NonFinite`] when a statistic or refitted value is not finite.
    pub fn new(
        m: &Machine,
        source: CampaignValidationSource,
        v: &CampaignValidation,
    ) -> Result<CampaignValidationReport, NonFinite> {
        let mut records = Vec::with_capacity(v.records.len());
        for (r, rv) in v.records.iter().enumerate() {
            let at = |f: &str| format!("records[{r}].{f}");
            let [x, y, z] = &rv.validation.per_direction;
            let refitted = rv
                .refitted
                .iter()
                .enumerate()
                .map(|(k, p)| {
                    let f = p.term.display_factor(m);
                    Ok(RefittedReport {
                        name: p.name.clone(),
                        value: finite_opt(
                            || at(&format!("refitted[{k}].value")),
                            p.value.map(|x| x * f),
                        )?,
                        std: finite_opt(
                            || at(&format!("refitted[{k}].std")),
                            p.std.map(|x| x * f),
                        )?,
                        unit: p.term.unit(m).to_string(),
                    })
                })
                .collect::<Result<_, NonFinite>>()?;
            records.push(RecordValidationReport {
                label: rv.label.clone(),
                data: source.data.get(r).cloned().unwrap_or_default(),
                setup: rv.setup.clone(),
                setup_fitted: rv.setup_fitted,
                record_fitted: rv.record_fitted,
                samples: rv.validation.samples,
                refitted,
                overall: direction(&at("overall"), &rv.validation.overall)?,
                per_direction: PerDirectionReport {
                    x: direction(&at("per_direction.x"), x)?,
                    y: direction(&at("per_direction.y"), y)?,
                    z: direction(&at("per_direction.z"), z)?,
                },
                unidentified_set_to_zero: rv.validation.defaulted.clone(),
            });
        }
        let [x, y, z] = &v.per_direction;
        Ok(CampaignValidationReport {
            kind: super::campaign::CAMPAIGN_KIND.into(),
            machine: m.name.clone(),
            model: source.model.into(),
            params: source.params.into(),
            prediction: if source.exact { "exact" } else { "first-order" }.into(),
            samples: v.records.iter().map(|r| r.validation.samples).sum(),
            overall: direction("overall", &v.overall)?,
            per_direction: PerDirectionReport {
                x: direction("per_direction.x", x)?,
                y: direction("per_direction.y", y)?,
                z: direction("per_direction.z", z)?,
            },
            records,
        })
    }
}

impl RecordValidationReport {
    /// Per-direction and overall statistics: `[x, y, z, all]`.
    pub fn rows(&self) -> [(&'static str, &DirectionReport); 4] {
        [
            ("x", &self.per_direction.x),
            ("y", &self.per_direction.y),
            ("z", &self.per_direction.z),
            ("all", &self.overall),
        ]
    }
}
