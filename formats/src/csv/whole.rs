//! The whole-file reader: every sample of a measurement or path CSV in one [`Record`].

use crate::csv::lines::Lines;
use crate::csv::read::{header_only, read_header};
use crate::csv::rows::parse_rows;
use crate::csv::{CsvError, Ctx, Need, ReadOptions};
use model_spec::Machine;
use simulation::paths::record_from_commands;
use simulation::record::Record;
use std::io::Read;

/// Reads a CSV of machine `m` (text `text`, named `file` in messages); `need` says whether the
/// measured columns are required. See [`read_csv`].
///
/// # Errors
/// As [`read_csv`].
pub fn parse_csv(
    file: &str,
    text: &str,
    m: &Machine,
    need: Need,
    opts: &ReadOptions,
) -> Result<Record, CsvError> {
    read_csv(file, text.as_bytes(), m, need, opts)
}

/// Reads a CSV of machine `m` from `reader` (named `file` in messages) through the bounded line
/// reader: commands in mm and rad, readings in mm (zero-length without measured columns),
/// times in s. `need` says whether the measured columns are required. The samples are checked
/// as a whole once read ([`crate::csv`]: nest on the ball, strokes, plausible readings).
///
/// # Errors
/// [`CsvError::Format`] at the line (and column) of the first malformed line, including a line
/// longer than [`ReadOptions::max_line_bytes`] or not UTF-8; [`CsvError::Refused`] for samples
/// that are well formed but cannot be an R-test record of `m`; [`CsvError::Io`] when `reader`
/// fails.
pub fn read_csv<R: Read>(
    file: &str,
    reader: R,
    m: &Machine,
    need: Need,
    opts: &ReadOptions,
) -> Result<Record, CsvError> {
    let cx = Ctx { file };
    let mut lines = Lines::new(reader, opts);
    let header = read_header(&cx, &mut lines, m, need)?;
    let parsed = parse_rows(&cx, &mut lines, &header, m)?;
    let row_lines = parsed.lines;
    let n = parsed.rows.len();
    let (mut commands, mut times, mut measured) = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    let mut timed = true;
    for (c, t, d) in parsed.rows {
        timed &= t.is_some();
        times.push(t.unwrap_or(commands.len() as f64));
        commands.push(c);
        measured.push(d);
    }
    if commands.is_empty() {
        return Err(header_only(&cx, &header));
    }
    header.fill(&cx, m, &mut commands, &row_lines)?;
    header.checks(m, opts).check(
        file,
        &commands,
        header.measured.then_some(&measured[..]),
        &row_lines,
    )?;
    let mut record = record_from_commands(commands, times);
    for s in &mut record.samples {
        s.timed = timed;
    }
    if header.measured {
        record.measured = measured;
    }
    record.lines = row_lines;
    Ok(record)
}
