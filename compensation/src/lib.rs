//! Compensation: what was identified, put back onto the machine.
//!
//! - [`values`]: the identified machine errors at any pose (what is left out, and why);
//! - [`correct`]: the corrected pose of a commanded pose, through the generated compensation
//!   programs (the same instructions the `no_std` code runs);
//! - [`run`]: every pose of a file corrected, checked against strokes and ranges, summarised;
//! - [`kinematics`]: the corrected kinematic description (location errors folded into the
//!   offsets);
//! - [`tables`]: axis compensation tables;
//! - [`controllers`]: what a controller's kinematics can hold of a description (LinuxCNC's
//!   `trt` modules);
//! - [`limits`]: the safety limits (words that cannot carry the correction, changes beyond a
//!   limit);
//! - [`confounded`]: whether the tool-side length can be told from what is compensated;
//! - [`verify`]: the machine's own error at poses of the exact virtual machine, before and
//!   after;
//! - [`volumetric`]: the three-axis scheme from 6D laser-interferometer measurements (the
//!   kinematic-parameter independent model and its volumetric grid).

#![warn(missing_docs)]

pub mod confounded;
pub mod controllers;
pub mod correct;
pub mod kinematics;
pub mod limits;
pub mod run;
pub mod tables;
pub mod values;
pub mod verify;
pub mod volumetric;
