//! Where the program comes from and goes to: the clearance height of the tool axis, the start
//! of the approach above the first pose and the end of the retract above the last one, along
//! the tool axis.
//!
//! The **tool axis** is the z axis of the tool frame, pointing from the nest towards the
//! spindle (`simulation::generator::clearance`). With the rotary axes fixed, the nest's
//! position relative to the ball is affine in the linear commands `q`: `A·q + b` (bed frame,
//! mm), so the linear commands that take the nest `d` mm away from the ball along the tool
//! axis `t` are `q + d·A⁻¹·t`. The columns of `A` come from the nominal chains at `q` and at
//! `q + 1 mm` on each linear axis.
//!
//! The **clearance axis** is the linear axis most nearly along the tool axis with every rotary
//! axis at 0 (the `Z` of ISO 841 on a machine whose spindle is vertical at 0°), and the
//! direction it moves to retract is the one that takes the nest away from the ball there. The
//! **clearance** is a position of that axis in machine coordinates: by default the end of its
//! stroke in that direction, as the machine description gives it.

use crate::measure::{MeasureError, MeasureOptions};
use model_spec::units::short;
use model_spec::{Machine, Side};
use simulation::exact::VirtualMachine;

/// The clearance and the approach and retract positions of a program (file units: mm and
/// degrees, one per axis in [`Machine::axes`] order).
pub(crate) struct Retreat {
    /// The clearance axis (an index into [`Machine::axes`]).
    pub(crate) axis: usize,
    /// Its clearance position, mm.
    pub(crate) clearance_mm: f64,
    /// The start of the approach: the first pose moved back along the tool axis.
    pub(crate) above_first: Vec<f64>,
    /// The end of the retract: the last pose moved back along the tool axis.
    pub(crate) above_last: Vec<f64>,
}

