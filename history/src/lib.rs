//! A machine's calibration history: every identification recorded in an embedded SQLite file,
//! and the trend of each error over the checks, with drift flags.
//!
//! This crate has one job: the store and the trend statistics (no command line).
//!
//! - [`Check`] is one identification as recorded: the user's machine id beside the machine
//!   description's fingerprint, the machine and model names and the model's terms, the test
//!   paths, the times (UTC, RFC 3339), the SHA-256 of every input file ([`sha256`]), the rtest
//!   version, every identified value with its standard uncertainty and unit, the
//!   identifiability (rank, the groups the data could not separate) and the residual RMS.
//!   [`Check::from_identification`] builds it from the report of `rtest identify`, of one
//!   record or of a campaign of several (whose shared values trend like a record's).
//! - [`Store`] is the database ([`schema`]: versioned by `PRAGMA user_version`, migrated in
//!   order). One transaction per check, WAL mode and a busy timeout, so several processes can
//!   record at once; a damaged or foreign file is refused with its name and never changed.
//! - [`trend`] selects one error's comparable checks of one machine and flags them: beyond
//!   tolerance ([`tolerance`]), changed against a baseline, drifting (a weighted least-squares
//!   slope and Student's t, [`stats`]); [`report`] writes the listing and the trend for
//!   people, as CSV and as JSON.
//!
//! Values are kept in the unit the reports give them: µm for translational errors, µrad for
//! angular ones.

#![warn(missing_docs)]

pub mod check;
pub mod error;
pub mod report;
pub mod schema;
pub mod sha256;
pub mod stats;
pub mod store;

pub mod tolerance;
pub mod trend;

pub use check::{Check, CheckKind, InputFile, Parameter, Provenance, RecheckedCalibration};
pub use error::HistoryError;
pub use formats::time::Timestamp;
pub use store::{DEFAULT_FILE, MachineSummary, RecordedCheck, Staged, Store};
