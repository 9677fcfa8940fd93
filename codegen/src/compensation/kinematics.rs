//! The symbolic ingredients of compensation: the nominal pose of the tool relative to the
//! workpiece, and the position and rotation gains of the model's errors and of every axis's
//! positioning error (the columns of the nominal Jacobian), with the workpiece point put at the
//! tool point.

use crate::derive::{GainModel, Vec3, nominal_pose, rotation_gains};
use crate::poly::Poly;
use model_spec::{AxisKind, ErrorId, ErrorKind, Machine, Motion, Symbol, SymbolId, Value};

/// Why a machine or model cannot be compensated by the generated code.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum CompensationError {
    /// The topology is outside what the corrected-pose solver handles.
    #[error(
        "machine `{machine}`: compensation needs three linear axes along three different directions and at most two rotary axes ({found})"
    )]
    Topology {
        /// The machine.
        machine: String,
        /// What it has.
        found: String,
    },
}

/// The polynomials a compensation program is built from. Atoms are those of
/// [`Ingredients::machine`]: the machine's own atoms followed by the three coordinates of the
/// workpiece point (the tool point, in the work frame).
#[derive(Clone, Debug)]
pub struct Ingredients {
    /// The machine with its work end moved to three new symbols (the workpiece point).
    pub machine: Machine,
    /// The three new symbols.
    pub work_point: [SymbolId; 3],
    /// The tool point in the last frame of the work chain (mm).
    pub tool_point: Vec3,
    /// The rotation from the tool frame to that work frame.
    pub tool_to_work: [[Poly; 3]; 3],
    /// The model errors: position gains (tool frame) and rotation gains (tool frame).
    pub errors: Vec<(Vec3, Vec3)>,
    /// Their names.
    pub error_names: Vec<String>,
    /// Every axis, machine order: its position and rotation gains per unit of command (mm or
    /// rad), i.e. the column of the nominal Jacobian in the tool frame.
    pub columns: Vec<(Vec3, Vec3)>,
    /// The linear axes, machine order.
    pub linear: Vec<usize>,
    /// The rotary axes, machine order.
    pub rotary: Vec<usize>,
}

/// The axis's positioning error: the translation along (rotation about) its own direction.
fn positioning_error(m: &Machine, axis: usize) -> ErrorId {
    let a = &m.axes[axis];
    let motion = match a.kind {
        AxisKind::Linear => Motion::Translation(a.direction.own.dir),
        AxisKind::Rotary => Motion::Rotation(a.direction.own.dir),
    };
    m.catalogue
        .iter()
        .position(|e| e.kind == ErrorKind::Component { axis, motion })
        .expect("every axis has its positioning error in the catalogue")
}

/// A symbol name not used by `m`.
fn fresh_name(m: &Machine, base: &str) -> String {
    let mut name = base.to_string();
    while m.symbol_by_name(&name).is_some() {
        name.push('_');
    }
    name
}

/// Checks the topology: three linear axes along three directions, at most two rotary axes.
pub fn check_topology(m: &Machine) -> Result<(), CompensationError> {
    let linear: Vec<usize> = m.linear_axes().collect();
    let rotary = m.rotary_axes().count();
    // An inclined linear axis counts as a direction of its own (never one of the three).
    let mut dirs: Vec<usize> = linear
        .iter()
        .map(|&a| {
            m.axes[a]
                .direction
                .as_coordinate()
                .map_or(3 + a, |d| d.dir.index())
        })
        .collect();
    dirs.sort_unstable();
    dirs.dedup();
    let along_xyz = dirs.iter().all(|&d| d < 3);
    if linear.len() != 3 || dirs.len() != 3 || !along_xyz || rotary > 2 {
        return Err(CompensationError::Topology {
            machine: m.name.clone(),
            found: format!(
                "it has {} linear axes along {} directions{} and {rotary} rotary axes",
                linear.len(),
                dirs.len(),
                if along_xyz {
                    ""
                } else {
                    ", not all along x, y or z"
                }
            ),
        });
    }
    Ok(())
}

impl Ingredients {
    /// Derives the ingredients for the errors `errors` (catalogue ids of `m`, in model order).
    ///
    /// # Errors
    /// [`CompensationError::Topology`] for a machine outside what the solver handles.
    pub fn derive(m: &Machine, errors: &[ErrorId]) -> Result<Ingredients, CompensationError> {
        check_topology(m)?;
        let mut machine = m.clone();
        let first = machine.symbols.len();
        for base in ["work_x", "work_y", "work_z"] {
            let name = fresh_name(&machine, base);
            machine.symbols.push(Symbol { name, default: 0.0 });
        }
        machine.work.end_offset = [
            Value::Symbol(first),
            Value::Symbol(first + 1),
            Value::Symbol(first + 2),
        ];
        let axes: Vec<usize> = (0..m.axes.len()).collect();
        // The model's errors, then the positioning errors the model does not have (the
        // derivation tracks each error once).
        let mut all: Vec<ErrorId> = errors.to_vec();
        let column_rows: Vec<usize> = axes
            .iter()
            .map(|&a| {
                let e = positioning_error(m, a);
                all.iter().position(|&x| x == e).unwrap_or_else(|| {
                    all.push(e);
                    all.len() - 1
                })
            })
            .collect();
        let gains = GainModel::derive(&machine, &all);
        let rotations = rotation_gains(&machine, &all);
        let pair = |i: usize| -> (Vec3, Vec3) {
            let g = &gains.gains[i];
            (
                [g[0].clone(), g[1].clone(), g[2].clone()],
                rotations[i].clone(),
            )
        };
        let n = errors.len();
        let columns = axes
            .iter()
            .map(|&a| {
                let (p, r) = pair(column_rows[a]);
                if m.axes[a].direction.own.negative {
                    (p.map(|x| x.neg()), r.map(|x| x.neg()))
                } else {
                    (p, r)
                }
            })
            .collect();
        let nominal = nominal_pose(&machine);
        Ok(Ingredients {
            work_point: [first, first + 1, first + 2],
            tool_point: nominal.tool_point_in_work,
            tool_to_work: nominal.tool_to_work,
            errors: (0..n).map(pair).collect(),
            error_names: errors
                .iter()
                .map(|&e| m.catalogue[e].name.clone())
                .collect(),
            columns,
            linear: m.linear_axes().collect(),
            rotary: m.rotary_axes().collect(),
            machine,
        })
    }
}
