//! The second pass over the log: the readings within each measuring window averaged (static),
//! or interpolated at each instant (continuous), and the windows that look wrong flagged.

use crate::measure::TimingPlan;
use crate::segment::align::{Alignment, Anchor};
use crate::segment::log::{LogClock, LogReader};
use crate::segment::still::{STILL_FLOOR_MM, StillPeriod};
use crate::segment::{SegmentError, SegmentOptions};
use formats::csv::CsvError;
use model_spec::units::short;
use std::io::Read;

/// Why a window is flagged (the sample is kept; the engineer decides).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WindowFlag {
    /// Its readings scatter far more than the other windows': more than four times the median
    /// spread.
    Spread,
    /// Its still period did not cover the planned window: the machine was still moving, or
    /// already moving, during more than a tenth of it; the window was shortened.
    Motion,
}

impl WindowFlag {
    /// `spread` or `motion`.
    pub fn name(self) -> &'static str {
        match self {
            WindowFlag::Spread => "spread",
            WindowFlag::Motion => "motion",
        }
    }
}

/// One pose's sample cut from the log.
#[derive(Clone, Debug, PartialEq)]
pub struct Window {
    /// The pose's number in the plan, 1-based.
    pub sample: usize,
    /// The readings averaged: from this log time (s, s after the log's first row) …
    pub log_start_s: f64,
    /// … to this one; equal to `log_start_s` for an instant of a continuous plan.
    pub log_end_s: f64,
    /// The number of log rows averaged (2 for an interpolated instant).
    pub readings: usize,
    /// The sample's time on the program clock: the window's middle, or the instant, minus the
    /// program's start in the log, s.
    pub t_s: f64,
    /// This pose's offset minus the program start's: how far the machine's timing has drifted
    /// from the plan by this pose, s (continuous: the instant found minus the planned one).
    pub shift_s: f64,
    /// How the pose was placed.
    pub anchor: Anchor,
    /// The mean of each reading column, mm.
    pub mean_mm: Vec<f64>,
    /// The standard deviation of each reading column within the window, mm (0 for an
    /// instant).
    pub sd_mm: Vec<f64>,
    /// Why the window looks wrong, if it does.
    pub flags: Vec<WindowFlag>,
}

/// Where a static window is cut, s after the log's first row.
pub(crate) struct Cut {
    pub(crate) lo: f64,
    pub(crate) hi: f64,
    pub(crate) clipped: bool,
    /// The window before it was clipped to its still period.
    pub(crate) planned: (f64, f64),
}

/// The cut of every pose of a static plan: its planned window moved by its offset, less
/// `margin(i)` at each end, within its still period.
pub(crate) fn static_cuts(
    plan: &TimingPlan,
    al: &Alignment,
    periods: &[StillPeriod],
    margin: &dyn Fn(usize) -> f64,
) -> Vec<Cut> {
    plan.rows
        .iter()
        .zip(&al.placed)
        .enumerate()
        .map(|(i, (r, p))| {
            let (lo, hi) = (
                r.start_s + p.offset + margin(i),
                r.end_s + p.offset - margin(i),
            );
            let (clo, chi) = match p.period {
                Some(j) => (lo.max(periods[j].lo), hi.min(periods[j].hi)),
                None => (lo, hi),
            };
            Cut {
                lo: clo,
                hi: chi,
                clipped: chi - clo < 0.9 * (hi - lo),
                planned: (lo, hi),
            }
        })
        .collect()
}

/// Sums of the readings of one window: relative to its first reading.
struct Sums {
    n: usize,
    first: Vec<f64>,
    sum: Vec<f64>,
    square: Vec<f64>,
}

/// The readings of one window, averaged.
pub(crate) struct Averaged {
    /// Log rows averaged.
    pub(crate) n: usize,
    /// Per reading column, mm.
    pub(crate) mean: Vec<f64>,
    /// Per reading column, the sample standard deviation, mm (0 below two rows).
    pub(crate) sd: Vec<f64>,
    /// The first and the last row's times, s after the log's first row (NaN without a row).
    pub(crate) first: f64,
    pub(crate) last: f64,
}

