//! A path of commanded poses, corrected: the CSV's axis columns replaced by the corrected
//! commands, every other byte of the file kept as it is.
//!
//! The pose CSV handling is deliberately minimal and lives in [`correct_path_csv`] alone:
//! the header is the first line that is neither blank nor a `#` comment; it must name one
//! column per linear axis of the machine by its letter (`X,Y,Z`, any case, any order, other
//! columns allowed); fields are separated by commas without quoting; every data row has as
//! many fields as the header; the axis fields are decimals in mm. Comments, blank lines, the
//! other columns and the line ends (`\n` or `\r\n`) are copied unchanged. Corrected commands
//! are written as the shortest decimal that reads back to the same value.

use super::VolumetricError;
use super::compensate::{Corrected, correct_within_strokes};
use super::laser::column_axes;
use super::model::VolumetricModel;
use model_spec::Machine;
use model_spec::units::{format_scaled, parse_scaled};
use std::path::Path;

/// The largest path file read, bytes (64 MiB).
pub const MAX_PATH_BYTES: u64 = 64 << 20;

/// Reads the path CSV `path` and corrects it: see [`correct_path_csv`].
///
/// # Errors
/// [`VolumetricError::Text`] when the file cannot be read; see [`correct_path_csv`].
pub fn correct_path_file(
    path: &Path,
    m: &Machine,
    model: &VolumetricModel,
) -> Result<(String, Vec<Corrected>), VolumetricError> {
    let text = model_spec::text::read_text(path, MAX_PATH_BYTES)?;
    correct_path_csv(&path.display().to_string(), &text, m, model)
}

/// The text of the path CSV `text` (called `file` in messages) with each pose's linear axis
/// commands replaced by the corrected commands, and the corrections (one per data row).
///
/// # Errors
/// [`VolumetricError::Format`] naming the line (and column) for: no header, an axis column
/// missing or given twice, a row with the wrong number of fields, a field that is not a finite
/// number, a pose outside the measured ranges, a corrected command outside a stroke, a path
/// without a pose; [`VolumetricError::Computation`] (naming the line) for a correction that
/// fails.
pub fn correct_path_csv(
    file: &str,
    text: &str,
    m: &Machine,
    model: &VolumetricModel,
) -> Result<(String, Vec<Corrected>), VolumetricError> {
    let err =
        |line: usize, column: Option<(usize, String)>, message: String| VolumetricError::Format {
            file: file.to_string(),
            line,
            column,
            message,
        };
    let axes = column_axes(m);
    let letters: Vec<&str> = axes.iter().map(|&a| m.axes[a].name.as_str()).collect();
    let mut out = String::with_capacity(text.len() + text.len() / 4);
    let mut columns: Option<Vec<(usize, usize)>> = None; // (field index, axis)
    let mut width = 0;
    let mut corrected = Vec::new();
    let mut number = 0;
    for piece in text.split_inclusive('\n') {
        number += 1;
        let (body, end) = match piece.strip_suffix("\r\n") {
            Some(b) => (b, "\r\n"),
            None => match piece.strip_suffix('\n') {
                Some(b) => (b, "\n"),
                None => (piece, ""),
            },
        };
        let t = body.trim();
        if t.is_empty() || t.starts_with('#') {
            out += piece;
            continue;
        }
        let fields: Vec<&str> = body.split(',').collect();
        let Some(cols) = &columns else {
            let mut found: Vec<(usize, usize)> = Vec::new();
            for (i, f) in fields.iter().enumerate() {
                let name = f.trim().trim_matches('"').trim();
                if let Some(&a) = axes
                    .iter()
                    .find(|&&a| m.axes[a].name.eq_ignore_ascii_case(name))
                {
                    if found.iter().any(|&(_, b)| b == a) {
                        return Err(err(
                            number,
                            Some((i + 1, name.to_string())),
                            "axis column given twice".into(),
                        ));
                    }
                    found.push((i, a));
                }
            }
            let missing: Vec<&str> = axes
                .iter()
                .filter(|&&a| !found.iter().any(|&(_, b)| b == a))
                .map(|&a| m.axes[a].name.as_str())
                .collect();
            if !missing.is_empty() {
                return Err(err(
                    number,
                    None,
                    format!(
                        "the header misses the column{} {} of the commanded poses (mm); it needs {}",
                        if missing.len() == 1 { "" } else { "s" },
                        missing.join(", "),
                        letters.join(",")
                    ),
                ));
            }
            width = fields.len();
            columns = Some(found);
            out += piece;
            continue;
        };
        if fields.len() != width {
            return Err(err(
                number,
                None,
                format!(
                    "{} fields, but the header has {width} columns",
                    fields.len()
                ),
            ));
        }
        let mut pose = vec![0.0; m.axes.len()];
        for &(i, a) in cols {
            let f = fields[i].trim();
            pose[a] = parse_scaled(f, 0)
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    err(
                        number,
                        Some((i + 1, m.axes[a].name.clone())),
                        format!("`{f}` is not a finite number (mm)"),
                    )
                })?;
        }
        let c = correct_within_strokes(model, m, &pose).map_err(|e| match e {
            VolumetricError::Computation(msg) => {
                VolumetricError::Computation(format!("{file}:{number}: {msg}"))
            }
            other => err(number, None, format!("the pose: {other}")),
        })?;
        let mut new_fields: Vec<String> = fields.iter().map(|f| f.to_string()).collect();
        for &(i, a) in cols {
            new_fields[i] = format_scaled(c.commands[a], 0);
        }
        out += &new_fields.join(",");
        out += end;
        corrected.push(c);
    }
    if columns.is_none() {
        return Err(err(
            number.max(1),
            None,
            format!(
                "no header: a path needs the columns {} (commanded poses, mm)",
                letters.join(",")
            ),
        ));
    }
    if corrected.is_empty() {
        return Err(err(number, None, "the path has no pose".into()));
    }
    Ok((out, corrected))
}
