//! Lack of fit: is what the model leaves consistent with the measurement noise?
//!
//! The noise model ([`NoiseModel`]: σ and φ of an AR(1) process per direction) does not come
//! from the fit: it is declared, estimated from a static record, or estimated by the variogram
//! of second differences, which a smooth misfit of the model does not fool. Per direction d
//! the statistic is
//!
//! ```text
//! T_kd = (mean of r_kd²) / σ̂_d²
//! ```
//!
//! the mean square of record k's residual over the noise variance, with σ̂_d the declared or
//! static σ, or, for an estimated model, the σ estimated from all the residuals together;
//! where the records' own estimates of a direction differ by more than a factor
//! [`HOMOGENEITY`], the smallest of them. A misfit faster than the sampling (a ballscrew
//! period of a few samples) looks like noise to any estimator from one record, but not on
//! every record alike: on a path where the axis barely moves it is absent, and that record's
//! σ̂ is the noise's. Its null distribution is
//! drawn by a parametric bootstrap of the whole procedure: AR(1) noise of the model's σ and φ
//! on the record's samples, fitted by the same generalized least squares (the model's columns,
//! whitened), its residual's noise estimated again when the model was estimated, and `T_d`
//! computed the same way. So the test accounts for the serial correlation, for what the fit
//! absorbs, and for the uncertainty of an estimated σ (each draw estimates it again by the
//! same rule). The p-value of a direction is `(1 + #{draws with T at least as large}) /
//! (D + 1)`; when fewer than [`TAIL_DRAWS`] draws reach the statistic, the rank cannot resolve
//! it, and the p-value is the Gaussian tail of `ln T` beyond the draws' mean and standard
//! deviation (never more than the rank p-value).
//!
//! The test is made on the fitted record and on every held-out record (the extended model's
//! prediction there; each draw's held-out residual is its noise minus the prediction that the
//! draw's own fit makes there, so the fit's uncertainty is carried into it, and a prediction
//! zeroed at the first sample is compared with a draw zeroed the same way): a model
//! that fits the fitted path to the noise with look-alike terms shows its misfit on the paths
//! it did not see. The overall p-value is that of the largest statistic over records and
//! directions, each standardised by its draws (`ln T` minus the draws' mean, over their
//! standard deviation: Westfall and Young's max-T), against the same maximum in every draw; what
//! remains is `consistent_with_noise` when it is at least α. The rank of that maximum is never
//! below `1/(D + 1)`: when fewer than [`TAIL_DRAWS`] draws reach it, its p-value is the tail of
//! the Gumbel law of the drawn maxima (never more than the rank), so that the number of draws
//! does not floor a clear failure into a pass. The per-direction p-values are reported for
//! people.
//!
//! Whatever the p-value, a residual whose RMS in a direction of a record is more than
//! [`NOISE_MULTIPLE`] times what the null gives there (the noise's σ; on a held-out record
//! also the fit's own uncertainty carried into its prediction, the draws' mean square) is not
//! consistent with the noise.
//!
//! An estimated noise model is estimated after the periodic disturbances in time are taken out
//! of the residuals ([`super::tones`]), so that a line in the spectrum does not pass for
//! correlated noise.

use fitting::noise::{NoiseError, NoiseModel};
use nalgebra::{DMatrix, DVector};
use simulation::rng::Rng;

/// Records whose σ estimates of one direction differ by more than this factor are not
/// measuring the same noise.
pub const HOMOGENEITY: f64 = 1.5;

/// Draws of the bootstrap null by default ([`super::DiagnoseOptions::adequacy_draws`]).
pub const DRAWS: usize = 200;

/// Below this many draws at least as large, the p-value is the Gaussian tail of `ln T`.
pub const TAIL_DRAWS: usize = 5;

use fitting::distributions::normal_upper_tail as normal_tail;

