//! `rtest segment`: a time-stamped R-test log cut into one sample per pose of a measurement
//! program's timing plan, written as a measurement record.

use super::args::RecordLimits;
use super::{EXIT_CODES, Error, VerbResult, check_outputs};
use crate::Done;
use formats::csv::{CsvError, parse_measurement};
use model_spec::units::{UM_PER_MM, short};
use output::{Outputs, Target};
use programs::measure::{PlanKind, read_plan};
use programs::segment::{
    LogClock, SegmentError, SegmentOptions, Segmented, format_segmented, format_windows,
    segment_file,
};
use std::path::{Path, PathBuf};

const LONG_ABOUT: &str = "\
Cuts a time-stamped R-test log into one sample per pose of a measurement program's timing plan and \
writes the samples as a measurement record. Details: docs/measurement-programs.md.

--plan is the plan written beside the program (sample, the axes in mm and degrees, arrive_s, \
start_s, end_s, depart_s on the program clock). --log is the R-test's stream: a CSV with a time \
column, t_s (s on any clock) or t_abs_s (Unix time, s), and reading columns named …_um (µm: \
dx_um,dy_um,dz_um, or sensor columns s1_um,s2_um,…; not both); other columns are not read. The log \
is read twice, so it must be a file.

Static plans: the still periods of the readings are matched with the plan's rests, each pose \
tracked from the one before, so a machine whose timing drifts from the plan is followed. An \
ambiguous match (two runs) or a poor one (fewer than half the poses placed at an edge) is refused: \
give --offset-s, the program's start on the log's clock. Each window, less --margin-s at each end \
(default a tenth of it) and within its still period, is averaged; windows whose readings scatter \
more than four times the median, or that motion cut short, are flagged. Continuous plans: the run \
is found between its lead-in and lead-out dwells, the readings interpolated at each pose's \
instant.

The record (-o) has the plan's axis columns, the averaged reading columns and t_s, the window's \
middle on the program clock as the log measured it; with dx_um,dy_um,dz_um it is read back as \
`identify` reads it before it is written. --windows: each window's log times, readings, drift, \
anchor, spread per column (µm) and flags. Prints the program's start in the log, the alignment, \
the noise and the flagged windows.";

/// Flags of `rtest segment`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Cut a time-stamped R-test log into one sample per pose of a timing plan (writes a measurement CSV)",
    long_about = LONG_ABOUT,
    after_help = EXIT_CODES
)]
pub struct SegmentArgs {
    /// Built-in machine (see `rtest machines`) or path of a machine TOML file.
    #[arg(long, value_name = "NAME|FILE")]
    machine: String,
    /// The timing plan written with the measurement program (CSV).
    #[arg(long, value_name = "FILE")]
    plan: PathBuf,
    /// The R-test's log: t_s or t_abs_s, and reading columns …_um (CSV, a file).
    #[arg(long, value_name = "FILE")]
    log: PathBuf,
    /// The measurement record to write (`-`: standard output).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Target,
    /// The program's start on the log's clock, s (Unix seconds for a t_abs_s log): not searched
    /// for.
    #[arg(long, value_name = "S", allow_negative_numbers = true, value_parser = finite)]
    offset_s: Option<f64>,
    /// Dropped at each end of each window, s (default a tenth of the window).
    #[arg(long, value_name = "S", value_parser = at_least_zero)]
    margin_s: Option<f64>,
    /// The stillness limit: standard deviation of a reading column over a short sliding
    /// window, µm (default from the log's noise).
    #[arg(long, value_name = "UM", value_parser = super::args::positive)]
    still_um: Option<f64>,
    /// How far a still period's edge may be from where the plan puts it, s (default 0.3 × the
    /// shortest time from one departure to the next; continuous: a quarter of the run).
    #[arg(long, value_name = "S", value_parser = super::args::positive)]
    tolerance_s: Option<f64>,
    /// The fewest log rows a window may average.
    #[arg(long, value_name = "N", default_value = "5",
          value_parser = clap::value_parser!(u32).range(1..))]
    min_readings: u32,
    /// Also write each window's times, readings, drift, anchor, spread and flags (CSV).
    #[arg(long, value_name = "FILE")]
    windows: Option<Target>,
    #[command(flatten)]
    records: RecordLimits,
}

/// A finite number.
fn finite(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        _ => Err(format!("`{s}` is not a finite number")),
    }
}

/// A finite number, at least zero.
fn at_least_zero(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
        _ => Err(format!("`{s}` is not a finite number at least zero")),
    }
}

