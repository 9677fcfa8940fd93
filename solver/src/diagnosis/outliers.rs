//! Outliers: isolated readings far outside the residual's robust local scale.
//!
//! Per direction d of a residual series `r_i` (samples in record order):
//!
//! 1. the local deviation `e_i = r_i − median(r_{i−3} … r_{i+3})` (the window is cut at the
//!    ends): a smooth misfit of the model moves the median with it, a spike does not;
//! 2. the robust scale `s = 1.4826 · median |e_i − median e|` (the MAD, which a few spikes
//!    cannot inflate; 1.4826 makes it the standard deviation of Gaussian deviations);
//! 3. a reading is flagged when `|e_i| > THRESHOLD · s` and `|e_i| > FLOOR_MM` (the floor keeps
//!    rounding noise of noise-free data from being flagged);
//! 4. an **outlier** is a run of at most [`MAX_RUN`] consecutive flagged samples in one
//!    direction. A longer run is a deviation spanning many samples: structure, described as
//!    unexplained, not discarded.
//!
//! With Gaussian noise, `P(|z| > 6) ≈ 2e-9` per reading: on the 3 × 723 readings of K4, K1 and
//! K2 together, a false outlier turns up about once in 10⁵ diagnoses.

/// Flagging threshold, in robust local scales.
pub const THRESHOLD: f64 = 6.0;

/// The smallest local deviation flagged, mm (1 nm).
pub const FLOOR_MM: f64 = 1e-6;

/// The longest run of consecutive flagged samples counted as outliers.
pub const MAX_RUN: usize = 2;

/// Half-width of the running median, samples.
const HALF_WINDOW: usize = 3;

/// One isolated reading far outside the residual's scale.
#[derive(Clone, Debug, PartialEq)]
pub struct Outlier {
    /// The sample's index in its record (0-based).
    pub sample: usize,
    /// The 1-based line of the record's file it was read from; `None` when the record was not
    /// read from a file.
    pub line: Option<usize>,
    /// 0, 1, 2 for x, y, z.
    pub direction: usize,
    /// The residual at that reading, mm.
    pub residual_mm: f64,
    /// Its deviation from the running median, mm.
    pub deviation_mm: f64,
    /// The threshold it exceeded (`THRESHOLD` robust scales), mm.
    pub threshold_mm: f64,
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        0.0
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// The local deviations `e_i` of one series from its running median.
fn deviations(r: &[f64]) -> Vec<f64> {
    (0..r.len())
        .map(|i| {
            let lo = i.saturating_sub(HALF_WINDOW);
            let hi = (i + HALF_WINDOW + 1).min(r.len());
            let mut w = r[lo..hi].to_vec();
            r[i] - median(&mut w)
        })
        .collect()
}

/// The outliers of a residual (`residual[i][d]`, mm, one row per sample in record order),
/// by sample, then direction.
pub fn find(residual: &[[f64; 3]]) -> Vec<Outlier> {
    let mut out = Vec::new();
    for d in 0..3 {
        let r: Vec<f64> = residual.iter().map(|v| v[d]).collect();
        let e = deviations(&r);
        let mut centred = e.clone();
        let mid = median(&mut centred);
        let mut abs: Vec<f64> = e.iter().map(|v| (v - mid).abs()).collect();
        let scale = 1.4826 * median(&mut abs);
        let threshold = THRESHOLD * scale;
        let flagged: Vec<bool> = e
            .iter()
            .map(|v| v.abs() > threshold && v.abs() > FLOOR_MM)
            .collect();
        let mut i = 0;
        while i < flagged.len() {
            if !flagged[i] {
                i += 1;
                continue;
            }
            let start = i;
            while i < flagged.len() && flagged[i] {
                i += 1;
            }
            if i - start <= MAX_RUN {
                out.extend((start..i).map(|s| Outlier {
                    sample: s,
                    line: None,
                    direction: d,
                    residual_mm: r[s],
                    deviation_mm: e[s],
                    threshold_mm: threshold,
                }));
            }
        }
    }
    out.sort_by_key(|o| (o.sample, o.direction));
    out
}

/// The outliers of the residual of `record` (as [`find`]), with the lines of its file.
pub fn find_in(record: &crate::record::Record, residual: &[[f64; 3]]) -> Vec<Outlier> {
    let mut out = find(residual);
    for o in &mut out {
        o.line = record.lines.get(o.sample).copied();
    }
    out
}

/// The samples with at least one outlying reading, ascending, each once.
pub fn samples(outliers: &[Outlier]) -> Vec<usize> {
    let mut s: Vec<usize> = outliers.iter().map(|o| o.sample).collect();
    s.dedup();
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulation::rng::Rng;

    fn noisy(n: usize, seed: u64) -> Vec<[f64; 3]> {
        let mut rng = Rng::new(seed);
        (0..n)
            .map(|i| {
                // A smooth misfit of 3 µm once over the record, and 0.5 µm noise.
                let s = 3e-3 * (i as f64 / n as f64 * std::f64::consts::TAU).sin();
                [
                    s + 5e-4 * rng.normal(),
                    5e-4 * rng.normal(),
                    -s + 5e-4 * rng.normal(),
                ]
            })
            .collect()
    }

    #[test]
    fn spikes_are_found_and_smooth_misfit_is_not() {
        for seed in 1..=20 {
            let mut r = noisy(241, seed);
            assert_eq!(find(&r), vec![], "seed {seed}: nothing on clean data");
            for (k, &i) in [10usize, 60, 61, 150, 240].iter().enumerate() {
                r[i][k % 3] += if k % 2 == 0 { 0.02 } else { -0.02 };
            }
            let o = find(&r);
            let got: Vec<(usize, usize)> = o.iter().map(|o| (o.sample, o.direction)).collect();
            assert_eq!(
                got,
                vec![(10, 0), (60, 1), (61, 2), (150, 0), (240, 1)],
                "seed {seed}"
            );
            assert_eq!(samples(&o), vec![10, 60, 61, 150, 240]);
        }
    }

    #[test]
    fn a_long_deviation_is_structure_not_outliers() {
        let mut r = noisy(241, 3);
        for v in r.iter_mut().skip(100).take(5) {
            v[2] += 0.02;
        }
        assert_eq!(find(&r), vec![]);
    }

    #[test]
    fn noise_free_data_has_no_outliers() {
        let r: Vec<[f64; 3]> = (0..100).map(|i| [1e-12 * i as f64, 0.0, -1e-13]).collect();
        assert_eq!(find(&r), vec![]);
    }
}
