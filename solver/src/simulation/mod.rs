//! The exact virtual machine and what it measures.
//!
//! - [`exact`]: chain transforms, the exact error vector (tool minus workpiece, tool frame),
//!   nominal tool-centre-point inverse kinematics;
//! - [`fd`]: error gains by central finite differences of [`exact`], the reference the
//!   symbolic engine is tested against;
//! - [`generator`]: the test catalogue of any machine and the generation of its tests within
//!   strokes, ranges and the clearance rule;
//! - [`paths`]: the built-in test paths and paths from files, the linear axes following the
//!   ball;
//! - [`truth`]: what a virtual machine's errors really are (TOML files and built-in truths);
//! - [`readings`]: simulated R-test readings of a truth along a path, with noise and zeroing;
//! - [`rng`]: the platform-independent noise generator;
//! - [`stream`]: a simulated R-test log of a measurement program's run, streamed row by row.

pub mod exact;
pub mod fd;
pub mod generator;
pub mod paths;
pub mod pose;
pub mod readings;
pub mod rng;
pub mod stream;
pub mod truth;

pub use exact::{
    ErrorVector, ExactError, Transform, VirtualMachine, chain_transform, error_vector,
    nominal_error_vector, tool_centre_point_ik,
};
pub use fd::{FdSteps, fd_gains, fd_gains_with};
pub use paths::{builtin_path, load_path};
pub use readings::{SimulateError, provenance, simulate};
pub use truth::{Truth, builtin_truth, load_truth};
