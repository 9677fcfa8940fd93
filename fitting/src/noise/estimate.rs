//! Estimating the noise: Yule–Walker on a static record, the variogram of second differences
//! on fit residuals (accuracies measured in `docs/identification.md`).
//!
//! Variogram of second differences at lag k, for AR(1) noise of marginal variance σ² and lag-1
//! autocorrelation φ plus a smooth misfit `s` (what the model does not describe):
//!
//! ```text
//! D_k(t) = e_{t+k} − 2·e_t + e_{t−k}
//! V(k)   = E[D_k²] = σ²·(6 − 8·φ^k + 2·φ^{2k}) + c·k⁴
//! ```
//!
//! (`c·k⁴` is the second difference of a smooth `s`, `≈ k²·s''`, squared.) A constant or a
//! straight line in the residual (an offset, a drift) cancels exactly; a smooth misfit grows as
//! `k⁴` while the noise's part saturates at `6σ²` (white) or rises as `1 − φ^k` (AR(1)), so
//! the two are told apart by the shape over lags 1..L. Per direction, with the records
//! pooled, `V̂(k)` is the mean of `D_k²` over every record and every `t` with both neighbours
//! in the record. For every φ on the grid 0, 0.01, …, 0.95, σ² ≥ 0 and c ≥ 0 are fitted to
//! `V̂(1..L)` (L = [`VARIOGRAM_LAGS`]) by weighted least squares with weights `n_k / V(k)²` (`n_k` pairs at lag k; the
//! variance of `V̂(k)` is about `2·V(k)²/n_k`): first with `V̂(k)` in the weights, then once
//! more with the best model's `V(k)`. The φ of the smallest weighted residual wins.

use super::{DIRECTIONS, NoiseError, NoiseModel, NoiseSource};
use simulation::record::Record;

/// L, the largest lag of the variogram: at φ = 0.8 the noise's part is then at its plateau
/// (`0.8²⁴ = 0.005`), and 241 samples leave 193 second differences at lag 24. Measured against
/// L = 12 on AR(1) series of 241 samples, φ = 0.8: the spread of σ̂ falls from 22 % to 14 %.
pub const VARIOGRAM_LAGS: usize = 24;

/// The fewest lags the variogram needs (shorter records use the lags they have, down to this).
pub const VARIOGRAM_MIN_LAGS: usize = 8;

/// A lag of the variogram is used when the records give at least this many second
/// differences at it.
pub const VARIOGRAM_MIN_PAIRS: usize = 20;

const PASSES: usize = 2;

/// The step of the grid of φ of the variogram fit.
pub const PHI_GRID_STEP: f64 = 0.01;

/// The largest φ the variogram fit considers: beyond it, 12 lags no longer see the plateau.
pub const MAX_ESTIMATED_PHI: f64 = 0.95;

/// The fewest samples of a static record: at φ = 0.8 its σ is then within about 15 % and its
/// φ within about 0.06 (one standard deviation).
pub const MIN_STATIC_SAMPLES: usize = 100;

/// The largest φ a static record's Yule–Walker estimate is given (larger estimates are set to
/// it).
pub const MAX_STATIC_PHI: f64 = 0.98;

/// The smallest σ an estimate may have, mm (1e-5 µm, far below any R-test's resolution): a
/// residual below it is rounding and second-order terms, not noise.
pub const NOISE_FLOOR_MM: f64 = 1e-8;

/// The variogram of second differences of residual series, per direction.
#[derive(Clone, Debug, PartialEq)]
pub struct Variogram {
    /// The lags used, 1, 2, …
    pub lags: Vec<usize>,
    /// Second differences at each lag, over all records.
    pub pairs: Vec<usize>,
    /// Per direction x, y, z, `V̂(k)` at each lag, mm².
    pub values: [Vec<f64>; 3],
}

/// The variogram of second differences of `residuals` (one slice per record, `[x, y, z]` mm
/// per sample) at lags 1..=`max_lag`, stopping at the first lag with fewer than
/// [`VARIOGRAM_MIN_PAIRS`] second differences.
pub fn variogram(residuals: &[&[[f64; 3]]], max_lag: usize) -> Variogram {
    let mut out = Variogram {
        lags: Vec::new(),
        pairs: Vec::new(),
        values: [Vec::new(), Vec::new(), Vec::new()],
    };
    for k in 1..=max_lag {
        let pairs: usize = residuals
            .iter()
            .map(|r| r.len().saturating_sub(2 * k))
            .sum();
        if pairs < VARIOGRAM_MIN_PAIRS {
            break;
        }
        let mut sums = [0.0; 3];
        for r in residuals {
            for t in k..r.len().saturating_sub(k) {
                for (d, sum) in sums.iter_mut().enumerate() {
                    let dd = r[t + k][d] - 2.0 * r[t][d] + r[t - k][d];
                    *sum += dd * dd;
                }
            }
        }
        out.lags.push(k);
        out.pairs.push(pairs);
        for (values, sum) in out.values.iter_mut().zip(sums) {
            values.push(sum / pairs as f64);
        }
    }
    out
}

