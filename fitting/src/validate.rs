//! What a validation is made of: its options, its errors, its statistics and the validation of
//! one record. The validation itself ([`crate::validate()`], in [`mod@crate::campaign::validate`])
//! takes a campaign, as every stage does.
//!
//! - Prediction `p_i = H_i·v` (mm), `H` of the record's model on the validation record
//!   ([`crate::hmatrix`]), `v` the identified values; a parameter without a value (not
//!   determined by the identification) is set by [`Unidentified`] (default 0, and
//!   [`Validation::defaulted`] names it).
//! - With [`ValidateOptions::exact`], `p_i` is the exact machine at the identified values
//!   instead ([`crate::refine::exact_prediction`]).
//! - "Before" is the nominal machine: prediction 0, residual = measured. "After" is the model:
//!   residual `r_i = m_i − p_i`.
//! - Per direction d ∈ {x, y, z}: RMS `√(Σ_i r_id² / N)` and max `|r_id|`; over all three:
//!   RMS `√(Σ_i Σ_d r_id² / 3N)`, max over all.
//! - For tolerances ([`crate::verdict`]): per direction the [`Extent`] of the measured values
//!   and of the residual over a record, its largest |value| and its range `max − min`.

use crate::EstimateError;
use crate::hmatrix::HMatrixError;

/// What a parameter without a value becomes in the prediction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Unidentified {
    /// Zero (the nominal value), named in [`Validation::defaulted`].
    #[default]
    Zero,
    /// Refuse to predict ([`ValidateError::Unidentified`]).
    Refuse,
}

/// Options of [`crate::validate()`] (`ValidateOptions::default()`, then set the fields
/// wanted; each record of the campaign carries its own zeroing and kinematic parameters).
#[derive(Clone, Debug, PartialEq, Default)]
#[non_exhaustive]
pub struct ValidateOptions {
    /// What parameters without a value become.
    pub unidentified: Unidentified,
    /// Predict with the exact machine at the identified values
    /// ([`crate::refine::exact_prediction`]) instead of the first-order `H·v`: the difference is
    /// the second-order terms (about 1e-3 µm for errors of tens of µm and µrad).
    pub exact: bool,
}

impl ValidateOptions {
    /// The defaults: undetermined parameters set to 0, first-order prediction.
    pub fn new() -> ValidateOptions {
        ValidateOptions::default()
    }

    /// With what parameters without a value become.
    pub fn unidentified(mut self, unidentified: Unidentified) -> ValidateOptions {
        self.unidentified = unidentified;
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

/// The extent of the deviation over a test in one direction: its smallest and largest value
/// (mm, or any one unit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extent {
    /// The smallest value.
    pub min: f64,
    /// The largest value.
    pub max: f64,
}

impl Extent {
    /// The extent per direction x, y, z of `samples` (`None` for no sample; a value that is
    /// not finite makes its direction's extent not finite).
    pub fn of(samples: &[[f64; 3]]) -> Option<[Extent; 3]> {
        let first = samples.first()?;
        let mut e = first.map(|x| Extent { min: x, max: x });
        for s in samples {
            for (e, &x) in e.iter_mut().zip(s) {
                if x.is_nan() || e.min.is_nan() {
                    *e = Extent {
                        min: f64::NAN,
                        max: f64::NAN,
                    };
                } else {
                    e.min = e.min.min(x);
                    e.max = e.max.max(x);
                }
            }
        }
        Some(e)
    }

    /// The largest |value|: `max(|min|, |max|)`.
    pub fn max_abs(&self) -> f64 {
        if self.min.is_nan() || self.max.is_nan() {
            return f64::NAN;
        }
        self.min.abs().max(self.max.abs())
    }

    /// The range `max − min`.
    pub fn range(&self) -> f64 {
        self.max - self.min
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extents_give_the_largest_deviation_and_the_range() {
        let e = Extent::of(&[[1.0, -2.0, 0.0], [-3.0, 1.0, 0.0], [2.0, 0.5, 0.0]]).unwrap();
        assert_eq!((e[0].max_abs(), e[0].range()), (3.0, 5.0));
        assert_eq!((e[1].max_abs(), e[1].range()), (2.0, 3.0));
        assert_eq!((e[2].max_abs(), e[2].range()), (0.0, 0.0));
        assert!(Extent::of(&[]).is_none());
        let e = Extent::of(&[[1.0, 0.0, 0.0], [f64::NAN, 0.0, 0.0]]).unwrap();
        assert!(e[0].max_abs().is_nan() && e[0].range().is_nan());
    }
}
