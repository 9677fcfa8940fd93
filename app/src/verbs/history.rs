//! `rtest history`: the machines and checks of a history database, and one error's trend
//! with its flags (table, figure, CSV, JSON) (docs/history.md). The `--record` flags that put a
//! check into it are [`super::record`].

use super::record::history_error;
use super::{EXIT_CODES, Error, VerbResult, check_outputs};
use crate::Done;
use history::Store;
use history::report::{TrendReport, known_parameters, listing, listing_json};
use history::tolerance::{self, MAX_TOLERANCE_BYTES, Tolerances};
use history::trend::{self, Options, TrendError};
use output::{Outputs, Target};
use std::path::{Path, PathBuf};

const LONG_ABOUT: &str = "\
The machine's history: the checks `rtest identify --record` put into an SQLite database (--db, \
default rtest-history.sqlite), and the trend of one error over them.

Without --machine-id: every machine id with its checks (id, measurement time, model, paths, \
residual RMS in µm, rank). With --machine-id ID: that machine's checks and the errors it can \
show. With --error NAME as well: that error's trend over the machine's comparable checks (same \
machine description, model, test paths and constraint; the others are listed as left out, with \
why) as a table with the flags of every check; the calibrations' series, or with --rechecks the \
re-checks' (rtest validate --refit --record):

- tolerance: |value| > limit (µm or µrad; --tolerance NAME=LIMIT or --tolerances FILE);
- baseline: the value changed against the baseline check (--baseline CHECK, default the first \
of the series) by more than z·√(σ² + σ_b²), z the two-sided normal quantile of --alpha;
- trend: the weighted least-squares slope (per day) from the baseline to the check is \
significant (Student's t, two-sided, at --alpha).

Each row's flags use that check and the ones before it only. --figure FILE.svg draws the values \
± σ, the tolerance band, the baseline and the trend line; --csv FILE writes the rows (values in \
the error's unit); --json FILE writes the listing or the trend (`-`: standard output, the text \
then goes to standard error).

Details: docs/history.md.";

/// Flags of `rtest history`.
#[derive(Debug, clap::Args)]
#[command(
    about = "The machine's history: its checks, and one error's trend with drift flags",
    long_about = LONG_ABOUT,
    after_help = EXIT_CODES
)]
pub struct HistoryArgs {
    /// The history database (default rtest-history.sqlite in the working directory).
    #[arg(long, value_name = "FILE")]
    db: Option<PathBuf>,
    /// The machine id whose checks to show.
    #[arg(long, value_name = "ID")]
    machine_id: Option<String>,
    /// The error (parameter) whose trend to show: XOC, ECC@harmonic:2:cos, …
    #[arg(long, value_name = "NAME", requires = "machine_id")]
    error: Option<String>,
    /// The baseline: a check id of the series (default: its first check).
    #[arg(long, value_name = "CHECK", requires = "error")]
    baseline: Option<i64>,
    /// Trend the re-checks (rtest validate --refit --record: pivot and preset), a series of
    /// their own, instead of the calibrations.
    #[arg(long, requires = "error")]
    rechecks: bool,
    /// Two-sided level of the change and trend tests (1e-6 to 0.2).
    #[arg(long, value_name = "ALPHA", default_value_t = trend::DEFAULT_ALPHA, requires = "error")]
    alpha: f64,
    /// A tolerance |NAME| ≤ LIMIT, µm or µrad (repeatable).
    #[arg(
        long,
        value_name = "NAME=LIMIT",
        requires = "error",
        conflicts_with = "tolerances"
    )]
    tolerance: Vec<String>,
    /// The machine's tolerance file (TOML: NAME = limit, µm or µrad; docs/history.md).
    #[arg(long, value_name = "FILE", requires = "error")]
    tolerances: Option<PathBuf>,
    /// Write the trend figure (SVG) to FILE.
    #[arg(long, value_name = "FILE.svg", requires = "error")]
    figure: Option<Target>,
    /// Write the trend's rows as CSV to FILE (`-`: standard output).
    #[arg(long, value_name = "FILE", requires = "error")]
    csv: Option<Target>,
    /// Write the listing or the trend as JSON to FILE (`-`: standard output).
    #[arg(long, value_name = "FILE")]
    json: Option<Target>,
}

