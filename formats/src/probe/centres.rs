//! The sphere centres CSV (`docs/probe.md`): one row per pose, the centre of the calibration
//! sphere another device (the control's probing cycle, a CMM program) fitted from its hits.
//!
//! Columns, in any order: `pose` (the pose's label, a token, each once), one column per axis of
//! the machine named by its letter (the pose's commands: linear axes in mm, rotary axes in
//! degrees), `cx,cy,cz` (the fitted centre, machine coordinates, mm); optionally
//! `u_cx,u_cy,u_cz` (the standard uncertainties of the centre's coordinates, mm, above 0; all
//! three or none) and `r` (the fitted radius, mm, above 0). At most [`MAX_PROBE_POSES`] rows.

use super::table::{Rows, check_label, off_limits};
use super::{MAX_PROBE_POSES, POSE_COLUMN, axis_header};
use crate::csv::{CsvError, comment_lines};
use model_spec::Machine;
use model_spec::units::format_scaled;
use std::collections::{HashMap, HashSet};
use std::io::Read;
use std::path::Path;

/// The columns of a sphere centres CSV beside `pose` and the axes, in the order they are
/// written: the centre (required), its standard uncertainties and the radius (optional).
pub const CENTRE_COLUMNS: [&str; 7] = ["cx", "cy", "cz", "u_cx", "u_cy", "u_cz", "r"];

const WHAT: &str = "a sphere centres CSV";

/// The centre of the sphere fitted at one pose.
#[derive(Clone, Debug, PartialEq)]
pub struct SphereCentre {
    /// 1-based line of the file that holds the pose (every line counted); 0 for a pose not
    /// read from a file.
    pub line: usize,
    /// The pose's label, as the file writes it.
    pub label: String,
    /// The pose's commands, in the order of [`Machine::axes`]: mm for linear axes, degrees for
    /// rotary axes.
    pub axes: Vec<f64>,
    /// The fitted centre, machine coordinates, mm.
    pub centre: [f64; 3],
    /// The standard uncertainties of the centre's coordinates, mm (each above 0), when the
    /// file gives them.
    pub uncertainty_mm: Option<[f64; 3]>,
    /// The fitted radius, mm (above 0), when the file gives it.
    pub radius_mm: Option<f64>,
}

/// The sphere centres of a probe campaign, one per pose.
#[derive(Clone, Debug, PartialEq)]
pub struct SphereCentres {
    /// The poses, in the order of the file.
    pub poses: Vec<SphereCentre>,
}

/// Reads the sphere centres CSV `text` (named `file` in messages) of machine `m`; see
/// [`read_sphere_centres`].
///
/// # Errors
/// As [`read_sphere_centres`].
pub fn parse_sphere_centres(
    file: &str,
    text: &str,
    m: &Machine,
) -> Result<SphereCentres, CsvError> {
    read_centres(file, text.as_bytes(), m, MAX_PROBE_POSES)
}

/// Reads the sphere centres CSV at `path` of machine `m` through the bounded line reader;
/// messages name it as `path.display()` writes it.
///
/// # Errors
/// [`CsvError::Format`] for the first problem, at its line and column: no header, an unknown,
/// repeated or missing column (`cx,cy,cz` required; `u_cx,u_cy,u_cz` all three or none), a row
/// with another number of fields, a label that is not a token or names a pose already given,
/// a value that is not a finite decimal, an axis value beyond its limits, an uncertainty or a
/// radius not above 0, more than [`MAX_PROBE_POSES`] rows, no row; a line too long or not
/// UTF-8; [`CsvError::Io`] when the file cannot be read.
pub fn read_sphere_centres(path: &Path, m: &Machine) -> Result<SphereCentres, CsvError> {
    let (file, f) = crate::csv::open(path)?;
    read_centres(&file, f, m, MAX_PROBE_POSES)
}

/// [`read_sphere_centres`] of the bytes of `reader` (named `file` in messages).
pub(super) fn read_centres_from(
    file: &str,
    reader: impl Read,
    m: &Machine,
) -> Result<SphereCentres, CsvError> {
    read_centres(file, reader, m, MAX_PROBE_POSES)
}

/// The reader, with at most `max_poses` rows.
fn read_centres<R: Read>(
    file: &str,
    reader: R,
    m: &Machine,
    max_poses: usize,
) -> Result<SphereCentres, CsvError> {
    let mut rows = Rows::new(file, reader, m, &CENTRE_COLUMNS, &["mm"; 7], WHAT)?;
    let present = rows.header.present.clone();
    let missing = |ks: &[usize]| -> Vec<&str> {
        ks.iter()
            .filter(|&&k| !present[k])
            .map(|&k| CENTRE_COLUMNS[k])
            .collect()
    };
    let no_centre = missing(&[0, 1, 2]);
    if !no_centre.is_empty() {
        return Err(rows.err_at(
            rows.header.line,
            None,
            format!(
                "missing column(s) {}: every pose gives its fitted centre cx, cy, cz (mm)",
                no_centre.join(", ")
            ),
        ));
    }
    let no_u = missing(&[3, 4, 5]);
    if !no_u.is_empty() && no_u.len() < 3 {
        return Err(rows.err_at(
            rows.header.line,
            None,
            format!(
                "missing column(s) {}: the uncertainties u_cx, u_cy, u_cz are given all three or none",
                no_u.join(", ")
            ),
        ));
    }
    let mut poses: Vec<SphereCentre> = Vec::new();
    // The line of each pose by its label (a long file is not searched row after row).
    let mut lines: HashMap<String, usize> = HashMap::new();
    while let Some(row) = rows.next_row()? {
        if poses.len() == max_poses {
            return Err(rows.err_at(
                row.line,
                None,
                format!(
                    "more than {max_poses} poses: rtest reads at most {max_poses} poses from one file; split it"
                ),
            ));
        }
        if let Some(&line) = lines.get(&row.pose) {
            return Err(rows.err_at(
                row.line,
                Some(rows.pose_column()),
                format!(
                    "pose `{}` is given twice (also line {}): one row per pose",
                    row.pose, line
                ),
            ));
        }
        for k in 3..7 {
            if let Some(x) = row.own[k]
                && x <= 0.0
            {
                let what = if k == 6 {
                    "the fitted radius"
                } else {
                    "a standard uncertainty"
                };
                return Err(rows.err_at(
                    row.line,
                    rows.own_column(k),
                    format!("{what} must be above 0 mm, not {x}"),
                ));
            }
        }
        let v = |k: usize| row.own[k].unwrap_or(f64::NAN);
        lines.insert(row.pose.clone(), row.line);
        poses.push(SphereCentre {
            line: row.line,
            label: row.pose,
            axes: row.axes,
            centre: [v(0), v(1), v(2)],
            uncertainty_mm: present[3].then(|| [v(3), v(4), v(5)]),
            radius_mm: present[6].then(|| v(6)),
        });
    }
    if poses.is_empty() {
        return Err(rows.header_only());
    }
    Ok(SphereCentres { poses })
}

