//! The identification report (`rtest identify --json`): one type for one record and for a
//! campaign of several (a record is a campaign of one).
//!
//! A report of **one record** (`--data k4.csv`, or a campaign file of one record) names its
//! parameters as a single fit does (`XOW`, `dx0`) and has `data` and `zeroed`:
//!
//! ```json
//! {"version": 2, "machine": "seed-ac", "fingerprint": "fa038fe9e24c960a", "data": "k4.csv",
//!  "model": "reduced", "base_model": "reduced", "terms": ["XOW", …, "BOC"],
//!  "setups": [{"label": "k4", "records": ["k4"]}],
//!  "records": [{"label": "k4", "data": "k4.csv", "setup": "k4", "params": {"Xw": -217.504, …},
//!               "zeroed": false, "samples": 241, "residual_rms_um": 0.49}],
//!  "parameters": [{"name": "XOC", "error": "XOC", "basis": "const", "value": 12.3, "std": 0.05,
//!                  "unit": "um", "determined": true, "fixed": false}, …],
//!  "residual_rms_um": 0.49, "rank": 11, "condition": 4.2, "confounded": [["XOC", "dx0"]], …,
//!  "zeroed": false, "refinement": {"method": "exact", "iterations": 3, "converged": true, …},
//!  "noise_model": {…}, "notes": […]}
//! ```
//!
//! A report of **several records** has `"kind": "campaign"`, no `data` nor `zeroed` (each record
//! says its own), and every parameter says whose it is: `owner` `shared` (the machine's errors,
//! one value for the campaign), `setup` (the ball set-up errors of the set-up `of`) or `record`
//! (the zero and drift of the R-test, and the terms of a time basis on a record's own clock, of
//! the record `of`), its name carrying the owner (`XOW[k4]`, `dx0[k1]`). Its `terms` are the
//! model as given, without the zero offsets its zeroed records add; a record's report lists them
//! with its terms. `clock` (`{"start_s", "end_s"}`) is there when the records are on one
//! campaign clock, and then every record has `start_s`.
//!
//! `version` is 2. A report without it is version 1, what rtest wrote before: a record's report
//! without `setups` and `records` (its record is the stem of `data`, on its own set-up, at the
//! machine's default kinematic parameters), or a campaign's (`"kind": "campaign"`) with them.
//! Both are read ([`super::read`], [`IdentificationReport::from_json`]).
//!
//! `noise_model` says which noise the uncertainties assume: `{"source": "estimated",
//! "sigma_um": [0.3, 0.3, 0.3], "phi": [0.8, 0.8, 0.8], "whitened_sigma": 1.02, "text": …}`
//! (`source`: `declared`, `static-record`, `estimated`, or `residual`, white with the σ̂ of an
//! ordinary fit).
//! `value` and `std` are `null` where the data do not determine the parameter; `basis` is
//! `const`, `harmonic:K:cos`, `harmonic:K:sin`, `poly:K`, `reversal` or `time:K`; `unit` is
//! `um` (translational errors, sensor offsets, changes of kinematic offsets) or `urad` (angular
//! errors). A kinematic offset (`"error": "Zt"`, a symbol of the description) also has
//! `nominal_mm`, the symbol's value its change `value` is from, and `identified_mm`, the
//! identified length (`null` when the change is not determined).

mod build;

use super::Ordered;
pub use super::fit_summary::{constraint_text, poly_stroke};
use super::read::{ReportError, versioned};
use fitting::hmatrix::Backend;
use serde::{Deserialize, Serialize};

/// The version of the reports this rtest writes.
pub const REPORT_VERSION: u32 = 2;

/// The value of `"kind"` in a report of several records.
pub const CAMPAIGN_KIND: &str = "campaign";

