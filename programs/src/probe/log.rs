//! The controls' logs of the latched positions, one line per probe trip
//! (`docs/probe-programs.md`):
//!
//! - **LinuxCNC** (`(PROBEOPEN file)`): nine numbers separated by blanks, the axes X Y Z A B C
//!   U V W at the trip in the program's coordinates (`%f`: six decimals), e.g.
//!   `217.495000 -0.279000 86.661000 0.000000 0.000000 90.000000 0.000000 0.000000 0.000000`;
//! - **ISO** (`DPRNT[X#31[44]*Y#32[44]*Z#33[44]]`): the letters X, Y, Z each followed by its
//!   value, blanks where the format reserves digits or the sign (`X 217.4950 Y  -0.2790 Z
//!   86.6610`); a line of `%` alone (what `POPEN` and `PCLOS` may write) is skipped;
//! - **Heidenhain** (`FN 16` with the format `"X %+.4LF Y %+.4LF Z %+.4LF"`): the same,
//!   `X +217.4950 Y -0.2790 Z +86.6610`.
//!
//! Blank lines are skipped; any other line is refused at its line. Numbers are plain decimals
//! (a sign, digits, a point); the log is read through the bounded line reader of the CSVs.

use formats::csv::{CsvError, Ctx, Lines, ReadOptions, column_order};
use formats::nc::Dialect;
use formats::poses::axis_words;
use formats::probe::MAX_HITS;
use model_spec::units::parse_scaled;
use model_spec::{AxisKind, Machine};
use std::io::Read;
use std::path::Path;

/// The axes of a LinuxCNC probe log's nine numbers, in order.
const LINUXCNC_AXES: &str = "XYZABCUVW";

/// One probe trip of a log.
#[derive(Clone, Debug, PartialEq)]
pub struct LoggedTrip {
    /// The 1-based line of the log.
    pub line: usize,
    /// The latched position of every axis of the machine the log holds ([`Machine::axes`]
    /// order; mm, degrees); `None` for an axis it does not (the rotary axes of the ISO and
    /// Heidenhain logs).
    pub axes: Vec<Option<f64>>,
}

/// Reads the log `text` (named `file` in messages) of a program in `dialect` run on machine
/// `m`; see [`read_probe_log`].
///
/// # Errors
/// As [`read_probe_log`].
pub fn parse_probe_log(
    file: &str,
    text: &str,
    dialect: Dialect,
    m: &Machine,
) -> Result<Vec<LoggedTrip>, CsvError> {
    read_log(file, text.as_bytes(), dialect, m)
}

/// Reads the probe log at `path` of a program in `dialect` run on machine `m` (see the module
/// documentation): one trip per line that is not blank.
///
/// # Errors
/// [`CsvError::Format`] naming the line: not nine numbers (LinuxCNC), not the letters of the
/// linear axes each with a number (ISO, Heidenhain), a number that cannot be read, a line too
/// long or not UTF-8; a log without a trip or with more than [`MAX_HITS`]; [`CsvError::Io`]
/// when the file cannot be read.
pub fn read_probe_log(
    path: &Path,
    dialect: Dialect,
    m: &Machine,
) -> Result<Vec<LoggedTrip>, CsvError> {
    let (file, f) = formats::csv::open(path)?;
    read_log(&file, f, dialect, m)
}

fn read_log<R: Read>(
    file: &str,
    reader: R,
    dialect: Dialect,
    m: &Machine,
) -> Result<Vec<LoggedTrip>, CsvError> {
    let cx = Ctx { file };
    let mut lines = Lines::new(reader, &ReadOptions::default());
    let letters: Vec<char> = axis_words(m).iter().map(|w| w.letter).collect();
    let linear: Vec<usize> = column_order(m)
        .into_iter()
        .filter(|&a| m.axes[a].kind == AxisKind::Linear)
        .collect();
    let mut trips = Vec::new();
    while let Some((line, text)) = lines.next_line(&cx)? {
        let t = text.trim();
        if t.is_empty() || (dialect != Dialect::LinuxCnc && t == "%") {
            continue;
        }
        if trips.len() >= MAX_HITS {
            return Err(cx.err(
                line,
                None,
                format!("more than {MAX_HITS} trips: no probe plan has that many hits"),
            ));
        }
        let axes = match dialect {
            Dialect::LinuxCnc => linuxcnc_line(&cx, line, t, &letters)?,
            Dialect::Iso | Dialect::Heidenhain => {
                lettered_line(&cx, line, t, dialect, &letters, &linear)?
            }
        };
        trips.push(LoggedTrip { line, axes });
    }
    if trips.is_empty() {
        return Err(cx.err(
            lines.number_at_end(),
            None,
            "a probe log without a trip: the probe did not trip, or this is not the log the program wrote",
        ));
    }
    Ok(trips)
}

