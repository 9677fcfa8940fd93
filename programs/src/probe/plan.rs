//! The probe plan: every hit of a probing program, what the control's log lacks (the pose's
//! label, the rotary angles, the approach direction, the hit's time), written as a CSV beside
//! the program and read back (`docs/probe-programs.md`).
//!
//! **The CSV** (one row per hit, in the order of the program):
//!
//! | column | unit | what |
//! |---|---|---|
//! | `pose` | | the pose's label (`p3`; `p3+`, `p3-` when each pose is probed from both sides) |
//! | `hit` | 1 | the hit's number in its pose, 1, 2, … |
//! | one per axis (`X,Y,Z,A,C`) | mm, degrees | the planned contact: the linear axes where the tip centre touches the nominal sphere, the rotary axes as the program commands them |
//! | `nx,ny,nz` | | the direction of the probing move, bed frame, unit |
//! | `t_s` | s | the nominal time of the contact from the resume after the stop |
//! | `line` | 1 | the program's line of the probing block (`G38.2`, `G31`, `TCH PROBE 0.1`) |
//!
//! The text follows the probe CSVs' rules (`docs/probe.md`); values are written as the
//! shortest decimal that reads back to the same `f64`.

use formats::csv::{CsvError, Ctx, Lines, ReadOptions, clean_name, column_order, comment_lines};
use formats::probe::{MAX_HITS, MAX_LABEL_CHARS, ROTARY_CONSTANT_DEG, UNIT_NORM_TOLERANCE};
use model_spec::units::{format_scaled, parse_scaled};
use model_spec::{AxisKind, Machine};
use std::collections::HashMap;
use std::io::Read;
use std::path::Path;

/// The columns of a probe plan beside the axes, `pose` and `hit` before them, the others after.
pub const PLAN_COLUMNS: [&str; 7] = ["pose", "hit", "nx", "ny", "nz", "t_s", "line"];

/// One planned hit.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedHit {
    /// The pose's label.
    pub pose: String,
    /// The hit's number in its pose, from 1.
    pub hit: usize,
    /// The planned contact, in [`Machine::axes`] order: mm for linear axes, degrees for rotary
    /// axes (machine coordinates).
    pub axes: Vec<f64>,
    /// The direction of the probing move, bed frame, unit.
    pub direction: [f64; 3],
    /// The nominal time of the contact, s.
    pub t_s: f64,
    /// The program's line of the probing block.
    pub line: usize,
}

/// The hits of a probing program, in its order.
#[derive(Clone, Debug, PartialEq)]
pub struct ProbePlan {
    /// The hits.
    pub rows: Vec<PlannedHit>,
}

/// The CSV text of `plan` for machine `m`, `comments` as `# ` lines (see the module
/// documentation).
///
/// # Errors
/// [`CsvError::Record`] for a row that [`parse_probe_plan`] would refuse: not one value per
/// axis, a value that is not finite, a label that is not a token.
pub fn format_probe_plan(
    m: &Machine,
    plan: &ProbePlan,
    comments: &[String],
) -> Result<String, CsvError> {
    let axes = column_order(m);
    let mut out = comment_lines(comments);
    let mut header: Vec<&str> = PLAN_COLUMNS[..2].to_vec();
    header.extend(axes.iter().map(|&a| m.axes[a].name.as_str()));
    header.extend(&PLAN_COLUMNS[2..]);
    out += &header.join(",");
    out.push('\n');
    for (i, r) in plan.rows.iter().enumerate() {
        let finite = r.axes.iter().chain(&r.direction).all(|v| v.is_finite()) && r.t_s.is_finite();
        if r.axes.len() != m.axes.len() || !finite || check_label(&r.pose).is_err() {
            return Err(CsvError::Record(format!(
                "plan row {}: not one finite value per axis of machine {}, or a pose label that is not a token",
                i + 1,
                m.name
            )));
        }
        out += &format!("{},{}", r.pose, r.hit);
        for &a in &axes {
            out.push(',');
            out += &format_scaled(r.axes[a], 0);
        }
        for v in r.direction.iter().chain([&r.t_s]) {
            out.push(',');
            out += &format_scaled(*v, 0);
        }
        out += &format!(",{}\n", r.line);
    }
    Ok(out)
}

/// Why `label` is not a pose label: empty, longer than [`MAX_LABEL_CHARS`], a blank, control
/// character, comma or double quote in it, or a `#` first.
fn check_label(label: &str) -> Result<(), String> {
    if label.is_empty() {
        return Err("empty: every hit names its pose".into());
    }
    if label.chars().count() > MAX_LABEL_CHARS {
        return Err(format!(
            "a pose label has at most {MAX_LABEL_CHARS} characters"
        ));
    }
    if let Some(c) = label
        .chars()
        .find(|c| c.is_whitespace() || c.is_control() || *c == '"' || *c == ',')
    {
        return Err(format!(
            "`{label}`: a pose label is one token, without blanks, control characters or quotes (found {c:?})"
        ));
    }
    if label.starts_with('#') {
        return Err(format!("`{label}`: a pose label does not start with #"));
    }
    Ok(())
}

