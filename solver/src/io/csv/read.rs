//! Reading measurement and path CSVs: the header, then one row at a time. The whole-file reader
//! ([`parse_csv`]) and the block reader for long records ([`MeasurementBlocks`]) share the same
//! header and row parsing, so both give the same errors at the same lines and columns. The
//! format is described in [`crate::io::csv`].

use crate::io::csv::{
    Col, CsvError, Ctx, MEASURED, Need, classify, clean_name, expected_columns, parse_scaled,
};
use crate::record::{Record, Sample};
use crate::simulation::paths::{fill_linear_ik, record_from_commands};
use model_spec::{AxisKind, Machine};
use std::io::BufRead;
use std::path::Path;

/// The parsed header of a CSV: what each column holds.
pub(crate) struct Header {
    line: usize,
    names: Vec<String>,
    cols: Vec<Col>,
    /// The linear axes are absent and filled by the nominal inverse kinematics.
    fill_ik: bool,
    /// The three measured columns are present.
    measured: bool,
}

/// One parsed row: commands (mm, rad), time (s, `None` without a `t_s` column) and the
/// measured error vector (mm, zeros without measured columns).
pub(crate) type Row = (Vec<f64>, Option<f64>, [f64; 3]);

impl Header {
    /// Parses the header line `text` (line number `line`).
    pub(crate) fn parse(
        cx: &Ctx,
        line: usize,
        text: &str,
        m: &Machine,
        need: Need,
    ) -> Result<Header, CsvError> {
        let expected = expected_columns(m);
        let names: Vec<String> = text.split(',').map(|n| clean_name(n).to_string()).collect();
        let mut cols: Vec<Col> = Vec::with_capacity(names.len());
        for (i, name) in names.iter().enumerate() {
            let col = classify(m, name).ok_or_else(|| {
                let what = if name.is_empty() {
                    "empty column name".to_string()
                } else {
                    format!("unknown column `{name}`")
                };
                cx.err(
                    line,
                    Some((i, name)),
                    format!("{what} (expected {expected})"),
                )
            })?;
            if let Some(j) = cols.iter().position(|&c| c == col) {
                return Err(cx.err(
                    line,
                    Some((i, name)),
                    format!("column `{name}` appears twice (also column {})", j + 1),
                ));
            }
            cols.push(col);
        }
        let has = |c: Col| cols.contains(&c);
        let missing = |ids: &mut dyn Iterator<Item = usize>| -> Vec<String> {
            ids.filter(|&a| !has(Col::Axis(a)))
                .map(|a| m.axes[a].name.clone())
                .collect()
        };
        let rotary_missing = missing(&mut m.rotary_axes());
        if !rotary_missing.is_empty() {
            return Err(cx.err(
                line,
                None,
                format!(
                    "missing column(s) {} (rotary axes, degrees): every rotary axis needs a column",
                    rotary_missing.join(", ")
                ),
            ));
        }
        let linear_missing = missing(&mut m.linear_axes());
        let n_linear = m.linear_axes().count();
        if !linear_missing.is_empty() && linear_missing.len() < n_linear {
            return Err(cx.err(
                line,
                None,
                format!(
                    "missing column(s) {} (linear axes, mm): give every linear axis or none (then they are filled by the nominal inverse kinematics)",
                    linear_missing.join(", ")
                ),
            ));
        }
        let n_measured = (0..3).filter(|&k| has(Col::Measured(k))).count();
        let required = need == Need::Measured || n_measured > 0;
        if required && n_measured < 3 {
            let absent: Vec<&str> = (0..3)
                .filter(|&k| !has(Col::Measured(k)))
                .map(|k| MEASURED[k])
                .collect();
            return Err(cx.err(
                line,
                None,
                format!(
                    "missing column(s) {} (measured error vector, µm): a measurement file needs dx_um, dy_um and dz_um",
                    absent.join(", ")
                ),
            ));
        }
        Ok(Header {
            line,
            names,
            cols,
            fill_ik: n_linear > 0 && !linear_missing.is_empty(),
            measured: n_measured == 3,
        })
    }