/// The text of the sphere centres CSV of `centres` of machine `m`: `comments` as `# ` lines,
/// the header (`pose`, the axes as in [`crate::csv::column_order`], `cx,cy,cz`, then
/// `u_cx,u_cy,u_cz` and `r` when the poses give them), one row per pose. Every number is the
/// shortest decimal that reads back to the same bits, so [`parse_sphere_centres`] of the text
/// gives `centres` again (lines aside).
///
/// # Errors
/// [`CsvError::Record`] when the centres are not what the reader would accept: no pose, more
/// than [`MAX_PROBE_POSES`], a label that is not a token or repeated, a pose without one value
/// per axis, a value that is not finite, an axis value beyond its limits, an uncertainty or a
/// radius not above 0, uncertainties or radii given for some poses and not others.
pub fn format_sphere_centres(
    m: &Machine,
    centres: &SphereCentres,
    comments: &[String],
) -> Result<String, CsvError> {
    let bad = |msg: String| CsvError::Record(msg);
    let poses = &centres.poses;
    let Some(first) = poses.first() else {
        return Err(bad(
            "no pose: a sphere centres CSV has at least one row".into()
        ));
    };
    if poses.len() > MAX_PROBE_POSES {
        return Err(bad(format!(
            "{} poses: a file holds at most {MAX_PROBE_POSES}",
            poses.len()
        )));
    }
    let with_u = first.uncertainty_mm.is_some();
    let with_r = first.radius_mm.is_some();
    let (order, mut header) = axis_header(m);
    header.insert(0, POSE_COLUMN.to_string());
    let own = CENTRE_COLUMNS
        .iter()
        .enumerate()
        .filter(|&(k, _)| k < 3 || (k < 6 && with_u) || (k == 6 && with_r))
        .map(|(_, c)| c.to_string());
    header.extend(own);
    let mut out = comment_lines(comments);
    out += &header.join(",");
    out.push('\n');
    let mut seen: HashSet<&str> = HashSet::new();
    for (i, p) in poses.iter().enumerate() {
        check_label(&p.label).map_err(|e| bad(format!("pose {i}: {e}")))?;
        let at = format!("pose `{}`", p.label);
        if !seen.insert(&p.label) {
            return Err(bad(format!("{at} is given twice")));
        }
        if p.axes.len() != m.axes.len() {
            return Err(bad(format!(
                "{at} has {} axis values, machine {} has {} axes",
                p.axes.len(),
                m.name,
                m.axes.len()
            )));
        }
        if p.uncertainty_mm.is_some() != with_u || p.radius_mm.is_some() != with_r {
            return Err(bad(format!(
                "{at}: uncertainties and radii are given for every pose or for none (the file has one set of columns)"
            )));
        }
        let positive: Vec<f64> = p
            .uncertainty_mm
            .iter()
            .flatten()
            .chain(&p.radius_mm)
            .copied()
            .collect();
        let all = p.axes.iter().chain(&p.centre).chain(&positive);
        if all.clone().any(|v| !v.is_finite()) {
            return Err(bad(format!("{at} has a non-finite value")));
        }
        if positive.iter().any(|&v| v <= 0.0) {
            return Err(bad(format!(
                "{at}: an uncertainty or the radius is not above 0 mm"
            )));
        }
        if let Some(a) = off_limits(m, &p.axes) {
            return Err(bad(format!(
                "{at}: axis {} at {} is beyond its limits",
                m.axes[a].name, p.axes[a]
            )));
        }
        let mut fields = vec![p.label.clone()];
        fields.extend(order.iter().map(|&a| format_scaled(p.axes[a], 0)));
        fields.extend(p.centre.iter().map(|&v| format_scaled(v, 0)));
        fields.extend(positive.iter().map(|&v| format_scaled(v, 0)));
        out += &fields.join(",");
        out.push('\n');
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_limit_on_poses_is_refused_at_the_first_row_beyond() {
        let m = model_spec::builtin("seed-ac").unwrap().unwrap();
        let text = "pose,X,Y,Z,A,C,cx,cy,cz\n# two\np1,0,0,0,0,0,1,2,3\np2,0,0,0,0,0,1,2,3\n";
        let read = |p| read_centres("c.csv", text.as_bytes(), &m, p);
        assert_eq!(read(2).unwrap().poses.len(), 2);
        assert_eq!(
            read(1).unwrap_err().to_string(),
            "c.csv:4: more than 1 poses: rtest reads at most 1 poses from one file; split it"
        );
    }
}
