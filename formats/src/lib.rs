//! The files rtest exchanges with people, instruments and controllers, read and written.
//!
//! Every reader bounds what it reads (bytes, lines, rows), refuses bad input with the file,
//! line, column and field, and never returns a partial result; every writer writes what its
//! reader reads back, bit for bit. The TOML files (truths, campaigns, and the squareness and
//! tolerance files of the crates above) are read through one helper, [`located`], so their
//! messages are located and worded alike.
//!
//! - [`mod@campaign`]: the campaign file (records, set-ups, ball positions, zeroing, clock);
//! - [`controllers`]: the files a controller loads (LinuxCNC's HAL pins and joint
//!   compensation files);
//! - [`csv`]: the R-test measurement CSV, read whole or in blocks, written so that it reads
//!   back bit for bit;
//! - [`paths`]: path files (the commanded samples of a test), or a built-in test by name;
//! - [`nc`]: NC programs of commanded poses (ISO G-code, Heidenhain), read and written back;
//! - [`poses`]: commanded poses, their axis words and their CSV, read and written back;
//! - [`probe`]: the files of a touch-probe calibration (probe hits, sphere centres, the probe
//!   instrument), read and written back bit for bit;
//! - [`sensors`]: records of an R-test head's sensor readings, and calibration records;
//! - [`progress`]: how far a long read has come, for progress bars;
//! - [`time`]: UTC times as files write them (RFC 3339, whole seconds);
//! - [`tolerance`]: the tolerance file of the R-test checks (per test and direction, the
//!   largest deviation and range in µm, ISO 10791-6 style);
//! - [`truth`]: truth files (what a simulated machine's errors really are) and the built-in
//!   truths.
//!
//! It builds on [`simulation`] (a record's linear axes follow the ball by the nominal inverse
//! kinematics, and every pose read is checked against the machine) and imports nothing from
//! the fit, the diagnosis or the compensation.

#![warn(missing_docs)]

pub mod campaign;
pub mod controllers;
pub mod csv;
pub mod located;
pub mod nc;
pub mod paths;
pub mod poses;
pub mod probe;
pub mod progress;
pub mod sensors;
pub mod time;
pub mod tolerance;
pub mod truth;
