//! The R-test instrument layer: sensor readings turned into error vectors, exactly
//! (`docs/instrument.md`).
//!
//! An instrument ([`model_spec::instrument::Instrument`]) is a precision ball and three or more
//! displacement sensors in the nest. This module gives its geometry numbers:
//!
//! - [`contact`]: one sensor's exact contact with the ball (flat face or ball tip): the plunger
//!   travel for a displacement, and its gradient;
//! - [`head`]: all sensors together, forward (displacement → readings) and inverse (readings →
//!   displacement by weighted Gauss–Newton, converged to 1e-13 mm) with the covariance of the
//!   result from the sensors' noise;
//! - [`convert`]: a record of sensor readings turned into a [`crate::record::Record`] of error
//!   vectors (tool frame) with per-sample covariances, zeroed readings and machine-frame
//!   instruments included;
//! - [`simulate`](mod@simulate): the readings a head would give on the exact virtual machine;
//! - [`CalibrationRecord`]: known displacements and the sensors' readings of them, which
//!   `fitting::calibrate` fits for the sensors' gain errors, zeros and direction
//!   errors.
//!
//! The error vector `e` is the tool point minus the workpiece point, the nest centre minus the
//! ball centre, in mm (`docs/conventions.md`); readings are in mm inside, µm in files.
//!
//! # Example: the exact inverse against the first-order one
//!
//! ```
//! use model_spec::instrument::preset;
//! use simulation::instrument::head::SensorHead;
//!
//! let head = SensorHead::new(&preset("inclined-45").unwrap().unwrap());
//! let e = [0.05, 0.0, 0.0]; // 50 µm along x
//! let s = head.readings(e).unwrap();
//! let exact = head.displacement(&s, false).unwrap();
//! assert!((exact.displacement[0] - 0.05).abs() < 1e-12);
//! // Ball tips: the first-order map misses the lateral term |e⊥|²/(2(R + r)).
//! let linear = head.first_order_displacement(&s).unwrap();
//! assert!((linear[2] - 0.0).abs() > 1e-5);
//! ```

pub mod contact;
pub mod convert;
pub mod head;
pub mod simulate;

pub use convert::{SensorRecord, to_record};
pub use head::{Inverse, InverseError, SensorHead};
pub use simulate::simulate_sensors;

/// A calibration record: known error vectors and the sensors' readings.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CalibrationRecord {
    /// The file it was read from (for messages), or empty.
    pub file: String,
    /// Per row, the known error vector (nest minus ball, nest frame), mm.
    pub displacements: Vec<[f64; 3]>,
    /// Per row, every sensor's reading in the instrument's order, mm.
    pub readings: Vec<Vec<f64>>,
    /// The 1-based line of each row in its file (empty when not read from a file).
    pub lines: Vec<usize>,
}
