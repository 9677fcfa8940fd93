//! The whole diagnosis of `seed-ac`: fitted on K4 (241 samples, 723 rows), K1 and K2
//! held out, the full dictionary (harmonics 1–4, polynomials 1–3, time 1–2: every error of the
//! topology the reduced model lacks; and the scanned families: periods, steps, warm-ups, lags,
//! drift of axis lines, instrument terms), default options (α = 0.01, 1000 Monte-Carlo draws,
//! the noise estimated from the records). It includes the outlier search, the noise estimate,
//! the base and extended fits (generalized least squares, refined against the exact machine),
//! the refinement of scanned parameters, the exact predictions of the held-out records and the
//! lack-of-fit bootstrap (400 draws per record).
//!
//! - `diagnose/demo`: truth `seed-ac-demo` (one hidden effect, ECC harmonic:2; one finding);
//! - `diagnose/budget`: truth `seed-ac-budget` (the full error budget; several findings, the
//!   exchange pass, a Monte-Carlo null at the last step);
//! - `diagnose/budget-wide`: the same with a wider dictionary (harmonics 1–8, polynomials 1–5,
//!   time 1–4).
//!
//! `cargo bench -p solver --bench diagnose`. The set-up prints the dictionary's size (candidate
//! terms and H-matrix columns).

use criterion::{Criterion, criterion_group, criterion_main};
use model_spec::Machine;
use solver::diagnosis::dictionary::{DictionaryOptions, dictionary, scanned};
use solver::diagnosis::{DiagnoseOptions, diagnose};
use solver::model::Model;
use solver::record::Record;
use solver::simulation::paths::builtin_path;
use solver::simulation::readings::simulate;
use solver::simulation::truth::builtin_truth;
use std::hint::black_box;

fn seed_ac() -> Machine {
    model_spec::builtin("seed-ac")
        .expect("built-in")
        .expect("valid")
}

/// K4, K1, K2 simulated with the built-in truth `name` (noise seeds 1, 2, 3).
fn records(m: &Machine, name: &str) -> Vec<(String, Record)> {
    let mut truth = builtin_truth(name, m).expect("built in").expect("valid");
    ["K4", "K1", "K2"]
        .iter()
        .enumerate()
        .map(|(k, p)| {
            truth.seed = k as u64 + 1;
            let path = builtin_path(m, p).expect("built in").expect("path");
            (p.to_string(), simulate(m, &truth, &path).expect("simulate"))
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let m = seed_ac();
    let base = Model::of(&m, "reduced").expect("reduced model");
    let wide = DiagnoseOptions::new().dictionary(DictionaryOptions::new(8, 5, 4));
    let cases = [
        ("demo", "seed-ac-demo", DiagnoseOptions::default()),
        ("budget", "seed-ac-budget", DiagnoseOptions::default()),
        ("budget-wide", "seed-ac-budget", wide),
    ];
    let mut g = c.benchmark_group("diagnose");
    g.sample_size(30);
    for (name, truth, o) in cases {
        let recs = records(&m, truth);
        let mut candidates = dictionary(&m, &base.terms, &o.dictionary);
        candidates.extend(scanned(&m, &base.terms, &recs[0].1, &o.dictionary));
        let columns: usize = candidates.iter().map(|t| t.basis.width()).sum();
        let d = diagnose(&m, &base, &recs[0].1, &recs[1..], &o).expect("diagnosis");
        println!(
            "{name}: dictionary of {} candidate terms, {columns} H-matrix columns (base: {}), K4 {} rows; {} finding(s): {}",
            candidates.len(),
            base.width(),
            3 * recs[0].1.samples.len(),
            d.findings.len(),
            d.findings
                .iter()
                .map(|f| f.term.spelling(&m))
                .collect::<Vec<_>>()
                .join(", ")
        );
        g.bench_function(name, |b| {
            b.iter(|| {
                diagnose(
                    black_box(&m),
                    black_box(&base),
                    black_box(&recs[0].1),
                    black_box(&recs[1..]),
                    black_box(&o),
                )
                .expect("diagnosis")
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
