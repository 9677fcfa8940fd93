//! Axis compensation tables: per axis with component errors, the identified component errors
//! over its stroke at a chosen pitch, and its positioning correction in the axis's own sense,
//! as a controller's pitch-error (lead-screw, measuring-system) compensation table takes it.
//!
//! Rows: from the start of the stroke in steps of the pitch, the last row at the end of the
//! stroke (a shorter last step when the pitch does not divide the stroke); a rotary axis without
//! a `range` goes over 0–360°. Values are absolute at each position (not increments between
//! rows), not shifted to zero at any reference point.
//!
//! Columns (`docs/compensation-tables.md`):
//! - the position: `X_mm` (linear, mm) or `C_deg` (rotary, degrees);
//! - each component error of the axis that has a compensated term, in rtest's convention
//!   (along or about the positive coordinate direction, docs/conventions.md §2): `EXX_um`,
//!   `EAX_urad`, …;
//! - when the axis's positioning error is among them: `deviation_um` (`deviation_urad`), the
//!   positioning deviation in the axis's own sense, actual minus commanded position along (or
//!   about) the axis's signed direction (ISO 230-2's sign): `+EXX` on a `+x` axis, `−EXX` on a
//!   `-x` axis; and `correction_um` (`correction_urad`), what to add to the command to cancel
//!   it: `−deviation`. A controller that takes the error (a positive value makes the axis move
//!   back) takes the deviation; one that adds the value to the set-point takes the correction.
//!
//! Every number is the shortest decimal that reads back to the same `f64` (µm, µrad moved from
//! mm, rad in the text); positions are rounded to 1e-9 mm or degree first, so that `0.3` is
//! written as `0.3`.

use super::values::{CompensationError, MachineErrors};
use model_spec::catalogue::Motion;
use model_spec::units::format_scaled;
use model_spec::{AxisId, AxisKind, Direction, ErrorId, ErrorKind, Machine};

/// The most rows a table may have.
pub const MAX_TABLE_POINTS: usize = 100_000;

/// The pitch of the tables: the step between rows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pitch {
    /// For linear axes, mm.
    pub linear_mm: f64,
    /// For rotary axes, degrees.
    pub rotary_deg: f64,
}

/// One row of a table.
#[derive(Clone, Debug, PartialEq)]
pub struct TableRow {
    /// The position: mm (linear axis) or degrees (rotary axis).
    pub position: f64,
    /// The value of each of [`AxisTable::errors`] at this position: mm or rad.
    pub errors: Vec<f64>,
    /// The positioning deviation in the axis's own sense (actual minus commanded), mm or rad;
    /// `None` when the axis's positioning error is not compensated.
    pub deviation: Option<f64>,
}

impl TableRow {
    /// What to add to the command to cancel the positioning deviation (its negative), mm or
    /// rad; `None` when the axis's positioning error is not compensated.
    pub fn correction(&self) -> Option<f64> {
        self.deviation.map(|d| -d)
    }
}

/// The compensation table of one axis.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisTable {
    /// The machine's name.
    pub machine: String,
    /// The fingerprint of its description.
    pub fingerprint: String,
    /// The file of the identified values.
    pub source: String,
    /// The axis letter.
    pub axis: String,
    /// Linear or rotary.
    pub kind: AxisKind,
    /// Its signed direction.
    pub direction: Direction,
    /// The pitch, mm or degrees.
    pub pitch: f64,
    /// The axis's compensated component errors, in catalogue order.
    pub errors: Vec<ErrorId>,
    /// Their names (`EXX`).
    pub error_names: Vec<String>,
    /// Per error: angular (rad, µrad in the CSV) or translational (mm, µm).
    pub angular: Vec<bool>,
    /// The index in `errors` of the axis's positioning error (`EXX`, `ECC`), when it is
    /// compensated: then every row has a deviation.
    pub positioning: Option<usize>,
    /// The rows, ascending in position.
    pub rows: Vec<TableRow>,
}

