//! The integration tests of the symbolic engine and the code generator, in one test binary (one
//! link instead of one per file): each file of this directory is a module, and `cargo test -p
//! codegen --test all NAME::` runs one of them.

mod support;

mod emitted;
mod engine;
mod sharing;
mod snapshots;
mod split;
