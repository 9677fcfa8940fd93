//! Validation: the identified model's prediction against the measurement of another record.
//!
//! - Prediction `p_i = H_i·v` (mm), `H` of the model on the validation record
//!   ([`crate::hmatrix`]), `v` the identified values; a parameter without a value (not
//!   determined by the identification) is set by [`Unidentified`] (default 0, and
//!   [`Validation::defaulted`] names it).
//! - With [`ValidateOptions::exact`], `p_i` is the exact machine at the identified values
//!   instead ([`crate::refine::exact_prediction`]).
//! - Zeroed readings (the record was zeroed at its first sample): `p_i = (H_i − H_0)·v`. Constant
//!   effects cancel, so the sensor offsets and the errors they swallow do not matter.
//! - "Before" is the nominal machine: prediction 0, residual = measured. "After" is the model:
//!   residual `r_i = m_i − p_i`.
//! - Per direction d ∈ {x, y, z}: RMS `√(Σ_i r_id² / N)` and max `|r_id|`; over all three:
//!   RMS `√(Σ_i Σ_d r_id² / 3N)`, max over all.

use crate::hmatrix::{GainSource, HMatrixError, check_model, h_matrix, parameter_names};
use crate::{EstimateError, measurement_vector};
use model_spec::Machine;
use nalgebra::DVector;
use simulation::model::Model;
use simulation::record::Record;

/// What a parameter without a value becomes in the prediction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Unidentified {
    /// Zero (the nominal value), named in [`Validation::defaulted`].
    #[default]
    Zero,
    /// Refuse to predict ([`ValidateError::Unidentified`]).
    Refuse,
}

/// Options of [`validate`] (`ValidateOptions::default()`, then set the fields wanted).
#[derive(Clone, Debug, PartialEq, Default)]
#[non_exhaustive]
pub struct ValidateOptions {
    /// The record's readings were zeroed at its first sample.
    pub zeroed: bool,
    /// What parameters without a value become.
    pub unidentified: Unidentified,
    /// Kinematic parameters (mm, symbol order); `None`: the machine's defaults.
    pub params: Option<Vec<f64>>,
    /// Predict with the exact machine at the identified values
    /// ([`crate::refine::exact_prediction`]) instead of the first-order `H·v`: the difference is
    /// the second-order terms (about 1e-3 µm for errors of tens of µm and µrad).
    pub exact: bool,
}

impl ValidateOptions {
    /// The defaults: not zeroed, undetermined parameters set to 0, default kinematic
    /// parameters, first-order prediction.
    pub fn new() -> ValidateOptions {
        ValidateOptions::default()
    }

    /// With the prediction zeroed at the first sample (or not).
    pub fn zeroed(mut self, zeroed: bool) -> ValidateOptions {
        self.zeroed = zeroed;
        self
    }

    /// With what parameters without a value become.
    pub fn unidentified(mut self, unidentified: Unidentified) -> ValidateOptions {
        self.unidentified = unidentified;
        self
    }

    /// With the kinematic parameters `params` (mm, symbol order).
    pub fn params(mut self, params: Vec<f64>) -> ValidateOptions {
        self.params = Some(params);
        self
    }

    /// With the exact prediction (or the first-order one).
    pub fn exact(mut self, exact: bool) -> ValidateOptions {
        self.exact = exact;
        self
    }
}

/// Why a validation could not be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ValidateError {
    /// The H matrix could not be built.
    #[error(transparent)]
    HMatrix(#[from] HMatrixError),
    /// The record's measurements are missing or not finite.
    #[error(transparent)]
    Measurements(#[from] EstimateError),
    /// Values that do not fit the model.
    #[error("{0}")]
    Shape(String),
    /// The exact prediction failed.
    #[error(transparent)]
    Simulate(#[from] simulation::readings::SimulateError),
    /// Parameters without a value, with [`Unidentified::Refuse`].
    #[error(
        "the identification gave no value for {}; cannot predict (choose to set them to 0)",
        .0.join(", ")
    )]
    Unidentified(Vec<String>),
}

/// RMS and maximum absolute value of the measurement and of the residual (mm).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Stats {
    /// RMS of the measured values ("before": residual of the nominal machine), mm.
    pub measured_rms: f64,
    /// Largest |measured value|, mm.
    pub measured_max: f64,
    /// RMS of measured minus predicted ("after"), mm.
    pub residual_rms: f64,
    /// Largest |measured minus predicted|, mm.
    pub residual_max: f64,
}

/// A validation on one record.
#[derive(Clone, Debug, PartialEq)]
pub struct Validation {
    /// Number of samples.
    pub samples: usize,
    /// Predicted error vector per sample (mm, tool frame).
    pub prediction: Vec<[f64; 3]>,
    /// Measured minus predicted per sample (mm).
    pub residual: Vec<[f64; 3]>,
    /// Statistics per direction x, y, z.
    pub per_direction: [Stats; 3],
    /// Statistics over all three directions.
    pub overall: Stats,
    /// Parameters without a value that were set to 0.
    pub defaulted: Vec<String>,
    /// Whether the prediction was zeroed at the first sample.
    pub zeroed: bool,
}

