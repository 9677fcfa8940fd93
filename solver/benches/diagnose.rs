//! Placeholder replaced by the diagnosis benchmark.
fn main() {}
