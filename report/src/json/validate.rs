//! The validation report (`rtest validate --json`): identified values predicting records, each
//! on its set-up; the residual per record, per direction and overall, before (the nominal
//! machine: prediction 0) and after (the identified values, with what was refitted on the
//! record), in µm. Overall RMS = `√(Σ r² / 3N)`. One type for one record and for several (a
//! record is a campaign of one).
//!
//! ```json
//! {"version": 2, "machine": "seed-ac", "model": "reduced", "params": "ident.json",
//!  "data": "k1.csv", "prediction": "exact", "samples": 361,
//!  "measured_rms_um": …, "measured_max_um": …, "residual_rms_um": …, "residual_max_um": …,
//!  "per_direction": {"x": {…}, "y": {…}, "z": {…}}, "zeroed": false,
//!  "unidentified_set_to_zero": [],
//!  "records": [{"label": "k1", "data": "k1.csv", "setup": "k4", "setup_fitted": true,
//!               "record_fitted": false, "zeroed": false, "params": {"Xw": -217.504, …},
//!               "samples": 361,
//!               "refitted": [{"name": "XOW[b]", "value": 3.1, "std": 0.02, "unit": "um"}, …],
//!               "measured_rms_um": …, …, "per_direction": {…},
//!               "unidentified_set_to_zero": []}]}
//! ```
//!
//! A validation of **several records** has `"kind": "campaign"` and no `data` nor `zeroed` (each
//! record says its own); its top-level statistics are over every record. `refitted` lists the
//! parameters fitted on the record itself (a set-up that was not fitted, the record's own zero
//! and drift), with every other value held: that record's residual is after those parameters
//! were fitted on it. `unidentified_set_to_zero` at the top lists every parameter some record's
//! prediction set to 0.
//!
//! A re-check (`--refit NAMES`) adds `recheck` ([`super::recheck`]): the machine parameters
//! refitted over every record, with every other value held.
//!
//! With `--tolerance FILE`, `tolerance` holds the verdict per test and direction, before and
//! after, with the rule and the noise it assumed ([`super::tolerance`]); it is absent
//! otherwise.
//!
//! `version` is 2; a report without it is version 1: a record's (`data`, `zeroed`, without
//! `records`) or a campaign's (`"kind": "campaign"`). [`ValidationReport::from_json`] reads
//! both.

use super::identify::{CAMPAIGN_KIND, REPORT_VERSION};
use super::read::{ReportError, versioned};
use super::tolerance::ToleranceReport;
use super::{NonFinite, Ordered, finite, finite_opt};
use fitting::campaign::CampaignValidation;
use fitting::validate::Stats;
use model_spec::Machine;
use model_spec::units::UM_PER_MM;
use serde::{Deserialize, Serialize};

/// RMS and max of one direction (or all three), µm.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DirectionReport {
    /// RMS of the measured values (nominal machine), µm.
    pub measured_rms_um: f64,
    /// Largest |measured value|, µm.
    pub measured_max_um: f64,
    /// RMS of measured minus predicted, µm.
    pub residual_rms_um: f64,
    /// Largest |measured minus predicted|, µm.
    pub residual_max_um: f64,
}

/// The three directions of the tool frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PerDirectionReport {
    /// x.
    pub x: DirectionReport,
    /// y.
    pub y: DirectionReport,
    /// z.
    pub z: DirectionReport,
}

impl PerDirectionReport {
    /// Per-direction and overall statistics (`overall` the last): `[x, y, z, all]`.
    pub fn rows<'a>(
        &'a self,
        overall: &'a DirectionReport,
    ) -> [(&'static str, &'a DirectionReport); 4] {
        [
            ("x", &self.x),
            ("y", &self.y),
            ("z", &self.z),
            ("all", overall),
        ]
    }
}

/// A parameter refitted on a validation record, in its unit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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

/// One record of a validation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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
    /// Whether its readings were zeroed at the first sample (its zero refitted, unless the
    /// record was fitted).
    #[serde(default)]
    pub zeroed: bool,
    /// Its kinematic parameters (the ball's position), every symbol in the machine's order,
    /// mm; empty in a version-1 report (the machine's defaults).
    #[serde(default)]
    pub params: Ordered<f64>,
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

impl RecordValidationReport {
    /// Per-direction and overall statistics: `[x, y, z, all]`.
    pub fn rows(&self) -> [(&'static str, &DirectionReport); 4] {
        self.per_direction.rows(&self.overall)
    }
}

fn version_1() -> u32 {
    1
}

/// The validation report (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ValidationReport {
    /// The report's version ([`REPORT_VERSION`]; 1 when the file has none).
    #[serde(default = "version_1")]
    pub version: u32,
    /// `campaign` for a validation of several records; absent for one record.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kind: Option<String>,
    /// Machine name.
    pub machine: String,
    /// The model's label (from the identification).
    pub model: String,
    /// The identification report whose values were applied.
    pub params: String,
    /// One record: its measurement file; absent for several (see `records`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub data: Option<String>,
    /// Samples over every record.
    pub samples: usize,
    /// `exact` (the exact machine at the values) or `first-order` (`H·v`).
    pub prediction: String,
    /// Over every record and all three directions (written as top-level fields:
    /// `measured_rms_um`, `measured_max_um`, `residual_rms_um`, `residual_max_um`).
    #[serde(flatten)]
    pub overall: DirectionReport,
    /// Per direction, over every record.
    pub per_direction: PerDirectionReport,
    /// One record: whether its readings were zeroed at the first sample; absent for several.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub zeroed: Option<bool>,
    /// Parameters without a value that a record's prediction set to 0 (each once).
    #[serde(default)]
    pub unidentified_set_to_zero: Vec<String>,
    /// Per record, in order.
    #[serde(default)]
    pub records: Vec<RecordValidationReport>,
    /// The verdicts against a tolerance file (`--tolerance`); absent without one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<ToleranceReport>,
    /// The re-check (`--refit`): the machine parameters refitted over the records
    /// ([`super::recheck`]); absent in a validation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub recheck: Option<super::recheck::RecheckReport>,
}

