//! SINUMERIK's interpolatory compensation tables (function manual K3, "Interpolatory
//! compensation"): what of the identified errors they hold, as tables over the machine axes of
//! a [`SwivelKinematics`].
//!
//! - **Measuring-system error compensation** (`$AA_ENC_COMP`, one table per axis): the
//!   positioning error of a linear or rotary axis. K3: the value modifies the axis's actual
//!   value, and "a positive compensation value causes the corresponding machine axis to move in
//!   the negative direction": the value is the deviation, actual minus commanded position, in
//!   the machine axis's own sense and unit (mm, degrees).
//! - **Sag / angularity compensation** (`$AN_CEC`, input axis → output axis): a straightness
//!   error of a linear axis (`EYX`: the deviation along y while X moves), input the moving
//!   axis, output the machine axis of the deviation's coordinate. K3 does not say whether the
//!   value acts on the output axis's actual value or its set-point; the value written is, as
//!   for `$AA_ENC_COMP`, the deviation of the tool relative to the table along the output
//!   machine axis (a value that acts like `$AA_ENC_COMP` cancels it; one added to the
//!   set-point would double it: check on the machine before use).
//!
//! The deviation along a machine axis is read off the description's exact chains (the effect
//! of the error on the tool point relative to the table, with the rotary axes at 0), so its
//! sign follows the side the axis is on: a table-side X that drifts +y moves the tool −y
//! relative to the table.
//!
//! **The grid**: equidistant (`STEP`), from `MIN` = the lower end of the axis's stroke in
//! machine coordinates, with as many steps as reach its upper end (`MAX` is past it by less
//! than a step when the pitch does not divide the stroke); a rotary axis without a range goes
//! over 0–360° as a modulo table. Values outside `MIN`…`MAX` are held at the end values by the
//! NC (K3). At most [`MAX_POINTS`] points per table.

use super::SwivelKinematics;
use crate::tables::Pitch;
use crate::values::{CompensationError, MachineErrors};
use model_spec::catalogue::Motion;
use model_spec::{AxisKind, ErrorKind, Machine, Side};
use nalgebra::Vector3;
use simulation::exact::VirtualMachine;

/// The most points per table written: the documented fixed sizes of the smaller controls
/// (808D: 200 points of measuring-system compensation per axis; 828D: eight sag tables of 200
/// points, "cannot be extended"). On an 840D sl, MD38000 `$MA_MM_ENC_COMP_MAX_POINTS` and
/// MD18342 `$MN_MM_CEC_MAX_POINTS` set the size.
pub const MAX_POINTS: usize = 200;

/// Which compensation a table is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableKind {
    /// `$AA_ENC_COMP`: the axis's own positioning error.
    Encoder,
    /// `$AN_CEC`: a deviation of the output axis as a function of the input axis.
    CrossAxis,
}

/// One table over a machine axis.
#[derive(Clone, Debug, PartialEq)]
pub struct SiemensTable {
    /// Which compensation.
    pub kind: TableKind,
    /// The identified error it holds (`EXX`, `EYX`).
    pub error: String,
    /// The description's axis it is a function of.
    pub axis: String,
    /// The machine axis it is a function of (`X1`).
    pub input: String,
    /// The machine axis it corrects (`X1`; for `$AA_ENC_COMP` the input axis).
    pub output: String,
    /// `true` for a rotary axis: positions and values in degrees; otherwise mm.
    pub rotary: bool,
    /// The first point's position (mm or degrees).
    pub min: f64,
    /// The distance between points (mm or degrees).
    pub step: f64,
    /// `true` for a rotary axis without a range (0–360°).
    pub modulo: bool,
    /// The values at `min + k·step` (mm or degrees).
    pub values: Vec<f64>,
}

impl SiemensTable {
    /// The last point's position (mm or degrees).
    pub fn max(&self) -> f64 {
        self.min + self.step * (self.values.len() - 1) as f64
    }
}

/// Why the tables cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum TableError {
    /// A table would have more than [`MAX_POINTS`] points.
    #[error(
        "the table of {error} over axis {axis} would have {points} points at a pitch of {pitch} {unit}, more than the {MAX_POINTS} written per table"
    )]
    TooManyPoints {
        /// The error.
        error: String,
        /// The description's axis.
        axis: String,
        /// The points needed.
        points: usize,
        /// The pitch (mm or degrees).
        pitch: f64,
        /// `mm` or `degrees`.
        unit: &'static str,
    },
    /// The pitch is not a positive number.
    #[error("the pitch {pitch} {unit} is not a positive number")]
    BadPitch {
        /// The pitch.
        pitch: f64,
        /// `mm` or `degrees`.
        unit: &'static str,
    },
    /// The errors or their values.
    #[error(transparent)]
    Values(#[from] CompensationError),
}

