//! The integration tests of the calibration history, in one test binary (one link instead of one
//! per file): each file of this directory is a module, and `cargo test -p history --test all
//! NAME::` runs one of them.

mod common;
#[path = "../../../fitting/tests/all/one_record.rs"]
mod one_record;
#[path = "../../../report/tests/all/one_report.rs"]
mod one_report;

mod store;
mod trend;
