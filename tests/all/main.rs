//! The end-to-end tests of the rtest binary and the workspace, in one test binary (one link
//! instead of one per file): each file of this directory is a module, and
//! `cargo test --test all NAME::` runs one of them.

mod common;
#[path = "../../compensation/tests/all/identified.rs"]
mod identified;
#[path = "../../fitting/tests/all/one_record.rs"]
mod one_record;
mod support;

mod browser_harness;
mod cli;
mod cli_campaign;
mod cli_compensate;
mod cli_compensate_limits;
mod cli_diagnose;
mod cli_gains;
mod cli_generate_crate;
mod cli_hardening;
mod cli_history;
mod cli_identify;
mod cli_instrument;
mod cli_linuxcnc;
mod cli_noise;
mod cli_offsets;
mod cli_path;
mod cli_path_probe;
mod cli_plan;
mod cli_plan_probe;
mod cli_probe;
mod cli_progress;
mod cli_recheck;
mod cli_report;
mod cli_report_inputs;
mod cli_report_probe;
mod cli_reversal;
mod cli_segment;
mod cli_sensor_campaign;
mod cli_siemens;
mod cli_simulate_probe;
mod cli_stream;
mod cli_templates;
mod cli_timebases;
mod cli_validate_tolerance;
mod cli_vocabulary;
mod cli_volumetric;
mod engine_long_chains;
mod gains_negative_directions;
mod gains_property;
mod golden;
mod inclined_axes;
mod inclined_directions;
mod linuxcnc_oracle;
mod linuxcnc_probe_program;
mod readers_fuzz;
mod report_browser;
mod seed_tables;
mod siemens_forward;
