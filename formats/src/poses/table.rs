//! The CSV of commanded poses: read into its poses ([`read_pose_csv`]) and written back with
//! every byte kept but the axis numbers ([`PoseTable::writer`]).
//!
//! The format (`docs/nc-programs.md`):
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
//! - every row has as many fields as the header; at least one row, at most [`MAX_POSES`].
//!
//! Written back, a row keeps every byte but the numbers of its axis fields, each replaced by the
//! shortest decimal that reads back to the same `f64` ([`format_scaled`]); a value equal (bit
//! for bit) to the one read keeps its text, so unchanged poses give an identical file.
//!
//! The table holds its text and its poses ([`PoseList`]), nothing per field: the writer reads
//! the rows again (the same reading, so the same fields) to find the numbers it replaces.

use crate::csv::format_located;
use crate::poses::{
    AxisWord, CommandedPose, Lines, MAX_COMMAND, MAX_FILE_BYTES, MAX_LINE_BYTES, MAX_POSES,
    PoseList, letters, lines, read_flat, read_keeping_bom, strip_bom,
};
use model_spec::text::TextError;
use model_spec::units::{format_scaled, parse_scaled};
use std::path::Path;

/// A problem with a CSV of commanded poses, or with the poses given to write it back.
#[derive(Debug, thiserror::Error)]
pub enum PoseCsvError {
    /// The content is malformed, or holds more than [`MAX_POSES`] rows; located by line and,
    /// where there is one, column (1-based index and header name).
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
    /// The corrected poses given to [`PoseTable::writer`] do not fit the file.
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

/// A CSV of commanded poses as read: its text and its poses.
#[derive(Clone, Debug)]
pub struct PoseTable {
    file: String,
    text: String,
    axes: Vec<AxisWord>,
    poses: PoseList,
}

/// The number of one axis field of a row: the axis, its byte range in the text, its value.
#[derive(Clone, Copy, Debug)]
struct AxisNumber {
    axis: usize,
    start: usize,
    end: usize,
    value: f64,
}

/// The header of the CSV: its line, its column names, the axis each column holds.
struct Header {
    line: usize,
    names: Vec<String>,
    columns: Vec<Option<usize>>,
}

/// The rows of a CSV of commanded poses, read one at a time with every check of the format:
/// what the reader and the writer both go through, so that the writer finds the numbers the
/// reader read.
struct Rows<'a> {
    file: &'a str,
    axes: &'a [AxisWord],
    lines: Lines<'a>,
    header: Option<Header>,
}

impl<'a> Rows<'a> {
    fn new(file: &'a str, text: &'a str, axes: &'a [AxisWord]) -> Self {
        Rows {
            file,
            axes,
            lines: lines(text),
            header: None,
        }
    }

    fn err(&self, line: usize, column: Option<(usize, &str)>, message: String) -> PoseCsvError {
        PoseCsvError::Format {
            file: self.file.to_string(),
            line,
            column: column.map(|(i, n)| (i, n.to_string())),
            message,
        }
    }

    /// The next row: its line, and its axis numbers into `numbers` (in the order of the
    /// fields); `None` after the last line.
    fn next(&mut self, numbers: &mut Vec<AxisNumber>) -> Result<Option<usize>, PoseCsvError> {
        numbers.clear();
        while let Some((number, offset, raw)) = self.lines.next() {
            if raw.len() > MAX_LINE_BYTES {
                return Err(self.err(
                    number,
                    None,
                    format!(
                        "line longer than {MAX_LINE_BYTES} bytes: not a CSV of commanded poses"
                    ),
                ));
            }
            let (line, bom) = strip_bom(number, raw);
            let trimmed = line.trim();
            if trimmed.is_empty() || trimmed.starts_with('#') {
                continue;
            }
            let fields = split_fields(line).map_err(|i| {
                self.err(
                    number,
                    None,
                    format!("field {i}: a quoted field must close on its line and be followed by a comma or the line end"),
                )
            })?;
            let Some(header) = &self.header else {
                self.header = Some(parse_header(self.file, number, line, &fields, self.axes)?);
                continue;
            };
            if fields.len() != header.names.len() {
                return Err(self.err(
                    number,
                    None,
                    format!(
                        "{} field(s), the header (line {}) has {} columns",
                        fields.len(),
                        header.line,
                        header.names.len()
                    ),
                ));
            }
            for (i, (&(s, e), axis)) in fields.iter().zip(&header.columns).enumerate() {
                let Some(a) = *axis else { continue };
                let column = Some((i + 1, header.names[i].as_str()));
                let (start, end) = number_in_field(line, s, e);
                let t = &line[start..end];
                let unit = self.axes[a].unit();
                let what = if t.is_empty() {
                    "empty".to_string()
                } else {
                    format!("`{t}` is not a decimal number")
                };
                let x = parse_scaled(t, 0)
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| {
                        self.err(
                            number,
                            column,
                            format!("{what} ({}, {unit})", self.axes[a].letter),
                        )
                    })?;
                if x.abs() >= MAX_COMMAND {
                    return Err(self.err(
                        number,
                        column,
                        format!("{t} {unit} is beyond ±{MAX_COMMAND} (no axis command reaches it)"),
                    ));
                }
                numbers.push(AxisNumber {
                    axis: a,
                    start: offset + bom + start,
                    end: offset + bom + end,
                    value: x,
                });
            }
            return Ok(Some(number));
        }
        Ok(None)
    }
}