/// The noise part of the variogram per unit σ²: `6 − 8·φ^k + 2·φ^{2k}`.
fn shape(phi: f64, k: usize) -> f64 {
    let p = phi.powi(k as i32);
    6.0 - 8.0 * p + 2.0 * p * p
}

/// `Σ wᵢ·aᵢ·bᵢ`.
fn weighted_dot(w: &[f64], a: &[f64], b: &[f64]) -> f64 {
    (0..a.len()).map(|i| w[i] * a[i] * b[i]).sum()
}

/// The weighted residual `Σ wᵢ·(vᵢ − a·gᵢ − c·qᵢ)²`.
fn weighted_ssr(w: &[f64], v: &[f64], (g, a): (&[f64], f64), (q, c): (&[f64], f64)) -> f64 {
    (0..v.len())
        .map(|i| w[i] * (v[i] - a * g[i] - c * q[i]).powi(2))
        .sum()
}

/// One fit of σ² ≥ 0, c ≥ 0 at the noise's shape `g` of one φ (`shape(φ, k)` per lag), `q`
/// the misfit's `k⁴` over `scale`: `(σ², c, weighted residual)`. `fixed` holds what does not
/// depend on φ: `q·q`, `q·v` (weighted) and the weighted residual of `σ² = c = 0`.
fn fit_at(g: &[f64], (q, scale): (&[f64], f64), v: &[f64], w: &[f64], fixed: [f64; 3]) -> [f64; 3] {
    let [qq, qv, zero] = fixed;
    let (gg, gq, gv) = (
        weighted_dot(w, g, g),
        weighted_dot(w, g, q),
        weighted_dot(w, g, v),
    );
    let mut best = (0.0, 0.0, zero);
    let mut consider = |a: f64, c: f64| {
        if a >= 0.0 && c >= 0.0 && a.is_finite() && c.is_finite() {
            let s = weighted_ssr(w, v, (g, a), (q, c));
            if s < best.2 {
                best = (a, c, s);
            }
        }
    };
    let det = gg * qq - gq * gq;
    if det > 0.0 {
        consider((gv * qq - qv * gq) / det, (qv * gg - gv * gq) / det);
    }
    if gg > 0.0 {
        consider(gv / gg, 0.0);
    }
    if qq > 0.0 {
        consider(0.0, qv / qq);
    }
    [best.0, best.1 / scale, best.2]
}

/// The best `(σ², φ)` of one direction's variogram over the grid of φ (see the module
/// documentation). The noise's shapes at every φ of the grid and the misfit's are made once.
fn fit_direction(lags: &[usize], pairs: &[usize], v: &[f64]) -> (f64, f64) {
    let steps = (MAX_ESTIMATED_PHI / PHI_GRID_STEP).round() as usize;
    let grid: Vec<(f64, Vec<f64>)> = (0..=steps)
        .map(|i| {
            let phi = i as f64 * PHI_GRID_STEP;
            (phi, lags.iter().map(|&k| shape(phi, k)).collect())
        })
        .collect();
    let scale = lags.last().map_or(1.0, |&l| (l as f64).powi(4));
    let q: Vec<f64> = lags.iter().map(|&k| (k as f64).powi(4) / scale).collect();
    let floor = v.iter().copied().fold(0.0, f64::max) * 1e-12 + f64::MIN_POSITIVE;
    let weights = |model: &dyn Fn(usize) -> f64| -> Vec<f64> {
        (0..lags.len())
            .map(|i| pairs[i] as f64 / model(i).max(floor).powi(2))
            .collect()
    };
    let search = |w: &[f64]| -> (f64, f64, f64) {
        let fixed = [
            weighted_dot(w, &q, &q),
            weighted_dot(w, &q, v),
            weighted_ssr(w, v, (&grid[0].1, 0.0), (&q, 0.0)),
        ];
        let mut best = (0.0, 0.0, 0.0, f64::INFINITY);
        for (phi, g) in &grid {
            let [a, c, s] = fit_at(g, (&q, scale), v, w, fixed);
            if s < best.3 {
                best = (a, *phi, c, s);
            }
        }
        (best.0, best.1, best.2)
    };
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    let (mut a, mut phi, mut c) = search(&weights(&|_| mean));
    for _ in 0..PASSES {
        let model = |i: usize| a * shape(phi, lags[i]) + c * (lags[i] as f64).powi(4);
        (a, phi, c) = search(&weights(&model));
    }
    (a, phi)
}

