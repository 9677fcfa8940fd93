//! Opening a history database: a new one is made whole in a temporary file and linked into
//! place (so no process ever sees a half-made or empty database); an existing one is checked
//! through a read-only connection (SQLite's magic, the application id, the schema version,
//! `PRAGMA quick_check`, the tables) before anything is written to it, and a damaged or
//! foreign file is refused and left as it is. Older schema versions are migrated, each
//! migration in one transaction.

use crate::error::HistoryError;
use crate::schema::{APPLICATION_ID, MIGRATIONS, TABLES, VERSION};
use rusqlite::{Connection, OpenFlags, TransactionBehavior};
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// How long a connection waits for another process's write transaction before it gives up.
pub const BUSY_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(60);

/// The first 16 bytes of every SQLite 3 database file.
const MAGIC: &[u8; 16] = b"SQLite format 3\0";

type Res<T> = Result<T, HistoryError>;

/// Opens the existing database at `path` for recording and reading: checked, migrated to the
/// current schema, in WAL mode, with the busy timeout.
///
/// # Errors
/// [`HistoryError::NotFound`] when there is no file, [`HistoryError::NotHistory`] for a file
/// that is not an rtest history database or is damaged, [`HistoryError::Newer`] for a newer
/// schema, [`HistoryError::Failed`] for anything else.
pub(crate) fn open_existing(path: &Path) -> Res<Connection> {
    check_file(path)?;
    check_contents(path)?;
    let sql = |e| HistoryError::sqlite(path, e);
    let mut conn = Connection::open_with_flags(
        path,
        OpenFlags::SQLITE_OPEN_READ_WRITE | OpenFlags::SQLITE_OPEN_NO_MUTEX,
    )
    .map_err(sql)?;
    conn.busy_timeout(BUSY_TIMEOUT).map_err(sql)?;
    migrate(path, &mut conn)?;
    let mode: String = conn
        .pragma_query_value(None, "journal_mode", |r| r.get(0))
        .map_err(sql)?;
    if !mode.eq_ignore_ascii_case("wal") {
        let set: String = conn
            .pragma_update_and_check(None, "journal_mode", "WAL", |r| r.get(0))
            .map_err(sql)?;
        if !set.eq_ignore_ascii_case("wal") {
            return Err(HistoryError::Failed {
                file: path.display().to_string(),
                message: format!("cannot switch the database to WAL mode (it stays `{set}`)"),
            });
        }
    }
    conn.pragma_update(None, "foreign_keys", true)
        .map_err(sql)?;
    Ok(conn)
}

/// Opens the existing database at `path` for reading: as [`open_existing`] opens it where
/// that works (so an older schema is migrated and SQLite's files beside it are removed when
/// it closes), else, at the current schema version, through a read-only connection that
/// writes nothing and reads in a directory one may not write ([`super::reading::connect`]).
///
/// # Errors
/// Those of [`open_existing`] (a `-wal`, `-shm` or `-journal` beside the database that is not
/// a regular file is [`HistoryError::Failed`] in either case); where it fails, an older schema (its migration needs write
/// access) is [`HistoryError::Failed`] saying so, and so is a read-only connection that
/// fails too.
pub(crate) fn open_for_reading(path: &Path) -> Res<Connection> {
    // A log beside the database that SQLite cannot open is refused here too: the read-only
    // connection would read the database without it.
    check_companions(path)?;
    let written = match open_existing(path) {
        Err(HistoryError::Failed { file, message }) => (file, message),
        other => return other,
    };
    let sql = |e| HistoryError::sqlite(path, e);
    let conn = super::reading::connect(path).map_err(sql)?;
    conn.busy_timeout(BUSY_TIMEOUT).map_err(sql)?;
    let version: i32 = conn
        .pragma_query_value(None, "user_version", |r| r.get(0))
        .map_err(sql)?;
    if version < VERSION {
        let (file, message) = written;
        return Err(HistoryError::Failed {
            file,
            message: format!(
                "the database has schema version {version}, older than this rtest's {VERSION}; reading it needs a migration, which needs write access: {message}"
            ),
        });
    }
    Ok(conn)
}

