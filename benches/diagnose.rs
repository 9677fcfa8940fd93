//! The whole diagnosis of `seed-ac`: fitted on K4 (241 samples, 723 rows), K1 and K2
//! held out, the full dictionary (harmonics 1–4, polynomials 1–3, time 1–2: every error of the
//! topology the reduced model lacks; and the scanned families: periods, steps, warm-ups, lags,
//! drift of axis lines, instrument terms), default options (α = 0.01, 1000 Monte-Carlo draws,
//! the noise estimated from the records). It includes the outlier search, the noise estimate,
//! the base and extended fits (generalized least squares, refined against the exact machine),
//! the refinement of scanned parameters, the exact predictions of the held-out records and the
//! lack-of-fit bootstrap (200 draws per record).
//!
//! - `diagnose/demo`: truth `seed-ac-demo` (one hidden effect, ECC harmonic:2; one finding);
//! - `diagnose/budget`: truth `seed-ac-budget` (the full error budget; several findings, the
//!   exchange pass, a Monte-Carlo null at the last step);
//! - `diagnose/budget-wide`: the same with a wider dictionary (harmonics 1–8, polynomials 1–5,
//!   time 1–4);
//! - `diagnose/demo-campaign`: truth `seed-ac-demo`, K4 and K1 fitted together (each its own
//!   set-up), K2 held out on a set-up of its own (its set-up errors refitted on it).
//!
//! And a campaign (`diagnose-campaign/budget-five`): five records of `seed-ac-budget` (noise
//! seeds 1–5) fitted together, no record held out: K4, K1 and K2 with the ball at the
//! description's position and K4 and K1 with the ball 50 mm higher (`Zw + 50`), each ball
//! position its own set-up; 1325 samples, 3975 rows. The diagnosis's default options, as
//! `rtest diagnose --campaign` runs them.
//!
//! `cargo bench -p benches --bench diagnose`. The set-up prints the dictionary's size (candidate
//! terms and H-matrix columns).

#[path = "../diagnosis/examples/support/campaign.rs"]
mod campaign;

use campaign::campaign;
use criterion::{Criterion, criterion_group, criterion_main};
use diagnosis::dictionary::{DictionaryOptions, dictionary, scanned};
use diagnosis::{DiagnoseOptions, diagnose, one_record};
use formats::progress::Unwatched;
use formats::truth::builtin_truth;
use model_spec::Machine;
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::model::Model;
use simulation::paths::builtin_path;
use simulation::readings::simulate;
use simulation::record::Record;
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

fn bench_campaign(c: &mut Criterion) {
    let m = seed_ac();
    let base = Model::of(&m, "reduced").expect("reduced model");
    let o = DiagnoseOptions::default();
    let fitted = campaign(&m);
    let none = Campaign {
        records: Vec::new(),
    };
    let d = diagnose(&m, &base, &fitted, &none, &o, &Unwatched).expect("diagnosis");
    println!(
        "budget-five: {} records, {} samples; {} finding(s): {}",
        fitted.records.len(),
        fitted
            .records
            .iter()
            .map(|r| r.record.samples.len())
            .sum::<usize>(),
        d.findings.len(),
        d.findings
            .iter()
            .map(|f| format!("{} (p = {:.3e})", f.term.spelling(&m), f.p_value))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let mut g = c.benchmark_group("diagnose-campaign");
    g.sample_size(10);
    g.bench_function("budget-five", |b| {
        b.iter(|| {
            diagnose(
                black_box(&m),
                black_box(&base),
                black_box(&fitted),
                black_box(&none),
                black_box(&o),
                &Unwatched,
            )
            .expect("diagnosis")
        })
    });
    g.finish();
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
        let (fitted, held) = one_record(
            &recs[0].0,
            recs[0].1.clone(),
            recs[1..].to_vec(),
            m.default_parameters(),
            false,
        )
        .expect("campaigns");
        let d = diagnose(&m, &base, &fitted, &held, &o, &Unwatched).expect("diagnosis");
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
                    black_box(&fitted),
                    black_box(&held),
                    black_box(&o),
                    &Unwatched,
                )
                .expect("diagnosis")
            })
        });
    }
    // A campaign: K4 and K1 fitted together, each on its own set-up; K2 on a set-up of its own.
    let recs = records(&m, "seed-ac-demo");
    let own = |k: usize| CampaignRecord::on_own_setup(&m, &recs[k].0, recs[k].1.clone());
    let fitted = Campaign::new(vec![own(0), own(1)]).expect("campaign");
    let held = Campaign::new(vec![own(2)]).expect("campaign");
    let o = DiagnoseOptions::default();
    g.sample_size(10);
    g.bench_function("demo-campaign", |b| {
        b.iter(|| {
            diagnose(
                black_box(&m),
                black_box(&base),
                black_box(&fitted),
                black_box(&held),
                black_box(&o),
                &Unwatched,
            )
            .expect("diagnosis")
        })
    });
    g.finish();
}

criterion_group!(benches, bench, bench_campaign);
criterion_main!(benches);
