//! The time-stamped log of an R-test: its header (the time column and the reading columns)
//! and its rows, read one at a time through the bounded line reader.
//!
//! - **Time**: exactly one of `t_s` (seconds on any clock, a decimal with an optional
//!   exponent) and `t_abs_s` (Unix time, seconds since 1970-01-01 UTC, `digits[.digits]`).
//!   Times must increase from row to row. Inside, times are seconds since the first row: a
//!   Unix time is split into its whole seconds and its fraction, so no precision is lost to the
//!   size of the number.
//! - **Readings**: every column whose name ends in `_um` (any case): µm, decimals with an
//!   optional exponent, finite, kept under their names. Either the error vector
//!   `dx_um,dy_um,dz_um` (all three, nothing else) or sensor columns `s1_um,s2_um,…`: a
//!   record holds one or the other, as `identify` reads it.
//! - **Other columns** (a sample counter, a status word) are not read; their names are
//!   reported.
//!
//! `#` lines and blank lines are comments; fields are separated by commas; names are matched
//! without regard to case and to spaces or double quotes around them.

use formats::csv::{CsvError, Ctx, Lines, ReadOptions, clean_name};
use std::io::Read;

/// The clock of a log's time column.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LogClock {
    /// `t_s`: seconds on the logger's own clock; the first row's time, s.
    Seconds {
        /// The time of the first row, s.
        first: f64,
    },
    /// `t_abs_s`: Unix time; the first row's whole seconds.
    Unix {
        /// The whole seconds of the first row's time, s since 1970-01-01 UTC.
        first_whole: i64,
    },
}

impl LogClock {
    /// The log's own time (s on its clock) of `rel` seconds after its first row.
    pub fn log_time(&self, rel: f64) -> f64 {
        match *self {
            LogClock::Seconds { first } => first + rel,
            LogClock::Unix { first_whole } => first_whole as f64 + rel,
        }
    }

    /// Seconds after the first row of the log's own time `t` (s on its clock).
    pub fn relative(&self, t: f64) -> f64 {
        match *self {
            LogClock::Seconds { first } => t - first,
            LogClock::Unix { first_whole } => t - first_whole as f64,
        }
    }

    /// The time column's name: `t_s` or `t_abs_s`.
    pub fn column(&self) -> &'static str {
        match self {
            LogClock::Seconds { .. } => "t_s",
            LogClock::Unix { .. } => "t_abs_s",
        }
    }
}

/// What the header of a log says.
#[derive(Clone, Debug)]
pub(crate) struct LogHeader {
    /// Every column's name, as written (cleaned).
    names: Vec<String>,
    /// The index of the time column.
    time: usize,
    /// `t_abs_s` rather than `t_s`.
    unix: bool,
    /// The indices of the reading columns, in the order of the file.
    readings: Vec<usize>,
}

impl LogHeader {
    /// The reading columns' names, in the order of the file.
    pub(crate) fn reading_names(&self) -> Vec<String> {
        self.readings
            .iter()
            .map(|&i| self.names[i].clone())
            .collect()
    }

    /// The names of the columns that are not read.
    pub(crate) fn ignored_names(&self) -> Vec<String> {
        (0..self.names.len())
            .filter(|&i| i != self.time && !self.readings.contains(&i))
            .map(|i| self.names[i].clone())
            .collect()
    }
}

/// The rows of a log, one at a time.
pub(crate) struct LogReader<'f, R> {
    file: &'f str,
    lines: Lines<R>,
    pub(crate) header: LogHeader,
    clock: Option<LogClock>,
    /// The time of the last row read (s after the first) and its line.
    last: Option<(f64, usize)>,
}

