//! The sample-timing plan of a measurement program: for every pose, when the machine arrives
//! there, the measuring window, and when it leaves, on the program clock; written as a CSV
//! beside the program and read back.
//!
//! The program clock starts (`t = 0`) when the program resumes after its stop (`M0`, `STOP`),
//! the nest at rest on the ball at the first pose where the approach left it. The clearance,
//! the approach and the operator's check at the stop come before that, the retract after the
//! last pose's departure: they take what they take, so none of them is in the plan, whose
//! times are those of the measuring poses only. Every time is in s on that clock.
//!
//! **The CSV** (one row per pose, in the order of the program):
//!
//! | column | unit | what |
//! |---|---|---|
//! | `sample` | 1 | the pose's number, 1, 2, … |
//! | one per axis (`X,Y,Z,A,C`) | mm, degrees | the pose as the program commands it (its words, rounded to the program's decimals) |
//! | `arrive_s` | s | the machine is at rest at the pose (static), or passes it (continuous) |
//! | `start_s`, `end_s` | s | the measuring window: `arrive_s` + settle time to the end of the dwell (static); the instant the pose is passed, `start_s = end_s` (continuous) |
//! | `depart_s` | s | the next move starts |
//!
//! Every row has `arrive_s ≤ start_s ≤ end_s ≤ depart_s ≤` the next row's `arrive_s`. In a
//! static plan every window has a length (`end_s > start_s`); in a continuous one none has.
//! In a continuous plan the first row rests from `arrive_s` (the lead-in dwell) and the last
//! until `depart_s` (the lead-out dwell): the still periods the segmentation finds the program
//! by. The columns are matched without regard to case (spaces or double quotes around a name
//! are ignored), in any order; `#` lines and blank lines are comments. Numbers are decimals
//! (an exponent is allowed), written by rtest as the shortest decimal that reads back to the
//! same `f64`.

use formats::csv::{CsvError, Ctx, Lines, ReadOptions, clean_name, column_order, comment_lines};
use model_spec::units::{degrees_for, format_scaled, parse_scaled};
use model_spec::{AxisKind, Machine};
use simulation::paths::record_from_commands;
use simulation::record::Record;
use std::io::Read;
use std::path::Path;

/// The names of the time columns of a plan, in the order they are written.
pub const PLAN_TIMES: [&str; 4] = ["arrive_s", "start_s", "end_s", "depart_s"];

/// How the poses are measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlanKind {
    /// At rest: each pose has a measuring window (a dwell).
    Static,
    /// On the fly: each pose is an instant of a continuous run.
    Continuous,
}

impl PlanKind {
    /// `static` or `continuous`, as messages and headers name it.
    pub fn name(self) -> &'static str {
        match self {
            PlanKind::Static => "static",
            PlanKind::Continuous => "continuous",
        }
    }
}

/// One pose of a plan and its times (s, program clock).
#[derive(Clone, Debug, PartialEq)]
pub struct PlanRow {
    /// The commanded pose, in [`Machine::axes`] order: mm for linear axes, rad for rotary ones.
    pub commands: Vec<f64>,
    /// The machine is at rest at the pose (static) or passes it (continuous), s.
    pub arrive_s: f64,
    /// The measuring window starts, s.
    pub start_s: f64,
    /// The measuring window ends, s (equal to `start_s` in a continuous plan).
    pub end_s: f64,
    /// The move to the next pose starts, s.
    pub depart_s: f64,
}

impl PlanRow {
    /// The four times in the order of [`PLAN_TIMES`], s.
    pub fn times(&self) -> [f64; 4] {
        [self.arrive_s, self.start_s, self.end_s, self.depart_s]
    }

    /// The middle of the measuring window, s.
    pub fn middle_s(&self) -> f64 {
        0.5 * (self.start_s + self.end_s)
    }
}

/// The sample-timing plan: one row per pose of the program, in its order.
#[derive(Clone, Debug, PartialEq)]
pub struct TimingPlan {
    /// Static or continuous.
    pub kind: PlanKind,
    /// The poses and their times.
    pub rows: Vec<PlanRow>,
}

impl TimingPlan {
    /// Checks the plan: at least one row; finite times in order within each row and from row
    /// to row; windows of a length in a static plan and of none in a continuous one.
    ///
    /// # Errors
    /// The index of the first row at fault and what is wrong.
    pub fn check(&self) -> Result<(), (usize, String)> {
        if self.rows.is_empty() {
            return Err((0, "a plan without a pose".into()));
        }
        let mut previous_depart = f64::NEG_INFINITY;
        for (i, r) in self.rows.iter().enumerate() {
            check_row(self.kind, r, previous_depart).map_err(|m| (i, m))?;
            previous_depart = r.depart_s;
        }
        Ok(())
    }

    /// The plan's poses as a record without readings: the commands (mm, rad), the time of each
    /// sample the middle of its measuring window (s), the directions of motion from the order of
    /// the poses. What a static simulation of the same poses takes ([`simulation::simulate`]).
    pub fn record(&self) -> Record {
        record_from_commands(
            self.rows.iter().map(|r| r.commands.clone()).collect(),
            self.rows.iter().map(PlanRow::middle_s).collect(),
        )
    }

