//! Compensation: putting what was measured or identified back onto the machine.

pub mod volumetric;