/// One parameter (a column of the design matrix), in its term's unit
/// ([`simulation::model::Term::unit`]): µm, µrad, ms (`velocity`) or 1 (instrument terms).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParameterReport {
    /// In a report of several records: `shared`, `setup` or `record`; absent in a record's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub owner: Option<String>,
    /// In a report of several records: the set-up's or the record's label of a `setup` or
    /// `record` parameter; absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub of: Option<String>,
    /// The parameter's name (`XOC`, `ECC@harmonic:2:cos`, `dx0`; `XOW[k4]` in a report of
    /// several records).
    pub name: String,
    /// Effect name (`XOC`, `dx0`).
    pub error: String,
    /// Basis column (`const`, `harmonic:2:cos`, `reversal`, …).
    pub basis: String,
    /// Estimate, in `unit`; `null` when the data do not determine it (and no constraint gives
    /// it a value).
    pub value: Option<f64>,
    /// Standard uncertainty, in `unit`; `null` when undetermined, fixed, or without a degree
    /// of freedom.
    pub std: Option<f64>,
    /// `um`, `urad`, `ms` (the lag of a `velocity` term) or `1` (an instrument term).
    pub unit: String,
    /// Whether the data determine it (fixed parameters count as determined).
    pub determined: bool,
    /// Fixed to 0 by the constraint.
    pub fixed: bool,
    /// For a `poly:K` column: the stroke of its axis the polynomial is normalised over, mm
    /// (the value means something only over the same stroke); absent for other bases.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub over_mm: Option<[f64; 2]>,
    /// For a kinematic offset (`error` a symbol of the description): the symbol's value the
    /// records were modelled with, mm, from which `value` (µm) is the change; absent for other
    /// parameters.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nominal_mm: Option<f64>,
    /// For a kinematic offset: the identified value of the symbol, `nominal_mm + value`, mm;
    /// `null` when the change is not determined; absent for other parameters.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        with = "present_or_null"
    )]
    pub identified_mm: Option<Option<f64>>,
}

/// An optional field whose value may be `null`: absent (`None`), `null` (`Some(None)`) or a
/// number (`Some(Some(x))`).
mod present_or_null {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(v: &Option<Option<f64>>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            Some(x) => x.serialize(s),
            None => s.serialize_none(),
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Option<f64>>, D::Error> {
        Option::<f64>::deserialize(d).map(Some)
    }
}

/// A pair of determined parameters with a high correlation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NearPairReport {
    /// The two parameter names.
    pub parameters: [String; 2],
    /// Correlation of their estimates, in [−1, 1].
    pub correlation: f64,
}

/// What the refinement against the exact machine did.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RefinementReport {
    /// `exact` (refined against the exact machine) or `first-order` (not refined).
    pub method: String,
    /// Gauss–Newton steps taken (0 for `first-order`).
    pub iterations: usize,
    /// Whether the last step was below the tolerance (always `true` for `first-order`, whose
    /// linear solution is exact). An identification that did not converge is not a result:
    /// `rtest identify` refuses it (exit code 3) and writes no file.
    pub converged: bool,
    /// Per step, the largest change of the prediction at any reading, µm.
    pub steps_um: Vec<f64>,
    /// The tolerance the steps were compared with, µm (1e-9 µm, or the rounding floor of an
    /// ill-conditioned fit when larger); absent for `first-order`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance_um: Option<f64>,
    /// Residual RMS of the first-order fit, µm.
    pub first_order_rms_um: f64,
}

/// The noise model the uncertainties assume ([`fitting::noise::NoiseModel`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NoiseModelReport {
    /// `declared`, `static-record`, `estimated`, or `residual` (white with the σ̂ of an
    /// ordinary fit: ordinary least squares).
    pub source: String,
    /// Marginal standard deviation of a reading per direction x, y, z, µm.
    pub sigma_um: [f64; 3],
    /// Lag-1 autocorrelation per direction x, y, z (0: white).
    pub phi: [f64; 3],
    /// σ̂ of the whitened residual (unitless, about 1 when the model's σ is right); `null` for
    /// an ordinary fit or without degrees of freedom.
    pub whitened_sigma: Option<f64>,
    /// The model for people, with where it came from.
    pub text: String,
}

/// How a record was read in blocks and folded into an incremental QR decomposition.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StreamingReport {
    /// Blocks read.
    pub blocks: usize,
    /// Samples per block asked for.
    pub block: usize,
    /// Samples of the first block (it reads ahead until every axis has moved).
    pub first_block: usize,
}

