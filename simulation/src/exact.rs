//! The exact virtual machine: homogeneous transforms of both kinematic chains with no
//! linearisation, the exact error vector (tool minus workpiece, in the tool frame) and the
//! nominal tool-centre-point inverse kinematics.
//!
//! The composition order is the one of [`model_spec::kinematics::chain_steps`]; this module only
//! gives each [`Step`] its exact transform:
//!
//! - `Offset([x, y, z])`: translation by the offset (mm; a symbol takes its value from `params`);
//! - `ErrorTranslation([ex, ey, ez])`: translation by the error values (mm; `None` is 0);
//! - `ErrorRotation([a, b, c])`: exactly `Rx(a)·Ry(b)·Rz(c)` (rad; `None` is 0);
//! - `Motion` of a linear axis moving along the signed direction `±d` by the command `q` (mm):
//!   translation by `±q·d`;
//! - `Motion` of a rotary axis turning about `±d` by the command `θ` (rad) with angular
//!   positioning error `e` (rad): `R(d, ±θ)·R(d, e)`.
//!
//! A chain's transform is `T = S1·S2·…·Sn` (bed outwards); its end point is `T·(0, 0, 0, 1)` and
//! its frame's z axis is the third column of the rotation of `T`.
//!
//! Argument conventions shared by every function here:
//! - `commands`: one per axis in [`Machine::axes`] order; linear axes in mm, rotary axes in
//!   **radians**;
//! - `params`: one per kinematic symbol in [`Machine::symbols`] order (mm), e.g.
//!   [`Machine::default_parameters`];
//! - `errors`: one per catalogue entry in [`Machine::catalogue`] order; translational errors in
//!   mm, angular errors in rad.
//!
//! Slices of the wrong length are programming errors and panic with a message naming the
//! machine and the expected length.

use model_spec::kinematics::{FrameTurn, Step, chain_steps};
use model_spec::{AxisDirection, AxisKind, Dir, ErrorId, Machine, Offset, Side, Value};
use nalgebra::{Matrix3, Rotation3, Translation3, Vector3};

/// A rigid transform of the exact virtual machine: rotation matrix and translation (mm).
/// `Transform::to_homogeneous` gives the 4×4 homogeneous matrix.
pub type Transform = nalgebra::IsometryMatrix3<f64>;

/// The smallest `|det A|` the inverse kinematics accepts, where the columns of `A` are the unit
/// directions (in the bed frame) in which the linear axes move the tool point relative to the
/// workpiece point. Below it the linear axes are treated as unable to reach the point.
pub const IK_MIN_DETERMINANT: f64 = 1e-9;

/// Why the nominal tool-centre-point inverse kinematics has no (unique) answer.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ExactError {
    /// The machine does not have exactly three linear axes, so the linear commands that bring
    /// the tool point onto the workpiece point are not unique (more) or do not exist (fewer).
    #[error(
        "machine `{machine}`: the tool-centre-point inverse kinematics needs exactly three linear axes to place the tool point on the workpiece point; this machine has {count} ({names})"
    )]
    LinearAxisCount {
        /// The machine's name.
        machine: String,
        /// How many linear axes it has.
        count: usize,
        /// Their names, comma-separated.
        names: String,
    },
    /// At this pose the directions in which the linear axes move the tool point relative to the
    /// workpiece point are (nearly) coplanar, so no linear commands reach every point.
    #[error(
        "machine `{machine}`: at {pose} the linear axes {names} move the tool point relative to the workpiece in (nearly) coplanar directions (|det| = {det:e} < {min:e}); the tool-centre-point inverse kinematics has no unique solution",
        min = IK_MIN_DETERMINANT
    )]
    Singular {
        /// The machine's name.
        machine: String,
        /// The rotary commands, for people (`A = -45°, C = 30°`).
        pose: String,
        /// The linear axes' names, comma-separated.
        names: String,
        /// The determinant of the 3×3 matrix of (unit) linear directions.
        det: f64,
    },
}

/// The error vector of the tool point relative to the workpiece point, expressed in the tool
/// frame (the seed's eqs. (8) and (14)–(16), tool minus workpiece).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorVector {
    /// `R_tool^T · (P_tool − P_work)`, mm, with `R_tool` the rotation of the actual (erroneous)
    /// tool-chain transform.
    pub position: Vector3<f64>,
    /// `R_tool0^T · ((z_tool − z_tool0) − (z_work − z_work0))`, dimensionless (rad to first
    /// order), with `z` the third column of a chain's rotation (`0`: without errors) and
    /// `R_tool0` the nominal tool rotation.
    pub orientation: Vector3<f64>,
}

