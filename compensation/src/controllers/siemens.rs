//! SINUMERIK's swivel data records (`$TC_CARR1` … `$TC_CARR23`, the orientable toolholder of
//! the function manual W1, used by CYCLE800 and, with TRAORI type 72, by the five-axis
//! transformation): which machines a record covers, and the record's vectors that reproduce a
//! machine description, computed from its exact chains. The axis compensation tables
//! (`$AA_ENC_COMP`, `$AN_CEC`) are in [`tables`]; the files are written by
//! `formats::controllers::siemens`. See docs/controllers.md, section "Siemens".
//!
//! **The chain** ([`tool_in_table`]; W1 2005 §2.5 and the CYCLE800 commissioning manual IM9,
//! §22.6 (2013) and §21.7 (2017): the vector definitions; the composition is read off their
//! figures, the manuals print no formula). `J` is the position of the three linear machine axes
//! (mm), `R_i` the right-handed rotation by the effective angle `α_i` (degrees: the axis's
//! position minus `$TC_CARR24`/`25`) about the unit vector `v_i` (`$TC_CARR7..9`, `10..12`),
//! both vectors given with every rotary axis at 0:
//!
//! ```text
//! T (head):   tool tip   = J − [l1 + R1·(l2 + R2·l3)]          table point p stays at p
//! P (table):  tool tip   = J,   table point p moves to  l2 + R1·(l3 + R2·(p − l2 − l3))
//! M (mixed):  tool tip   = J − [l1 + R1·l2],   table point p moves to  l3 + R2·(p − l3)
//! ```
//!
//! with the closures `l1 = −(l2 + l3)` (T), `l4 = −(l2 + l3)` (P), `l1 = −l2`, `l4 = −l3` (M).
//! The tool tip relative to the table is the table map inverted at the tool tip: what this
//! module computes and checks, and what the tests recompute from the written text.
//!
//! **The machine coordinates** the vectors are given in: the description's bed axes, the
//! origin at the description's tool point when every axis is at 0 (the controlled point is
//! the description's tool point, tool length 0). A linear machine axis is the coordinate along
//! which its axis moves the tool point relative to the table, with that sign (the table-side X
//! of `seed-ac` moves the table along +x, so machine axis X1 is `−X`); a rotary axis's
//! position is its command, and its vector the direction about which a positive command turns
//! the table or the head (right-handed), read off the chain: on a table that is the
//! description's direction, whatever the ISO convention of the machine.
//!
//! **The vectors** are the description's axis lines: `v_i` their directions, the offsets the
//! points where they are taken: for two axes on one side, the ends of their common
//! perpendicular (for intersecting axes, the intersection); for one axis on each side (M), the
//! point of each line nearest the origin. The description is normally the corrected one
//! ([`crate::kinematics::corrected_description`]), whose offsets (and, where folded, axis
//! directions) hold the identified location errors.
//!
//! Covered: three linear axes that each move the tool point relative to the table along one
//! coordinate direction, carried by no rotary axis, and two rotary axes: both in the table
//! (P), one in the head and one in the table (M), or both in the head (T). Rotary axis 1 is the
//! table's outer axis (P), the head's (M), the head's outer axis (T).
//!
//! Every result is checked before it is returned: at [`CHECK_POSES`] poses over the axes'
//! ranges, the chain with these vectors gives the description's tool point relative to its
//! table to [`CHECK_TOLERANCE_MM`].

pub mod tables;

use super::linuxcnc::check_poses;
use model_spec::{AxisId, AxisKind, Machine, Side};
use nalgebra::{Matrix2, Rotation3, Unit, Vector2, Vector3};
use simulation::exact::{Transform, VirtualMachine};

/// The poses at which every result is checked against the description.
pub const CHECK_POSES: usize = 50;

/// How closely the chain with the computed vectors must give the description's tool point
/// relative to the table (mm).
pub const CHECK_TOLERANCE_MM: f64 = 1e-9;

/// A vector of the record (mm, or a unit vector).
pub type Vector = Vector3<f64>;

