//! Commanded poses: the axis words of a machine ([`AxisWord`]), the poses of a file held flat
//! ([`PoseList`], at most [`MAX_POSES`]), and the CSV of commanded poses ([`read_pose_csv`],
//! [`PoseTable::writer`]), read and written back with every other byte kept.
//!
//! A **commanded pose** is the command of every axis of the machine, in the order of
//! [`model_spec::Machine::axes`]: linear axes in mm, rotary axes in degrees, as the files hold
//! them (the caller converts to rad). The NC programs of [`crate::nc`] give the same poses.
//!
//! Files: `list` (the flat list of poses, the limit on their number), `table` (the CSV).

mod list;
mod table;

pub(crate) use list::read_flat;
pub use list::{MAX_POSES, PoseList};
pub use table::{PoseCsvError, PoseTable, TableWriter, read_pose_csv, read_pose_file};

use model_spec::sha256::Digest;
use model_spec::text::{TextError, decode_text};
use model_spec::{AxisKind, Machine};
use std::path::Path;

/// The largest file of commanded poses (CSV or NC program) read, bytes (256 MiB): a five-axis
/// finishing program of several million blocks. The whole text is held while it is corrected,
/// with its poses ([`PoseList`]).
pub const MAX_FILE_BYTES: u64 = 256 << 20;

/// The longest line, bytes, without its line end (64 KiB, as in the measurement CSV). No NC
/// control accepts blocks of that length.
pub const MAX_LINE_BYTES: usize = 65_536;

/// The largest magnitude of an axis command read or written, mm or degrees (exclusive): the
/// longest stroke a machine description may have ([`model_spec::limits::MAX_LENGTH_MM`]), and
/// the five digits before the decimal point of the axis words of ISO and Heidenhain controls.
pub const MAX_COMMAND: f64 = model_spec::limits::MAX_LENGTH_MM;

/// One axis as commanded poses name it: its letter and whether its commands are mm or degrees.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AxisWord {
    /// The axis letter, upper case (`X`, `A`, …).
    pub letter: char,
    /// Linear (commands in mm) or rotary (degrees).
    pub kind: AxisKind,
}

impl AxisWord {
    /// The unit of the axis's commands in files: `mm` or `deg`.
    pub fn unit(&self) -> &'static str {
        match self.kind {
            AxisKind::Linear => "mm",
            AxisKind::Rotary => "deg",
        }
    }
}

/// Commands as the files hold them (mm, degrees) from commands as the computation takes them
/// (mm, rad), one per axis of `m`.
pub fn to_file_units(m: &Machine, commands: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; commands.len().min(m.axes.len())];
    to_file_units_into(m, commands, &mut out);
    out
}

/// Commands as the computation takes them (mm, rad) from commands as the files hold them (mm,
/// degrees), one per axis of `m`.
pub fn from_file_units(m: &Machine, commands: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; commands.len().min(m.axes.len())];
    from_file_units_into(m, commands, &mut out);
    out
}

/// [`to_file_units`] into `out` (one value per axis of `m`).
pub fn to_file_units_into(m: &Machine, commands: &[f64], out: &mut [f64]) {
    convert(m, commands, out, f64::to_degrees);
}

/// [`from_file_units`] into `out` (one value per axis of `m`).
pub fn from_file_units_into(m: &Machine, commands: &[f64], out: &mut [f64]) {
    convert(m, commands, out, f64::to_radians);
}

fn convert(m: &Machine, commands: &[f64], out: &mut [f64], rotary: fn(f64) -> f64) {
    for ((o, &q), a) in out.iter_mut().zip(commands).zip(&m.axes) {
        *o = match a.kind {
            AxisKind::Rotary => rotary(q),
            AxisKind::Linear => q,
        };
    }
}

/// The axis words of machine `m`, in the order of [`Machine::axes`] (the order of every
/// [`CommandedPose::commands`]).
pub fn axis_words(m: &Machine) -> Vec<AxisWord> {
    m.axes
        .iter()
        .map(|a| AxisWord {
            // A validated axis name is one upper-case ASCII letter.
            letter: a.name.chars().next().unwrap_or('?'),
            kind: a.kind,
        })
        .collect()
}

/// The letters of `axes`, `X, Y, Z, A, C`, for messages.
pub(crate) fn letters(axes: &[AxisWord]) -> String {
    axes.iter()
        .map(|a| a.letter.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// One commanded pose of a file: where it is and what it commands.
#[derive(Clone, Debug, PartialEq)]
pub struct CommandedPose {
    /// 1-based line of the file that holds the pose (every line counted).
    pub line: usize,
    /// The command of every axis, in the order of the axis words given to the reader: mm for
    /// linear axes, degrees for rotary axes.
    pub commands: Vec<f64>,
}

/// The lines of `text`: (1-based number, byte offset of the line, the line without its end).
pub(crate) fn lines(text: &str) -> Lines<'_> {
    Lines {
        text,
        offset: 0,
        number: 0,
    }
}

/// The iterator of [`lines`].
pub(crate) struct Lines<'a> {
    text: &'a str,
    /// Byte offset of the next line.
    offset: usize,
    /// The number of the line given last.
    number: usize,
}

impl<'a> Iterator for Lines<'a> {
    type Item = (usize, usize, &'a str);

    fn next(&mut self) -> Option<Self::Item> {
        let rest = &self.text[self.offset..];
        if rest.is_empty() {
            return None;
        }
        let start = self.offset;
        let raw = match rest.find('\n') {
            Some(i) => &rest[..i + 1],
            None => rest,
        };
        self.offset += raw.len();
        self.number += 1;
        let body = raw.strip_suffix('\n').unwrap_or(raw);
        let body = body.strip_suffix('\r').unwrap_or(body);
        Some((self.number, start, body))
    }
}

/// The line without a leading byte-order mark, and the bytes it had (0 or 3).
pub(crate) fn strip_bom(number: usize, line: &str) -> (&str, usize) {
    match line.strip_prefix('\u{feff}') {
        Some(rest) if number == 1 => (rest, 3),
        _ => (line, 0),
    }
}

/// The text of the file at `path`, at most [`MAX_FILE_BYTES`], UTF-8, with its byte-order mark
/// (if it has one) kept as the first character, so that the file written back keeps it too;
/// and the digest of the bytes read (the file is opened once).
///
/// # Errors
/// [`TextError`]: the file cannot be read, is larger than [`MAX_FILE_BYTES`], or not UTF-8.
pub fn read_keeping_bom(path: &Path) -> Result<(String, Digest), TextError> {
    let (bytes, digest) = model_spec::text::read_bytes_hashed(path, MAX_FILE_BYTES)?;
    let bom = bytes.starts_with(b"\xef\xbb\xbf");
    let mut text = decode_text(&path.display().to_string(), bytes)?;
    if bom {
        text.insert(0, '\u{feff}');
    }
    text.shrink_to_fit();
    Ok((text, digest))
}
