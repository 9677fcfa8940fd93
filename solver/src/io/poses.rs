//! Commanded poses: the axis words of a machine ([`AxisWord`]) and the CSV of commanded poses
//! ([`read_pose_csv`], [`PoseTable::write`]), read and written back with every other byte kept.
//!
//! A **commanded pose** is the command of every axis of the machine, in the order of
//! [`model_spec::Machine::axes`]: linear axes in mm, rotary axes in degrees, as the files hold
//! them (the caller converts to rad). The NC programs of [`crate::io::nc`] give the same poses.
//!
//! **The CSV** (`docs/nc-programs.md`):
//! - the header names one column per axis by its letter (`X,Y,Z,A,C` on `seed-ac`), in any order,
//!   matched without regard to case, spaces or double quotes around the name; every other column
//!   is kept as it is. A column named after an axis with a unit (`X_mm`, `A (deg)`) is not that
//!   axis: when the axis column is then missing, the message says so;
//! - the text is UTF-8 (a byte-order mark is kept), lines end with `\n` or `\r\n` (each line's
//!   own end is kept), no line is longer than [`MAX_LINE_BYTES`], the file has at most
//!   [`MAX_FILE_BYTES`];
//! - lines whose first non-blank character is `#`, and blank lines, are kept and not read;
//! - fields are separated by commas; a field may be quoted (`"a,b"`, `""` for a quote inside),
//!   but not across lines. An axis field is a plain decimal (`12.5`, `-0.25`, `1e-3`), with
//!   spaces or double quotes around it if the file has them;
//! - every row has as many fields as the header; at least one row.
//!
//! Written back, a row keeps every byte but the numbers of its axis fields, each replaced by the
//! shortest decimal that reads back to the same `f64` ([`format_scaled`]); a value equal (bit
//! for bit) to the one read keeps its text, so unchanged poses give an identical file.

use crate::io::csv::format_located;
use model_spec::text::{TextError, decode_text};
use model_spec::units::{format_scaled, parse_scaled};
use model_spec::{AxisKind, Machine};
use std::io::Read;
use std::path::Path;

/// The largest file of commanded poses (CSV or NC program) read, bytes (256 MiB): a five-axis
/// finishing program of several million blocks. The whole text is held, with the positions of
/// its numbers, while it is corrected.
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
    convert(m, commands, f64::to_degrees)
}

/// Commands as the computation takes them (mm, rad) from commands as the files hold them (mm,
/// degrees), one per axis of `m`.
pub fn from_file_units(m: &Machine, commands: &[f64]) -> Vec<f64> {
    convert(m, commands, f64::to_radians)
}

