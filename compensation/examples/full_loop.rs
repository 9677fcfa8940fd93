//! The full calibration loop on a full error budget: prints the four figures of
//! docs/compensation.md ("The full loop on a full budget") at the noise seeds given.
//!
//! ```sh
//! cargo run --release -p compensation --example full_loop -- 1 2 3 4 5
//! # What the extended model lacks: the truth's missing machine terms added group by group.
//! cargo run --release -p compensation --example full_loop -- --groups 1
//! # The grouped candidates (error groups tested as one candidate each, confirmed on the
//! # records left out in turn), and the extended model with every selected group added.
//! cargo run --release -p compensation --example full_loop -- --error-groups 1 2 3 4 5
//! # The same on a sixth record, K2 with the ball at the higher position.
//! cargo run --release -p compensation --example full_loop -- --error-groups --k2-high 1
//! # Each record predicted by the fit on the four others, with each selected group.
//! cargo run --release -p compensation --example full_loop -- --left-out 1
//! # The diagnosis allowed more than its default 8 findings.
//! cargo run --release -p compensation --example full_loop -- --max-findings 30 1 2 3
//! ```
//!
//! A five-record campaign of `seed-ac-budget` (K4, K1, K2 with the ball at the description's
//! position, K4 and K1 with it 50 mm higher, each ball position its own set-up) is diagnosed
//! with the reduced model as base, identified with the reduced model, the diagnosis's extended
//! model and the truth's own terms, and each identification's shared errors are compensated on
//! 200 random five-axis poses with the ball at `Zw + 25` mm; the machine's own error is measured
//! on the exact virtual machine before and after (the study is `solv../tests/all/full_loop/study.rs`,
//! the test `compensation/tests/all/full_loop.rs` asserts its gate).

// The test `full_loop` uses the rest of the study.
#[allow(dead_code)]
#[path = "../tests/all/full_loop/study.rs"]
mod study;

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let groups = args.iter().any(|a| a == "--groups");
    args.retain(|a| a != "--groups");
    let error_groups = args.iter().any(|a| a == "--error-groups");
    args.retain(|a| a != "--error-groups");
    let k2_high = args.iter().any(|a| a == "--k2-high");
    args.retain(|a| a != "--k2-high");
    let left_out = args.iter().any(|a| a == "--left-out");
    args.retain(|a| a != "--left-out");
    let mut options = diagnosis::DiagnoseOptions::default();
    if let Some(k) = args.iter().position(|a| a == "--max-findings") {
        let n = args.get(k + 1).and_then(|n| n.parse::<usize>().ok());
        let Some(n) = n.filter(|&n| n >= 1) else {
            eprintln!("full_loop: --max-findings takes a whole number ≥ 1");
            std::process::exit(2)
        };
        options = options.max_findings(n);
        args.drain(k..k + 2);
    }
    let seeds: Vec<u64> = args
        .into_iter()
        .map(|a| match a.parse::<u64>() {
            Ok(s) if s >= 1 => s,
            _ => {
                eprintln!("full_loop: `{a}` is not a noise seed (a whole number ≥ 1)");
                std::process::exit(2)
            }
        })
        .collect();
    let seeds = if seeds.is_empty() { vec![1] } else { seeds };
    for seed in seeds {
        if left_out {
            for line in study::left_out(seed) {
                println!("noise seed {seed}: {line}");
            }
            continue;
        }
        if error_groups {
            let (groups, confirmed, f) = study::groups(seed, k2_high);
            for g in groups {
                println!("noise seed {seed}: group {g}");
            }
            println!(
                "noise seed {seed}: the extended model ({}): {:.3} → {:.3} µm, {:.1} % less with the set-up refitted ({:.1} % without)",
                confirmed.model,
                confirmed.before_um,
                confirmed.after_refitted_um,
                100.0 * confirmed.fall_refitted(),
                100.0 * confirmed.fall()
            );
            println!(
                "noise seed {seed}: extended + every selected group ({}): {:.3} → {:.3} µm, {:.1} % less with the set-up refitted ({:.1} % without)",
                f.model,
                f.before_um,
                f.after_refitted_um,
                100.0 * f.fall_refitted(),
                100.0 * f.fall()
            );
            continue;
        }
        if groups {
            for (group, terms, f) in study::additions(seed) {
                println!(
                    "noise seed {seed}: extended + {group} ({}): {:.3} → {:.3} µm, {:.1} % less with the set-up refitted ({:.1} % without)",
                    terms.join(" "),
                    f.before_um,
                    f.after_refitted_um,
                    100.0 * f.fall_refitted(),
                    100.0 * f.fall()
                );
            }
        } else {
            print!("{}", study::text(&study::run_with(seed, &options)));
        }
    }
}