/// The kinematic type of a swivel data record, `$TC_CARR23`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KinematicType {
    /// `T`: only the tool turns (a swivel head).
    T,
    /// `P`: only the part turns (a swivel table).
    P,
    /// `M`: the tool turns about rotary axis 1, the part about rotary axis 2.
    M,
}

impl KinematicType {
    /// The letter `$TC_CARR23` takes.
    pub fn letter(self) -> char {
        match self {
            KinematicType::T => 'T',
            KinematicType::P => 'P',
            KinematicType::M => 'M',
        }
    }
}

/// The kinematic values of a swivel data record (mm; the vectors `v1`, `v2` unit vectors).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SwivelData {
    /// `$TC_CARR23`.
    pub kind: KinematicType,
    /// Offset vector `l1` (`$TC_CARR1..3`).
    pub l1: Vector3<f64>,
    /// Offset vector `l2` (`$TC_CARR4..6`).
    pub l2: Vector3<f64>,
    /// Offset vector `l3` (`$TC_CARR15..17`).
    pub l3: Vector3<f64>,
    /// Offset vector `l4` (`$TC_CARR18..20`).
    pub l4: Vector3<f64>,
    /// Direction of rotary axis 1 (`$TC_CARR7..9`).
    pub v1: Vector3<f64>,
    /// Direction of rotary axis 2 (`$TC_CARR10..12`).
    pub v2: Vector3<f64>,
}

/// A machine axis of the controller and the description's axis it is.
#[derive(Clone, Debug, PartialEq)]
pub struct MachineAxis {
    /// The description's axis.
    pub axis: AxisId,
    /// Its letter in the description.
    pub axis_name: String,
    /// The machine axis's name as written into the tables (`X1`, `C1`): SINUMERIK's default
    /// machine axis names, the coordinate's letter (linear) or the description's letter
    /// (rotary) followed by 1.
    pub name: String,
    /// The machine axis's position is `sign ×` the description's command (mm; for a rotary
    /// axis always +1, degrees).
    pub sign: f64,
}

/// A machine description mapped onto a swivel data record.
#[derive(Clone, Debug, PartialEq)]
pub struct SwivelKinematics {
    /// The record's values.
    pub data: SwivelData,
    /// The linear machine axes X1, Y1, Z1, in this order.
    pub linear: Vec<MachineAxis>,
    /// Rotary axis 1, then rotary axis 2.
    pub rotary: Vec<MachineAxis>,
    /// The origin of the machine coordinates: the description's tool point with every axis at
    /// 0, in its bed frame (mm).
    pub origin: Vector3<f64>,
    /// The largest difference between the chain with these values and the description at the
    /// [`CHECK_POSES`] check poses (mm).
    pub check_mm: f64,
}

/// Why a description is not covered by a swivel data record.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("machine `{machine}` is not covered by a SINUMERIK swivel data record: {why}")]
pub struct NotCovered {
    /// The machine's name.
    pub machine: String,
    /// Why.
    pub why: String,
}

/// The right-handed rotation by `deg` degrees about `v` (normalised).
fn rotation(v: &Vector3<f64>, deg: f64) -> Rotation3<f64> {
    Rotation3::from_axis_angle(&Unit::new_normalize(*v), deg.to_radians())
}

/// The documented chain (see the module documentation): the tool tip relative to the table, in
/// machine coordinates of the table at every rotary axis 0 (mm), for the linear machine axes at
/// `j` (mm) and the effective angles `alpha1`, `alpha2` (degrees).
pub fn tool_in_table(d: &SwivelData, j: &Vector3<f64>, alpha1: f64, alpha2: f64) -> Vector3<f64> {
    let r1 = rotation(&d.v1, alpha1);
    let r2 = rotation(&d.v2, alpha2);
    match d.kind {
        KinematicType::T => j - (d.l1 + r1 * (d.l2 + r2 * d.l3)),
        KinematicType::P => d.l2 + d.l3 + r2.inverse() * (r1.inverse() * (j - d.l2) - d.l3),
        KinematicType::M => {
            let tip = j - (d.l1 + r1 * d.l2);
            d.l3 + r2.inverse() * (tip - d.l3)
        }
    }
}