impl<'f, R: Read> LogReader<'f, R> {
    /// Opens the log `reader` (named `file` in messages): reads up to its header.
    ///
    /// # Errors
    /// [`CsvError::Format`] for a file without a header, a header without a time column or
    /// with two, a repeated column, no reading column; a line too long or not UTF-8.
    pub(crate) fn open(file: &'f str, reader: R) -> Result<Self, CsvError> {
        let cx = Ctx { file };
        let mut lines = Lines::new(reader, &ReadOptions::default());
        loop {
            let Some((line, text)) = lines.next_line(&cx)? else {
                let line = lines.number_at_end();
                return Err(cx.err(line, None, "an empty log: no header and no row"));
            };
            let trimmed = text.trim();
            if trimmed.is_empty() || trimmed.starts_with('#') {
                continue;
            }
            let header = parse_header(&cx, line, text)?;
            return Ok(LogReader {
                file,
                lines,
                header,
                clock: None,
                last: None,
            });
        }
    }

    /// The clock, once a row has been read.
    pub(crate) fn clock(&self) -> Option<LogClock> {
        self.clock
    }

    /// The next row: its line, its time (s after the first row), and its readings written
    /// into `readings` (mm, one per reading column); `None` at the end of the log.
    ///
    /// # Errors
    /// [`CsvError::Format`] naming the line and column: a row of the wrong length, a time or
    /// reading that cannot be read or is not finite, a time that does not increase.
    pub(crate) fn next_row(
        &mut self,
        readings: &mut [f64],
    ) -> Result<Option<(usize, f64)>, CsvError> {
        let cx = Ctx { file: self.file };
        let h = &self.header;
        let clock = &mut self.clock;
        loop {
            let Some((line, text)) = self.lines.next_line(&cx)? else {
                return Ok(None);
            };
            let trimmed = text.trim();
            if trimmed.is_empty() || trimmed.starts_with('#') {
                continue;
            }
            let mut time = None;
            let mut count = 0;
            let mut next_reading = 0;
            for (i, field) in text.split(',').enumerate() {
                count += 1;
                if i >= h.names.len() {
                    continue;
                }
                let at = Some((i, h.names[i].as_str()));
                if i == h.time {
                    time = Some(time_of(clock, h.unix, &cx, line, at, field.trim())?);
                } else if h.readings.get(next_reading) == Some(&i) {
                    let f = field.trim();
                    let v: f64 =
                        f.parse()
                            .ok()
                            .filter(|v: &f64| v.is_finite())
                            .ok_or_else(|| {
                                cx.err(
                                    line,
                                    at,
                                    format!("`{f}` is not a finite number (a reading, µm)"),
                                )
                            })?;
                    readings[next_reading] = v * 1e-3;
                    next_reading += 1;
                }
            }
            if count != h.names.len() {
                return Err(cx.err(
                    line,
                    None,
                    format!("{count} fields, the header has {}", h.names.len()),
                ));
            }
            let t = time.unwrap_or(0.0);
            if let Some((previous, previous_line)) = self.last
                && t <= previous
            {
                let column = Some((h.time, h.names[h.time].as_str()));
                let clock = clock.unwrap_or(LogClock::Seconds { first: 0.0 });
                return Err(cx.err(
                    line,
                    column,
                    format!(
                        "the time {} s does not increase (line {previous_line}: {} s): a log's rows must be in time order, without repeats",
                        clock.log_time(t),
                        clock.log_time(previous)
                    ),
                ));
            }
            self.last = Some((t, line));
            return Ok(Some((line, t)));
        }
    }
}

