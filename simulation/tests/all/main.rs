//! The integration tests of the `simulation` crate, in one test binary (one link instead of one
//! per file): each file of this directory is a module, and
//! `cargo test -p simulation --test all NAME::` runs one of them.

mod common;

mod exact_machine;
mod fd;
mod generator_orders;
mod instrument_description;
mod instrument_geometry;
mod probe;
mod simulate;