    /// Parses the row `text` (line number `line`); `last_t` is the time of the previous row with
    /// its line, for the check that times do not decrease.
    pub(crate) fn row(
        &self,
        cx: &Ctx,
        line: usize,
        text: &str,
        m: &Machine,
        last_t: &mut Option<(f64, usize)>,
    ) -> Result<Row, CsvError> {
        let fields: Vec<&str> = text.split(',').collect();
        if fields.len() != self.cols.len() {
            return Err(cx.err(
                line,
                None,
                format!(
                    "ragged row: {} field(s), the header (line {}) has {} columns",
                    fields.len(),
                    self.line,
                    self.cols.len()
                ),
            ));
        }
        let mut c = vec![0.0; m.axes.len()];
        let mut t = None;
        let mut d = [0.0; 3];
        for (i, (field, &col)) in fields.iter().zip(&self.cols).enumerate() {
            let at = Some((i, self.names[i].as_str()));
            let f = field.trim();
            let unit = match col {
                Col::Axis(a) if m.axes[a].kind == AxisKind::Rotary => "degrees",
                Col::Axis(_) => "mm",
                Col::Time => "s",
                Col::Measured(_) => "µm",
            };
            let x = match f.parse::<f64>() {
                _ if f.is_empty() => {
                    return Err(cx.err(
                        line,
                        at,
                        format!("empty field: expected a number ({unit})"),
                    ));
                }
                Ok(x) if x.is_finite() => x,
                Ok(_) => {
                    return Err(cx.err(line, at, format!("`{f}` is not a finite number ({unit})")));
                }
                Err(_) => return Err(cx.err(line, at, format!("`{f}` is not a number ({unit})"))),
            };
            match col {
                Col::Axis(a) => {
                    c[a] = match m.axes[a].kind {
                        AxisKind::Rotary => x.to_radians(),
                        AxisKind::Linear => x,
                    }
                }
                Col::Time => {
                    if let Some((prev, prev_line)) = *last_t
                        && x < prev
                    {
                        return Err(cx.err(
                            line,
                            at,
                            format!("time {f} s is before the time of the previous sample ({prev} s, line {prev_line}): times must not decrease"),
                        ));
                    }
                    *last_t = Some((x, line));
                    t = Some(x);
                }
                Col::Measured(k) => {
                    d[k] = match parse_scaled(f, -3) {
                        Some(v) if v.is_finite() => v,
                        _ => return Err(cx.err(line, at, format!("`{f}` is out of range (µm)"))),
                    }
                }
            }
        }
        Ok((c, t, d))
    }

    /// Fills the linear commands by inverse kinematics when the file has none.
    fn fill(
        &self,
        cx: &Ctx,
        m: &Machine,
        commands: &mut [Vec<f64>],
        lines: &[usize],
    ) -> Result<(), CsvError> {
        if !self.fill_ik {
            return Ok(());
        }
        fill_linear_ik(m, &m.default_parameters(), commands).map_err(|(i, e)| {
            cx.err(lines[i], None, format!("the linear axes are not given and the nominal inverse kinematics cannot fill them: {e}"))
        })
    }
}

/// The lines of a text that hold data: 1-based line numbers, without `#` comments and blank
/// lines, `\r` removed.
fn data_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.split('\n')
        .enumerate()
        .map(|(i, l)| (i + 1, l.strip_suffix('\r').unwrap_or(l)))
        .filter(|(_, l)| {
            let t = l.trim();
            !t.is_empty() && !t.starts_with('#')
        })
}

/// Reads a CSV of machine `m`; `need` says whether the measured columns are required.
pub fn parse_csv(file: &str, text: &str, m: &Machine, need: Need) -> Result<Record, CsvError> {
    let cx = Ctx { file };
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = data_lines(text);
    let Some((header_line, header)) = lines.next() else {
        let last = text.split('\n').count().max(1);
        return Err(cx.err(
            last,
            None,
            format!(
                "empty file: expected a header line naming the columns ({})",
                expected_columns(m)
            ),
        ));
    };
    let header = Header::parse(&cx, header_line, header, m, need)?;
    let (mut commands, mut times, mut measured, mut row_lines) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut last_t = None;
    for (line, row) in lines {
        let (c, t, d) = header.row(&cx, line, row, m, &mut last_t)?;
        times.push(t.unwrap_or(commands.len() as f64));
        commands.push(c);
        measured.push(d);
        row_lines.push(line);
    }
    if commands.is_empty() {
        return Err(cx.err(
            header.line,
            None,
            "header only: the file has no samples (one row per sample expected after the header)",
        ));
    }
    header.fill(&cx, m, &mut commands, &row_lines)?;
    let mut record = record_from_commands(commands, times);
    if header.measured {
        record.measured = measured;
    }
    Ok(record)
}

/// Most samples the first block of a [`MeasurementBlocks`] holds while waiting for every axis to
/// move.
pub const FIRST_LOOKAHEAD: usize = 65_536;

/// A long measurement file read in blocks of samples, without holding the record: each block
/// is a [`Record`] with its measurements. The direction of motion of every axis carries over
/// from one block to the next, and times (the `t_s` column, or the sample index in s) keep
/// counting, so the blocks are exactly the slices of [`parse_csv`]'s record. (The direction of
/// an axis before its first move is that of its first move; the first block grows until every
/// axis has moved, up to [`FIRST_LOOKAHEAD`] samples. An axis whose first move comes later
/// starts at +1 here, as if it had not moved.)
pub struct MeasurementBlocks<'m, R: BufRead> {
    m: &'m Machine,
    file: String,
    lines: std::io::Lines<R>,
    line: usize,
    header: Header,
    block: usize,
    samples: usize,
    last_t: Option<(f64, usize)>,
    /// The previous sample's commands and directions of motion.
    previous: Option<(Vec<f64>, Vec<i8>)>,
    failed: bool,
}