/// Runs `rtest segment`.
pub fn run(args: &SegmentArgs) -> VerbResult<Done> {
    let m = super::load_machine(&args.machine)?;
    let mut inputs: Vec<(&str, &Path)> = vec![("--plan", &args.plan), ("--log", &args.log)];
    inputs.extend(super::machine_file(&args.machine).map(|p| ("--machine", p)));
    let mut outputs: Vec<(&str, &Target)> = vec![("-o", &args.output)];
    if let Some(w) = &args.windows {
        outputs.push(("--windows", w));
    }
    check_outputs(&inputs, &outputs, &[])?;
    let plan = read_plan(&args.plan, &m).map_err(|e| Error::input(format!("--plan: {e}")))?;
    let opts = SegmentOptions {
        offset_s: args.offset_s,
        margin_s: args.margin_s,
        still_mm: args.still_um.map(|u| u / UM_PER_MM),
        tolerance_s: args.tolerance_s,
        min_readings: args.min_readings as usize,
    };
    let seg = segment_file(&args.log, &plan, &opts).map_err(|e| match e {
        SegmentError::Options(m) => Error::usage(m),
        SegmentError::Csv(e) => Error::input(format!("--log: {e}")),
        e => Error::input(format!("--log: {e}")),
    })?;
    let comments = vec![
        format!(
            "segmented by rtest {} from the log {} with the plan {}",
            env!("CARGO_PKG_VERSION"),
            args.log.display(),
            args.plan.display()
        ),
        format!(
            "machine {}; program start at {} s on the log's clock ({}); t_s is on the program clock",
            m.name,
            short(seg.start_s),
            if seg.start_given { "given" } else { "found" }
        ),
        "readings in µm: the mean of each measuring window (static) or interpolated at the pose's instant (continuous)".into(),
    ];
    let csv = format_segmented(&m, &plan, &seg, &comments)
        .map_err(|e| Error::computation(format!("-o: {e}")))?;
    let error_vector = seg.columns.len() == 3
        && ["dx_um", "dy_um", "dz_um"]
            .iter()
            .all(|c| seg.columns.iter().any(|s| s.eq_ignore_ascii_case(c)));
    if error_vector {
        parse_measurement(
            &args.output.to_string(),
            &csv,
            &m,
            &args.records.read_options(),
        )
        .map_err(|e: CsvError| {
            Error::input(format!(
                "--log: the segmented record would not be accepted by identify, so it is not written: {e}"
            ))
        })?;
    }
    let mut files = Outputs::new();
    files.add("-o", args.output.clone(), csv);
    if let Some(w) = &args.windows {
        files.add("--windows", w.clone(), format_windows(&seg));
    }
    let stdout_taken =
        matches!(args.output, Target::Stdout) || matches!(args.windows, Some(Target::Stdout));
    Ok(Done::new(summary(&seg, &args.log), files, stdout_taken))
}

/// The summary for people.
fn summary(seg: &Segmented, log: &Path) -> String {
    let n = seg.windows.len();
    let mut s = format!(
        "Segmented {} into {n} samples ({} plan): {} log rows over {} s, reading columns {}{}\n",
        log.display(),
        match seg.kind {
            PlanKind::Static => "static",
            PlanKind::Continuous => "continuous",
        },
        seg.rows,
        short(seg.span_s),
        seg.columns.join(","),
        if seg.ignored.is_empty() {
            String::new()
        } else {
            format!(" (not read: {})", seg.ignored.join(","))
        }
    );
    let start = match seg.clock {
        LogClock::Unix { .. } => format!("{} s ({})", short(seg.start_s), utc(seg.start_s)),
        LogClock::Seconds { .. } => format!("{} s", short(seg.start_s)),
    };
    s += &format!(
        "Program start on the log's clock ({}): {start}, {}\n",
        seg.clock.column(),
        if seg.start_given { "given" } else { "found" }
    );
    match seg.kind {
        PlanKind::Static => {
            let shifts = seg.windows.iter().map(|w| w.shift_s);
            let (lo, hi) = shifts.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            });
            s += &format!(
                "Alignment: {} of {n} poses at an edge of their still period ({} still periods found); timing drift against the plan {} .. {} s\n",
                seg.anchored,
                seg.still_periods,
                short(lo),
                short(hi)
            );
            if let Some((o, a)) = seg.runner_up {
                s += &format!(
                    "Next best alignment: program start at {} s, {a} of {n} poses at an edge\n",
                    short(o)
                );
            }
            let flagged: Vec<String> = seg
                .windows
                .iter()
                .filter(|w| !w.flags.is_empty())
                .map(|w| {
                    let f: Vec<&str> = w.flags.iter().map(|f| f.name()).collect();
                    format!("{} ({})", w.sample, f.join(", "))
                })
                .collect();
            s += &if flagged.is_empty() {
                "Flagged windows: none\n".to_string()
            } else {
                format!("Flagged windows: {}\n", flagged.join(", "))
            };
        }
        PlanKind::Continuous => {
            s += &format!(
                "Run time found over the planned one: {} (both ends at an edge: {})\n",
                short(seg.time_scale),
                if seg.anchored == 2 { "yes" } else { "no" }
            );
        }
    }
    s += &format!(
        "Noise of a reading at rest: {} µm per column; stillness limit {} µm\n",
        short(seg.noise_mm * UM_PER_MM),
        short(seg.still_limit_mm * UM_PER_MM)
    );
    s
}

/// A Unix time (s) as a UTC date and time, `2024-05-31 12:34:56.789 UTC`.
fn utc(unix_s: f64) -> String {
    let whole = unix_s.floor();
    let millis = ((unix_s - whole) * 1000.0).floor() as i64;
    let secs = whole as i64;
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    // Civil date from days since 1970-01-01 (the proleptic Gregorian calendar).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02} {:02}:{:02}:{:02}.{millis:03} UTC",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

#[cfg(test)]
mod tests {
    use super::utc;

    #[test]
    fn unix_times_as_dates() {
        assert_eq!(utc(0.0), "1970-01-01 00:00:00.000 UTC");
        assert_eq!(utc(951_782_400.5), "2000-02-29 00:00:00.500 UTC");
        assert_eq!(utc(1_717_171_717.25), "2024-05-31 16:08:37.250 UTC");
    }
}
