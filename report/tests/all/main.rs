//! The integration tests of the `report` crate, in one test binary (one link instead of one
//! per file): each file of this directory is a module, and
//! `cargo test -p report --test all NAME::` runs one of them.

#[path = "../../../simulation/tests/all/common/mod.rs"]
mod common;
#[path = "../../../diagnosis/tests/all/diagnose/helpers.rs"]
mod diagnose_helpers;
#[path = "../../../fitting/tests/all/one_record.rs"]
mod one_record;
mod one_report;

mod compensation_clamped;
mod compensation_length;
mod compensation_loop;
mod compensation_values;
mod diagnose_instrument_knock;
mod offsets;
mod readers_prop;
mod report_versions;
mod validate;
