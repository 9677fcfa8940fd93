//! The diagnosis report (`rtest diagnose --json`, `"version": 2`): the records (fitted and held
//! out, each with its set-up), the base fit, the residual structure, the findings with their
//! significance, what the data cannot see, the extended model and its gain on the fitted and
//! the held-out records. One report for one record or a campaign: a single record is the
//! campaign of that record. Values in µm and µrad.

pub use super::diagnose_records::{DroppedReport, RecordReport};
use super::diagnose_records::{notes, records};
use super::verdict::{
    AdequacyReport, BudgetReport, OutlierReport, UnexplainedReport, adequacy, outliers, unexplained,
};
use super::{NonFinite, finite, finite_opt};
use crate::diagnosis::confirm::Judges;
use crate::diagnosis::harmonic::harmonic;
use crate::diagnosis::structure::Component;
use crate::diagnosis::{Correction, DiagnoseOptions, Diagnosis};
use crate::model::{Basis, Carrier, Term};
use model_spec::Machine;
use model_spec::units::UM_PER_MM;
use serde::{Deserialize, Deserializer, Serialize};

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
    /// Whether that exceeds 2: confirmed on its own.
    pub confirmed: bool,
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
/// ([`solver::diagnosis::separable`](crate::diagnosis::separable)).
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

/// What the report says besides the diagnosis: where things come from and go.
#[derive(Clone, Debug)]
pub struct DiagnosisSource<'a> {
    /// `--machine` as given.
    pub machine_source: &'a str,
    /// The base model's label.
    pub label: &'a str,
    /// The fitted records' files, one per record in order.
    pub data: Vec<String>,
    /// The held-out records' files, one per record in order.
    pub held_out: Vec<String>,
    /// The command-line words that give the fitted records to another command.
    pub data_arguments: Vec<String>,
    /// The options of the diagnosis.
    pub opts: &'a DiagnoseOptions,
    /// The extended machine description written: the model's name and the file.
    pub model_out: Option<(String, String)>,
}

impl DiagnosisSource<'_> {
    /// The file of the record labelled `label` (fitted or held out) in diagnosis `d`; the label
    /// itself when it has none.
    pub fn file_of(&self, d: &Diagnosis, label: &str) -> String {
        let fitted = d.records.iter().position(|r| r.label == label);
        let held = d.validation.iter().position(|h| h.name == label);
        match (fitted, held) {
            (Some(i), _) => self.data.get(i),
            (None, Some(i)) => self.held_out.get(i),
            (None, None) => None,
        }
        .cloned()
        .unwrap_or_else(|| label.to_string())
    }
}

/// The entries of [`Diagnosis::position_or_time`], with the `rtest plan` command of each: the
/// two terms planned on the axis's turn at the ball position of the first record on which the
/// axis moves monotonically (`--param` for what differs from the description's defaults).
fn position_or_time(
    m: &Machine,
    source: &DiagnosisSource,
    d: &Diagnosis,
) -> Result<Vec<PositionOrTimeReport>, NonFinite> {
    use crate::diagnosis::separable::Verdict;
    let defaults = m.default_parameters();
    d.position_or_time
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let field = |what: &str| format!("position_or_time[{i}].{what}");
            let plan_command = (!e.plan_arguments.is_empty()).then(|| {
                let mut words = vec![
                    "rtest".to_string(),
                    "plan".into(),
                    "--machine".into(),
                    source.machine_source.to_string(),
                ];
                words.extend(e.plan_arguments.iter().cloned());
                let params = e
                    .monotonic
                    .first()
                    .and_then(|l| d.records.iter().find(|r| &r.label == l))
                    .map(|r| r.params.clone())
                    .unwrap_or_default();
                let changed: Vec<String> = m
                    .symbols
                    .iter()
                    .zip(&params)
                    .zip(&defaults)
                    .filter(|((_, x), y)| x.to_bits() != y.to_bits())
                    .map(|((s, x), _)| format!("{}={}", s.name, model_spec::units::short(*x)))
                    .collect();
                if !changed.is_empty() {
                    words.push("--param".into());
                    words.push(changed.join(","));
                }
                words.join(" ")
            });
            Ok(PositionOrTimeReport {
                position: e.position.spelling(m),
                time: e.time.spelling(m),
                chosen: e.chosen.spelling(m),
                verdict: match e.verdict {
                    Verdict::Undecided => "cannot be told apart",
                    Verdict::Position => "position preferred",
                    Verdict::Time => "time preferred",
                }
                .into(),
                axis: e.axis.clone(),
                monotonic: e.monotonic.iter().map(|l| source.file_of(d, l)).collect(),
                time_in_position: finite(|| field("time_in_position"), e.time_in_position)?,
                position_in_time: finite(|| field("position_in_time"), e.position_in_time)?,
                threshold: crate::diagnosis::separable::COLLINEAR_COSINE,
                position_beyond_time_p: finite(
                    || field("position_beyond_time_p"),
                    e.position_beyond_time_p,
                )?,
                time_beyond_position_p: finite(
                    || field("time_beyond_position_p"),
                    e.time_beyond_position_p,
                )?,
                separating: e.separating.clone(),
                plan_command,
            })
        })
        .collect()
}

