//! The probe hits CSV (`docs/probe.md`): one row per hit of the probe on the sphere.
//!
//! Columns, in any order: `pose` (the pose's label, a token), one column per axis of the
//! machine named by its letter (the position latched at the trigger, machine coordinates:
//! linear axes in mm, rotary axes in degrees), `nx,ny,nz` (the approach direction, machine
//! frame, a unit vector to within [`UNIT_NORM_TOLERANCE`]) and `t_s` (the time of the hit, s,
//! non-decreasing). All are required.
//!
//! The hits are grouped by pose, the poses in the order of their first hit. The hits of a pose
//! are contiguous rows, and the rotary axes keep one value within a pose (to within
//! [`ROTARY_CONSTANT_DEG`]). At most [`MAX_HITS`] rows and [`MAX_PROBE_POSES`] poses.

use super::table::{Row, Rows};
use super::{
    MAX_HITS, MAX_PROBE_POSES, ROTARY_CONSTANT_DEG, UNIT_NORM_TOLERANCE, axis_header,
    table::check_label,
};
use crate::csv::{CsvError, comment_lines};
use model_spec::units::format_scaled;
use model_spec::{AxisKind, Machine};
use std::collections::{HashMap, HashSet};
use std::io::Read;
use std::path::Path;

/// The columns of a hits CSV beside `pose` and the axes, in the order they are written.
pub const HIT_COLUMNS: [&str; 4] = ["nx", "ny", "nz", "t_s"];

/// The units of [`HIT_COLUMNS`], for messages.
const HIT_UNITS: [&str; 4] = ["unit vector", "unit vector", "unit vector", "s"];

const WHAT: &str = "a probe hits CSV";

/// One hit of the probe on the sphere.
#[derive(Clone, Debug, PartialEq)]
pub struct ProbeHit {
    /// 1-based line of the file that holds the hit (every line counted); 0 for a hit not read
    /// from a file.
    pub line: usize,
    /// The axis positions latched at the trigger, in the order of [`Machine::axes`]: mm for
    /// linear axes, degrees for rotary axes (machine coordinates).
    pub axes: Vec<f64>,
    /// The approach direction: the direction the probe moved in when it touched, machine
    /// frame, a unit vector.
    pub direction: [f64; 3],
    /// The time of the hit, s.
    pub t_s: f64,
}

/// The hits of one pose: the rotary axes stand still while the probe touches the sphere.
#[derive(Clone, Debug, PartialEq)]
pub struct ProbePose {
    /// The pose's label, as the file writes it.
    pub label: String,
    /// The pose's hits, in the order of the file (at least one).
    pub hits: Vec<ProbeHit>,
}

/// The hits of a probe campaign, grouped by pose.
#[derive(Clone, Debug, PartialEq)]
pub struct ProbeHits {
    /// The poses, in the order of their first hit.
    pub poses: Vec<ProbePose>,
}

impl ProbeHits {
    /// The number of hits, all poses together.
    pub fn hit_count(&self) -> usize {
        self.poses.iter().map(|p| p.hits.len()).sum()
    }
}

/// Reads the probe hits CSV `text` (named `file` in messages) of machine `m`; see
/// [`read_probe_hits`].
///
/// # Errors
/// As [`read_probe_hits`].
pub fn parse_probe_hits(file: &str, text: &str, m: &Machine) -> Result<ProbeHits, CsvError> {
    read_hits(file, text.as_bytes(), m, MAX_HITS, MAX_PROBE_POSES)
}

/// Reads the probe hits CSV at `path` of machine `m` through the bounded line reader (the
/// file is never held whole as text); messages name it as `path.display()` writes it.
///
/// # Errors
/// [`CsvError::Format`] for the first problem, at its line and column: no header, an unknown,
/// repeated or missing column, a row with another number of fields, a label that is not a
/// token, a value that is not a finite decimal, an axis value beyond its limits, a direction
/// that is not a unit vector, a time going backwards, a pose whose hits are not contiguous, a
/// rotary axis that moves within a pose, more than [`MAX_HITS`] rows or [`MAX_PROBE_POSES`]
/// poses, no row; a line too long or not UTF-8; [`CsvError::Io`] when the file cannot be
/// read.
pub fn read_probe_hits(path: &Path, m: &Machine) -> Result<ProbeHits, CsvError> {
    let (file, f) = crate::csv::open(path)?;
    read_hits(&file, f, m, MAX_HITS, MAX_PROBE_POSES)
}

/// [`read_probe_hits`] of the bytes of `reader` (named `file` in messages).
pub(super) fn read_hits_from(
    file: &str,
    reader: impl Read,
    m: &Machine,
) -> Result<ProbeHits, CsvError> {
    read_hits(file, reader, m, MAX_HITS, MAX_PROBE_POSES)
}

