//! The nominal frame of one probing pose, the one computation the simulation, the probing
//! programs, the probe plans and the reading of probe records share: the commands that put
//! the probe's tip centre on the sphere's centre, the tool frame's rotation and the table
//! normal there, and the linear map from the linear commands to the tip centre's position
//! relative to the sphere.
//!
//! With the rotary axes still, the nominal gap `P_tool − P_work` (bed frame, mm) is affine in
//! the linear commands `q`: `g(q) = g₀ + A·(q − q₀)`, `q₀` the nominal inverse kinematics'
//! commands (tip centre on the sphere's centre, `g₀ ≈ 0`), the columns of `A` the differences
//! of the exact nominal chains at `q₀` and at `q₀ + 1 mm` on each linear axis (exact for an
//! affine map). A point `p` (bed frame, from the sphere's centre) is commanded at
//! `q₀ + A⁻¹·(p − g₀)`.

use crate::exact::{ExactError, VirtualMachine};
use model_spec::{AxisKind, Side};
use nalgebra::{Matrix3, Rotation3, Vector3};

/// The nominal frame of a pose.
#[derive(Clone, Debug, PartialEq)]
pub struct PoseFrame {
    /// The pose's nominal commands (`Machine::axes` order; mm, rad): the rotary axes as given,
    /// the linear axes from the nominal inverse kinematics (tip centre on the sphere's centre).
    pub commands: Vec<f64>,
    /// The three linear axes (indices into `Machine::axes`), in the machine's order.
    pub linear: [usize; 3],
    /// The nominal tool frame's rotation (bed frame ← tool frame) at the pose.
    pub tool_rotation: Rotation3<f64>,
    /// The nominal table normal (unit, bed frame): the workpiece chain's z axis at the pose,
    /// along the sphere's stem from its foot to the sphere.
    pub table_normal: Vector3<f64>,
    /// `g₀`: the nominal gap at [`PoseFrame::commands`] (bed frame, mm; zero to rounding).
    pub gap_mm: Vector3<f64>,
    /// `A`: the change of the nominal gap (bed frame) per unit change of each linear axis, in
    /// the order of [`PoseFrame::linear`] (mm/mm).
    pub linear_map: Matrix3<f64>,
}

/// `P_tool − P_work` of the nominal machine at `q` (mm, rad), bed frame (mm).
fn nominal_gap(vm: &VirtualMachine<'_>, q: &[f64], params: &[f64]) -> Vector3<f64> {
    let tool = vm.transform_with(Side::Tool, q, params, &|_| 0.0);
    let work = vm.transform_with(Side::Work, q, params, &|_| 0.0);
    tool.translation.vector - work.translation.vector
}

impl PoseFrame {
    /// The frame of the pose whose rotary axes stand at `pose` (`Machine::axes` order; rad;
    /// the linear entries are ignored), with the kinematic parameters `params` (mm).
    ///
    /// # Errors
    /// The nominal inverse kinematics' ([`VirtualMachine::tool_centre_point_ik`]): not three
    /// linear axes, linear axes that do not move the tip in three directions.
    pub fn at(vm: &VirtualMachine<'_>, pose: &[f64], params: &[f64]) -> Result<Self, ExactError> {
        let mut q = pose.to_vec();
        vm.tool_centre_point_ik(&mut q, params)?;
        let m = vm.machine();
        // The inverse kinematics succeeded: the machine has three linear axes.
        let mut linear = [0; 3];
        for (slot, i) in linear.iter_mut().zip(m.linear_axes()) {
            *slot = i;
        }
        let gap_mm = nominal_gap(vm, &q, params);
        let mut a = Matrix3::zeros();
        for (j, &i) in linear.iter().enumerate() {
            let mut e = q.clone();
            e[i] += 1.0;
            a.set_column(j, &(nominal_gap(vm, &e, params) - gap_mm));
        }
        let tool = vm.transform_with(Side::Tool, &q, params, &|_| 0.0);
        let work = vm.transform_with(Side::Work, &q, params, &|_| 0.0);
        Ok(PoseFrame {
            commands: q,
            linear,
            tool_rotation: tool.rotation,
            table_normal: work.rotation.matrix().column(2).into_owned(),
            gap_mm,
            linear_map: a,
        })
    }

    /// The nominal gap (bed frame, mm) with the linear axes at those of `axes` (mm;
    /// `Machine::axes` order, the rotary entries ignored: the pose's own are used), from the
    /// exact nominal chains.
    pub fn gap(&self, vm: &VirtualMachine<'_>, axes: &[f64], params: &[f64]) -> Vector3<f64> {
        let m = vm.machine();
        let commands: Vec<f64> = m
            .axes
            .iter()
            .zip(self.commands.iter().zip(axes))
            .map(|(a, (&own, &x))| match a.kind {
                AxisKind::Linear => x,
                AxisKind::Rotary => own,
            })
            .collect();
        nominal_gap(vm, &commands, params)
    }

    /// The change of every command (`Machine::axes` order; mm; 0 for the rotary axes) that
    /// moves the nominal gap by `d` (bed frame, mm): `A⁻¹·d` on the linear axes (NaN when `A`
    /// is singular, which the inverse kinematics has already refused).
    pub fn command_change(&self, d: &Vector3<f64>) -> Vec<f64> {
        let x = self
            .linear_map
            .lu()
            .solve(d)
            .unwrap_or_else(|| Vector3::repeat(f64::NAN));
        let mut full = vec![0.0; self.commands.len()];
        for (j, &i) in self.linear.iter().enumerate() {
            full[i] = x[j];
        }
        full
    }

    /// The commands (mm, rad) that put the nominal tip centre at `p` (bed frame, mm, from the
    /// sphere's centre): `q₀ + A⁻¹·(p − g₀)`.
    pub fn commands_at(&self, p: &Vector3<f64>) -> Vec<f64> {
        let d = self.command_change(&(p - self.gap_mm));
        self.commands.iter().zip(&d).map(|(a, b)| a + b).collect()
    }

    /// The direction (unit, bed frame) the tip centre moves relative to the sphere when linear
    /// axis `k` (an index into [`PoseFrame::linear`]) moves in its + direction.
    pub fn axis_direction(&self, k: usize) -> Vector3<f64> {
        self.linear_map.column(k).normalize()
    }

    /// The nominal tool axis (unit, bed frame): from the tip towards the spindle.
    pub fn tool_axis(&self) -> Vector3<f64> {
        self.tool_rotation.matrix().column(2).into_owned()
    }

    /// A bed-frame vector expressed in the tool frame.
    pub fn to_tool(&self, v: &Vector3<f64>) -> Vector3<f64> {
        self.tool_rotation.inverse_transform_vector(v)
    }
}
