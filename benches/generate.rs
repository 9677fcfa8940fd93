//! Code generation cost per built-in machine, and how it scales with the length of the chain:
//! the symbolic derivation alone, derivation plus CSE into the IR, and the whole pipeline to
//! pretty-printed Rust source (every model of the machine).
//!
//! Built-in machines: `derive/NAME`, `derive+cse/NAME`, `rust-source/NAME`. Synthetic chains of
//! `N` rotary axes (`codegen/tests/all/support/chains.rs`: a serial arm on the tool side, a table
//! stack on the work side, directions x, z, y and an inclined one in turn, every offset a
//! symbol): `chain/derive/N`, `chain/derive+cse/N`, `chain/rust-source/N`.
//!
//! Run with `cargo bench -p benches --bench generate` (`-- chain/` for the chains only).

#[path = "../codegen/tests/all/support/chains.rs"]
mod chains;

use codegen::{GainModel, compile};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Duration;

fn generate(c: &mut Criterion) {
    for m in model_spec::all_builtin() {
        let full = m
            .model_errors("full")
            .expect("every machine has a full model")
            .to_vec();
        c.bench_function(&format!("derive/{}", m.name), |b| {
            b.iter(|| GainModel::derive(black_box(&m), black_box(&full)))
        });
        c.bench_function(&format!("derive+cse/{}", m.name), |b| {
            b.iter(|| {
                let g = GainModel::derive(black_box(&m), black_box(&full));
                compile(&m, &g)
            })
        });
        c.bench_function(&format!("rust-source/{}", m.name), |b| {
            b.iter(|| {
                codegen::emit::generate_machine(black_box(&m), &[]).expect("built-ins generate")
            })
        });
    }
}

fn chain(c: &mut Criterion) {
    let mut group = c.benchmark_group("chain");
    group
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    for n in [2, 4, 6, 8, 10, 12, 14, 16] {
        let m = chains::synthetic(n, false);
        let full = m.model_errors("full").expect("a full model").to_vec();
        group.bench_with_input(BenchmarkId::new("derive", n), &n, |b, _| {
            b.iter(|| GainModel::derive(black_box(&m), black_box(&full)))
        });
        group.bench_with_input(BenchmarkId::new("derive+cse", n), &n, |b, _| {
            b.iter(|| compile(&m, &GainModel::derive(black_box(&m), black_box(&full))))
        });
        group.bench_with_input(BenchmarkId::new("rust-source", n), &n, |b, _| {
            b.iter(|| {
                codegen::emit::generate_machine(black_box(&m), &[]).expect("the chains generate")
            })
        });
    }
    group.finish();
}

criterion_group!(benches, generate, chain);
criterion_main!(benches);
