//! Records of an R-test head's sensor readings (`docs/instrument.md`): read and turned into
//! records of error vectors, written, and the calibration records of an instrument.
//!
//! A **sensor record** is a measurement CSV ([`crate::csv`]) whose error vector columns
//! `dx_um,dy_um,dz_um` are replaced by one column per sensor, named after it: `s1_um,s2_um,
//! s3_um[,s4_um]` (µm, the sensors' readings, zeros included). The axis columns, `t_s`, the
//! text rules and the line reader are those of the measurement CSV, and so are the checks
//! (nest on the ball, strokes, plausible readings: on the error vectors the readings give).
//! Reading one gives a [`Record`] of error vectors (tool frame, mm) with the covariance of each
//! ([`simulation::instrument::to_record`]).
//!
//! A **calibration record** holds known displacements and what the sensors read for them:
//! `dx_um,dy_um,dz_um` (the error vector the instrument should read, nest minus ball, nest
//! frame, µm), one column per sensor (µm), and optionally `t_s`; no axis columns.

use crate::csv::checks::SampleChecks;
use crate::csv::lines::Lines;
use crate::csv::read::{header_only, is_data, read_header_with};
use crate::csv::{
    CsvError, Ctx, MEASURED, Need, ReadOptions, clean_name, column_order, comment_lines,
};
use model_spec::instrument::{GAIN_RANGE, MAX_ZERO_UM};
use model_spec::instrument::{Instrument, ReadingsFrame};
use model_spec::units::{degrees_for, format_scaled, parse_scaled, significant};
use model_spec::{AxisKind, Machine};
use simulation::instrument::CalibrationRecord;
use simulation::instrument::convert::{SensorRecord, to_record};
use simulation::instrument::head::SensorHead;
use simulation::paths::record_from_commands;
use simulation::record::Record;
use std::io::Read;
use std::path::Path;

/// Reads a sensor record of machine `m` taken with `instrument` from `reader` (named `file`
/// in messages): the samples and the sensors' readings (mm), not yet converted. The poses are
/// checked as in a measurement CSV (nest on the ball, strokes).
///
/// # Errors
/// [`CsvError::Format`] at the line (and column) of the first malformed line: a missing sensor
/// column, `dx_um`… beside the sensor columns, a value that is not a finite number, …;
/// [`CsvError::Refused`] for poses off the ball or the strokes; [`CsvError::Io`].
pub fn read_sensor_csv<R: Read>(
    file: &str,
    reader: R,
    m: &Machine,
    instrument: &Instrument,
    opts: &ReadOptions,
) -> Result<SensorRecord, CsvError> {
    let cx = Ctx { file };
    let mut lines = Lines::new(reader, opts);
    let columns = instrument.columns();
    let header = read_header_with(&cx, &mut lines, m, Need::Path, &columns)?;
    if header.measured {
        return Err(cx.err(
            header.line,
            None,
            format!(
                "a record of the sensor readings of instrument {} has the columns {}, not dx_um, dy_um, dz_um: give one or the other (without an instrument the file is read as error vectors)",
                instrument.name,
                columns.join(", ")
            ),
        ));
    }
    let (mut commands, mut times, mut readings, mut row_lines) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut last_t = None;
    let reading_bound = max_sensor_reading_mm(opts.max_reading_mm);
    let mut timed = true;
    while let Some((line, text)) = lines.next_line(&cx)? {
        if !is_data(text) {
            continue;
        }
        let ((c, t, _), s) = header.row_with(&cx, line, text, m, &mut last_t)?;
        for (k, &x) in s.iter().enumerate() {
            if let Some(why) = beyond(x, reading_bound, "a sensor's reading") {
                return Err(cx.err(line, Some(header.extra_column(k)), why));
            }
        }
        timed &= t.is_some();
        times.push(t.unwrap_or(commands.len() as f64));
        commands.push(c);
        readings.push(s);
        row_lines.push(line);
    }
    if commands.is_empty() {
        return Err(header_only(&cx, &header));
    }
    header.fill(&cx, m, &mut commands, &row_lines)?;
    header
        .checks(m, opts)
        .check(file, &commands, None, &row_lines)?;
    let mut record = record_from_commands(commands, times);
    for s in &mut record.samples {
        s.timed = timed;
    }
    record.lines = row_lines;
    Ok(SensorRecord { record, readings })
}

