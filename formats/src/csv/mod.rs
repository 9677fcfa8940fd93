//! The R-test measurement CSV (docs/conventions.md): read and written.
//!
//! One row a sample; the header names the columns, in any order:
//! - one column per axis of the machine, named after it (`X,Y,Z,A,C` for `seed-ac`): linear
//!   axes in mm, rotary axes in degrees. Rotary columns are required; the linear columns are
//!   all present or all missing, and when missing they are filled by the machine's nominal
//!   tool-centre-point inverse kinematics with its default kinematic parameters
//!   ([`simulation::paths::fill_linear_ik`]);
//! - `dx_um,dy_um,dz_um`: the measured error vector (tool minus workpiece, tool frame, µm),
//!   required in a measurement file, optional (all three or none) in a path file;
//! - `t_s` (optional): time since the start, s, finite and non-decreasing. Without it, sample
//!   `i` (0-based) is taken at `t = i` s.
//!
//! The text is UTF-8 (a byte-order mark at the start is accepted), lines end with `\n` or
//! `\r\n`, and no line is longer than [`ReadOptions::max_line_bytes`] (64 KiB by default): the
//! readers never hold more of a line, so an endless stream without line ends is refused after
//! that many bytes. Column names are matched without regard to case and surrounding spaces (or
//! double quotes). Lines whose first non-blank character is `#` are comments, blank lines are
//! skipped. Fields are separated by commas, without quoting. Every other deviation is a
//! [`CsvError::Format`] naming the file, the line and, where there is one, the column (1-based
//! index and header name, or the character position in a line that is not UTF-8).
//!
//! Well-formed samples must still be an R-test record of the machine ([`CsvError::Refused`]
//! otherwise, with how many samples or readings offend and the first few by line; the block
//! reader checks each block, so it lists those of the first block that has any):
//! - when the file gives the linear axes, each pose puts the nominal tool point on the nominal
//!   workpiece point (the sensor nest on the ball) within [`ReadOptions::on_ball_tolerance_mm`]
//!   (0.5 mm), at the machine's default kinematic parameters. In an R-test record the linear
//!   axes follow the ball and the readings are the small error vector; leaving the linear
//!   columns out has them filled by the inverse kinematics;
//! - every pose, linear axes filled, lies within the machine's strokes (mm) and ranges
//!   (degrees), inclusive to within 1e-9 of the axis unit, unless
//!   [`ReadOptions::allow_off_stroke`];
//! - every reading lies within ±[`ReadOptions::max_reading_mm`] (1000 µm) in each direction.
//!
//! Numbers are converted without double rounding: a µm value is read by moving the decimal
//! point of its text three places ([`model_spec::units::parse_scaled`]), and written as the shortest decimal of the
//! mm value with the point moved back ([`model_spec::units::format_scaled`]), so write → read gives the same bits.
//! Degrees are written as the shortest decimal whose `to_radians()` is the command; every
//! command that was itself read from degrees (files, built-in paths) round-trips bit for bit.
//!
//! This module formats the text ([`format_record`]); the command line writes files through its
//! `output` crate.
//!
//! Files: `lines` (the bounded line reader), `read` (header and rows), `whole` and `blocks`
//! (the two readers), `checks` (what samples must satisfy), `write`; the exact number conversions are
//! [`model_spec::units::exact`].

mod blocks;
pub(crate) mod checks;
pub(crate) mod lines;
pub(crate) mod read;
mod rows;
mod whole;
mod write;

pub use blocks::{FIRST_LOOKAHEAD, MeasurementBlocks, time_span};
pub use checks::LISTED;
pub use lines::Lines;
pub use lines::READ_BUFFER_BYTES;
use model_spec::catalogue::iso_rank;
use model_spec::{AxisKind, Machine};
use simulation::record::Record;
use std::path::Path;
pub use whole::{parse_csv, read_csv};
pub use write::{comment_lines, format_record};

