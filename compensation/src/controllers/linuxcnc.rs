//! LinuxCNC's five-axis kinematics modules for table-table machines, `xyzac-trt-kins` and
//! `xyzbc-trt-kins`: which machines they cover, how rtest's axes map onto their joints, and the
//! values of their HAL pins that reproduce a machine description.
//!
//! **The modules' model** (LinuxCNC's `trtfuncs.c`, the kinematics documentation's section on
//! the `trt` modules): with the world position `P` (the controlled point in the coordinates of
//! the table, mm), the tilt angle `θ` (A about x or B about y, degrees) and the table angle `C`
//! (about z), the joints of the linear axes are
//!
//! ```text
//! J = r + d + R_t(θ) · (R_z(C) · (P − r) − d)
//! ```
//!
//! where `r` = (`x-rot-point`, `y-rot-point`, `z-rot-point`) is a point of the C axis and
//! `r + d` a point of the tilt axis, `d` = (0, `y-offset`, `z-offset` + `tool-offset`) for A and
//! (`x-offset`, 0, `z-offset` + `tool-offset`) for B; `R_t` and `R_z` are right-handed
//! rotations of the module's angles. At θ = C = 0 the world position is the joint position.
//!
//! **What the pins hold**: the position of the two axis lines (the C line's x and y, the tilt
//! line's two coordinates across it), nothing else. The directions are the module's (x or y,
//! and z): an angular location error, a squareness or a component error cannot be held and is
//! listed by the caller. The pins are computed from a machine description ([`trt_kinematics`]),
//! normally the corrected one, whose offsets hold the identified location translations
//! ([`crate::kinematics::corrected_description`]).
//!
//! **The joint map** is read off the description, not assumed: a linear axis's joint is the
//! coordinate along which it moves the tool point relative to the table, with the sign of that
//! motion (the table-side X of `seed-ac` moves the table along +x, so its joint is `−X`); a
//! rotary axis's joint angle is `±` its command, the sign that makes the description's rotation
//! of the table the module's right-handed `R_t(θ)·R_z(C)`.
//!
//! The values are written with `z-offset` = `tool-offset` = 0 and `z-rot-point` at the height of
//! the tilt axis (the three only add up, so this is a choice, documented); the controlled point
//! is the description's tool point (for an R-test description, the nest's reference point at
//! its holder length).
//!
//! Every result is checked before it is returned: at [`CHECK_POSES`] poses over the axes'
//! ranges the module's inverse kinematics with these pins gives the joints of the description's
//! own kinematics to [`CHECK_TOLERANCE_MM`].

use model_spec::{AxisId, AxisKind, Dir, Machine, Side};
use nalgebra::{Matrix2, Rotation3, Vector2, Vector3};
use simulation::exact::{Transform, VirtualMachine};

/// The poses at which every result is checked against the description.
pub const CHECK_POSES: usize = 50;

/// How closely the module's inverse kinematics must give the description's joints (mm).
pub const CHECK_TOLERANCE_MM: f64 = 1e-9;

/// One of LinuxCNC's table-table kinematics modules.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrtModule {
    /// `xyzac-trt-kins`: an A table about x carrying a C table about z.
    Xyzac,
    /// `xyzbc-trt-kins`: a B table about y carrying a C table about z.
    Xyzbc,
}

impl TrtModule {
    /// The module's name, as `[KINS] KINEMATICS` and the HAL pins spell it.
    pub fn name(self) -> &'static str {
        match self {
            TrtModule::Xyzac => "xyzac-trt-kins",
            TrtModule::Xyzbc => "xyzbc-trt-kins",
        }
    }

    /// The tilt axis's letter (`A` or `B`).
    pub fn tilt_letter(self) -> char {
        match self {
            TrtModule::Xyzac => 'A',
            TrtModule::Xyzbc => 'B',
        }
    }

    /// `[TRAJ] COORDINATES` of the module, joints 0–4 in this order.
    pub fn coordinates(self) -> &'static str {
        match self {
            TrtModule::Xyzac => "XYZAC",
            TrtModule::Xyzbc => "XYZBC",
        }
    }

    /// The tilt rotation `R_t(θ)` (rad), right-handed.
    fn tilt(self, theta: f64) -> Rotation3<f64> {
        match self {
            TrtModule::Xyzac => Rotation3::from_axis_angle(&Vector3::x_axis(), theta),
            TrtModule::Xyzbc => Rotation3::from_axis_angle(&Vector3::y_axis(), theta),
        }
    }
}