/// The exact chains of a description at commands (mm, rad).
struct Chains<'m> {
    vm: VirtualMachine<'m>,
    params: &'m [f64],
    zero: Vec<f64>,
}

impl Chains<'_> {
    fn chain(&self, side: Side, q: &[f64]) -> Transform {
        self.vm.nominal_chain_transform(side, q, self.params)
    }

    /// The tool point relative to the table, in bed coordinates of the table at every axis 0
    /// (mm).
    fn tool_in_table(&self, q: &[f64]) -> Vector3<f64> {
        let tool = self.chain(Side::Tool, q).translation.vector;
        let w = self.chain(Side::Work, q);
        let w0 = self.chain(Side::Work, &self.zero);
        (w0 * w.inverse_transform_point(&tool.into())).coords
    }

    /// The line of rotary axis `axis` with every other axis at 0: its direction (right-handed
    /// for a positive command) and its point nearest the bed origin, in bed coordinates.
    fn line(&self, axis: AxisId, side: Side) -> Option<(Vector3<f64>, Vector3<f64>)> {
        let theta = std::f64::consts::FRAC_PI_2;
        let mut q = self.zero.clone();
        q[axis] = theta;
        let moved: Transform = self.chain(side, &q) * self.chain(side, &self.zero).inverse();
        let (v, angle) = moved.rotation.axis_angle()?;
        if (angle - theta).abs() > 1e-9 {
            return None;
        }
        let v = v.into_inner();
        let t = moved.translation.vector;
        // The fixed points: (I − R)·c = t, solved in the plane across v.
        let u = v
            .cross(&if v.x.abs() < 0.9 {
                Vector3::x()
            } else {
                Vector3::y()
            })
            .normalize();
        let w = v.cross(&u);
        let m = moved.rotation.matrix();
        let a = |x: &Vector3<f64>| x - m * x;
        let (au, aw) = (a(&u), a(&w));
        let sys = Matrix2::new(u.dot(&au), u.dot(&aw), w.dot(&au), w.dot(&aw));
        let ab = sys.lu().solve(&Vector2::new(u.dot(&t), w.dot(&t)))?;
        Some((v, u * ab[0] + w * ab[1]))
    }
}

/// The ends of the common perpendicular of the lines `(v1, c1)` and `(v2, c2)`, or for
/// parallel lines the point of line 1 nearest `near` and the point of line 2 nearest that.
fn common_perpendicular(
    (v1, c1): (Vector3<f64>, Vector3<f64>),
    (v2, c2): (Vector3<f64>, Vector3<f64>),
    near: &Vector3<f64>,
) -> (Vector3<f64>, Vector3<f64>) {
    let n = v1.cross(&v2);
    if n.norm() < 1e-9 {
        let p1 = nearest(&v1, &c1, near);
        return (p1, nearest(&v2, &c2, &p1));
    }
    // c1 + s·v1 − (c2 + t·v2) ⟂ v1 and v2.
    let d = c1 - c2;
    let sys = Matrix2::new(v1.dot(&v1), -v1.dot(&v2), v1.dot(&v2), -v2.dot(&v2));
    let st = sys
        .lu()
        .solve(&Vector2::new(-d.dot(&v1), -d.dot(&v2)))
        .unwrap_or_else(Vector2::zeros);
    (c1 + v1 * st[0], c2 + v2 * st[1])
}

/// The point of the line through `c` along the unit vector `v` nearest `p`.
fn nearest(v: &Vector3<f64>, c: &Vector3<f64>, p: &Vector3<f64>) -> Vector3<f64> {
    c + v * v.dot(&(p - c))
}

/// `x` rounded to `1e-12` mm, so that the numeric noise of the chains does not reach the file
/// (far below the check's tolerance).
fn clean_mm(x: Vector3<f64>) -> Vector3<f64> {
    x.map(|c| (c * 1e12).round() / 1e12 + 0.0)
}

