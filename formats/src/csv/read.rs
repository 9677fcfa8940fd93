//! The header and the rows of measurement and path CSVs, shared by the whole-file reader
//! ([`crate::csv::read_csv`]) and the block reader for long records
//! ([`crate::csv::MeasurementBlocks`]), so both give the same errors at the same lines and
//! columns. The format is described in [`crate::csv`].

use crate::csv::checks::SampleChecks;
use crate::csv::lines::Lines;
use crate::csv::{
    Col, CsvError, Ctx, MEASURED, Need, ReadOptions, classify, clean_name, expected_columns,
};
use model_spec::units::{parse_scaled, significant};
use model_spec::{AxisKind, Machine};
use simulation::exact::{ExactError, VirtualMachine};
use simulation::paths::fill_linear_ik;
use std::io::Read;

/// The parsed header of a CSV: what each column holds.
pub(crate) struct Header {
    /// Its line number.
    pub(crate) line: usize,
    names: Vec<String>,
    cols: Vec<Col>,
    /// The linear axes are absent and filled by the nominal inverse kinematics.
    fill_ik: bool,
    /// The three measured columns are present.
    pub(crate) measured: bool,
    /// The number of extra columns asked for ([`Header::parse`]), all present.
    extra: usize,
}

/// One parsed row: commands (mm, rad), time (s, `None` without a `t_s` column) and the
/// measured error vector (mm, zeros without measured columns).
pub(crate) type Row = (Vec<f64>, Option<f64>, [f64; 3]);

