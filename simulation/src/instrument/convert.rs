//! Sensor records turned into records of error vectors: per sample, the exact inverse of the
//! head ([`SensorHead::displacement`]), the rotation into the tool frame when the instrument
//! reads in the machine frame, and the covariance of the result.
//!
//! **Zeroed readings.** When the first sample reads exactly zero on every sensor (and there are
//! others), the readings were zeroed at the first pose, as R-test software does: the zeroing is
//! in sensor space and took the place of the sensors' zeros, so the zeros of the description are
//! not subtracted and the first pose is taken as the zero position (its error vector is then
//! exactly zero, and the record reads zeroed: `--zeroed` applies). For flat tips this is exact:
//! the readings are linear, and a zeroing in sensor space is one in displacement space. For ball
//! tips it is exact to first order only: per sensor the neglected term is
//! `e₀⊥·(e − e₀)⊥/(R + r)` (`e₀` the error vector at the first pose, `⊥` across the sensor's
//! axis), up to twice `|e₀|·|e − e₀|/(R + r)` in the error vector with three sensors at 45°.
//! Measured on `seed-ac`'s K4 with the demo truth (`|e₀|` = 35 µm, `|e − e₀|` up to 70 µm,
//! `inclined-45`): 0.17 µm at most. Zero the head with the ball centred, or keep the readings
//! absolute (with calibrated zeros), when that matters.
//!
//! **Frames.** With [`ReadingsFrame::Machine`] the head's displacement is in the machine (bed)
//! frame; it is rotated into the tool frame by the nominal tool-chain rotation at the sample's
//! pose, `e_tool = R₀ᵀ·e_machine`, `Σ_tool = R₀ᵀ·Σ·R₀` (the machine's default kinematic
//! parameters: what the controller believes).

use super::head::{InverseError, SensorHead};
use crate::exact::VirtualMachine;
use crate::record::Record;
use model_spec::instrument::ReadingsFrame;
use model_spec::{Machine, Side};
use nalgebra::{Matrix3, Vector3};

/// A record of sensor readings: the samples (commands, times, directions of motion, lines)
/// and, per sample, one reading per sensor (mm, zeros included unless zeroed).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SensorRecord {
    /// The samples; `measured` and `covariance` empty.
    pub record: Record,
    /// Per sample, the reading of every sensor in the instrument's order, mm.
    pub readings: Vec<Vec<f64>>,
}

impl SensorRecord {
    /// `true` when the first sample reads exactly zero on every sensor and there are others:
    /// the readings were zeroed at the first pose.
    pub fn looks_zeroed(&self) -> bool {
        self.readings.len() > 1
            && self
                .readings
                .first()
                .is_some_and(|r| r.iter().all(|&v| v == 0.0))
    }
}

/// A sample whose readings give no error vector.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{error}")]
pub struct ConvertError {
    /// The sample (0-based).
    pub sample: usize,
    /// Why.
    pub error: InverseError,
}

/// The rotation of `m`'s nominal tool chain at `commands` (mm, rad) with `params` (mm): it maps
/// tool-frame vectors to the machine frame.
pub fn nominal_tool_rotation(
    vm: &VirtualMachine,
    commands: &[f64],
    params: &[f64],
) -> Matrix3<f64> {
    *vm.nominal_chain_transform(Side::Tool, commands, params)
        .rotation
        .matrix()
}

/// The record of error vectors (tool frame, mm) and their covariances (mm²) that the sensor
/// record `sensors` of machine `m` gives through `head`, whose displacements are in `frame`
/// (see the module documentation).
///
/// # Errors
/// [`ConvertError`] naming the first sample whose readings give no error vector.
pub fn to_record(
    head: &SensorHead,
    m: &Machine,
    frame: ReadingsFrame,
    sensors: &SensorRecord,
) -> Result<Record, ConvertError> {
    let zeroed = sensors.looks_zeroed();
    let vm = VirtualMachine::new(m);
    let params = m.default_parameters();
    let n = sensors.readings.len();
    let mut measured = Vec::with_capacity(n);
    let mut covariance = Vec::with_capacity(n);
    for (i, r) in sensors.readings.iter().enumerate() {
        let inv = head
            .displacement(r, zeroed)
            .map_err(|error| ConvertError { sample: i, error })?;
        let (mut e, mut c) = (
            Vector3::from(inv.displacement),
            Matrix3::from_fn(|a, b| inv.covariance[a][b]),
        );
        if frame == ReadingsFrame::Machine {
            let commands = &sensors.record.samples[i].commands;
            let r0 = nominal_tool_rotation(&vm, commands, &params);
            e = r0.transpose() * e;
            c = r0.transpose() * c * r0;
        }
        measured.push([e.x, e.y, e.z]);
        covariance.push([
            [c[(0, 0)], c[(0, 1)], c[(0, 2)]],
            [c[(1, 0)], c[(1, 1)], c[(1, 2)]],
            [c[(2, 0)], c[(2, 1)], c[(2, 2)]],
        ]);
    }
    Ok(Record {
        measured,
        covariance,
        ..sensors.record.clone()
    })
}
