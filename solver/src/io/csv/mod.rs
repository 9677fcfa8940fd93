//! The R-test measurement CSV (DESIGN.md): read and written.
//!
//! One row a sample; the header names the columns, in any order:
//! - one column per axis of the machine, named after it (`X,Y,Z,A,C` for `seed-ac`): linear
//!   axes in mm, rotary axes in degrees. Rotary columns are required; the linear columns are
//!   all present or all missing, and when missing they are filled by the machine's nominal
//!   tool-centre-point inverse kinematics with its default kinematic parameters
//!   ([`crate::simulation::paths::fill_linear_ik`]);
//! - `dx_um,dy_um,dz_um`: the measured error vector (tool minus workpiece, tool frame, µm),
//!   required in a measurement file, optional (all three or none) in a path file;
//! - `t_s` (optional): time since the start, s, finite and non-decreasing. Without it, sample
//!   `i` (0-based) is taken at `t = i` s.
//!
//! Column names are matched without regard to case and surrounding spaces (or double quotes).
//! Lines whose first non-blank character is `#` are comments, blank lines are skipped. Fields
//! are separated by commas, without quoting. Every other deviation is a [`CsvError`] naming the
//! file, the line and, where there is one, the column (1-based index and header name).
//!
//! Numbers are converted without double rounding: a µm value is read by moving the decimal
//! point of its text three places ([`parse_scaled`]), and written as the shortest decimal of the
//! mm value with the point moved back ([`format_scaled`]), so write → read gives the same bits.
//! Degrees are written as the shortest decimal whose `to_radians()` is the command; every
//! command that was itself read from degrees (files, built-in paths) round-trips bit for bit.
//!
//! Files are written atomically: to a temporary file in the same directory, then renamed.

mod read;

use crate::record::Record;
use model_spec::catalogue::iso_rank;
use model_spec::{AxisKind, Machine};
pub use read::{FIRST_LOOKAHEAD, MeasurementBlocks, parse_csv, time_span};
use std::io::Write;
use std::path::Path;

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
    /// A record that cannot be written (not a file problem: a programming error reported).
    #[error("cannot write the record: {0}")]
    Record(String),
    /// The file could not be read or written.
    #[error("{file}: {source}")]
    Io {
        /// The file name.
        file: String,
        /// Why.
        source: std::io::Error,
    },
}

fn format_located(
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

pub(crate) struct Ctx<'a> {
    pub(crate) file: &'a str,
}

impl Ctx<'_> {
    pub(crate) fn err(
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
/// backwards, inverse kinematics without a solution.
pub fn parse_measurement(file: &str, text: &str, m: &Machine) -> Result<Record, CsvError> {
    parse_csv(file, text, m, Need::Measured)
}

/// Reads the measurement CSV file `path` of machine `m`; see [`parse_measurement`].
pub fn read_measurement(path: &Path, m: &Machine) -> Result<Record, CsvError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| CsvError::Io {
        file: file.clone(),
        source,
    })?;
    parse_measurement(&file, &text, m)
}

