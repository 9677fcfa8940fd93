//! Lack of fit: is what the model leaves consistent with the measurement noise?
//!
//! The noise model ([`NoiseModel`]: σ and φ of an AR(1) process per direction) does not come
//! from the fit: it is declared, estimated from a static record, or estimated by the variogram
//! of second differences, which a smooth misfit of the model does not fool. Per direction d
//! the statistic is
//!
//! ```text
//! T_d = (mean of r_d²) / σ̂_d²
//! ```
//!
//! the residual's mean square over the noise variance, with σ̂_d the declared or static σ, or,
//! for an estimated model, the σ estimated from that residual alone. Its null distribution is
//! drawn by a parametric bootstrap of the whole procedure: AR(1) noise of the model's σ and φ
//! on the record's samples, fitted by the same generalized least squares (the model's columns,
//! whitened), its residual's noise estimated again when the model was estimated, and `T_d`
//! computed the same way. So the test accounts for the serial correlation, for what the fit
//! absorbs, and for the uncertainty of an estimated σ. The p-value of a direction is
//! `(1 + #{draws with T_d at least as large}) / (D + 1)`; the overall p-value is the smallest of
//! the three times 3 (Bonferroni over the directions), and the residual is
//! `consistent_with_noise` when it is at least α.

use crate::fitting::noise::{NoiseError, NoiseModel};
use crate::simulation::rng::Rng;
use nalgebra::{DMatrix, DVector};

/// Draws of the bootstrap null.
pub const DRAWS: usize = 400;

/// The lack-of-fit test of a residual.
#[derive(Clone, Debug, PartialEq)]
pub struct Adequacy {
    /// The noise model tested against.
    pub noise: NoiseModel,
    /// The noise's σ per direction the statistic used, mm (for an estimated model: estimated
    /// from this residual).
    pub noise_sigma_mm: [f64; 3],
    /// RMS of the residual per direction, mm.
    pub residual_sigma_mm: [f64; 3],
    /// `T_d`, the residual's mean square over σ̂² per direction.
    pub statistic: [f64; 3],
    /// The bootstrap p-value per direction.
    pub p_values: [f64; 3],
    /// The smallest of them times 3, at most 1.
    pub p_value: f64,
    /// Bootstrap draws.
    pub draws: usize,
    /// `p_value ≥ α`.
    pub consistent_with_noise: bool,
}

/// Rows `[x, y, z]` of a vector of 3 rows per sample.
fn rows(v: &[f64]) -> Vec<[f64; 3]> {
    v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
}

/// Mean square per direction of `r` (3 rows per sample).
fn mean_squares(r: &[[f64; 3]]) -> [f64; 3] {
    let n = r.len().max(1) as f64;
    std::array::from_fn(|d| r.iter().map(|v| v[d] * v[d]).sum::<f64>() / n)
}

/// The σ the statistic divides by: the model's, or estimated from `r` when the model was.
fn sigma_of(noise: &NoiseModel, estimated: bool, r: &[[f64; 3]]) -> Result<[f64; 3], NoiseError> {
    if estimated {
        Ok(NoiseModel::estimate(&[r])?.sigma_mm)
    } else {
        Ok(noise.sigma_mm)
    }
}

/// AR(1) noise of `noise` on `samples` samples: 3 rows per sample.
fn draw(noise: &NoiseModel, samples: usize, rng: &mut Rng) -> DVector<f64> {
    let mut e = DVector::zeros(3 * samples);
    for d in 0..3 {
        let (s, p) = (noise.sigma_mm[d], noise.phi[d]);
        let innovation = s * (1.0 - p * p).sqrt();
        let mut prev = s * rng.normal();
        e[d] = prev;
        for i in 1..samples {
            prev = p * prev + innovation * rng.normal();
            e[3 * i + d] = prev;
        }
    }
    e
}

/// Tests the residual `residual` (mm, 3 rows per sample, one record) of a fit of the columns
/// `h` (mm per unit of each parameter, same rows) against `noise`; `estimated`: the noise model
/// was estimated from the records (so each draw estimates it again); level `alpha`.
///
/// # Errors
/// [`NoiseError`] when the noise model cannot whiten, or σ cannot be estimated from the
/// residual (noise-free data).
pub fn adequacy(
    noise: &NoiseModel,
    estimated: bool,
    h: &DMatrix<f64>,
    residual: &DVector<f64>,
    alpha: f64,
    seed: u64,
) -> Result<Adequacy, NoiseError> {
    let samples = residual.len() / 3;
    let layout = [samples];
    let r = rows(residual.as_slice());
    let noise_sigma_mm = sigma_of(noise, estimated, &r)?;
    let ms = mean_squares(&r);
    let statistic: [f64; 3] = std::array::from_fn(|d| ms[d] / noise_sigma_mm[d].powi(2));

    // The generalized least-squares fit of a draw: β = (whitened H)⁺ · (whitened e).
    let mut hw = h.clone();
    noise.whiten_matrix(&layout, &mut hw)?;
    let svd = hw.svd(true, true);
    let tol = svd.singular_values.max() * 1e-10 * (h.nrows().max(h.ncols()) as f64);
    let pinv = svd
        .pseudo_inverse(tol)
        .map_err(|e| NoiseError::Whitening(e.to_string()))?;
    let mut rng = Rng::new(seed);
    let mut exceed = [0usize; 3];
    for _ in 0..DRAWS {
        let e = draw(noise, samples, &mut rng);
        let mut ew = e.clone();
        noise.whiten_vector(&layout, &mut ew)?;
        let beta = &pinv * ew;
        let rd = rows((e - h * beta).as_slice());
        // A draw whose σ cannot be estimated counts as exceeding: conservative, it can only
        // make the residual look more consistent with the noise.
        let Ok(sigma) = sigma_of(noise, estimated, &rd) else {
            exceed.iter_mut().for_each(|x| *x += 1);
            continue;
        };
        let msd = mean_squares(&rd);
        for d in 0..3 {
            if msd[d] / sigma[d].powi(2) >= statistic[d] {
                exceed[d] += 1;
            }
        }
    }
    let p_values: [f64; 3] = std::array::from_fn(|d| (1 + exceed[d]) as f64 / (DRAWS + 1) as f64);
    let p_value = (3.0 * p_values.iter().copied().fold(1.0, f64::min)).min(1.0);
    Ok(Adequacy {
        noise: noise.clone(),
        noise_sigma_mm,
        residual_sigma_mm: ms.map(f64::sqrt),
        statistic,
        p_values,
        p_value,
        draws: DRAWS,
        consistent_with_noise: p_value >= alpha,
    })
}