/// The reader, with at most `max_hits` rows and `max_poses` poses.
fn read_hits<R: Read>(
    file: &str,
    reader: R,
    m: &Machine,
    max_hits: usize,
    max_poses: usize,
) -> Result<ProbeHits, CsvError> {
    let mut rows = Rows::new(file, reader, m, &HIT_COLUMNS, &HIT_UNITS, WHAT)?;
    if let Some(k) = rows.header.present.iter().position(|p| !p) {
        return Err(rows.err_at(
            rows.header.line,
            None,
            format!(
                "missing column {}: every hit gives its approach direction nx, ny, nz and its time t_s",
                HIT_COLUMNS[k]
            ),
        ));
    }
    let mut poses: Vec<ProbePose> = Vec::new();
    // The first and last line of each pose, to name them when a label comes back.
    let mut spans: Vec<(usize, usize)> = Vec::new();
    // The index of each pose by its label (a long file is not searched row after row).
    let mut index: HashMap<String, usize> = HashMap::new();
    let mut rows_read = 0usize;
    let mut last_t: Option<(f64, usize)> = None;
    while let Some(row) = rows.next_row()? {
        rows_read += 1;
        if rows_read > max_hits {
            return Err(rows.err_at(
                row.line,
                None,
                format!(
                    "more than {max_hits} hits: rtest reads at most {max_hits} hits from one file; split it"
                ),
            ));
        }
        let hit = check_hit(&rows, &row, &mut last_t)?;
        let same = poses.last().is_some_and(|p| p.label == row.pose);
        if same {
            let pose = poses.last_mut().expect("checked above");
            check_rotary(&rows, m, &pose.hits[0], &hit)?;
            pose.hits.push(hit);
            spans.last_mut().expect("one per pose").1 = row.line;
            continue;
        }
        if let Some(&i) = index.get(&row.pose) {
            let (first, last) = spans[i];
            let other = &poses[i + 1].label;
            let (other_line, _) = spans[i + 1];
            return Err(rows.err_at(
                row.line,
                Some(rows.pose_column()),
                format!(
                    "pose `{}` comes back: its hits are on lines {first} to {last}, then pose `{other}` begins at line {other_line}; the hits of a pose must be contiguous rows",
                    row.pose
                ),
            ));
        }
        if poses.len() == max_poses {
            return Err(rows.err_at(
                row.line,
                Some(rows.pose_column()),
                format!(
                    "more than {max_poses} poses: rtest reads at most {max_poses} poses from one file; split it"
                ),
            ));
        }
        spans.push((row.line, row.line));
        index.insert(row.pose.clone(), poses.len());
        poses.push(ProbePose {
            label: row.pose,
            hits: vec![hit],
        });
    }
    if poses.is_empty() {
        return Err(rows.header_only());
    }
    Ok(ProbeHits { poses })
}

/// The hit of `row`: its direction a unit vector, its time finite and not before the last.
fn check_hit<R: Read>(
    rows: &Rows<'_, R>,
    row: &Row,
    last_t: &mut Option<(f64, usize)>,
) -> Result<ProbeHit, CsvError> {
    let value = |k: usize| row.own[k].unwrap_or(f64::NAN);
    let n = [value(0), value(1), value(2)];
    let norm = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if (norm - 1.0).abs() > UNIT_NORM_TOLERANCE {
        return Err(rows.err_at(
            row.line,
            rows.own_column(0),
            format!(
                "the approach direction ({}, {}, {}) has norm {norm}, not 1 within {UNIT_NORM_TOLERANCE}: give a unit vector (rtest normalises nothing)",
                n[0], n[1], n[2]
            ),
        ));
    }
    let t = value(3);
    if let Some((before, line)) = *last_t
        && t < before
    {
        return Err(rows.err_at(
            row.line,
            rows.own_column(3),
            format!("time goes backwards: {t} s after {before} s at line {line}"),
        ));
    }
    *last_t = Some((t, row.line));
    Ok(ProbeHit {
        line: row.line,
        axes: row.axes.clone(),
        direction: n,
        t_s: t,
    })
}

/// Refuses `hit` when one of its rotary axes differs from the pose's first hit `first` by
/// more than [`ROTARY_CONSTANT_DEG`].
fn check_rotary<R: Read>(
    rows: &Rows<'_, R>,
    m: &Machine,
    first: &ProbeHit,
    hit: &ProbeHit,
) -> Result<(), CsvError> {
    for (a, axis) in m.axes.iter().enumerate() {
        if axis.kind != AxisKind::Rotary {
            continue;
        }
        let (x, x0) = (hit.axes[a], first.axes[a]);
        if (x - x0).abs() > ROTARY_CONSTANT_DEG {
            return Err(rows.err_at(
                hit.line,
                Some(rows.axis_column(a)),
                format!(
                    "rotary axis {} is at {x} deg, but at {x0} deg at line {}, the pose's first hit: a probe cycle does not turn the rotary axes during a pose (tolerance {ROTARY_CONSTANT_DEG} deg)",
                    axis.name, first.line
                ),
            ));
        }
    }
    Ok(())
}

