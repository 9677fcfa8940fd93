//! The integration tests of `output`, in one test binary (one link instead of one per file):
//! each file of this directory is a module, and `cargo test -p output --test all NAME::` runs
//! one of them. Tests that need a process of their own (standard output, signals, an
//! unprivileged user) run this binary again as a child with their full name (`module::test`).

mod common;

mod all_or_none;
mod files;
mod inputs;
mod refusals;
mod streams;
mod temporaries;