impl ErrorVector {
    /// `[position (mm); orientation]` as one 6-vector.
    pub fn to_array(&self) -> [f64; 6] {
        let (p, o) = (&self.position, &self.orientation);
        [p.x, p.y, p.z, o.x, o.y, o.z]
    }
}

/// The rotation of a [`Step::Frame`] of an axis whose direction is `direction`: into its own
/// frame (the matrix whose columns are `x' y' z'`) or back (its transpose).
pub fn frame_rotation(direction: &AxisDirection, turn: FrameTurn) -> Rotation3<f64> {
    // nalgebra reads `[[f64; 3]; 3]` as columns: `own` has the columns x' y' z'.
    let own = Matrix3::from(direction.frame());
    Rotation3::from_matrix_unchecked(match turn {
        FrameTurn::Into => own,
        FrameTurn::Back => own.transpose(),
    })
}

/// The rotation by `angle` (rad) about the positive coordinate direction `dir`.
pub fn coordinate_rotation(dir: Dir, angle: f64) -> Rotation3<f64> {
    let (s, c) = angle.sin_cos();
    let m = match dir {
        Dir::X => Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c),
        Dir::Y => Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c),
        Dir::Z => Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0),
    };
    Rotation3::from_matrix_unchecked(m)
}

/// The unit vector of the coordinate direction `dir`.
fn unit(dir: Dir) -> Vector3<f64> {
    let mut v = Vector3::zeros();
    v[dir.index()] = 1.0;
    v
}

/// A machine with its chains lowered once, so that repeated evaluations (paths, finite
/// differences) do not lower them again. Every free function of this module builds one.
#[derive(Clone, Debug)]
pub struct VirtualMachine<'m> {
    machine: &'m Machine,
    work: Vec<Step>,
    tool: Vec<Step>,
}

impl<'m> VirtualMachine<'m> {
    /// Lowers both chains of `machine` with [`chain_steps`].
    pub fn new(machine: &'m Machine) -> Self {
        VirtualMachine {
            machine,
            work: chain_steps(machine, Side::Work),
            tool: chain_steps(machine, Side::Tool),
        }
    }