/// RMS and max of `measured` and of `measured − prediction`, per direction and over all.
/// The two slices have one entry per sample (extra entries of the longer one are ignored).
pub fn statistics(measured: &[[f64; 3]], prediction: &[[f64; 3]]) -> ([Stats; 3], Stats) {
    let n = measured.len().min(prediction.len());
    let mut per = [Stats::default(); 3];
    let mut all = Stats::default();
    for (mv, pv) in measured.iter().zip(prediction).take(n) {
        for d in 0..3 {
            let (mm, r) = (mv[d], mv[d] - pv[d]);
            for s in [&mut per[d], &mut all] {
                s.measured_rms += mm * mm;
                s.residual_rms += r * r;
                s.measured_max = s.measured_max.max(mm.abs());
                s.residual_max = s.residual_max.max(r.abs());
            }
        }
    }
    let finish = |s: &mut Stats, count: usize| {
        let c = count.max(1) as f64;
        s.measured_rms = (s.measured_rms / c).sqrt();
        s.residual_rms = (s.residual_rms / c).sqrt();
    };
    for s in &mut per {
        finish(s, n);
    }
    finish(&mut all, 3 * n);
    (per, all)
}

/// Validates `model` with `values` (one per model column, mm or rad, `None`: no value) on the
/// measured `record` of `m`, with the best gain source.
///
/// # Errors
/// See [`validate_with`].
pub fn validate(
    m: &Machine,
    model: &Model,
    values: &[Option<f64>],
    record: &Record,
    opts: &ValidateOptions,
) -> Result<Validation, ValidateError> {
    let params = opts
        .params
        .clone()
        .unwrap_or_else(|| m.default_parameters());
    check_model(m, model)?;
    let mut source = GainSource::new(m, &model.errors(), &params)?;
    validate_with(m, model, values, record, &mut source, opts)
}

/// As [`validate`], with gains from `source` (covering the model's errors; its parameters
/// are used, `opts.params` is ignored).
///
/// # Errors
/// Values that do not match the model's columns or are not finite, a model or record that does
/// not fit `m`, missing or non-finite measurements, no samples, parameters without a value and
/// [`Unidentified::Refuse`].
pub fn validate_with(
    m: &Machine,
    model: &Model,
    values: &[Option<f64>],
    record: &Record,
    source: &mut GainSource,
    opts: &ValidateOptions,
) -> Result<Validation, ValidateError> {
    let names = parameter_names(m, model);
    if values.len() != names.len() {
        return Err(ValidateError::Shape(format!(
            "{} values for the {} parameters of the model ({})",
            values.len(),
            names.len(),
            names.join(", ")
        )));
    }
    if let Some(j) = values
        .iter()
        .position(|v| v.is_some_and(|x| !x.is_finite()))
    {
        return Err(ValidateError::Shape(format!(
            "the value of `{}` is not finite",
            names[j]
        )));
    }
    if record.samples.is_empty() {
        return Err(ValidateError::Shape("the record has no samples".into()));
    }
    let missing: Vec<String> = (0..names.len())
        .filter(|&j| values[j].is_none())
        .map(|j| names[j].clone())
        .collect();
    if !missing.is_empty() && opts.unidentified == Unidentified::Refuse {
        return Err(ValidateError::Unidentified(missing));
    }
    let y = measurement_vector(record)?;
    let p: Vec<f64> = if opts.exact {
        crate::refine::exact_prediction(m, model, values, record, source.params())?
            .iter()
            .flat_map(|r| r.iter().copied())
            .collect()
    } else {
        let h = h_matrix(m, model, record, source)?;
        let v = DVector::from_iterator(values.len(), values.iter().map(|v| v.unwrap_or(0.0)));
        (h * v).as_slice().to_vec()
    };
    let at = |i: usize| [p[3 * i], p[3 * i + 1], p[3 * i + 2]];
    let first = at(0);
    let prediction: Vec<[f64; 3]> = (0..record.samples.len())
        .map(|i| {
            let q = at(i);
            if opts.zeroed {
                std::array::from_fn(|d| q[d] - first[d])
            } else {
                q
            }
        })
        .collect();
    let measured: Vec<[f64; 3]> = (0..record.samples.len())
        .map(|i| [y[3 * i], y[3 * i + 1], y[3 * i + 2]])
        .collect();
    let residual = measured
        .iter()
        .zip(&prediction)
        .map(|(a, b)| std::array::from_fn(|d| a[d] - b[d]))
        .collect();
    let (per_direction, overall) = statistics(&measured, &prediction);
    Ok(Validation {
        samples: record.samples.len(),
        prediction,
        residual,
        per_direction,
        overall,
        defaulted: missing,
        zeroed: opts.zeroed,
    })
}