impl<'m> MeasurementBlocks<'m, std::io::BufReader<std::fs::File>> {
    /// Opens `path` (a measurement CSV of machine `m`) and reads its header; blocks hold
    /// `block` samples (the last one fewer).
    pub fn open(path: &Path, m: &'m Machine, block: usize) -> Result<Self, CsvError> {
        let file = path.display().to_string();
        let f = std::fs::File::open(path).map_err(|source| CsvError::Io {
            file: file.clone(),
            source,
        })?;
        MeasurementBlocks::new(file, std::io::BufReader::new(f), m, block)
    }
}

impl<'m, R: BufRead> MeasurementBlocks<'m, R> {
    /// Reads the header from `reader` (named `file` in messages).
    pub fn new(file: String, reader: R, m: &'m Machine, block: usize) -> Result<Self, CsvError> {
        let mut lines = reader.lines();
        let mut line = 0;
        let cx = Ctx { file: &file };
        let header = loop {
            let Some(l) = lines.next() else {
                return Err(cx.err(
                    line.max(1),
                    None,
                    format!(
                        "empty file: expected a header line naming the columns ({})",
                        expected_columns(m)
                    ),
                ));
            };
            line += 1;
            let l = l.map_err(|source| CsvError::Io {
                file: file.clone(),
                source,
            })?;
            let t = l
                .strip_prefix('\u{feff}')
                .unwrap_or(&l)
                .trim_end_matches('\r');
            if t.trim().is_empty() || t.trim().starts_with('#') {
                continue;
            }
            break Header::parse(&cx, line, t, m, Need::Measured)?;
        };
        Ok(MeasurementBlocks {
            m,
            file,
            lines,
            line,
            header,
            block: block.max(1),
            samples: 0,
            last_t: None,
            previous: None,
            failed: false,
        })
    }

    fn next_block(&mut self) -> Result<Option<Record>, CsvError> {
        let cx = Ctx { file: &self.file };
        let (mut commands, mut times, mut measured, mut row_lines) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        // The first block looks ahead until every axis has moved (its direction before the first
        // move is that of the first move, as in the whole-file reader), up to FIRST_LOOKAHEAD.
        let first = self.previous.is_none();
        let all_moved = |commands: &[Vec<f64>]| {
            commands
                .first()
                .is_none_or(|c0| (0..c0.len()).all(|a| commands.iter().any(|c| c[a] != c0[a])))
        };
        while commands.len() < self.block
            || (first && commands.len() < FIRST_LOOKAHEAD && !all_moved(&commands))
        {
            let Some(l) = self.lines.next() else { break };
            self.line += 1;
            let l = l.map_err(|source| CsvError::Io {
                file: self.file.clone(),
                source,
            })?;
            let t = l.trim_end_matches('\r');
            if t.trim().is_empty() || t.trim().starts_with('#') {
                continue;
            }
            let (c, time, d) = self
                .header
                .row(&cx, self.line, t, self.m, &mut self.last_t)?;
            times.push(time.unwrap_or((self.samples + commands.len()) as f64));
            commands.push(c);
            measured.push(d);
            row_lines.push(self.line);
        }
        if commands.is_empty() {
            if self.samples == 0 {
                return Err(cx.err(self.header.line, None, "header only: the file has no samples (one row per sample expected after the header)"));
            }
            return Ok(None);
        }
        self.header.fill(&cx, self.m, &mut commands, &row_lines)?;
        self.samples += commands.len();
        // Directions of motion, continuing from the previous block.
        let motion = match self.previous.take() {
            None => crate::record::motion_directions(&commands),
            Some((mut last, mut dir)) => commands
                .iter()
                .map(|c| {
                    for a in 0..c.len() {
                        if c[a] > last[a] {
                            dir[a] = 1;
                        } else if c[a] < last[a] {
                            dir[a] = -1;
                        }
                    }
                    last.clone_from(c);
                    dir.clone()
                })
                .collect(),
        };
        self.previous = Some((
            commands.last().cloned().unwrap_or_default(),
            motion.last().cloned().unwrap_or_default(),
        ));
        let samples = commands
            .into_iter()
            .zip(times)
            .zip(motion)
            .map(|((commands, t), motion)| Sample {
                commands,
                t,
                motion,
            })
            .collect();
        Ok(Some(Record { samples, measured }))
    }
}

impl<R: BufRead> Iterator for MeasurementBlocks<'_, R> {
    type Item = Result<Record, CsvError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.failed {
            return None;
        }
        match self.next_block() {
            Ok(b) => b.map(Ok),
            Err(e) => {
                self.failed = true;
                Some(Err(e))
            }
        }
    }
}

/// The first and last time of a measurement file (s), for normalising `time:K` terms over the
/// whole record when it is read in blocks (a pass over the file that keeps nothing else).
pub fn time_span(path: &Path, m: &Machine) -> Result<(f64, f64), CsvError> {
    let mut span: Option<(f64, f64)> = None;
    for block in MeasurementBlocks::open(path, m, 65_536)? {
        let b = block?;
        if let (Some(first), Some(last)) = (b.samples.first(), b.samples.last()) {
            span = Some(span.map_or((first.t, last.t), |(a, _)| (a, last.t)));
        }
    }
    Ok(span.unwrap_or((0.0, 0.0)))
}