/// The readings of the log `reader` averaged within each of `cuts` (in time order, disjoint).
pub(crate) fn average<R: Read>(
    reader: &mut LogReader<'_, R>,
    cuts: &[Cut],
    k: usize,
) -> Result<Vec<Averaged>, CsvError> {
    let mut sums: Vec<Sums> = cuts
        .iter()
        .map(|_| Sums {
            n: 0,
            first: vec![0.0; k],
            sum: vec![0.0; k],
            square: vec![0.0; k],
        })
        .collect();
    let mut span: Vec<(f64, f64)> = vec![(f64::NAN, f64::NAN); cuts.len()];
    let mut r = vec![0.0; k];
    let mut w = 0;
    while let Some((_, t)) = reader.next_row(&mut r)? {
        while w < cuts.len() && t > cuts[w].hi {
            w += 1;
        }
        if w == cuts.len() {
            // The rest of the log is not needed, but it is read to the end so that a malformed
            // row anywhere is an error, as in the first pass.
            continue;
        }
        if t >= cuts[w].lo {
            let s = &mut sums[w];
            if s.n == 0 {
                s.first.copy_from_slice(&r);
                span[w].0 = t;
            }
            s.n += 1;
            span[w].1 = t;
            for (c, (&x, &x0)) in r.iter().zip(&s.first).enumerate() {
                let d = x - x0;
                s.sum[c] += d;
                s.square[c] += d * d;
            }
        }
    }
    Ok(sums
        .into_iter()
        .zip(span)
        .map(|(s, (a, b))| {
            let n = s.n as f64;
            let mean: Vec<f64> = (0..k).map(|c| s.first[c] + s.sum[c] / n.max(1.0)).collect();
            let sd: Vec<f64> = (0..k)
                .map(|c| {
                    if s.n < 2 {
                        0.0
                    } else {
                        ((s.square[c] - s.sum[c] * s.sum[c] / n) / (n - 1.0))
                            .max(0.0)
                            .sqrt()
                    }
                })
                .collect();
            Averaged {
                n: s.n,
                mean,
                sd,
                first: a,
                last: b,
            }
        })
        .collect())
}

/// The readings interpolated at each instant (one vector per instant, mm), or the first
/// instant that cannot be read and why.
pub(crate) type Interpolated = Result<Vec<Vec<f64>>, (usize, String)>;

/// The readings of the log `reader` interpolated linearly at each of `instants` (s after the
/// first row, non-decreasing), between the two rows around it; no more than `max_gap` s apart.
/// `Err` with the instant's index and why, for an instant outside the log or in a gap.
pub(crate) fn interpolate<R: Read>(
    reader: &mut LogReader<'_, R>,
    instants: &[f64],
    k: usize,
    max_gap: f64,
) -> Result<Interpolated, CsvError> {
    let mut out: Vec<Vec<f64>> = Vec::with_capacity(instants.len());
    let mut previous: Option<(f64, Vec<f64>)> = None;
    let mut r = vec![0.0; k];
    let mut failure: Option<(usize, String)> = None;
    while let Some((_, t)) = reader.next_row(&mut r)? {
        while failure.is_none() && out.len() < instants.len() && instants[out.len()] <= t {
            let at = instants[out.len()];
            match &previous {
                _ if at == t => out.push(r.clone()),
                Some((t0, r0)) if t - t0 <= max_gap => {
                    let u = (at - t0) / (t - t0);
                    out.push(r0.iter().zip(&r).map(|(a, b)| a + u * (b - a)).collect());
                }
                Some((t0, _)) => {
                    failure = Some((
                        out.len(),
                        format!(
                            "the log has a gap of {} s there (rows at {t0} and {t} s after its first)",
                            t - t0
                        ),
                    ));
                }
                None => {
                    failure = Some((out.len(), "it is before the log's first row".into()));
                }
            }
        }
        previous = Some((t, r.clone()));
    }
    if let Some(f) = failure {
        return Ok(Err(f));
    }
    if out.len() < instants.len() {
        return Ok(Err((
            out.len(),
            "it is after the log's last row: the log is shorter than the program".into(),
        )));
    }
    Ok(Ok(out))
}

/// Flags the windows of a static plan whose spread is more than four times the median spread
/// (and above the stillness floor), and those cut short by motion.
pub(crate) fn flag(windows: &mut [Window], clipped: &[bool]) {
    let spread = |w: &Window| {
        (w.sd_mm.iter().map(|s| s * s).sum::<f64>() / w.sd_mm.len().max(1) as f64).sqrt()
    };
    let mut all: Vec<f64> = windows.iter().map(spread).collect();
    all.sort_by(f64::total_cmp);
    let median = all.get(all.len() / 2).copied().unwrap_or(0.0);
    let limit = 4.0 * median.max(STILL_FLOOR_MM);
    for (w, &c) in windows.iter_mut().zip(clipped) {
        if spread(w) > limit {
            w.flags.push(WindowFlag::Spread);
        }
        if c {
            w.flags.push(WindowFlag::Motion);
        }
    }
}