/// Reads a probe plan (text `text`, named `file` in messages) of machine `m`; see
/// [`read_probe_plan`].
///
/// # Errors
/// As [`read_probe_plan`].
pub fn parse_probe_plan(file: &str, text: &str, m: &Machine) -> Result<ProbePlan, CsvError> {
    read_plan(file, text.as_bytes(), m)
}

/// Reads the probe plan CSV `path` of machine `m` (see the module documentation).
///
/// # Errors
/// [`CsvError::Format`] at the line and column of the first problem: an unknown, repeated or
/// missing column, a row of the wrong length, a label that is not a token, a pose whose hits
/// are not contiguous or not numbered 1, 2, …, a number that cannot be read, an axis outside
/// its limits, a rotary axis that moves within a pose, a direction that is not a unit vector,
/// time going backwards, lines not increasing, more than [`MAX_HITS`] rows, no row;
/// [`CsvError::Io`] when the file cannot be read.
pub fn read_probe_plan(path: &Path, m: &Machine) -> Result<ProbePlan, CsvError> {
    let (file, f) = formats::csv::open(path)?;
    read_plan(&file, f, m)
}

/// What a column of a plan holds.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Col {
    /// One of [`PLAN_COLUMNS`].
    Own(usize),
    Axis(usize),
}

fn header(
    cx: &Ctx,
    line: usize,
    text: &str,
    m: &Machine,
) -> Result<(Vec<String>, Vec<Col>), CsvError> {
    let mut expected: Vec<String> = PLAN_COLUMNS[..2].iter().map(|s| s.to_string()).collect();
    expected.extend(column_order(m).into_iter().map(|a| m.axes[a].name.clone()));
    expected.extend(PLAN_COLUMNS[2..].iter().map(|s| s.to_string()));
    let expected = expected.join(",");
    let names: Vec<String> = text.split(',').map(|n| clean_name(n).to_string()).collect();
    let mut cols: Vec<Col> = Vec::new();
    for (i, name) in names.iter().enumerate() {
        let col = PLAN_COLUMNS
            .iter()
            .position(|c| c.eq_ignore_ascii_case(name))
            .map(Col::Own)
            .or_else(|| {
                m.axes
                    .iter()
                    .position(|a| a.name.eq_ignore_ascii_case(name))
                    .map(Col::Axis)
            })
            .ok_or_else(|| {
                cx.err(
                    line,
                    Some((i, name)),
                    format!(
                        "unknown column in a probe plan of machine {} (columns {expected})",
                        m.name
                    ),
                )
            })?;
        if let Some(j) = cols.iter().position(|&c| c == col) {
            return Err(cx.err(
                line,
                Some((i, name)),
                format!("a second column `{}` (also column {})", names[j], j + 1),
            ));
        }
        cols.push(col);
    }
    let mut missing: Vec<String> = (0..PLAN_COLUMNS.len())
        .filter(|&k| !cols.contains(&Col::Own(k)))
        .map(|k| PLAN_COLUMNS[k].to_string())
        .collect();
    missing.extend(
        column_order(m)
            .into_iter()
            .filter(|&a| !cols.contains(&Col::Axis(a)))
            .map(|a| m.axes[a].name.clone()),
    );
    if !missing.is_empty() {
        return Err(cx.err(
            line,
            None,
            format!(
                "missing column(s) {}: a probe plan of machine {} has columns {expected}",
                missing.join(", "),
                m.name
            ),
        ));
    }
    Ok((names, cols))
}

