//! The nominal geometry of one probing pose: where the nominal machine puts the probe's tip
//! centre relative to the sphere's centre, and how the probe's (tool) frame stands.

use model_spec::{AxisKind, Machine, Side};
use nalgebra::{Matrix3, Rotation3, Vector3};
use simulation::exact::{ExactError, VirtualMachine};

/// The nominal geometry of a pose: its rotary commands, the nominal linear commands that put
/// the tip centre on the sphere's centre, and the tool frame's rotation there.
#[derive(Clone, Debug)]
pub struct PoseGeometry {
    /// The pose's commands (`Machine::axes` order; mm, rad): the rotary axes as probed, the
    /// linear axes from the nominal inverse kinematics (tip centre on the sphere's centre).
    pub commands: Vec<f64>,
    /// The nominal tool frame's rotation (bed frame ← tool frame) at the pose.
    pub tool_rotation: Rotation3<f64>,
    /// The nominal table normal (unit, bed frame): the workpiece chain's z axis at the pose,
    /// along the sphere's stem from its foot to the sphere.
    pub table_normal: Vector3<f64>,
}

impl PoseGeometry {
    /// The pose whose rotary axes stand at `axes` (`Machine::axes` order, rotary in degrees;
    /// linear entries ignored), with the kinematic parameters `params` (mm).
    ///
    /// # Errors
    /// When the nominal inverse kinematics has no unique answer at that pose.
    pub fn at(vm: &VirtualMachine<'_>, axes: &[f64], params: &[f64]) -> Result<Self, ExactError> {
        let m = vm.machine();
        let mut commands: Vec<f64> = m
            .axes
            .iter()
            .zip(axes)
            .map(|(a, &x)| match a.kind {
                AxisKind::Linear => 0.0,
                AxisKind::Rotary => x.to_radians(),
            })
            .collect();
        vm.tool_centre_point_ik(&mut commands, params)?;
        let tool = vm.transform_with(Side::Tool, &commands, params, &|_| 0.0);
        let work = vm.transform_with(Side::Work, &commands, params, &|_| 0.0);
        Ok(PoseGeometry {
            commands,
            tool_rotation: tool.rotation,
            table_normal: work.rotation.matrix().column(2).into_owned(),
        })
    }

    /// The nominal tip centre relative to the nominal sphere centre (`P_tool − P_work`, bed
    /// frame, mm) with the linear axes at `axes` (mm; `Machine::axes` order, rotary entries
    /// ignored: the pose's own are used).
    pub fn gap(&self, vm: &VirtualMachine<'_>, axes: &[f64], params: &[f64]) -> Vector3<f64> {
        let m = vm.machine();
        let commands = self.with_linear(m, axes);
        let tool = vm.transform_with(Side::Tool, &commands, params, &|_| 0.0);
        let work = vm.transform_with(Side::Work, &commands, params, &|_| 0.0);
        tool.translation.vector - work.translation.vector
    }

    /// The bed-frame move of the tip centre relative to the sphere per mm of each linear axis
    /// (columns in the machine's order of its linear axes, the first three): the nominal gap is
    /// affine in the linear commands at the pose's rotary ones, so one difference per axis
    /// gives it exactly.
    pub fn linear_map(&self, vm: &VirtualMachine<'_>, params: &[f64]) -> Matrix3<f64> {
        let m = vm.machine();
        let base = self.gap(vm, &self.commands, params);
        let mut a = Matrix3::zeros();
        for (k, i) in m.linear_axes().enumerate().take(3) {
            let mut moved = self.commands.clone();
            moved[i] += 1.0;
            a.set_column(k, &(self.gap(vm, &moved, params) - base));
        }
        a
    }

    /// The pose's commands with the linear axes replaced by those of `axes` (mm).
    fn with_linear(&self, m: &Machine, axes: &[f64]) -> Vec<f64> {
        m.axes
            .iter()
            .zip(self.commands.iter().zip(axes))
            .map(|(a, (&own, &x))| match a.kind {
                AxisKind::Linear => x,
                AxisKind::Rotary => own,
            })
            .collect()
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
