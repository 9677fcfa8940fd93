//! The laser measurements taken on the exact virtual machine
//! ([`simulation::exact`]) with the position-dependent errors of a truth, as the seed's
//! three-axis paper takes them: the reflector at the tool end, one axis moving at a time, the
//! other axes standing at their measurement positions; and the exact tool-end error in the
//! model's frame, to check the model against.
//!
//! - **Translations:** the tool point's exact position minus its nominal one (bed frame, the
//!   machine's real kinematic parameters), minus the same at the first position: the laser is
//!   zeroed where the run starts. The straightness is left with whatever slope the machine
//!   gives it (the laser's alignment): the model takes the least-squares line out.
//! - **Rotations:** the rotation vector of `R(q)·R(q_first)ᵀ`, `R` the exact rotation of the
//!   tool frame: the change of the reflector's orientation since the first position.
//! - **Squareness:** the angles between the least-squares lines of the three measured tool-point
//!   trajectories, in the machine's squareness errors (ISO 230-1): with the frame's rotation
//!   `ω`, the six straightness slopes are `ω × n_k` plus the squareness errors' share, solved
//!   for both.
//!
//! Every error of the truth is evaluated at the pose (commands of every axis, each moving in
//! the + direction); terms that need sample times (`velocity`, `exp:TAU`) are refused.

use super::laser::{AxisMeasurement, column_axes};
use super::squareness::{Squareness, squareness_errors};
use super::table::Table;
use super::{MAX_ANGLE_RAD, MAX_TRANSLATION_MM, VolumetricError};
use model_spec::{AxisId, AxisKind, ErrorKind, Machine, Side};
use nalgebra::{Matrix6, Rotation3, Vector3, Vector6};
use simulation::exact::VirtualMachine;
use simulation::model::BasisContext;
use simulation::truth::Truth;

/// One planned laser measurement: the axis, its positions and where the others stand.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedAxis {
    /// The measured axis ([`Machine::axes`] index).
    pub axis: AxisId,
    /// Its positions, mm, strictly increasing.
    pub positions: Vec<f64>,
    /// The commands of every axis ([`Machine::axes`] order, mm); the measured axis's entry is
    /// replaced by each position.
    pub pose: Vec<f64>,
}

/// The three laser measurements to take, and the reference point.
#[derive(Clone, Debug, PartialEq)]
pub struct LaserPlan {
    /// One per linear axis.
    pub axes: Vec<PlannedAxis>,
    /// The reference point ([`Machine::axes`] order, mm): the zero of the model's frame.
    pub reference: Vec<f64>,
}

impl LaserPlan {
    /// Every linear axis of `m` measured at `points` evenly spaced positions over its whole
    /// stroke (to the nanometre), the other axes at 0 (or the nearest end of a stroke that
    /// excludes 0); the reference point there too.
    ///
    /// # Errors
    /// [`VolumetricError::Setup`] for fewer than two points.
    pub fn over_strokes(m: &Machine, points: usize) -> Result<LaserPlan, VolumetricError> {
        if points < 2 {
            return Err(VolumetricError::Setup(format!(
                "a laser measurement needs at least two positions, not {points}"
            )));
        }
        let home: Vec<f64> = m
            .axes
            .iter()
            .map(|a| 0f64.clamp(a.limits[0], a.limits[1]))
            .collect();
        let axes = column_axes(m)
            .into_iter()
            .map(|a| {
                let [lo, hi] = m.axes[a].limits;
                let step = (hi - lo) / (points - 1) as f64;
                let positions = (0..points)
                    .map(|i| {
                        if i + 1 == points {
                            hi
                        } else {
                            ((lo + i as f64 * step) * 1e6).round() / 1e6
                        }
                    })
                    .collect();
                PlannedAxis {
                    axis: a,
                    positions,
                    pose: home.clone(),
                }
            })
            .collect();
        Ok(LaserPlan {
            axes,
            reference: home,
        })
    }
}

