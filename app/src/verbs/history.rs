//! `rtest history`: the machines and checks of a history database, and one error's trend
//! with its flags (table, figure, CSV, JSON); and the `--record` flags of `rtest identify`
//! that put a check into it (docs/history.md).

use super::{EXIT_CODES, Error, ReadFile, VerbResult, check_outputs};
use crate::Done;
use history::report::{TrendReport, known_parameters, listing, listing_json};
use history::tolerance::{self, MAX_TOLERANCE_BYTES, Tolerances};
use history::trend::{self, Options, TrendError};
use history::{Check, HistoryError, InputFile, Provenance, Staged, Store, Timestamp};
use output::{Outputs, Target};
use report::text::shell;
use std::path::{Path, PathBuf};

/// The `--record` flags of `rtest identify`.
#[derive(Debug, clap::Args)]
pub struct RecordArgs {
    /// Record the identification in the machine's history (an SQLite file, --db) once it
    /// succeeded: machine id, fingerprint, model and terms, test paths, times, the SHA-256 of
    /// every input file, every value with its σ and unit, rank, unidentifiable groups,
    /// residual (docs/history.md).
    #[arg(long)]
    pub record: bool,
    /// The history database (made when missing; default rtest-history.sqlite in the working
    /// directory).
    #[arg(long, value_name = "FILE", requires = "record")]
    pub db: Option<PathBuf>,
    /// The machine's own id, e.g. its serial number (required with --record): two machines of
    /// one description are two histories.
    #[arg(long, value_name = "ID", requires = "record")]
    pub machine_id: Option<String>,
    /// The test paths of this check, for comparing checks (default: the data file's stem,
    /// k4.csv → k4; a campaign's record labels).
    #[arg(long, value_name = "LABEL[,LABEL...]", requires = "record")]
    pub record_paths: Option<String>,
    /// When the measurement was taken: RFC 3339 (2025-03-04T08:15:00Z,
    /// 2025-03-04T09:15:00+01:00) or a date (2025-03-04); kept in UTC to the second (default:
    /// now).
    #[arg(long, value_name = "TIME", requires = "record")]
    pub measured_at: Option<String>,
}

/// The history a check will be recorded in: the database checked before any work, the
/// inputs hashed, the check's provenance.
#[derive(Debug)]
pub struct Recorder {
    db: PathBuf,
    store: Option<Store>,
    provenance: Provenance,
    /// The line that says where the check went, when not [`Recorder::recorded`]'s own.
    line: Option<fn(i64) -> String>,
}

/// A history error as a verb's error, `flag` naming the database's flag.
pub(crate) fn history_error(flag: &str, e: HistoryError) -> Error {
    Error::input(format!("{flag} {e}"))
}

impl RecordArgs {
    /// The database's path.
    fn db(&self) -> PathBuf {
        self.db
            .clone()
            .unwrap_or_else(|| PathBuf::from(history::DEFAULT_FILE))
    }

    /// The database as an input of the command (no output may name it), when recording.
    pub fn input(&self) -> Option<(&'static str, PathBuf)> {
        self.record.then(|| ("--db", self.db()))
    }

    /// The recorder of a command, or `None` without --record. Checks the flags and an existing
    /// database now, before any work; the input files are added as the command reads them
    /// ([`Recorder::add_read`]).
    ///
    /// # Errors
    /// A usage error for missing or malformed flags; a bad input for a database that cannot
    /// be used.
    pub fn recorder(&self) -> VerbResult<Option<Recorder>> {
        if !self.record {
            return Ok(None);
        }
        let Some(machine_id) = self.machine_id.clone() else {
            return Err(Error::usage(
                "--record needs --machine-id ID: the machine's own id (e.g. its serial number); two machines of one description are two histories",
            ));
        };
        history::check::label("machine id", &machine_id, false)
            .map_err(|e| Error::usage(format!("--machine-id: {e}")))?;
        let paths = match &self.record_paths {
            None => Vec::new(),
            Some(list) => {
                let paths: Vec<String> = list.split(',').map(|p| p.trim().to_string()).collect();
                for (i, p) in paths.iter().enumerate() {
                    history::check::label("test path", p, true)
                        .map_err(|e| Error::usage(format!("--record-paths: {e}")))?;
                    if paths[..i].iter().any(|q| q.eq_ignore_ascii_case(p)) {
                        return Err(Error::usage(format!(
                            "--record-paths: test path `{p}` is given twice"
                        )));
                    }
                }
                paths
            }
        };
        let now = Timestamp::now().map_err(|e| Error::input(format!("--record: {e}")))?;
        let measured_at = match &self.measured_at {
            None => now,
            Some(t) => {
                Timestamp::parse(t).map_err(|e| Error::usage(format!("--measured-at: {e}")))?
            }
        };
        let db = self.db();
        let store = match Store::open(&db) {
            Ok(s) => Some(s),
            Err(HistoryError::NotFound { .. }) => None,
            Err(e) => return Err(history_error("--db", e)),
        };
        Ok(Some(Recorder {
            line: None,
            db,
            store,
            provenance: Provenance {
                machine_id,
                paths,
                measured_at,
                recorded_at: now,
                rtest_version: env!("CARGO_PKG_VERSION").to_string(),
                inputs: Vec::new(),
            },
        }))
    }
}

