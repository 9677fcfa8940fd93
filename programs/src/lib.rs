//! Measurement programs and what comes back from running them.
//!
//! - [`measure`]: the NC program that takes the machine through an R-test's poses (ISO G-code,
//!   LinuxCNC or Heidenhain), with its timing plan;
//! - [`probe`]: the touch-probe calibration program that probes a sphere at every pose (ISO
//!   G-code, LinuxCNC or Heidenhain), its probe plan, and the control's log of the latched
//!   positions turned into probe hits;
//! - [`reader`]: the blocks of a program rtest wrote, read back in its dialect and sorted into
//!   the steps of its sequence (for the read-back and the tests);
//! - [`segment`]: a time-stamped R-test log of that program's run cut into one sample per
//!   pose of the timing plan;
//! - [`stream`]: a simulated R-test log of a measurement program's run, streamed row by row.
//!
//! It builds on [`simulation`] and [`formats`] (NC programs, the measurement CSV); nothing in
//! the fit, the diagnosis or the compensation depends on it.

#![warn(missing_docs)]

pub mod measure;
pub mod probe;
pub mod reader;
pub mod segment;
pub mod stream;
