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

use crate::io::csv::{CsvError, column_order, comment_lines};
use crate::io::nc::measure::{PlanKind, TimingPlan};
pub use align::Anchor;
use align::{Alignment, align_continuous, align_static};
pub use log::LogClock;
use log::LogReader;
use model_spec::units::{degrees_for, format_scaled};
use model_spec::{AxisKind, Machine};
use std::io::Read;
use std::path::Path;
use still::{Bins, still_periods};
pub use windows::{Window, WindowFlag};

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
        return Err(SegmentError::Csv(CsvError::Format {
            file: file.into(),
            line: 1,
            column: None,
            message: format!("{rows} row(s): a log needs at least two"),
        }));
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
        for (name, v) in [
            ("offset", opts.offset_s),
            ("margin", opts.margin_s),
            ("stillness limit", opts.still_mm),
            ("tolerance", opts.tolerance_s),
        ] {
            if let Some(v) = v
                && (!v.is_finite()
                    || (name != "offset" && v < 0.0)
                    || (name == "tolerance" && v == 0.0))
            {
                return bad(format!(
                    "{name} {v}: finite, and above 0 (a margin or limit may be 0)"
                ));
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
                        "a margin of {m} s at each end leaves nothing of the shortest window ({shortest} s)"
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

#[allow(clippy::too_many_arguments)]
fn static_windows<R: Read>(
    file: &str,
    reader: &mut LogReader<'_, R>,
    plan: &TimingPlan,
    al: &Alignment,
    periods: &[still::StillPeriod],
    opts: &SegmentOptions,
    clock: &LogClock,
    k: usize,
) -> Result<Vec<Window>, SegmentError> {
    let margin = |i: usize| {
        opts.margin_s
            .unwrap_or(0.1 * (plan.rows[i].end_s - plan.rows[i].start_s))
    };
    let cuts = windows::static_cuts(plan, al, periods, &margin);
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
    let sums = windows::average(reader, &cuts, k)?;
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
    windows::flag(&mut out, &clipped);
    Ok(out)
}

fn continuous_windows<R: Read>(
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
    let values =
        windows::interpolate(reader, &instants, k, 5.0 * period)?.map_err(|(i, why)| {
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
        .enumerate()
        .map(|(i, (mean, &at))| Window {
            sample: i + 1,
            log_start_s: clock.log_time(at),
            log_end_s: clock.log_time(at),
            readings: 2,
            t_s: at - al.offset,
            shift_s: 0.0,
            anchor: al.placed[i].anchor,
            mean_mm: mean,
            sd_mm: vec![0.0; k],
            flags: Vec::new(),
        })
        .collect())
}

/// The measurement record of `seg` (cut by `plan`, of machine `m`) as CSV text: `comments` as
/// `# ` lines, the header (the axes as [`column_order`] orders them, the reading columns under
/// the log's names, `t_s`), one row per pose: axes in mm and degrees, readings in µm, `t_s` in
/// s, each the shortest decimal that reads back to the same value.
///
/// # Errors
/// [`CsvError::Record`] when `seg` does not have one window per row of `plan`, or a value is
/// not finite.
pub fn format_segmented(
    m: &Machine,
    plan: &TimingPlan,
    seg: &Segmented,
    comments: &[String],
) -> Result<String, CsvError> {
    if seg.windows.len() != plan.rows.len() {
        return Err(CsvError::Record(format!(
            "{} samples for the {} poses of the plan",
            seg.windows.len(),
            plan.rows.len()
        )));
    }
    let axes = column_order(m);
    let mut out = comment_lines(comments);
    let mut header: Vec<&str> = axes.iter().map(|&a| m.axes[a].name.as_str()).collect();
    header.extend(seg.columns.iter().map(String::as_str));
    header.push("t_s");
    out += &header.join(",");
    out.push('\n');
    for (row, w) in plan.rows.iter().zip(&seg.windows) {
        let mut fields: Vec<String> = Vec::with_capacity(header.len());
        for &a in &axes {
            let q = *row.commands.get(a).unwrap_or(&f64::NAN);
            fields.push(match m.axes[a].kind {
                AxisKind::Linear => format_scaled(q, 0),
                AxisKind::Rotary => format_scaled(degrees_for(q), 0),
            });
        }
        fields.extend(w.mean_mm.iter().map(|&v| format_scaled(v, 3)));
        fields.push(format_scaled(w.t_s, 0));
        if row
            .commands
            .iter()
            .chain(&w.mean_mm)
            .any(|v| !v.is_finite())
            || !w.t_s.is_finite()
        {
            return Err(CsvError::Record(format!(
                "sample {} has a value that is not finite",
                w.sample
            )));
        }
        out += &fields.join(",");
        out.push('\n');
    }
    Ok(out)
}

/// The windows of `seg` as a CSV for people and tools: `sample`, `log_start_s`, `log_end_s`
/// (the log's clock), `readings`, `t_s` (program clock), `shift_s` (the timing drift),
/// `anchor`, the standard deviation of each reading column within the window (`<column>_sd`,
/// µm), and `flags` (`spread`, `motion`, separated by spaces).
pub fn format_windows(seg: &Segmented) -> String {
    let mut header = vec![
        "sample".to_string(),
        "log_start_s".into(),
        "log_end_s".into(),
        "readings".into(),
        "t_s".into(),
        "shift_s".into(),
        "anchor".into(),
    ];
    header.extend(seg.columns.iter().map(|c| format!("{c}_sd")));
    header.push("flags".into());
    let mut out = header.join(",");
    out.push('\n');
    for w in &seg.windows {
        let mut f = vec![
            w.sample.to_string(),
            format_scaled(w.log_start_s, 0),
            format_scaled(w.log_end_s, 0),
            w.readings.to_string(),
            format_scaled(w.t_s, 0),
            format_scaled(w.shift_s, 0),
            w.anchor.name().to_string(),
        ];
        f.extend(w.sd_mm.iter().map(|&s| format_scaled(s, 3)));
        f.push(
            w.flags
                .iter()
                .map(|f| f.name())
                .collect::<Vec<_>>()
                .join(" "),
        );
        out += &f.join(",");
        out.push('\n');
    }
    out
}

/// A time for messages: at most six decimals, no trailing zeros.
fn short(x: f64) -> String {
    model_spec::units::short(x)
}
