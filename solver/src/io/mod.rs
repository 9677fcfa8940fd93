//! What rtest reads and writes for people and tools.
//!
//! - [`mod@campaign`]: the campaign file (records, set-ups, ball positions, zeroing, clock);
//! - [`csv`]: the R-test measurement CSV, read whole or in blocks, written so that it reads
//!   back bit for bit;
//! - [`nc`]: NC programs of commanded poses (ISO G-code, Heidenhain), read and written back;
//! - [`poses`]: commanded poses, their axis words and their CSV, read and written back;
//! - [`sensors`]: records of an R-test head's sensor readings, and calibration records;
//! - [`segment`]: a time-stamped R-test log cut into one sample per pose of a measurement
//!   program's timing plan;
//! - [`report`]: the reports (identification, validation, diagnosis, gain tables) as serde
//!   types, written as JSON; an identification read back;
//! - [`text`]: the same reports as text for people.

pub mod campaign;
pub mod csv;
pub mod nc;
pub mod poses;
pub mod progress;
pub mod report;
pub mod segment;
pub mod sensors;
pub mod text;
