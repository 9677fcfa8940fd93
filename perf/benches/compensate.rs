//! The cost of compensation on the host (BENCHMARKS.md):
//! `cargo bench -p perf --bench compensate`. One pose of `seed-ac`, full model (44 errors):
//! - `compensate/generated-f64`: the generated `compensate` (target and three steps, sines and
//!   cosines by `f64::sin_cos`);
//! - `compensate/generated-f32`: the generated single-precision first-order correction (the
//!   caller's sines and cosines included);
//! - `compensate/host`: the host's corrected pose (`Compensator::correct`: the IR evaluated in
//!   process, the check of the remainder, values at the corrected pose).

use criterion::{Criterion, criterion_group, criterion_main};
use generated::seed_ac::{PARAMETERS, Params, full};
use solver::compensation::correct::Compensator;
use std::hint::black_box;

fn compensate(c: &mut Criterion) {
    let m = model_spec::builtin("seed-ac").unwrap().unwrap();
    let errors = m.model_errors("full").unwrap().to_vec();
    let params = m.default_parameters();
    let mut commands = [0.0, -0.4, 0.9, 0.0, 0.0];
    solver::simulation::exact::tool_centre_point_ik(&m, &mut commands, &params).unwrap();
    let values: Vec<f64> = (0..errors.len())
        .map(|i| {
            let size = if m.catalogue[errors[i]].is_angular() {
                20e-6
            } else {
                10e-3
            };
            size * ((i as f64 * 0.7).sin())
        })
        .collect();
    let values_array: [f64; full::N] = values.clone().try_into().unwrap();
    let typed = Params::default();
    let mut g = c.benchmark_group("compensate");
    g.bench_function("generated-f64", |b| {
        b.iter(|| {
            full::compensation::compensate(
                black_box(&commands),
                &typed,
                black_box(&values_array),
                f64::sin_cos,
            )
        })
    });
    let params32: [f32; PARAMETERS.len()] = std::array::from_fn(|i| params[i] as f32);
    let values32: [f32; full::N] = std::array::from_fn(|i| values[i] as f32);
    g.bench_function("generated-f32", |b| {
        let mut out = [0.0f32; 11];
        b.iter(|| {
            let q = black_box(&commands);
            let (sa, ca) = (q[1] as f32).sin_cos();
            let (sc, cc) = (q[2] as f32).sin_cos();
            let pose = [sa, ca, sc, cc, q[0] as f32, q[3] as f32, q[4] as f32];
            full::compensation::first_order_f32(&pose, &params32, black_box(&values32), &mut out);
            out[0]
        })
    });
    let mut host = Compensator::new(&m, &errors, params.clone()).unwrap();
    g.bench_function("host", |b| {
        b.iter(|| {
            let mut values_at = |_: &[f64], out: &mut [f64]| out.copy_from_slice(&values);
            host.correct(black_box(&commands), &mut values_at).unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, compensate);
criterion_main!(benches);
