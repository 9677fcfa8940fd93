//! The diagnosis report (`rtest diagnose --json`, `"version": 2`): the records (fitted and held
//! out, each with its set-up), the base fit, the residual structure, the findings with their
//! significance, what the data cannot see, the extended model and its gain on the fitted and
//! the held-out records. One report for one record or a campaign: a single record is the
//! campaign of that record. Values in µm and µrad.

pub use super::diagnose_records::{DroppedReport, RecordReport};
use super::verdict::{AdequacyReport, BudgetReport, OutlierReport, UnexplainedReport};
use serde::{Deserialize, Deserializer, Serialize};

mod build;

pub use build::DiagnosisSource;

/// The version of the diagnosis report this code writes and reads.
pub const VERSION: u32 = 2;

/// Reads `version`, refusing any other than [`VERSION`].
fn version<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    let v = u32::deserialize(d)?;
    if v != VERSION {
        return Err(serde::de::Error::custom(format!(
            "a diagnosis report of version {v}; this rtest reads version {VERSION} (run rtest diagnose again)"
        )));
    }
    Ok(v)
}

/// How many residual components the report lists, before and after.
pub const COMPONENTS_LISTED: usize = 12;

/// The base model's fit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BaseFitReport {
    /// The terms fitted (offsets of zeroed readings included).
    pub terms: Vec<String>,
    /// Residual RMS over all readings, µm.
    pub residual_rms_um: f64,
    /// Residual RMS with the outliers' samples in the fit, µm (equal to `residual_rms_um`
    /// when there are none).
    pub residual_rms_um_with_outliers: f64,
    /// σ̂, µm; `null` without degrees of freedom.
    pub sigma_um: Option<f64>,
    /// Degrees of freedom.
    pub dof: usize,
}

/// One shape of the residual.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ComponentReport {
    /// What it follows: an axis name, or `time`.
    pub source: String,
    /// The shape: `harmonic:2`, `poly:1`, `time:1`, `reversal`.
    pub shape: String,
    /// `x`, `y` or `z`.
    pub direction: String,
    /// RMS of what the shape alone explains, µm.
    pub explained_rms_um: f64,
    /// In `before`: what the same shape explains of the extended fit's residual, µm (absent
    /// in `after`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extended_rms_um: Option<f64>,
}

/// The residual structure before and after the extension.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StructureReport {
    /// Of the base fit, largest first.
    pub before: Vec<ComponentReport>,
    /// Of the extended fit, largest first.
    pub after: Vec<ComponentReport>,
}

/// One significant effect found.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FindingReport {
    /// Effect name (`ECC`).
    pub error: String,
    /// Basis (`harmonic:2`).
    pub basis: String,
    /// The term's name for people.
    pub description: String,
    /// The axis whose position the basis follows (`C` for `ECC@harmonic:2`); absent for
    /// effects of no axis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<String>,
    /// Its value(s) in the extended model, µm or µrad (`[cos, sin]` for a harmonic); `null`
    /// where undetermined.
    pub values: Vec<Option<f64>>,
    /// Their standard uncertainties.
    pub stds: Vec<Option<f64>>,
    /// `um` or `urad`.
    pub unit: String,
    /// The column names of the basis (`harmonic:2:cos`, `harmonic:2:sin`).
    pub columns: Vec<String>,
    /// A harmonic's amplitude and phase (written as the fields `amplitude`, `amplitude_std`,
    /// `phase_deg`, `phase_std_deg`); absent for other bases.
    #[serde(flatten, default, skip_serializing_if = "Option::is_none")]
    pub harmonic: Option<HarmonicReport>,
    /// Share of the base model's residual sum of squares it explains beyond the other findings.
    pub explained_fraction: f64,
    /// The F statistic of its step.
    pub f: f64,
    /// Its p-value corrected for the candidates tried.
    pub p_value: f64,
    /// `bonferroni` or `monte-carlo`.
    pub correction: String,
    /// Candidates tried at that step.
    pub candidates_tried: usize,
    /// Candidates the data cannot tell from it (`NAME@BASIS`).
    pub alternatives: Vec<String>,
    /// Its size (`|value|`, or the amplitude of a pair), in `unit`.
    pub size: f64,
    /// The budget of its unit it was compared with (`--budget`), in `unit`.
    pub limit: f64,
    /// `size ≤ limit`: named as a cause and in the extended model. `false`: it fits, but is
    /// implausible, and is left out of the extended model.
    pub plausible: bool,
    /// For `period:P`, `step:V`, `exp:TAU`, `warmup:TAU`: the refined parameter and its 95 %
    /// interval from the profile of the fit (the values' stds are conditional on it); absent
    /// otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scan: Option<ScanReport>,
    /// What the finding is: `cause` (plausible, confirmed on its own by the held-out records,
    /// or with none by the fitted records left out in turn, and the extended model, which holds
    /// the confirmed findings, is recommended), `not confirmed` (plausible, but its own held-out
    /// gain is within the noise's, or the extended model is not recommended, or there are no
    /// records to check it) or `implausible`.
    pub status: String,
    /// What the held-out records say of it on its own; absent when no record judged it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub confirmation: Option<ConfirmationReport>,
}