/// The text of the probe hits CSV of `hits` of machine `m`: `comments` as `# ` lines, the
/// header (`pose`, the axes as in [`crate::csv::column_order`], `nx,ny,nz,t_s`), one row per
/// hit, poses in order. Every number is the shortest decimal that reads back to the same
/// bits, so [`parse_probe_hits`] of the text gives `hits` again (lines aside).
///
/// # Errors
/// [`CsvError::Record`] when the hits are not what the reader would accept: no pose, a pose
/// without hits or with a label that is not a token or repeated, a hit without one value per
/// axis, a value that is not finite, an axis value beyond its limits, a direction that is not a unit vector, a time going
/// backwards, a rotary axis moving within a pose, more than [`MAX_HITS`] hits or
/// [`MAX_PROBE_POSES`] poses.
pub fn format_probe_hits(
    m: &Machine,
    hits: &ProbeHits,
    comments: &[String],
) -> Result<String, CsvError> {
    let bad = |msg: String| CsvError::Record(msg);
    if hits.poses.is_empty() {
        return Err(bad("no pose: a probe hits CSV has at least one hit".into()));
    }
    if hits.poses.len() > MAX_PROBE_POSES || hits.hit_count() > MAX_HITS {
        return Err(bad(format!(
            "{} poses and {} hits: a file holds at most {MAX_PROBE_POSES} poses and {MAX_HITS} hits",
            hits.poses.len(),
            hits.hit_count()
        )));
    }
    let (order, mut header) = axis_header(m);
    header.insert(0, super::POSE_COLUMN.to_string());
    header.extend(HIT_COLUMNS.iter().map(|s| s.to_string()));
    let mut out = comment_lines(comments);
    out += &header.join(",");
    out.push('\n');
    let mut last_t = f64::NEG_INFINITY;
    let mut seen: HashSet<&str> = HashSet::new();
    for (i, pose) in hits.poses.iter().enumerate() {
        check_label(&pose.label).map_err(|e| bad(format!("pose {i}: {e}")))?;
        if !seen.insert(&pose.label) {
            return Err(bad(format!("pose `{}` is given twice", pose.label)));
        }
        let Some(first) = pose.hits.first() else {
            return Err(bad(format!("pose `{}` has no hit", pose.label)));
        };
        for (j, h) in pose.hits.iter().enumerate() {
            let at = format!("pose `{}`, hit {j}", pose.label);
            if h.axes.len() != m.axes.len() {
                return Err(bad(format!(
                    "{at} has {} axis values, machine {} has {} axes",
                    h.axes.len(),
                    m.name,
                    m.axes.len()
                )));
            }
            let values = h.axes.iter().chain(&h.direction).chain([&h.t_s]);
            if values.clone().any(|v| !v.is_finite()) {
                return Err(bad(format!("{at} has a non-finite value")));
            }
            if let Some(a) = super::table::off_limits(m, &h.axes) {
                return Err(bad(format!(
                    "{at}: axis {} at {} is beyond its limits",
                    m.axes[a].name, h.axes[a]
                )));
            }
            let n = h.direction;
            let norm = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if (norm - 1.0).abs() > UNIT_NORM_TOLERANCE {
                return Err(bad(format!(
                    "{at}: the approach direction has norm {norm}, not 1"
                )));
            }
            if h.t_s < last_t {
                return Err(bad(format!("{at}: time goes backwards")));
            }
            last_t = h.t_s;
            let moved = m.axes.iter().enumerate().any(|(a, axis)| {
                axis.kind == AxisKind::Rotary
                    && (h.axes[a] - first.axes[a]).abs() > ROTARY_CONSTANT_DEG
            });
            if moved {
                return Err(bad(format!("{at}: a rotary axis moves within the pose")));
            }
            let mut fields = vec![pose.label.clone()];
            fields.extend(order.iter().map(|&a| format_scaled(h.axes[a], 0)));
            fields.extend(n.iter().map(|&v| format_scaled(v, 0)));
            fields.push(format_scaled(h.t_s, 0));
            out += &fields.join(",");
            out.push('\n');
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_limits_on_rows_and_poses_are_refused_at_the_first_row_beyond() {
        let m = model_spec::builtin("seed-ac").unwrap().unwrap();
        let text = "pose,X,Y,Z,A,C,nx,ny,nz,t_s\n\
                    p1,0,0,0,0,0,1,0,0,0\n\
                    p1,0,0,0,0,0,0,1,0,1\n\
                    p2,0,0,0,0,0,0,0,1,2\n";
        let read = |h, p| read_hits("h.csv", text.as_bytes(), &m, h, p);
        assert_eq!(read(3, 2).unwrap().hit_count(), 3);
        assert_eq!(
            read(2, 2).unwrap_err().to_string(),
            "h.csv:4: more than 2 hits: rtest reads at most 2 hits from one file; split it"
        );
        assert_eq!(
            read(3, 1).unwrap_err().to_string(),
            "h.csv:4: column 1 `pose`: more than 1 poses: rtest reads at most 1 poses from one file; split it"
        );
    }
}
