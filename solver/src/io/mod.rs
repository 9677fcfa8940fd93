//! What rtest reads and writes for people and tools.
//!
//! - [`csv`]: the R-test measurement CSV, read whole or in blocks, written so that it reads
//!   back bit for bit;
//! - [`json`]: the JSON reports (identification, validation) as serde types, and the reading
//!   of an identification back into model values.

pub mod csv;
pub mod json;