/// How the readers judge a file: the bounds of what they accept.
///
/// `ReadOptions::default()` (or [`ReadOptions::new`]) is what the command line uses; set the
/// fields to change one (`let mut o = ReadOptions::new(); o.allow_off_stroke = true;`).
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq)]
pub struct ReadOptions {
    /// Largest magnitude of a reading (each of `dx`, `dy`, `dz`), mm; beyond it the file is
    /// refused. Default 1.0 mm (1000 µm): an R-test reads a small error vector.
    /// `f64::INFINITY` turns the check off.
    pub max_reading_mm: f64,
    /// Accept poses outside the machine's strokes (mm) and ranges (degrees). Default `false`.
    pub allow_off_stroke: bool,
    /// Largest distance between the nominal tool point and the nominal workpiece point, mm,
    /// when the file gives the linear axes. Default 0.5 mm. `f64::INFINITY` turns the check
    /// off.
    pub on_ball_tolerance_mm: f64,
    /// Longest line, bytes (its line end not counted). Default 65 536. The readers never hold
    /// more of a line, and read at most this plus [`READ_BUFFER_BYTES`] of a longer one.
    pub max_line_bytes: usize,
    /// Called with the bytes read of the source so far, for a progress bar. Default `None`.
    pub progress: Option<crate::progress::ReadProgress>,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            max_reading_mm: 1.0,
            allow_off_stroke: false,
            on_ball_tolerance_mm: simulation::pose::ON_BALL_TOLERANCE_MM,
            max_line_bytes: 65_536,
            progress: None,
        }
    }
}

impl ReadOptions {
    /// The default options (see the fields).
    pub fn new() -> Self {
        ReadOptions::default()
    }
}

/// Opens `path` for one of the CSV readers: its name as messages give it (`path.display()`)
/// and the file, or [`CsvError::Io`] naming it.
///
/// # Errors
/// [`CsvError::Io`] when the file cannot be opened.
pub fn open(path: &std::path::Path) -> Result<(String, std::fs::File), CsvError> {
    let file = path.display().to_string();
    match std::fs::File::open(path) {
        Ok(f) => Ok((file, f)),
        Err(source) => Err(CsvError::Io { file, source }),
    }
}

/// A problem with a CSV file.
#[derive(Debug, thiserror::Error)]
pub enum CsvError {
    /// The content is malformed; located by line and, where there is one, column.
    #[error("{}", format_located(file, *line, column, message))]
    Format {
        /// The file name.
        file: String,
        /// 1-based line number in the file (comment lines counted).
        line: usize,
        /// The column: 1-based index and header name.
        column: Option<(usize, String)>,
        /// What is wrong.
        message: String,
    },
    /// Well-formed samples that cannot be an R-test record of the machine: nest off the ball,
    /// poses outside the strokes, implausible readings (see the module documentation).
    #[error("{file}: {message}")]
    Refused {
        /// The file name.
        file: String,
        /// How many samples (poses) or readings offend (in the block, for the block reader).
        count: usize,
        /// The 1-based lines of the offending samples listed in the message (the first few, at
        /// most [`LISTED`], each once).
        lines: Vec<usize>,
        /// What is wrong, with the offending samples listed by line.
        message: String,
    },
    /// A record that cannot be written (not a file problem: a programming error reported).
    #[error("cannot write the record: {0}")]
    Record(String),
    /// A line that is not UTF-8 text, located at its first byte that is not.
    #[error(transparent)]
    Text(model_spec::text::TextError),
    /// The file could not be read.
    #[error("cannot read `{file}`: {source}")]
    Io {
        /// The file name.
        file: String,
        /// Why.
        source: std::io::Error,
    },
}

/// `file:line: column N `NAME`: message`, or `file:line: message` without a column: how every
/// CSV error of rtest is located.
pub fn format_located(
    file: &str,
    line: usize,
    column: &Option<(usize, String)>,
    message: &str,
) -> String {
    match column {
        Some((i, name)) => format!("{file}:{line}: column {i} `{name}`: {message}"),
        None => format!("{file}:{line}: {message}"),
    }
}

