//! The verdict part of the diagnosis report: outliers, the size budget, the lack-of-fit test
//! against the noise and what remains unexplained. Values in µm.

use super::{NonFinite, finite};
use diagnosis::Diagnosis;
use diagnosis::adequacy::Adequacy;
use diagnosis::unexplained::{Shape, Unexplained};
use model_spec::units::UM_PER_MM;
use serde::{Deserialize, Serialize};

/// An isolated reading far outside the residual's robust local scale, left out of the fits
/// and of the RMS.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OutlierReport {
    /// The record's file.
    pub data: String,
    /// The 1-based line of the sample in that file; absent when not read from a file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line: Option<usize>,
    /// The 1-based sample number in the record.
    pub sample: usize,
    /// `x`, `y` or `z`.
    pub direction: String,
    /// The residual of the base model at that reading, µm.
    pub residual_um: f64,
    /// Its deviation from the running median of the residual, µm.
    pub deviation_um: f64,
    /// The threshold it exceeded, µm.
    pub threshold_um: f64,
}

/// The size budget findings are compared with.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BudgetReport {
    /// Translational errors and offsets, µm.
    pub um: f64,
    /// Angular errors, µrad.
    pub urad: f64,
    /// Servo lag, ms.
    pub ms: f64,
    /// Instrument gain and cross-talk, a fraction.
    #[serde(rename = "1")]
    pub fraction: f64,
    /// Rates of translational errors and offsets (`rate`), µm/s (a report written before
    /// rates were budgeted reads with the default).
    #[serde(rename = "um/s", default = "default_um_per_s")]
    pub um_per_s: f64,
    /// Rates of angular errors (`rate`), µrad/s (the default when the report has none).
    #[serde(rename = "urad/s", default = "default_urad_per_s")]
    pub urad_per_s: f64,
}

fn default_um_per_s() -> f64 {
    diagnosis::plausible::Budget::default().um_per_s
}

fn default_urad_per_s() -> f64 {
    diagnosis::plausible::Budget::default().urad_per_s
}

/// The lack-of-fit test on one record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RecordAdequacyReport {
    /// The record's file.
    pub data: String,
    /// `true` for the fitted record.
    pub fitted: bool,
    /// The noise's σ per direction x, y, z the test used, µm.
    pub noise_sigma_um: [f64; 3],
    /// The residual's RMS per direction, µm.
    pub residual_sigma_um: [f64; 3],
    /// Per direction, the residual's mean square over the noise variance.
    pub statistic: [f64; 3],
    /// Per direction, the bootstrap p-value.
    pub p_values: [f64; 3],
    /// The RMS the null gives this residual per direction, µm: the noise and, on a held-out
    /// record, the fit's own uncertainty carried into the prediction (the draws' mean square).
    #[serde(default)]
    pub null_rms_um: [f64; 3],
    /// The directions (`x`, `y`, `z`) whose residual RMS is more than twice the larger of the
    /// noise's σ and `null_rms_um`: never consistent with the noise, whatever the p-value.
    #[serde(default)]
    pub over_noise: Vec<String>,
}

/// The lack-of-fit test of the extended model's residuals against the noise model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AdequacyReport {
    /// The test, for people.
    pub test: String,
    /// Per record: the fitted one, then the held-out ones.
    pub records: Vec<RecordAdequacyReport>,
    /// The family-wise p-value over records and directions (the maximum of the standardised
    /// statistics against its bootstrap distribution).
    pub p_value: f64,
    /// Bootstrap draws per record.
    pub draws: usize,
    /// `p_value ≥ alpha`: what remains is consistent with the noise.
    pub consistent_with_noise: bool,
}

/// What remains in a direction the noise does not account for, described.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct UnexplainedReport {
    /// The record's file.
    pub data: String,
    /// `x`, `y` or `z`.
    pub direction: String,
    /// RMS of the residual in that direction, µm.
    pub rms_um: f64,
    /// What it follows (`C`, `X`, `time`, `velocity of A`, `direction of motion of C`,
    /// `sample`); absent when it follows nothing simple.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub follows: Option<String>,
    /// The unit of what it follows (`deg`, `mm`, `s`, `deg/s`, `mm/s`, `±1`; empty for
    /// `sample`).
    pub unit: String,
    /// `smooth`, `periodic`, `step`, `local` or `irregular`.
    pub shape: String,
    /// The period of a periodic shape, in `unit`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub period: Option<f64>,
    /// Where a step is, in `unit`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at: Option<f64>,
    /// The first and last sample (1-based) of a local deviation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub samples: Option<[usize; 2]>,
    /// For a step in a source that moves one way along the record (time, an axis turning one
    /// way): the first sample (1-based) past the jump.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sample: Option<usize>,
    /// Whose residual this describes: `extended` (the extended model's, on every record), or
    /// `base` (the base model's on a fitted record, described because the findings may have
    /// absorbed there what the held-out records mispredict).
    #[serde(default = "extended_residual")]
    pub residual: String,
    /// RMS of what the shape explains, µm.
    pub explained_rms_um: f64,
}

