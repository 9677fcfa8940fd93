//! What can go wrong with a history database. Every message names the file.

use rusqlite::ErrorCode;
use std::path::Path;

/// A failure of the history database.
#[derive(Debug, thiserror::Error)]
pub enum HistoryError {
    /// No database at that path (reading a history that was never recorded).
    #[error(
        "{file}: no history database there (rtest identify --record --db {} creates it)",
        report::text::shell(file)
    )]
    NotFound {
        /// The path.
        file: String,
    },
    /// A file that is not an rtest history database, or one that is damaged: it is left as it
    /// is, never changed or repaired.
    #[error("{file}: not a readable rtest history database: {reason}; the file was left as it is")]
    NotHistory {
        /// The path.
        file: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A database written by a newer rtest (a schema version this one does not know).
    #[error(
        "{file}: written by a newer rtest (schema version {version}; this rtest knows versions up to {known}); the file was left as it is"
    )]
    Newer {
        /// The path.
        file: String,
        /// Its schema version.
        version: i32,
        /// The newest version this rtest knows.
        known: i32,
    },
    /// A check that cannot be recorded (an empty machine id, a path label with a comma, …).
    #[error("{file}: cannot record the check: {message}")]
    Invalid {
        /// The path.
        file: String,
        /// What is wrong with the check.
        message: String,
    },
    /// Any other failure of the database or the file system (locked beyond the busy timeout,
    /// a directory that does not exist, a read-only file, a full disk).
    #[error("{file}: {message}")]
    Failed {
        /// The path.
        file: String,
        /// What failed.
        message: String,
    },
}

impl HistoryError {
    /// The error of an SQLite call on the database at `file`: a damaged file is
    /// [`HistoryError::NotHistory`], anything else [`HistoryError::Failed`].
    pub fn sqlite(file: &Path, e: rusqlite::Error) -> HistoryError {
        let file = file.display().to_string();
        match e.sqlite_error_code() {
            Some(ErrorCode::NotADatabase) => HistoryError::NotHistory {
                file,
                reason: "it is not an SQLite database".into(),
            },
            Some(ErrorCode::DatabaseCorrupt) => HistoryError::NotHistory {
                file,
                reason: format!("it is damaged ({e})"),
            },
            Some(ErrorCode::DatabaseBusy | ErrorCode::DatabaseLocked) => HistoryError::Failed {
                file,
                message: format!(
                    "the database stayed locked by another process for more than {} s ({e})",
                    crate::store::BUSY_TIMEOUT.as_secs()
                ),
            },
            Some(ErrorCode::ReadOnly) => HistoryError::Failed {
                file,
                message: format!("the database cannot be written ({e})"),
            },
            _ => HistoryError::Failed {
                file,
                message: e.to_string(),
            },
        }
    }

    /// An I/O error on `file`, with what was being done.
    pub fn io(file: &Path, doing: &str, e: &std::io::Error) -> HistoryError {
        HistoryError::Failed {
            file: file.display().to_string(),
            message: format!("cannot {doing}: {e}"),
        }
    }

    /// A damaged or foreign file.
    pub fn not_history(file: &Path, reason: impl Into<String>) -> HistoryError {
        HistoryError::NotHistory {
            file: file.display().to_string(),
            reason: reason.into(),
        }
    }
}