fn spell(m: &Machine, ts: &[Term]) -> Vec<String> {
    ts.iter().map(|t| t.spelling(m)).collect()
}

/// The largest components of `c`; with `after`, each with what the same shape explains there.
fn components(
    field: &str,
    c: &[Component],
    after: Option<&[Component]>,
) -> Result<Vec<ComponentReport>, NonFinite> {
    c.iter()
        .take(COMPONENTS_LISTED)
        .enumerate()
        .map(|(i, c)| {
            let same = |x: &&Component| {
                x.source == c.source && x.shape == c.shape && x.direction == c.direction
            };
            let extended = after.map(|a| a.iter().find(same).map_or(0.0, |x| x.explained_rms_um));
            Ok(ComponentReport {
                extended_rms_um: finite_opt(
                    || format!("structure.{field}[{i}].extended_rms_um"),
                    extended,
                )?,
                source: c.source.clone(),
                shape: c.shape.clone(),
                direction: ["x", "y", "z"][c.direction].into(),
                explained_rms_um: finite(
                    || format!("structure.{field}[{i}].explained_rms_um"),
                    c.explained_rms_um,
                )?,
            })
        })
        .collect()
}

fn gain_row(
    field: &str,
    data: &str,
    before: f64,
    after: f64,
    undetermined: Vec<Vec<String>>,
) -> Result<GainRow, NonFinite> {
    Ok(GainRow {
        estimable: undetermined.is_empty(),
        undetermined,
        data: data.into(),
        residual_rms_um_before: finite(
            || format!("{field}.residual_rms_um_before"),
            before * UM_PER_MM,
        )?,
        residual_rms_um_after: finite(
            || format!("{field}.residual_rms_um_after"),
            after * UM_PER_MM,
        )?,
    })
}

/// The gain rows of held-out (or left-out) records, each named by its file.
fn held_rows(
    field: &str,
    rows: &[crate::diagnosis::heldout::HeldOut],
    file_of: &dyn Fn(&str) -> String,
) -> Result<Vec<GainRow>, NonFinite> {
    rows.iter()
        .enumerate()
        .map(|(i, h)| {
            let mut groups = h.undetermined_before.clone();
            for g in &h.undetermined_after {
                if !groups.contains(g) {
                    groups.push(g.clone());
                }
            }
            gain_row(
                &format!("{field}[{i}]"),
                &file_of(&h.name),
                h.before_rms,
                h.after_rms,
                groups,
            )
        })
        .collect()
}

