//! `rtest bench`: what the generated code buys, measured on this computer (the `perf` crate).

use super::{EXIT_CODES, Error, VerbResult};
use crate::Done;

const LONG_ABOUT: &str = "\
Measures, on this computer and in this process, what the generated code buys (medians of \
repeated runs; ratios as well as times):
  1. identification of a long synthetic R-test record (10^6 samples; --quick 10^5) of the seed \
machine, reduced model, streamed (blocks folded into an incremental QR) and in memory (the whole \
record and H): both times, their ratio, and each run's peak memory (the process's peak reset \
before each run);
  2. the gains of the whole seed-ac model (44 errors x 6) at one pose, sines and cosines \
included, by (a) the generated code, (b) the in-process IR evaluator, (c) the exact HTM chain \
with central finite differences, (d) a runtime first-order product of the chain;
  3. the H matrix of the full model (3 rows x 44 columns per pose) for 10^6 poses (--quick 10^5), \
filled by the generated position_gains in blocks into a reused buffer, against a plain write of \
the same bytes into the same buffer: a block that stays in the cache, and one larger than the \
last-level cache (the memory-bandwidth comparison);
  4. the code generation of every built-in machine.
BENCHMARKS.md has the careful versions (criterion, callgrind instruction counts).";

/// Flags of `rtest bench`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Measure the generated code against its baselines on this computer",
    long_about = LONG_ABOUT,
    after_help = EXIT_CODES
)]
pub struct BenchArgs {
    /// Smaller sizes (10^5 instead of 10^6 poses and samples), fewer runs.
    #[arg(long)]
    quick: bool,
    /// Print the results as JSON (times in s, ns and ms as the keys say; bandwidths in GB/s).
    #[arg(long)]
    json: bool,
}

/// Runs `rtest bench`.
pub fn run(args: &BenchArgs) -> VerbResult<Done> {
    let report = perf::report::run(args.quick);
    if let Some(what) = perf::report::non_finite(&report) {
        return Err(Error::computation(format!(
            "bench: a measurement failed: {what}"
        )));
    }
    if args.json {
        let json = serde_json::to_string_pretty(&report)
            .map_err(|e| Error::computation(format!("--json: {e}")))?;
        Ok(Done::text(json + "\n"))
    } else {
        Ok(Done::text(perf::report::text(&report)))
    }
}
