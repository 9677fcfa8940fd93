//! Periodic disturbances in time: found and taken out of a residual before its noise is
//! estimated, so that the noise model does not absorb them.
//!
//! A disturbance that repeats in time with a period of a few samples to a few tens of samples
//! (a coolant pump, a fan, a ballscrew's period passed at constant speed) looks like correlated
//! noise to the variogram of second differences: fitted as AR(1) noise it raises σ and φ (a
//! 0.5 µm sinusoid of 14 samples in 0.3 µm white noise estimates as σ = 0.53 µm, φ = 0.77), and
//! every test after is then too tame to see it. A sinusoid is a line in the spectrum, AR(1)
//! noise is not: per direction, the Hann-windowed periodogram `I(f)` is compared with the
//! spectrum of the AR(1) noise estimated from the same series,
//!
//! ```text
//! S(f) = σ²·(1 − φ²) / (1 − 2·φ·cos 2πf + φ²)
//! ```
//!
//! Under that noise `I(f)/S(f)` is close to exponential with mean 1 at every frequency, so the
//! largest ratio `q` over the `M` frequencies searched (the padded grid counted in full, which
//! errs towards keeping) has the p-value `1 − (1 − e^{−q})^M`. A line with p below
//! [`TONE_ALPHA`] is a disturbance: its frequency is refined, its sinusoid fitted by least
//! squares and subtracted, the noise estimated again, and the search repeated (at most
//! [`MAX_TONES`] per direction). The periods searched run from [`SHORTEST_PERIOD`] samples to
//! [`LONGEST_PERIOD`] samples (at most a quarter of the record): slower variations grow over
//! the variogram's lags as a smooth misfit does, and the variogram already sets them apart. A
//! misfit of the model that is periodic in time within that range (a high harmonic on a path
//! at constant speed) is taken out too: it is not noise either.
//!
//! What is taken out is only kept out of the noise estimate. The residual the tests see is
//! unchanged, so a disturbance left in it fails the lack-of-fit test and is described
//! ([`super::unexplained`]: periodic in time).

use fitting::noise::{NoiseModel, VARIOGRAM_LAGS};

/// The p-value below which a spectral line is a disturbance, per direction and series.
pub const TONE_ALPHA: f64 = 1e-3;

/// At most this many lines are taken out of one direction of one series.
pub const MAX_TONES: usize = 3;

/// The shortest period searched, samples.
pub const SHORTEST_PERIOD: f64 = 2.5;

/// The longest period searched, samples: twice the variogram's largest lag (slower variations
/// grow over its lags as a smooth misfit does).
pub const LONGEST_PERIOD: f64 = 2.0 * VARIOGRAM_LAGS as f64;

/// Frequencies searched per Fourier frequency (zero padding of the periodogram).
const PAD: f64 = 4.0;

/// The fewest samples a series needs to be searched.
const MIN_SAMPLES: usize = 64;

/// A periodic disturbance found in one direction of a residual series.
#[derive(Clone, Debug, PartialEq)]
pub struct Tone {
    /// 0, 1, 2 for x, y, z.
    pub direction: usize,
    /// Its period, samples.
    pub period_samples: f64,
    /// Its amplitude, mm.
    pub amplitude_mm: f64,
    /// The p-value of its line against the AR(1) noise.
    pub p_value: f64,
}

/// `residual` (one `[x, y, z]` per sample, mm, equally spaced) with the periodic disturbances
/// of every direction taken out, and the disturbances. A series too short to search, or whose
/// noise cannot be estimated, comes back unchanged.
pub fn without_tones(residual: &[[f64; 3]]) -> (Vec<[f64; 3]>, Vec<Tone>) {
    let mut out = residual.to_vec();
    let mut found = Vec::new();
    if residual.len() < MIN_SAMPLES {
        return (out, found);
    }
    for d in 0..3 {
        for _ in 0..MAX_TONES {
            let Ok(noise) = NoiseModel::estimate(&[&out]) else {
                break;
            };
            let x: Vec<f64> = out.iter().map(|v| v[d]).collect();
            let Some(line) = strongest_line(&x, noise.sigma_mm[d], noise.phi[d]) else {
                break;
            };
            if line.p_value >= TONE_ALPHA {
                break;
            }
            let f = refine_frequency(&x, line.frequency);
            let (c, s) = fit_sinusoid(&x, f);
            for (t, v) in out.iter_mut().enumerate() {
                let (sn, cs) = (std::f64::consts::TAU * f * t as f64).sin_cos();
                v[d] -= c * cs + s * sn;
            }
            found.push(Tone {
                direction: d,
                period_samples: 1.0 / f,
                amplitude_mm: c.hypot(s),
                p_value: line.p_value,
            });
        }
    }
    (out, found)
}

