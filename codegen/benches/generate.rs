//! Code generation cost per built-in machine: the symbolic derivation alone, derivation plus
//! CSE into the IR, and the whole pipeline to pretty-printed Rust source (every model of the
//! machine). Run with `cargo bench -p codegen --bench generate`.

use codegen::{GainModel, compile};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

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

criterion_group!(benches, generate);
criterion_main!(benches);
