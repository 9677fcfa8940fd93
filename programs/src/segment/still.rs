//! Where the readings of a log are still: the log binned in time, a sliding variance over the
//! bins, and the still periods where it stays below a limit.
//!
//! The log is first reduced to bins of `h` seconds holding, per reading column, the count,
//! the sum and the sum of squares of the readings (relative to the first reading, so that the
//! sums do not lose the small variations to a large offset). A bin's **stillness** is the mean
//! over the columns of the variance of the readings within a sliding window of `2r + 1` bins
//! centred on it. The **limit** is given, or derived from the noise: the variance per column
//! at the quiet end of the log, `σ̂²` = the `q`-quantile of the bins' stillness (`q` half the
//! share of the plan's time spent at rest, at most 0.2), times a factor for the scatter of a
//! variance estimated from `N` readings (`1 + 5·√(2/N)`), and at least
//! [`STILL_FLOOR_MM`]². A **still period** is a run of bins at or below the limit, widened by
//! `r` bins on each side (every window in the run is still, so their union is), and clipped to
//! the log.

/// The smallest stillness limit, mm (0.05 µm, the standard deviation of one reading): readings
/// that vary less than this are still, however quiet the log.
pub const STILL_FLOOR_MM: f64 = 5e-5;

/// The most bins held: beyond it, pairs of bins are merged (the bin width doubles).
const MAX_BINS: usize = 1 << 20;

/// The binned log: per bin the count and, per reading column, the sum and the sum of squares
/// of the readings minus the first reading.
pub(crate) struct Bins {
    /// Bin width, s.
    pub(crate) h: f64,
    k: usize,
    count: Vec<u32>,
    sum: Vec<f64>,
    square: Vec<f64>,
    reference: Vec<f64>,
}

impl Bins {
    /// Empty bins of width `h` (s) for `k` reading columns.
    pub(crate) fn new(h: f64, k: usize) -> Bins {
        Bins {
            h,
            k,
            count: Vec::new(),
            sum: Vec::new(),
            square: Vec::new(),
            reference: Vec::new(),
        }
    }

    /// Adds the readings `r` (mm) at `t` seconds after the first row (`t ≥ 0`).
    pub(crate) fn add(&mut self, t: f64, r: &[f64]) {
        if self.reference.is_empty() {
            self.reference = r.to_vec();
        }
        let mut b = (t / self.h) as usize;
        while b >= MAX_BINS {
            self.merge_pairs();
            b = (t / self.h) as usize;
        }
        if b >= self.count.len() {
            self.count.resize(b + 1, 0);
            self.sum.resize((b + 1) * self.k, 0.0);
            self.square.resize((b + 1) * self.k, 0.0);
        }
        self.count[b] += 1;
        for (c, (&x, &x0)) in r.iter().zip(&self.reference).enumerate() {
            let d = x - x0;
            self.sum[b * self.k + c] += d;
            self.square[b * self.k + c] += d * d;
        }
    }

    /// Merges bins two by two: the width doubles.
    fn merge_pairs(&mut self) {
        let n = self.count.len().div_ceil(2);
        for b in 0..n {
            let (i, j) = (2 * b, 2 * b + 1);
            let cj = self.count.get(j).copied().unwrap_or(0);
            self.count[b] = self.count[i] + cj;
            for c in 0..self.k {
                let sj = if j < self.count.len() {
                    self.sum[j * self.k + c]
                } else {
                    0.0
                };
                let qj = if j < self.count.len() {
                    self.square[j * self.k + c]
                } else {
                    0.0
                };
                self.sum[b * self.k + c] = self.sum[i * self.k + c] + sj;
                self.square[b * self.k + c] = self.square[i * self.k + c] + qj;
            }
        }
        self.count.truncate(n);
        self.sum.truncate(n * self.k);
        self.square.truncate(n * self.k);
        self.h *= 2.0;
    }

    /// The number of bins.
    pub(crate) fn len(&self) -> usize {
        self.count.len()
    }
}

/// A still period of the log, s after its first row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct StillPeriod {
    pub(crate) lo: f64,
    pub(crate) hi: f64,
    /// It starts with the log: its start is not an arrival.
    pub(crate) open_lo: bool,
    /// It ends with the log: its end is not a departure.
    pub(crate) open_hi: bool,
}

/// The still periods of a log, and the limit they were found with.
pub(crate) struct Stillness {
    pub(crate) periods: Vec<StillPeriod>,
    /// The limit of the stillness (mean variance per column over the sliding window), mm².
    pub(crate) limit_mm2: f64,
    /// The estimated noise per column (standard deviation of one reading at rest), mm.
    pub(crate) noise_mm: f64,
}

