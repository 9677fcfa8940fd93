//! The generated code against its baselines, in one run (BENCHMARKS.md):
//! `cargo bench -p benches --bench gains`.
//! - `gains/*`: all 44 × 6 gains of seed-ac at one pose (sines and cosines included) by
//!   (a) the generated code, (b) the IR evaluator, (c) the exact HTM chain with central finite
//!   differences, (d) the runtime first-order product;
//! - `fill/*`: 10^6 poses of the full H (position rows) in blocks of 65 536 poses (larger than
//!   the last-level cache) against a plain write of the same bytes;
//! - `streaming/identify-1e6`: the reduced model from 10^6 synthetic samples, in blocks;
//!   `streaming/in-memory-1e6`: the same samples identified in memory (whole record and H).

use criterion::{Criterion, criterion_group, criterion_main};
use generated::seed_ac::{Params, Pose, full};
use std::hint::black_box;

fn gains(c: &mut Criterion) {
    let m = model_spec::builtin("seed-ac").unwrap().unwrap();
    let errors = m.model_errors("full").unwrap().to_vec();
    let params = m.default_parameters();
    let model = codegen::GainModel::derive(&m, &errors);
    let program = codegen::compile(&m, &model);
    let chain = perf::first_order::FirstOrderChain::new(&m, &errors);
    let vm = simulation::exact::VirtualMachine::new(&m);
    let mut commands = vec![0.0, -0.4, 0.9, 0.0, 0.0];
    simulation::exact::tool_centre_point_ik(&m, &mut commands, &params).unwrap();
    let typed = Params::default();
    let mut g = c.benchmark_group("gains");
    g.bench_function("a-generated", |b| {
        let mut out = [[0.0; 6]; full::N];
        b.iter(|| {
            let c = black_box(&commands);
            let (sa, ca) = c[1].sin_cos();
            let (sc, cc) = c[2].sin_cos();
            let pose = Pose {
                sin_a: sa,
                cos_a: ca,
                sin_c: sc,
                cos_c: cc,
                x: c[0],
                y: c[3],
                z: c[4],
            };
            full::gains(&pose, &typed, &mut out);
            black_box(&out);
        })
    });
    g.bench_function("b-evaluator", |b| {
        let (mut scratch, mut out) = (Vec::new(), vec![0.0; 6 * errors.len()]);
        b.iter(|| {
            let inputs = model.atoms.values(black_box(&commands), &params);
            program.eval(&inputs, &mut scratch, &mut out);
            black_box(&out);
        })
    });
    let steps = simulation::fd::FdSteps {
        richardson: false,
        ..Default::default()
    };
    g.bench_function("c-htm-finite-differences", |b| {
        b.iter(|| {
            black_box(simulation::fd::fd_gains_with(
                &vm,
                black_box(&commands),
                &params,
                &errors,
                steps,
            ))
        })
    });
    g.bench_function("d-first-order-product", |b| {
        let mut out = vec![[0.0; 6]; errors.len()];
        b.iter(|| {
            chain.gains(black_box(&commands), &params, &mut out);
            black_box(&out);
        })
    });
    g.finish();
}

fn fill_and_stream(c: &mut Criterion) {
    let mut g = c.benchmark_group("fill");
    g.sample_size(10);
    g.bench_function("h-1e6-poses-44-errors", |b| {
        b.iter(|| black_box(perf::fill_bandwidth(1_000_000, 65_536, 1)))
    });
    g.finish();
    let mut g = c.benchmark_group("streaming");
    g.sample_size(10);
    g.bench_function("identify-1e6", |b| {
        b.iter(|| black_box(perf::streaming_identify(1_000_000)))
    });
    g.bench_function("in-memory-1e6", |b| {
        b.iter(|| black_box(perf::memory_identify(1_000_000)))
    });
    g.finish();
}

criterion_group!(benches, gains, fill_and_stream);
criterion_main!(benches);