#[allow(clippy::too_many_arguments)]
/// The samples of a static plan: the windows cut (see [`static_cuts`]), averaged, checked for
/// their number of rows, flagged.
pub(crate) fn static_windows<R: Read>(
    file: &str,
    reader: &mut LogReader<'_, R>,
    plan: &TimingPlan,
    al: &Alignment,
    periods: &[StillPeriod],
    opts: &SegmentOptions,
    clock: &LogClock,
    k: usize,
) -> Result<Vec<Window>, SegmentError> {
    let margin = |i: usize| {
        opts.margin_s
            .unwrap_or(0.1 * (plan.rows[i].end_s - plan.rows[i].start_s))
    };
    let cuts = static_cuts(plan, al, periods, &margin);
    for (i, w) in cuts.windows(2).enumerate() {
        if w[1].lo < w[0].hi {
            return Err(SegmentError::Window {
                file: file.into(),
                sample: i + 2,
                message: format!(
                    "its window ({} .. {} s, log clock) overlaps the one before ({} .. {} s): the offset given or found does not fit the log",
                    short(clock.log_time(w[1].lo)),
                    short(clock.log_time(w[1].hi)),
                    short(clock.log_time(w[0].lo)),
                    short(clock.log_time(w[0].hi))
                ),
            });
        }
    }
    let sums = average(reader, &cuts, k)?;
    let min = if opts.min_readings == 0 {
        5
    } else {
        opts.min_readings
    };
    let mut out = Vec::with_capacity(cuts.len());
    for (i, (a, cut)) in sums.into_iter().zip(&cuts).enumerate() {
        let n = a.n;
        if n < min {
            let (lo, hi) = cut.planned;
            let message = if cut.hi <= cut.lo {
                format!(
                    "its window {} .. {} s (log clock) lies outside the still period it was placed in: the log has a gap there, or the machine moved",
                    short(clock.log_time(lo)),
                    short(clock.log_time(hi))
                )
            } else {
                format!(
                    "{n} log row(s) in its window {} .. {} s (log clock), fewer than {min}: the log is too sparse there, or has a gap",
                    short(clock.log_time(cut.lo)),
                    short(clock.log_time(cut.hi))
                )
            };
            return Err(SegmentError::Window {
                file: file.into(),
                sample: i + 1,
                message,
            });
        }
        out.push(Window {
            sample: i + 1,
            log_start_s: clock.log_time(a.first),
            log_end_s: clock.log_time(a.last),
            readings: n,
            t_s: 0.5 * (a.first + a.last) - al.offset,
            shift_s: al.placed[i].offset - al.offset,
            anchor: al.placed[i].anchor,
            mean_mm: a.mean,
            sd_mm: a.sd,
            flags: Vec::new(),
        });
    }
    let clipped: Vec<bool> = cuts.iter().map(|c| c.clipped).collect();
    flag(&mut out, &clipped);
    Ok(out)
}

/// The samples of a continuous plan: the readings at each pose's instant, mapped between the
/// run's two ends.
pub(crate) fn continuous_windows<R: Read>(
    file: &str,
    reader: &mut LogReader<'_, R>,
    plan: &TimingPlan,
    al: &Alignment,
    period: f64,
    clock: &LogClock,
    k: usize,
) -> Result<Vec<Window>, SegmentError> {
    let d0 = plan.rows[0].depart_s;
    let instants: Vec<f64> = plan
        .rows
        .iter()
        .map(|r| al.offset + d0 + al.scale * (r.start_s - d0))
        .collect();
    let values = interpolate(reader, &instants, k, 5.0 * period)?.map_err(|(i, why)| {
        SegmentError::Window {
            file: file.into(),
            sample: i + 1,
            message: format!(
                "its instant {} s (log clock) cannot be read: {why}",
                short(clock.log_time(instants[i]))
            ),
        }
    })?;
    Ok(values
        .into_iter()
        .zip(&instants)
        .zip(&plan.rows)
        .enumerate()
        .map(|(i, ((mean, &at), row))| Window {
            sample: i + 1,
            log_start_s: clock.log_time(at),
            log_end_s: clock.log_time(at),
            readings: 2,
            t_s: at - al.offset,
            shift_s: at - al.offset - row.start_s,
            anchor: al.placed[i].anchor,
            mean_mm: mean,
            sd_mm: vec![0.0; k],
            flags: Vec::new(),
        })
        .collect())
}
