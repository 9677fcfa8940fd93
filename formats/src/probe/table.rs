//! What the two probe CSVs share: the header (a `pose` column, one column per axis of the
//! machine, the format's own columns), the rows read through the bounded line reader of the
//! measurement CSV, and the checks of a label, an axis value and a number.

use crate::csv::lines::Lines;
use crate::csv::{CsvError, Ctx, ReadOptions, clean_name, column_order};
use crate::poses::MAX_COMMAND;
use model_spec::units::parse_scaled;
use model_spec::{AxisKind, Machine};
use std::io::Read;

use super::{MAX_LABEL_CHARS, POSE_COLUMN};

/// What a column of a probe CSV holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Col {
    Pose,
    Axis(usize),
    /// The format's own column, by its index in the format's list.
    Own(usize),
}

/// The header of a probe CSV: its line, its column names, what each holds, and which of the
/// format's own columns are there.
pub(super) struct Header {
    pub line: usize,
    names: Vec<String>,
    columns: Vec<Col>,
    /// Whether each of the format's own columns is in the header.
    pub present: Vec<bool>,
}

/// One row as read: its line, the pose label, the axis values (machine order: mm, degrees),
/// and the format's own columns (`None` where the header has no such column).
pub(super) struct Row {
    pub line: usize,
    pub pose: String,
    pub axes: Vec<f64>,
    pub own: Vec<Option<f64>>,
}

/// The rows of a probe CSV being read, with the header and its context.
pub(super) struct Rows<'a, R> {
    pub cx: Ctx<'a>,
    lines: Lines<R>,
    pub header: Header,
    own: &'a [&'a str],
    /// The unit of each own column, for messages.
    units: &'a [&'a str],
    m: &'a Machine,
    /// What the file is, for messages (`a probe hits CSV`).
    what: &'a str,
}

impl<'a, R: Read> Rows<'a, R> {
    /// Reads the header of `reader` (named `file`): `own` lists the format's own columns, in
    /// the order their values are given, `units` their units (for messages); `what` names the
    /// file's kind in messages.
    ///
    /// The caller checks which own columns are required with [`Header::present`].
    pub fn new(
        file: &'a str,
        reader: R,
        m: &'a Machine,
        own: &'a [&'a str],
        units: &'a [&'a str],
        what: &'a str,
    ) -> Result<Self, CsvError> {
        let cx = Ctx { file };
        let mut lines = Lines::new(reader, &ReadOptions::default());
        let header = loop {
            let Some((number, line)) = lines.next_line(&cx)? else {
                return Err(cx.err(
                    lines.number_at_end(),
                    None,
                    format!(
                        "no header: {what} names its columns in its first line that is not a comment ({})",
                        expected(m, own)
                    ),
                ));
            };
            if is_data(line) {
                break parse_header(&cx, number, line, m, own, what)?;
            }
        };
        Ok(Rows {
            cx,
            lines,
            header,
            own,
            units,
            m,
            what,
        })
    }

    /// A format error at `line`, in the column (0-based) of `col` when there is one.
    pub fn err_at(&self, line: usize, col: Option<usize>, msg: impl Into<String>) -> CsvError {
        self.cx
            .err(line, col.map(|i| (i, self.header.names[i].as_str())), msg)
    }

    /// The 0-based column of the pose label.
    pub fn pose_column(&self) -> usize {
        self.column_of(Col::Pose)
    }

    /// The 0-based column of axis `a` (machine order).
    pub fn axis_column(&self, a: usize) -> usize {
        self.column_of(Col::Axis(a))
    }

    /// The 0-based column of own column `k`, if the header has it.
    pub fn own_column(&self, k: usize) -> Option<usize> {
        self.header.columns.iter().position(|&c| c == Col::Own(k))
    }

    fn column_of(&self, c: Col) -> usize {
        // The header was checked to hold the pose and every axis.
        self.header
            .columns
            .iter()
            .position(|&x| x == c)
            .unwrap_or(0)
    }

    /// The next row, `None` at the end of the file.
    ///
    /// # Errors
    /// [`CsvError::Format`]: a row with another number of fields than the header, a label that
    /// is not a token, an axis value that is not a decimal, not finite or beyond
    /// [`MAX_COMMAND`] or the axis's limits, an own value that is not a finite decimal.
    pub fn next_row(&mut self) -> Result<Option<Row>, CsvError> {
        let (number, text) = loop {
            match self.lines.next_line(&self.cx)? {
                None => return Ok(None),
                Some((n, l)) if is_data(l) => break (n, l.to_string()),
                Some(_) => {}
            }
        };
        let fields: Vec<&str> = text.split(',').collect();
        let h = &self.header;
        if fields.len() != h.names.len() {
            return Err(self.cx.err(
                number,
                None,
                format!(
                    "{} field(s), the header (line {}) has {} columns",
                    fields.len(),
                    h.line,
                    h.names.len()
                ),
            ));
        }
        let mut row = Row {
            line: number,
            pose: String::new(),
            axes: vec![0.0; self.m.axes.len()],
            own: vec![None; self.own.len()],
        };
        for (i, (field, &col)) in fields.iter().zip(&h.columns).enumerate() {
            let t = field.trim();
            let at = |msg: String| self.err_at(number, Some(i), msg);
            match col {
                Col::Pose => {
                    row.pose = check_label(t).map_err(at)?;
                }
                Col::Axis(a) => {
                    let axis = &self.m.axes[a];
                    let unit = unit(axis.kind);
                    let x = number_of(t, unit).map_err(at)?;
                    if x.abs() >= MAX_COMMAND {
                        return Err(at(format!(
                            "{t} {unit} is beyond ±{MAX_COMMAND} (no axis command reaches it)"
                        )));
                    }
                    let [lo, hi] = axis.limits;
                    if x < lo - 1e-9 || x > hi + 1e-9 {
                        return Err(at(format!(
                            "{t} {unit} is outside the limits [{lo}, {hi}] {unit} of axis {} of machine {}",
                            axis.name, self.m.name
                        )));
                    }
                    row.axes[a] = x;
                }
                Col::Own(k) => {
                    row.own[k] = Some(number_of(t, self.units[k]).map_err(at)?);
                }
            }
        }
        Ok(Some(row))
    }

    /// The error for a header and no row.
    pub fn header_only(&self) -> CsvError {
        self.cx.err(
            self.header.line,
            None,
            format!("a header and no row: {} without data", self.what),
        )
    }
}

