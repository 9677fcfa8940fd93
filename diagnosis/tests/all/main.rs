//! The integration tests of the `diagnosis` crate, in one test binary (one link instead of one
//! per file): each file of this directory is a module, and
//! `cargo test -p diagnosis --test all NAME::` runs one of them.

mod diagnose;
mod diagnose_adequacy;
mod diagnose_campaign;
mod diagnose_convergence;
mod diagnose_extra_causes;
mod diagnose_families;
mod diagnose_honesty;
mod diagnose_noise;
mod diagnose_same_finding;
mod diagnose_trunnion;
