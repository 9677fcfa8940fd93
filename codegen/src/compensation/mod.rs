//! Compensation programs: from a commanded pose and the identified error values to the
//! corrected pose, as straight-line IR that the host evaluates ([`Program::eval`]) and the
//! emitter writes as `no_std` Rust ([`crate::emit`]); both walk the same instructions, so the
//! two agree bit for bit.
//!
//! The corrected pose `q'` makes the predicted tool point and tool axis at `q'` (nominal
//! kinematics plus the model's first-order error) equal the nominal ones at the commanded
//! pose `q`, in the workpiece's own frame. One step, from an iterate `q_k`:
//!
//! 1. the residual `F` at `q_k`, in the tool frame: position `Rᵀ·(t(q_k) − t(q)) + δ`, where
//!    `t` is the tool point in the work frame, `R` the tool-to-work rotation and `δ` the
//!    predicted error (gains × values, with the workpiece point put at the tool point); tilt
//!    of the tool axis `(ω_y − b_x, −ω_x − b_y)` with `ω` the predicted rotation of the tool
//!    relative to the workpiece and `b = Rᵀ·a(q)` the commanded tool axis; roll `ω_z`;
//! 2. the nominal Jacobian's columns are the gains of each axis's positioning error (a command
//!    `+Δ` on a `+x` axis is `EXX = Δ`; on a `−x` axis, `EXX = −Δ`);
//! 3. the rotary axes take the tilt by damped least squares ([`DAMPING`]), the linear axes the
//!    position residual plus what the rotary change moves (exact 3 × 3 inverse).
//!
//! The roll about the tool axis is not corrected (no axis of a five-axis machine turns the tool
//! about its own axis relative to the workpiece without moving the tilt): it is an output.
//! [`STEPS`] steps take the predicted remainder far below 1 nm on every built-in machine; the
//! host checks it and goes on where it is not, with the rotary axes held (near a singular pose
//! the damped orientation converges slowly, and each of its steps would move the predicted
//! error by about the error times the rotary change).

mod kinematics;
mod program;

pub use kinematics::{CompensationError, Ingredients, check_topology};
pub use program::DAMPING;

use crate::atoms::AtomTable;
use crate::ir::Program;
use model_spec::{AxisKind, ErrorId, Machine};

/// The number of steps of the generated `compensate` function (and of the host before it
/// checks the remainder).
pub const STEPS: usize = 3;

/// The outputs of a step after the axis changes: position residual x, y, z (mm), tilt about
/// x and y (rad), roll about the tool axis (rad), all in the tool frame.
pub const RESIDUALS: usize = 6;

/// The compensation programs of one model of one machine.
#[derive(Clone, Debug, PartialEq)]
pub struct CompensationPrograms {
    /// The machine's axes, machine order: name and `true` for a rotary axis.
    pub axes: Vec<(String, bool)>,
    /// Pose inputs (sines and cosines of the rotary commands, linear commands in mm) at the
    /// start of every program's inputs.
    pub pose_inputs: usize,
    /// Kinematic parameters after them (mm), the machine's symbols in order.
    pub params: usize,
    /// The model's errors, whose values (mm, rad) follow in the step programs' inputs.
    pub errors: Vec<String>,
    /// Pose, params → the tool point in the work frame (3, mm) and the tool axis in the work
    /// frame (3): the target of a commanded pose.
    pub target: Program,
    /// Pose, params, values, target (6) → the change of every axis command (mm, rad; machine
    /// order) and the residual at the pose ([`RESIDUALS`] values).
    pub step: Program,
    /// Pose, params, values → as `step` with the pose's own target: the first-order
    /// correction of the commanded pose and the predicted error there.
    pub first_step: Program,
    /// As `step` with the rotary axes held (their changes 0): the host's refinement of the
    /// position once the fixed steps have settled the orientation.
    pub position_step: Program,
}

impl CompensationPrograms {
    /// The number of axes.
    pub fn axis_count(&self) -> usize {
        self.axes.len()
    }
}

/// Compiles the compensation programs of the errors `errors` (catalogue ids of `m`, in model
/// order).
///
/// # Errors
/// [`CompensationError::Topology`] when the machine does not have three linear axes along
/// three directions and at most two rotary axes.
pub fn compile_compensation(
    m: &Machine,
    errors: &[ErrorId],
) -> Result<CompensationPrograms, CompensationError> {
    let ing = Ingredients::derive(m, errors)?;
    let atoms = AtomTable::new(m);
    let pose_inputs = 2 * m.rotary_axes().count() + m.linear_axes().count();
    Ok(CompensationPrograms {
        axes: m
            .axes
            .iter()
            .map(|a| (a.name.clone(), a.kind == AxisKind::Rotary))
            .collect(),
        pose_inputs,
        params: m.symbols.len(),
        errors: errors
            .iter()
            .map(|&e| m.catalogue[e].name.clone())
            .collect(),
        target: program::build(&ing, &atoms, program::Kind::Target),
        step: program::build(&ing, &atoms, program::Kind::Step),
        first_step: program::build(&ing, &atoms, program::Kind::FirstStep),
        position_step: program::build(&ing, &atoms, program::Kind::PositionStep),
    })
}