/// See [`NoiseModel::estimate`].
pub(super) fn estimate(residuals: &[&[[f64; 3]]]) -> Result<NoiseModel, NoiseError> {
    for (r, series) in residuals.iter().enumerate() {
        if let Some(i) = series.iter().position(|s| s.iter().any(|x| !x.is_finite())) {
            return Err(NoiseError::Unestimable(format!(
                "the residual of sample {} of record {} is not finite",
                i + 1,
                r + 1
            )));
        }
    }
    let vg = variogram(residuals, VARIOGRAM_LAGS);
    let samples: usize = residuals.iter().map(|r| r.len()).sum();
    if vg.lags.len() < VARIOGRAM_MIN_LAGS {
        return Err(NoiseError::Unestimable(format!(
            "{samples} samples in {} record(s) give second differences at {} lag(s); {VARIOGRAM_MIN_LAGS} lags of at least {VARIOGRAM_MIN_PAIRS} are needed",
            residuals.len(),
            vg.lags.len()
        )));
    }
    let mut sigma_mm = [0.0; 3];
    let mut phi = [0.0; 3];
    for d in 0..3 {
        let (s2, p) = fit_direction(&vg.lags, &vg.pairs, &vg.values[d]);
        let s = s2.sqrt();
        if !(s.is_finite() && s >= NOISE_FLOOR_MM) {
            return Err(NoiseError::Unestimable(format!(
                "direction {}: σ = {:.1e} µm is below the floor of {:.0e} µm (the residual is rounding and second-order terms, not noise)",
                DIRECTIONS[d],
                s * 1e3,
                NOISE_FLOOR_MM * 1e3
            )));
        }
        sigma_mm[d] = s;
        phi[d] = p;
    }
    Ok(NoiseModel {
        sigma_mm,
        phi,
        source: NoiseSource::Estimated {
            records: residuals.len(),
            samples,
        },
    })
}

/// See [`NoiseModel::from_static_record`]. Per direction, `x_t` the readings minus their mean
/// over the `n` samples: `r = Σ x_t·x_{t+1} / Σ x_t²`, `φ = r + (1 + 4r)/n` (the small-sample
/// bias of the lag-1 autocorrelation removed), clamped to [0, [`MAX_STATIC_PHI`]];
/// `σ² = (Σ x_t² / n) / (1 − (1+φ)/(n·(1−φ)))` (the variance the removed mean takes away put
/// back). A record whose correction exceeds one half is too short for its correlation.
///
/// A record with covariances (read through an instrument) is first whitened by them
/// ([`super::SampleWhitening`]): the model then describes the whitened rows, as the fits of a
/// record with covariances use it.
pub(super) fn from_static_record(record: &Record) -> Result<NoiseModel, NoiseError> {
    let n = record.measured.len();
    if n == 0 {
        return Err(NoiseError::Readings(
            "the static record has no measured readings".into(),
        ));
    }
    if n < MIN_STATIC_SAMPLES {
        return Err(NoiseError::TooShort {
            samples: n,
            min: MIN_STATIC_SAMPLES,
        });
    }
    if let Some(first) = record.samples.first() {
        for (i, s) in record.samples.iter().enumerate().skip(1) {
            if let Some(a) = (0..s.commands.len()).find(|&a| s.commands[a] != first.commands[a]) {
                return Err(NoiseError::NotStatic {
                    sample: i + 1,
                    axis: a + 1,
                });
            }
        }
    }
    if let Some(i) = record
        .measured
        .iter()
        .position(|r| r.iter().any(|x| !x.is_finite()))
    {
        return Err(NoiseError::Readings(format!(
            "reading {} of the static record is not finite",
            i + 1
        )));
    }
    let whitened: Vec<[f64; 3]>;
    let measured: &[[f64; 3]] = match super::SampleWhitening::of(record)? {
        None => &record.measured,
        Some(w) => {
            let mut v = nalgebra::DVector::from_iterator(
                3 * n,
                record.measured.iter().flat_map(|r| r.iter().copied()),
            );
            w.whiten_vector(&mut v)?;
            whitened = v
                .as_slice()
                .chunks_exact(3)
                .map(|r| [r[0], r[1], r[2]])
                .collect();
            &whitened
        }
    };
    let mut sigma_mm = [0.0; 3];
    let mut phi = [0.0; 3];
    let nf = n as f64;
    for d in 0..3 {
        let mean = measured.iter().map(|r| r[d]).sum::<f64>() / nf;
        let x: Vec<f64> = measured.iter().map(|r| r[d] - mean).collect();
        let g0: f64 = x.iter().map(|v| v * v).sum();
        if g0 <= 0.0 {
            return Err(NoiseError::Readings(format!(
                "direction {}: the static record's readings are all equal (no noise to measure)",
                DIRECTIONS[d]
            )));
        }
        let g1: f64 = x.windows(2).map(|w| w[0] * w[1]).sum();
        let r = g1 / g0;
        let p = (r + (1.0 + 4.0 * r) / nf).clamp(0.0, MAX_STATIC_PHI);
        let lost = (1.0 + p) / (nf * (1.0 - p));
        if lost > 0.5 {
            return Err(NoiseError::TooCorrelated {
                direction: DIRECTIONS[d],
                samples: n,
                phi: p,
            });
        }
        sigma_mm[d] = (g0 / nf / (1.0 - lost)).sqrt();
        phi[d] = p;
    }
    Ok(NoiseModel {
        sigma_mm,
        phi,
        source: NoiseSource::StaticRecord { samples: n },
    })
}
