//! The laser measurement of one linear axis: a CSV with the commands of every linear axis
//! (the measured axis moving, the others standing still) and the six component errors the 6D
//! laser interferometer measured at the tool end.
//!
//! ```text
//! # X axis, reflector in the spindle, Y and Z at home
//! X_mm,Y_mm,Z_mm,EXX_um,EYX_um,EZX_um,EAX_urad,EBX_urad,ECX_urad
//! -400,0,0,0,0,0,0,0,0
//! -380,0,0,0.82,-0.11,0.05,1.2,-0.7,0.3
//! ```
//!
//! - one column `<L>_mm` per linear axis `L` of the machine (mm, commands);
//! - `EX<K>_um EY<K>_um EZ<K>_um` (µm) and `EA<K>_urad EB<K>_urad EC<K>_urad` (µrad), `K` the
//!   measured axis: the reflector's translation along, and rotation about, +x, +y, +z;
//! - columns in any order, names matched without regard to case (spaces and double quotes
//!   around a name ignored); `#` lines and blank lines skipped; `\n` or `\r\n` line ends;
//! - the measured axis's positions strictly increasing, at least two; the other axes the same
//!   on every row; every command within its stroke; every value finite, translations within
//!   ±1000 µm and angles within ±10 000 µrad.
//!
//! Every problem is an error naming the file, the line and the column.

use super::{MAX_ANGLE_RAD, MAX_TRANSLATION_MM, VolumetricError};
use model_spec::units::{format_scaled, parse_scaled};
use model_spec::{AxisId, AxisKind, Dir, Machine};
use std::path::Path;

/// The largest laser file read, bytes (16 MiB: some 200 000 rows).
pub const MAX_LASER_BYTES: u64 = 16 << 20;

/// The most rows a laser file may have.
pub const MAX_LASER_ROWS: usize = 100_000;

/// The laser measurement of one linear axis, in the units inside (mm, rad).
#[derive(Clone, Debug, PartialEq)]
pub struct AxisMeasurement {
    /// Where it came from (the file name), for messages.
    pub source: String,
    /// The measured axis, by index into [`Machine::axes`].
    pub axis: AxisId,
    /// The commands of every axis during the measurement ([`Machine::axes`] order, mm): the
    /// other axes where they stood, the measured axis at its first position.
    pub pose: Vec<f64>,
    /// The measured axis's positions, mm, strictly increasing.
    pub positions: Vec<f64>,
    /// The reflector's translation along +x, +y, +z at each position, mm.
    pub translations: Vec<[f64; 3]>,
    /// The reflector's rotation about +x, +y, +z at each position, rad.
    pub rotations: Vec<[f64; 3]>,
}

/// The six column names of the errors of axis `name`, translations then rotations:
/// `EXX_um … ECX_urad`.
pub fn error_columns(name: &str) -> [String; 6] {
    let t = |c: char| format!("E{c}{name}_um");
    let r = |c: char| format!("E{c}{name}_urad");
    [t('X'), t('Y'), t('Z'), r('A'), r('B'), r('C')]
}

/// The linear axes of `m` in the order of the columns people read (X Y Z U V W, then the
/// rest).
pub fn column_axes(m: &Machine) -> Vec<AxisId> {
    formats::csv::column_order(m)
        .into_iter()
        .filter(|&a| m.axes[a].kind == AxisKind::Linear)
        .collect()
}

/// What a column holds.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Col {
    /// The command of an axis, mm.
    Axis(AxisId),
    /// Translation along a direction (µm in the file).
    Translation(Dir),
    /// Rotation about a direction (µrad in the file).
    Rotation(Dir),
}

const DIRS: [Dir; 3] = [Dir::X, Dir::Y, Dir::Z];

/// Reads the laser measurement of axis `axis` of `m` from `path`.
///
/// # Errors
/// [`VolumetricError::Text`] when the file cannot be read, is larger than
/// [`MAX_LASER_BYTES`] or is not UTF-8; see [`parse_laser`].
pub fn read_laser(
    path: &Path,
    m: &Machine,
    axis: AxisId,
) -> Result<AxisMeasurement, VolumetricError> {
    let text = model_spec::text::read_text(path, MAX_LASER_BYTES)?;
    parse_laser(&path.display().to_string(), &text, m, axis)
}

