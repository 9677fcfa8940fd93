//! The integration tests of the `compensation` crate, in one test binary (one link instead of one
//! per file): each file of this directory is a module, and
//! `cargo test -p compensation --test all NAME::` runs one of them.

#[path = "../../../simulation/tests/all/common/mod.rs"]
mod common;
#[path = "../../../fitting/tests/all/one_record.rs"]
mod one_record;

mod axis_tables;
mod compensation_engine;
mod compensation_firmware;
mod corrected_kinematics;
mod full_loop;
mod identified;
mod isg_volumetric;
mod linuxcnc_kinematics;
mod range_limits;
mod safety_limits;
mod siemens_kinematics;
mod timebases;
mod volumetric;