/// The largest line of a series against AR(1) noise of σ and φ.
struct Line {
    /// Cycles per sample.
    frequency: f64,
    /// `1 − (1 − e^{−q})^M`.
    p_value: f64,
}

/// The frequency (cycles per sample) of the largest `I(f)/S(f)` on the padded grid of the
/// searched band, and its p-value; `None` when the band is empty or the noise is degenerate.
fn strongest_line(x: &[f64], sigma: f64, phi: f64) -> Option<Line> {
    let n = x.len();
    let longest = LONGEST_PERIOD.min(n as f64 / 4.0);
    let (lo, hi) = (1.0 / longest, 1.0 / SHORTEST_PERIOD);
    if sigma.is_nan() || sigma <= 0.0 || lo >= hi {
        return None;
    }
    let mean = x.iter().sum::<f64>() / n as f64;
    // Hann window: the sidelobes of a large slow misfit fall as 1/Δf³ and do not reach the band.
    let w: Vec<f64> = (0..n)
        .map(|t| {
            let a = std::f64::consts::TAU * (t as f64 + 0.5) / n as f64;
            0.5 * (1.0 - a.cos())
        })
        .collect();
    let ww: f64 = w.iter().map(|v| v * v).sum();
    let xw: Vec<f64> = x.iter().zip(&w).map(|(v, w)| (v - mean) * w).collect();
    let step = 1.0 / (PAD * n as f64);
    let count = ((hi - lo) / step).floor() as usize + 1;
    let mut best = (0.0f64, lo);
    for k in 0..count {
        let f = lo + k as f64 * step;
        let (c, s) = transform(&xw, f);
        let spectrum = sigma * sigma * (1.0 - phi * phi)
            / (1.0 - 2.0 * phi * (std::f64::consts::TAU * f).cos() + phi * phi);
        let q = (c * c + s * s) / ww / spectrum;
        if q > best.0 {
            best = (q, f);
        }
    }
    let m = count as f64;
    // 1 − (1 − e^{−q})^M without cancellation.
    let p = -(m * (-(-best.0).exp()).ln_1p()).exp_m1();
    Some(Line {
        frequency: best.1,
        p_value: p.clamp(0.0, 1.0),
    })
}

/// `Σ x_t·cos 2πft` and `Σ x_t·sin 2πft`.
fn transform(x: &[f64], f: f64) -> (f64, f64) {
    let (mut c, mut s) = (0.0, 0.0);
    for (t, v) in x.iter().enumerate() {
        let (sn, cs) = (std::f64::consts::TAU * f * t as f64).sin_cos();
        c += v * cs;
        s += v * sn;
    }
    (c, s)
}

/// The least-squares coefficients `(c, s)` of `cos 2πft` and `sin 2πft` with an intercept.
fn fit_sinusoid(x: &[f64], f: f64) -> (f64, f64) {
    let n = x.len();
    let mut a = nalgebra::DMatrix::zeros(n, 3);
    for t in 0..n {
        let (sn, cs) = (std::f64::consts::TAU * f * t as f64).sin_cos();
        a[(t, 0)] = 1.0;
        a[(t, 1)] = cs;
        a[(t, 2)] = sn;
    }
    let b = nalgebra::DVector::from_column_slice(x);
    match a.svd(true, true).solve(&b, 1e-12) {
        Ok(beta) => (beta[1], beta[2]),
        Err(_) => (0.0, 0.0),
    }
}

/// What the sinusoid of frequency `f` (with an intercept) explains of `x`.
fn explained(x: &[f64], f: f64) -> f64 {
    let (c, s) = fit_sinusoid(x, f);
    x.iter()
        .enumerate()
        .map(|(t, _)| {
            let (sn, cs) = (std::f64::consts::TAU * f * t as f64).sin_cos();
            (c * cs + s * sn).powi(2)
        })
        .sum()
}

