//! The history database: an SQLite file holding every recorded check.
//!
//! Recording is one immediate transaction per check (the check's row, its terms, paths, input
//! files, parameters and unidentifiable groups, all or nothing), in WAL mode with a busy
//! timeout of [`BUSY_TIMEOUT`]: several processes recording into one file at once wait for
//! each other and lose nothing. [`Store::stage`] inserts a check without committing it, so a
//! caller can commit only once its own outputs are written; dropping the [`Staged`] check rolls
//! it back.

mod open;
mod read;
mod reading;

pub use open::BUSY_TIMEOUT;
pub use read::{MachineSummary, RecordedCheck};

use crate::check::Check;
use crate::error::HistoryError;
use rusqlite::{Connection, Transaction, TransactionBehavior, params};
use std::path::{Path, PathBuf};

/// The file name of the history database when none is given, in the working directory.
pub const DEFAULT_FILE: &str = "rtest-history.sqlite";

/// An open history database.
#[derive(Debug)]
pub struct Store {
    conn: Connection,
    path: PathBuf,
}

/// A check inserted in an open transaction: [`Staged::commit`] records it, dropping it records
/// nothing.
#[derive(Debug)]
pub struct Staged<'a> {
    tx: Transaction<'a>,
    id: i64,
    path: &'a Path,
}

impl Staged<'_> {
    /// The id the check gets once committed.
    pub fn id(&self) -> i64 {
        self.id
    }

    /// Commits the check; returns its id.
    ///
    /// # Errors
    /// [`HistoryError`] when the commit fails (nothing is recorded then).
    pub fn commit(self) -> Result<i64, HistoryError> {
        let path = self.path;
        self.tx
            .commit()
            .map_err(|e| HistoryError::sqlite(path, e))?;
        Ok(self.id)
    }
}

fn count(n: usize) -> i64 {
    i64::try_from(n).unwrap_or(i64::MAX)
}

impl Store {
    /// Opens the existing database at `path` (checked, migrated to the current schema).
    ///
    /// # Errors
    /// [`HistoryError::NotFound`] when there is no file; [`HistoryError::NotHistory`] for a
    /// file that is not an rtest history database or is damaged (it is left unchanged);
    /// [`HistoryError::Newer`]; [`HistoryError::Failed`].
    pub fn open(path: &Path) -> Result<Store, HistoryError> {
        Ok(Store {
            conn: open::open_existing(path)?,
            path: path.to_path_buf(),
        })
    }

    /// Opens the existing database at `path` for reading: as [`Store::open`] where that works,
    /// else (a directory or file system one may not write) through a read-only connection, so
    /// that such a history can be read. Recording through a read-only store fails
    /// ([`HistoryError::Failed`], the database cannot be written).
    ///
    /// # Errors
    /// Those of [`Store::open`]; [`HistoryError::Failed`] for an older schema that cannot be
    /// migrated (it needs write access).
    pub fn open_for_reading(path: &Path) -> Result<Store, HistoryError> {
        Ok(Store {
            conn: open::open_for_reading(path)?,
            path: path.to_path_buf(),
        })
    }

    /// Opens the database at `path`, making a new, empty one when there is no file there.
    ///
    /// # Errors
    /// Those of [`Store::open`]; [`HistoryError::Failed`] when the file cannot be made.
    pub fn open_or_create(path: &Path) -> Result<Store, HistoryError> {
        Ok(Store {
            conn: open::open_or_create(path)?,
            path: path.to_path_buf(),
        })
    }

    /// The database's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn sql(&self) -> impl Fn(rusqlite::Error) -> HistoryError + '_ {
        |e| HistoryError::sqlite(&self.path, e)
    }

    /// Records `check` in one transaction; returns its id.
    ///
    /// # Errors
    /// [`HistoryError::Invalid`] for a check that [`Check::validate`] refuses; a database
    /// failure.
    pub fn record(&mut self, check: &Check) -> Result<i64, HistoryError> {
        self.stage(check)?.commit()
    }

    /// Inserts `check` in an open immediate transaction, without committing it.
    ///
    /// # Errors
    /// As [`Store::record`].
    pub fn stage(&mut self, check: &Check) -> Result<Staged<'_>, HistoryError> {
        let Store { conn, path } = self;
        let path: &Path = path;
        check.validate().map_err(|message| HistoryError::Invalid {
            file: path.display().to_string(),
            message,
        })?;
        let sql = |e| HistoryError::sqlite(path, e);
        let tx = conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .map_err(sql)?;
        let id = insert(&tx, check).map_err(sql)?;
        Ok(Staged { tx, id, path })
    }

    /// The number of checks recorded.
    ///
    /// # Errors
    /// A database failure.
    pub fn count(&self) -> Result<usize, HistoryError> {
        let n: i64 = self
            .conn
            .query_row("SELECT count(*) FROM checks", [], |r| r.get(0))
            .map_err(self.sql())?;
        Ok(usize::try_from(n).unwrap_or(0))
    }
}

/// Inserts every row of `check`; returns its id.
fn insert(tx: &Transaction<'_>, c: &Check) -> rusqlite::Result<i64> {
    tx.execute(
        "INSERT INTO checks (machine_id, fingerprint, machine, model, base_model, recorded_at,
             measured_at, rtest_version, kind, rank, free_parameters, condition, residual_rms_um,
             sigma_um, samples, dof, zeroed, constraint_text, refinement, noise_model, recheck)
         VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15, ?16, ?17, ?18,
                 ?19, ?20, ?21)",
        params![
            c.machine_id,
            c.fingerprint,
            c.machine,
            c.model,
            c.base_model,
            c.recorded_at.to_string(),
            c.measured_at.to_string(),
            c.rtest_version,
            c.kind.as_str(),
            count(c.rank),
            count(c.free_parameters),
            c.condition,
            c.residual_rms_um,
            c.sigma_um,
            count(c.samples),
            count(c.dof),
            c.zeroed,
            c.constraint,
            c.refinement,
            c.noise_model,
            c.recheck,
        ],
    )?;
    let id = tx.last_insert_rowid();
    let mut term = tx.prepare("INSERT INTO check_terms VALUES (?1, ?2, ?3)")?;
    for (i, t) in c.terms.iter().enumerate() {
        term.execute(params![id, count(i), t])?;
    }
    let mut path = tx.prepare("INSERT INTO check_paths VALUES (?1, ?2, ?3)")?;
    for (i, p) in c.paths.iter().enumerate() {
        path.execute(params![id, count(i), p])?;
    }
    let mut input = tx.prepare("INSERT INTO check_inputs VALUES (?1, ?2, ?3, ?4, ?5, ?6)")?;
    for (i, f) in c.inputs.iter().enumerate() {
        let bytes = i64::try_from(f.bytes).unwrap_or(i64::MAX);
        input.execute(params![id, count(i), f.role, f.path, bytes, f.sha256])?;
    }
    let mut parameter = tx.prepare(
        "INSERT INTO parameters VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12)",
    )?;
    for (i, q) in c.parameters.iter().enumerate() {
        parameter.execute(params![
            id,
            count(i),
            q.name,
            q.error,
            q.basis,
            q.owner,
            q.of,
            q.value,
            q.std,
            q.unit,
            q.determined,
            q.fixed,
        ])?;
    }
    let mut group = tx.prepare("INSERT INTO unidentifiable VALUES (?1, ?2, ?3, ?4)")?;
    for (g, names) in c.unidentifiable.iter().enumerate() {
        for (i, n) in names.iter().enumerate() {
            group.execute(params![id, count(g), count(i), n])?;
        }
    }
    Ok(id)
}