/// Reads the CSV of commanded poses `text` (named `file_name` in messages) for the axes `axes`:
/// the poses, each with its line, commands in the order of `axes` (see the module
/// documentation for the format).
///
/// # Errors
/// [`PoseCsvError::Format`] for the first problem, with its line and, where there is one, its
/// column: no header, a missing or repeated axis column, a quote that does not close, a row
/// with a different number of fields, an axis field that is empty, not a decimal, not finite or
/// not below [`MAX_COMMAND`] in magnitude, a line longer than [`MAX_LINE_BYTES`], no row, more
/// than [`MAX_POSES`] rows; [`PoseCsvError::Text`] for a text longer than [`MAX_FILE_BYTES`].
pub fn read_pose_csv(
    file_name: &str,
    text: &str,
    axes: &[AxisWord],
) -> Result<PoseTable, PoseCsvError> {
    read_table(file_name, text.to_string(), axes, MAX_POSES)
}

/// [`read_pose_csv`] of a text the table keeps, with at most `max_poses` rows.
fn read_table(
    file_name: &str,
    text: String,
    axes: &[AxisWord],
    max_poses: usize,
) -> Result<PoseTable, PoseCsvError> {
    if text.len() as u64 > MAX_FILE_BYTES {
        return Err(PoseCsvError::Text(TextError::TooLarge {
            file: file_name.to_string(),
            limit: MAX_FILE_BYTES,
        }));
    }
    let too_many = |line: usize| PoseCsvError::Format {
        file: file_name.to_string(),
        line,
        column: None,
        message: format!(
            "more than {max_poses} rows of poses: rtest reads at most {max_poses} poses from one file; split it"
        ),
    };
    let mut header_line = None;
    let poses = read_flat(&text, axes.len(), max_poses, too_many, |pose| {
        let mut rows = Rows::new(file_name, &text, axes);
        let mut numbers = Vec::with_capacity(axes.len());
        let mut commands = vec![0.0; axes.len()];
        while let Some(line) = rows.next(&mut numbers)? {
            for n in &numbers {
                commands[n.axis] = n.value;
            }
            pose(line, &commands)?;
        }
        header_line = rows.header.map(|h| h.line);
        Ok(())
    })?;
    let err = |line: usize, message: &str| PoseCsvError::Format {
        file: file_name.to_string(),
        line,
        column: None,
        message: message.to_string(),
    };
    let Some(header_line) = header_line else {
        return Err(err(
            lines(&text).count().max(1),
            "no header: the first line that is not a comment names the columns",
        ));
    };
    if poses.is_empty() {
        return Err(err(header_line, "a header and no pose: nothing to read"));
    }
    Ok(PoseTable {
        file: file_name.to_string(),
        text,
        axes: axes.to_vec(),
        poses,
    })
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
fn parse_header(
    file: &str,
    number: usize,
    line: &str,
    fields: &[(usize, usize)],
    axes: &[AxisWord],
) -> Result<Header, PoseCsvError> {
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
    Ok(Header {
        line: number,
        names,
        columns,
    })
}

impl PoseTable {
    /// The poses, in the order of the rows, held flat.
    pub fn pose_list(&self) -> &PoseList {
        &self.poses
    }

    /// The poses, in the order of the rows, each copied out with a vector of its own
    /// ([`PoseList::to_poses`]): for short files and tests; [`PoseTable::pose_list`] holds
    /// them without a copy.
    pub fn poses(&self) -> Vec<CommandedPose> {
        self.poses.to_poses()
    }

    /// The file name given to the reader.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// The bytes the table holds on the heap: its text, its poses (8 bytes per axis and 4 per
    /// pose), its file name and axes. Besides the text, 44 bytes a pose of five axes.
    pub fn held_bytes(&self) -> usize {
        self.text.capacity()
            + self.poses.held_bytes()
            + self.file.capacity()
            + self.axes.capacity() * size_of::<AxisWord>()
    }

    /// A writer of the file with corrected poses, given one at a time in the order of the rows
    /// ([`TableWriter::pose`]): the way to write a long file without holding its corrected
    /// poses.
    pub fn writer(&self) -> TableWriter<'_> {
        TableWriter {
            table: self,
            rows: Rows::new(&self.file, &self.text, &self.axes),
            numbers: Vec::with_capacity(self.axes.len()),
            out: String::with_capacity(self.text.len() + self.text.len() / 4),
            at: 0,
            given: 0,
        }
    }

    /// The text of the file with the axis fields of pose `i` replaced by `corrected[i]`: every
    /// pose given to [`PoseTable::writer`] in turn.
    ///
    /// # Errors
    /// [`PoseCsvError::Write`] when `corrected` does not hold one pose per row; as
    /// [`TableWriter::pose`].
    pub fn write(&self, corrected: &[Vec<f64>]) -> Result<String, PoseCsvError> {
        if corrected.len() != self.poses.len() {
            return Err(self.write_err(format!(
                "{} corrected poses for {} rows",
                corrected.len(),
                self.poses.len()
            )));
        }
        let mut w = self.writer();
        for c in corrected {
            w.pose(c)?;
        }
        w.finish()
    }

    fn write_err(&self, message: String) -> PoseCsvError {
        PoseCsvError::Write {
            file: self.file.clone(),
            message,
        }
    }
}