/// The HAL pins of a `trt` module (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrtPins {
    /// `x-rot-point`: the C axis line's x.
    pub x_rot_point: f64,
    /// `y-rot-point`: the C axis line's y.
    pub y_rot_point: f64,
    /// `z-rot-point`: the tilt axis line's z.
    pub z_rot_point: f64,
    /// `x-offset`: for B, the tilt line's x minus the C line's x (`xyzac-trt-kins` ignores it: 0).
    pub x_offset: f64,
    /// `y-offset`: for A, the tilt line's y minus the C line's y (`xyzbc-trt-kins` ignores it: 0).
    pub y_offset: f64,
    /// `z-offset`: 0 (see the module documentation).
    pub z_offset: f64,
    /// `tool-offset`: 0; the controlled point is the description's tool point.
    pub tool_offset: f64,
}

/// The joint of one axis of the description.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// The description's axis.
    pub axis: AxisId,
    /// Its letter in the description.
    pub axis_name: String,
    /// The joint number (0–4: X, Y, Z, then the tilt, then C).
    pub joint: usize,
    /// The joint's coordinate letter in LinuxCNC.
    pub letter: char,
    /// The joint's position is `sign ×` the axis's command (mm, degrees).
    pub sign: f64,
}

/// A machine description mapped onto a `trt` module.
#[derive(Clone, Debug, PartialEq)]
pub struct TrtKinematics {
    /// The module.
    pub module: TrtModule,
    /// Its pins.
    pub pins: TrtPins,
    /// One joint per axis of the description, in joint order.
    pub joints: Vec<Joint>,
    /// The world origin: where the description's tool point is, in its workpiece frame, when
    /// every axis is at 0 (mm). LinuxCNC's world position is the workpiece-frame tool point
    /// minus this.
    pub world_origin: [f64; 3],
    /// The largest difference between the module's joints and the description's at the
    /// [`CHECK_POSES`] check poses (mm).
    pub check_mm: f64,
}

/// Why a description is not covered by LinuxCNC's `trt` modules.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("machine `{machine}` is not covered by LinuxCNC's xyzac-trt-kins or xyzbc-trt-kins: {why}")]
pub struct NotCovered {
    /// The machine's name.
    pub machine: String,
    /// Why.
    pub why: String,
}

/// The exact chains of a description at commands (mm, rad).
struct Chains<'m> {
    vm: VirtualMachine<'m>,
    params: &'m [f64],
}

impl Chains<'_> {
    fn work(&self, q: &[f64]) -> Transform {
        self.vm.nominal_chain_transform(Side::Work, q, self.params)
    }

    /// The tool point in the workpiece frame (mm).
    fn tool_in_work(&self, q: &[f64]) -> Vector3<f64> {
        let tool = self.vm.nominal_chain_transform(Side::Tool, q, self.params);
        let work = self.work(q);
        work.inverse_transform_point(&tool.translation.vector.into())
            .coords
    }
}

/// The axes of a covered machine: three linear, the tilt, C.
struct Roles {
    module: TrtModule,
    tilt: AxisId,
    c: AxisId,
}

