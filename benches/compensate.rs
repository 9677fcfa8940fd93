//! The cost of compensation on the host (BENCHMARKS.md):
//! `cargo bench -p benches --bench compensate`. One pose of `seed-ac`, full model (44 errors):
//! - `compensate/generated-f64`: the generated `compensate` (target and three steps, sines and
//!   cosines by `f64::sin_cos`);
//! - `compensate/generated-f32`: the generated single-precision first-order correction (the
//!   caller's sines and cosines included);
//! - `compensate/host`: the host's corrected pose (`Compensator::correct`: the IR evaluated in
//!   process, the check of the remainder, values at the corrected pose);
//! - `program/iso-1e5`: a 10^5-block ISO program read, every pose corrected (on every core)
//!   and written back, with the values of the demo truth's recommended model identified on K4:
//!   what `rtest compensate --nc iso` does between reading and writing its files.

use compensation::correct::Compensator;
use criterion::{Criterion, criterion_group, criterion_main};
use generated::seed_ac::{PARAMETERS, Params, full};
use std::hint::black_box;

fn compensate(c: &mut Criterion) {
    let m = model_spec::builtin("seed-ac").unwrap().unwrap();
    let errors = m.model_errors("full").unwrap().to_vec();
    let params = m.default_parameters();
    let mut commands = [0.0, -0.4, 0.9, 0.0, 0.0];
    simulation::exact::tool_centre_point_ik(&m, &mut commands, &params).unwrap();
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

fn program(c: &mut Criterion) {
    use compensation::run::{CommandedPose, compensate_poses};
    use compensation::values::MachineErrors;
    use fitting::{IdentifyOptions, RefineOptions, identify};
    use formats::nc::{Dialect, WriteOptions, parse_program};
    use formats::poses::{axis_words, from_file_units, to_file_units};
    use report::json::read::parse_identification;
    use report::json::{CampaignSource, IdentificationReport, to_json};
    let m = model_spec::builtin("seed-ac").unwrap().unwrap();
    let truth = formats::truth::builtin_truth("seed-ac-demo", &m)
        .unwrap()
        .unwrap();
    let k4 = simulation::builtin_path(&m, "K4").unwrap().unwrap();
    let record = simulation::simulate(&m, &truth, &k4).unwrap();
    let mut model = simulation::model::Model::of(&m, "reduced").unwrap();
    model
        .terms
        .push(model_spec::terms::Term::parse(&m, "ECC@harmonic:2").unwrap());
    let k4_record = simulation::campaign::CampaignRecord::new(
        "k4",
        record.clone(),
        m.default_parameters(),
        "k4",
        false,
    );
    let one = simulation::campaign::Campaign::new(vec![k4_record]).unwrap();
    let opts = IdentifyOptions::default().refined(RefineOptions::default());
    let fit = identify(&m, &model, &one, &opts).unwrap();
    let source = CampaignSource {
        label: "extended",
        base_model: None,
        data: &["k4.csv".to_string()],
    };
    let report =
        IdentificationReport::of_campaign(&m, source, &fit, fit.refinement.as_ref()).unwrap();
    let values = parse_identification("id.json", &to_json(&report).unwrap(), &m).unwrap();
    let (errors, _) = MachineErrors::from_values(&m, &values.values, &values.file).unwrap();
    // 10^5 blocks along K4, over and over.
    let mut text = String::from("%\nO2000 (LONG)\nG21 G90 G94\n");
    for i in 0..100_000 {
        let q = &record.samples[i % record.samples.len()].commands;
        text.push_str(&format!(
            "N{} G1 X{:.4} Y{:.4} Z{:.4} A{:.4} C{:.4} F2000\n",
            i + 1,
            q[0],
            q[3],
            q[4],
            q[1].to_degrees(),
            q[2].to_degrees()
        ));
    }
    text.push_str("M30\n%\n");
    let words = axis_words(&m);
    let params = m.default_parameters();
    let mut g = c.benchmark_group("program");
    g.sample_size(10);
    g.bench_function("iso-1e5", |b| {
        b.iter(|| {
            let program = parse_program("long.nc", black_box(&text), Dialect::Iso, &words).unwrap();
            let poses: Vec<CommandedPose> = program
                .poses()
                .iter()
                .map(|p| CommandedPose {
                    line: p.line,
                    commands: from_file_units(&m, &p.commands),
                })
                .collect();
            let values_at = |q: &[f64], out: &mut [f64]| errors.values_at(&m, q, out);
            let done = compensate_poses(
                &m,
                errors.errors(),
                params.clone(),
                "long.nc",
                &poses,
                &values_at,
            )
            .unwrap();
            let corrected: Vec<Vec<f64>> =
                done.poses.iter().map(|q| to_file_units(&m, q)).collect();
            program
                .write(&corrected, &WriteOptions::new())
                .unwrap()
                .text
                .len()
        })
    });
    g.finish();
}

criterion_group!(benches, compensate, program);
criterion_main!(benches);
