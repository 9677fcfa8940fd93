//! `rtest bench`: the performance comparisons, in-process, in a few seconds.

use super::json::Json;
use super::{CliResult, EXIT_CODES};
use perf;

const LONG_ABOUT: &str = "\
Measures, on this computer and in this process, what the generated code buys (medians of \
repeated runs; ratios as well as times):
  1. streaming identification of a long synthetic R-test record (10^6 samples; --quick 10^5) of \
the seed machine, reduced model, blocks folded into an incremental QR: time and peak memory \
(measured first, so that the peak is this step's);
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
#[command(about = "Measure the generated code against its baselines on this computer", long_about = LONG_ABOUT, after_help = EXIT_CODES)]
pub struct BenchArgs {
    /// Fewer poses, samples and repetitions (about a second).
    #[arg(long)]
    quick: bool,
    /// Print the results as JSON instead of tables.
    #[arg(long)]
    json: bool,
}

/// Runs `rtest bench`.
pub fn run(args: &BenchArgs) -> CliResult {
    let n = if args.quick { 100_000 } else { 1_000_000 };
    let streaming = perf::streaming_identify(n);
    let methods = perf::gain_methods(args.quick);
    let fills: Vec<perf::FillBandwidth> = [4096, 65536]
        .iter()
        .map(|&b| perf::fill_bandwidth(n, b, if args.quick { 2 } else { 3 }))
        .collect();
    let codegen = perf::codegen_times(if args.quick { 3 } else { 9 });
    if args.json {
        let obj = Json::Obj(vec![
            (
                "streaming_identify".into(),
                Json::Obj(vec![
                    ("samples".into(), Json::Num(streaming.samples as f64)),
                    ("seconds".into(), Json::Num(streaming.total_seconds)),
                    (
                        "data_generation_seconds".into(),
                        Json::Num(streaming.generate_seconds),
                    ),
                    (
                        "peak_rss_mb".into(),
                        streaming
                            .peak_rss_bytes
                            .map_or(Json::Null, |b| Json::Num(b as f64 / 1e6)),
                    ),
                    ("worst_z".into(), Json::Num(streaming.worst_z)),
                ]),
            ),
            (
                "gains_per_pose".into(),
                Json::Arr(
                    methods
                        .iter()
                        .map(|m| {
                            Json::Obj(vec![
                                ("method".into(), Json::str(m.method)),
                                ("ns".into(), Json::Num(m.ns_per_pose)),
                                ("ratio_to_generated".into(), Json::Num(m.ratio_to_generated)),
                            ])
                        })
                        .collect(),
                ),
            ),
            (
                "h_fill".into(),
                Json::Arr(
                    fills
                        .iter()
                        .map(|f| {
                            Json::Obj(vec![
                                ("poses".into(), Json::Num(f.poses as f64)),
                                ("block_poses".into(), Json::Num(f.block as f64)),
                                (
                                    "fill_gb_per_s".into(),
                                    Json::Num(f.bytes / f.fill_seconds / 1e9),
                                ),
                                (
                                    "plain_write_gb_per_s".into(),
                                    Json::Num(f.bytes / f.write_seconds / 1e9),
                                ),
                                ("fraction".into(), Json::Num(f.fraction())),
                            ])
                        })
                        .collect(),
                ),
            ),
            (
                "codegen_ms".into(),
                Json::Obj(
                    codegen
                        .iter()
                        .map(|(m, s)| (m.clone(), Json::Num(s * 1e3)))
                        .collect(),
                ),
            ),
        ]);
        print!("{}", obj.render());
        return Ok(());
    }
    println!(
        "rtest bench{}: medians on this computer, one core\n",
        if args.quick { " --quick" } else { "" }
    );
    println!("Gains of seed-ac, full model (44 errors x 6), per pose, sines and cosines included:");
    println!("  {:<40} {:>12} {:>12}", "method", "ns/pose", "x generated");
    for m in &methods {
        println!(
            "  {:<40} {:>12.1} {:>12.1}",
            m.method, m.ns_per_pose, m.ratio_to_generated
        );
    }
    println!(
        "\nH matrix of the full model, {} poses (3 x 44 per pose, {:.0} MB in all):",
        n,
        n as f64 * 3.0 * 44.0 * 8.0 / 1e6
    );
    println!(
        "  {:<34} {:>14} {:>18} {:>10}",
        "block", "fill GB/s", "plain write GB/s", "fraction"
    );
    for f in &fills {
        let label = format!(
            "{} poses ({:.1} MB)",
            f.block,
            (f.block * 3 * 44 * 8) as f64 / 1e6
        );
        println!(
            "  {:<34} {:>14.2} {:>18.2} {:>9.0}%",
            label,
            f.bytes / f.fill_seconds / 1e9,
            f.bytes / f.write_seconds / 1e9,
            100.0 * f.fraction()
        );
    }
    println!(
        "\nStreaming identification, reduced model, {} samples: {:.2} s ({:.2} s of it generating the synthetic record), peak memory {}; worst estimate {:.1} std from the values used",
        streaming.samples,
        streaming.total_seconds,
        streaming.generate_seconds,
        streaming
            .peak_rss_bytes
            .map_or("unknown".into(), |b| format!("{:.0} MB", b as f64 / 1e6)),
        streaming.worst_z
    );
    println!("\nCode generation (every model, Rust source):");
    for (m, s) in &codegen {
        println!("  {m:<16} {:.2} ms", s * 1e3);
    }
    Ok(())
}
