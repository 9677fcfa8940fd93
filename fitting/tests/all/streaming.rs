//! Streaming identification equals the in-memory solver.

use fitting::hmatrix::{GainSource, h_matrix, parameter_names};
use fitting::streaming::identify_streaming;
use fitting::{Constraint, Tolerances, least_squares, measurement_vector, with_offsets};
use formats::truth::builtin_truth;
use model_spec::builtin;
use model_spec::terms::Term;
use simulation::model::Model;
use simulation::paths::builtin_path;
use simulation::readings::simulate;
use simulation::record::Record;

fn blocks(r: &Record, size: usize) -> Vec<Result<Record, std::io::Error>> {
    (0..r.samples.len())
        .step_by(size)
        .map(|a| {
            let b = (a + size).min(r.samples.len());
            Ok(Record {
                samples: r.samples[a..b].to_vec(),
                measured: r.measured[a..b].to_vec(),
                lines: r.lines.get(a..b).map_or(Vec::new(), <[usize]>::to_vec),
                ..Default::default()
            })
        })
        .collect()
}

fn compare(model: &Model, block: usize) {
    let m = builtin("seed-ac").unwrap().unwrap();
    let mut t = builtin_truth("seed-ac-demo", &m).unwrap().unwrap();
    t.seed = 11;
    let k4 = simulate(&m, &t, &builtin_path(&m, "K4").unwrap().unwrap()).unwrap();
    let mut source = GainSource::new(&m, &model.errors(), &m.default_parameters()).unwrap();
    let h = h_matrix(&m, model, &k4, &mut source).unwrap();
    let y = measurement_vector(&k4).unwrap();
    let names = parameter_names(&m, model);
    let tol = Tolerances::default();
    let full = least_squares(&h, &y, &names, &Constraint::None, &tol).unwrap();
    let span = (k4.samples[0].t, k4.samples.last().unwrap().t);
    let s = identify_streaming(
        &m,
        model,
        blocks(&k4, block),
        Some(span),
        &mut source,
        &Constraint::None,
        &tol,
    )
    .unwrap();
    assert_eq!(s.samples, k4.samples.len());
    assert_eq!(s.fit.rank, full.rank);
    assert_eq!(s.fit.dof, full.dof);
    assert!(
        (s.fit.rss / full.rss - 1.0).abs() < 1e-9,
        "rss {} vs {}",
        s.fit.rss,
        full.rss
    );
    for (j, name) in names.iter().enumerate() {
        match (s.fit.values[j], full.values[j]) {
            (Some(a), Some(b)) => assert!(
                (a - b).abs() <= 1e-9 * b.abs().max(1e-6),
                "{name}: {a} vs {b}"
            ),
            (None, None) => {}
            other => panic!("{name}: determined differently {other:?}"),
        }
        match (s.fit.std[j], full.std[j]) {
            (Some(a), Some(b)) => {
                assert!((a / b - 1.0).abs() < 1e-9, "{name} std: {a} vs {b}")
            }
            (None, None) => {}
            other => panic!("{name} std: {other:?}"),
        }
    }
    assert_eq!(
        s.fit.identifiability.confounded,
        full.identifiability.confounded
    );
}

#[test]
fn streaming_equals_in_memory_for_the_reduced_model_with_a_drift_term() {
    let m = builtin("seed-ac").unwrap().unwrap();
    let mut model = Model::of(&m, "reduced").unwrap();
    model.terms.push(Term::parse(&m, "dz0@time:1").unwrap());
    model.terms.push(Term::parse(&m, "ECC@harmonic:2").unwrap());
    for block in [1, 37, 241] {
        compare(&model, block);
    }
}

#[test]
fn streaming_keeps_the_identifiability_analysis_of_a_rank_deficient_model() {
    // The reduced model with constant sensor offsets: XOC/dx0, YOA/dy0, ZOA/dz0 are confounded.
    let m = builtin("seed-ac").unwrap().unwrap();
    let model = with_offsets(&Model::of(&m, "reduced").unwrap());
    compare(&model, 50);
}
