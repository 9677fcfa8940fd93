//! What rtest reads and writes for people and tools.
//!
//! - [`mod@campaign`]: the campaign file (records, set-ups, ball positions, zeroing, clock);
//! - [`csv`]: the R-test measurement CSV, read whole or in blocks, written so that it reads
//!   back bit for bit;
//! - [`nc`]: NC programs of commanded poses (ISO G-code, Heidenhain), read and written back;
//! - [`poses`]: commanded poses, their axis words and their CSV, read and written back;
//! - [`report`]: the reports (identification, validation, diagnosis, gain tables) as serde
//!   types, written as JSON; an identification read back;
//! - [`text`]: the same reports as text for people.

pub mod campaign;
pub mod csv;
pub mod nc;
pub mod poses;
pub mod report;
pub mod text;
