//! The validation report (`rtest validate --json`): residuals of a prediction on a record, per
//! direction and overall, before (the nominal machine: prediction 0) and after (the model), in
//! µm. Overall RMS = `√(Σ r² / 3N)`.

use super::{NonFinite, finite};
use crate::fitting::validate::{Stats, Validation};
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

/// The validation report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ValidationReport {
    /// Machine name.
    pub machine: String,
    /// The model's label (from the identification).
    pub model: String,
    /// The identification report whose values were applied.
    pub params: String,
    /// The measurement file validated on.
    pub data: String,
    /// Number of samples.
    pub samples: usize,
    /// `exact` (the exact machine at the values) or `first-order` (`H·v`).
    pub prediction: String,
    /// Over all three directions (written as top-level fields: `measured_rms_um`,
    /// `measured_max_um`, `residual_rms_um`, `residual_max_um`).
    #[serde(flatten)]
    pub overall: DirectionReport,
    /// Per direction.
    pub per_direction: PerDirectionReport,
    /// Whether the prediction was zeroed at the first sample.
    pub zeroed: bool,
    /// Parameters without a value that the prediction set to 0.
    pub unidentified_set_to_zero: Vec<String>,
}

/// Where the values and the data of a validation come from, for its report.
#[derive(Clone, Copy, Debug)]
pub struct ValidationSource<'a> {
    /// Machine name.
    pub machine: &'a str,
    /// Model label.
    pub model: &'a str,
    /// The identification report file.
    pub params: &'a str,
    /// The measurement file.
    pub data: &'a str,
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

impl ValidationReport {
    /// The report of `v` from `source`.
    ///
    /// # Errors
    /// [`NonFinite`] when a statistic is not finite.
    pub fn new(source: ValidationSource, v: &Validation) -> Result<ValidationReport, NonFinite> {
        let [x, y, z] = &v.per_direction;
        Ok(ValidationReport {
            machine: source.machine.into(),
            model: source.model.into(),
            params: source.params.into(),
            data: source.data.into(),
            samples: v.samples,
            prediction: if source.exact { "exact" } else { "first-order" }.into(),
            overall: direction("overall", &v.overall)?,
            per_direction: PerDirectionReport {
                x: direction("per_direction.x", x)?,
                y: direction("per_direction.y", y)?,
                z: direction("per_direction.z", z)?,
            },
            zeroed: v.zeroed,
            unidentified_set_to_zero: v.defaulted.clone(),
        })
    }

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