    /// When the program ends: the last row's `depart_s`, s.
    pub fn duration_s(&self) -> f64 {
        self.rows.last().map_or(0.0, |r| r.depart_s)
    }
}

/// What is wrong with row `r` of a plan of kind `kind` after a row that departs at
/// `previous_depart` (s).
fn check_row(kind: PlanKind, r: &PlanRow, previous_depart: f64) -> Result<(), String> {
    let t = r.times();
    if let Some(k) = t.iter().position(|x| !x.is_finite()) {
        return Err(format!("{} is not finite", PLAN_TIMES[k]));
    }
    if let Some(k) = (1..4).find(|&k| t[k] < t[k - 1]) {
        return Err(format!(
            "{} = {} s is before {} = {} s",
            PLAN_TIMES[k],
            t[k],
            PLAN_TIMES[k - 1],
            t[k - 1]
        ));
    }
    if r.arrive_s < previous_depart {
        return Err(format!(
            "arrive_s = {} s is before the previous pose's depart_s = {previous_depart} s",
            r.arrive_s
        ));
    }
    match kind {
        PlanKind::Static if r.end_s <= r.start_s => Err(format!(
            "a measuring window without a length (start_s = end_s = {} s) in a static plan",
            r.start_s
        )),
        PlanKind::Continuous if r.end_s != r.start_s => Err(format!(
            "a measuring window of {} s in a continuous plan, whose poses are instants (start_s = end_s)",
            r.end_s - r.start_s
        )),
        _ => Ok(()),
    }
}

/// The CSV text of `plan` for machine `m`: `comments` as `# ` lines, the header (`sample`, the
/// axes as [`column_order`] orders them, [`PLAN_TIMES`]), one row per pose; linear axes in mm,
/// rotary axes in degrees, times in s, each the shortest decimal that reads back to the same
/// value.
///
/// # Errors
/// [`CsvError::Record`] when a row does not have one command per axis, a value is not finite,
/// or the plan does not pass [`TimingPlan::check`].
pub fn format_plan(
    m: &Machine,
    plan: &TimingPlan,
    comments: &[String],
) -> Result<String, CsvError> {
    plan.check()
        .map_err(|(i, why)| CsvError::Record(format!("plan row {}: {why}", i + 1)))?;
    let axes = column_order(m);
    let mut out = comment_lines(comments);
    let mut header = vec!["sample"];
    header.extend(axes.iter().map(|&a| m.axes[a].name.as_str()));
    header.extend(PLAN_TIMES);
    out += &header.join(",");
    out.push('\n');
    for (i, r) in plan.rows.iter().enumerate() {
        if r.commands.len() != m.axes.len() || r.commands.iter().any(|q| !q.is_finite()) {
            return Err(CsvError::Record(format!(
                "plan row {}: {} commands for the {} axes of machine {}, or a value that is not finite",
                i + 1,
                r.commands.len(),
                m.axes.len(),
                m.name
            )));
        }
        out += &(i + 1).to_string();
        for &a in &axes {
            out.push(',');
            let q = r.commands[a];
            out += &match m.axes[a].kind {
                AxisKind::Linear => format_scaled(q, 0),
                AxisKind::Rotary => format_scaled(degrees_for(q), 0),
            };
        }
        for t in r.times() {
            out.push(',');
            out += &format_scaled(t, 0);
        }
        out.push('\n');
    }
    Ok(out)
}

/// Reads a plan CSV (text `text`, named `file` in messages) of machine `m`; see [`read_plan`].
///
/// # Errors
/// As [`read_plan`].
pub fn parse_plan(file: &str, text: &str, m: &Machine) -> Result<TimingPlan, CsvError> {
    read_plan_from(file, text.as_bytes(), m)
}

/// Reads the plan CSV file `path` of machine `m` (see the module documentation): commands in
/// mm and rad, times in s. The kind (static or continuous) is that of the first row.
///
/// # Errors
/// [`CsvError::Format`] naming the line and, where there is one, the column: an unknown,
/// missing or repeated column, a row of the wrong length, a number that cannot be read or is
/// not finite, a sample number out of order, times out of order, a pose outside the machine's
/// strokes and ranges, a row of the other kind, a file without a row; [`CsvError::Io`] when the
/// file cannot be read.
pub fn read_plan(path: &Path, m: &Machine) -> Result<TimingPlan, CsvError> {
    let (file, f) = formats::csv::open(path)?;
    read_plan_from(&file, f, m)
}

/// What a column of a plan holds.
#[derive(Clone, Copy, PartialEq, Eq)]
enum PlanCol {
    Sample,
    Axis(usize),
    Time(usize),
}