/// A unit vector with components rounded to `1e-15`.
fn clean_unit(x: Vector3<f64>) -> Vector3<f64> {
    x.map(|c| (c * 1e15).round() / 1e15 + 0.0)
}

/// Which side each rotary axis is on, in the order of the record, and the type; or why not.
fn roles(m: &Machine) -> Result<(KinematicType, [(AxisId, Side); 2]), String> {
    let rotary: Vec<AxisId> = m.rotary_axes().collect();
    let linear = m.linear_axes().count();
    if rotary.len() != 2 || linear != 3 {
        return Err(format!(
            "a record describes two rotary axes over three linear ones; this machine has {linear} linear and {} rotary",
            rotary.len()
        ));
    }
    for side in [Side::Work, Side::Tool] {
        let mut rotary_seen = false;
        for a in m.chain(side).axes() {
            match m.axes[a].kind {
                AxisKind::Rotary => rotary_seen = true,
                AxisKind::Linear if rotary_seen => {
                    return Err(format!(
                        "its linear axis {} is carried by a rotary axis; a record's linear axes are the machine's, below the rotary ones",
                        m.axes[a].name
                    ));
                }
                AxisKind::Linear => {}
            }
        }
    }
    let on = |side: Side| -> Vec<AxisId> {
        m.chain(side)
            .axes()
            .filter(|a| rotary.contains(a))
            .collect()
    };
    let (work, tool) = (on(Side::Work), on(Side::Tool));
    Ok(match (tool.len(), work.len()) {
        (0, _) => (
            KinematicType::P,
            [(work[0], Side::Work), (work[1], Side::Work)],
        ),
        (2, _) => (
            KinematicType::T,
            [(tool[0], Side::Tool), (tool[1], Side::Tool)],
        ),
        _ => (
            KinematicType::M,
            [(tool[0], Side::Tool), (work[0], Side::Work)],
        ),
    })
}