/// Opens the database at `path`, making a new one first when there is no file there.
///
/// # Errors
/// Those of [`open_existing`]; [`HistoryError::Failed`] when the new file cannot be made.
pub(crate) fn open_or_create(path: &Path) -> Res<Connection> {
    match std::fs::symlink_metadata(path) {
        Ok(_) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => create(path)?,
        Err(e) => return Err(HistoryError::io(path, "read the file's metadata", &e)),
    }
    open_existing(path)
}

/// Refuses what is plainly not a database before SQLite opens it: a missing file, a directory,
/// an empty file (this rtest never leaves one), or a file without SQLite's magic.
fn check_file(path: &Path) -> Res<()> {
    let meta = match std::fs::metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(HistoryError::NotFound {
                file: path.display().to_string(),
            });
        }
        Err(e) => return Err(HistoryError::io(path, "read the file's metadata", &e)),
    };
    if meta.is_dir() {
        return Err(HistoryError::not_history(path, "it is a directory"));
    }
    if !meta.is_file() {
        return Err(HistoryError::not_history(path, "it is not a regular file"));
    }
    if meta.len() == 0 {
        return Err(HistoryError::not_history(
            path,
            "it is empty (0 bytes); a history database is never empty: remove the file to start a new history",
        ));
    }
    check_companions(path)?;
    let mut head = Vec::with_capacity(100);
    std::fs::File::open(path)
        .and_then(|f| f.take(100).read_to_end(&mut head))
        .map_err(|e| HistoryError::io(path, "read the file", &e))?;
    if head.len() < 100 || &head[..16] != MAGIC {
        return Err(HistoryError::not_history(
            path,
            "it is not an SQLite database (no SQLite header)",
        ));
    }
    Ok(())
}

/// Refuses the files SQLite keeps beside a database (`-wal`, `-shm`, `-journal`) when one is
/// there but is not a regular file: SQLite opens none of them through a symbolic link, and
/// would say only "unable to open database file" or "attempt to write a readonly database".
fn check_companions(path: &Path) -> Res<()> {
    for (suffix, what) in [
        ("-wal", "write-ahead log"),
        ("-shm", "shared-memory file"),
        ("-journal", "rollback journal"),
    ] {
        let side = beside(path, suffix);
        let Ok(meta) = std::fs::symlink_metadata(&side) else {
            continue;
        };
        let kind = if meta.file_type().is_symlink() {
            let to = std::fs::read_link(&side)
                .map_or_else(|_| String::new(), |t| format!(" (to `{}`)", t.display()));
            format!("a symbolic link{to}")
        } else if meta.is_dir() {
            "a directory".to_string()
        } else if meta.is_file() {
            continue;
        } else {
            "not a regular file".to_string()
        };
        return Err(HistoryError::Failed {
            file: path.display().to_string(),
            message: format!(
                "SQLite's {what} beside it, `{}`, is {kind}: SQLite opens only a regular file there; move it away (the database's own {what} is a regular file that SQLite made)",
                side.display()
            ),
        });
    }
    Ok(())
}

/// What the raw header says of a damaged file: its page size and page count against the
/// file's length (a truncated file is shorter than its header says).
fn header_note(path: &Path) -> String {
    let Ok(bytes) = std::fs::read(path) else {
        return String::new();
    };
    if bytes.len() < 100 {
        return String::new();
    }
    let raw = u32::from(u16::from_be_bytes([bytes[16], bytes[17]]));
    let page = if raw == 1 { 65_536 } else { raw };
    let word =
        |at: usize| u32::from_be_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let len = bytes.len() as u64;
    let pages = u64::from(word(28));
    if word(24) == word(92) && pages > 0 && len < pages * u64::from(page) {
        format!(
            "; its header counts {pages} pages of {page} bytes ({} bytes) but the file has {len} bytes: it was truncated",
            pages * u64::from(page)
        )
    } else if page >= 512 && !len.is_multiple_of(u64::from(page)) {
        format!("; its length ({len} bytes) is not a whole number of its {page}-byte pages")
    } else {
        String::new()
    }
}

