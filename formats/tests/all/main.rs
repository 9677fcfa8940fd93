//! The integration tests of the `formats` crate, in one test binary (one link instead of one
//! per file): each file of this directory is a module, and
//! `cargo test -p formats --test all NAME::` runs one of them.

#[path = "../../../simulation/tests/all/common/mod.rs"]
mod common;
mod csvfiles;

mod csvblocks;
mod csvchecks;
mod csvio;
mod csvlines;
mod csvprop;
mod generator;
mod instrument_record;
mod nc_programs;
mod paths;
mod pose_csv;
mod pose_memory;
mod probe_files;
mod truth;