/// Maps the description `m` with kinematic parameters `params` (mm, symbol order) onto a swivel
/// data record (see the module documentation).
///
/// # Errors
/// [`NotCovered`] when the machine does not have three linear axes each moving the tool point
/// relative to the table along one coordinate and two rotary axes about fixed lines, or when
/// the chain with the vectors found does not reproduce the description to
/// [`CHECK_TOLERANCE_MM`] at every check pose.
pub fn swivel_kinematics(m: &Machine, params: &[f64]) -> Result<SwivelKinematics, NotCovered> {
    let not_covered = |why: String| NotCovered {
        machine: m.name.clone(),
        why,
    };
    let (kind, roles) = roles(m).map_err(&not_covered)?;
    let chains = Chains {
        vm: VirtualMachine::new(m),
        params,
        zero: vec![0.0; m.axes.len()],
    };
    let zero = chains.zero.clone();
    let at_zero = chains.tool_in_table(&zero);
    let origin = chains.chain(Side::Tool, &zero).translation.vector;

    let mut linear: Vec<(usize, MachineAxis)> = Vec::new();
    for i in m.linear_axes() {
        let mut q = zero.clone();
        q[i] = 1.0;
        let s = chains.tool_in_table(&q) - at_zero;
        let k = s.iamax();
        let sign = s[k].signum();
        if (s - Vector3::ith(k, sign)).abs().max() > 1e-12 {
            return Err(not_covered(format!(
                "its axis {} moves the tool point relative to the table along ({:.6}, {:.6}, {:.6}), not along a coordinate direction",
                m.axes[i].name, s[0], s[1], s[2]
            )));
        }
        if linear.iter().any(|(c, _)| *c == k) {
            return Err(not_covered(
                "two of its linear axes move the tool point along the same coordinate".into(),
            ));
        }
        linear.push((
            k,
            MachineAxis {
                axis: i,
                axis_name: m.axes[i].name.clone(),
                name: format!("{}1", ['X', 'Y', 'Z'][k]),
                sign,
            },
        ));
    }
    linear.sort_by_key(|(k, _)| *k);
    let linear: Vec<MachineAxis> = linear.into_iter().map(|(_, a)| a).collect();

    let mut lines = Vec::new();
    for &(axis, side) in &roles {
        let line = chains.line(axis, side).ok_or_else(|| {
            not_covered(format!(
                "its axis {} does not turn about a fixed line by its command",
                m.axes[axis].name
            ))
        })?;
        lines.push(line);
    }
    let o = origin;
    let (c1, c2) = match kind {
        KinematicType::M => (
            nearest(&lines[0].0, &lines[0].1, &o),
            nearest(&lines[1].0, &lines[1].1, &o),
        ),
        _ => common_perpendicular(lines[0], lines[1], &o),
    };
    let zero3 = Vector3::zeros();
    let (l1, l2, l3, l4) = match kind {
        KinematicType::P => {
            let (l2, l3) = (clean_mm(c1 - o), clean_mm(c2 - c1));
            (zero3, l2, l3, clean_mm(-(l2 + l3)))
        }
        KinematicType::T => {
            let (l2, l3) = (clean_mm(c1 - c2), clean_mm(c2 - o));
            (clean_mm(-(l2 + l3)), l2, l3, zero3)
        }
        KinematicType::M => {
            let (l2, l3) = (clean_mm(c1 - o), clean_mm(c2 - o));
            (-l2, l2, l3, -l3)
        }
    };
    let data = SwivelData {
        kind,
        l1,
        l2,
        l3,
        l4,
        v1: clean_unit(lines[0].0),
        v2: clean_unit(lines[1].0),
    };
    let rotary = roles
        .iter()
        .map(|&(axis, _)| MachineAxis {
            axis,
            axis_name: m.axes[axis].name.clone(),
            name: format!("{}1", m.axes[axis].name),
            sign: 1.0,
        })
        .collect();
    let mut k = SwivelKinematics {
        data,
        linear,
        rotary,
        origin: o,
        check_mm: 0.0,
    };
    k.check_mm = check_poses(m)
        .iter()
        .map(|q| {
            let want = chains.tool_in_table(q) - o;
            (k.tool_in_table_at(q) - want).abs().max()
        })
        .fold(0.0, f64::max);
    if k.check_mm.is_nan() || k.check_mm > CHECK_TOLERANCE_MM {
        return Err(not_covered(format!(
            "the record's chain with the vectors found misses the description's tool point by {:.3e} mm at a check pose",
            k.check_mm
        )));
    }
    Ok(k)
}

impl SwivelKinematics {
    /// The machine axes' positions of the description's commands `q` (mm, rad): the linear
    /// machine axes (mm) and the two rotary axes' angles (degrees).
    pub fn machine_positions(&self, q: &[f64]) -> (Vector3<f64>, f64, f64) {
        let j = Vector3::from_iterator(self.linear.iter().map(|a| a.sign * q[a.axis]));
        (
            j,
            q[self.rotary[0].axis].to_degrees(),
            q[self.rotary[1].axis].to_degrees(),
        )
    }

    /// The record's chain at the description's commands `q` (mm, rad): the tool tip relative
    /// to the table, machine coordinates (mm).
    pub fn tool_in_table_at(&self, q: &[f64]) -> Vector3<f64> {
        let (j, a1, a2) = self.machine_positions(q);
        tool_in_table(&self.data, &j, a1, a2)
    }

    /// `X1 = -X, Y1 = Y, Z1 = Z, A1 = A, C1 = C`: each machine axis and the description's axis
    /// it is.
    pub fn axis_map(&self) -> String {
        self.linear
            .iter()
            .chain(&self.rotary)
            .map(|a| {
                format!(
                    "{} = {}{}",
                    a.name,
                    if a.sign < 0.0 { "-" } else { "" },
                    a.axis_name
                )
            })
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The machine axis of the description's axis `axis`.
    pub fn machine_axis(&self, axis: AxisId) -> Option<&MachineAxis> {
        self.linear
            .iter()
            .chain(&self.rotary)
            .find(|a| a.axis == axis)
    }
}