/// The reader.
fn read_plan<R: Read>(file: &str, reader: R, m: &Machine) -> Result<ProbePlan, CsvError> {
    let cx = Ctx { file };
    let mut lines = Lines::new(reader, &ReadOptions::default());
    let mut head: Option<(Vec<String>, Vec<Col>)> = None;
    let mut rows: Vec<PlannedHit> = Vec::new();
    // Each pose's first line, to name it when a label comes back.
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut pose_line = 0usize;
    let mut last_t: Option<(f64, usize)> = None;
    while let Some((line, text)) = lines.next_line(&cx)? {
        let trimmed = text.trim();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        let Some((names, cols)) = &head else {
            head = Some(header(&cx, line, text, m)?);
            continue;
        };
        if rows.len() >= MAX_HITS {
            return Err(cx.err(
                line,
                None,
                format!("more than {MAX_HITS} hits in a probe plan"),
            ));
        }
        let fields: Vec<&str> = text.split(',').collect();
        if fields.len() != cols.len() {
            return Err(cx.err(
                line,
                None,
                format!(
                    "{} field(s), the header has {} columns",
                    fields.len(),
                    cols.len()
                ),
            ));
        }
        let mut row = PlannedHit {
            pose: String::new(),
            hit: 0,
            axes: vec![0.0; m.axes.len()],
            direction: [0.0; 3],
            t_s: 0.0,
            line: 0,
        };
        let mut hit_at = 0;
        let mut line_at = 0;
        let mut direction_at = 0;
        let mut t_at = 0;
        for (i, (field, col)) in fields.iter().zip(cols).enumerate() {
            let at = Some((i, names[i].as_str()));
            let f = clean_name(field);
            if *col == Col::Own(0) {
                check_label(f).map_err(|why| cx.err(line, at, why))?;
                row.pose = f.to_string();
                continue;
            }
            let unit = match col {
                Col::Axis(a) => {
                    if m.axes[*a].kind == AxisKind::Linear {
                        "mm"
                    } else {
                        "deg"
                    }
                }
                Col::Own(5) => "s",
                _ => "",
            };
            let value = parse_scaled(f, 0)
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    cx.err(
                        line,
                        at,
                        format!(
                            "`{f}` is not a finite decimal number{}",
                            if unit.is_empty() {
                                String::new()
                            } else {
                                format!(" ({unit})")
                            }
                        ),
                    )
                })?;
            let count = |what: &str| {
                if value >= 1.0 && value.fract() == 0.0 && value <= 1e12 {
                    Ok(value as usize)
                } else {
                    Err(cx.err(line, at, format!("`{f}`: {what} is a whole number from 1")))
                }
            };
            match *col {
                Col::Own(1) => {
                    row.hit = count("a hit's number")?;
                    hit_at = i;
                }
                Col::Own(6) => {
                    row.line = count("a program line")?;
                    line_at = i;
                }
                Col::Own(k @ 2..=4) => {
                    row.direction[k - 2] = value;
                    if k == 2 {
                        direction_at = i;
                    }
                }
                Col::Own(_) => {
                    row.t_s = value;
                    t_at = i;
                }
                Col::Axis(a) => row.axes[a] = value,
            }
        }
        let at = |i: usize| Some((i, names[i].as_str()));
        let norm = row.direction.iter().map(|v| v * v).sum::<f64>().sqrt();
        if (norm - 1.0).abs() > UNIT_NORM_TOLERANCE {
            return Err(cx.err(
                line,
                at(direction_at),
                format!("the direction has norm {norm}, not 1 within {UNIT_NORM_TOLERANCE}"),
            ));
        }
        let commands = formats::poses::from_file_units(m, &row.axes);
        m.check_pose(&commands)
            .map_err(|e| cx.err(line, None, format!("the contact is refused: {e}")))?;
        let previous = rows.last();
        let same_pose = previous.is_some_and(|p| p.pose == row.pose);
        if same_pose {
            let p = previous.expect("a previous row");
            if row.hit != p.hit + 1 {
                return Err(cx.err(
                    line,
                    at(hit_at),
                    format!(
                        "hit {} of pose `{}` where hit {} belongs",
                        row.hit,
                        row.pose,
                        p.hit + 1
                    ),
                ));
            }
            for a in m.rotary_axes() {
                if (row.axes[a] - p.axes[a]).abs() > ROTARY_CONSTANT_DEG {
                    return Err(cx.err(
                        line,
                        None,
                        format!(
                            "rotary axis {} moves within pose `{}` ({} deg, {} deg at line {pose_line})",
                            m.axes[a].name, row.pose, row.axes[a], p.axes[a]
                        ),
                    ));
                }
            }
        } else {
            if let Some(first) = seen.get(&row.pose) {
                return Err(cx.err(
                    line,
                    at(0),
                    format!(
                        "pose `{}` comes back (it began at line {first}): the hits of a pose are contiguous rows",
                        row.pose
                    ),
                ));
            }
            if row.hit != 1 {
                return Err(cx.err(
                    line,
                    at(hit_at),
                    format!("pose `{}` begins with hit {}, not 1", row.pose, row.hit),
                ));
            }
            seen.insert(row.pose.clone(), line);
            pose_line = line;
        }
        if let Some((t, l)) = last_t
            && row.t_s < t
        {
            return Err(cx.err(
                line,
                at(t_at),
                format!("time goes backwards: {} s after {t} s at line {l}", row.t_s),
            ));
        }
        if previous.is_some_and(|p| row.line <= p.line) {
            return Err(cx.err(
                line,
                at(line_at),
                format!(
                    "program line {} is not after the previous hit's ({})",
                    row.line,
                    previous.map_or(0, |p| p.line)
                ),
            ));
        }
        last_t = Some((row.t_s, line));
        rows.push(row);
    }
    if rows.is_empty() {
        let what = if head.is_some() {
            "a probe plan with a header and no hit"
        } else {
            "an empty probe plan: no header and no hit"
        };
        return Err(cx.err(lines.number_at_end(), None, what));
    }
    Ok(ProbePlan { rows })
}
