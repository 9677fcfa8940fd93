//! Simulated sensor readings: what an R-test head would read on the exact virtual machine.
//!
//! 1. The error vector of every sample comes from [`crate::simulate`] with the
//!    truth, not zeroed: the exact machine, the truth's instrument terms `S` and offsets
//!    `dx0 dy0 dz0`, and the truth's noise (σ, φ per direction, from `Rng::new(seed)`), which
//!    is then the noise of the displacement itself (vibration, drift between nest and ball);
//! 2. for an instrument that reads in the machine frame the error vector is rotated into it by
//!    the nominal tool-chain rotation at the pose (default kinematic parameters, as the reader
//!    rotates back; the second-order difference from the actual rotation, the machine's
//!    angular errors times the displacement, is not simulated);
//! 3. each sensor's reading is the exact forward geometry ([`SensorHead::readings`]: gain,
//!    travel, zero) plus its own Gaussian noise of σ = its `noise_um`, independent between
//!    sensors and samples: standard normal draws of `Rng::new(seed ^ SENSOR_NOISE_STREAM)`, in
//!    sample order and sensor order;
//! 4. when the truth is zeroed, the first sample's readings are subtracted from every sample's
//!    (in sensor space, as R-test software zeroes), so that the first row is exactly zero.

use super::contact::ContactError;
use super::convert::{SensorRecord, nominal_tool_rotation};
use super::head::SensorHead;
use crate::exact::VirtualMachine;
use crate::readings::{SimulateError, simulate};
use crate::record::Record;
use crate::rng::Rng;
use crate::truth::Truth;
use model_spec::Machine;
use model_spec::instrument::{Instrument, ReadingsFrame};
use nalgebra::Vector3;

/// Mixed into the truth's seed for the sensors' noise, so that it is independent of the
/// displacement noise the truth's own seed gives (the fractional part of the golden ratio).
pub const SENSOR_NOISE_STREAM: u64 = 0x9e37_79b9_7f4a_7c15;

/// Why sensor readings could not be simulated.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SensorSimulationError {
    /// The simulation of the error vectors failed.
    #[error(transparent)]
    Simulate(#[from] SimulateError),
    /// A sensor cannot touch the ball at a sample's error vector.
    #[error("sample {}: {error}", sample + 1)]
    Contact {
        /// The sample (0-based).
        sample: usize,
        /// Why.
        error: ContactError,
    },
}

/// The readings `instrument` (displacements in `frame`) would give on the virtual machine `m`
/// with `truth` along `path` (see the module documentation): the path's samples and, per
/// sample, every sensor's reading (mm).
///
/// # Errors
/// As [`crate::simulate`]; [`SensorSimulationError::Contact`] when an error vector
/// takes the ball off a sensor.
pub fn simulate_sensors(
    m: &Machine,
    truth: &Truth,
    path: &Record,
    instrument: &Instrument,
    frame: ReadingsFrame,
) -> Result<SensorRecord, SensorSimulationError> {
    let mut displacement_truth = truth.clone();
    displacement_truth.zeroed = false;
    let vectors = simulate(m, &displacement_truth, path)?;
    let head = SensorHead::new(instrument);
    let vm = VirtualMachine::new(m);
    let params = m.default_parameters();
    let mut rng = Rng::new(truth.seed ^ SENSOR_NOISE_STREAM);
    let mut readings: Vec<Vec<f64>> = Vec::with_capacity(vectors.measured.len());
    for (i, e) in vectors.measured.iter().enumerate() {
        let mut e = Vector3::from(*e);
        if frame == ReadingsFrame::Machine {
            e = nominal_tool_rotation(&vm, &path.samples[i].commands, &params) * e;
        }
        let mut s = head
            .readings([e.x, e.y, e.z])
            .map_err(|error| SensorSimulationError::Contact { sample: i, error })?;
        for (v, sigma) in s.iter_mut().zip(&head.noise_mm) {
            *v += sigma * rng.normal();
        }
        readings.push(s);
    }
    if truth.zeroed
        && let Some(first) = readings.first().cloned()
    {
        for r in &mut readings {
            for (v, f) in r.iter_mut().zip(&first) {
                *v -= f;
            }
        }
    }
    Ok(SensorRecord {
        record: Record {
            samples: path.samples.clone(),
            lines: path.lines.clone(),
            ..Default::default()
        },
        readings,
    })
}
