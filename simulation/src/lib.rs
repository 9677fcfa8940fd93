//! The machine as rtest simulates it: the model a fit has, the record it is fitted on, the
//! instrument that reads it, and the exact virtual machine that produces both.
//!
//! The bottom of rtest's numeric layers: it depends only on the machine description
//! ([`model_spec`]); the crates of files (`formats`), fitting, diagnosis and compensation
//! build on it (`docs/architecture.md`).
//!
//! - [`model`]: the terms a fit has (errors, their bases, the R-test's offsets);
//! - [`record`]: samples along a path (commands, times, directions of motion) with readings;
//! - [`campaign`]: several records, each with its own set-up, measured on one machine;
//! - [`instrument`]: the R-test head's geometry, sensor readings turned into error vectors;
//! - [`exact`]: chain transforms, the exact error vector (tool minus workpiece, tool frame),
//!   nominal tool-centre-point inverse kinematics;
//! - [`fd`]: error gains by central finite differences of [`exact`], the reference the
//!   symbolic engine is tested against;
//! - [`generator`]: the test catalogue of any machine and the generation of its tests within
//!   strokes, ranges and the clearance rule;
//! - [`paths`]: the built-in test paths, the linear axes following the ball;
//! - [`truth`]: what a virtual machine's errors really are (read from TOML files by `formats`);
//! - [`readings`]: simulated R-test readings of a truth along a path, with noise and zeroing;
//! - [`probe`]: simulated touch-probe hits on a calibration sphere, exact contacts;
//! - [`rng`]: the platform-independent noise generator;
//! - [`pose`]: one pose from the axis positions a person gives, checked against the machine.
//!
//! Units inside: lengths and translational errors in mm, rotary commands and angular errors in
//! rad. Conversions to degrees, µm and µrad happen at the boundaries people see
//! ([`model_spec::units`]), not here.

#![warn(missing_docs)]

pub mod campaign;
pub mod instrument;
pub mod model;
pub mod record;

pub mod exact;
pub mod fd;
pub mod generator;
pub mod paths;
pub mod pose;
pub mod probe;
pub mod readings;
pub mod rng;
pub mod truth;

pub use exact::{
    ErrorVector, ExactError, Transform, VirtualMachine, chain_transform, error_vector,
    nominal_error_vector, tool_centre_point_ik,
};
pub use fd::{FdSteps, fd_gains, fd_gains_with};
pub use paths::builtin_path;
pub use readings::{SimulateError, provenance, simulate};
pub use truth::Truth;