/// A CSV of commanded poses being written back, pose after pose ([`PoseTable::writer`]).
pub struct TableWriter<'a> {
    table: &'a PoseTable,
    rows: Rows<'a>,
    numbers: Vec<AxisNumber>,
    out: String,
    /// Byte of the text up to which `out` holds it.
    at: usize,
    /// Poses given.
    given: usize,
}

impl TableWriter<'_> {
    /// Writes the next row with its axis fields replaced by `corrected` (mm and degrees, in the
    /// order of the axis words), each the shortest decimal that reads back to the same `f64`.
    /// A value equal, bit for bit, to the one read keeps its text; every other byte (other
    /// columns, quotes, spaces, comments, line ends) is kept.
    ///
    /// # Errors
    /// [`PoseCsvError::Write`] for a pose beyond the last row, a pose that does not hold one
    /// value per axis, or a value that is not finite or not below [`MAX_COMMAND`].
    pub fn pose(&mut self, corrected: &[f64]) -> Result<(), PoseCsvError> {
        let t = self.table;
        let n = t.axes.len();
        let Some(line) = self.rows.next(&mut self.numbers)? else {
            return Err(t.write_err(format!(
                "more corrected poses than the {} rows",
                t.poses.len()
            )));
        };
        self.given += 1;
        if corrected.len() != n {
            return Err(t.write_err(format!(
                "the pose of line {line} has {} values for {n} axes",
                corrected.len(),
            )));
        }
        for number in &self.numbers {
            let x = corrected[number.axis];
            self.out.push_str(&t.text[self.at..number.start]);
            if x.to_bits() == number.value.to_bits() {
                self.out.push_str(&t.text[number.start..number.end]);
            } else if !x.is_finite() || x.abs() >= MAX_COMMAND {
                let axis = t.axes[number.axis];
                return Err(t.write_err(format!(
                    "line {line}: axis {} would be {x} {}, beyond ±{MAX_COMMAND}",
                    axis.letter,
                    axis.unit()
                )));
            } else {
                self.out.push_str(&format_scaled(x, 0));
            }
            self.at = number.end;
        }
        Ok(())
    }

    /// The whole text written back.
    ///
    /// # Errors
    /// [`PoseCsvError::Write`] when fewer poses were given than the file has rows.
    pub fn finish(mut self) -> Result<String, PoseCsvError> {
        let t = self.table;
        if self.given != t.poses.len() {
            return Err(t.write_err(format!(
                "{} corrected poses for {} rows",
                self.given,
                t.poses.len()
            )));
        }
        self.out.push_str(&t.text[self.at..]);
        Ok(self.out)
    }
}

/// Reads the CSV of commanded poses at `path` (at most [`MAX_FILE_BYTES`], UTF-8; named in
/// messages as `path.display()` writes it); see [`read_pose_csv`].
///
/// # Errors
/// As [`read_pose_csv`]; [`PoseCsvError::Text`] when the file cannot be read, is too large or
/// is not UTF-8.
pub fn read_pose_file(path: &Path, axes: &[AxisWord]) -> Result<PoseTable, PoseCsvError> {
    let (text, _) = read_keeping_bom(path).map_err(PoseCsvError::Text)?;
    read_table(&path.display().to_string(), text, axes, MAX_POSES)
}

#[cfg(test)]
mod tests {
    use super::*;
    use model_spec::AxisKind::{Linear, Rotary};

    #[test]
    fn a_table_over_the_pose_limit_is_refused() {
        let axes = [
            AxisWord {
                letter: 'X',
                kind: Linear,
            },
            AxisWord {
                letter: 'C',
                kind: Rotary,
            },
        ];
        let text = "# poses\nid,X,C\n1,0,0\n2,0,1\n\n3,0,2\n";
        let t = read_table("p.csv", text.into(), &axes, 3).unwrap();
        assert_eq!(t.pose_list().line(2), 6);
        for max in [2, 1] {
            let e = read_table("p.csv", text.into(), &axes, max).unwrap_err();
            assert_eq!(
                e.to_string(),
                format!(
                    "p.csv:{}: more than {max} rows of poses: rtest reads at most {max} poses from one file; split it",
                    if max == 2 { 6 } else { 4 }
                )
            );
        }
    }
}
