//! How code generation scales with the length of the chain: for synthetic machines of 1 to 16
//! rotary axes (`codegen/tests/support/chains.rs`: a serial arm on the tool side, a table stack
//! on the work side, directions x, z, y and an inclined one in turn, every offset a symbol),
//! the time of the derivation, of derivation plus CSE, of the whole Rust source, and the size
//! of the program of the full model.
//!
//! `cargo run --release -p codegen --example chain_scaling [MAX_AXES]` (default 16). Times are
//! the median of several runs on this computer.

#[path = "../tests/support/chains.rs"]
mod chains;

use codegen::{GainModel, compile};
use std::time::{Duration, Instant};

/// The median wall-clock time of `f` over `runs` runs.
fn median<T>(runs: usize, mut f: impl FnMut() -> T) -> Duration {
    let mut times: Vec<Duration> = (0..runs)
        .map(|_| {
            let t = Instant::now();
            std::hint::black_box(f());
            t.elapsed()
        })
        .collect();
    times.sort();
    times[runs / 2]
}

fn ms(d: Duration) -> String {
    format!("{:.2}", d.as_secs_f64() * 1e3)
}

fn main() {
    let max: usize = std::env::args()
        .nth(1)
        .map(|a| a.parse().expect("MAX_AXES is a number"))
        .unwrap_or(16);
    println!(
        "| rotary axes | errors | derive (ms) | derive + CSE (ms) | Rust source (ms) | instructions | operations |"
    );
    println!("|---|---|---|---|---|---|---|");
    for n in 1..=max {
        let m = chains::synthetic(n, false);
        let errors = m.model_errors("full").expect("a full model").to_vec();
        let first = Instant::now();
        let model = GainModel::derive(&m, &errors);
        let program = compile(&m, &model);
        let once = first.elapsed();
        let runs = if once > Duration::from_secs(2) { 1 } else { 5 };
        let derive = median(runs, || GainModel::derive(&m, &errors));
        let cse = median(runs, || compile(&m, &GainModel::derive(&m, &errors)));
        let source = median(runs, || {
            codegen::emit::generate_machine(&m, &[]).expect("the synthetic chains generate")
        });
        println!(
            "| {n} | {} | {} | {} | {} | {} | {} |",
            errors.len(),
            ms(derive),
            ms(cse),
            ms(source),
            program.ops.len(),
            program.op_counts().total()
        );
    }
}