/// Which module fits the topology of `m`, or why none.
fn roles(m: &Machine) -> Result<Roles, String> {
    let rotary: Vec<AxisId> = m.rotary_axes().collect();
    let linear = m.linear_axes().count();
    if rotary.len() != 2 || linear != 3 {
        return Err(format!(
            "the modules drive three linear and two rotary axes; this machine has {linear} linear and {} rotary",
            rotary.len()
        ));
    }
    for &i in &rotary {
        let a = &m.axes[i];
        if a.side != Side::Work {
            return Err(format!(
                "its rotary axis {} is on the tool side; the modules have both rotary axes in the table",
                a.name
            ));
        }
        if a.direction.inclined.is_some() {
            return Err(format!(
                "its rotary axis {} is inclined; the modules' axes are along x or y and z",
                a.name
            ));
        }
    }
    // The work chain from the bed: the tilt first, then the C table it carries.
    let order: Vec<AxisId> = m.work.axes().filter(|a| rotary.contains(a)).collect();
    let (tilt, c) = (order[0], order[1]);
    let dir = |i: AxisId| m.axes[i].direction.own.dir;
    if dir(c) != Dir::Z {
        return Err(format!(
            "the rotary axis {} carried by {} turns about {}, not z",
            m.axes[c].name,
            m.axes[tilt].name,
            dir(c)
        ));
    }
    let module = match dir(tilt) {
        Dir::X => TrtModule::Xyzac,
        Dir::Y => TrtModule::Xyzbc,
        Dir::Z => {
            return Err(format!(
                "its tilting axis {} turns about z; the modules tilt about x (A) or y (B)",
                m.axes[tilt].name
            ));
        }
    };
    Ok(Roles { module, tilt, c })
}

/// The sign `s` with which a turn `θ` of `axis` turns the table by `R(about, s·θ)`, or `None`
/// when it turns it about another line.
fn rotation_sign(
    chains: &Chains,
    q0: &[f64],
    axis: AxisId,
    about: &nalgebra::Unit<Vector3<f64>>,
) -> Option<f64> {
    let theta = 30f64.to_radians();
    let mut q = q0.to_vec();
    q[axis] = theta;
    let r = chains.work(&q).rotation * chains.work(q0).rotation.inverse();
    [1.0, -1.0].into_iter().find(|&s| {
        let want = Rotation3::from_axis_angle(about, s * theta);
        (r.matrix() - want.matrix()).abs().max() < 1e-12
    })
}

/// Solves `(R − I)·c = R·p` for the two coordinates `ij` across a rotation axis (the fixed
/// points of `x ↦ R·(x − c) + c` matching `p`, see [`trt_kinematics`]).
fn axis_point(r: &Rotation3<f64>, p: &Vector3<f64>, ij: [usize; 2]) -> Vector2<f64> {
    let m = r.matrix() - nalgebra::Matrix3::identity();
    let rhs = r * p;
    let a = Matrix2::new(
        m[(ij[0], ij[0])],
        m[(ij[0], ij[1])],
        m[(ij[1], ij[0])],
        m[(ij[1], ij[1])],
    );
    let b = Vector2::new(rhs[ij[0]], rhs[ij[1]]);
    a.lu().solve(&b).unwrap_or_else(Vector2::zeros)
}

/// The joints (mm) the module computes for the world position `p` (mm) at the module's angles
/// (rad): its inverse kinematics, as the module documentation states it.
pub fn module_joints(
    module: TrtModule,
    pins: &TrtPins,
    p: &Vector3<f64>,
    tilt: f64,
    c: f64,
) -> Vector3<f64> {
    let r = Vector3::new(pins.x_rot_point, pins.y_rot_point, pins.z_rot_point);
    let dz = pins.z_offset + pins.tool_offset;
    let d = match module {
        TrtModule::Xyzac => Vector3::new(0.0, pins.y_offset, dz),
        TrtModule::Xyzbc => Vector3::new(pins.x_offset, 0.0, dz),
    };
    let rz = Rotation3::from_axis_angle(&Vector3::z_axis(), c);
    r + d + module.tilt(tilt) * (rz * (p - r) - d)
}