/// The first axis of `m` whose value in `axes` (mm, degrees) the reader would refuse: not
/// below [`MAX_COMMAND`] in magnitude, or outside the axis's limits by more than 1e-9.
pub(super) fn off_limits(m: &Machine, axes: &[f64]) -> Option<usize> {
    m.axes.iter().zip(axes).position(|(axis, &x)| {
        let [lo, hi] = axis.limits;
        x.abs() >= MAX_COMMAND || x < lo - 1e-9 || x > hi + 1e-9
    })
}

/// Whether a line holds data (is neither blank nor a `#` comment).
fn is_data(line: &str) -> bool {
    let t = line.trim();
    !t.is_empty() && !t.starts_with('#')
}

fn unit(kind: AxisKind) -> &'static str {
    match kind {
        AxisKind::Linear => "mm",
        AxisKind::Rotary => "deg",
    }
}

/// The finite decimal `t`, or the message saying why not (`unit` names its unit).
fn number_of(t: &str, unit: &str) -> Result<f64, String> {
    if t.is_empty() {
        return Err(format!("empty: a number ({unit}) belongs here"));
    }
    parse_scaled(t, 0)
        .filter(|x| x.is_finite())
        .ok_or_else(|| format!("`{t}` is not a finite decimal number ({unit})"))
}

/// The pose label `t` if it is a token: non-empty, at most [`MAX_LABEL_CHARS`] characters,
/// without blanks, control characters or double quotes, not starting with `#`.
pub(super) fn check_label(t: &str) -> Result<String, String> {
    if t.is_empty() {
        return Err("empty: every row names its pose".into());
    }
    if t.chars().count() > MAX_LABEL_CHARS {
        return Err(format!(
            "a pose label of more than {MAX_LABEL_CHARS} characters"
        ));
    }
    if let Some(c) = t
        .chars()
        .find(|c| c.is_whitespace() || c.is_control() || *c == '"')
    {
        return Err(format!(
            "`{}`: a pose label is one token, without blanks, control characters or quotes (found {c:?})",
            t.escape_debug()
        ));
    }
    if t.starts_with('#') {
        return Err(format!("`{t}`: a pose label cannot start with `#`"));
    }
    Ok(t.to_string())
}

fn expected(m: &Machine, own: &[&str]) -> String {
    let mut v = vec![POSE_COLUMN.to_string()];
    v.extend(
        column_order(m)
            .into_iter()
            .map(|a| format!("{} ({})", m.axes[a].name, unit(m.axes[a].kind))),
    );
    v.extend(own.iter().map(|s| s.to_string()));
    format!("columns {}", v.join(", "))
}

fn parse_header(
    cx: &Ctx,
    number: usize,
    line: &str,
    m: &Machine,
    own: &[&str],
    what: &str,
) -> Result<Header, CsvError> {
    let names: Vec<String> = line.split(',').map(|s| clean_name(s).to_string()).collect();
    let mut columns = Vec::with_capacity(names.len());
    for (i, name) in names.iter().enumerate() {
        let col = if name.eq_ignore_ascii_case(POSE_COLUMN) {
            Some(Col::Pose)
        } else if let Some(a) = m
            .axes
            .iter()
            .position(|a| a.name.eq_ignore_ascii_case(name))
        {
            Some(Col::Axis(a))
        } else {
            own.iter()
                .position(|c| c.eq_ignore_ascii_case(name))
                .map(Col::Own)
        };
        let Some(col) = col else {
            return Err(cx.err(
                number,
                Some((i, name)),
                format!(
                    "unknown column in {what} of machine {} ({})",
                    m.name,
                    expected(m, own)
                ),
            ));
        };
        if let Some(j) = columns.iter().position(|&c| c == col) {
            return Err(cx.err(
                number,
                Some((i, name)),
                format!("a second column `{}` (also column {})", names[j], j + 1),
            ));
        }
        columns.push(col);
    }
    let mut missing: Vec<String> = Vec::new();
    if !columns.contains(&Col::Pose) {
        missing.push(POSE_COLUMN.into());
    }
    for a in column_order(m) {
        if !columns.contains(&Col::Axis(a)) {
            missing.push(m.axes[a].name.clone());
        }
    }
    if !missing.is_empty() {
        return Err(cx.err(
            number,
            None,
            format!(
                "missing column(s) {}: {what} of machine {} has {}",
                missing.join(", "),
                m.name,
                expected(m, own)
            ),
        ));
    }
    let present = (0..own.len())
        .map(|k| columns.contains(&Col::Own(k)))
        .collect();
    Ok(Header {
        line: number,
        names,
        columns,
        present,
    })
}
