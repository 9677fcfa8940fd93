//! The numeric side of rtest: the exact virtual machine of a [`model_spec::Machine`] (exact
//! homogeneous transforms, no linearisation) for simulation and checks, and numeric error gains
//! by finite differences of it, the reference the symbolic engine is tested against.
//!
//! Units inside: lengths and translational errors in mm, rotary commands and angular errors in
//! rad. Conversions to degrees, µm and µrad happen at the boundaries people see, not here.
//!
//! - [`exact`]: chain transforms, the exact error vector (tool minus workpiece, tool frame),
//!   nominal tool-centre-point inverse kinematics;
//! - [`fd`]: error gains by central finite differences of [`exact`].

#![warn(missing_docs)]

pub mod basis;
pub mod csvio;
pub mod csvread;
pub mod diagnose;
pub mod distributions;
pub mod estimate;
pub mod exact;
pub mod fd;
pub mod first_order;
pub mod hmatrix;
pub mod identifiability;
pub mod model;
pub mod paths;
pub mod perf;
pub mod record;
pub mod refine;
pub mod report;
pub mod rng;
pub mod simulate;
pub mod streaming;

pub mod truth;
pub mod validate;

pub use exact::{
    ErrorVector, ExactError, Transform, VirtualMachine, chain_transform, error_vector,
    nominal_error_vector, tool_centre_point_ik,
};
pub use fd::{FdSteps, fd_gains, fd_gains_with};