/// Maps the description `m` with kinematic parameters `params` (mm, symbol order) onto
/// LinuxCNC's `trt` module that fits it: the joints and the pins (see the module
/// documentation).
///
/// # Errors
/// [`NotCovered`] when the topology is not a table-table machine with a tilt about x or y
/// carrying a C table, when a linear axis does not move the tool along a coordinate direction,
/// or when the module with the pins found does not reproduce the description to
/// [`CHECK_TOLERANCE_MM`] at every check pose.
pub fn trt_kinematics(m: &Machine, params: &[f64]) -> Result<TrtKinematics, NotCovered> {
    let not_covered = |why: String| NotCovered {
        machine: m.name.clone(),
        why,
    };
    let roles = roles(m).map_err(&not_covered)?;
    let module = roles.module;
    let chains = Chains {
        vm: VirtualMachine::new(m),
        params,
    };
    let n = m.axes.len();
    let q0 = vec![0.0; n];
    let origin = chains.tool_in_work(&q0);

    let mut joints = Vec::with_capacity(n);
    for i in m.linear_axes() {
        let mut q = q0.clone();
        q[i] = 1.0;
        let s = chains.tool_in_work(&q) - origin;
        let k = s.iamax();
        let sign = s[k].signum();
        let unit_error = (s - Vector3::ith(k, sign)).abs().max();
        if unit_error > 1e-12 {
            return Err(not_covered(format!(
                "its axis {} moves the tool point relative to the table along ({:.6}, {:.6}, {:.6}), not along a coordinate direction",
                m.axes[i].name, s[0], s[1], s[2]
            )));
        }
        joints.push(Joint {
            axis: i,
            axis_name: m.axes[i].name.clone(),
            joint: k,
            letter: ['X', 'Y', 'Z'][k],
            sign,
        });
    }
    joints.sort_by_key(|j| j.joint);
    if joints.iter().enumerate().any(|(k, j)| j.joint != k) {
        return Err(not_covered(
            "two of its linear axes move the tool point along the same coordinate".to_string(),
        ));
    }
    let tilt_about = match module {
        TrtModule::Xyzac => Vector3::x_axis(),
        TrtModule::Xyzbc => Vector3::y_axis(),
    };
    let c_about = Vector3::z_axis();
    for (axis, about, joint, letter) in [
        (roles.tilt, tilt_about, 3, module.tilt_letter()),
        (roles.c, c_about, 4, 'C'),
    ] {
        let sign = rotation_sign(&chains, &q0, axis, &about).ok_or_else(|| {
            not_covered(format!(
                "its axis {} does not turn the table about a coordinate axis",
                m.axes[axis].name
            ))
        })?;
        joints.push(Joint {
            axis,
            axis_name: m.axes[axis].name.clone(),
            joint,
            letter,
            sign,
        });
    }

    // The world position at a pose with the linear axes at 0 (joints 0): `P = p_w − origin`.
    // With `J = 0` the module's relation gives, at a turn of C alone, `(R_z − I)·r = R_z·P`,
    // and at a turn of the tilt alone, `(R_t − I)·(r + d) = R_t·P`.
    let quarter = std::f64::consts::FRAC_PI_2;
    let world_at = |axis: AxisId| {
        let mut q = q0.clone();
        q[axis] = quarter;
        chains.tool_in_work(&q) - origin
    };
    let c_sign = joints[4].sign;
    let tilt_sign = joints[3].sign;
    let rz = Rotation3::from_axis_angle(&Vector3::z_axis(), c_sign * quarter);
    let rxy = axis_point(&rz, &world_at(roles.c), [0, 1]);
    let rt = module.tilt(tilt_sign * quarter);
    let across = match module {
        TrtModule::Xyzac => [1, 2],
        TrtModule::Xyzbc => [0, 2],
    };
    let t = axis_point(&rt, &world_at(roles.tilt), across);
    let pins = match module {
        TrtModule::Xyzac => TrtPins {
            x_rot_point: rxy[0],
            y_rot_point: rxy[1],
            z_rot_point: t[1],
            x_offset: 0.0,
            y_offset: t[0] - rxy[1],
            z_offset: 0.0,
            tool_offset: 0.0,
        },
        TrtModule::Xyzbc => TrtPins {
            x_rot_point: rxy[0],
            y_rot_point: rxy[1],
            z_rot_point: t[1],
            x_offset: t[0] - rxy[0],
            y_offset: 0.0,
            z_offset: 0.0,
            tool_offset: 0.0,
        },
    };
    let mut k = TrtKinematics {
        module,
        pins,
        joints,
        world_origin: origin.into(),
        check_mm: 0.0,
    };
    k.check_mm = check(m, &chains, &k);
    if k.check_mm.is_nan() || k.check_mm > CHECK_TOLERANCE_MM {
        return Err(not_covered(format!(
            "the module with the pins found misses the description's joints by {:.3e} mm at a check pose",
            k.check_mm
        )));
    }
    Ok(k)
}

