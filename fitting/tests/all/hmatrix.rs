//! The H matrix: compiled code and the IR evaluator agree, and columns equal finite differences
//! of the exact virtual machine at on-ball poses.

use crate::common;

use common::{builtin, id};
use fitting::hmatrix::{
    Backend, GainSource, HMatrixError, h_matrix, h_matrix_auto, parameter_names,
};
use model_spec::{Dir, Machine};
use nalgebra::DMatrix;
use simulation::fd::fd_gains;
use simulation::model::Basis;
use simulation::model::{Effect, Model, Term};
use simulation::record::Record;

fn term(m: &Machine, s: &str) -> Term {
    Term::parse(m, s).unwrap()
}

/// Constant, harmonic, poly, reversal and time terms, and sensor offsets.
fn mixed_model(m: &Machine) -> Model {
    Model {
        terms: [
            "XOC",
            "BOA",
            "AOC",
            "ZOW",
            "ECC@harmonic:2",
            "EXC@harmonic:1",
            "EXX@poly:2",
            "EYY@poly:3",
            "ECC@reversal",
            "EAA@reversal",
            "XOW@time:1",
            "COA@time:2",
            "dx0",
            "dz0@time:1",
        ]
        .iter()
        .map(|s| term(m, s))
        .collect(),
    }
}

fn max_abs(h: &DMatrix<f64>) -> f64 {
    h.iter().fold(0.0, |a, &x| a.max(x.abs()))
}

#[test]
fn compiled_and_evaluator_give_the_same_matrix() {
    let m = builtin("seed-ac");
    let p = m.default_parameters();
    let rec = k4(&m);
    let model = mixed_model(&m);
    let mut compiled = GainSource::compiled(&m, &model.errors(), &p).unwrap();
    let mut evaluator = GainSource::evaluator(&m, &model.errors(), &p).unwrap();
    assert_eq!(compiled.backend(), Backend::Compiled);
    assert_eq!(evaluator.backend(), Backend::Evaluator);
    let a = h_matrix(&m, &model, &rec, &mut compiled).unwrap();
    let b = h_matrix(&m, &model, &rec, &mut evaluator).unwrap();
    assert_eq!(a.shape(), (3 * 241, model.width()));
    assert_eq!(model.width(), 16);
    let scale = max_abs(&a);
    let diff = max_abs(&(&a - &b));
    eprintln!("compiled vs evaluator: max |difference| {diff:e}, max |H| {scale}");
    assert!(
        diff <= 1e-12 * scale,
        "max difference {diff:e} (scale {scale})"
    );
    // Every column is used (no all-zero column).
    for c in 0..a.ncols() {
        assert!(a.column(c).amax() > 0.0, "column {c} is zero");
    }
    // Same for the full 44-error model.
    let full = Model::constant(&m.errors);
    let a = h_matrix_auto(&m, &full, &rec, &p).unwrap();
    let mut ev = GainSource::evaluator(&m, &full.errors(), &p).unwrap();
    let b = h_matrix(&m, &full, &rec, &mut ev).unwrap();
    assert!(max_abs(&(&a - &b)) <= 1e-12 * max_abs(&a));
}

#[test]
fn columns_are_finite_differences_of_the_exact_machine() {
    let m = builtin("seed-ac");
    let p = m.default_parameters();
    let rec = k4(&m);
    let mut model = Model::constant(&m.errors);
    model.terms.push(term(&m, "ECC@harmonic:2"));
    model.terms.push(term(&m, "EYY@poly:2"));
    model.terms.push(term(&m, "dy0"));
    let h = h_matrix_auto(&m, &model, &rec, &p).unwrap();
    let n = m.errors.len();
    let (c_axis, y_axis) = (m.axis_by_name("C").unwrap(), m.axis_by_name("Y").unwrap());
    let [ylo, yhi] = m.axes[y_axis].limits;
    let mut worst: f64 = 0.0;
    for i in (0..rec.samples.len()).step_by(8) {
        let c = &rec.samples[i].commands;
        let mut ids = m.errors.clone();
        ids.push(id(&m, "ECC"));
        ids.push(id(&m, "EYY"));
        let fd = fd_gains(&m, c, &p, &ids);
        let (s2, c2) = (2.0 * c[c_axis]).sin_cos();
        let u = 2.0 * (c[y_axis] - ylo) / (yhi - ylo) - 1.0;
        let p2 = 0.5 * (3.0 * u * u - 1.0);
        for d in 0..3 {
            let row = 3 * i + d;
            for (j, g) in fd.iter().take(n).enumerate() {
                worst = worst.max((h[(row, j)] - g[d]).abs());
            }
            worst = worst.max((h[(row, n)] - fd[n][d] * c2).abs());
            worst = worst.max((h[(row, n + 1)] - fd[n][d] * s2).abs());
            worst = worst.max((h[(row, n + 2)] - fd[n + 1][d] * p2).abs());
            assert_eq!(h[(row, n + 3)], if d == 1 { 1.0 } else { 0.0 });
        }
    }
    // FD accuracy: ~1e-10 mm/rad for lever arms of a few hundred mm (see simulation::fd).
    eprintln!("largest deviation from finite differences: {worst:e} mm/mm or mm/rad");
    assert!(
        worst < 1e-8,
        "largest deviation from finite differences: {worst:e}"
    );
}