/// The largest magnitude of a sensor's reading, mm, when the error vector is bounded by
/// `max_reading_mm` (mm, [`ReadOptions::max_reading_mm`]): that displacement read with the
/// largest plausible gain ([`GAIN_RANGE`]) plus the largest zero ([`MAX_ZERO_UM`]). With the
/// default bound of 1 mm it is 12 mm; beyond it a reading is refused where it is read.
pub fn max_sensor_reading_mm(max_reading_mm: f64) -> f64 {
    max_reading_mm * GAIN_RANGE.1 + MAX_ZERO_UM * 1e-3
}

/// `None` when `x` (mm) is within `bound_mm`, else why, for a field of `what`.
fn beyond(x: f64, bound_mm: f64, what: &str) -> Option<String> {
    (x.abs() > bound_mm).then(|| {
        format!(
            "{} µm is beyond the plausibility bound of {what}, ±{} µm",
            significant(x * 1e3),
            significant(bound_mm * 1e3)
        )
    })
}

/// Reads the sensor record file `path` of machine `m` taken with `instrument` and turns it
/// into a record of error vectors (tool frame, mm) with their covariances (mm²), the
/// instrument's displacements taken in `frame` ([`simulation::instrument::to_record`]). The error
/// vectors are checked like the readings of a measurement CSV (plausibility bound).
///
/// # Errors
/// As [`read_sensor_csv`]; [`CsvError::Format`] at the line of a sample whose readings give
/// no error vector (a sensor off the ball, no convergence, readings of a redundant head that
/// disagree); [`CsvError::Refused`] for implausible error vectors.
pub fn read_sensor_measurement(
    path: &Path,
    m: &Machine,
    instrument: &Instrument,
    frame: ReadingsFrame,
    opts: &ReadOptions,
) -> Result<Record, CsvError> {
    let (file, f) = crate::csv::open(path)?;
    read_sensor_measurement_from(&file, f, m, instrument, frame, opts)
}

/// [`read_sensor_measurement`] of the bytes of `reader` (named `file` in messages).
///
/// # Errors
/// As [`read_sensor_measurement`].
pub fn read_sensor_measurement_from<R: Read>(
    file: &str,
    reader: R,
    m: &Machine,
    instrument: &Instrument,
    frame: ReadingsFrame,
    opts: &ReadOptions,
) -> Result<Record, CsvError> {
    let sensors = read_sensor_csv(file, reader, m, instrument, opts)?;
    sensor_measurement(file, m, instrument, frame, &sensors, opts)
}

/// [`read_sensor_measurement`] of the text `text` (named `file` in messages).
///
/// # Errors
/// As [`read_sensor_measurement`].
pub fn parse_sensor_measurement(
    file: &str,
    text: &str,
    m: &Machine,
    instrument: &Instrument,
    frame: ReadingsFrame,
    opts: &ReadOptions,
) -> Result<Record, CsvError> {
    let sensors = read_sensor_csv(file, text.as_bytes(), m, instrument, opts)?;
    sensor_measurement(file, m, instrument, frame, &sensors, opts)
}

/// The record of error vectors of a sensor record read from `file`, checked.
fn sensor_measurement(
    file: &str,
    m: &Machine,
    instrument: &Instrument,
    frame: ReadingsFrame,
    sensors: &SensorRecord,
    opts: &ReadOptions,
) -> Result<Record, CsvError> {
    let head = SensorHead::new(instrument);
    let lines = &sensors.record.lines;
    let record = to_record(&head, m, frame, sensors).map_err(|e| CsvError::Format {
        file: file.to_string(),
        line: lines.get(e.sample).copied().unwrap_or(0),
        column: None,
        message: format!(
            "the readings of instrument {} give no error vector: {}",
            instrument.name, e.error
        ),
    })?;
    let commands: Vec<Vec<f64>> = record.samples.iter().map(|s| s.commands.clone()).collect();
    // The poses passed their checks when they were read; these are the error vectors'.
    SampleChecks::new(m, false, opts)
        .check(file, &commands, Some(&record.measured), lines)
        .map_err(|e| match e {
            CsvError::Refused {
                file,
                count,
                lines,
                message,
            } => CsvError::Refused {
                file,
                count,
                lines,
                message: format!(
                    "{message} (the error vectors that the readings of instrument {} give)",
                    instrument.name
                ),
            },
            other => other,
        })?;
    Ok(record)
}

