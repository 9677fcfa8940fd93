//! The geometry of a pose: its nominal frame (`simulation::probe::PoseFrame`, the one the
//! simulation, the plans and the reading of probe records use: the nominal centre's commands,
//! the linear map from the linear commands to the tip's position relative to the sphere, the
//! tool axis, the table normal), the pattern turned into the bed frame at the pose
//! (`simulation::probe::PatternTurn`), and the points of a hit: pre-touch, contact, end of the
//! probing move, the point above at the safe height.
//!
//! With the rotary axes fixed, the tip centre's position relative to the sphere's centre is
//! affine in the linear commands `q`: `g₀ + A·(q − q₀)` (bed frame, mm), `q₀` the nominal
//! inverse kinematics' commands (the tip on the centre, `g₀ ≈ 0`), so a point `p` (bed frame,
//! from the centre) is commanded at `q₀ + A⁻¹·(p − g₀)`: on `seed-ac` X moves the table, so
//! its column is `(−1, 0, 0)` and a point on the +x side of the sphere is at a smaller X.

use super::{MAX_OBLIQUE_DEG, PatternHit, ProbeOptions};
use formats::nc::Dialect;
use formats::poses::{from_file_units, to_file_units};
use model_spec::Machine;
use model_spec::units::short;
use nalgebra::Vector3;
use simulation::exact::VirtualMachine;
use simulation::probe::{PatternTurn, PoseFrame};

/// The frame of one pose: the nominal frame every probe computation shares
/// ([`PoseFrame`]), and the nominal centre's commands as the program writes them.
pub(crate) struct Frame {
    /// The pose's nominal frame (commands in mm and rad).
    pub(crate) pose: PoseFrame,
    /// The commands with the tip on the sphere's centre (file units: mm, degrees; the rotary
    /// axes as written).
    pub(crate) centre: Vec<f64>,
}

impl Frame {
    /// The frame of the pose whose rotary axes are at `written` (file units: degrees; its
    /// linear entries are ignored), on machine `m` at the kinematic parameters `params`.
    ///
    /// # Errors
    /// Why the pose has no frame: not three linear axes (a message starting `machine `), the
    /// inverse kinematics.
    pub(crate) fn new(
        m: &Machine,
        vm: &VirtualMachine,
        params: &[f64],
        written: &[f64],
    ) -> Result<Frame, String> {
        let linear = m.linear_axes().count();
        if linear != 3 {
            return Err(format!(
                "machine {} has {linear} linear axes: probing a sphere needs three",
                m.name
            ));
        }
        let q = from_file_units(m, written);
        let pose = PoseFrame::at(vm, &q, params)
            .map_err(|e| format!("no nominal inverse kinematics: {e}"))?;
        let mut centre = to_file_units(m, &pose.commands);
        for a in m.rotary_axes() {
            centre[a] = written[a];
        }
        Ok(Frame { pose, centre })
    }

    /// The three linear axes (indices into [`Machine::axes`]), in the machine's order.
    pub(crate) fn linear(&self) -> [usize; 3] {
        self.pose.linear
    }

    /// The tool axis (unit, bed frame): from the tip towards the spindle.
    pub(crate) fn tool_axis(&self) -> Vector3<f64> {
        self.pose.tool_axis()
    }

    /// The commands (file units) that put the tip centre at `p` (bed frame, mm, from the
    /// sphere's centre): the centre's plus `A⁻¹·(p − g₀)` on the linear axes
    /// ([`PoseFrame::command_change`]).
    pub(crate) fn at(&self, p: &Vector3<f64>) -> Vec<f64> {
        let d = self.pose.command_change(&(p - self.pose.gap_mm));
        let mut q = self.centre.clone();
        for &axis in &self.pose.linear {
            q[axis] += d[axis];
        }
        q
    }

    /// The cosine between `v` (unit, bed frame) and the direction linear axis `k` (an index
    /// into [`Frame::linear`]) moves the tip in.
    pub(crate) fn axis_cos(&self, k: usize, v: &Vector3<f64>) -> f64 {
        self.pose.axis_direction(k).dot(v)
    }
}

/// The hit `hit` of the pattern (probe frame) turned into the bed frame by `turn`.
pub(crate) fn turned(turn: &PatternTurn, hit: &PatternHit) -> (Vector3<f64>, Vector3<f64>) {
    (
        turn.apply(&Vector3::from(hit.point)),
        turn.apply(&Vector3::from(hit.approach)),
    )
}