/// The positions of a table over `[lo, hi]` at `pitch` (the same unit), or why not.
fn positions(lo: f64, hi: f64, pitch: f64, unit: &str) -> Result<Vec<f64>, String> {
    if !(pitch.is_finite() && pitch > 0.0) {
        return Err(format!("the pitch {pitch} {unit} is not a positive number"));
    }
    let span = hi - lo;
    // Whole pitches within the stroke (a quotient a rounding short of a whole number counts as
    // that number), and whether the end of the stroke needs a row of its own.
    let steps = (span / pitch * (1.0 + 1e-12)).floor();
    let end_row = steps.is_finite() && (hi - (lo + steps * pitch)).abs() > 1e-9 * span.max(1.0);
    let count = steps + 1.0 + if end_row { 1.0 } else { 0.0 };
    if !count.is_finite() || count > MAX_TABLE_POINTS as f64 {
        return Err(format!(
            "the pitch {} {unit} over {} .. {} {unit} gives {} points, more than {MAX_TABLE_POINTS}: choose a larger pitch",
            format_scaled(pitch, 0),
            format_scaled(lo, 0),
            format_scaled(hi, 0),
            if count.is_finite() {
                format!("{count:.0}")
            } else {
                "too many".into()
            }
        ));
    }
    let round = |x: f64| (x * 1e9).round() / 1e9 + 0.0;
    let mut out: Vec<f64> = (0..=steps as usize)
        .map(|k| round(lo + k as f64 * pitch))
        .collect();
    match out.last_mut() {
        Some(last) if !end_row => *last = hi,
        _ => out.push(hi),
    }
    Ok(out)
}

/// The axis's component errors among `errors`, in catalogue order, and which of them is its
/// positioning error.
fn axis_errors(m: &Machine, axis: AxisId, errors: &[ErrorId]) -> (Vec<usize>, Option<usize>) {
    let a = &m.axes[axis];
    let mut slots = Vec::new();
    let mut positioning = None;
    for (slot, &e) in errors.iter().enumerate() {
        if let ErrorKind::Component { axis: ax, motion } = m.catalogue[e].kind
            && ax == axis
        {
            let own = match (a.kind, motion) {
                (AxisKind::Linear, Motion::Translation(d))
                | (AxisKind::Rotary, Motion::Rotation(d)) => d == a.direction.own.dir,
                _ => false,
            };
            if own {
                positioning = Some(slots.len());
            }
            slots.push(slot);
        }
    }
    (slots, positioning)
}

/// One table per axis of `m` that has compensated component errors, in axis order, over its
/// stroke (a rotary axis without a range: 0–360°) at `pitch` (mm for linear axes, degrees for
/// rotary ones); see the module documentation.
///
/// # Errors
/// [`CompensationError::OtherMachine`] when `errors` were identified on another description;
/// [`CompensationError::Pitch`] for a pitch that is not positive or gives more than
/// [`MAX_TABLE_POINTS`] rows on an axis; [`CompensationError::NonFinite`] for a value that is
/// not finite.
pub fn axis_tables(
    m: &Machine,
    errors: &MachineErrors,
    pitch: Pitch,
) -> Result<Vec<AxisTable>, CompensationError> {
    errors.check_machine(m)?;
    let mut tables = Vec::new();
    let mut values = vec![0.0; errors.errors().len()];
    for (axis, a) in m.axes.iter().enumerate() {
        let (slots, positioning) = axis_errors(m, axis, errors.errors());
        if slots.is_empty() {
            continue;
        }
        let (lo, hi, step, unit) = match a.kind {
            AxisKind::Linear => (a.limits[0], a.limits[1], pitch.linear_mm, "mm"),
            AxisKind::Rotary if a.limits[0].is_finite() => {
                (a.limits[0], a.limits[1], pitch.rotary_deg, "degrees")
            }
            AxisKind::Rotary => (0.0, 360.0, pitch.rotary_deg, "degrees"),
        };
        let at = positions(lo, hi, step, unit).map_err(|why| CompensationError::Pitch {
            axis: a.name.clone(),
            why,
        })?;
        let mut commands = vec![0.0; m.axes.len()];
        let mut rows = Vec::with_capacity(at.len());
        for p in at {
            commands[axis] = match a.kind {
                AxisKind::Linear => p,
                AxisKind::Rotary => p.to_radians(),
            };
            errors.values_at(m, &commands, &mut values);
            let row: Vec<f64> = slots.iter().map(|&s| values[s]).collect();
            if let Some(v) = row.iter().find(|v| !v.is_finite()) {
                return Err(CompensationError::NonFinite {
                    file: errors.file().to_string(),
                    what: format!("the table of axis {} at {p} {unit}", a.name),
                    value: *v,
                });
            }
            rows.push(TableRow {
                position: p,
                deviation: positioning.map(|k| a.direction.own.sign() * row[k] + 0.0),
                errors: row,
            });
        }
        let ids: Vec<ErrorId> = slots.iter().map(|&s| errors.errors()[s]).collect();
        tables.push(AxisTable {
            machine: m.name.clone(),
            fingerprint: m.fingerprint(),
            source: errors.file().to_string(),
            axis: a.name.clone(),
            kind: a.kind,
            direction: a.direction.own,
            pitch: step,
            error_names: ids.iter().map(|&e| m.catalogue[e].name.clone()).collect(),
            angular: ids.iter().map(|&e| m.catalogue[e].is_angular()).collect(),
            positioning,
            errors: ids,
            rows,
        });
    }
    Ok(tables)
}