impl DiagnosisReport {
    /// The report of `d` on machine `m`.
    ///
    /// # Errors
    /// [`NonFinite`] when a value or statistic is not finite.
    pub fn new(
        m: &Machine,
        source: &DiagnosisSource,
        d: &Diagnosis,
    ) -> Result<DiagnosisReport, NonFinite> {
        let o = source.opts;
        let mut findings = Vec::new();
        for (i, f) in d.findings.iter().enumerate() {
            let field = |what: &str| format!("findings[{i}].{what}");
            let k = f.term.display_factor(m);
            let h = harmonic(m, d, f);
            findings.push(FindingReport {
                error: f.term.effect.name(m),
                basis: f.term.basis.to_string(),
                description: f.description.clone(),
                axis: match f.term.effect.carrier(m) {
                    Carrier::Axis(a) => Some(m.axes[a].name.clone()),
                    Carrier::None => None,
                },
                values: f
                    .values
                    .iter()
                    .map(|v| finite_opt(|| field("values"), v.map(|v| v * k)))
                    .collect::<Result<_, _>>()?,
                stds: f
                    .stds
                    .iter()
                    .map(|s| finite_opt(|| field("stds"), s.map(|s| s * k)))
                    .collect::<Result<_, _>>()?,
                unit: f.term.unit(m).into(),
                columns: f.term.basis.column_names(),
                harmonic: match h {
                    Some(h) => Some(HarmonicReport {
                        amplitude: finite(|| field("amplitude"), h.amplitude)?,
                        amplitude_std: finite_opt(|| field("amplitude_std"), h.amplitude_std)?,
                        phase_deg: finite(|| field("phase_deg"), h.phase_deg)?,
                        phase_std_deg: finite_opt(|| field("phase_std_deg"), h.phase_std_deg)?,
                    }),
                    None => None,
                },
                explained_fraction: finite(|| field("explained_fraction"), f.explained_fraction)?,
                f: finite(|| field("f"), f.f)?,
                p_value: finite(|| field("p_value"), f.p_value)?,
                correction: match f.correction {
                    Correction::Bonferroni => "bonferroni",
                    Correction::MonteCarlo => "monte-carlo",
                }
                .into(),
                candidates_tried: f.candidates_tried,
                alternatives: spell(m, &f.alternatives),
                size: finite(|| field("size"), f.size)?,
                limit: f.limit,
                plausible: f.plausible,
                scan: f.scan.map(|sc| {
                    let (parameter, unit) = match f.term.basis {
                        Basis::Period(_) => ("P", "mm"),
                        Basis::Exp(_) | Basis::Warmup(_) => ("TAU", "s"),
                        _ => match f.term.effect.carrier(m) {
                            Carrier::Axis(a) if m.axes[a].kind == model_spec::AxisKind::Rotary => {
                                ("V", "deg")
                            }
                            _ => ("V", "mm"),
                        },
                    };
                    ScanReport {
                        parameter: parameter.into(),
                        value: sc.value,
                        low: sc.low,
                        high: sc.high,
                        unit: unit.into(),
                    }
                }),
                status: if !f.plausible {
                    "implausible"
                } else if d.is_cause(f) {
                    "cause"
                } else {
                    "not confirmed"
                }
                .into(),
                confirmation: match &f.confirmation {
                    Some(c) => Some(ConfirmationReport {
                        judged_by: match c.judges {
                            Judges::HeldOut => "held-out",
                            Judges::LeftOut => "left-out",
                        }
                        .into(),
                        gain_sd: finite(|| field("confirmation.gain_sd"), c.gain_sd)?,
                        confirmed: c.confirmed,
                        replaces: c.replaces.map(|t| t.spelling(m)),
                        tried: c
                            .tried
                            .iter()
                            .map(|&(t, z)| {
                                Ok(TriedReport {
                                    term: t.spelling(m),
                                    gain_sd: finite(|| field("confirmation.tried.gain_sd"), z)?,
                                })
                            })
                            .collect::<Result<_, NonFinite>>()?,
                    }),
                    None => None,
                },
            });
        }
        let (name, file) = match &source.model_out {
            Some((n, f)) => (Some(n.clone()), Some(f.clone())),
            None => (None, None),
        };
        let fit = &d.base_fit.fit;
        let data = source.data.join(",");
        let file_of = |label: &str| source.file_of(d, label);
        Ok(DiagnosisReport {
            version: VERSION,
            machine: m.name.clone(),
            machine_source: source.machine_source.into(),
            data: data.clone(),
            data_arguments: source.data_arguments.clone(),
            samples: d.records.iter().map(|r| r.samples).sum(),
            held_out: d
                .validation
                .iter()
                .map(|h| (file_of(&h.name), h.samples))
                .collect(),
            records: records(m, d, &file_of)?,
            base_model: source.label.into(),
            zeroed: d.records.iter().any(|r| r.zeroed),
            alpha: o.alpha,
            draws: o.draws,
            dictionary_extent: [o.dictionary.harmonics, o.dictionary.poly, o.dictionary.time],
            base_fit: BaseFitReport {
                terms: spell(m, &d.base.terms),
                residual_rms_um: finite(
                    || "base_fit.residual_rms_um".into(),
                    d.fit_rms.0 * UM_PER_MM,
                )?,
                sigma_um: finite_opt(
                    || "base_fit.sigma_um".into(),
                    fit.sigma.map(|s| s * UM_PER_MM),
                )?,
                residual_rms_um_with_outliers: finite(
                    || "base_fit.residual_rms_um_with_outliers".into(),
                    d.fit_rms_with_outliers * UM_PER_MM,
                )?,
                dof: fit.dof,
            },
            structure: StructureReport {
                before: components("before", &d.structure_before, Some(&d.structure_after))?,
                after: components("after", &d.structure_after, None)?,
            },
            dictionary_size: d.dictionary_size,
            unexcited: spell(m, &d.unexcited),
            findings,
            stop: StopReport {
                reason: d.stop.reason.clone(),
                best_remaining: d.stop.best.map(|t| t.spelling(m)),
                p_value: finite(|| "stop.p_value".into(), d.stop.p_value)?,
            },
            confounded: d
                .confounded
                .iter()
                .map(|c| ConfoundedReport {
                    error: c.term.effect.name(m),
                    basis: c.term.basis.to_string(),
                    with: spell(m, &c.with),
                })
                .collect(),
            position_or_time: position_or_time(m, source, d)?,
            extended_model: ExtendedModelReport {
                label: d.extended_label(m, source.label),
                terms: spell(m, &d.extended_terms().terms),
                added: d
                    .findings
                    .iter()
                    .filter(|f| f.in_model)
                    .map(|f| f.term.spelling(m))
                    .collect(),
                name,
                file,
            },
            gain: GainReport {
                fit: gain_row("gain.fit", &data, d.fit_rms.0, d.fit_rms.1, Vec::new())?,
                validation: held_rows("gain.validation", &d.validation, &file_of)?,
                left_out: held_rows("gain.left_out", &d.left_out, &file_of)?,
            },
            outliers: outliers(d, &file_of)?,
            budget: BudgetReport {
                um: o.budget.um,
                urad: o.budget.urad,
                ms: o.budget.ms,
                fraction: o.budget.fraction,
                um_per_s: o.budget.um_per_s,
                urad_per_s: o.budget.urad_per_s,
            },
            recommended: d.recommendation.recommended,
            recommendation: d
                .recommendation_named(if d.validation.is_empty() {
                    &source.data
                } else {
                    &source.held_out
                })
                .reasons,
            noise_model: d.noise.to_string(),
            adequacy: match &d.adequacy {
                Ok(a) => Some(adequacy(a, &file_of)?),
                Err(_) => None,
            },
            adequacy_unavailable: d.adequacy.as_ref().err().cloned(),
            unexplained: d
                .unexplained
                .iter()
                .enumerate()
                .map(|(i, u)| unexplained(i, u, &file_of))
                .collect::<Result<_, _>>()?,
            dropped: d
                .dropped
                .iter()
                .map(|x| DroppedReport {
                    term: x.term.spelling(m),
                    why: x.why.clone(),
                })
                .collect(),
            notes: notes(d),
        })
    }
}
