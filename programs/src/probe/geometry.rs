//! The geometry of a pose: the nominal centre's commands, the linear map from the linear
//! commands to the tip's position relative to the sphere (bed frame), the tool axis and the
//! sphere's stem; and the points of a hit: pre-touch, contact, end of the probing move, the
//! point above at the safe height.
//!
//! With the rotary axes fixed, the tip centre's position relative to the sphere's centre is
//! affine in the linear commands `q`: `A·(q − q₀)` (bed frame, mm), `q₀` the nominal inverse
//! kinematics' commands (the tip on the centre). The columns of `A` come from the nominal
//! chains at `q₀` and at `q₀ + 1 mm` on each linear axis, so a point `p` (bed frame, from the
//! centre) is commanded at `q₀ + A⁻¹·p`: on `seed-ac` X moves the table, so its column is
//! `(−1, 0, 0)` and a point on the +x side of the sphere is at a smaller X.

use super::{MAX_OBLIQUE_DEG, PatternHit, ProbeOptions};
use formats::nc::Dialect;
use formats::poses::{from_file_units, to_file_units};
use model_spec::units::short;
use model_spec::{Machine, Side};
use simulation::exact::VirtualMachine;

/// A vector of the bed frame, mm or unit.
pub(crate) type V3 = [f64; 3];