/// Where a hit is probed: points from the sphere's centre, bed frame, mm.
#[derive(Clone, Debug)]
pub(crate) struct HitPoints {
    /// The nominal tip centre at the contact: `R_eff` along the hit's point.
    pub(crate) contact: Vector3<f64>,
    /// The direction of the probing move (unit): the pattern's approach (ISO, LinuxCNC), or
    /// the machine axis nearest it (Heidenhain cycle 0).
    pub(crate) approach: Vector3<f64>,
    /// The probing move's start, `pretouch_mm` outside the sphere on the probing line.
    pub(crate) pre: Vector3<f64>,
    /// The probing move's end, `overtravel_mm` beyond the contact (G-code).
    pub(crate) end: Vector3<f64>,
    /// Above the pre-touch point along the tool axis, at the safe height.
    pub(crate) safe: Vector3<f64>,
    /// Heidenhain cycle 0: the probing axis (an index into [`Frame::linear`]) and whether it
    /// probes towards +.
    pub(crate) axis: Option<(usize, bool)>,
}

/// The points of the hit whose point and approach (unit, bed frame, at the pose) are `hit`, in
/// frame `f` under the options `o`.
///
/// # Errors
/// Why the hit cannot be probed at this pose: below the sphere's equator seen along the tool
/// axis (the stylus would meet the sphere), too near the stem, no machine axis within
/// [`MAX_OBLIQUE_DEG`] of its normal (Heidenhain).
pub(crate) fn hit_points(
    f: &Frame,
    hit: &(Vector3<f64>, Vector3<f64>),
    o: &ProbeOptions,
) -> Result<HitPoints, String> {
    let r = o.effective_radius_mm();
    let (p, hit_approach) = hit;
    let t = f.tool_axis();
    let described = format!(
        "the hit at ({}, {}, {}) from the centre (bed frame)",
        short(p.x),
        short(p.y),
        short(p.z)
    );
    if let Some(why) =
        simulation::probe::unreachable(p, &t, &f.pose.table_normal, o.stem_clearance_deg)
    {
        return Err(if why.contains("stem") {
            format!("{why} (rtest path --stem-clearance-deg)")
        } else {
            why
        });
    }
    let contact = p * r;
    // The start on the probing line along `u` at R_eff + pretouch from the centre: contact − λ·u
    // with λ² + 2λ·R·cosθ − (2·R·c + c²) = 0, cosθ = −p·u (λ = c for a radial approach).
    let pre_touch = |u: &Vector3<f64>| {
        let cos = -p.dot(u);
        let c = o.pretouch_mm;
        let lambda = -r * cos + (r * r * cos * cos + 2.0 * r * c + c * c).sqrt();
        contact - u * lambda
    };
    let (approach, axis, pre) = if o.dialect == Dialect::Heidenhain {
        // The machine axis nearest the normal (within MAX_OBLIQUE_DEG) from whose pre-touch
        // point the way up along the tool axis (the way down to it from the safe height)
        // keeps the tip centre at least half the pre-touch distance outside the sphere: on a
        // tilted head an equator hit probed along a machine axis starts a little below the
        // equator seen along the tool axis.
        let mut best: Option<(usize, f64, f64, Vector3<f64>)> = None;
        for k in 0..3 {
            let c = f.axis_cos(k, hit_approach);
            let u = f.pose.axis_direction(k) * c.signum();
            let pre = pre_touch(&u);
            let within = c.abs() >= MAX_OBLIQUE_DEG.to_radians().cos();
            if within
                && descent_clearance(&pre, &t) >= r + 0.5 * o.pretouch_mm
                && best.is_none_or(|(_, b, _, _)| c.abs() > b + 1e-9)
            {
                best = Some((k, c.abs(), c.signum(), pre));
            }
        }
        let Some((k, _, sign, pre)) = best else {
            return Err(format!(
                "{described}: no machine axis is within {MAX_OBLIQUE_DEG}° of its normal with a pre-touch point reached along the tool axis at least half the pre-touch distance outside the sphere, and touch probe cycle 0 probes along one axis"
            ));
        };
        (f.pose.axis_direction(k) * sign, Some((k, sign > 0.0)), pre)
    } else {
        (*hit_approach, None, pre_touch(hit_approach))
    };
    let end = contact + approach * o.overtravel_mm;
    let rise = r + o.safe_mm - pre.dot(&t);
    let safe = pre + t * rise;
    Ok(HitPoints {
        contact,
        approach,
        pre,
        end,
        safe,
        axis,
    })
}

/// The least distance from the sphere's centre of the line from `pre` (bed frame, mm, from the
/// centre) up along the tool axis `t` (unit): `|pre|` when `pre` is on the spindle's side of
/// the equator (`pre·t ≥ 0`), else the line's distance `√(|pre|² − (pre·t)²)`.
fn descent_clearance(pre: &Vector3<f64>, t: &Vector3<f64>) -> f64 {
    let along = pre.dot(t);
    if along >= 0.0 {
        pre.norm()
    } else {
        (pre.norm_squared() - along * along).max(0.0).sqrt()
    }
}