/// The test on one record.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordAdequacy {
    /// The record's name.
    pub name: String,
    /// `true` for the fitted record, `false` for a held-out one.
    pub fitted: bool,
    /// The noise's σ per direction the statistic used, mm (for an estimated model: the smallest
    /// of the records' own estimates).
    pub noise_sigma_mm: [f64; 3],
    /// RMS of the residual per direction, mm.
    pub residual_sigma_mm: [f64; 3],
    /// The RMS the null gives this residual per direction, mm: the noise and, on a held-out
    /// record, the fit's own uncertainty carried into the prediction (the bootstrap draws' mean
    /// square).
    pub null_rms_mm: [f64; 3],
    /// `T_d`, the residual's mean square over σ̂² per direction.
    pub statistic: [f64; 3],
    /// The bootstrap p-value per direction.
    pub p_values: [f64; 3],
}

/// The lack-of-fit test of the extended model.
#[derive(Clone, Debug, PartialEq)]
pub struct Adequacy {
    /// The noise model tested against.
    pub noise: NoiseModel,
    /// Per record: the fitted one first, then the held-out ones.
    pub records: Vec<RecordAdequacy>,
    /// The family-wise p-value over records and directions (max-T).
    pub p_value: f64,
    /// Bootstrap draws.
    pub draws: usize,
    /// The (record, direction) pairs, indices into `records` and 0, 1, 2 for x, y, z, whose
    /// residual RMS is more than [`NOISE_MULTIPLE`] times what the null gives there (the
    /// noise's σ, or on a held-out record the RMS the noise and the fit's uncertainty give its
    /// prediction, whichever is larger).
    pub over_noise: Vec<(usize, usize)>,
    /// `p_value ≥ α` and no residual more than [`NOISE_MULTIPLE`] times the noise
    /// (`over_noise` empty).
    pub consistent_with_noise: bool,
}

/// A residual whose RMS in a direction is more than this multiple of what the null gives
/// there ([`RecordAdequacy::null_rms_mm`], at least the noise's σ) is never consistent with the
/// noise, whatever the bootstrap's p-value: its mean square is 4 times the null's, which the
/// noise reaches on a record of 30 samples or more with a probability far below any α used, so
/// a p-value that passes it comes from a null that does not fit the residual (a drift the
/// draws cannot make, too few draws).
pub const NOISE_MULTIPLE: f64 = 2.0;

/// `P(M ≥ m)` under the Gumbel law with the mean and standard deviation of `maxima` (1 when
/// they do not spread).
fn gumbel_tail(maxima: &[f64], m: f64) -> f64 {
    let n = maxima.len() as f64;
    if maxima.len() < 2 {
        return 1.0;
    }
    let mean = maxima.iter().sum::<f64>() / n;
    let sd = (maxima.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    if sd.is_nan() || sd <= 0.0 || !m.is_finite() {
        return 1.0;
    }
    let beta = sd * 6f64.sqrt() / std::f64::consts::PI;
    let loc = mean - 0.577_215_664_901_532_9 * beta;
    -(-(-(m - loc) / beta).exp()).exp_m1()
}

/// What to test: a residual and, for the fitted record, the columns that were fitted.
pub struct Residual<'a> {
    /// The record's name.
    pub name: &'a str,
    /// `y − prediction`, mm, 3 rows per sample.
    pub residual: &'a DVector<f64>,
    /// The columns fitted to this record (mm per unit); `None` for a held-out record.
    pub fitted: Option<&'a DMatrix<f64>>,
    /// For a held-out record: the same columns on it, so that each draw's prediction error
    /// (the fit's own uncertainty) enters its residual.
    pub predicted: Option<&'a DMatrix<f64>>,
    /// The prediction was zeroed at the first sample.
    pub zeroed: bool,
}

/// Rows `[x, y, z]` of a vector of 3 rows per sample.
fn rows(v: &[f64]) -> Vec<[f64; 3]> {
    v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
}

/// Mean square per direction of `r`.
fn mean_squares(r: &[[f64; 3]]) -> [f64; 3] {
    let n = r.len().max(1) as f64;
    std::array::from_fn(|d| r.iter().map(|v| v[d] * v[d]).sum::<f64>() / n)
}