/// Parses the laser measurement of axis `axis` of `m` from `text`; `file` names it in
/// messages.
///
/// # Errors
/// [`VolumetricError::Format`] for the first problem (see the module documentation).
pub fn parse_laser(
    file: &str,
    text: &str,
    m: &Machine,
    axis: AxisId,
) -> Result<AxisMeasurement, VolumetricError> {
    let err =
        |line: usize, column: Option<(usize, String)>, message: String| VolumetricError::Format {
            file: file.to_string(),
            line,
            column,
            message,
        };
    let name = &m.axes[axis].name;
    if m.axes[axis].kind != AxisKind::Linear {
        return Err(VolumetricError::Setup(format!(
            "{file}: axis {name} is not a linear axis: the laser measures linear axes"
        )));
    }
    let axes = column_axes(m);
    let mut expected: Vec<(String, Col)> = axes
        .iter()
        .map(|&a| (format!("{}_mm", m.axes[a].name), Col::Axis(a)))
        .collect();
    let errs = error_columns(name);
    for (i, d) in DIRS.iter().enumerate() {
        expected.push((errs[i].clone(), Col::Translation(*d)));
    }
    for (i, d) in DIRS.iter().enumerate() {
        expected.push((errs[3 + i].clone(), Col::Rotation(*d)));
    }
    let all_names = || {
        expected
            .iter()
            .map(|(n, _)| n.as_str())
            .collect::<Vec<_>>()
            .join(",")
    };

    let mut lines = text
        .split('\n')
        .enumerate()
        .map(|(i, l)| (i + 1, l.strip_suffix('\r').unwrap_or(l)));
    let is_data = |l: &str| {
        let t = l.trim();
        !t.is_empty() && !t.starts_with('#')
    };
    let Some((header_line, header)) = lines.by_ref().find(|(_, l)| is_data(l)) else {
        return Err(err(
            1,
            None,
            format!(
                "no header: the laser file of axis {name} needs the columns {}",
                all_names()
            ),
        ));
    };
    let mut cols: Vec<(Col, String)> = Vec::new();
    for (i, raw) in header.split(',').enumerate() {
        let clean = raw.trim().trim_matches('"').trim();
        let found = expected.iter().find(|(n, _)| n.eq_ignore_ascii_case(clean));
        let Some((canonical, col)) = found else {
            return Err(err(
                header_line,
                Some((i + 1, clean.to_string())),
                format!(
                    "unknown column for the laser measurement of axis {name} (expected {})",
                    all_names()
                ),
            ));
        };
        if cols.iter().any(|(c, _)| c == col) {
            return Err(err(
                header_line,
                Some((i + 1, clean.to_string())),
                "column given twice".into(),
            ));
        }
        cols.push((*col, canonical.clone()));
    }
    let missing: Vec<&str> = expected
        .iter()
        .filter(|(_, c)| !cols.iter().any(|(k, _)| k == c))
        .map(|(n, _)| n.as_str())
        .collect();
    if !missing.is_empty() {
        return Err(err(
            header_line,
            None,
            format!(
                "the laser measurement of axis {name} misses the column{} {}",
                if missing.len() == 1 { "" } else { "s" },
                missing.join(", ")
            ),
        ));
    }

    let mut meas = AxisMeasurement {
        source: file.to_string(),
        axis,
        pose: vec![f64::NAN; m.axes.len()],
        positions: Vec::new(),
        translations: Vec::new(),
        rotations: Vec::new(),
    };
    // The line and text of the first row's value of every standing axis.
    let mut standing: Vec<Option<(usize, f64)>> = vec![None; m.axes.len()];
    let mut last: Option<(usize, f64)> = None;
    for (line, text_line) in lines {
        if !is_data(text_line) {
            continue;
        }
        if meas.positions.len() == MAX_LASER_ROWS {
            return Err(err(
                line,
                None,
                format!("more than {MAX_LASER_ROWS} rows, the most a laser file may have"),
            ));
        }
        let fields: Vec<&str> = text_line.split(',').collect();
        if fields.len() != cols.len() {
            return Err(err(
                line,
                None,
                format!(
                    "{} fields, but the header has {} columns",
                    fields.len(),
                    cols.len()
                ),
            ));
        }
        let (mut t, mut r) = ([0.0; 3], [0.0; 3]);
        let mut position = f64::NAN;
        for (i, ((col, cname), field)) in cols.iter().zip(&fields).enumerate() {
            let at = Some((i + 1, cname.clone()));
            let (shift, unit) = match col {
                Col::Axis(_) => (0, "mm"),
                Col::Translation(_) => (-3, "µm"),
                Col::Rotation(_) => (-6, "µrad"),
            };
            let f = field.trim();
            let v = parse_scaled(f, shift)
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    err(
                        line,
                        at.clone(),
                        if f.is_empty() {
                            format!("empty field: a number ({unit}) is needed")
                        } else {
                            format!("`{f}` is not a finite number ({unit})")
                        },
                    )
                })?;
            match *col {
                Col::Axis(a) => {
                    let [lo, hi] = m.axes[a].limits;
                    let tol = model_spec::pose::LIMIT_TOLERANCE;
                    if v < lo - tol || v > hi + tol {
                        return Err(err(
                            line,
                            at,
                            format!(
                                "{} = {f} mm is outside its stroke {} .. {} mm",
                                m.axes[a].name,
                                model_spec::units::short(lo),
                                model_spec::units::short(hi)
                            ),
                        ));
                    }
                    if a == axis {
                        if let Some((pl, pv)) = last
                            && v <= pv
                        {
                            return Err(err(
                                line,
                                at,
                                format!(
                                    "{name} = {f} mm is not above the position of line {pl} ({} mm): the positions of the measured axis must increase strictly",
                                    model_spec::units::compact(pv)
                                ),
                            ));
                        }
                        last = Some((line, v));
                        position = v;
                    } else {
                        match standing[a] {
                            None => standing[a] = Some((line, v)),
                            Some((fl, fv)) if fv != v => {
                                return Err(err(
                                    line,
                                    at,
                                    format!(
                                        "{} = {f} mm, but {} mm on line {fl}: axis {} must stand still while axis {name} is measured",
                                        m.axes[a].name,
                                        model_spec::units::compact(fv),
                                        m.axes[a].name
                                    ),
                                ));
                            }
                            Some(_) => {}
                        }
                    }
                }
                Col::Translation(d) => {
                    if v.abs() > MAX_TRANSLATION_MM {
                        return Err(err(
                            line,
                            at,
                            format!(
                                "{f} µm is beyond ±1000 µm: not a component error of a machine tool"
                            ),
                        ));
                    }
                    t[d.index()] = v;
                }
                Col::Rotation(d) => {
                    if v.abs() > MAX_ANGLE_RAD {
                        return Err(err(
                            line,
                            at,
                            format!(
                                "{f} µrad is beyond ±10000 µrad: not a component error of a machine tool"
                            ),
                        ));
                    }
                    r[d.index()] = v;
                }
            }
        }
        meas.positions.push(position);
        meas.translations.push(t);
        meas.rotations.push(r);
    }
    if meas.positions.len() < 2 {
        let end = text.split('\n').count();
        return Err(err(
            end,
            None,
            format!(
                "{} row{}: the laser measurement of axis {name} needs at least two positions",
                meas.positions.len(),
                if meas.positions.len() == 1 { "" } else { "s" }
            ),
        ));
    }
    for &a in &axes {
        meas.pose[a] = if a == axis {
            meas.positions[0]
        } else {
            standing[a].map_or(f64::NAN, |(_, v)| v)
        };
    }
    Ok(meas)
}

/// The CSV text of `meas` (axis of `m`): `comments` as `# ` lines, the header (linear axes as
/// in [`column_axes`], then the six errors), one row per position; every number the shortest
/// decimal that reads back to the same value.
pub fn format_laser(m: &Machine, meas: &AxisMeasurement, comments: &[String]) -> String {
    let axes = column_axes(m);
    let mut out = formats::csv::comment_lines(comments);
    let mut header: Vec<String> = axes
        .iter()
        .map(|&a| format!("{}_mm", m.axes[a].name))
        .collect();
    header.extend(error_columns(&m.axes[meas.axis].name));
    out += &header.join(",");
    out.push('\n');
    for (i, &q) in meas.positions.iter().enumerate() {
        let mut fields: Vec<String> = axes
            .iter()
            .map(|&a| format_scaled(if a == meas.axis { q } else { meas.pose[a] }, 0))
            .collect();
        fields.extend(meas.translations[i].iter().map(|&v| format_scaled(v, 3)));
        fields.extend(meas.rotations[i].iter().map(|&v| format_scaled(v, 6)));
        out += &fields.join(",");
        out.push('\n');
    }
    out
}