/// What a column holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Col {
    Axis(usize),
    Time,
    Measured(usize),
    /// A column a caller asked for beside the machine's (a sensor's readings, µm).
    Extra(usize),
}

pub(crate) const MEASURED: [&str; 3] = ["dx_um", "dy_um", "dz_um"];

/// Whether the `dx_um,dy_um,dz_um` columns must be there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Need {
    /// A measurement file: required.
    Measured,
    /// A path file: optional (all three or none); read if present.
    Path,
}

/// Where a reader is, for its messages: the file as named in them.
pub struct Ctx<'a> {
    /// The file, as given.
    pub file: &'a str,
}

impl Ctx<'_> {
    /// A format error at 1-based `line` and, when known, 0-based `column` with its name.
    pub fn err(
        &self,
        line: usize,
        column: Option<(usize, &str)>,
        msg: impl Into<String>,
    ) -> CsvError {
        CsvError::Format {
            file: self.file.to_string(),
            line,
            column: column.map(|(i, n)| (i + 1, n.to_string())),
            message: msg.into(),
        }
    }
}

/// Reads a measurement CSV (text `text`, named `file` in messages) of machine `m`: commands in
/// mm and rad, measured error vectors in mm, times in s (see the module documentation).
///
/// # Errors
/// [`CsvError::Format`] for the first problem: empty file, header only, unknown, duplicate or
/// missing column, ragged row, text or a non-finite number where a number belongs, time going
/// backwards, inverse kinematics without a solution, a line too long; [`CsvError::Refused`]
/// for samples off the ball, off the strokes or with implausible readings.
pub fn parse_measurement(
    file: &str,
    text: &str,
    m: &Machine,
    opts: &ReadOptions,
) -> Result<Record, CsvError> {
    parse_csv(file, text, m, Need::Measured, opts)
}

/// Reads the measurement CSV file `path` of machine `m` through the bounded line reader (the
/// file is never read whole into memory as text); see [`parse_measurement`].
///
/// # Errors
/// As [`parse_measurement`]; [`CsvError::Io`] when the file cannot be opened or read.
pub fn read_measurement(path: &Path, m: &Machine, opts: &ReadOptions) -> Result<Record, CsvError> {
    let (file, f) = crate::csv::open(path)?;
    read_csv(&file, f, m, Need::Measured, opts)
}

/// A header field without its blanks and surrounding double quotes.
pub fn clean_name(s: &str) -> &str {
    let s = s.trim();
    s.strip_prefix('"')
        .and_then(|s| s.strip_suffix('"'))
        .unwrap_or(s)
        .trim()
}

pub(crate) fn classify(m: &Machine, name: &str) -> Option<Col> {
    if let Some(a) = m
        .axes
        .iter()
        .position(|a| a.name.eq_ignore_ascii_case(name))
    {
        return Some(Col::Axis(a));
    }
    if name.eq_ignore_ascii_case("t_s") {
        return Some(Col::Time);
    }
    MEASURED
        .iter()
        .position(|c| c.eq_ignore_ascii_case(name))
        .map(Col::Measured)
}

/// The axes in the order columns are written: linear, then rotary, each in ISO order
/// (`X,Y,Z,A,C` for `seed-ac`).
pub fn column_order(m: &Machine) -> Vec<usize> {
    let mut axes: Vec<usize> = (0..m.axes.len()).collect();
    axes.sort_by_key(|&a| {
        (
            m.axes[a].kind == AxisKind::Rotary,
            iso_rank(&m.axes[a].name),
        )
    });
    axes
}

pub(crate) fn expected_columns(m: &Machine) -> String {
    let mut v: Vec<String> = column_order(m)
        .into_iter()
        .map(|a| {
            let unit = match m.axes[a].kind {
                AxisKind::Linear => "mm",
                AxisKind::Rotary => "deg",
            };
            format!("{} ({unit})", m.axes[a].name)
        })
        .collect();
    v.extend(MEASURED.iter().map(|s| s.to_string()));
    v.push("t_s".into());
    format!("columns of machine {}: {}", m.name, v.join(", "))
}