/// The noise of several records' residual series, estimated from all of them together; except
/// in a direction where the records' own estimates of σ differ by more than [`HOMOGENEITY`]:
/// there σ and φ are those of the record with the smallest σ (a misfit that looks like noise on
/// one record, a fast period or a harmonic beyond the model's, is absent where its axis does not
/// move, and that record's estimate is the noise's).
///
/// # Errors
/// [`NoiseError`] when the noise cannot be estimated from the series together.
pub fn estimate_records(residuals: &[&[[f64; 3]]]) -> Result<NoiseModel, NoiseError> {
    let cleaned: Vec<Vec<[f64; 3]>> = residuals
        .iter()
        .map(|r| super::tones::without_tones(r).0)
        .collect();
    let residuals: Vec<&[[f64; 3]]> = cleaned.iter().map(Vec::as_slice).collect();
    estimate_pooled(&residuals)
}

/// [`estimate_records`] without looking for periodic disturbances first: the rule of the
/// bootstrap draws, whose noise is AR(1) by construction (a line in a draw is found at a rate
/// of [`super::tones::TONE_ALPHA`] per direction, too seldom to change the null).
fn estimate_pooled(residuals: &[&[[f64; 3]]]) -> Result<NoiseModel, NoiseError> {
    let mut out = NoiseModel::estimate(residuals)?;
    let own: Vec<NoiseModel> = residuals
        .iter()
        .filter_map(|r| NoiseModel::estimate(&[r]).ok())
        .collect();
    for d in 0..3 {
        let lo = own
            .iter()
            .min_by(|a, b| a.sigma_mm[d].total_cmp(&b.sigma_mm[d]));
        let hi = own.iter().map(|m| m.sigma_mm[d]).fold(0.0f64, f64::max);
        if let Some(lo) = lo
            && own.len() > 1
            && hi > HOMOGENEITY * lo.sigma_mm[d]
        {
            out.sigma_mm[d] = lo.sigma_mm[d];
            out.phi[d] = lo.phi[d];
        }
    }
    Ok(out)
}