/// The still periods of `bins` (of a log of `span` s after its first row) with a sliding
/// window of `2r + 1` bins holding about `per_window` readings; the limit is `limit_mm` (the
/// standard deviation per column, mm) when given, else derived with the quantile `q` (see the
/// module documentation).
pub(crate) fn still_periods(
    bins: &Bins,
    span: f64,
    r: usize,
    per_window: f64,
    limit_mm: Option<f64>,
    q: f64,
) -> Stillness {
    let n = bins.len();
    let k = bins.k;
    let mut stillness = vec![f64::NAN; n];
    let (mut count, mut sum, mut square) = (0u64, vec![0.0; k], vec![0.0; k]);
    let add = |b: usize, sign: f64, count: &mut u64, sum: &mut [f64], square: &mut [f64]| {
        if sign > 0.0 {
            *count += u64::from(bins.count[b]);
        } else {
            *count -= u64::from(bins.count[b]);
        }
        for c in 0..k {
            sum[c] += sign * bins.sum[b * k + c];
            square[c] += sign * bins.square[b * k + c];
        }
    };
    // The window of bin b is [b − r, b + r]: bins enter at b + r and leave after b − r.
    for b in 0..r.min(n) {
        add(b, 1.0, &mut count, &mut sum, &mut square);
    }
    for (b, slot) in stillness.iter_mut().enumerate() {
        if b + r < n {
            add(b + r, 1.0, &mut count, &mut sum, &mut square);
        }
        if b > r {
            add(b - r - 1, -1.0, &mut count, &mut sum, &mut square);
        }
        if count >= 3 {
            let c = count as f64;
            let v: f64 = (0..k)
                .map(|j| ((square[j] - sum[j] * sum[j] / c) / c).max(0.0))
                .sum::<f64>()
                / k as f64;
            *slot = v;
        }
    }
    let mut sorted: Vec<f64> = stillness
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .collect();
    sorted.sort_by(f64::total_cmp);
    let quiet = sorted
        .get(((sorted.len() as f64 * q) as usize).min(sorted.len().saturating_sub(1)))
        .copied()
        .unwrap_or(0.0);
    let limit_mm2 = match limit_mm {
        Some(l) => l * l,
        None => {
            let scatter = 1.0 + 5.0 * (2.0 / per_window.max(3.0)).sqrt();
            (scatter * quiet).max(STILL_FLOOR_MM * STILL_FLOOR_MM)
        }
    };
    let mut periods = Vec::new();
    let mut b = 0;
    while b < n {
        if stillness[b].is_nan() || stillness[b] > limit_mm2 {
            b += 1;
            continue;
        }
        let first = b;
        while b < n && stillness[b] <= limit_mm2 {
            b += 1;
        }
        let lo_bin = first as f64 - r as f64;
        let hi_bin = (b + r) as f64;
        let (lo, hi) = ((lo_bin * bins.h).max(0.0), (hi_bin * bins.h).min(span));
        periods.push(StillPeriod {
            lo,
            hi,
            open_lo: lo_bin * bins.h <= 0.0,
            open_hi: hi_bin * bins.h >= span,
        });
    }
    // Widening may make neighbours touch: merge them.
    let mut merged: Vec<StillPeriod> = Vec::with_capacity(periods.len());
    for p in periods {
        match merged.last_mut() {
            Some(last) if p.lo <= last.hi => {
                last.hi = last.hi.max(p.hi);
                last.open_hi = p.open_hi;
            }
            _ => merged.push(p),
        }
    }
    Stillness {
        periods: merged,
        limit_mm2,
        noise_mm: quiet.sqrt(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_splits_the_still_periods() {
        // 10 s at 100 Hz: still, a ramp of 1 s, still.
        let mut bins = Bins::new(0.05, 1);
        for i in 0..1000 {
            let t = i as f64 * 0.01;
            let x = if t < 4.0 {
                0.0
            } else if t < 5.0 {
                (t - 4.0) * 0.01
            } else {
                0.01
            };
            bins.add(t, &[x]);
        }
        let s = still_periods(&bins, 9.99, 2, 50.0, None, 0.2);
        assert_eq!(s.periods.len(), 2, "{:?}", s.periods);
        let (a, b) = (s.periods[0], s.periods[1]);
        assert!(a.open_lo && !a.open_hi && !b.open_lo && b.open_hi);
        assert!(
            (a.hi - 4.0).abs() < 0.11 && (b.lo - 5.0).abs() < 0.11,
            "{a:?} {b:?}"
        );
    }

    #[test]
    fn merged_bins_keep_their_sums() {
        let mut bins = Bins::new(1e-3, 1);
        bins.add(0.0, &[1.0]);
        bins.add((MAX_BINS as f64 + 10.0) * 1e-3, &[3.0]);
        assert!(bins.len() <= MAX_BINS && bins.h >= 2e-3);
        assert_eq!(bins.count.iter().map(|&c| c as usize).sum::<usize>(), 2);
        assert_eq!(bins.sum.iter().sum::<f64>(), 2.0);
    }
}