impl AxisTable {
    /// The file name of the table: `axis_X.csv`.
    pub fn file_name(&self) -> String {
        format!("axis_{}.csv", self.axis)
    }

    /// The unit people read for a value: `um` or `urad` (a positioning value of a rotary axis
    /// is angular).
    fn unit(&self, angular: bool) -> (&'static str, i32) {
        if angular { ("urad", 6) } else { ("um", 3) }
    }

    /// The CSV text of the table: `# ` comment lines (machine, axis, units, signs), the header,
    /// one row per position. See the module documentation for the columns.
    pub fn to_csv(&self) -> String {
        let rotary = self.kind == AxisKind::Rotary;
        let (pos_unit, scale) = if rotary { ("deg", 0) } else { ("mm", 0) };
        let (own_unit, own_shift) = self.unit(rotary);
        let positioning = self.positioning.map(|k| self.error_names[k].as_str());
        let mut out = String::new();
        out += &format!(
            "# Compensation table of axis {} ({} {}) of machine {} (fingerprint {}), from {}.\n",
            self.axis,
            if rotary {
                "rotary, about"
            } else {
                "linear, along"
            },
            self.direction,
            self.machine,
            self.fingerprint,
            self.source.replace(['\n', '\r'], " ")
        );
        out += &format!(
            "# Position in {}; component errors in rtest's convention (along or about the positive coordinate directions; an inclined axis's in its own frame x' y' z'), µm and µrad; absolute values at each position.\n",
            if rotary { "degrees" } else { "mm" }
        );
        if let Some(name) = positioning {
            out += &format!(
                "# deviation_{own_unit}: actual minus commanded position in the axis's own sense ({}{name}); correction_{own_unit}: add it to the command to cancel the deviation (= -deviation).\n",
                if self.direction.negative { "-" } else { "+" },
            );
        }
        let mut header = vec![format!("{}_{pos_unit}", self.axis)];
        for (n, &a) in self.error_names.iter().zip(&self.angular) {
            header.push(format!("{n}_{}", self.unit(a).0));
        }
        if positioning.is_some() {
            header.push(format!("deviation_{own_unit}"));
            header.push(format!("correction_{own_unit}"));
        }
        out += &header.join(",");
        out.push('\n');
        for r in &self.rows {
            let mut fields = vec![format_scaled(r.position + 0.0, scale)];
            for (v, &a) in r.errors.iter().zip(&self.angular) {
                fields.push(format_scaled(v + 0.0, self.unit(a).1));
            }
            if let (Some(d), Some(c)) = (r.deviation, r.correction()) {
                fields.push(format_scaled(d + 0.0, own_shift));
                fields.push(format_scaled(c + 0.0, own_shift));
            }
            out += &fields.join(",");
            out.push('\n');
        }
        out
    }
}
