//! The runner of the fuzzing tests (`tests/all/readers_fuzz.rs`, `app/src/verbs/plan_fuzz.rs`): how many
//! cases a property takes, and the count of inputs read and refused.

use proptest::strategy::Strategy;
use proptest::test_runner::{Config, TestCaseError, TestRunner};

/// Cases per property in the default suite.
pub const CASES: u32 = 600;

/// The cases of one property: `RTEST_FUZZ_CASES` when set (the documented fuzzing pass runs
/// 100 000), else [`CASES`].
pub fn config() -> Config {
    let cases = std::env::var("RTEST_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(CASES);
    Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    }
}

/// Runs `check` (`Ok(true)`: the input was read) on `config()` cases of `strategy`, prints how
/// many were read, and with `both` asserts that the inputs were neither all read nor all
/// refused (damage that always breaks or never breaks a file tests little).
pub fn fuzz<S: Strategy>(
    what: &str,
    strategy: &S,
    check: impl Fn(S::Value) -> Result<bool, TestCaseError>,
    both: bool,
) {
    let read = std::cell::Cell::new(0u64);
    let cases = std::cell::Cell::new(0u64);
    TestRunner::new(config())
        .run(strategy, |v| {
            let r = check(v)?;
            cases.set(cases.get() + 1);
            read.set(read.get() + u64::from(r));
            Ok(())
        })
        .unwrap();
    eprintln!("{what}: {} of {} inputs read", read.get(), cases.get());
    if both {
        assert!(
            read.get() > 0 && read.get() < cases.get(),
            "{what}: {} of {} inputs read",
            read.get(),
            cases.get()
        );
    }
}