fn read_plan_from<R: Read>(file: &str, reader: R, m: &Machine) -> Result<TimingPlan, CsvError> {
    let cx = Ctx { file };
    let mut lines = Lines::new(reader, &ReadOptions::default());
    let mut header: Option<(Vec<String>, Vec<PlanCol>)> = None;
    let mut rows: Vec<PlanRow> = Vec::new();
    let mut kind = PlanKind::Static;
    let mut previous_depart = f64::NEG_INFINITY;
    while let Some((line, text)) = lines.next_line(&cx)? {
        let trimmed = text.trim();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        let Some((names, cols)) = &header else {
            header = Some(plan_header(&cx, line, text, m)?);
            continue;
        };
        let fields: Vec<&str> = text.split(',').collect();
        if fields.len() != cols.len() {
            return Err(cx.err(
                line,
                None,
                format!("{} fields, the header has {}", fields.len(), cols.len()),
            ));
        }
        let mut commands = vec![0.0; m.axes.len()];
        let mut times = [0.0; 4];
        for (i, (field, col)) in fields.iter().zip(cols).enumerate() {
            let at = Some((i, names[i].as_str()));
            let value = parse_scaled(clean_name(field), 0)
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    cx.err(
                        line,
                        at,
                        format!("`{}` is not a finite decimal number", field.trim()),
                    )
                })?;
            match *col {
                PlanCol::Sample => {
                    if value != (rows.len() + 1) as f64 {
                        return Err(cx.err(
                            line,
                            at,
                            format!(
                                "sample {} where sample {} belongs: the rows number the poses 1, 2, … in order",
                                field.trim(),
                                rows.len() + 1
                            ),
                        ));
                    }
                }
                PlanCol::Axis(a) => {
                    commands[a] = match m.axes[a].kind {
                        AxisKind::Linear => value,
                        AxisKind::Rotary => value.to_radians(),
                    }
                }
                PlanCol::Time(k) => times[k] = value,
            }
        }
        if let Err(e) = m.check_pose(&commands) {
            return Err(cx.err(line, None, format!("the pose is refused: {e}")));
        }
        let row = PlanRow {
            commands,
            arrive_s: times[0],
            start_s: times[1],
            end_s: times[2],
            depart_s: times[3],
        };
        if rows.is_empty() && row.end_s == row.start_s {
            kind = PlanKind::Continuous;
        }
        check_row(kind, &row, previous_depart).map_err(|why| {
            let why = if rows.is_empty() {
                why
            } else {
                format!("{why} (the plan is {}, by its first row)", kind.name())
            };
            cx.err(line, None, why)
        })?;
        previous_depart = row.depart_s;
        rows.push(row);
    }
    if rows.is_empty() {
        let line = lines.number_at_end();
        let what = if header.is_some() {
            "a plan with a header and no row: no pose to measure"
        } else {
            "an empty plan: no header and no row"
        };
        return Err(cx.err(line, None, what));
    }
    Ok(TimingPlan { kind, rows })
}

/// The header of a plan: its column names and what each holds.
fn plan_header(
    cx: &Ctx,
    line: usize,
    text: &str,
    m: &Machine,
) -> Result<(Vec<String>, Vec<PlanCol>), CsvError> {
    let expected = {
        let mut v = vec!["sample".to_string()];
        v.extend(column_order(m).into_iter().map(|a| m.axes[a].name.clone()));
        v.extend(PLAN_TIMES.iter().map(|s| s.to_string()));
        v.join(",")
    };
    let names: Vec<String> = text.split(',').map(|n| clean_name(n).to_string()).collect();
    let mut cols: Vec<PlanCol> = Vec::with_capacity(names.len());
    for (i, name) in names.iter().enumerate() {
        let col = if name.eq_ignore_ascii_case("sample") {
            Some(PlanCol::Sample)
        } else if let Some(k) = PLAN_TIMES.iter().position(|t| t.eq_ignore_ascii_case(name)) {
            Some(PlanCol::Time(k))
        } else {
            m.axes
                .iter()
                .position(|a| a.name.eq_ignore_ascii_case(name))
                .map(PlanCol::Axis)
        };
        let col = col.ok_or_else(|| {
            cx.err(
                line,
                Some((i, name)),
                format!(
                    "unknown column `{name}` (the columns of a plan of machine {}: {expected})",
                    m.name
                ),
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
    let mut missing: Vec<String> = Vec::new();
    if !cols.contains(&PlanCol::Sample) {
        missing.push("sample".into());
    }
    missing.extend(
        column_order(m)
            .into_iter()
            .filter(|&a| !cols.contains(&PlanCol::Axis(a)))
            .map(|a| m.axes[a].name.clone()),
    );
    missing.extend(
        (0..4)
            .filter(|&k| !cols.contains(&PlanCol::Time(k)))
            .map(|k| PLAN_TIMES[k].to_string()),
    );
    if !missing.is_empty() {
        return Err(cx.err(
            line,
            None,
            format!(
                "missing column(s) {} (the columns of a plan of machine {}: {expected})",
                missing.join(", "),
                m.name
            ),
        ));
    }
    Ok((names, cols))
}