/// The frame the model's `du` is expressed in, and the exact tool-end error in it.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelFrame {
    /// The small rotation from the bed frame to the model's frame, rad.
    pub rotation: Vector3<f64>,
    /// The reference point ([`Machine::axes`] order, mm).
    pub reference: Vec<f64>,
    /// The signed unit direction of every axis ([`Machine::axes`] order; zero for a rotary
    /// axis).
    directions: Vec<Vector3<f64>>,
}

/// What the simulated laser and squareness measurements give.
#[derive(Clone, Debug, PartialEq)]
pub struct SimulatedLaser {
    /// One laser measurement per planned axis.
    pub measurements: Vec<AxisMeasurement>,
    /// The squareness errors (the angles between the measured lines) and the reference point.
    pub squareness: Squareness,
    /// The model's frame.
    pub frame: ModelFrame,
}

/// The exact tool point's error (actual minus nominal, bed frame, mm) and the exact rotation
/// of the tool frame at `commands` ([`Machine::axes`] order, mm and rad), with the truth's
/// errors and kinematic parameters.
pub fn exact_tool(
    vm: &VirtualMachine<'_>,
    truth: &Truth,
    commands: &[f64],
) -> (Vector3<f64>, Rotation3<f64>) {
    let m = vm.machine();
    let motion = vec![1i8; m.axes.len()];
    let cx = BasisContext {
        commands,
        motion: &motion,
        tau: 0.0,
        elapsed_s: 0.0,
        since_start_s: 0.0,
        velocity: &[],
        reading: [0.0; 3],
    };
    let errors = truth.error_values(m, &cx);
    let actual = vm.chain_transform(Side::Tool, commands, &truth.params, &errors);
    let nominal = vm.nominal_chain_transform(Side::Tool, commands, &truth.params);
    (
        actual.translation.vector - nominal.translation.vector,
        actual.rotation,
    )
}

impl ModelFrame {
    /// The exact tool-end error at `commands` ([`Machine::axes`] order, mm) in the model's
    /// frame: zero at the reference point, rotated by [`ModelFrame::rotation`], mm.
    pub fn error(&self, vm: &VirtualMachine<'_>, truth: &Truth, commands: &[f64]) -> Vector3<f64> {
        let (d, _) = exact_tool(vm, truth, commands);
        let (d0, _) = exact_tool(vm, truth, &self.reference);
        let moved: Vector3<f64> = self
            .directions
            .iter()
            .zip(commands.iter().zip(&self.reference))
            .map(|(n, (q, q0))| n * (q - q0))
            .sum();
        d - d0 - self.rotation.cross(&moved)
    }
}

fn unit(d: model_spec::Dir) -> Vector3<f64> {
    let mut v = Vector3::zeros();
    v[d.index()] = 1.0;
    v
}

