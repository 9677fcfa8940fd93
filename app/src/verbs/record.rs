//! The `--record` flags of `rtest identify` and the recorder that puts a check into the
//! history database once every output is written (docs/history.md).

use super::{Error, ReadFile, VerbResult};
use history::{Check, HistoryError, InputFile, Provenance, Staged, Store, Timestamp};
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