/// The CSV text of a sensor record of machine `m` taken with `instrument`: `comments` as `# `
/// lines, the header (axes as in [`column_order`], the sensor columns, `t_s`), one row per
/// sample; every number the shortest decimal that reads back to the same bits (readings in µm,
/// linear axes in mm, rotary in degrees, time in s).
///
/// # Errors
/// [`CsvError::Record`] when a sample has the wrong number of commands or readings, or a value
/// is not finite.
pub fn format_sensor_record(
    m: &Machine,
    instrument: &Instrument,
    sensors: &SensorRecord,
    comments: &[String],
) -> Result<String, CsvError> {
    let record = &sensors.record;
    let n = record.samples.len();
    if sensors.readings.len() != n {
        return Err(CsvError::Record(format!(
            "it has {n} samples but {} rows of sensor readings",
            sensors.readings.len()
        )));
    }
    let axes = column_order(m);
    let mut out = comment_lines(comments);
    let mut header: Vec<String> = axes.iter().map(|&a| m.axes[a].name.clone()).collect();
    header.extend(instrument.columns());
    header.push("t_s".into());
    out += &header.join(",");
    out.push('\n');
    for (i, (s, r)) in record.samples.iter().zip(&sensors.readings).enumerate() {
        if s.commands.len() != m.axes.len() || r.len() != instrument.sensors.len() {
            return Err(CsvError::Record(format!(
                "sample {i} has {} commands and {} readings, machine {} has {} axes and instrument {} {} sensors",
                s.commands.len(),
                r.len(),
                m.name,
                m.axes.len(),
                instrument.name,
                instrument.sensors.len()
            )));
        }
        let bad = |v: &f64| !v.is_finite();
        if s.commands.iter().any(bad) || r.iter().any(bad) || !s.t.is_finite() {
            return Err(CsvError::Record(format!(
                "sample {i} has a non-finite value"
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
        fields.extend(r.iter().map(|&v| format_scaled(v, 3)));
        fields.push(format_scaled(s.t, 0));
        out += &fields.join(",");
        out.push('\n');
    }
    Ok(out)
}

/// Reads a calibration record of `instrument` from `reader` (named `file` in messages): per
/// row the known error vector (`dx_um,dy_um,dz_um`, mm inside) and the sensors' readings (mm);
/// an optional `t_s` column is read (finite, not decreasing) and not used.
///
/// # Errors
/// [`CsvError::Format`] at the line and column of the first problem: an unknown, duplicate or
/// missing column, a ragged row, a value that is not a finite number, a time going backwards,
/// no rows; [`CsvError::Io`].
pub fn read_calibration<R: Read>(
    file: &str,
    reader: R,
    instrument: &Instrument,
    opts: &ReadOptions,
) -> Result<CalibrationRecord, CsvError> {
    let cx = Ctx { file };
    let mut lines = Lines::new(reader, opts);
    let sensors = instrument.columns();
    let mut expected: Vec<String> = MEASURED.iter().map(|s| s.to_string()).collect();
    expected.extend(sensors.iter().cloned());
    expected.push("t_s".into());
    // Column i holds: 0..3 the error vector, 3.. the sensors, usize::MAX the time.
    let (header_line, names, cols) = loop {
        let Some((line, text)) = lines.next_line(&cx)? else {
            return Err(cx.err(
                lines.number_at_end(),
                None,
                format!(
                    "empty file: expected a header line naming the columns ({})",
                    expected.join(", ")
                ),
            ));
        };
        if !is_data(text) {
            continue;
        }
        let names: Vec<String> = text.split(',').map(|n| clean_name(n).to_string()).collect();
        let mut cols: Vec<usize> = Vec::with_capacity(names.len());
        for (i, name) in names.iter().enumerate() {
            let col = if name.eq_ignore_ascii_case("t_s") {
                Some(usize::MAX)
            } else {
                expected[..expected.len() - 1]
                    .iter()
                    .position(|c| c.eq_ignore_ascii_case(name))
            };
            let Some(col) = col else {
                return Err(cx.err(
                    line,
                    Some((i, name)),
                    format!(
                        "unknown column `{name}` (a calibration record of instrument {} has the columns {})",
                        instrument.name,
                        expected.join(", ")
                    ),
                ));
            };
            if let Some(j) = cols.iter().position(|&c| c == col) {
                return Err(cx.err(
                    line,
                    Some((i, name)),
                    format!("column `{name}` appears twice (also column {})", j + 1),
                ));
            }
            cols.push(col);
        }
        let missing: Vec<&str> = (0..expected.len() - 1)
            .filter(|c| !cols.contains(c))
            .map(|c| expected[c].as_str())
            .collect();
        if !missing.is_empty() {
            return Err(cx.err(
                line,
                None,
                format!(
                    "missing column(s) {}: a calibration record needs the known error vector (dx_um, dy_um, dz_um) and every sensor's reading",
                    missing.join(", ")
                ),
            ));
        }
        break (line, names, cols);
    };
    let mut out = CalibrationRecord::default();
    let mut last_t: Option<(f64, usize)> = None;
    let reading_bound = max_sensor_reading_mm(opts.max_reading_mm);
    while let Some((line, text)) = lines.next_line(&cx)? {
        if !is_data(text) {
            continue;
        }
        let n_fields = text.bytes().filter(|&b| b == b',').count() + 1;
        if n_fields != cols.len() {
            return Err(cx.err(
                line,
                None,
                format!(
                    "ragged row: {n_fields} field(s), the header (line {header_line}) has {} columns",
                    cols.len()
                ),
            ));
        }
        let mut d = [0.0; 3];
        let mut s = vec![0.0; sensors.len()];
        for (i, (field, &col)) in text.split(',').zip(&cols).enumerate() {
            let f = field.trim();
            let unit = if col == usize::MAX { "s" } else { "µm" };
            let value = if col == usize::MAX {
                f.parse::<f64>().ok()
            } else {
                parse_scaled(f, -3)
            };
            let Some(x) = value.filter(|x| x.is_finite()) else {
                let why = if f.is_empty() {
                    format!("empty field: expected a number ({unit})")
                } else {
                    format!("`{f}` is not a finite number ({unit})")
                };
                return Err(cx.err(line, Some((i, names[i].as_str())), why));
            };
            match col {
                usize::MAX => {
                    if let Some((prev, prev_line)) = last_t
                        && x < prev
                    {
                        return Err(cx.err(
                            line,
                            Some((i, names[i].as_str())),
                            format!("time {f} s is before the time of the previous sample ({} s, line {prev_line}): times must not decrease", significant(prev)),
                        ));
                    }
                    last_t = Some((x, line));
                }
                c => {
                    let (bound, what) = if c < 3 {
                        (opts.max_reading_mm, "a known displacement")
                    } else {
                        (reading_bound, "a sensor's reading")
                    };
                    if let Some(why) = beyond(x, bound, what) {
                        return Err(cx.err(line, Some((i, names[i].as_str())), why));
                    }
                    if c < 3 {
                        d[c] = x;
                    } else {
                        s[c - 3] = x;
                    }
                }
            }
        }
        out.displacements.push(d);
        out.readings.push(s);
        out.lines.push(line);
    }
    if out.lines.is_empty() {
        return Err(cx.err(
            header_line,
            None,
            "header only: the file has no rows (one row per known displacement expected after the header)",
        ));
    }
    Ok(out)
}

/// Reads the calibration record file `path` of `instrument` ([`read_calibration`]).
///
/// # Errors
/// As [`read_calibration`]; [`CsvError::Io`] when the file cannot be opened.
pub fn read_calibration_file(
    path: &Path,
    instrument: &Instrument,
    opts: &ReadOptions,
) -> Result<CalibrationRecord, CsvError> {
    let (file, f) = crate::csv::open(path)?;
    let mut r = read_calibration(&file, f, instrument, opts)?;
    r.file = file;
    Ok(r)
}
