//! The integration tests of the machine descriptions, in one test binary (one link instead of one
//! per file): each file of this directory is a module, and `cargo test -p model-spec --test all
//! NAME::` runs one of them.

mod builtin;
mod describe;
mod docs;
mod errors;
mod fingerprint;
mod kinematics;
mod limits;
mod pose;
mod robustness;
mod templates;
mod text;
mod write;
