//! Cutting a time-stamped R-test log into one sample per pose of a measurement program's
//! timing plan (`docs/measurement-programs.md`).
//!
//! The R-test streams its readings while the machine runs the program; the log's clock is not
//! the program's, and it usually starts earlier. [`segment_file`] finds the program in the log
//! and averages each pose's measuring window:
//!
//! 1. **First pass**: the log ([`log`]: `t_s` or `t_abs_s`, and the reading columns `…_um`) is
//!    read row by row into time bins, and the **still periods** of the readings are found
//!    ([`still`]);
//! 2. **Alignment** ([`align`]): the plan's rests are matched with the still periods, each pose
//!    tracked from the one before, so that a machine whose timing drifts from the plan is
//!    followed; an ambiguous or poor match is refused ([`SegmentOptions::offset_s`] gives the
//!    program's start instead);
//! 3. **Second pass** ([`windows`]): the log is read again and each window, less a margin at
//!    each end and within its still period, is averaged (static plans), or the readings are
//!    interpolated at each instant (continuous plans). Windows whose readings scatter far more
//!    than the others', or that the machine's motion cut short, are flagged.
//!
//! The log is never held: memory is the bins (at most 2²⁰) and the windows. It is read twice,
//! so it must be a file (not a pipe).
//!
//! The result ([`Segmented`]) is written as a measurement record ([`format_segmented`]): the
//! plan's axis columns, the averaged reading columns under their names, and `t_s`, the
//! window's middle on the program clock as the log measured it. With the reading columns
//! `dx_um,dy_um,dz_um` it is what `identify` reads.

pub mod align;
pub mod log;
pub mod still;
pub mod windows;
mod write;

use crate::measure::{PlanKind, TimingPlan};
pub use align::Anchor;
use align::{align_continuous, align_static};
use formats::csv::CsvError;
pub use log::LogClock;
use log::LogReader;
use model_spec::units::significant;
use std::io::Read;
use std::path::Path;
use still::{Bins, still_periods};
pub use windows::{Window, WindowFlag};
use windows::{continuous_windows, static_windows};
pub use write::{format_segmented, format_windows};

/// How a log is cut. `SegmentOptions::default()` finds everything from the data.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SegmentOptions {
    /// The program's start (`t = 0` of the plan) on the log's clock, s (Unix seconds for a
    /// `t_abs_s` log): given, the first pose is not searched for (the others are still tracked).
    pub offset_s: Option<f64>,
    /// Dropped at each end of each measuring window, s. Default a tenth of the window.
    pub margin_s: Option<f64>,
    /// The stillness limit: the standard deviation of the readings per column over a short
    /// sliding window, mm. Default from the log's noise (see [`still`]).
    pub still_mm: Option<f64>,
    /// How far an edge of a still period may be from where the plan, tracked from the pose
    /// before, puts it, s. Default 0.3 × the shortest time from one departure to the next
    /// (static), or the larger of 0.3 × the lead-in and a quarter of the run (continuous).
    pub tolerance_s: Option<f64>,
    /// The fewest log rows a window may average; default (0) 5.
    pub min_readings: usize,
}

/// A log cut into one sample per pose of a plan.
#[derive(Clone, Debug, PartialEq)]
pub struct Segmented {
    /// Static or continuous, as the plan.
    pub kind: PlanKind,
    /// The reading columns, as the log names them, in its order.
    pub columns: Vec<String>,
    /// The log's other columns, not read.
    pub ignored: Vec<String>,
    /// The log's clock (its time column and first time).
    pub clock: LogClock,
    /// The log's rows.
    pub rows: usize,
    /// From the log's first row to its last, s.
    pub span_s: f64,
    /// The program's start (`t = 0`) on the log's clock, s (Unix seconds for `t_abs_s`).
    pub start_s: f64,
    /// `true` when the start was given, not found.
    pub start_given: bool,
    /// Continuous plans: the run time found over the planned one; 1 for static plans.
    pub time_scale: f64,
    /// Poses placed at an edge of their still period (see [`Anchor`]).
    pub anchored: usize,
    /// The best other placement: its program start on the log's clock (s) and its anchored
    /// poses.
    pub runner_up: Option<(f64, usize)>,
    /// The still periods found.
    pub still_periods: usize,
    /// The stillness limit used, as a standard deviation per column, mm.
    pub still_limit_mm: f64,
    /// The noise of one reading at rest estimated from the log, per column, mm.
    pub noise_mm: f64,
    /// One per pose of the plan, in its order.
    pub windows: Vec<Window>,
}