fn extended_residual() -> String {
    "extended".into()
}

/// The lack-of-fit test `a`, its records named by their files (`file_of` a label).
pub(super) fn adequacy(
    a: &Adequacy,
    file_of: &dyn Fn(&str) -> String,
) -> Result<AdequacyReport, NonFinite> {
    let records = a
        .records
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let three = |what: &str, v: [f64; 3], k: f64| -> Result<[f64; 3], NonFinite> {
                for x in v {
                    finite(|| format!("adequacy.records[{i}].{what}"), x * k)?;
                }
                Ok(v.map(|x| x * k))
            };
            Ok(RecordAdequacyReport {
                data: file_of(&r.name),
                fitted: r.fitted,
                noise_sigma_um: three("noise_sigma_um", r.noise_sigma_mm, UM_PER_MM)?,
                residual_sigma_um: three("residual_sigma_um", r.residual_sigma_mm, UM_PER_MM)?,
                null_rms_um: three("null_rms_um", r.null_rms_mm, UM_PER_MM)?,
                over_noise: a
                    .over_noise
                    .iter()
                    .filter(|(k, _)| *k == i)
                    .map(|(_, d)| ["x", "y", "z"][*d].to_string())
                    .collect(),
                statistic: three("statistic", r.statistic, 1.0)?,
                p_values: r.p_values,
            })
        })
        .collect::<Result<_, NonFinite>>()?;
    Ok(AdequacyReport {
        test: format!(
            "per record and direction, the residual's mean square over the noise variance, against a parametric bootstrap of the fit and its predictions under the noise model ({} draws); family-wise by the maximum of the standardised statistics (max-T), its tail beyond the draws from the Gumbel law of the drawn maxima; a residual more than twice what the null gives is never consistent",
            a.draws
        ),
        records,
        p_value: a.p_value,
        draws: a.draws,
        consistent_with_noise: a.consistent_with_noise,
    })
}

/// What remains, `u` (the `i`-th), its record named by its file (`file_of` a label).
pub(super) fn unexplained(
    i: usize,
    u: &Unexplained,
    file_of: &dyn Fn(&str) -> String,
) -> Result<UnexplainedReport, NonFinite> {
    let um = |what: &str, v: f64| finite(|| format!("unexplained[{i}].{what}"), v * UM_PER_MM);
    let (shape, period, at, samples) = match u.shape {
        Shape::Smooth => ("smooth", None, None, None),
        Shape::Periodic { period } => ("periodic", Some(period), None, None),
        Shape::Step { at } => ("step", None, Some(at), None),
        Shape::Local { first, last } => ("local", None, None, Some([first + 1, last + 1])),
        Shape::Irregular => ("irregular", None, None, None),
    };
    Ok(UnexplainedReport {
        data: file_of(&u.data),
        direction: ["x", "y", "z"][u.direction].into(),
        rms_um: um("rms_um", u.rms_mm)?,
        follows: u.follows.clone(),
        unit: u.unit.clone(),
        shape: shape.into(),
        period,
        at,
        samples,
        sample: u.sample.map(|i| i + 1),
        residual: if u.base { "base" } else { "extended" }.into(),
        explained_rms_um: um("explained_rms_um", u.explained_rms_mm)?,
    })
}

/// The outliers of every fitted record and of every held-out record, named by their files
/// (`file_of` a label).
pub(super) fn outliers(
    d: &Diagnosis,
    file_of: &dyn Fn(&str) -> String,
) -> Result<Vec<OutlierReport>, NonFinite> {
    let all = d
        .records
        .iter()
        .flat_map(|r| r.outliers.iter().map(move |o| (r.label.as_str(), o)))
        .chain(
            d.validation
                .iter()
                .flat_map(|h| h.outliers.iter().map(move |o| (h.name.as_str(), o))),
        );
    all.enumerate()
        .map(|(i, (label, o))| {
            let um = |what: &str, v: f64| finite(|| format!("outliers[{i}].{what}"), v * UM_PER_MM);
            Ok(OutlierReport {
                data: file_of(label),
                line: o.line,
                sample: o.sample + 1,
                direction: ["x", "y", "z"][o.direction].into(),
                residual_um: um("residual_um", o.residual_mm)?,
                deviation_um: um("deviation_um", o.deviation_mm)?,
                threshold_um: um("threshold_um", o.threshold_mm)?,
            })
        })
        .collect()
}