/// A plain decimal (`-217.495`, `+0.5`, `12`), finite.
fn number(text: &str) -> Option<f64> {
    let valid = !text.is_empty()
        && text
            .trim_start_matches(['+', '-'])
            .bytes()
            .all(|b| b.is_ascii_digit() || b == b'.')
        && text.bytes().filter(|&b| b == b'+' || b == b'-').count() <= 1;
    valid
        .then(|| parse_scaled(text, 0))
        .flatten()
        .filter(|v| v.is_finite())
}

/// A LinuxCNC line: nine numbers, the machine's axes taken by their letters.
fn linuxcnc_line(
    cx: &Ctx,
    line: usize,
    text: &str,
    letters: &[char],
) -> Result<Vec<Option<f64>>, CsvError> {
    let fields: Vec<&str> = text.split_whitespace().collect();
    if fields.len() != LINUXCNC_AXES.len() {
        return Err(cx.err(
            line,
            None,
            format!(
                "{} field(s): a LinuxCNC probe log line holds nine numbers, X Y Z A B C U V W",
                fields.len()
            ),
        ));
    }
    let mut values = Vec::with_capacity(fields.len());
    for (f, axis) in fields.iter().zip(LINUXCNC_AXES.chars()) {
        values.push(number(f).ok_or_else(|| {
            cx.err(
                line,
                None,
                format!("`{f}` (axis {axis}) is not a finite decimal number"),
            )
        })?);
    }
    Ok(letters
        .iter()
        .map(|c| LINUXCNC_AXES.find(*c).map(|k| values[k]))
        .collect())
}

/// An ISO (`DPRNT`) or Heidenhain (`FN 16`) line: the letters of the linear axes (`linear`,
/// in order), each followed by its value.
fn lettered_line(
    cx: &Ctx,
    line: usize,
    text: &str,
    dialect: Dialect,
    letters: &[char],
    linear: &[usize],
) -> Result<Vec<Option<f64>>, CsvError> {
    let expected: String = linear
        .iter()
        .map(|&a| format!("{}<number>", letters[a]))
        .collect::<Vec<_>>()
        .join(" ");
    let what = match dialect {
        Dialect::Iso => "DPRNT",
        _ => "FN 16",
    };
    let refuse = |why: String| {
        cx.err(
            line,
            None,
            format!("{why}: a {what} line of the probe log is `{expected}`"),
        )
    };
    let mut values: Vec<Option<f64>> = vec![None; letters.len()];
    let mut rest = text;
    for &a in linear {
        let letter = letters[a];
        rest = rest.trim_start();
        let Some(after) = rest.strip_prefix(letter) else {
            return Err(refuse(format!(
                "`{}` where {letter} belongs",
                rest.chars().take(12).collect::<String>()
            )));
        };
        // The value: a sign, digits and a point, blanks allowed between the letter, the sign
        // and the digits (DPRNT pads reserved places with blanks).
        let after = after.trim_start();
        let (sign, after) = match after.strip_prefix(['+', '-']) {
            Some(r) => (&after[..1], r.trim_start()),
            None => ("", after),
        };
        let end = after
            .find(|c: char| !(c.is_ascii_digit() || c == '.'))
            .unwrap_or(after.len());
        let digits = &after[..end];
        let v = number(&format!("{sign}{digits}")).ok_or_else(|| {
            refuse(format!(
                "axis {letter}: `{sign}{}` is not a finite decimal number",
                after.chars().take(12).collect::<String>()
            ))
        })?;
        values[a] = Some(v);
        rest = &after[end..];
    }
    if !rest.trim().is_empty() {
        return Err(refuse(format!("`{}` after the last axis", rest.trim())));
    }
    Ok(values)
}
