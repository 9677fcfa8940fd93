//! Compensation: what was identified, put back onto the machine.
//!
//! - [`correct`]: the corrected pose of a commanded pose, through the generated compensation
//!   programs (the same instructions the `no_std` code runs);
//! - [`run`]: every pose of a file corrected, checked against strokes and ranges, summarised.

pub mod correct;
pub mod run;
