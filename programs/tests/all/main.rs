//! The integration tests of the `programs` crate, in one test binary (one link instead of one
//! per file): each file of this directory is a module, and
//! `cargo test -p programs --test all NAME::` runs one of them.

#[path = "../../../simulation/tests/all/common/mod.rs"]
mod common;
#[path = "../../../fitting/tests/all/one_record.rs"]
mod one_record;

mod nc_measure;
mod probe_log;
mod probe_program;
mod segment;
mod sequence;