/// A group of sensor offsets and the errors they cannot be told from (zeroed readings).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SwallowedReport {
    /// The offsets (`dx0`).
    pub offsets: Vec<String>,
    /// The errors (`XOC`); empty when the offsets are confounded with each other only.
    pub errors: Vec<String>,
}

/// One set-up (one ball mounting): its label and its records.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SetupReport {
    /// The set-up's label.
    pub label: String,
    /// The labels of its records.
    pub records: Vec<String>,
}

/// One record of an identification.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RecordReport {
    /// Its label.
    pub label: String,
    /// The measurement file it was read from.
    pub data: String,
    /// Its set-up's label.
    pub setup: String,
    /// Its kinematic parameters (the ball's position lives here), every symbol in the
    /// machine's order, mm. Empty in a version-1 report of one record: the machine's defaults.
    #[serde(default)]
    pub params: Ordered<f64>,
    /// Whether its readings were zeroed at the first sample (its own `dx0 dy0 dz0` fitted).
    pub zeroed: bool,
    /// Its time 0 on the campaign clock, s; absent when the records keep their own clocks.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_s: Option<f64>,
    /// Its samples.
    pub samples: usize,
    /// The residual RMS of its readings, `√(RSS_r / 3N_r)`, µm.
    pub residual_rms_um: f64,
}

/// The campaign clock's span, s.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClockReport {
    /// The first sample of all records on the campaign clock, s.
    pub start_s: f64,
    /// The last, s.
    pub end_s: f64,
}

fn version_1() -> u32 {
    1
}

/// The identification report (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IdentificationReport {
    /// The report's version ([`REPORT_VERSION`]; 1 when the file has none).
    #[serde(default = "version_1")]
    pub version: u32,
    /// `campaign` for a report of several records; absent for one record.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kind: Option<String>,
    /// Machine name.
    pub machine: String,
    /// The machine's fingerprint (topology and machine-side kinematic defaults): values are
    /// applied only to a machine with the same fingerprint.
    pub fingerprint: String,
    /// One record: the measurement file fitted; absent for several (see `records`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub data: Option<String>,
    /// The model's label (`reduced`, `reduced + ECC@harmonic:2`, `XOC + EXX@poly:1`).
    pub model: String,
    /// The machine's model it starts from (`--model`); absent when the model is a list of
    /// terms only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_model: Option<String>,
    /// The terms fitted, in order (`XOC`, `ECC@harmonic:2`, `dx0`): one record's with the
    /// offsets of zeroed readings; several records': the model as given.
    pub terms: Vec<String>,
    /// The set-ups, in order of first appearance.
    #[serde(default)]
    pub setups: Vec<SetupReport>,
    /// The records, in order.
    #[serde(default)]
    pub records: Vec<RecordReport>,
    /// The campaign clock, when the records are on one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clock: Option<ClockReport>,
    /// Every parameter: one record's in its model's order; several records' shared, then per
    /// set-up, then per record.
    pub parameters: Vec<ParameterReport>,
    /// `√(RSS / 3N)` over every record, µm.
    pub residual_rms_um: f64,
    /// Numerical rank of the column-scaled H (the stacked design matrix).
    pub rank: usize,
    /// Free parameters (not fixed by the constraint).
    pub free_parameters: usize,
    /// Condition number of the scaled H over the identifiable part; `null` when the rank is 0.
    pub condition: Option<f64>,
    /// Groups of parameters the data cannot separate (parameter names).
    pub confounded: Vec<Vec<String>>,
    /// Number of samples fitted, over every record.
    pub samples: usize,
    /// Readings fitted (3 per sample).
    pub readings: usize,
    /// Degrees of freedom `3N − rank`.
    pub dof: usize,
    /// One record: whether its readings were zeroed at the first sample (then `dx0 dy0 dz0`
    /// were fitted); absent for several (see `records`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub zeroed: Option<bool>,
    /// `none`, `minimum-norm` or `zero: NAME, …`.
    pub constraint: String,
    /// σ̂ = √(RSS / (3N − rank)), µm; `null` without degrees of freedom.
    pub sigma_um: Option<f64>,
    /// Determined pairs with |correlation| > 0.99.
    pub near_confounded: Vec<NearPairReport>,
    /// What the sensor offsets swallow (zeroed readings).
    pub swallowed: Vec<SwallowedReport>,
    /// `compiled`, `evaluator` or `mixed`: the code that computed the gains.
    pub gains: String,
    /// The refinement against the exact machine.
    pub refinement: RefinementReport,
    /// The noise model the uncertainties assume (one for every record, records independent);
    /// absent in reports written before noise models existed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise_model: Option<NoiseModelReport>,
    /// How a long record was read in blocks (`--stream`); absent when it was read whole.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub streaming: Option<StreamingReport>,
    /// The touch probe's sphere fits and the dispersion per rotary axis, when the records
    /// were read through a probe (`--probe`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probe: Option<super::probe::ProbeReport>,
    /// Statements for people (what was swallowed, what has no value and why, non-convergence,
    /// set-up errors the records cannot tell from the machine's).
    pub notes: Vec<String>,
}