pub(crate) fn clean_name(s: &str) -> &str {
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

/// The CSV text of `record` of machine `m`: `comments` as `# ` lines, then the header
/// (axes as in [`column_order`], `dx_um,dy_um,dz_um` when the record is measured, `t_s`), then
/// one row per sample. Linear axes in mm, rotary in degrees, measured in µm, time in s, each the
/// shortest decimal that reads back to the same bits.
///
/// # Errors
/// [`CsvError::Record`] when a sample has the wrong number of commands, `measured` is neither
/// empty nor one per sample, or a value is not finite.
pub fn format_record(
    m: &Machine,
    record: &Record,
    comments: &[String],
) -> Result<String, CsvError> {
    let n = record.samples.len();
    let measured = !record.measured.is_empty();
    if measured && record.measured.len() != n {
        return Err(CsvError::Record(format!(
            "it has {n} samples but {} measured vectors",
            record.measured.len()
        )));
    }
    let axes = column_order(m);
    let mut out = String::new();
    for c in comments {
        for l in c.lines() {
            out += "# ";
            out += l;
            out.push('\n');
        }
    }
    let mut header: Vec<&str> = axes.iter().map(|&a| m.axes[a].name.as_str()).collect();
    if measured {
        header.extend(MEASURED);
    }
    header.push("t_s");
    out += &header.join(",");
    out.push('\n');
    for (i, s) in record.samples.iter().enumerate() {
        if s.commands.len() != m.axes.len() {
            return Err(CsvError::Record(format!(
                "sample {i} has {} commands, machine {} has {} axes",
                s.commands.len(),
                m.name,
                m.axes.len()
            )));
        }
        let mut fields: Vec<String> = Vec::with_capacity(header.len());
        for &a in &axes {
            let x = s.commands[a];
            fields.push(match m.axes[a].kind {
                AxisKind::Linear => format_scaled(x, 0),
                AxisKind::Rotary => format_scaled(degrees_for(x), 0),
            });
        }
        if measured {
            fields.extend(record.measured[i].iter().map(|&v| format_scaled(v, 3)));
        }
        fields.push(format_scaled(s.t, 0));
        let bad = |v: &f64| !v.is_finite();
        if s.commands.iter().any(bad)
            || !s.t.is_finite()
            || (measured && record.measured[i].iter().any(bad))
        {
            return Err(CsvError::Record(format!(
                "sample {i} has a non-finite value"
            )));
        }
        out += &fields.join(",");
        out.push('\n');
    }
    Ok(out)
}

/// Writes `record` of machine `m` to `path` atomically (see [`format_record`]).
///
/// # Errors
/// See [`format_record`]; [`CsvError::Io`] when the file cannot be written (then nothing is
/// left behind).
pub fn write_record(
    path: &Path,
    m: &Machine,
    record: &Record,
    comments: &[String],
) -> Result<(), CsvError> {
    let text = format_record(m, record, comments)?;
    write_atomically(path, text.as_bytes()).map_err(|source| CsvError::Io {
        file: path.display().to_string(),
        source,
    })
}

/// Writes `bytes` to `path` atomically: to a temporary file in the same directory, flushed to
/// disk, then renamed over `path`. On failure the temporary file is removed and `path` is
/// untouched.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| std::io::Error::other("the path names no file"))?
        .to_string_lossy();
    let tmp = dir.join(format!(
        ".{name}.tmp-{}-{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// The degree value written for the rotary command `rad`: among the few `f64` next to
/// `rad.to_degrees()`, the one with the shortest decimal whose `to_radians()` gives `rad`
/// exactly (the nearest such one on a tie); `rad.to_degrees()` if none does.
pub fn degrees_for(rad: f64) -> f64 {
    let d0 = rad.to_degrees();
    if !d0.is_finite() {
        return d0;
    }
    let mut best: Option<(usize, u32, f64)> = None;
    let (mut up, mut down) = (d0, d0);
    for k in 0..=4u32 {
        for d in [up, down] {
            if d.to_radians().to_bits() == rad.to_bits() {
                let len = format_scaled(d, 0).len();
                if best.is_none_or(|(l, bk, _)| (len, k) < (l, bk)) {
                    best = Some((len, k, d));
                }
            }
        }
        up = up.next_up();
        down = down.next_down();
    }
    best.map_or(d0, |(_, _, d)| d)
}

/// The decimal number `text` times `10^shift`, rounded once to the nearest `f64`: the decimal
/// point is moved in the text, then the text is parsed. `None` when `text` is not a plain
/// decimal (`[+-]digits[.digits][e[+-]digits]`; `inf` and `nan` are not).
pub fn parse_scaled(text: &str, shift: i32) -> Option<f64> {
    let t = text.trim();
    let (sign, rest) = match t.as_bytes().first()? {
        b'-' => ("-", &t[1..]),
        b'+' => ("", &t[1..]),
        _ => ("", t),
    };
    let (mantissa, exp) = match rest.find(['e', 'E']) {
        Some(i) => (&rest[..i], rest[i + 1..].parse::<i64>().ok()?),
        None => (rest, 0),
    };
    let (int, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    let digits = |s: &str| s.bytes().all(|b| b.is_ascii_digit());
    if (int.is_empty() && frac.is_empty()) || !digits(int) || !digits(frac) {
        return None;
    }
    let e = exp
        .checked_sub(frac.len() as i64)?
        .checked_add(shift as i64)?;
    format!("{sign}{int}{frac}e{e}").parse().ok()
}

/// The shortest decimal of `x` (the one that reads back to the same `f64`) times `10^shift`,
/// exactly (the decimal point is moved in the text, nothing is rounded): plain notation,
/// scientific (`1.5e-12`) outside 1e-7 … 1e21. `parse_scaled(&format_scaled(x, k), -k)` is `x`
/// bit for bit. Non-finite values are written as Rust prints them (`NaN`, `inf`).
pub fn format_scaled(x: f64, shift: i32) -> String {
    if !x.is_finite() {
        return format!("{x}");
    }
    let sign = if x.is_sign_negative() { "-" } else { "" };
    if x == 0.0 {
        return format!("{sign}0");
    }
    let e = format!("{:e}", x.abs());
    let (mantissa, exp) = e.split_once('e').unwrap_or((&e, "0"));
    let exp: i64 = exp.parse().unwrap_or(0);
    let digits: String = mantissa.chars().filter(|c| *c != '.').collect();
    // Number of digits before the decimal point.
    let point = exp + 1 + shift as i64;
    let n = digits.len() as i64;
    let body = if !(-6..=21).contains(&point) {
        let (first, rest) = digits.split_at(1);
        if rest.is_empty() {
            format!("{first}e{}", point - 1)
        } else {
            format!("{first}.{rest}e{}", point - 1)
        }
    } else if point <= 0 {
        format!("0.{}{digits}", "0".repeat((-point) as usize))
    } else if point >= n {
        format!("{digits}{}", "0".repeat((point - n) as usize))
    } else {
        let (a, b) = digits.split_at(point as usize);
        format!("{a}.{b}")
    };
    format!("{sign}{body}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scaled_numbers() {
        assert_eq!(format_scaled(0.012345, 3), "12.345");
        assert_eq!(format_scaled(-0.01, 3), "-10");
        assert_eq!(format_scaled(1.5, 0), "1.5");
        assert_eq!(format_scaled(1e-20, 3), "1e-17");
        assert_eq!(format_scaled(1234.5, 3), "1234500");
        assert_eq!(format_scaled(-0.0, 3), "-0");
        assert_eq!(parse_scaled("12.345", -3), Some(0.012345));
        assert_eq!(parse_scaled("-10", -3), Some(-0.01));
        assert_eq!(parse_scaled(".5", 0), Some(0.5));
        assert_eq!(parse_scaled("5.", 0), Some(5.0));
        assert_eq!(parse_scaled("1.5E2", -3), Some(0.15));
        assert_eq!(parse_scaled("inf", 0), None);
        assert_eq!(parse_scaled("nan", 0), None);
        assert_eq!(parse_scaled("1.2.3", 0), None);
        assert_eq!(parse_scaled("", 0), None);
        assert_eq!(parse_scaled("-", 0), None);
        let mut r = crate::simulation::rng::Rng::new(3);
        for _ in 0..20_000 {
            let x = r.normal() * 10f64.powi((r.uniform() * 40.0) as i32 - 20);
            for k in [0, 3, 6, -3] {
                let s = format_scaled(x, k);
                assert_eq!(
                    parse_scaled(&s, -k).map(f64::to_bits),
                    Some(x.to_bits()),
                    "{x} {k} {s}"
                );
            }
        }
    }

    #[test]
    fn degrees_round_trip() {
        for i in 0..=3600 {
            let d = -180.0 + 0.1 * i as f64;
            let r = d.to_radians();
            assert_eq!(degrees_for(r).to_radians().to_bits(), r.to_bits(), "{d}");
        }
        assert_eq!(degrees_for(1.5f64.to_radians()), 1.5);
        assert_eq!(degrees_for(0.0), 0.0);
    }
}