pub(crate) fn dot(a: &V3, b: &V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: &V3, b: &V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn scale(a: &V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

pub(crate) fn add(a: &V3, b: &V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn norm(a: &V3) -> f64 {
    dot(a, a).sqrt()
}

/// The frame of one pose.
pub(crate) struct Frame {
    /// The three linear axes (indices into [`Machine::axes`]), in the machine's order.
    pub(crate) linear: [usize; 3],
    /// The commands with the tip on the sphere's centre (file units: mm, degrees; the rotary
    /// axes as written).
    pub(crate) centre: Vec<f64>,
    /// `A`: column `k` is the tip's motion relative to the sphere per mm of `linear[k]`.
    a: [V3; 3],
    /// `A⁻¹`, rows.
    inverse: [V3; 3],
    /// The tool axis (unit, bed frame): from the tip towards the spindle.
    pub(crate) tool_axis: V3,
    /// The sphere's stem (unit, bed frame): the table normal reversed.
    pub(crate) stem: V3,
}

/// The tip relative to the sphere (bed frame, mm), the tool axis and the table normal at `q`
/// (mm, rad) on the nominal machine.
fn chains(vm: &VirtualMachine, params: &[f64], q: &[f64]) -> (V3, V3, V3) {
    let tool = vm.nominal_chain_transform(Side::Tool, q, params);
    let work = vm.nominal_chain_transform(Side::Work, q, params);
    let g = tool.translation.vector - work.translation.vector;
    let t = tool.rotation.matrix().column(2).into_owned();
    let w = work.rotation.matrix().column(2).into_owned();
    ([g.x, g.y, g.z], [t.x, t.y, t.z], [w.x, w.y, w.z])
}

impl Frame {
    /// The frame of the pose whose rotary axes are at `written` (file units: degrees; its
    /// linear entries are ignored), on machine `m` at the kinematic parameters `params`.
    ///
    /// # Errors
    /// Why the pose has no frame: not three linear axes, the inverse kinematics.
    pub(crate) fn new(
        m: &Machine,
        vm: &VirtualMachine,
        params: &[f64],
        written: &[f64],
    ) -> Result<Frame, String> {
        let linear: Vec<usize> = m.linear_axes().collect();
        let Ok(linear) = <[usize; 3]>::try_from(linear.as_slice()) else {
            return Err(format!(
                "machine {} has {} linear axes: probing a sphere needs three",
                m.name,
                linear.len()
            ));
        };
        let mut q = from_file_units(m, written);
        for &a in &linear {
            q[a] = 0.0;
        }
        simulation::exact::tool_centre_point_ik(m, &mut q, params)
            .map_err(|e| format!("no nominal inverse kinematics: {e}"))?;
        let (g0, t, w) = chains(vm, params, &q);
        let mut a = [[0.0; 3]; 3];
        for (k, &axis) in linear.iter().enumerate() {
            let mut moved = q.clone();
            moved[axis] += 1.0;
            let (g, _, _) = chains(vm, params, &moved);
            a[k] = [g[0] - g0[0], g[1] - g0[1], g[2] - g0[2]];
        }
        let det = dot(&a[0], &cross(&a[1], &a[2]));
        if det.abs() < 1e-9 {
            return Err(
                "the linear axes move the tip in coplanar directions: no point of the sphere can be commanded"
                    .into(),
            );
        }
        // Rows of A⁻¹ for A with columns a0, a1, a2: (a1×a2, a2×a0, a0×a1)/det.
        let inverse = [
            scale(&cross(&a[1], &a[2]), 1.0 / det),
            scale(&cross(&a[2], &a[0]), 1.0 / det),
            scale(&cross(&a[0], &a[1]), 1.0 / det),
        ];
        let mut centre = to_file_units(m, &q);
        for a in m.rotary_axes() {
            centre[a] = written[a];
        }
        Ok(Frame {
            linear,
            centre,
            a,
            inverse,
            tool_axis: t,
            stem: scale(&w, -1.0),
        })
    }

    /// The commands (file units) that put the tip centre at `p` (bed frame, mm, from the
    /// sphere's centre): the centre's plus `A⁻¹·p` on the linear axes.
    pub(crate) fn at(&self, p: &V3) -> Vec<f64> {
        let mut q = self.centre.clone();
        for (k, &axis) in self.linear.iter().enumerate() {
            q[axis] += dot(&self.inverse[k], p);
        }
        q
    }

    /// The cosine between `v` (unit, bed frame) and the direction linear axis `k` (an index
    /// into [`Frame::linear`]) moves the tip in.
    pub(crate) fn axis_cos(&self, k: usize, v: &V3) -> f64 {
        dot(&self.axis_direction(k), v)
    }

    /// The direction (unit, bed frame) the tip moves relative to the sphere when linear axis
    /// `k` (an index into [`Frame::linear`]) moves in its + direction.
    fn axis_direction(&self, k: usize) -> V3 {
        scale(&self.a[k], 1.0 / norm(&self.a[k]))
    }
}

/// Where a hit is probed: points from the sphere's centre, bed frame, mm.
#[derive(Clone, Debug)]
pub(crate) struct HitPoints {
    /// The nominal tip centre at the contact: `R_eff` along the hit's point.
    pub(crate) contact: V3,
    /// The direction of the probing move (unit): the pattern's approach (ISO, LinuxCNC), or
    /// the machine axis nearest it (Heidenhain cycle 0).
    pub(crate) approach: V3,
    /// The probing move's start, `pretouch_mm` outside the sphere on the probing line.
    pub(crate) pre: V3,
    /// The probing move's end, `overtravel_mm` beyond the contact (G-code).
    pub(crate) end: V3,
    /// Above the pre-touch point along the tool axis, at the safe height.
    pub(crate) safe: V3,
    /// Heidenhain cycle 0: the probing axis (an index into [`Frame::linear`]) and whether it
    /// probes towards +.
    pub(crate) axis: Option<(usize, bool)>,
}

/// The points of hit `hit` in frame `f` under the options `o`.
///
/// # Errors
/// Why the hit cannot be probed at this pose: below the sphere's equator seen along the tool
/// axis (the stylus would meet the sphere), too near the stem, no machine axis within
/// [`MAX_OBLIQUE_DEG`] of its normal (Heidenhain).
pub(crate) fn hit_points(
    f: &Frame,
    hit: &PatternHit,
    o: &ProbeOptions,
) -> Result<HitPoints, String> {
    let r = o.effective_radius_mm();
    let p = hit.point;
    let t = f.tool_axis;
    let described = format!(
        "the hit at ({}, {}, {}) from the centre (bed frame)",
        short(p[0]),
        short(p[1]),
        short(p[2])
    );
    let v = |x: &V3| nalgebra::Vector3::new(x[0], x[1], x[2]);
    if let Some(why) = simulation::probe::unreachable(
        &v(&p),
        &v(&t),
        &v(&scale(&f.stem, -1.0)),
        o.stem_clearance_deg,
    ) {
        return Err(if why.contains("stem") {
            format!("{why} (rtest path --stem-clearance-deg)")
        } else {
            why
        });
    }
    let (approach, axis) = if o.dialect == Dialect::Heidenhain {
        let mut best: Option<(usize, f64, f64)> = None;
        for k in 0..3 {
            let c = dot(&f.axis_direction(k), &hit.approach);
            if best.is_none_or(|(_, b, _)| c.abs() > b + 1e-9) {
                best = Some((k, c.abs(), c.signum()));
            }
        }
        let (k, cos, sign) = best.unwrap_or((0, 0.0, 1.0));
        if cos < MAX_OBLIQUE_DEG.to_radians().cos() {
            return Err(format!(
                "{described}: no machine axis is within {MAX_OBLIQUE_DEG}° of its normal, and touch probe cycle 0 probes along one axis"
            ));
        }
        (scale(&f.axis_direction(k), sign), Some((k, sign > 0.0)))
    } else {
        (hit.approach, None)
    };
    let contact = scale(&p, r);
    // The start on the probing line at R_eff + pretouch from the centre: contact − λ·u with
    // λ² + 2λ·R·cosθ − (2·R·c + c²) = 0, cosθ = −p·u (λ = c for a radial approach).
    let cos = -dot(&p, &approach);
    let c = o.pretouch_mm;
    let lambda = -r * cos + (r * r * cos * cos + 2.0 * r * c + c * c).sqrt();
    let pre = add(&contact, &scale(&approach, -lambda));
    let end = add(&contact, &scale(&approach, o.overtravel_mm));
    let rise = r + o.safe_mm - dot(&pre, &t);
    let safe = add(&pre, &scale(&t, rise));
    Ok(HitPoints {
        contact,
        approach,
        pre,
        end,
        safe,
        axis,
    })
}