/// Runs `rtest history`.
pub fn run(args: &HistoryArgs) -> VerbResult<Done> {
    let db = args
        .db
        .clone()
        .unwrap_or_else(|| PathBuf::from(history::DEFAULT_FILE));
    let mut inputs: Vec<(&str, &Path)> = vec![("--db", db.as_path())];
    if let Some(t) = &args.tolerances {
        inputs.push(("--tolerances", t.as_path()));
    }
    let outputs: Vec<(&str, &Target)> = [
        ("--figure", &args.figure),
        ("--csv", &args.csv),
        ("--json", &args.json),
    ]
    .into_iter()
    .filter_map(|(f, t)| t.as_ref().map(|t| (f, t)))
    .collect();
    check_outputs(&inputs, &outputs, &[])?;
    let store = Store::open_for_reading(&db).map_err(|e| history_error("--db", e))?;
    let all = store.checks(None).map_err(|e| history_error("--db", e))?;
    let name = db.display().to_string();
    if all.is_empty() {
        return Err(Error::input(format!(
            "--db {name}: the history is empty: no check recorded"
        )));
    }
    let stdout_taken = outputs.iter().any(|(_, t)| matches!(t, Target::Stdout));
    let mut files = Outputs::new();
    let text = match (&args.machine_id, &args.error) {
        (id, None) => {
            let mut machines = store.machines().map_err(|e| history_error("--db", e))?;
            let checks: Vec<_> = match id {
                None => all,
                Some(id) => {
                    machines.retain(|m| &m.machine_id == id);
                    if machines.is_empty() {
                        return Err(unknown_machine(id, &all));
                    }
                    all.into_iter()
                        .filter(|c| &c.check.machine_id == id)
                        .collect()
                }
            };
            if let Some(t) = &args.json {
                let json = listing_json(&name, &machines, &checks)
                    .map_err(|e| Error::computation(format!("--json: {e}")))?;
                files.add("--json", t.clone(), json);
            }
            listing(&name, &machines, &checks)
        }
        (Some(id), Some(error)) => trend_outputs(args, &name, &all, id, error, &mut files)?,
        (None, Some(_)) => return Err(Error::usage("--error needs --machine-id ID")),
    };
    Ok(Done::new(text, files, stdout_taken))
}

fn unknown_machine(id: &str, all: &[history::RecordedCheck]) -> Error {
    let mut known: Vec<&str> = all.iter().map(|c| c.check.machine_id.as_str()).collect();
    known.sort_unstable();
    known.dedup();
    Error::usage(format!(
        "--machine-id: no check of machine `{id}` in the history (machines: {})",
        known.join(", ")
    ))
}

/// A trend error as a verb's error.
fn trend_error(e: TrendError) -> Error {
    match e {
        TrendError::UnknownParameter { .. } | TrendError::NeverDetermined { .. } => {
            Error::usage(format!("--error: {e}"))
        }
        TrendError::Reference { .. } => Error::usage(format!("--baseline: {e}")),
        TrendError::Alpha(m) => Error::usage(format!("--alpha: {m}")),
        TrendError::Tolerance(m) => Error::usage(format!("--tolerance: {m}")),
        TrendError::UnknownMachine { .. } => Error::usage(format!("--machine-id: {e}")),
        TrendError::EmptyHistory => Error::input(format!("--db: {e}")),
    }
}