/// Takes the laser measurements of `plan` on the exact virtual machine of `m` with `truth`,
/// and the squareness measurement.
///
/// # Errors
/// [`VolumetricError::Setup`] when the truth needs sample times, a planned axis is not linear
/// or its positions do not increase strictly, or the squareness cannot be told from the
/// measured lines (three linear axes along three different directions are needed);
/// [`VolumetricError::Computation`] when a measured value is beyond ±1000 µm or ±10 000 µrad.
pub fn measure(
    m: &Machine,
    truth: &Truth,
    plan: &LaserPlan,
) -> Result<SimulatedLaser, VolumetricError> {
    if truth.needs_times() {
        return Err(VolumetricError::Setup(format!(
            "truth {}: the laser simulation evaluates position-dependent errors only; `velocity` and `exp:TAU` terms need sample times",
            truth.source
        )));
    }
    let vm = VirtualMachine::new(m);
    let directions: Vec<Vector3<f64>> = m
        .axes
        .iter()
        .map(|a| match a.kind {
            AxisKind::Linear => Vector3::from(a.direction.unit()),
            AxisKind::Rotary => Vector3::zeros(),
        })
        .collect();
    let mut measurements = Vec::new();
    for p in &plan.axes {
        let a = &m.axes[p.axis];
        if a.kind != AxisKind::Linear
            || p.positions.len() < 2
            || p.positions.windows(2).any(|w| w[0] >= w[1])
        {
            return Err(VolumetricError::Setup(format!(
                "the planned measurement of axis {} needs a linear axis and at least two strictly increasing positions",
                a.name
            )));
        }
        let at = |q: f64| {
            let mut pose = p.pose.clone();
            pose[p.axis] = q;
            exact_tool(&vm, truth, &pose)
        };
        let (d0, r0) = at(p.positions[0]);
        let mut x = AxisMeasurement {
            source: format!("<simulated laser, axis {}>", a.name),
            axis: p.axis,
            pose: p.pose.clone(),
            positions: p.positions.clone(),
            translations: Vec::new(),
            rotations: Vec::new(),
        };
        x.pose[p.axis] = p.positions[0];
        for &q in &p.positions {
            let (d, r) = at(q);
            let t = d - d0;
            let w = (r * r0.inverse()).scaled_axis();
            if t.amax() > MAX_TRANSLATION_MM
                || w.amax() > MAX_ANGLE_RAD
                || !t.iter().chain(w.iter()).all(|v| v.is_finite())
            {
                return Err(VolumetricError::Computation(format!(
                    "the simulated laser measurement of axis {} at {q} mm reads ({}, {}, {}) µm and ({}, {}, {}) µrad, beyond ±1000 µm or ±10000 µrad",
                    a.name,
                    t.x * 1e3,
                    t.y * 1e3,
                    t.z * 1e3,
                    w.x * 1e6,
                    w.y * 1e6,
                    w.z * 1e6
                )));
            }
            x.translations.push([t.x, t.y, t.z]);
            x.rotations.push([w.x, w.y, w.z]);
        }
        measurements.push(x);
    }
    let (values, rotation) = squareness_of_lines(m, &measurements, &directions)?;
    let mut squareness = Squareness::new(m, "<simulated squareness>", &values);
    squareness.reference = plan.reference.clone();
    Ok(SimulatedLaser {
        measurements,
        squareness,
        frame: ModelFrame {
            rotation,
            reference: plan.reference.clone(),
            directions,
        },
    })
}

/// The squareness errors of `m` (catalogue order, rad) and the rotation of the model's frame
/// (rad) that explain the slopes of the measured straightness.
fn squareness_of_lines(
    m: &Machine,
    measurements: &[AxisMeasurement],
    directions: &[Vector3<f64>],
) -> Result<(Vec<f64>, Vector3<f64>), VolumetricError> {
    let chain: Vec<AxisId> = m.tool.axes().collect();
    let sq = squareness_errors(m);
    let cannot = || {
        VolumetricError::Setup(format!(
            "machine `{}`: the squareness cannot be told from the laser measurements: the model needs three linear axes carrying the tool along three different directions, each measured once",
            m.name
        ))
    };
    if measurements.len() != 3 || sq.len() != 3 || chain.len() != 3 {
        return Err(cannot());
    }
    let depth = |a: AxisId| chain.iter().position(|&c| c == a);
    let mut a = Matrix6::zeros();
    let mut b = Vector6::zeros();
    let mut row = 0;
    for x in measurements {
        let k = depth(x.axis).ok_or_else(cannot)?;
        let n = directions[x.axis];
        // The volumetric machines' linear axes are along coordinate directions.
        let along = m.axes[x.axis].direction.own.dir.index();
        for d in (0..3).filter(|&d| d != along) {
            let t = Table::new(
                x.positions.clone(),
                x.translations.iter().map(|v| v[d]).collect(),
            );
            b[row] = t.least_squares_line().1;
            for i in 0..3 {
                let mut e = Vector3::zeros();
                e[i] = 1.0;
                a[(row, i)] = e.cross(&n)[d];
            }
            for (j, &s) in sq.iter().enumerate() {
                if let ErrorKind::Squareness { axis, about } = m.catalogue[s].kind
                    && depth(axis).is_some_and(|c| c <= k)
                {
                    a[(row, 3 + j)] = unit(about).cross(&n)[d];
                }
            }
            row += 1;
        }
    }
    let x = a.lu().solve(&b).ok_or_else(cannot)?;
    if !x.iter().all(|v| v.is_finite()) {
        return Err(cannot());
    }
    Ok((vec![x[3], x[4], x[5]], Vector3::new(x[0], x[1], x[2])))
}