/// Seconds after the first row of the time `text` of line `line`; the first row sets the
/// clock.
fn time_of(
    clock: &mut Option<LogClock>,
    unix: bool,
    cx: &Ctx,
    line: usize,
    at: Option<(usize, &str)>,
    text: &str,
) -> Result<f64, CsvError> {
    if unix {
        let bad = || {
            cx.err(
                line,
                at,
                format!("`{text}` is not a Unix time (s since 1970-01-01 UTC, digits[.digits])"),
            )
        };
        let (whole, fraction) = text.split_once('.').unwrap_or((text, ""));
        let digits = |s: &str| s.bytes().all(|b| b.is_ascii_digit());
        if whole.is_empty() || whole.len() > 12 || !digits(whole) || !digits(fraction) {
            return Err(bad());
        }
        let whole: i64 = whole.parse().map_err(|_| bad())?;
        let fraction: f64 = match fraction.len() {
            0 => 0.0,
            // Up to 18 digits fit a u64: the digits over a power of ten, no text built.
            1..=18 => {
                fraction.parse::<u64>().map_err(|_| bad())? as f64
                    / 10f64.powi(fraction.len() as i32)
            }
            _ => format!("0.{fraction}").parse().map_err(|_| bad())?,
        };
        let first = match *clock {
            Some(LogClock::Unix { first_whole }) => first_whole,
            _ => {
                *clock = Some(LogClock::Unix { first_whole: whole });
                whole
            }
        };
        Ok((whole - first) as f64 + fraction)
    } else {
        let t: f64 = text
            .parse()
            .ok()
            .filter(|t: &f64| t.is_finite())
            .ok_or_else(|| {
                cx.err(
                    line,
                    at,
                    format!("`{text}` is not a finite number (a time, s)"),
                )
            })?;
        let first = match *clock {
            Some(LogClock::Seconds { first }) => first,
            _ => {
                *clock = Some(LogClock::Seconds { first: t });
                t
            }
        };
        Ok(t - first)
    }
}

fn parse_header(cx: &Ctx, line: usize, text: &str) -> Result<LogHeader, CsvError> {
    let names: Vec<String> = text.split(',').map(|n| clean_name(n).to_string()).collect();
    let mut time: Option<(usize, bool)> = None;
    let mut readings = Vec::new();
    for (i, name) in names.iter().enumerate() {
        if let Some(j) = names[..i].iter().position(|n| n.eq_ignore_ascii_case(name)) {
            return Err(cx.err(
                line,
                Some((i, name)),
                format!("column `{name}` appears twice (also column {})", j + 1),
            ));
        }
        let unix = name.eq_ignore_ascii_case("t_abs_s");
        if unix || name.eq_ignore_ascii_case("t_s") {
            if let Some((j, _)) = time {
                return Err(cx.err(
                    line,
                    Some((i, name)),
                    format!(
                        "a second time column (column {} `{}` is one): give t_s or t_abs_s",
                        j + 1,
                        names[j]
                    ),
                ));
            }
            time = Some((i, unix));
        } else if name.len() > 3 && name[name.len() - 3..].eq_ignore_ascii_case("_um") {
            readings.push(i);
        }
    }
    let Some((time, unix)) = time else {
        return Err(cx.err(
            line,
            None,
            "no time column: a log needs `t_s` (s on any clock) or `t_abs_s` (Unix time, s)",
        ));
    };
    if readings.is_empty() {
        return Err(cx.err(
            line,
            None,
            "no reading column: a log's readings are the columns named `…_um` (µm: dx_um,dy_um,dz_um or s1_um,s2_um,…)",
        ));
    }
    // A record holds the error vector or sensor readings, never a part or a mixture of them
    // (`identify` reads one or the other).
    const ERROR_VECTOR: [&str; 3] = ["dx_um", "dy_um", "dz_um"];
    let is_vector = |&i: &usize| {
        ERROR_VECTOR
            .iter()
            .any(|c| names[i].eq_ignore_ascii_case(c))
    };
    let vector: Vec<usize> = readings.iter().copied().filter(is_vector).collect();
    if !vector.is_empty() {
        if let Some(&k) = readings.iter().find(|k| !is_vector(k)) {
            return Err(cx.err(
                line,
                Some((k, &names[k])),
                format!(
                    "a reading column beside the error vector's `{}`: a record holds dx_um,dy_um,dz_um or sensor columns (s1_um,s2_um,…), not both (remove one set from the log)",
                    names[vector[0]]
                ),
            ));
        }
        if vector.len() < 3 {
            let missing: Vec<&str> = ERROR_VECTOR
                .into_iter()
                .filter(|c| !vector.iter().any(|&i| names[i].eq_ignore_ascii_case(c)))
                .collect();
            return Err(cx.err(
                line,
                None,
                format!(
                    "the error vector lacks {}: a record holds all of dx_um,dy_um,dz_um",
                    missing.join(", ")
                ),
            ));
        }
    }
    Ok(LogHeader {
        names,
        time,
        unix,
        readings,
    })
}