impl Header {
    /// Parses the header line `text` (line number `line`), with the columns `extra` (µm,
    /// matched without regard to case) required beside the machine's: their values are read by
    /// [`Header::row_with`], in this order.
    pub(crate) fn parse(
        cx: &Ctx,
        line: usize,
        text: &str,
        m: &Machine,
        need: Need,
        extra: &[String],
    ) -> Result<Header, CsvError> {
        let mut expected = expected_columns(m);
        if !extra.is_empty() {
            expected += &format!("; and {}", extra.join(", "));
        }
        let names: Vec<String> = text.split(',').map(|n| clean_name(n).to_string()).collect();
        let mut cols: Vec<Col> = Vec::with_capacity(names.len());
        for (i, name) in names.iter().enumerate() {
            let col = extra
                .iter()
                .position(|x| x.eq_ignore_ascii_case(name))
                .map(Col::Extra)
                .or_else(|| classify(m, name));
            let col = col.ok_or_else(|| {
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
        let extra_missing: Vec<&str> = (0..extra.len())
            .filter(|&k| !has(Col::Extra(k)))
            .map(|k| extra[k].as_str())
            .collect();
        if !extra_missing.is_empty() {
            return Err(cx.err(
                line,
                None,
                format!(
                    "missing column(s) {} (sensor readings, µm): every sensor of the instrument needs a column",
                    extra_missing.join(", ")
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
            extra: extra.len(),
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
        self.row_with(cx, line, text, m, last_t).map(|(row, _)| row)
    }

    /// [`Header::row`], with the values of the extra columns (mm, read from µm), in the order
    /// they were asked for.
    pub(crate) fn row_with(
        &self,
        cx: &Ctx,
        line: usize,
        text: &str,
        m: &Machine,
        last_t: &mut Option<(f64, usize)>,
    ) -> Result<(Row, Vec<f64>), CsvError> {
        let n_fields = text.bytes().filter(|&b| b == b',').count() + 1;
        if n_fields != self.cols.len() {
            return Err(cx.err(
                line,
                None,
                format!(
                    "ragged row: {n_fields} field(s), the header (line {}) has {} columns",
                    self.line,
                    self.cols.len()
                ),
            ));
        }
        let mut c = vec![0.0; m.axes.len()];
        let mut t = None;
        let mut d = [0.0; 3];
        let mut extra = vec![0.0; self.extra];
        for (i, (field, &col)) in text.split(',').zip(&self.cols).enumerate() {
            let f = field.trim();
            let bad = || self.bad_number(cx, line, i, f, col, m);
            match col {
                Col::Measured(k) => {
                    d[k] = match parse_scaled(f, -3) {
                        Some(v) if v.is_finite() => v,
                        _ => return Err(bad()),
                    }
                }
                Col::Extra(k) => {
                    extra[k] = match parse_scaled(f, -3) {
                        Some(v) if v.is_finite() => v,
                        _ => return Err(bad()),
                    }
                }
                Col::Axis(a) => {
                    let x = f
                        .parse::<f64>()
                        .ok()
                        .filter(|x| x.is_finite())
                        .ok_or_else(bad)?;
                    c[a] = match m.axes[a].kind {
                        AxisKind::Rotary => x.to_radians(),
                        AxisKind::Linear => x,
                    }
                }
                Col::Time => {
                    let x = f
                        .parse::<f64>()
                        .ok()
                        .filter(|x| x.is_finite())
                        .ok_or_else(bad)?;
                    if let Some((prev, prev_line)) = *last_t
                        && x < prev
                    {
                        return Err(cx.err(
                            line,
                            Some((i, self.names[i].as_str())),
                            format!("time {f} s is before the time of the previous sample ({} s, line {prev_line}): times must not decrease", significant(prev)),
                        ));
                    }
                    *last_t = Some((x, line));
                    t = Some(x);
                }
            }
        }
        Ok(((c, t, d), extra))
    }

    /// Why the field `f` of column `i` (holding `col`) on line `line` is not a number that can
    /// be read.
    /// The column index and name of extra column `k` ([`Header::row_with`]'s order).
    pub(crate) fn extra_column(&self, k: usize) -> (usize, &str) {
        let i = self
            .cols
            .iter()
            .position(|c| matches!(c, Col::Extra(j) if *j == k))
            .unwrap_or(0);
        (i, self.names.get(i).map_or("", String::as_str))
    }

    fn bad_number(
        &self,
        cx: &Ctx,
        line: usize,
        i: usize,
        f: &str,
        col: Col,
        m: &Machine,
    ) -> CsvError {
        let unit = match col {
            Col::Axis(a) if m.axes[a].kind == AxisKind::Rotary => "degrees",
            Col::Axis(_) => "mm",
            Col::Time => "s",
            Col::Measured(_) | Col::Extra(_) => "µm",
        };
        let why = match f.parse::<f64>() {
            _ if f.is_empty() => format!("empty field: expected a number ({unit})"),
            Err(_) => format!("`{f}` is not a number ({unit})"),
            Ok(x) if !x.is_finite() => format!("`{f}` is not a finite number ({unit})"),
            Ok(_) => format!("`{f}` is out of range ({unit})"),
        };
        cx.err(line, Some((i, self.names[i].as_str())), why)
    }

    /// Fills the linear commands by inverse kinematics when the file has none.
    pub(crate) fn fill(
        &self,
        cx: &Ctx,
        m: &Machine,
        commands: &mut [Vec<f64>],
        lines: &[usize],
    ) -> Result<(), CsvError> {
        if !self.fill_ik {
            return Ok(());
        }
        fill_linear_ik(m, &m.default_parameters(), commands)
            .map_err(|(i, e)| ik_error(cx, lines[i], e))
    }

    /// The nominal inverse kinematics that fills the linear commands of one row at a time
    /// (machine lowered once, default kinematic parameters), when the file has no linear
    /// columns.
    pub(crate) fn row_ik<'m>(&self, m: &'m Machine) -> Option<RowIk<'m>> {
        self.fill_ik
            .then(|| RowIk(VirtualMachine::new(m), m.default_parameters()))
    }

    /// The checks of the samples of this file ([`SampleChecks`]).
    pub(crate) fn checks<'m>(&self, m: &'m Machine, opts: &ReadOptions) -> SampleChecks<'m> {
        SampleChecks::new(m, !self.fill_ik, opts)
    }
}

/// The nominal inverse kinematics of a machine at its default kinematic parameters (mm).
pub(crate) struct RowIk<'m>(VirtualMachine<'m>, Vec<f64>);

impl RowIk<'_> {
    /// Fills the linear entries (mm) of the commands `c` of the row at line `line`.
    pub(crate) fn fill(&self, cx: &Ctx, line: usize, c: &mut [f64]) -> Result<(), CsvError> {
        self.0
            .tool_centre_point_ik(c, &self.1)
            .map_err(|e| ik_error(cx, line, e))
    }
}

fn ik_error(cx: &Ctx, line: usize, e: ExactError) -> CsvError {
    cx.err(
        line,
        None,
        format!(
            "the linear axes are not given and the nominal inverse kinematics cannot fill them: {e}"
        ),
    )
}

/// Whether a line holds data: neither blank nor a `#` comment.
pub(crate) fn is_data(text: &str) -> bool {
    let t = text.trim_start();
    !t.is_empty() && !t.starts_with('#')
}

/// Reads lines up to the header and parses it.
///
/// # Errors
/// An empty file (no header before the end, at the line number after the last line), or what
/// [`Header::parse`] finds wrong.
pub(crate) fn read_header<R: Read>(
    cx: &Ctx,
    lines: &mut Lines<R>,
    m: &Machine,
    need: Need,
) -> Result<Header, CsvError> {
    read_header_with(cx, lines, m, need, &[])
}

/// [`read_header`], with the extra columns `extra` ([`Header::parse`]).
pub(crate) fn read_header_with<R: Read>(
    cx: &Ctx,
    lines: &mut Lines<R>,
    m: &Machine,
    need: Need,
    extra: &[String],
) -> Result<Header, CsvError> {
    loop {
        let Some((line, text)) = lines.next_line(cx)? else {
            return Err(cx.err(
                lines.number_at_end(),
                None,
                format!(
                    "empty file: expected a header line naming the columns ({})",
                    expected_columns(m)
                ),
            ));
        };
        if is_data(text) {
            return Header::parse(cx, line, text, m, need, extra);
        }
    }
}

/// The error of a file with a header and no samples.
pub(crate) fn header_only(cx: &Ctx, header: &Header) -> CsvError {
    cx.err(
        header.line,
        None,
        "header only: the file has no samples (one row per sample expected after the header)",
    )
}