/// The tool point relative to the table (bed coordinates of the table at every axis 0, mm) of
/// machine `m` at commands `q` (mm, rad) with error values `values` (catalogue order).
fn tool_in_table(vm: &VirtualMachine, q: &[f64], params: &[f64], values: &[f64]) -> Vector3<f64> {
    let zero = vec![0.0; q.len()];
    let tool = vm.chain_transform(Side::Tool, q, params, values);
    let w = vm.chain_transform(Side::Work, q, params, values);
    let w0 = vm.nominal_chain_transform(Side::Work, &zero, params);
    (w0 * w.inverse_transform_point(&tool.translation.vector.into())).coords
}

/// The tables of `errors` (identified on `m`, kinematic parameters `params`, mm) over the
/// machine axes of `k` (from `m` or its corrected description: the same axes), with the
/// `pitch` of their points; the names of the errors they hold. See the module documentation.
///
/// # Errors
/// [`TableError`] for a pitch that is not positive or gives more than [`MAX_POINTS`] points, a
/// value that is not finite, or errors identified on another machine.
pub fn siemens_tables(
    m: &Machine,
    params: &[f64],
    errors: &MachineErrors,
    k: &SwivelKinematics,
    pitch: Pitch,
) -> Result<Vec<SiemensTable>, TableError> {
    errors.check_machine(m)?;
    let vm = VirtualMachine::new(m);
    let n = m.axes.len();
    let zero = vec![0.0; n];
    let unit_effect = |e: usize| {
        let mut values = vec![0.0; m.catalogue.len()];
        let base = tool_in_table(&vm, &zero, params, &values);
        values[e] = 1.0;
        tool_in_table(&vm, &zero, params, &values) - base
    };
    let mut tables = Vec::new();
    let mut slot_values = vec![0.0; errors.errors().len()];
    for (slot, &e) in errors.errors().iter().enumerate() {
        let ErrorKind::Component { axis, motion } = m.catalogue[e].kind else {
            continue;
        };
        let a = &m.axes[axis];
        let Some(input) = k.machine_axis(axis) else {
            continue;
        };
        // The output machine axis and the factor from the error's value to the deviation along
        // it (mm or degrees per mm or rad).
        let (output, factor, kind) = match (a.kind, motion) {
            (AxisKind::Linear, Motion::Translation(_)) => {
                let u = unit_effect(e);
                let c = u.iamax();
                if (u - Vector3::ith(c, u[c].signum())).abs().max() > 1e-12 {
                    continue;
                }
                let output = &k.linear[c];
                let kind = if output.axis == axis {
                    TableKind::Encoder
                } else {
                    TableKind::CrossAxis
                };
                (output.name.clone(), u[c], kind)
            }
            (AxisKind::Rotary, Motion::Rotation(d)) if d == a.direction.own.dir => (
                input.name.clone(),
                a.direction.own.sign() * 180.0 / std::f64::consts::PI,
                TableKind::Encoder,
            ),
            _ => continue,
        };
        let rotary = a.kind == AxisKind::Rotary;
        let (step, unit) = if rotary {
            (pitch.rotary_deg, "degrees")
        } else {
            (pitch.linear_mm, "mm")
        };
        if !(step.is_finite() && step > 0.0) {
            return Err(TableError::BadPitch { pitch: step, unit });
        }
        let (lo, hi, modulo) = match a.kind {
            AxisKind::Rotary if !a.limits[0].is_finite() => (0.0, 360.0, true),
            _ => {
                let (p, q) = (input.sign * a.limits[0], input.sign * a.limits[1]);
                (p.min(q), p.max(q), false)
            }
        };
        let steps = ((hi - lo) / step * (1.0 - 1e-12)).ceil().max(0.0);
        let points = steps + 1.0;
        if !points.is_finite() || points > MAX_POINTS as f64 {
            return Err(TableError::TooManyPoints {
                error: m.catalogue[e].name.clone(),
                axis: a.name.clone(),
                points: if points.is_finite() {
                    points as usize
                } else {
                    usize::MAX
                },
                pitch: step,
                unit,
            });
        }
        let mut q = zero.clone();
        let mut values = Vec::with_capacity(points as usize);
        for i in 0..points as usize {
            let position = lo + step * i as f64;
            let command = input.sign * position;
            q[axis] = if rotary {
                command.to_radians()
            } else {
                command
            };
            errors.values_at(m, &q, &mut slot_values);
            let v = factor * slot_values[slot] + 0.0;
            if !v.is_finite() {
                return Err(CompensationError::NonFinite {
                    file: errors.file().to_string(),
                    what: format!(
                        "{} at {position} {unit} of axis {}",
                        m.catalogue[e].name, a.name
                    ),
                    value: v,
                }
                .into());
            }
            values.push(v);
        }
        tables.push(SiemensTable {
            kind,
            error: m.catalogue[e].name.clone(),
            axis: a.name.clone(),
            input: input.name.clone(),
            output,
            rotary,
            min: lo,
            step,
            modulo,
            values,
        });
    }
    Ok(tables)
}