#[test]
fn layout_names_and_sensor_offsets() {
    let m = builtin("seed-ac");
    let rec = k4(&m);
    let model = mixed_model(&m);
    let names = parameter_names(&m, &model);
    assert_eq!(names[4], "ECC@harmonic:2:cos");
    assert_eq!(names[5], "ECC@harmonic:2:sin");
    assert_eq!(names[14], "dx0");
    assert_eq!(names[15], "dz0@time:1");
    let h = h_matrix_auto(&m, &model, &rec, &m.default_parameters()).unwrap();
    let last = rec.samples.len() - 1;
    for i in [0, 100, last] {
        let tau = rec.tau(i);
        assert_eq!(
            [h[(3 * i, 14)], h[(3 * i + 1, 14)], h[(3 * i + 2, 14)]],
            [1.0, 0.0, 0.0]
        );
        assert_eq!(
            [h[(3 * i, 15)], h[(3 * i + 1, 15)], h[(3 * i + 2, 15)]],
            [0.0, 0.0, tau]
        );
        // XOC: −1 along x everywhere (tool minus ball).
        assert!((h[(3 * i, 0)] + 1.0).abs() < 1e-15);
    }
    assert_eq!(rec.tau(0), -1.0);
    assert_eq!(rec.tau(last), 1.0);
}

#[test]
fn machines_from_files_use_the_evaluator() {
    let text = model_spec::BUILTIN
        .iter()
        .find(|(n, _)| *n == "seed-ac")
        .unwrap()
        .1
        .replace("name = \"seed-ac\"", "name = \"my-ac\"");
    let m = model_spec::parse_machine("my-ac.toml", &text).unwrap();
    let reference = builtin("seed-ac");
    let model = mixed_model(&m);
    let p = m.default_parameters();
    let s = GainSource::new(&m, &model.errors(), &p).unwrap();
    assert_eq!(s.backend(), Backend::Evaluator);
    assert!(matches!(
        GainSource::compiled(&m, &model.errors(), &p),
        Err(HMatrixError::NotCompiled { .. })
    ));
    let a = h_matrix_auto(&m, &model, &k4(&m), &p).unwrap();
    let b = h_matrix_auto(&reference, &mixed_model(&reference), &k4(&reference), &p).unwrap();
    assert!(max_abs(&(&a - &b)) <= 1e-12 * max_abs(&a));
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let m = builtin("seed-ac");
    let p = m.default_parameters();
    let model = mixed_model(&m);
    let mut rec = k4(&m);
    // Wrong parameter count.
    let e = GainSource::new(&m, &model.errors(), &p[..3]).unwrap_err();
    assert!(
        e.to_string()
            .contains("expected one kinematic parameter per symbol (13), got 3")
    );
    // Error id outside the catalogue.
    let e = GainSource::new(&m, &[999], &p).unwrap_err();
    assert!(
        matches!(e, HMatrixError::UnknownError { id: 999, .. }),
        "{e}"
    );
    // A term whose basis does not fit its effect, built without `Term::new`.
    let bad = Model {
        terms: vec![Term {
            effect: Effect::Error(id(&m, "XOC")),
            basis: Basis::Harmonic(1),
        }],
    };
    let e = h_matrix_auto(&m, &bad, &rec, &p).unwrap_err();
    assert!(e.to_string().starts_with("term `XOC@harmonic:1`"), "{e}");
    // A source without one of the model's errors.
    let mut small = GainSource::new(&m, &[id(&m, "XOC")], &p).unwrap();
    let e = h_matrix(&m, &model, &rec, &mut small).unwrap_err();
    assert!(e.to_string().contains("without error `BOA`"), "{e}");
    // A sample with a missing command, and one with a NaN command.
    rec.samples[7].commands.pop();
    let e = h_matrix_auto(&m, &model, &rec, &p).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("sample 7: 4 commands for the 5 axes"),
        "{e}"
    );
    rec.samples[7].commands.push(f64::NAN);
    let e = h_matrix_auto(&m, &model, &rec, &p).unwrap_err();
    assert!(
        e.to_string().starts_with("sample 7: the command of axis"),
        "{e}"
    );
    // An empty record gives an empty matrix.
    let offsets = Model {
        terms: vec![Term {
            effect: Effect::SensorOffset(Dir::X),
            basis: Basis::Const,
        }],
    };
    let h = h_matrix_auto(&m, &offsets, &Record::default(), &p).unwrap();
    assert_eq!(h.shape(), (0, 1));
}

/// The built-in test path K4 (docs/conventions.md).
fn k4(m: &Machine) -> Record {
    simulation::paths::builtin_path(m, "K4").unwrap().unwrap()
}