/// The σ per direction the statistics divide by: the model's; or, when it was estimated, that
/// of [`estimate_records`] on the residuals tested (periodic disturbances taken out first:
/// `observed`), or of its pooled estimate alone (a bootstrap draw).
fn reference_sigma(
    noise: &NoiseModel,
    estimated: bool,
    residuals: &[Vec<[f64; 3]>],
    observed: bool,
) -> Result<[f64; 3], NoiseError> {
    if !estimated {
        return Ok(noise.sigma_mm);
    }
    let all: Vec<&[[f64; 3]]> = residuals.iter().map(Vec::as_slice).collect();
    if observed {
        Ok(estimate_records(&all)?.sigma_mm)
    } else {
        Ok(estimate_pooled(&all)?.sigma_mm)
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

/// The fit of a draw on a fitted record: its columns and the pseudo-inverse of the whitened
/// columns (β = (whitened H)⁺ · (whitened e)).
fn draw_fit(noise: &NoiseModel, h: &DMatrix<f64>) -> Result<DMatrix<f64>, NoiseError> {
    let mut hw = h.clone();
    noise.whiten_matrix(&[h.nrows() / 3], &mut hw)?;
    let svd = hw.svd(true, true);
    let tol = svd.singular_values.max() * 1e-10 * (h.nrows().max(h.ncols()) as f64);
    svd.pseudo_inverse(tol)
        .map_err(|e| NoiseError::Whitening(e.to_string()))
}

/// Zeroes `v` (3 rows per sample) at its first sample.
fn zero_first(v: &mut DVector<f64>) {
    let first = v.rows(0, 3).into_owned();
    for i in 0..v.len() / 3 {
        let mut row = v.rows_mut(3 * i, 3);
        row -= &first;
    }
}

/// Each record's noise of one draw (AR(1) of `noise`, in the records' order): what a draw takes
/// from the random numbers.
fn draw_noise(noise: &NoiseModel, residuals: &[Residual], rng: &mut Rng) -> Vec<DVector<f64>> {
    residuals
        .iter()
        .map(|r| draw(noise, r.residual.len() / 3, rng))
        .collect()
}

/// One draw of every residual under the null from each record's drawn noise `drawn`: the
/// fitted record's noise and the residual of its fit, then every held-out record's noise minus
/// the prediction that fit makes there.
fn draw_residuals(
    noise: &NoiseModel,
    residuals: &[Residual],
    fits: &[Option<DMatrix<f64>>],
    drawn: Vec<DVector<f64>>,
) -> Result<Vec<Vec<[f64; 3]>>, NoiseError> {
    let mut beta: Option<DVector<f64>> = None;
    let mut out = Vec::with_capacity(residuals.len());
    for ((r, pinv), mut e) in residuals.iter().zip(fits).zip(drawn) {
        let samples = r.residual.len() / 3;
        if let (Some(h), Some(pinv)) = (r.fitted, pinv) {
            let mut ew = e.clone();
            noise.whiten_vector(&[samples], &mut ew)?;
            let b = pinv * ew;
            e -= h * &b;
            beta = Some(b);
        } else if let (Some(hh), Some(b)) = (r.predicted, &beta) {
            e -= hh * b;
        }
        if r.zeroed {
            zero_first(&mut e);
        }
        out.push(rows(e.as_slice()));
    }
    Ok(out)
}

/// How many draws are drawn from the random numbers before their fits and noise estimates are
/// made on every core.
const DRAW_BATCH: usize = 32;

/// Tests the residuals against `noise`; `estimated`: the noise model was estimated from the
/// records (so each draw estimates it again); level `alpha`.
///
/// # Errors
/// [`NoiseError`] when the noise model cannot whiten, or σ cannot be estimated from a
/// residual (noise-free data).
pub fn adequacy(
    noise: &NoiseModel,
    estimated: bool,
    residuals: &[Residual],
    alpha: f64,
    seed: u64,
    draws: usize,
) -> Result<Adequacy, NoiseError> {
    let observed: Vec<Vec<[f64; 3]>> = residuals
        .iter()
        .map(|r| rows(r.residual.as_slice()))
        .collect();
    let sigma = reference_sigma(noise, estimated, &observed, true)?;
    let statistic = |r: &[[f64; 3]], sigma: &[f64; 3]| -> [f64; 3] {
        let ms = mean_squares(r);
        std::array::from_fn(|d| ms[d] / sigma[d].powi(2))
    };
    let stats: Vec<[f64; 3]> = observed.iter().map(|r| statistic(r, &sigma)).collect();
    let fits = residuals
        .iter()
        .map(|r| r.fitted.map(|h| draw_fit(noise, h)).transpose())
        .collect::<Result<Vec<_>, _>>()?;
    let mut rng = Rng::new(seed);
    let mut exceed = vec![[0usize; 3]; residuals.len()];
    let mut logs = vec![[(0.0f64, 0.0f64); 3]; residuals.len()];
    // Every draw's T per record and direction, summed: the null's mean square over σ̂².
    let mut drawn_t = vec![[0.0f64; 3]; residuals.len()];
    // Every draw's ln T per record and direction (`None`: σ could not be estimated).
    let mut drawn_logs: Vec<Option<Vec<[f64; 3]>>> = Vec::with_capacity(draws);
    let mut left = draws;
    while left > 0 {
        // The random numbers in draw order, as one draw after the other takes them; the fits
        // and estimates of the batch's draws on every core, taken in draw order.
        let batch: Vec<Vec<DVector<f64>>> = (0..left.min(DRAW_BATCH))
            .map(|_| draw_noise(noise, residuals, &mut rng))
            .collect();
        left -= batch.len();
        let done = crate::parallel::map_in_order(&batch, |drawn| {
            let drawn = draw_residuals(noise, residuals, &fits, drawn.clone())?;
            Ok(reference_sigma(noise, estimated, &drawn, false)
                .ok()
                .map(|s| (drawn, s)))
        });
        for d in done {
            // A draw whose σ cannot be estimated counts as exceeding: conservative, it can only
            // make the residuals look more consistent with the noise.
            let Some((drawn, s)) = d? else {
                exceed.iter_mut().flatten().for_each(|x| *x += 1);
                drawn_logs.push(None);
                continue;
            };
            let mut this = Vec::with_capacity(drawn.len());
            for (k, r) in drawn.iter().enumerate() {
                let t = statistic(r, &s);
                let mut l3 = [0.0; 3];
                for d in 0..3 {
                    if t[d] >= stats[k][d] {
                        exceed[k][d] += 1;
                    }
                    drawn_t[k][d] += t[d];
                    let l = t[d].max(f64::MIN_POSITIVE).ln();
                    logs[k][d].0 += l;
                    logs[k][d].1 += l * l;
                    l3[d] = l;
                }
                this.push(l3);
            }
            drawn_logs.push(Some(this));
        }
    }
    // The overall test is the maximum over records and directions of ln T standardised by the
    // draws (Westfall and Young's max-T): its null distribution is drawn with the others, so the
    // family-wise level needs no Bonferroni factor and holds whatever the correlations.
    let n_ok = drawn_logs.iter().flatten().count().max(1) as f64;
    let moments: Vec<[(f64, f64); 3]> = logs
        .iter()
        .map(|l| {
            l.map(|(a, b)| {
                let mean = a / n_ok;
                (mean, (b / n_ok - mean * mean).max(0.0).sqrt())
            })
        })
        .collect();
    let z = |k: usize, d: usize, l: f64| -> f64 {
        let (mean, sd) = moments[k][d];
        if sd > 0.0 { (l - mean) / sd } else { 0.0 }
    };
    let observed_max = (0..stats.len())
        .flat_map(|k| (0..3).map(move |d| (k, d)))
        .map(|(k, d)| z(k, d, stats[k][d].max(f64::MIN_POSITIVE).ln()))
        .fold(f64::NEG_INFINITY, f64::max);
    let at_least = drawn_logs
        .iter()
        .filter(|dl| match dl {
            None => true,
            Some(l) => {
                (0..l.len())
                    .flat_map(|k| (0..3).map(move |d| (k, d)))
                    .map(|(k, d)| z(k, d, l[k][d]))
                    .fold(f64::NEG_INFINITY, f64::max)
                    >= observed_max
            }
        })
        .count();
    let records: Vec<RecordAdequacy> = residuals
        .iter()
        .enumerate()
        .map(|(k, r)| RecordAdequacy {
            name: r.name.to_string(),
            fitted: r.fitted.is_some(),
            noise_sigma_mm: sigma,
            residual_sigma_mm: mean_squares(&observed[k]).map(f64::sqrt),
            null_rms_mm: std::array::from_fn(|d| sigma[d] * (drawn_t[k][d] / n_ok).sqrt()),
            statistic: stats[k],
            p_values: std::array::from_fn(|d| {
                let rank = (1 + exceed[k][d]) as f64 / (draws + 1) as f64;
                if exceed[k][d] >= TAIL_DRAWS {
                    return rank;
                }
                let n = draws.max(1) as f64;
                let mean = logs[k][d].0 / n;
                let sd = (logs[k][d].1 / n - mean * mean).max(0.0).sqrt();
                let z = (stats[k][d].max(f64::MIN_POSITIVE).ln() - mean) / sd;
                if sd > 0.0 && z.is_finite() {
                    normal_tail(z).min(rank)
                } else {
                    rank
                }
            }),
        })
        .collect();
    // The rank of the maximum cannot go below 1/(D + 1): when fewer than TAIL_DRAWS draws
    // reach the observed maximum, the tail is the Gumbel law of the drawn maxima (moments),
    // never more than the rank.
    let rank = (1 + at_least) as f64 / (draws + 1) as f64;
    let p_value = if at_least < TAIL_DRAWS {
        let maxima: Vec<f64> = drawn_logs
            .iter()
            .flatten()
            .map(|l| {
                (0..l.len())
                    .flat_map(|k| (0..3).map(move |d| (k, d)))
                    .map(|(k, d)| z(k, d, l[k][d]))
                    .fold(f64::NEG_INFINITY, f64::max)
            })
            .collect();
        rank.min(gumbel_tail(&maxima, observed_max))
    } else {
        rank
    };
    let over_noise: Vec<(usize, usize)> = records
        .iter()
        .enumerate()
        .flat_map(|(k, r)| (0..3).map(move |d| (k, d, r)))
        .filter(|(_, d, r)| {
            r.residual_sigma_mm[*d] > NOISE_MULTIPLE * r.noise_sigma_mm[*d].max(r.null_rms_mm[*d])
        })
        .map(|(k, d, _)| (k, d))
        .collect();
    Ok(Adequacy {
        noise: noise.clone(),
        records,
        p_value,
        draws,
        consistent_with_noise: p_value >= alpha && over_noise.is_empty(),
        over_noise,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use fitting::noise::NoiseSource;

    /// White noise of σ in every direction, `n` samples, plus `extra(i)` in y.
    fn residual(n: usize, sigma: f64, seed: u64, extra: impl Fn(usize) -> f64) -> DVector<f64> {
        let mut rng = Rng::new(seed);
        DVector::from_fn(3 * n, |r, _| {
            let e = sigma * rng.normal();
            if r % 3 == 1 { e + extra(r / 3) } else { e }
        })
    }

    fn declared(sigma: f64) -> NoiseModel {
        NoiseModel::white(sigma, NoiseSource::Declared)
    }

    fn held_out<'a>(name: &'a str, r: &'a DVector<f64>) -> Residual<'a> {
        Residual {
            name,
            residual: r,
            fitted: None,
            predicted: None,
            zeroed: false,
        }
    }

    #[test]
    fn few_draws_do_not_floor_a_clear_failure_into_a_pass() {
        // 19 draws: the rank of the maximum cannot go below 1/20 = 0.05, above α = 0.01. A
        // residual with 1.6 times the noise's σ in y on 241 samples is a failure by far (its
        // mean square is 2.5 times the noise's; the chi-square tail is below 1e-30).
        for seed in 1..=5 {
            let r = residual(241, 4e-4, seed, |_| 5e-4);
            let a = adequacy(
                &declared(4e-4),
                false,
                &[held_out("K1", &r)],
                0.01,
                seed,
                19,
            )
            .unwrap();
            assert!(a.p_value < 0.01, "seed {seed}: p {}", a.p_value);
            assert!(!a.consistent_with_noise, "seed {seed}");
        }
    }

    #[test]
    fn a_residual_over_twice_the_noise_is_never_consistent() {
        // A random walk in y of the held-out record: its RMS is several times the noise's σ.
        // However tame the null's p-value, the rule holds.
        for seed in 1..=5 {
            let mut rng = Rng::new(100 + seed);
            let mut walk = vec![0.0];
            for _ in 1..241 {
                let last = *walk.last().unwrap();
                walk.push(last + 2e-4 * rng.normal());
            }
            let r = residual(241, 4e-4, seed, |i| walk[i]);
            let a = adequacy(
                &declared(4e-4),
                false,
                &[held_out("K1", &r)],
                0.01,
                seed,
                200,
            )
            .unwrap();
            let rms_y = a.records[0].residual_sigma_mm[1];
            assert!(
                rms_y > NOISE_MULTIPLE * 4e-4,
                "seed {seed}: the walk is too small"
            );
            assert_eq!(a.over_noise, vec![(0, 1)], "seed {seed}");
            assert!(!a.consistent_with_noise, "seed {seed}");
            // Forced: a null that cannot see it (α = 0) still does not pass it.
            let b = adequacy(
                &declared(4e-4),
                false,
                &[held_out("K1", &r)],
                0.0,
                seed,
                200,
            )
            .unwrap();
            assert_eq!(
                b.consistent_with_noise,
                b.over_noise.is_empty(),
                "seed {seed}"
            );
        }
    }

    #[test]
    fn noise_alone_is_consistent() {
        let mut passes = 0;
        for seed in 1..=20 {
            let r = residual(241, 4e-4, seed, |_| 0.0);
            let a = adequacy(
                &declared(4e-4),
                false,
                &[held_out("K1", &r)],
                0.01,
                seed,
                200,
            )
            .unwrap();
            assert!(a.over_noise.is_empty(), "seed {seed}");
            passes += usize::from(a.consistent_with_noise);
        }
        assert!(passes >= 18, "{passes} of 20 pass");
    }
}