/// The check poses: [`CHECK_POSES`] commands spread over the axes' ranges (a rotary axis
/// without a range over ±360°; linear axes over their strokes), deterministic.
pub fn check_poses(m: &Machine) -> Vec<Vec<f64>> {
    (0..CHECK_POSES)
        .map(|k| {
            m.axes
                .iter()
                .enumerate()
                .map(|(i, a)| {
                    // A low-discrepancy fraction per axis (golden-ratio steps).
                    let f = ((k as f64 + 0.5) * (0.618_033_988_749_895 + 0.137 * i as f64)).fract();
                    let [lo, hi] = a.limits;
                    let (lo, hi) = match a.kind {
                        AxisKind::Rotary if !lo.is_finite() || !hi.is_finite() => (-360.0, 360.0),
                        _ => (lo, hi),
                    };
                    let v = lo + f * (hi - lo);
                    if a.kind == AxisKind::Rotary {
                        v.to_radians()
                    } else {
                        v
                    }
                })
                .collect()
        })
        .collect()
}

/// The largest difference (mm) between the description's joints and the module's inverse
/// kinematics at the check poses.
fn check(m: &Machine, chains: &Chains, k: &TrtKinematics) -> f64 {
    let origin = Vector3::from(k.world_origin);
    check_poses(m)
        .iter()
        .map(|q| {
            let p = chains.tool_in_work(q) - origin;
            let angle = |j: &Joint| j.sign * q[j.axis];
            let got = module_joints(
                k.module,
                &k.pins,
                &p,
                angle(&k.joints[3]),
                angle(&k.joints[4]),
            );
            (0..3)
                .map(|j| (got[j] - k.joints[j].sign * q[k.joints[j].axis]).abs())
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max)
}

impl TrtKinematics {
    /// The pins in the order of the module's documentation, as a HAL file sets them.
    pub fn hal_pins(&self) -> Vec<formats::controllers::linuxcnc::Pin> {
        use formats::controllers::linuxcnc::Pin;
        let p = &self.pins;
        [
            ("x-rot-point", p.x_rot_point),
            ("y-rot-point", p.y_rot_point),
            ("z-rot-point", p.z_rot_point),
            ("x-offset", p.x_offset),
            ("y-offset", p.y_offset),
            ("z-offset", p.z_offset),
            ("tool-offset", p.tool_offset),
        ]
        .into_iter()
        .map(|(name, value)| Pin { name, value })
        .collect()
    }

    /// The joint positions (mm, degrees; joint order) of the description's commands (mm, rad).
    pub fn joints_of(&self, commands: &[f64]) -> Vec<f64> {
        self.joints
            .iter()
            .map(|j| {
                let v = j.sign * commands[j.axis];
                if j.joint >= 3 { v.to_degrees() } else { v }
            })
            .collect()
    }

    /// The description's commands (mm, rad; axis order) of joint positions (mm, degrees).
    pub fn commands_of(&self, joints: &[f64]) -> Vec<f64> {
        let mut q = vec![0.0; self.joints.len()];
        for (j, &v) in self.joints.iter().zip(joints) {
            q[j.axis] = j.sign * if j.joint >= 3 { v.to_radians() } else { v };
        }
        q
    }
}