    /// The machine.
    pub fn machine(&self) -> &'m Machine {
        self.machine
    }

    /// The lowered steps of the chain on `side`, bed outwards.
    pub fn steps(&self, side: Side) -> &[Step] {
        match side {
            Side::Work => &self.work,
            Side::Tool => &self.tool,
        }
    }

    pub(crate) fn check_pose(&self, commands: &[f64], params: &[f64]) {
        let m = self.machine;
        assert_eq!(
            commands.len(),
            m.axes.len(),
            "machine `{}`: expected one command per axis ({}), got {}",
            m.name,
            m.axes.len(),
            commands.len()
        );
        assert_eq!(
            params.len(),
            m.symbols.len(),
            "machine `{}`: expected one parameter per kinematic symbol ({}), got {}",
            m.name,
            m.symbols.len(),
            params.len()
        );
    }

    fn check_errors(&self, errors: &[f64]) {
        let m = self.machine;
        assert_eq!(
            errors.len(),
            m.catalogue.len(),
            "machine `{}`: expected one error value per catalogue entry ({}), got {}",
            m.name,
            m.catalogue.len(),
            errors.len()
        );
    }

    /// The exact transform of the chain on `side` (bed frame ← end frame, mm), with the error
    /// values `error(id)` (mm or rad).
    pub fn transform_with(
        &self,
        side: Side,
        commands: &[f64],
        params: &[f64],
        error: &dyn Fn(ErrorId) -> f64,
    ) -> Transform {
        let value = |v: &Value| match *v {
            Value::Number(x) => x,
            Value::Symbol(s) => params[s],
        };
        let offset = |o: &Offset| Translation3::new(value(&o[0]), value(&o[1]), value(&o[2]));
        let err = |e: &Option<ErrorId>| e.map_or(0.0, error);
        let mut t = Transform::identity();
        for step in self.steps(side) {
            let s = match step {
                Step::Offset(o) => Transform::from_parts(offset(o), Rotation3::identity()),
                Step::ErrorTranslation(e) => Transform::from_parts(
                    Translation3::new(err(&e[0]), err(&e[1]), err(&e[2])),
                    Rotation3::identity(),
                ),
                Step::ErrorRotation(e) => Transform::from_parts(
                    Translation3::identity(),
                    coordinate_rotation(Dir::X, err(&e[0]))
                        * coordinate_rotation(Dir::Y, err(&e[1]))
                        * coordinate_rotation(Dir::Z, err(&e[2])),
                ),
                Step::Frame { axis, turn } => Transform::from_parts(
                    Translation3::identity(),
                    frame_rotation(&self.machine.axes[*axis].direction, *turn),
                ),
                Step::Motion {
                    axis,
                    positioning_error,
                } => {
                    let a = &self.machine.axes[*axis];
                    let (dir, sign) = (a.direction.own.dir, a.direction.own.sign());
                    let q = commands[*axis];
                    match a.kind {
                        AxisKind::Linear => Transform::from_parts(
                            Translation3::from(unit(dir) * (sign * q)),
                            Rotation3::identity(),
                        ),
                        AxisKind::Rotary => Transform::from_parts(
                            Translation3::identity(),
                            coordinate_rotation(dir, sign * q)
                                * coordinate_rotation(dir, err(positioning_error)),
                        ),
                    }
                }
            };
            t *= s;
        }
        t
    }

    /// The exact transform of the chain on `side` (maps end-frame coordinates to the bed frame,
    /// mm) at `commands` (mm, rad) with `params` (mm) and error values `errors` (mm, rad).
    ///
    /// # Panics
    /// When a slice's length does not match the machine.
    pub fn chain_transform(
        &self,
        side: Side,
        commands: &[f64],
        params: &[f64],
        errors: &[f64],
    ) -> Transform {
        self.check_pose(commands, params);
        self.check_errors(errors);
        self.transform_with(side, commands, params, &|id| errors[id])
    }

    /// The transform of the chain on `side` with every error zero (the nominal machine).
    ///
    /// # Panics
    /// When a slice's length does not match the machine.
    pub fn nominal_chain_transform(
        &self,
        side: Side,
        commands: &[f64],
        params: &[f64],
    ) -> Transform {
        self.check_pose(commands, params);
        self.transform_with(side, commands, params, &|_| 0.0)
    }

    /// The exact error vector (tool minus workpiece, tool frame) at `commands` (mm, rad) with
    /// `params` (mm) and error values `errors` (mm, rad). See [`ErrorVector`].
    ///
    /// # Panics
    /// When a slice's length does not match the machine.
    pub fn error_vector(&self, commands: &[f64], params: &[f64], errors: &[f64]) -> ErrorVector {
        self.check_pose(commands, params);
        self.check_errors(errors);
        let actual = |side| self.transform_with(side, commands, params, &|id| errors[id]);
        let nominal = |side| self.transform_with(side, commands, params, &|_| 0.0);
        error_vector_of(
            &actual(Side::Tool),
            &actual(Side::Work),
            &nominal(Side::Tool),
            &nominal(Side::Work),
        )
    }

    /// The error vector with every error zero: the nominal mismatch `R_tool0^T·(P_tool0 −
    /// P_work0)` (mm) between the tool point and the workpiece point; its orientation part is
    /// zero. It is zero (to rounding) after [`VirtualMachine::tool_centre_point_ik`].
    ///
    /// # Panics
    /// When a slice's length does not match the machine.
    pub fn nominal_error_vector(&self, commands: &[f64], params: &[f64]) -> ErrorVector {
        self.check_pose(commands, params);
        let tool = self.transform_with(Side::Tool, commands, params, &|_| 0.0);
        let work = self.transform_with(Side::Work, commands, params, &|_| 0.0);
        error_vector_of(&tool, &work, &tool, &work)
    }

    /// `P_tool − P_work` of the nominal machine, in the bed frame (mm).
    fn nominal_gap(&self, commands: &[f64], params: &[f64]) -> Vector3<f64> {
        let tool = self.transform_with(Side::Tool, commands, params, &|_| 0.0);
        let work = self.transform_with(Side::Work, commands, params, &|_| 0.0);
        tool.translation.vector - work.translation.vector
    }

    /// Nominal tool-centre-point inverse kinematics: keeps the rotary entries of `commands`
    /// (rad) and overwrites its linear entries (mm) so that the nominal tool point coincides
    /// with the nominal workpiece point.
    ///
    /// With the rotary commands fixed, `P_tool − P_work` is affine in the linear commands `q`:
    /// `A·q + b`. `b` and the columns of `A` (unit vectors, bed frame) come from evaluating the
    /// chains at `q = 0` and at unit commands; `A·q = −b` is solved by LU, then refined by one
    /// Newton step on the residual.
    ///
    /// # Errors
    /// [`ExactError::LinearAxisCount`] unless the machine has exactly three linear axes;
    /// [`ExactError::Singular`] when `|det A| <` [`IK_MIN_DETERMINANT`] at this pose. On error
    /// `commands` is unchanged.
    ///
    /// # Panics
    /// When a slice's length does not match the machine.
    pub fn tool_centre_point_ik(
        &self,
        commands: &mut [f64],
        params: &[f64],
    ) -> Result<(), ExactError> {
        self.check_pose(commands, params);
        let m = self.machine;
        let linear: Vec<usize> = m.linear_axes().collect();
        let names = linear
            .iter()
            .map(|&i| m.axes[i].name.as_str())
            .collect::<Vec<_>>()
            .join(", ");
        if linear.len() != 3 {
            return Err(ExactError::LinearAxisCount {
                machine: m.name.clone(),
                count: linear.len(),
                names,
            });
        }
        let mut work: Vec<f64> = commands.to_vec();
        for &i in &linear {
            work[i] = 0.0;
        }
        let b = self.nominal_gap(&work, params);
        let mut a = Matrix3::zeros();
        for (j, &i) in linear.iter().enumerate() {
            work[i] = 1.0;
            a.set_column(j, &(self.nominal_gap(&work, params) - b));
            work[i] = 0.0;
        }
        let det = a.determinant();
        if det.abs() < IK_MIN_DETERMINANT || !det.is_finite() {
            let pose = m
                .rotary_axes()
                .map(|i| {
                    let deg = model_spec::units::degrees_for(commands[i]);
                    format!("{} = {}°", m.axes[i].name, model_spec::units::short(deg))
                })
                .collect::<Vec<_>>()
                .join(", ");
            return Err(ExactError::Singular {
                machine: m.name.clone(),
                pose: if pose.is_empty() {
                    "every pose".to_string()
                } else {
                    pose
                },
                names,
                det,
            });
        }
        let lu = a.lu();
        let mut q = lu.solve(&(-b)).expect("|det| checked above");
        // One refinement step on the exact residual removes the rounding of the LU solve.
        for (j, &i) in linear.iter().enumerate() {
            work[i] = q[j];
        }
        let residual = self.nominal_gap(&work, params);
        if let Some(dq) = lu.solve(&(-residual)) {
            q += dq;
        }
        for (j, &i) in linear.iter().enumerate() {
            commands[i] = q[j];
        }
        Ok(())
    }
}

