//! H-matrix filling on K4 of `seed-ac` (241 samples, 723 rows) for the reduced (11 errors) and
//! full (44 errors) models, compiled code against the IR evaluator; the evaluator's set-up
//! (derive + compile); and the estimation on K4 (least squares alone, and `identify` end to end).
//!
//! `cargo bench -p benches --bench hmatrix`.

use criterion::{Criterion, criterion_group, criterion_main};
use fitting::hmatrix::{GainSource, h_matrix, parameter_names};
use fitting::{Constraint, IdentifyOptions, Tolerances, identify, least_squares};
use model_spec::Machine;
use nalgebra::DVector;
use simulation::campaign::Campaign;
use simulation::model::Model;
use simulation::record::Record;
use std::hint::black_box;

fn seed_ac() -> Machine {
    model_spec::builtin("seed-ac")
        .expect("built-in")
        .expect("valid")
}

fn hmatrix(c: &mut Criterion) {
    let m = seed_ac();
    let p = m.default_parameters();
    let rec = k4(&m);
    let mut g = c.benchmark_group("hmatrix_k4");
    for name in ["reduced", "full"] {
        let model = Model::constant(m.model_errors(name).unwrap());
        let mut compiled = GainSource::compiled(&m, &model.errors(), &p).unwrap();
        let mut evaluator = GainSource::evaluator(&m, &model.errors(), &p).unwrap();
        g.bench_function(format!("{name}/compiled"), |b| {
            b.iter(|| h_matrix(&m, &model, black_box(&rec), &mut compiled).unwrap())
        });
        g.bench_function(format!("{name}/evaluator"), |b| {
            b.iter(|| h_matrix(&m, &model, black_box(&rec), &mut evaluator).unwrap())
        });
        g.bench_function(format!("{name}/evaluator_setup"), |b| {
            b.iter(|| GainSource::evaluator(&m, black_box(&model.errors()), &p).unwrap())
        });
    }
    g.finish();
}

fn estimation(c: &mut Criterion) {
    let m = seed_ac();
    let p = m.default_parameters();
    let model = Model::constant(m.model_errors("reduced").unwrap());
    let mut rec = k4(&m);
    let mut source = GainSource::new(&m, &model.errors(), &p).unwrap();
    let h = h_matrix(&m, &model, &rec, &mut source).unwrap();
    let x = DVector::from_column_slice(&[
        0.012, -0.008, 0.015, 0.021, -0.011, 35e-6, -22e-6, 0.018, -0.014, 41e-6, -17e-6,
    ]);
    let y = &h * x;
    rec.measured = (0..rec.samples.len())
        .map(|i| [y[3 * i], y[3 * i + 1], y[3 * i + 2]])
        .collect();
    let names = parameter_names(&m, &model);
    let tol = Tolerances::default();
    let mut g = c.benchmark_group("estimate_k4");
    g.bench_function("reduced/least_squares", |b| {
        b.iter(|| least_squares(black_box(&h), &y, &names, &Constraint::None, &tol).unwrap())
    });
    let params = m.default_parameters();
    let one = Campaign::of_record(rec.clone(), params.clone(), false);
    let opts = IdentifyOptions::default();
    g.bench_function("reduced/identify", |b| {
        b.iter(|| identify(&m, &model, black_box(&one), &opts).unwrap())
    });
    let zeroed = Campaign::of_record(rec.clone(), params, true);
    g.bench_function("reduced/identify_zeroed", |b| {
        b.iter(|| identify(&m, &model, black_box(&zeroed), &opts).unwrap())
    });
    let full = Model::constant(&m.errors);
    g.bench_function("full/identify", |b| {
        b.iter(|| identify(&m, &full, black_box(&one), &opts).unwrap())
    });
    g.finish();
}

criterion_group!(benches, hmatrix, estimation);
criterion_main!(benches);

/// The built-in test path K4 (docs/conventions.md).
fn k4(m: &Machine) -> Record {
    simulation::paths::builtin_path(m, "K4").unwrap().unwrap()
}
