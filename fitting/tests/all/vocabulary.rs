//! The vocabulary beyond constants, harmonics and polynomials — `period:P`, `step:V`,
//! `exp:TAU`, `velocity` and the R-test instrument terms `SXX` … `SZY` — on the exact virtual
//! machine: every H column is the change of the exact readings per unit of its coefficient,
//! identification recovers a hidden value, and terms that need real times refuse numbered
//! samples.

use crate::common;
use crate::one_record::{identify_one, identify_refined_one};

use common::builtin;
use fitting::IdentifyOptions;
use fitting::hmatrix::{HMatrixError, h_matrix_auto};
use fitting::refine::RefineOptions;
use formats::truth::builtin_truth;
use model_spec::Machine;
use simulation::model::{Model, Term};
use simulation::paths::builtin_path;
use simulation::readings::{SimulateError, simulate};
use simulation::record::Record;
use simulation::truth::Truth;

/// Truth lines (appended to seed-ac's reduced truth) and the term each adds.
const CASES: &[(&str, &str)] = &[
    (r#"EXX = { "period:10" = [2.0, -1.0] }"#, "EXX@period:10"),
    (r#"EXX = { "period:2.5" = [0.5, 0.25] }"#, "EXX@period:2.5"),
    (r#"EXX = { "step:100" = 3.0 }"#, "EXX@step:100"),
    (r#"ECC = { "step:90" = 5.0 }"#, "ECC@step:90"),
    (r#"EAA = { "step:-30" = -4.0 }"#, "EAA@step:-30"),
    (r#"dy0 = { "exp:20" = 4.0 }"#, "dy0@exp:20"),
    (r#"COX = { "exp:50" = 6.0 }"#, "COX@exp:50"),
    ("EXX = { velocity = 0.5 }", "EXX@velocity"),
    ("ECC = { velocity = 2.0 }", "ECC@velocity"),
    ("EAA = { velocity = 1.5 }", "EAA@velocity"),
    ("SXY = 0.03", "SXY"),
    ("SXX = 0.01", "SXX"),
    ("SZZ = -0.02", "SZZ"),
    ("SZX = 0.015", "SZX"),
];

fn machine() -> Machine {
    builtin("seed-ac")
}

fn k4(m: &Machine) -> Record {
    builtin_path(m, "K4").unwrap().unwrap()
}

fn reduced_truth(m: &Machine) -> Truth {
    builtin_truth("seed-ac-reduced", m).unwrap().unwrap()
}

/// The reduced truth with `line` added to its errors.
fn with_line(m: &Machine, line: &str) -> Truth {
    let text = formats::truth::truth_to_toml(&reduced_truth(m), m) + line + "\n";
    formats::truth::parse_truth("case.toml", &text, m).unwrap()
}

#[test]
fn every_new_column_is_the_change_of_the_exact_readings() {
    let m = machine();
    let path = k4(&m);
    let base = reduced_truth(&m);
    let r0 = simulate(&m, &base, &path).unwrap();
    for &(line, spelling) in CASES {
        let t = with_line(&m, line);
        let term = Term::parse(&m, spelling).unwrap();
        let c = t.coefficient(&term).unwrap().to_vec();
        let r1 = simulate(&m, &t, &path).unwrap();
        let model = Model { terms: vec![term] };
        let h = h_matrix_auto(&m, &model, &r0, &base.params).unwrap();
        let mut worst = 0.0f64;
        let mut size = 0.0f64;
        for (i, (a, b)) in r0.measured.iter().zip(&r1.measured).enumerate() {
            for d in 0..3 {
                let row = 3 * i + d;
                let predicted: f64 = (0..c.len()).map(|k| h[(row, k)] * c[k]).sum();
                worst = worst.max((b[d] - a[d] - predicted).abs());
                size = size.max(predicted.abs());
            }
        }
        // A change of at least 0.1 µm, matched to second order (products of two errors of tens
        // of µm and µrad with a lever arm: ~1e-4 relative).
        assert!(
            size > 1e-4,
            "{spelling}: the term moves the readings by {size} mm"
        );
        assert!(
            worst <= 1e-3 * size,
            "{spelling}: the exact change differs from H·c by {worst} mm (change up to {size} mm)"
        );
    }
}

#[test]
fn identification_recovers_each_hidden_term() {
    let m = machine();
    let path = k4(&m);
    for &(line, spelling) in CASES {
        let t = with_line(&m, line);
        let data = simulate(&m, &t, &path).unwrap();
        if spelling == "ECC@velocity" {
            // C turns at a constant rate on K4: its lag is a constant angular positioning
            // error there, which the reduced model's errors already span.
            let mut model = Model::of(&m, "reduced").unwrap();
            model.terms.push(Term::parse(&m, spelling).unwrap());
            let fit = identify_one(&m, &model, &data, &IdentifyOptions::default()).unwrap();
            assert_eq!(fit.fit.values.last(), Some(&None), "{spelling}");
            continue;
        }
        let term = Term::parse(&m, spelling).unwrap();
        let mut model = Model::of(&m, "reduced").unwrap();
        model.terms.push(term);
        let (ident, r) = identify_refined_one(
            &m,
            &model,
            &data,
            &IdentifyOptions::default(),
            &RefineOptions::default(),
        )
        .unwrap_or_else(|e| panic!("{spelling}: {e}"));
        assert!(r.converged, "{spelling}");
        let at: usize = model.terms[..model.terms.len() - 1]
            .iter()
            .map(|t| t.basis.width())
            .sum();
        let want = t.coefficient(&term).unwrap();
        for (k, &w) in want.iter().enumerate() {
            let got =
                ident.fit.values[at + k].unwrap_or_else(|| panic!("{spelling}: undetermined"));
            assert!(
                (got - w).abs() <= 1e-6 * w.abs(),
                "{spelling} column {k}: identified {got}, hidden {w}"
            );
        }
    }
}

#[test]
fn the_first_order_fit_of_an_instrument_term_is_biased_by_its_own_size() {
    // Documented in the H matrix: the measured reading stands for the displacement, so a gain
    // error S fitted to first order comes out as S / (1 + S); the refinement removes that.
    let m = machine();
    let t = with_line(&m, "SYY = 0.05");
    let data = simulate(&m, &t, &k4(&m)).unwrap();
    let mut model = Model::of(&m, "reduced").unwrap();
    model.terms.push(Term::parse(&m, "SYY").unwrap());
    let fit = identify_one(&m, &model, &data, &IdentifyOptions::default()).unwrap();
    let got = fit.fit.values[model.width() - 1].unwrap();
    assert!((got - 0.05 / 1.05).abs() < 1e-5, "{got}");
    assert!((got - 0.05).abs() > 2e-3, "{got}");
}

#[test]
fn terms_that_need_times_refuse_numbered_samples() {
    let m = machine();
    let base = reduced_truth(&m);
    for (line, spelling) in [
        ("ECC = { velocity = 2.0 }", "ECC@velocity"),
        (r#"dz0 = { "exp:20" = 1.0 }"#, "dz0@exp:20"),
    ] {
        let t = with_line(&m, line);
        let mut data = simulate(&m, &t, &k4(&m)).unwrap();
        data.samples.iter_mut().for_each(|s| s.timed = false);
        let model = Model {
            terms: vec![Term::parse(&m, spelling).unwrap()],
        };
        let e = h_matrix_auto(&m, &model, &data, &base.params).unwrap_err();
        assert!(matches!(e, HMatrixError::Times { .. }), "{e:?}");
        assert_eq!(
            e.to_string(),
            format!(
                "term `{spelling}`: term `{spelling}` needs the real sample times (a `t_s` column, s), but the record has none: its samples are only numbered"
            )
        );
        let e = simulate(&m, &t, &data).unwrap_err();
        assert!(matches!(e, SimulateError::Times { .. }), "{e:?}");
        assert!(e.to_string().contains(spelling), "{e}");
    }
}

#[test]
fn velocities_are_central_differences_one_sided_at_the_ends() {
    let m = machine();
    let mut r = k4(&m);
    r.samples.truncate(4);
    let times = [0.0, 0.5, 1.5, 3.0];
    let xs = [0.0, 1.0, 4.0, 4.0];
    for (s, (&t, &x)) in r.samples.iter_mut().zip(times.iter().zip(&xs)) {
        s.t = t;
        s.commands[0] = x;
    }
    let n = m.axes.len();
    let v = r.velocities("EXX@velocity", n).unwrap();
    let got: Vec<f64> = (0..4).map(|i| v[i * n]).collect();
    // mm/ms: one-sided, central, central, one-sided.
    assert_eq!(got, [2e-3, 4.0 / 1500.0, 3.0 / 2500.0, 0.0]);
    // Equal times around a sample: no velocity.
    r.samples[2].t = 0.0;
    r.samples[0].t = 0.0;
    r.samples[1].t = 0.0;
    let e = r.velocities("EXX@velocity", n).unwrap_err();
    assert!(e.0.contains("samples 0 and 1 have the same time"), "{e}");
}
