//! Path files: the commanded samples of a test, as a CSV in the measurement format
//! ([`crate::csv`]), or a built-in test of the machine by name
//! ([`simulation::paths`]).
//!
//! A path file has its rotary columns (degrees), optionally its linear columns (filled by the
//! nominal tool-centre-point inverse kinematics when absent), `t_s` optional, measured columns
//! optional and ignored. It is read by the same bounded line reader and checked as a
//! measurement file is (nest on the ball when the linear axes are given, strokes and ranges,
//! and the plausibility of the readings when there are any), under the same [`ReadOptions`].

use crate::csv::{CsvError, Need, ReadOptions, read_csv};
use model_spec::Machine;
use simulation::generator;
use simulation::paths::{PathError, builtin_path, test_names};
use simulation::record::Record;

/// Why a path could not be made or read.
#[derive(Debug, thiserror::Error)]
pub enum PathFileError {
    /// A built-in path that cannot be made.
    #[error(transparent)]
    Builtin(#[from] PathError),
    /// Neither a test of the machine nor an existing file.
    #[error("`{name}` is neither a test of machine {machine} ({tests}) nor an existing file")]
    NotFound {
        /// The name given.
        name: String,
        /// The machine.
        machine: String,
        /// Its tests, comma-separated (`no tests: it has no rotary axis`).
        tests: String,
    },
    /// The path file is malformed or unreadable.
    #[error("{0}")]
    Csv(#[from] CsvError),
}

/// A path given by the name of a test of `m` ([`builtin_path`]) or by the name of a CSV file,
/// read with `opts` (a built-in path is made, not read: `opts` do not apply to it).
///
/// # Errors
/// [`PathFileError::NotFound`] when it is neither; see [`builtin_path`] and [`read_path`].
pub fn load_path(
    m: &Machine,
    name_or_file: &str,
    opts: &ReadOptions,
) -> Result<Record, PathFileError> {
    if let Some(r) = builtin_path(m, name_or_file) {
        return Ok(r?);
    }
    let path = std::path::Path::new(name_or_file);
    // Anything that exists and is not a directory is read (a file, a FIFO, a link to one).
    if !path.exists() || path.is_dir() {
        return Err(PathFileError::NotFound {
            name: name_or_file.to_string(),
            machine: m.name.clone(),
            tests: test_names(&generator::tests(m)),
        });
    }
    let f = std::fs::File::open(path).map_err(|source| CsvError::Io {
        file: name_or_file.to_string(),
        source,
    })?;
    Ok(read_path(name_or_file, f, m, opts)?)
}

/// Reads a path CSV (text `text`, named `file` in messages) of machine `m`; see [`read_path`].
///
/// # Errors
/// As [`read_path`].
pub fn parse_path(
    file: &str,
    text: &str,
    m: &Machine,
    opts: &ReadOptions,
) -> Result<Record, CsvError> {
    read_path(file, text.as_bytes(), m, opts)
}

/// Reads a path CSV of machine `m` from `reader` (named `file` in messages): a record without
/// measurements (commands in mm and rad, times in s; see the module documentation).
///
/// # Errors
/// [`CsvError::Format`] naming the line and column of the first problem (a line too long or
/// not UTF-8 included); [`CsvError::Refused`] for poses off the ball or off the strokes, or
/// implausible readings; [`CsvError::Io`] when `reader` fails.
pub fn read_path<R: std::io::Read>(
    file: &str,
    reader: R,
    m: &Machine,
    opts: &ReadOptions,
) -> Result<Record, CsvError> {
    let mut r = read_csv(file, reader, m, Need::Path, opts)?;
    r.measured.clear();
    Ok(r)
}