/// The frequency near `f` (within one step of the padded grid) at which a sinusoid explains
/// most of `x`: golden-section search.
fn refine_frequency(x: &[f64], f: f64) -> f64 {
    let half = 1.0 / (PAD * x.len() as f64);
    let (mut a, mut b) = (f - half, f + half);
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (explained(x, c), explained(x, d));
    for _ in 0..40 {
        if fc > fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = explained(x, c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = explained(x, d);
        }
    }
    (a + b) / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use simulation::rng::Rng;

    fn ar1(n: usize, sigma: f64, phi: f64, rng: &mut Rng) -> Vec<f64> {
        let innovation = sigma * (1.0 - phi * phi).sqrt();
        let mut prev = sigma * rng.normal();
        (0..n)
            .map(|_| {
                let v = prev;
                prev = phi * prev + innovation * rng.normal();
                v
            })
            .collect()
    }

    fn series(x: Vec<f64>, rng: &mut Rng) -> Vec<[f64; 3]> {
        x.into_iter()
            .map(|v| [v, 3e-4 * rng.normal(), 3e-4 * rng.normal()])
            .collect()
    }

    #[test]
    fn a_pump_in_white_noise_is_found_and_taken_out() {
        for seed in 1..=10 {
            let mut rng = Rng::new(seed);
            let period = 1.0 / 0.07;
            let x: Vec<f64> = ar1(241, 3e-4, 0.0, &mut rng)
                .into_iter()
                .enumerate()
                .map(|(t, v)| v + 5e-4 * (std::f64::consts::TAU * t as f64 / period + 0.3).sin())
                .collect();
            let r = series(x, &mut rng);
            let before = NoiseModel::estimate(&[&r]).unwrap();
            let (clean, tones) = without_tones(&r);
            let after = NoiseModel::estimate(&[&clean]).unwrap();
            let on_x: Vec<&Tone> = tones.iter().filter(|t| t.direction == 0).collect();
            assert_eq!(on_x.len(), 1, "seed {seed}: {tones:?}");
            assert!(
                (on_x[0].period_samples - period).abs() < 0.02 * period,
                "seed {seed}: {:?}",
                on_x[0]
            );
            assert!((on_x[0].amplitude_mm - 5e-4).abs() < 1e-4, "seed {seed}");
            // The noise estimate was inflated by the pump; without it, it is the noise's.
            assert!(before.sigma_mm[0] > 1.3 * 3e-4, "seed {seed}: {before:?}");
            assert!(
                (after.sigma_mm[0] - 3e-4).abs() < 0.6e-4,
                "seed {seed}: {after:?}"
            );
        }
    }

    #[test]
    fn correlated_noise_has_no_lines() {
        // 200 series of AR(1) noise at φ from 0 to 0.9: at a level of 1e-3 per direction, at
        // most a couple of false lines in the 600 directions.
        let mut false_lines = 0;
        for seed in 0..200u64 {
            let mut rng = Rng::new(1000 + seed);
            let phi = [0.0, 0.5, 0.8, 0.9][seed as usize % 4];
            let r: Vec<[f64; 3]> = {
                let a = ar1(241, 3e-4, phi, &mut rng);
                let b = ar1(241, 3e-4, phi, &mut rng);
                let c = ar1(241, 3e-4, phi, &mut rng);
                (0..241).map(|t| [a[t], b[t], c[t]]).collect()
            };
            false_lines += without_tones(&r).1.len();
        }
        assert!(
            false_lines <= 3,
            "{false_lines} false lines in 600 directions"
        );
    }

    #[test]
    fn a_large_slow_misfit_is_no_line() {
        // A 20 µm misfit twice per record (K4's ECC harmonic:2 seen in time) leaks no line into
        // the searched band through the Hann window.
        let mut found = 0;
        for seed in 1..=20 {
            let mut rng = Rng::new(seed);
            let x: Vec<f64> = ar1(241, 3e-4, 0.3, &mut rng)
                .into_iter()
                .enumerate()
                .map(|(t, v)| v + 2e-2 * (std::f64::consts::TAU * 2.0 * t as f64 / 241.0).cos())
                .collect();
            found += without_tones(&series(x, &mut rng)).1.len();
        }
        assert!(found <= 1, "{found} lines from a slow misfit");
    }

    #[test]
    fn short_series_are_left_alone() {
        let mut rng = Rng::new(3);
        let r = series(ar1(40, 3e-4, 0.0, &mut rng), &mut rng);
        let (clean, tones) = without_tones(&r);
        assert!(tones.is_empty());
        assert_eq!(clean, r);
    }
}