fn convert(m: &Machine, commands: &[f64], rotary: fn(f64) -> f64) -> Vec<f64> {
    commands
        .iter()
        .zip(&m.axes)
        .map(|(&q, a)| match a.kind {
            AxisKind::Rotary => rotary(q),
            AxisKind::Linear => q,
        })
        .collect()
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

/// A problem with a CSV of commanded poses, or with the poses given to write it back.
#[derive(Debug, thiserror::Error)]
pub enum PoseCsvError {
    /// The content is malformed; located by line and, where there is one, column (1-based
    /// index and header name).
    #[error("{}", format_located(file, *line, column, message))]
    Format {
        /// The file name, as given.
        file: String,
        /// 1-based line (every line counted).
        line: usize,
        /// The column: 1-based index and header name.
        column: Option<(usize, String)>,
        /// What is wrong.
        message: String,
    },
    /// The corrected poses given to [`PoseTable::write`] do not fit the file.
    #[error("{file}: cannot write the poses: {message}")]
    Write {
        /// The file name, as given.
        file: String,
        /// What is wrong.
        message: String,
    },
    /// The file could not be read as text (too large, not UTF-8, an I/O error).
    #[error(transparent)]
    Text(TextError),
}

/// Where the number of one axis field is in the text.
#[derive(Clone, Copy, Debug)]
struct NumberSpan {
    axis: usize,
    start: usize,
    end: usize,
}

/// A CSV of commanded poses as read: its text, its poses, and where each axis number stands.
#[derive(Clone, Debug)]
pub struct PoseTable {
    file: String,
    text: String,
    poses: Vec<CommandedPose>,
    axes: Vec<AxisWord>,
    /// `axes.len()` spans per pose, in the order of the fields in the row.
    spans: Vec<NumberSpan>,
}

/// The lines of `text`: (1-based number, byte offset of the line, the line without its end).
pub(crate) fn lines(text: &str) -> impl Iterator<Item = (usize, usize, &str)> {
    let mut offset = 0;
    text.split_inclusive('\n').enumerate().map(move |(i, raw)| {
        let start = offset;
        offset += raw.len();
        let body = raw.strip_suffix('\n').unwrap_or(raw);
        let body = body.strip_suffix('\r').unwrap_or(body);
        (i + 1, start, body)
    })
}

/// The line without a leading byte-order mark, and the bytes it had (0 or 3).
pub(crate) fn strip_bom(number: usize, line: &str) -> (&str, usize) {
    match line.strip_prefix('\u{feff}') {
        Some(rest) if number == 1 => (rest, 3),
        _ => (line, 0),
    }
}

/// The fields of a CSV line as byte ranges `(start, end)` within it, a quoted field with its
/// quotes; `Err(column)` (1-based field index) for a quote that does not close on the line or
/// is followed by something other than the separator.
fn split_fields(line: &str) -> Result<Vec<(usize, usize)>, usize> {
    let b = line.as_bytes();
    let mut fields = Vec::new();
    let mut start = 0;
    loop {
        let mut i = start;
        while i < b.len() && (b[i] == b' ' || b[i] == b'\t') {
            i += 1;
        }
        if i < b.len() && b[i] == b'"' {
            i += 1;
            loop {
                match b[i..].iter().position(|&c| c == b'"') {
                    None => return Err(fields.len() + 1),
                    Some(q) if b.get(i + q + 1) == Some(&b'"') => i += q + 2,
                    Some(q) => {
                        i += q + 1;
                        break;
                    }
                }
            }
            while i < b.len() && (b[i] == b' ' || b[i] == b'\t') {
                i += 1;
            }
            if i < b.len() && b[i] != b',' {
                return Err(fields.len() + 1);
            }
        } else {
            i += b[i..]
                .iter()
                .position(|&c| c == b',')
                .unwrap_or(b.len() - i);
        }
        fields.push((start, i));
        if i == b.len() {
            return Ok(fields);
        }
        start = i + 1;
    }
}

/// A header name without spaces and double quotes around it.
fn clean_name(s: &str) -> &str {
    let s = s.trim();
    s.strip_prefix('"')
        .and_then(|s| s.strip_suffix('"'))
        .unwrap_or(s)
        .trim()
}

/// Whether header name `name` looks like axis `letter` with a unit (`X_mm`, `A (deg)`, `c[°]`).
fn unit_spelling(name: &str, letter: char) -> bool {
    let mut chars = name.chars();
    if !chars
        .next()
        .is_some_and(|c| c.eq_ignore_ascii_case(&letter))
    {
        return false;
    }
    let rest: String = chars
        .filter(|c| !matches!(c, ' ' | '_' | '-' | '(' | ')' | '[' | ']' | '/' | '.'))
        .collect::<String>()
        .to_lowercase();
    matches!(
        rest.as_str(),
        "mm" | "deg" | "degree" | "degrees" | "°" | "um" | "µm" | "rad" | "in" | "inch"
    )
}

/// Reads the CSV of commanded poses `text` (named `file_name` in messages) for the axes `axes`:
/// the poses, each with its line, commands in the order of `axes` (see the module
/// documentation for the format).
///
/// # Errors
/// [`PoseCsvError::Format`] for the first problem, with its line and, where there is one, its
/// column: no header, a missing or repeated axis column, a quote that does not close, a row
/// with a different number of fields, an axis field that is empty, not a decimal, not finite or
/// not below [`MAX_COMMAND`] in magnitude, a line longer than [`MAX_LINE_BYTES`], no row;
/// [`PoseCsvError::Text`] for a text longer than [`MAX_FILE_BYTES`].
pub fn read_pose_csv(
    file_name: &str,
    text: &str,
    axes: &[AxisWord],
) -> Result<PoseTable, PoseCsvError> {
    let err = |line: usize, column: Option<(usize, &str)>, message: String| PoseCsvError::Format {
        file: file_name.to_string(),
        line,
        column: column.map(|(i, n)| (i, n.to_string())),
        message,
    };
    if text.len() as u64 > MAX_FILE_BYTES {
        return Err(PoseCsvError::Text(TextError::TooLarge {
            file: file_name.to_string(),
            limit: MAX_FILE_BYTES,
        }));
    }
    let mut header: Option<(usize, Vec<String>, Vec<Option<usize>>)> = None;
    let mut poses = Vec::new();
    let mut spans = Vec::new();
    for (number, offset, raw) in lines(text) {
        if raw.len() > MAX_LINE_BYTES {
            return Err(err(
                number,
                None,
                format!("line longer than {MAX_LINE_BYTES} bytes: not a CSV of commanded poses"),
            ));
        }
        let (line, bom) = strip_bom(number, raw);
        let trimmed = line.trim();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        let fields = split_fields(line).map_err(|i| {
            err(
                number,
                None,
                format!("field {i}: a quoted field must close on its line and be followed by a comma or the line end"),
            )
        })?;
        let Some((header_line, names, columns)) = &header else {
            header = Some(parse_header(file_name, number, line, &fields, axes)?);
            continue;
        };
        if fields.len() != names.len() {
            return Err(err(
                number,
                None,
                format!(
                    "{} field(s), the header (line {header_line}) has {} columns",
                    fields.len(),
                    names.len()
                ),
            ));
        }
        let mut commands = vec![0.0; axes.len()];
        for (i, (&(s, e), axis)) in fields.iter().zip(columns).enumerate() {
            let Some(a) = *axis else { continue };
            let column = Some((i + 1, names[i].as_str()));
            let (start, end) = number_in_field(line, s, e);
            let t = &line[start..end];
            let what = if t.is_empty() {
                "empty".to_string()
            } else {
                format!("`{t}` is not a decimal number")
            };
            let x = parse_scaled(t, 0)
                .filter(|x| x.is_finite())
                .ok_or_else(|| {
                    err(
                        number,
                        column,
                        format!("{what} ({}, {})", axes[a].letter, axes[a].unit()),
                    )
                })?;
            if x.abs() >= MAX_COMMAND {
                return Err(err(
                    number,
                    column,
                    format!(
                        "{t} {} is beyond ±{MAX_COMMAND} (no axis command reaches it)",
                        axes[a].unit()
                    ),
                ));
            }
            commands[a] = x;
            spans.push(NumberSpan {
                axis: a,
                start: offset + bom + start,
                end: offset + bom + end,
            });
        }
        poses.push(CommandedPose {
            line: number,
            commands,
        });
    }
    let Some((header_line, ..)) = header else {
        return Err(err(
            lines(text).count().max(1),
            None,
            "no header: the first line that is not a comment names the columns".into(),
        ));
    };
    if poses.is_empty() {
        return Err(err(
            header_line,
            None,
            "a header and no pose: nothing to read".into(),
        ));
    }
    Ok(PoseTable {
        file: file_name.to_string(),
        text: text.to_string(),
        poses,
        axes: axes.to_vec(),
        spans,
    })
}

/// The number inside field `line[s..e]`: without the spaces and double quotes around it.
fn number_in_field(line: &str, s: usize, e: usize) -> (usize, usize) {
    let field = &line[s..e];
    let lead = field.len() - field.trim_start().len();
    let inner = field.trim();
    let (mut a, mut b) = (s + lead, s + lead + inner.len());
    if inner.len() >= 2 && inner.starts_with('"') && inner.ends_with('"') {
        let q = &line[a + 1..b - 1];
        a += 1 + (q.len() - q.trim_start().len());
        b = a + q.trim().len();
    }
    (a, b)
}

/// The header at line `number`: its names, and the axis each column holds.
#[allow(clippy::type_complexity)]
fn parse_header(
    file: &str,
    number: usize,
    line: &str,
    fields: &[(usize, usize)],
    axes: &[AxisWord],
) -> Result<(usize, Vec<String>, Vec<Option<usize>>), PoseCsvError> {
    let names: Vec<String> = fields
        .iter()
        .map(|&(s, e)| clean_name(&line[s..e]).to_string())
        .collect();
    let mut columns: Vec<Option<usize>> = Vec::with_capacity(names.len());
    for (i, name) in names.iter().enumerate() {
        let mut chars = name.chars();
        let axis = match (chars.next(), chars.next()) {
            (Some(c), None) => axes.iter().position(|a| a.letter.eq_ignore_ascii_case(&c)),
            _ => None,
        };
        if let Some(a) = axis
            && let Some(j) = columns.iter().position(|&c| c == Some(a))
        {
            return Err(PoseCsvError::Format {
                file: file.to_string(),
                line: number,
                column: Some((i + 1, name.clone())),
                message: format!(
                    "axis {} has two columns (also column {})",
                    axes[a].letter,
                    j + 1
                ),
            });
        }
        columns.push(axis);
    }
    let missing: Vec<usize> = (0..axes.len())
        .filter(|a| !columns.contains(&Some(*a)))
        .collect();
    if let Some(&a) = missing.first() {
        let letter = axes[a].letter;
        let hint = names
            .iter()
            .position(|n| unit_spelling(n, letter))
            .map(|i| {
                format!(
                    "; column {} `{}` is not read as it: name the column `{letter}` exactly ({} for this axis)",
                    i + 1,
                    names[i],
                    axes[a].unit()
                )
            })
            .unwrap_or_default();
        let list: Vec<String> = missing
            .iter()
            .map(|&a| axes[a].letter.to_string())
            .collect();
        return Err(PoseCsvError::Format {
            file: file.to_string(),
            line: number,
            column: None,
            message: format!(
                "missing axis column(s) {}: the header needs one column per axis ({}), named by its letter{hint}",
                list.join(", "),
                letters(axes)
            ),
        });
    }
    Ok((number, names, columns))
}

impl PoseTable {
    /// The poses, in the order of the rows.
    pub fn poses(&self) -> &[CommandedPose] {
        &self.poses
    }

    /// The file name given to the reader.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// The text of the file with the axis fields of pose `i` replaced by `corrected[i]` (mm and
    /// degrees, in the order of the axis words), each the shortest decimal that reads back to
    /// the same `f64`. A value equal, bit for bit, to the one read keeps its text; every other
    /// byte (other columns, quotes, spaces, comments, line ends) is kept.
    ///
    /// # Errors
    /// [`PoseCsvError::Write`] when `corrected` does not hold one pose per row, a pose does not
    /// hold one value per axis, or a value is not finite or not below [`MAX_COMMAND`].
    pub fn write(&self, corrected: &[Vec<f64>]) -> Result<String, PoseCsvError> {
        let fail = |message: String| PoseCsvError::Write {
            file: self.file.clone(),
            message,
        };
        if corrected.len() != self.poses.len() {
            return Err(fail(format!(
                "{} corrected poses for {} rows",
                corrected.len(),
                self.poses.len()
            )));
        }
        let mut out = String::with_capacity(self.text.len() + self.text.len() / 4);
        let mut at = 0;
        for (k, (pose, c)) in self.poses.iter().zip(corrected).enumerate() {
            let n = self.axes.len();
            if c.len() != n {
                return Err(fail(format!(
                    "the pose of line {} has {} values for {n} axes",
                    pose.line,
                    c.len(),
                )));
            }
            for span in &self.spans[k * n..(k + 1) * n] {
                let x = c[span.axis];
                out.push_str(&self.text[at..span.start]);
                if x.to_bits() == pose.commands[span.axis].to_bits() {
                    out.push_str(&self.text[span.start..span.end]);
                } else if !x.is_finite() || x.abs() >= MAX_COMMAND {
                    return Err(fail(format!(
                        "line {}: axis {} would be {x} {}, beyond ±{MAX_COMMAND}",
                        pose.line,
                        self.axes[span.axis].letter,
                        self.axes[span.axis].unit()
                    )));
                } else {
                    out.push_str(&format_scaled(x, 0));
                }
                at = span.end;
            }
        }
        out.push_str(&self.text[at..]);
        Ok(out)
    }
}

/// Reads the CSV of commanded poses at `path` (at most [`MAX_FILE_BYTES`], UTF-8; named in
/// messages as `path.display()` writes it); see [`read_pose_csv`].
///
/// # Errors
/// As [`read_pose_csv`]; [`PoseCsvError::Text`] when the file cannot be read, is too large or
/// is not UTF-8.
pub fn read_pose_file(path: &Path, axes: &[AxisWord]) -> Result<PoseTable, PoseCsvError> {
    let text = read_keeping_bom(path).map_err(PoseCsvError::Text)?;
    read_pose_csv(&path.display().to_string(), &text, axes)
}

/// The text of the file at `path`, at most [`MAX_FILE_BYTES`], UTF-8, with its byte-order mark
/// (if it has one) kept as the first character, so that the file written back keeps it too.
pub(crate) fn read_keeping_bom(path: &Path) -> Result<String, TextError> {
    let file = path.display().to_string();
    let io = |error| TextError::Io {
        file: file.clone(),
        error,
    };
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .map_err(io)?
        .take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(TextError::TooLarge {
            file,
            limit: MAX_FILE_BYTES,
        });
    }
    let bom = bytes.starts_with(b"\xef\xbb\xbf");
    let text = decode_text(&file, bytes)?;
    Ok(if bom { format!("\u{feff}{text}") } else { text })
}
