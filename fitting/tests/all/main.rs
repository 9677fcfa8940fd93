//! The integration tests of the `fitting` crate, in one test binary (one link instead of one
//! per file): each file of this directory is a module, and
//! `cargo test -p fitting --test all NAME::` runs one of them.

#[path = "../../../simulation/tests/all/common/mod.rs"]
mod common;
mod one_record;

mod campaign;
mod campaign_heights;
mod estimate;
mod hmatrix;
mod identify_exact;
mod identify_noise;
mod instrument_calibration;
mod instrument_fit;
mod noise_model;
mod plan;
mod plan_probe;
mod plan_reversal;
mod plan_update;
mod probe_campaign;
mod probe_readings;
mod probe_simulation;
mod probe_vs_rtest;
mod recheck;
mod sphere;
mod streaming;
mod templates;
mod vocabulary;