/// The nest's position relative to the ball, bed frame (mm), and the tool axis (unit vector)
/// at `q` (mm, rad) on the nominal machine.
fn gap_and_tool_axis(vm: &VirtualMachine, params: &[f64], q: &[f64]) -> ([f64; 3], [f64; 3]) {
    let tool = vm.nominal_chain_transform(Side::Tool, q, params);
    let work = vm.nominal_chain_transform(Side::Work, q, params);
    let g = tool.translation.vector - work.translation.vector;
    let z = tool.rotation.matrix().column(2).into_owned();
    ([g.x, g.y, g.z], [z.x, z.y, z.z])
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn det(c: &[[f64; 3]; 3]) -> f64 {
    dot(
        &c[0],
        &[
            c[1][1] * c[2][2] - c[1][2] * c[2][1],
            c[1][2] * c[2][0] - c[1][0] * c[2][2],
            c[1][0] * c[2][1] - c[1][1] * c[2][0],
        ],
    )
}

/// The three linear axes of a machine, the columns of `A` (mm per mm, bed frame) and the tool
/// axis (unit vector, bed frame) at a pose.
type Columns = ([usize; 3], [[f64; 3]; 3], [f64; 3]);

/// The linear axes of `m` (three, else an error), the columns of `A` at `q` (mm, rad) and the
/// tool axis there.
fn columns(
    m: &Machine,
    vm: &VirtualMachine,
    params: &[f64],
    q: &[f64],
) -> Result<Columns, MeasureError> {
    let linear: Vec<usize> = m.linear_axes().collect();
    let Ok(linear) = <[usize; 3]>::try_from(linear.as_slice()) else {
        return Err(MeasureError::Options(format!(
            "machine {} has {} linear axes: the approach along the tool axis needs three",
            m.name,
            linear.len()
        )));
    };
    let (g0, t) = gap_and_tool_axis(vm, params, q);
    let mut c = [[0.0; 3]; 3];
    for (k, &a) in linear.iter().enumerate() {
        let mut moved = q.to_vec();
        moved[a] += 1.0;
        let (g, _) = gap_and_tool_axis(vm, params, &moved);
        c[k] = [g[0] - g0[0], g[1] - g0[1], g[2] - g0[2]];
    }
    Ok((linear, c, t))
}

/// The change of the linear commands (mm per mm, one per axis, 0 for rotary axes) that moves
/// the nest along the tool axis, away from the ball, at `q` (mm, rad): `A⁻¹·t` by Cramer's
/// rule.
fn along_tool_axis(
    m: &Machine,
    vm: &VirtualMachine,
    params: &[f64],
    q: &[f64],
) -> Result<Vec<f64>, MeasureError> {
    let (linear, c, t) = columns(m, vm, params, q)?;
    let d = det(&c);
    if d.abs() < 1e-9 {
        return Err(MeasureError::Options(format!(
            "machine {}: the linear axes move the nest in coplanar directions, so no move along the tool axis exists",
            m.name
        )));
    }
    let mut step = vec![0.0; m.axes.len()];
    for k in 0..3 {
        let mut ck = c;
        ck[k] = t;
        step[linear[k]] = det(&ck) / d;
    }
    Ok(step)
}

/// `pose` (mm, degrees) moved `d` mm along the tool axis by `step` (mm per mm), the linear
/// axes only.
fn moved(pose: &[f64], step: &[f64], d: f64) -> Vec<f64> {
    pose.iter().zip(step).map(|(p, s)| p + d * s).collect()
}

/// The retreat of a program whose first and last poses are `first` and `last` (file units:
/// mm and degrees), for the options `o` (its clearance, approach distance, kinematic
/// parameters).
///
/// # Errors
/// [`MeasureError::Options`] for a machine without three linear axes, a clearance outside the
/// clearance axis's stroke or not beyond the approach's start, an approach that starts outside
/// the strokes.
pub(crate) fn retreat(
    m: &Machine,
    o: &MeasureOptions,
    first: &[f64],
    last: &[f64],
) -> Result<Retreat, MeasureError> {
    let vm = VirtualMachine::new(m);
    let params = &o.params;
    let internal = |p: &[f64]| formats::poses::from_file_units(m, p);
    // The clearance axis, at every rotary axis 0.
    let mut level = internal(first);
    for a in m.rotary_axes() {
        level[a] = 0.0;
    }
    let (linear, c, t) = columns(m, &vm, params, &level)?;
    let (k, along) = (0..3)
        .map(|k| (k, dot(&c[k], &t)))
        .max_by(|x, y| x.1.abs().total_cmp(&y.1.abs()))
        .unwrap_or((2, 1.0));
    let axis = linear[k];
    let ax = &m.axes[axis];
    let up = along >= 0.0;
    let [lo, hi] = ax.limits;
    let clearance_mm = match o.clearance_mm {
        Some(z) => z,
        None if up && hi.is_finite() => hi,
        None if !up && lo.is_finite() => lo,
        None => {
            return Err(MeasureError::Options(format!(
                "axis {} has no stroke end to retract to: give the clearance (rtest path --clearance-mm)",
                ax.name
            )));
        }
    };
    if !clearance_mm.is_finite() || clearance_mm < lo || clearance_mm > hi {
        return Err(MeasureError::Options(format!(
            "clearance {} {} mm: outside the stroke of axis {} ({} .. {} mm)",
            ax.name,
            short(clearance_mm),
            ax.name,
            short(lo),
            short(hi)
        )));
    }
    let step_first = along_tool_axis(m, &vm, params, &internal(first))?;
    let step_last = along_tool_axis(m, &vm, params, &internal(last))?;
    let above_first = moved(first, &step_first, o.approach_mm);
    let above_last = moved(last, &step_last, o.approach_mm);
    for (what, p) in [
        ("the approach starts", &above_first),
        ("the retract ends", &above_last),
    ] {
        let beyond = if up {
            clearance_mm >= p[axis]
        } else {
            clearance_mm <= p[axis]
        };
        if !beyond {
            return Err(MeasureError::Options(format!(
                "clearance {} {} mm: {what} at {} {} mm, beyond it: give a clearance farther from the ball (rtest path --clearance-mm) or a shorter approach (--approach-mm)",
                ax.name,
                short(clearance_mm),
                ax.name,
                short(p[axis])
            )));
        }
        let mut at_clearance = p.clone();
        at_clearance[axis] = clearance_mm;
        for q in [p, &at_clearance] {
            m.check_pose(&internal(q)).map_err(|e| {
                MeasureError::Options(format!(
                    "{what} outside the strokes ({} mm along the tool axis from the pose, the clearance {} {} mm): {e}; give a shorter approach (rtest path --approach-mm) or another clearance",
                    short(o.approach_mm),
                    ax.name,
                    short(clearance_mm)
                ))
            })?;
        }
    }
    Ok(Retreat {
        axis,
        clearance_mm,
        above_first,
        above_last,
    })
}