/// Why a log could not be cut.
#[derive(Debug, thiserror::Error)]
pub enum SegmentError {
    /// The log or the plan is malformed (file, line, column).
    #[error(transparent)]
    Csv(#[from] CsvError),
    /// The program was not found in the log, or not unambiguously.
    #[error("{file}: {message}")]
    Alignment {
        /// The log.
        file: String,
        /// Why.
        message: String,
    },
    /// A pose whose sample cannot be taken: too few readings in its window, an instant outside
    /// the log or in a gap.
    #[error("{file}: sample {sample}: {message}")]
    Window {
        /// The log.
        file: String,
        /// The pose, 1-based.
        sample: usize,
        /// Why, with the times.
        message: String,
    },
    /// An option out of range, or a plan that is not consistent.
    #[error("{0}")]
    Options(String),
}

/// Cuts the log file `path` by `plan` (see the module documentation).
///
/// # Errors
/// [`SegmentError::Csv`] for a log that cannot be read or is malformed (a path that is not a
/// regular file included: it is read twice); see [`segment`].
pub fn segment_file(
    path: &Path,
    plan: &TimingPlan,
    opts: &SegmentOptions,
) -> Result<Segmented, SegmentError> {
    let file = path.display().to_string();
    let io = |source| CsvError::Io {
        file: file.clone(),
        source,
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(SegmentError::Csv(io(std::io::Error::other(
            "not a regular file: a log is read twice, so it cannot be a pipe or a device",
        ))));
    }
    segment(&file, &mut || std::fs::File::open(path), plan, opts)
}

/// Cuts the log text `text` (named `file` in messages) by `plan`; see [`segment`].
///
/// # Errors
/// As [`segment`].
pub fn segment_text(
    file: &str,
    text: &str,
    plan: &TimingPlan,
    opts: &SegmentOptions,
) -> Result<Segmented, SegmentError> {
    segment(file, &mut || Ok(text.as_bytes()), plan, opts)
}

/// Cuts the log that `open` gives (twice; named `file` in messages) by `plan`.
///
/// # Errors
/// [`SegmentError::Options`] for options out of range or a plan that does not pass
/// [`TimingPlan::check`]; [`SegmentError::Csv`] for a malformed log (naming the line and
/// column) or one with fewer than two rows; [`SegmentError::Alignment`] when the program is not
/// found in the log, or ambiguously, or poses are missing (the log shorter than the program, a
/// gap, no still period where a rest should be); [`SegmentError::Window`] for a window with
/// fewer than [`SegmentOptions::min_readings`] rows, or an instant outside the log or in a gap.
pub fn segment<R: Read>(
    file: &str,
    open: &mut dyn FnMut() -> std::io::Result<R>,
    plan: &TimingPlan,
    opts: &SegmentOptions,
) -> Result<Segmented, SegmentError> {
    plan.check()
        .map_err(|(i, why)| SegmentError::Options(format!("the plan's row {}: {why}", i + 1)))?;
    let shape = Shape::of(plan, opts)?;
    let io = |source| CsvError::Io {
        file: file.to_string(),
        source,
    };
    // First pass: the bins.
    let mut reader = LogReader::open(file, open().map_err(io)?)?;
    let k = reader.header.reading_names().len();
    let mut bins = Bins::new(shape.bin_s, k);
    let mut r = vec![0.0; k];
    let (mut rows, mut span) = (0usize, 0.0);
    while let Some((_, t)) = reader.next_row(&mut r)? {
        bins.add(t, &r);
        rows += 1;
        span = t;
    }
    let Some(clock) = reader.clock().filter(|_| rows >= 2) else {
        return Err(SegmentError::Alignment {
            file: file.into(),
            message: format!("{rows} row(s): a log needs at least two"),
        });
    };
    let period = span / (rows - 1) as f64;
    let r_bins = ((shape.sliding_s / (2.0 * bins.h)).round() as usize)
        .max((2.0 * period / bins.h).ceil() as usize)
        .max(1);
    let per_window = (2 * r_bins + 1) as f64 * bins.h / period;
    let still = still_periods(
        &bins,
        span,
        r_bins,
        per_window,
        opts.still_mm,
        shape.quantile,
    );
    let tol = opts
        .tolerance_s
        .unwrap_or(shape.tolerance_s)
        .max(2.0 * bins.h);
    let given = opts.offset_s.map(|g| clock.relative(g));
    let al = match plan.kind {
        PlanKind::Static => align_static(plan, &still.periods, span, tol, given, &clock),
        PlanKind::Continuous => align_continuous(plan, &still.periods, span, tol, given, &clock),
    }
    .map_err(|message| SegmentError::Alignment {
        file: file.into(),
        message,
    })?;
    // Second pass: the samples.
    let mut reader = LogReader::open(file, open().map_err(io)?)?;
    let windows = match plan.kind {
        PlanKind::Static => static_windows(
            file,
            &mut reader,
            plan,
            &al,
            &still.periods,
            opts,
            &clock,
            k,
        )?,
        PlanKind::Continuous => {
            continuous_windows(file, &mut reader, plan, &al, period, &clock, k)?
        }
    };
    Ok(Segmented {
        kind: plan.kind,
        columns: reader.header.reading_names(),
        ignored: reader.header.ignored_names(),
        clock,
        rows,
        span_s: span,
        start_s: clock.log_time(al.offset),
        start_given: given.is_some(),
        time_scale: al.scale,
        anchored: al.anchored,
        runner_up: al.runner_up.map(|(o, n)| (clock.log_time(o), n)),
        still_periods: still.periods.len(),
        still_limit_mm: still.limit_mm2.sqrt(),
        noise_mm: still.noise_mm,
        windows,
    })
}

/// The scales the plan sets: bin width, sliding window, quantile of the quiet readings,
/// default tolerance.
struct Shape {
    bin_s: f64,
    sliding_s: f64,
    quantile: f64,
    tolerance_s: f64,
}

impl Shape {
    fn of(plan: &TimingPlan, opts: &SegmentOptions) -> Result<Shape, SegmentError> {
        let bad = |s: String| Err(SegmentError::Options(s));
        let rows = &plan.rows;
        let n = rows.len();
        let rest: f64 = rows.iter().map(|r| r.depart_s - r.arrive_s).sum();
        let whole = rows[n - 1].depart_s - rows[0].arrive_s;
        let quantile = if whole > 0.0 {
            (0.5 * rest / whole).clamp(0.01, 0.2)
        } else {
            0.2
        };
        // Named by their flags (the stillness limit is given in µm).
        for (flag, v, scale) in [
            ("--offset-s", opts.offset_s, 1.0),
            ("--margin-s", opts.margin_s, 1.0),
            ("--still-um", opts.still_mm, 1e3),
            ("--tolerance-s", opts.tolerance_s, 1.0),
        ] {
            if let Some(v) = v
                && (!v.is_finite()
                    || (flag != "--offset-s" && v < 0.0)
                    || (flag == "--tolerance-s" && v == 0.0))
            {
                let why = match flag {
                    "--offset-s" => "a finite number",
                    "--tolerance-s" => "a finite number above 0",
                    _ => "a finite number, at least 0",
                };
                return bad(format!("{flag}: {}: {why}", significant(v * scale)));
            }
        }
        let (feature, tolerance_s) = match plan.kind {
            PlanKind::Static => {
                let shortest = rows
                    .iter()
                    .map(|r| r.end_s - r.start_s)
                    .fold(f64::INFINITY, f64::min);
                if let Some(m) = opts.margin_s
                    && 2.0 * m >= shortest
                {
                    return bad(format!(
                        "--margin-s: a margin of {} s at each end leaves nothing of the shortest window ({} s)",
                        significant(m),
                        significant(shortest)
                    ));
                }
                let spacing = rows
                    .windows(2)
                    .map(|w| w[1].depart_s - w[0].depart_s)
                    .fold(rows[0].depart_s - rows[0].arrive_s, f64::min);
                (shortest, 0.3 * spacing)
            }
            PlanKind::Continuous => {
                let lead = rows[0].depart_s - rows[0].arrive_s;
                if lead <= 0.0 || rows[n - 1].depart_s <= rows[n - 1].arrive_s {
                    return bad("a continuous plan without a lead-in and a lead-out dwell: its run cannot be found in a log".into());
                }
                let run = rows[n - 1].arrive_s - rows[0].depart_s;
                (lead / 5.0, (0.3 * lead).max(0.25 * run))
            }
        };
        Ok(Shape {
            bin_s: (feature / 40.0).clamp(1e-3, 0.05),
            sliding_s: feature / 4.0,
            quantile,
            tolerance_s,
        })
    }
}