/// What the held-out (or left-out) records say of one finding.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ConfirmationReport {
    /// `held-out` (the held-out records) or `left-out` (every fitted record predicted by the
    /// fit on the others).
    pub judged_by: String,
    /// Its held-out gain given the other findings of the extended model, in standard
    /// deviations of a spurious gain.
    pub gain_sd: f64,
    /// Whether that exceeds 2: confirmed on its own; or, when no record could judge it, its
    /// corrected p-value is below `α·Φ̄(2)` (docs/diagnosis.md §6).
    pub confirmed: bool,
    /// No judging record could judge it: none's fit determines what it predicts there
    /// (`gain_sd` is then 0, over no record).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub not_judged: bool,
    /// The judging records that could not judge it (their labels).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub unjudged: Vec<String>,
    /// The selection's finding this term replaces, the held-out records having chosen it among
    /// that finding's alternatives (`NAME@BASIS`); absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replaces: Option<String>,
    /// The terms tried in the finding's place (the selection's finding first) and their
    /// held-out gains given the confirmed findings, in standard deviations; empty when none
    /// was tried.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub tried: Vec<TriedReport>,
}

/// An error group selected after the findings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GroupReport {
    /// What it is (`component errors of A, once per revolution`).
    pub name: String,
    /// Its members (`NAME@BASIS`).
    pub terms: Vec<String>,
    /// The directions its columns add on the fitted records (k of its F-test).
    pub directions: usize,
    /// Its F statistic and its p-value, corrected for the groups tried at its step.
    pub f: f64,
    /// The corrected p-value.
    pub p_value: f64,
    /// Its gain on the judging records that can judge it, in standard deviations of a spurious
    /// gain; absent when none can.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gain_sd: Option<f64>,
    /// The judging records that cannot judge it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub unjudged: Vec<String>,
    /// In the extended model.
    pub confirmed: bool,
    /// Its parameters the fit does not determine (identify with `--constraint min-norm`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub undetermined: Vec<String>,
}

/// A term tried in a finding's place on the held-out records.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TriedReport {
    /// `NAME@BASIS`.
    pub term: String,
    /// Its held-out gain, in standard deviations of a spurious gain.
    pub gain_sd: f64,
}

/// A scanned parameter and its interval.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScanReport {
    /// `P`, `V` or `TAU`.
    pub parameter: String,
    /// Its value.
    pub value: f64,
    /// The lower end of its 95 % interval.
    pub low: f64,
    /// The upper end.
    pub high: f64,
    /// `mm`, `deg` or `s`.
    pub unit: String,
}

/// The amplitude and phase of a harmonic finding.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HarmonicReport {
    /// √(cos² + sin²), µm or µrad.
    pub amplitude: f64,
    /// Its standard uncertainty; `null` when undetermined.
    pub amplitude_std: Option<f64>,
    /// atan2(sin, cos), degrees.
    pub phase_deg: f64,
    /// Its standard uncertainty, degrees; `null` when undetermined.
    pub phase_std_deg: Option<f64>,
}

/// Why the selection stopped.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StopReport {
    /// For people.
    pub reason: String,
    /// The best remaining candidate; absent when no candidate was left.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub best_remaining: Option<String>,
    /// Its corrected p-value.
    pub p_value: f64,
}

/// A candidate the model spans.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ConfoundedReport {
    /// Effect name.
    pub error: String,
    /// Basis.
    pub basis: String,
    /// The model's terms it is a combination of.
    pub with: Vec<String>,
}

/// A position error of an axis and a term of time that the fitted records cannot tell apart
/// ([`diagnosis::separable`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PositionOrTimeReport {
    /// The error of the axis that depends on its position (`EBB@harmonic:1`).
    pub position: String,
    /// The term of time (`BOC@rate`).
    pub time: String,
    /// Which of the two the selection chose.
    pub chosen: String,
    /// What the data say: `cannot be told apart`, `position preferred`, `time preferred`.
    pub verdict: String,
    /// The axis.
    pub axis: String,
    /// The fitted records (files) on which the axis moves monotonically in time.
    pub monotonic: Vec<String>,
    /// Cosine between what the time term explains and the position term's span, given the rest
    /// of the model.
    pub time_in_position: f64,
    /// Cosine between what the position term explains and the time term's span.
    pub position_in_time: f64,
    /// The least cosine, both ways, at which the two are not told apart.
    pub threshold: f64,
    /// Raw F-test p-value of the position term added to the time term.
    pub position_beyond_time_p: f64,
    /// Raw F-test p-value of the time term added to the position term.
    pub time_beyond_position_p: f64,
    /// The tests that separate them (`turn-B-back`, `turn-B-rev`).
    pub separating: Vec<String>,
    /// The `rtest plan` command that checks the separation before measuring; absent for an
    /// error of a linear axis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plan_command: Option<String>,
}