/// The path of SQLite's file `suffix` (`-wal`, `-shm`) beside the database at `path`.
pub(super) fn beside(path: &Path, suffix: &str) -> PathBuf {
    let mut side = path.as_os_str().to_owned();
    side.push(suffix);
    PathBuf::from(side)
}

/// Checks, through a read-only connection, that the file is an rtest history database that is
/// not damaged and whose version this rtest can read. A refused file is left as it was: the
/// empty write-ahead log and the shared-memory file that SQLite makes beside a WAL database
/// when it opens one are removed again if they were not there before.
fn check_contents(path: &Path) -> Res<()> {
    let (wal, shm) = (beside(path, "-wal"), beside(path, "-shm"));
    let (had_wal, had_shm) = (wal.exists(), shm.exists());
    let checked = read_only_checks(path);
    if checked.is_err() {
        if !had_wal && std::fs::metadata(&wal).is_ok_and(|m| m.len() == 0) {
            let _ = std::fs::remove_file(&wal);
        }
        if !had_shm && !wal.exists() {
            let _ = std::fs::remove_file(&shm);
        }
    }
    checked
}

/// The checks of [`check_contents`], on a connection closed when this returns.
fn read_only_checks(path: &Path) -> Res<()> {
    let damaged = |e: rusqlite::Error| match HistoryError::sqlite(path, e) {
        HistoryError::NotHistory { file, reason } => HistoryError::NotHistory {
            file,
            reason: reason + &header_note(path),
        },
        other => other,
    };
    let conn = super::reading::connect(path).map_err(damaged)?;
    conn.busy_timeout(BUSY_TIMEOUT).map_err(damaged)?;
    let id: i32 = conn
        .pragma_query_value(None, "application_id", |r| r.get(0))
        .map_err(damaged)?;
    if id != APPLICATION_ID {
        return Err(HistoryError::not_history(
            path,
            format!(
                "it is an SQLite database of another program (application id {id:#010x}, not {APPLICATION_ID:#010x})"
            ),
        ));
    }
    let mut problems: Vec<String> = Vec::new();
    conn.pragma_query(None, "quick_check", |r| {
        problems.push(r.get(0)?);
        Ok(())
    })
    .map_err(damaged)?;
    if problems.len() != 1 || problems[0] != "ok" {
        let first = problems.first().cloned().unwrap_or_default();
        return Err(HistoryError::not_history(
            path,
            format!("it is damaged (quick_check: {first}){}", header_note(path)),
        ));
    }
    let version: i32 = conn
        .pragma_query_value(None, "user_version", |r| r.get(0))
        .map_err(damaged)?;
    if version > VERSION {
        return Err(HistoryError::Newer {
            file: path.display().to_string(),
            version,
            known: VERSION,
        });
    }
    if version < 1 {
        return Err(HistoryError::not_history(
            path,
            format!("its schema version is {version}"),
        ));
    }
    check_tables(path, &conn, version)
}

/// The tables a database of `version` has.
fn check_tables(path: &Path, conn: &Connection, version: i32) -> Res<()> {
    let mut stmt = conn
        .prepare("SELECT name FROM sqlite_master WHERE type = 'table' ORDER BY name")
        .map_err(|e| HistoryError::sqlite(path, e))?;
    let names: Vec<String> = stmt
        .query_map([], |r| r.get(0))
        .and_then(Iterator::collect)
        .map_err(|e| HistoryError::sqlite(path, e))?;
    // Every version so far has the same tables; version 2 added a column.
    let _ = version;
    for t in TABLES {
        if !names.iter().any(|n| n == t) {
            return Err(HistoryError::not_history(
                path,
                format!("it lacks the table `{t}`"),
            ));
        }
    }
    Ok(())
}