/// The trend of `error` on machine `id`: its text, and its figure, CSV and JSON added to
/// `files`.
fn trend_outputs(
    args: &HistoryArgs,
    db: &str,
    all: &[history::RecordedCheck],
    id: &str,
    error: &str,
    files: &mut Outputs,
) -> VerbResult<String> {
    if !all.iter().any(|c| c.check.machine_id == id) {
        return Err(unknown_machine(id, all));
    }
    let tolerances = match &args.tolerances {
        Some(path) => {
            let text = model_spec::text::read_text(path, MAX_TOLERANCE_BYTES)
                .map_err(|e| Error::input(format!("--tolerances: {e}")))?;
            let t = tolerance::parse_file(&path.display().to_string(), &text)
                .map_err(|e| Error::input(format!("--tolerances {e}")))?;
            Some(("--tolerances", t))
        }
        None if !args.tolerance.is_empty() => Some((
            "--tolerance",
            tolerance::parse_args(&args.tolerance)
                .map_err(|e| Error::usage(format!("--tolerance: {}", e.message)))?,
        )),
        None => None,
    };
    let known = known_parameters(all, id);
    if let Some((flag, t)) = &tolerances {
        t.check(id, &known).map_err(|e| {
            if *flag == "--tolerance" {
                Error::usage(format!("--tolerance: {}", e.message))
            } else {
                Error::input(format!("--tolerances {e}"))
            }
        })?;
    }
    let series =
        trend::select(all, id, error, args.baseline, args.rechecks).map_err(trend_error)?;
    let (limit, from) = match &tolerances {
        Some((_, t)) => tolerance_of(t, &series.head.parameter),
        None => (None, None),
    };
    let options = Options {
        alpha: args.alpha,
        baseline: args.baseline,
        tolerance: limit,
    };
    let assessment = trend::assess(&series, &options).map_err(trend_error)?;
    let report = TrendReport::new(db, &series, assessment, from);
    if let Some(t) = &args.figure {
        files.add("--figure", t.clone(), figure(&report)?);
    }
    if let Some(t) = &args.csv {
        files.add("--csv", t.clone(), report.csv());
    }
    if let Some(t) = &args.json {
        let json = report
            .json()
            .map_err(|e| Error::computation(format!("--json: {e}")))?;
        files.add("--json", t.clone(), json);
    }
    Ok(report.text())
}

/// The limit of `parameter` in `t` and where it was given.
fn tolerance_of(t: &Tolerances, parameter: &str) -> (Option<f64>, Option<String>) {
    let key = history::check::canonical_key(parameter);
    t.entries
        .iter()
        .find(|e| history::check::canonical_key(&e.name) == key)
        .map_or((None, None), |e| {
            let from = if e.file == "--tolerance" {
                "--tolerance".to_string()
            } else {
                format!("{}:{}", e.file, e.at.0)
            };
            (Some(e.limit), Some(from))
        })
}

/// The trend figure: days since the first check of the series.
fn figure(report: &TrendReport) -> VerbResult<String> {
    let a = &report.assessment;
    let s = &report.series;
    let unit = model_spec::units::symbol(&s.unit).to_string();
    let t0 = a.rows[0].point.at;
    let points: Vec<plots::TrendPoint> = a
        .rows
        .iter()
        .map(|r| plots::TrendPoint {
            x: r.point.at.days_since(t0),
            value: r.point.value,
            std: r.point.std,
            flagged: !r.flags.is_empty(),
        })
        .collect();
    let base = a
        .rows
        .iter()
        .find(|r| r.point.id == a.baseline)
        .map(|r| r.point.value);
    let line = a.trend.as_ref().map(|sl| {
        let day = |id: i64| {
            a.rows
                .iter()
                .find(|r| r.point.id == id)
                .map_or(0.0, |r| r.point.at.days_since(t0))
        };
        let (start, end) = (day(sl.from), day(sl.to));
        let at = |x: f64| sl.centre_value + sl.per_day * (x - start - sl.centre_days);
        (
            [(start, at(start)), (end, at(end))],
            format!(
                "trend {}{} {unit}/day, checks {}–{} ({})",
                if sl.per_day >= 0.0 { "+" } else { "" },
                model_spec::units::readable(sl.per_day, 4),
                sl.from,
                sl.to,
                if sl.flagged {
                    "a drift"
                } else {
                    "not significant"
                }
            ),
        )
    });
    let title = format!("{} of machine {}", s.parameter, s.machine_id);
    let x_label = format!("days since {}", t0);
    plots::trend(&plots::TrendFigure {
        title: &title,
        x_label: &x_label,
        name: &s.parameter,
        unit: &unit,
        points: &points,
        tolerance: a.tolerance,
        baseline: base.map(|b| (b, format!("baseline (check {})", a.baseline))),
        line,
    })
    .map_err(|e| Error::computation(format!("--figure: {e}")))
}
