//! What rtest reads and writes for people and tools.
//!
//! - [`csv`]: the R-test measurement CSV, read whole or in blocks, written so that it reads
//!   back bit for bit;
//! - [`report`]: the reports (identification, validation, diagnosis, gain tables) as serde
//!   types, written as JSON; an identification read back;
//! - [`text`]: the same reports as text for people.

pub mod csv;
pub mod report;
pub mod text;
