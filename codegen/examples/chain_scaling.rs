//! How code generation scales with the length of the chain: for synthetic machines of 1 to 16
//! rotary axes (`codeg../tests/all/support/chains.rs`: a serial arm on the tool side, a table stack
//! on the work side, each machine the one before with one more axis, directions x, z, y and an
//! inclined one in turn, every offset a symbol), the time of the derivation, of derivation
//! plus CSE, of the whole Rust source, and the size of the program of the full model; then
//! the time of the expanded gain table (`codegen::table`, the form people read) and its size.
//!
//! `cargo run --release -p codegen --example chain_scaling [MAX_AXES [MAX_TABLE_AXES]]`
//! (defaults 16 and 10). Times are wall-clock medians of several runs on this computer.

#[path = "../tests/all/support/chains.rs"]
mod chains;

use codegen::table::{Format, render};
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

fn arg(i: usize, default: usize) -> usize {
    std::env::args()
        .nth(i)
        .map_or(default, |a| a.parse().expect("a number of axes"))
}

fn main() {
    let (max, max_table) = (arg(1, 16), arg(2, 10));
    println!(
        "| rotary axes | errors | intermediates | derive (ms) | derive + CSE (ms) | Rust source (ms) | instructions | operations |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for n in 1..=max {
        let m = chains::synthetic(n, false);
        let errors = m.model_errors("full").expect("a full model").to_vec();
        let model = GainModel::derive(&m, &errors);
        let program = compile(&m, &model);
        let derive = median(11, || GainModel::derive(&m, &errors));
        let cse = median(11, || compile(&m, &GainModel::derive(&m, &errors)));
        let source = median(11, || {
            codegen::emit::generate_machine(&m, &[]).expect("the synthetic chains generate")
        });
        println!(
            "| {n} | {} | {} | {} | {} | {} | {} | {} |",
            errors.len(),
            model.intermediates().len(),
            ms(derive),
            ms(cse),
            ms(source),
            program.ops.len(),
            program.op_counts().total()
        );
    }
    println!();
    println!("| rotary axes | expanded table (ms) | terms | characters |");
    println!("|---|---|---|---|");
    for n in 1..=max_table.min(max) {
        let m = chains::synthetic(n, false);
        let errors = m.model_errors("full").expect("a full model").to_vec();
        let t = Instant::now();
        let model = GainModel::derive(&m, &errors);
        let text = render(&m, &model, &m.name, Format::Text);
        let took = t.elapsed();
        let terms: usize = model.gains.iter().flatten().map(|p| p.len()).sum();
        println!("| {n} | {} | {terms} | {} |", ms(took), text.len());
    }
}
