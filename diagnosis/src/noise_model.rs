//! The noise model of a diagnosis: where it comes from, and the one the selection whitens
//! with.

use super::adequacy;
use fitting::noise::{self, NoiseChoice, NoiseModel, NoiseSource};

/// The noise model the selection whitens with when the noise was estimated: φ raised by two
/// standard errors of its estimate, `2·√((1 − φ²)/N)` with N the samples pooled (twice the
/// Yule–Walker standard error: the variogram estimate's spread, measured on AR(1) records of
/// the built-in paths' lengths), the raise shrunk in proportion below φ = 0.3. A φ estimated
/// too low leaves correlated noise that the F-tests and the Monte-Carlo null take for
/// structure, and that matters where the correlation is strong; one too high only makes them
/// conservative for the slowly varying candidates, which costs power where the noise is white.
pub(super) fn conservative(noise: &NoiseModel) -> NoiseModel {
    let samples = match noise.source {
        NoiseSource::Estimated { samples, .. } => samples.max(1) as f64,
        _ => return noise.clone(),
    };
    let mut out = noise.clone();
    for p in &mut out.phi {
        let se = 2.0 * ((1.0 - *p * *p) / samples).sqrt();
        *p = (*p + 2.0 * se * (*p / 0.3).min(1.0)).min(noise::MAX_ESTIMATED_PHI);
    }
    out
}

/// The noise model of a diagnosis, and whether it was estimated from the records: declared or
/// from a static record as given; estimated from `series`, the base model's residual on every
/// fitted record and its prediction residual on every held-out record without outliers
/// (independent realisations of the same instrument; [`adequacy::estimate_records`]: in a
/// direction where the records disagree, the cleanest record's); white with the base fit's σ̂
/// `sigma` (mm) when it cannot be estimated (noise-free data) or ordinary least squares was
/// asked for.
pub(super) fn choose(
    choice: &NoiseChoice,
    sigma: Option<f64>,
    series: &[&[[f64; 3]]],
) -> (NoiseModel, bool) {
    let sigma = sigma.filter(|s| *s > 0.0).unwrap_or(noise::NOISE_FLOOR_MM);
    match choice {
        NoiseChoice::Model(model) => (model.clone(), false),
        NoiseChoice::Ordinary => (NoiseModel::residual(sigma, "ordinary least squares"), false),
        // The diagnosis weighs the rows by the covariances' shape and takes the scale from
        // the base fit's residual, which the lack-of-fit test then judges.
        NoiseChoice::Instrument => (
            NoiseModel::residual(
                sigma,
                "ordinary least squares of the rows whitened by the instrument's covariances",
            ),
            false,
        ),
        NoiseChoice::Estimate => match adequacy::estimate_records(series) {
            Ok(model) => (model, true),
            Err(e) => (
                NoiseModel::residual(sigma, format!("the noise cannot be estimated: {e}")),
                false,
            ),
        },
    }
}