/// The error vector from the actual (`tool`, `work`) and nominal (`tool0`, `work0`) chain
/// transforms; see [`ErrorVector`].
pub fn error_vector_of(
    tool: &Transform,
    work: &Transform,
    tool0: &Transform,
    work0: &Transform,
) -> ErrorVector {
    let gap = tool.translation.vector - work.translation.vector;
    let z = |t: &Transform| t.rotation.matrix().column(2).into_owned();
    let dz = (z(tool) - z(tool0)) - (z(work) - z(work0));
    ErrorVector {
        position: tool.rotation.inverse_transform_vector(&gap),
        orientation: tool0.rotation.inverse_transform_vector(&dz),
    }
}

/// The exact transform of the chain on `side` of `machine` (end frame → bed frame, mm) at
/// `commands` (mm, rad), `params` (mm) and `errors` (mm, rad). The end point (mm, bed frame) is
/// its translation; `.to_homogeneous()` gives the 4×4 matrix.
///
/// # Panics
/// When a slice's length does not match the machine.
pub fn chain_transform(
    machine: &Machine,
    side: Side,
    commands: &[f64],
    params: &[f64],
    errors: &[f64],
) -> Transform {
    VirtualMachine::new(machine).chain_transform(side, commands, params, errors)
}

/// The exact error vector of `machine` (tool minus workpiece, tool frame; position mm) at
/// `commands` (mm, rad), `params` (mm) and `errors` (mm, rad). See [`ErrorVector`].
///
/// # Panics
/// When a slice's length does not match the machine.
pub fn error_vector(
    machine: &Machine,
    commands: &[f64],
    params: &[f64],
    errors: &[f64],
) -> ErrorVector {
    VirtualMachine::new(machine).error_vector(commands, params, errors)
}

/// The error vector of `machine` with every error zero (nominal mismatch of the tool point and
/// the workpiece point, tool frame, mm; orientation zero).
///
/// # Panics
/// When a slice's length does not match the machine.
pub fn nominal_error_vector(machine: &Machine, commands: &[f64], params: &[f64]) -> ErrorVector {
    VirtualMachine::new(machine).nominal_error_vector(commands, params)
}

/// Nominal tool-centre-point inverse kinematics of `machine`: overwrites the linear entries of
/// `commands` (mm) so that the nominal tool point meets the nominal workpiece point at the
/// rotary commands already in `commands` (rad). See [`VirtualMachine::tool_centre_point_ik`].
///
/// # Errors
/// [`ExactError::LinearAxisCount`] or [`ExactError::Singular`]; `commands` is then unchanged.
///
/// # Panics
/// When a slice's length does not match the machine.
pub fn tool_centre_point_ik(
    machine: &Machine,
    commands: &mut [f64],
    params: &[f64],
) -> Result<(), ExactError> {
    VirtualMachine::new(machine).tool_centre_point_ik(commands, params)
}
