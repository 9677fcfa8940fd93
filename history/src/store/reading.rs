//! Read-only connections: for the checks before anything is written, and for the verbs that
//! only read (`rtest history`), so that a history on a read-only file system, in a directory
//! one may not write, or of a file one may only read, can be read.
//!
//! SQLite reads a WAL database through its shared-memory file (`-shm`) beside it, which it
//! makes when it is missing. Where it cannot be made (a read-only directory) and no
//! write-ahead log (`-wal`) is there (the last connection closed cleanly, so everything is in
//! the database file), the file is opened `immutable`: read as it is, without the
//! shared-memory file or locks (<https://www.sqlite.org/wal.html>, "Read-Only Databases";
//! <https://www.sqlite.org/uri.html>, `immutable`). With a write-ahead log present, only a
//! connection that can use the shared-memory file reads it correctly, so that case stays an
//! error.

use rusqlite::{Connection, ErrorCode, OpenFlags};
use std::path::Path;

/// A read-only connection to the database at `path`, tried at once (a first read of the
/// header), immutable where the directory does not let SQLite make its shared-memory file
/// and no write-ahead log exists.
pub(crate) fn connect(path: &Path) -> Result<Connection, rusqlite::Error> {
    let flags = OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX;
    let tried = Connection::open_with_flags(path, flags).and_then(|c| {
        c.pragma_query_value(None, "schema_version", |r| r.get::<_, i64>(0))?;
        Ok(c)
    });
    match tried {
        Err(e)
            if matches!(
                e.sqlite_error_code(),
                Some(ErrorCode::ReadOnly | ErrorCode::CannotOpen)
            ) && !super::open::beside(path, "-wal").exists() =>
        {
            Connection::open_with_flags(immutable_uri(path), flags | OpenFlags::SQLITE_OPEN_URI)
        }
        other => other,
    }
}

/// The URI `file:PATH?immutable=1`, every byte of the path but unreserved ones and `/`
/// percent-encoded (RFC 3986), so that `?`, `#` or `%` in a file name stay part of it.
fn immutable_uri(path: &Path) -> String {
    let mut uri = String::from("file:");
    for &b in path.as_os_str().as_encoded_bytes() {
        if b.is_ascii_alphanumeric() || b"-._~/".contains(&b) {
            uri.push(char::from(b));
        } else {
            uri.push_str(&format!("%{b:02X}"));
        }
    }
    uri.push_str("?immutable=1");
    uri
}

#[cfg(test)]
mod tests {
    use super::immutable_uri;
    use std::path::Path;

    #[test]
    fn a_path_is_percent_encoded_in_the_uri() {
        assert_eq!(
            immutable_uri(Path::new("/tmp/a b/h?#%.sqlite")),
            "file:/tmp/a%20b/h%3F%23%25.sqlite?immutable=1"
        );
        assert_eq!(
            immutable_uri(Path::new("rel/ü.db")),
            "file:rel/%C3%BC.db?immutable=1"
        );
    }
}