/// Brings the database to [`VERSION`]: the missing migrations in order, each in an immediate
/// transaction that also sets `user_version` (two processes opening an old file at once
/// migrate it once: the second finds the new version inside its transaction).
fn migrate(path: &Path, conn: &mut Connection) -> Res<()> {
    let sql = |e| HistoryError::sqlite(path, e);
    let version: i32 = conn
        .pragma_query_value(None, "user_version", |r| r.get(0))
        .map_err(sql)?;
    if version >= VERSION {
        // Nothing to write: a read-only file stays readable.
        return Ok(());
    }
    loop {
        let tx = conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .map_err(sql)?;
        let version: i32 = tx
            .pragma_query_value(None, "user_version", |r| r.get(0))
            .map_err(sql)?;
        if version >= VERSION {
            return tx.commit().map_err(sql);
        }
        tx.execute_batch(MIGRATIONS[version as usize])
            .map_err(sql)?;
        tx.pragma_update(None, "user_version", version + 1)
            .map_err(sql)?;
        tx.commit().map_err(sql)?;
    }
}

/// A fresh name for a temporary file beside `path`.
fn temporary_beside(path: &Path) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    let name = path
        .file_name()
        .map_or_else(|| "history".into(), |n| n.to_string_lossy().into_owned());
    path.with_file_name(format!(
        ".{name}.rtest-{}-{n}-{nanos:09}.tmp",
        std::process::id()
    ))
}

/// Removes a temporary database and what SQLite may have left beside it.
fn remove_temporary(tmp: &Path) {
    let _ = std::fs::remove_file(tmp);
    for suffix in ["-wal", "-shm", "-journal"] {
        let _ = std::fs::remove_file(beside(tmp, suffix));
    }
}

/// Makes a new database at `path`: the whole schema in a temporary file beside it, then a
/// hard link to `path` (which never replaces a file another process made meanwhile: that one is
/// used instead).
fn create(path: &Path) -> Res<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        return Err(HistoryError::Failed {
            file: path.display().to_string(),
            message: format!(
                "cannot create the database: the directory `{}` does not exist",
                dir.display()
            ),
        });
    }
    let tmp = temporary_beside(path);
    let made = build(&tmp);
    let linked = made.and_then(|()| match std::fs::hard_link(&tmp, path) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Ok(()),
        Err(e) => Err(HistoryError::io(path, "create the database", &e)),
    });
    remove_temporary(&tmp);
    linked
}

/// The whole current schema in a new file at `tmp`, in WAL mode, closed.
fn build(tmp: &Path) -> Res<()> {
    let fail = |e: rusqlite::Error| HistoryError::Failed {
        file: tmp.display().to_string(),
        message: format!("cannot create the database: {e}"),
    };
    let mut conn = Connection::open_with_flags(
        tmp,
        OpenFlags::SQLITE_OPEN_READ_WRITE
            | OpenFlags::SQLITE_OPEN_CREATE
            | OpenFlags::SQLITE_OPEN_NO_MUTEX,
    )
    .map_err(fail)?;
    conn.pragma_update(None, "application_id", APPLICATION_ID)
        .map_err(fail)?;
    let tx = conn.transaction().map_err(fail)?;
    for m in MIGRATIONS {
        tx.execute_batch(m).map_err(fail)?;
    }
    tx.pragma_update(None, "user_version", VERSION)
        .map_err(fail)?;
    tx.commit().map_err(fail)?;
    conn.pragma_update_and_check(None, "journal_mode", "WAL", |r| r.get::<_, String>(0))
        .map_err(fail)?;
    conn.close().map_err(|(_, e)| fail(e))
}