impl Recorder {
    /// A recorder into `db` for `machine_id`'s check of `paths`, measured now, without
    /// input files yet ([`Recorder::add_input`]); an existing database is checked now.
    ///
    /// # Errors
    /// A bad input for a database that cannot be used (`flag` names it).
    pub fn open(flag: &str, db: &Path, machine_id: &str, paths: &[&str]) -> VerbResult<Recorder> {
        let store = match Store::open(db) {
            Ok(s) => Some(s),
            Err(HistoryError::NotFound { .. }) => None,
            Err(e) => return Err(history_error(flag, e)),
        };
        let now = Timestamp::now().map_err(|e| Error::input(format!("{flag} {e}")))?;
        Ok(Recorder {
            db: db.to_path_buf(),
            store,
            provenance: Provenance {
                machine_id: machine_id.into(),
                paths: paths.iter().map(|p| (*p).to_string()).collect(),
                measured_at: now,
                recorded_at: now,
                rtest_version: env!("CARGO_PKG_VERSION").to_string(),
                inputs: Vec::new(),
            },
            line: None,
        })
    }

    /// With `line` saying where check `id` went, instead of the default line.
    pub fn saying(mut self, line: fn(i64) -> String) -> Recorder {
        self.line = Some(line);
        self
    }

    /// Adds an input file given by its bytes (`role`: what it was, `path`: its name).
    pub fn add_input(&mut self, role: &str, path: &str, bytes: &[u8]) {
        let digest = ::history::sha256::Digest::of(bytes);
        self.provenance.inputs.push(InputFile {
            role: role.into(),
            path: path.into(),
            bytes: digest.bytes,
            sha256: digest.sha256,
        });
    }

    /// Adds the input files the command read, with the digests of the bytes it read.
    pub fn add_read(&mut self, files: &[ReadFile]) {
        self.provenance
            .inputs
            .extend(files.iter().map(|f| InputFile {
                role: f.flag.clone(),
                path: f.path.clone(),
                bytes: f.digest.bytes,
                sha256: f.digest.sha256.clone(),
            }));
    }

    /// The provenance of the check (machine id, paths, times, inputs).
    pub fn provenance(&self) -> Provenance {
        self.provenance.clone()
    }

    /// Inserts `check` without committing it (the database made now if it was missing).
    ///
    /// # Errors
    /// A bad input for a database that cannot be made or written, or a check it refuses.
    pub fn stage(&mut self, check: &Check) -> VerbResult<Staged<'_>> {
        // A check the database would refuse makes no database.
        check.validate().map_err(|e| {
            Error::input(format!(
                "--db {}: cannot record the check: {e}",
                self.db.display()
            ))
        })?;
        if self.store.is_none() {
            self.store =
                Some(Store::open_or_create(&self.db).map_err(|e| history_error("--db", e))?);
        }
        let store = self.store.as_mut().expect("opened above");
        store.stage(check).map_err(|e| history_error("--db", e))
    }

    /// The line that says where the check went.
    pub fn recorded(&self, id: i64) -> String {
        if let Some(line) = self.line {
            return line(id);
        }
        let m = &self.provenance.machine_id;
        format!(
            "Recorded as check {id} of machine {m} in {} (rtest history --db {} --machine-id {})\n",
            self.db.display(),
            shell(&self.db.display().to_string()),
            shell(m)
        )
    }
}

const LONG_ABOUT: &str = "\
The machine's history: the checks `rtest identify --record` put into an SQLite database (--db, \
default rtest-history.sqlite), and the trend of one error over them.

Without --machine-id: every machine id with its checks (id, measurement time, model, paths, \
residual RMS in µm, rank). With --machine-id ID: that machine's checks and the errors it can \
show. With --error NAME as well: that error's trend over the machine's comparable checks (same \
machine description, model, test paths and constraint; the others are listed as left out, with \
why) as a table with the flags of every check:

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
    let series = trend::select(all, id, error, args.baseline).map_err(trend_error)?;
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