/// Where the values and records of a validation come from.
#[derive(Clone, Copy, Debug)]
pub struct ValidationSource<'a> {
    /// The model's label.
    pub model: &'a str,
    /// The identification report file.
    pub params: &'a str,
    /// Per record, its measurement file.
    pub data: &'a [String],
    /// Per record, its kinematic parameters (mm, symbol order).
    pub kinematics: &'a [Vec<f64>],
    /// Exact prediction (`true`) or first order.
    pub exact: bool,
}

/// The report of `s` (mm) in µm, `field` naming it when a value is not finite.
///
/// # Errors
/// [`NonFinite`].
pub(crate) fn direction(field: &str, s: &Stats) -> Result<DirectionReport, NonFinite> {
    let um = |what: &str, x: f64| finite(|| format!("{field}.{what}"), x * UM_PER_MM);
    Ok(DirectionReport {
        measured_rms_um: um("measured_rms_um", s.measured_rms)?,
        measured_max_um: um("measured_max_um", s.measured_max)?,
        residual_rms_um: um("residual_rms_um", s.residual_rms)?,
        residual_max_um: um("residual_max_um", s.residual_max)?,
    })
}

/// The per-direction report of `[x, y, z]`, `field` naming it.
fn per_direction(field: &str, s: &[Stats; 3]) -> Result<PerDirectionReport, NonFinite> {
    let [x, y, z] = s;
    Ok(PerDirectionReport {
        x: direction(&format!("{field}.x"), x)?,
        y: direction(&format!("{field}.y"), y)?,
        z: direction(&format!("{field}.z"), z)?,
    })
}

impl ValidationReport {
    /// The report of `v` on machine `m`: a record's when it has one record, a campaign's
    /// otherwise.
    ///
    /// # Errors
    /// [`NonFinite`] when a statistic or refitted value is not finite.
    pub fn new(
        m: &Machine,
        source: ValidationSource,
        v: &CampaignValidation,
    ) -> Result<ValidationReport, NonFinite> {
        let mut records = Vec::with_capacity(v.records.len());
        for (r, rv) in v.records.iter().enumerate() {
            let at = |f: &str| format!("records[{r}].{f}");
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
                zeroed: rv.zeroed,
                params: Ordered(match source.kinematics.get(r) {
                    Some(p) => m
                        .symbols
                        .iter()
                        .zip(p)
                        .map(|(s, &v)| (s.name.clone(), v + 0.0))
                        .collect(),
                    None => Vec::new(),
                }),
                samples: rv.validation.samples,
                refitted,
                overall: direction(&at("overall"), &rv.validation.overall)?,
                per_direction: per_direction(&at("per_direction"), &rv.validation.per_direction)?,
                unidentified_set_to_zero: rv.validation.defaulted.clone(),
            });
        }
        let mut unidentified: Vec<String> = Vec::new();
        for r in &records {
            for n in &r.unidentified_set_to_zero {
                if !unidentified.contains(n) {
                    unidentified.push(n.clone());
                }
            }
        }
        let one = records.len() == 1;
        Ok(ValidationReport {
            version: REPORT_VERSION,
            kind: (!one).then(|| CAMPAIGN_KIND.to_string()),
            machine: m.name.clone(),
            model: source.model.into(),
            params: source.params.into(),
            data: one.then(|| records[0].data.clone()),
            samples: v.records.iter().map(|r| r.validation.samples).sum(),
            prediction: if source.exact { "exact" } else { "first-order" }.into(),
            overall: direction("overall", &v.overall)?,
            per_direction: per_direction("per_direction", &v.per_direction)?,
            zeroed: one.then(|| records[0].zeroed),
            unidentified_set_to_zero: unidentified,
            records,
            tolerance: None,
            recheck: None,
        })
    }

    /// Reads a validation report from its JSON `text` (`file` names it in messages), of either
    /// version: a version-1 report of one record (without `records`) gains its record, labelled
    /// by the stem of its `data` file (its set-up unknown: `setup` empty).
    ///
    /// # Errors
    /// [`ReportError::Json`] for text that is not JSON, [`ReportError::Field`] for a missing or
    /// malformed field or a version this rtest does not know.
    pub fn from_json(file: &str, text: &str) -> Result<ValidationReport, ReportError> {
        let mut r: ValidationReport = versioned(file, text, |r: &ValidationReport| r.version)?;
        if r.records.is_empty() {
            let data = r.data.clone().unwrap_or_default();
            r.records.push(RecordValidationReport {
                label: super::read::single_label(r.data.as_deref()),
                data,
                setup: String::new(),
                setup_fitted: false,
                record_fitted: false,
                zeroed: r.zeroed.unwrap_or(false),
                params: Ordered(Vec::new()),
                samples: r.samples,
                refitted: Vec::new(),
                overall: r.overall.clone(),
                per_direction: r.per_direction.clone(),
                unidentified_set_to_zero: r.unidentified_set_to_zero.clone(),
            });
        }
        Ok(r)
    }

    /// `true` for a validation of several records (`"kind": "campaign"`).
    pub fn is_campaign(&self) -> bool {
        self.kind.as_deref() == Some(CAMPAIGN_KIND)
    }

    /// Per-direction and overall statistics over every record: `[x, y, z, all]`.
    pub fn rows(&self) -> [(&'static str, &DirectionReport); 4] {
        self.per_direction.rows(&self.overall)
    }
}