/// The name of a gain backend in reports.
pub fn backend_name(b: Backend) -> &'static str {
    match b {
        Backend::Compiled => "compiled",
        Backend::Evaluator => "evaluator",
        Backend::Mixed => "mixed",
    }
}

/// What an identification report says besides the identification: the model's label and base
/// model, and each record's data file (in order).
#[derive(Clone, Copy, Debug)]
pub struct CampaignSource<'a> {
    /// The model's label.
    pub label: &'a str,
    /// The machine's model it starts from, if any.
    pub base_model: Option<&'a str>,
    /// Per record, the file it was read from.
    pub data: &'a [String],
}

impl IdentificationReport {
    /// Reads a report from its JSON `text` (`file` names it in messages), of either version:
    /// a version-1 report of one record (without `setups` and `records`) gains them, its
    /// record labelled by the stem of its `data` file, on a set-up of that label, at the
    /// machine's default kinematic parameters (`params` empty). The values are not checked
    /// against a machine ([`super::read`] does that).
    ///
    /// # Errors
    /// [`ReportError::Json`] for text that is not JSON, [`ReportError::Field`] for a missing or
    /// malformed field or a version this rtest does not know.
    pub fn from_json(file: &str, text: &str) -> Result<IdentificationReport, ReportError> {
        let mut r: IdentificationReport =
            versioned(file, text, |r: &IdentificationReport| r.version)?;
        if r.records.is_empty() {
            let data = r.data.clone().unwrap_or_default();
            let label = crate::json::read::single_label(r.data.as_deref());
            r.records.push(RecordReport {
                label: label.clone(),
                data,
                setup: label.clone(),
                params: Ordered(Vec::new()),
                zeroed: r.zeroed.unwrap_or(false),
                start_s: None,
                samples: r.samples,
                residual_rms_um: r.residual_rms_um,
            });
            r.setups = vec![SetupReport {
                label: label.clone(),
                records: vec![label],
            }];
        }
        Ok(r)
    }

    /// `true` for a report of several records (`"kind": "campaign"`).
    pub fn is_campaign(&self) -> bool {
        self.kind.as_deref() == Some(CAMPAIGN_KIND)
    }

    /// Whether any record's readings were zeroed at the first sample.
    pub fn any_zeroed(&self) -> bool {
        self.zeroed.unwrap_or(false) || self.records.iter().any(|r| r.zeroed)
    }

    /// The parameters of `owner` (`shared`, `setup` or `record`) of `of` (a label; `None` for
    /// shared), as a report of several records writes them (a record's report names no owner:
    /// none is found there).
    pub fn parameters_of(&self, owner: &str, of: Option<&str>) -> Vec<&ParameterReport> {
        self.parameters
            .iter()
            .filter(|p| p.owner.as_deref() == Some(owner) && p.of.as_deref() == of)
            .collect()
    }
}