/// The extended model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ExtendedModelReport {
    /// `reduced + ECC@harmonic:2`.
    pub label: String,
    /// Its terms, as a sub-model lists them.
    pub terms: Vec<String>,
    /// The terms added (the plausible findings).
    pub added: Vec<String>,
    /// The model's name in the machine description written (`--model-out`); absent when none
    /// was written.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// That file; absent when none was written.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
}

/// Residual RMS on one record, before and after, µm.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GainRow {
    /// The record's file.
    pub data: String,
    /// With the base model, µm.
    pub residual_rms_um_before: f64,
    /// With the extended model, µm.
    pub residual_rms_um_after: f64,
    /// `false` when a prediction needs a combination of parameters the fit does not
    /// determine: then the RMS is not the model's error and does not count.
    pub estimable: bool,
    /// The confounded groups (parameter names) the predictions need; empty when estimable.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub undetermined: Vec<Vec<String>>,
}

/// The gain of the extension.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GainReport {
    /// On the fitted record.
    pub fit: GainRow,
    /// On every held-out record.
    pub validation: Vec<GainRow>,
    /// With nothing held out and several records fitted: on every fitted record, predicted by
    /// the fits (base and extended model) on the others; absent otherwise.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub left_out: Vec<GainRow>,
}

/// The diagnosis report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DiagnosisReport {
    /// The report's version, [`VERSION`].
    #[serde(deserialize_with = "version")]
    pub version: u32,
    /// Machine name.
    pub machine: String,
    /// `--machine` as given (a built-in name or a file), for the commands it suggests.
    pub machine_source: String,
    /// The fitted records' files, comma-separated.
    pub data: String,
    /// The command-line words that give the same fitted records to another command (`--data
    /// k4.csv --zeroed`, `--campaign c.toml`), for the commands it suggests.
    pub data_arguments: Vec<String>,
    /// Their samples, outliers included.
    pub samples: usize,
    /// The held-out records: file and samples.
    pub held_out: Vec<(String, usize)>,
    /// Every record, fitted ones first.
    pub records: Vec<RecordReport>,
    /// The base model's label.
    pub base_model: String,
    /// Whether the readings of a fitted record were zeroed at the first sample.
    pub zeroed: bool,
    /// Significance level of each step.
    pub alpha: f64,
    /// Monte-Carlo draws of the corrected p-values.
    pub draws: usize,
    /// Highest harmonic, Legendre order and time order of the candidates.
    pub dictionary_extent: [u32; 3],
    /// The base fit.
    pub base_fit: BaseFitReport,
    /// The residual structure.
    pub structure: StructureReport,
    /// Candidates in the dictionary.
    pub dictionary_size: usize,
    /// Candidates that do not vary on the fitted path.
    pub unexcited: Vec<String>,
    /// The findings, in the order they were added.
    pub findings: Vec<FindingReport>,
    /// Findings the selection made but left out because the fit of the extended model with
    /// them did not converge (the other findings were selected with them in the model);
    /// absent when none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub dropped: Vec<DroppedReport>,
    /// The error groups selected after the findings (docs/diagnosis.md §6, "Error groups"),
    /// confirmed ones in the extended model; absent when none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub groups: Vec<GroupReport>,
    /// Why the selection stopped.
    pub stop: StopReport,
    /// Candidates the extended model spans.
    pub confounded: Vec<ConfoundedReport>,
    /// Position errors of axes and terms of time the fitted records cannot tell apart, with the
    /// tests that separate them; absent when none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub position_or_time: Vec<PositionOrTimeReport>,
    /// The extended model.
    pub extended_model: ExtendedModelReport,
    /// The gain.
    pub gain: GainReport,
    /// Outliers of the fitted and the held-out records.
    pub outliers: Vec<OutlierReport>,
    /// The size budget of the findings.
    pub budget: BudgetReport,
    /// Whether the extended model is recommended.
    pub recommended: bool,
    /// Why (not).
    pub recommendation: Vec<String>,
    /// The noise model every test and p-value assumes, for people.
    pub noise_model: String,
    /// The lack-of-fit test; `null` when no noise model independent of the fit exists
    /// (`adequacy_unavailable` says why).
    pub adequacy: Option<AdequacyReport>,
    /// Why there is no lack-of-fit test; absent when there is one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub adequacy_unavailable: Option<String>,
    /// What remains unexplained, per direction the test finds inconsistent with the noise.
    pub unexplained: Vec<UnexplainedReport>,
    /// What a reader should know of how this diagnosis was made (several fitted records), one
    /// sentence each.
    pub notes: Vec<String>,
}
