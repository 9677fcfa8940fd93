//! The instrument terms and a knocked ball, each at five noise seeds (every seed must pass).
//!
//! Set-up as `tests/all/diagnose.rs` (helpers shared): `seed-ac`, the 11 reduced errors of
//! `seed-ac-reduced` (10–30 µm and µrad), 0.5 µm white noise per direction, exact virtual
//! machine, fitted on K4, held out K1 and K2, default options (noise estimated from the
//! records).
//!
//! - **Instrument**: the x reading carrying 3 % of the y displacement (`SXY` 0.03: the x sensor
//!   1.7° off its axis towards y), a 5 % gain error of the x sensor (`SXX` 0.05: an uncalibrated
//!   gauge, or one calibrated at another temperature), 5 % of the x displacement in the z
//!   reading (`SZX` 0.05). Required: the instrument term is the first finding, or among its
//!   alternatives only where the two are an exact alias on K4 (their columns, the base model
//!   projected out, collinear to 1e-9: proved here, not assumed); its value within 4 standard
//!   uncertainties of the truth; no other term with the status `cause`.
//! - **Knock**: the ball knocked 3 µm along x of its table (`XOW` + 3 µm; and along z, `ZOW`)
//!   at sample 150 of K4, the set-up as it was at the start of K4 on K1 and K2. Required: no
//!   finding with the status `cause`, no finding selected twice, and what remains described
//!   as a jump at sample 150 ± 5 in `unexplained`. The jump is a candidate of the selection
//!   (`XOW@jump:149.5`, a term of K4 only), so it competes with its look-alikes on K4 and the
//!   held-out records see the machine's errors fitted with it in place.

use crate::diagnose_helpers as helpers;

use diagnosis::Diagnosis;
use diagnosis::dictionary::scanned;
use diagnosis::unexplained::Shape;
use fitting::hmatrix::h_matrix_auto;
use helpers::*;
use model_spec::Machine;
use nalgebra::DMatrix;
use report::json::diagnose::{DiagnosisReport, DiagnosisSource};
use simulation::model::{Model, Term};
use simulation::readings::simulate;
use simulation::truth::Truth;

/// The noise seeds of every case.
const SEEDS: [u64; 5] = [1, 2, 3, 4, 5];

/// The status of every finding, as the report gives it (`cause`, `not confirmed`,
/// `implausible`).
fn statuses(m: &Machine, d: &Diagnosis) -> Vec<String> {
    let o = options();
    let source = DiagnosisSource {
        machine_source: "seed-ac",
        label: "reduced",
        data: vec!["K4".into()],
        held_out: vec!["K1".into(), "K2".into()],
        data_arguments: Vec::new(),
        opts: &o,
        model_out: None,
    };
    DiagnosisReport::new(m, &source, d)
        .expect("report")
        .findings
        .into_iter()
        .map(|f| f.status)
        .collect()
}

/// `1 − cos²` of the largest angle between the columns of `b` and the span of the columns of
/// `a` on K4, both with the base model's columns projected out; the instrument columns from the
/// noise-free displacements of `truth` (the readings of the truth without its instrument terms).
fn alias_gap(m: &Machine, truth: &Truth, a: Term, b: Term) -> f64 {
    let mut clean = truth.clone();
    clean.noise_mm = 0.0;
    let mut at = 0;
    let (mut terms, mut coefficients) = (Vec::new(), Vec::new());
    for t in &truth.model.terms {
        let w = t.basis.width();
        if !matches!(t.effect, model_spec::terms::Effect::Instrument { .. }) {
            terms.push(*t);
            coefficients.extend_from_slice(&truth.coefficients[at..at + w]);
        }
        at += w;
    }
    clean.model = Model { terms };
    clean.coefficients = coefficients;
    let record = simulate(m, &clean, &path(m, "K4")).expect("simulate");
    let base = base_model(m, &[]);
    let h = |model: Model| h_matrix_auto(m, &model, &record, &m.default_parameters()).unwrap();
    let hb = h(base.clone());
    let q = hb.svd(true, false).u.unwrap();
    let project = |mut x: DMatrix<f64>| {
        for mut c in x.column_iter_mut() {
            let along = q.transpose() * &c;
            c -= &q * along;
            let n = c.norm();
            c /= n;
        }
        x
    };
    let pa = project(h(Model { terms: vec![a] }));
    let pb = project(h(Model { terms: vec![b] }));
    let qa = pa.svd(true, false).u.unwrap();
    pb.column_iter()
        .map(|c| 1.0 - (qa.transpose() * c).norm_squared())
        .fold(0.0, f64::max)
}

/// The truth with the instrument term `name` of value `value` (a fraction) hidden.
fn with_instrument(m: &Machine, name: &str, value: f64) -> Truth {
    let mut truth = base_truth(m);
    truth.model.terms.push(term(m, name));
    truth.coefficients.push(value);
    truth
}

/// The diagnosis of the truth with the instrument term `name` of value `value` hidden, fitted
/// on the first `fitted` of K4, K1, K2 (together, on one set-up) and held out on the others,
/// checked (see the module documentation).
fn instrument(name: &str, value: f64, seed: u64, fitted: usize) -> Diagnosis {
    let m = machine();
    let hidden = term(&m, name);
    let truth = with_instrument(&m, name, value);
    let recs = records(&m, &truth, &["K4", "K1", "K2"], seed);
    let d = run_fitted(&m, &base_model(&m, &[]), &recs, fitted, &options());
    let status = statuses(&m, &d);
    let value_of = |f: &diagnosis::Finding| format!("{:?} ± {:?}", f.values[0], f.stds[0]);
    let what = format!(
        "{name} {value} seed {seed}: {}; status {status:?}; first {}",
        summary(&m, &d, &recs[fitted - 1..]),
        d.findings.first().map(value_of).unwrap_or_default()
    );
    println!("{what}");
    let first = d.findings.first().unwrap_or_else(|| panic!("{what}"));
    // Named: the first finding, or an exact alias of it on the fitted records.
    if first.term != hidden {
        assert!(first.alternatives.contains(&hidden), "{what}");
        let gap = alias_gap(&m, &truth, first.term, hidden);
        assert!(gap < 1e-9, "{what}: an alternative 1 − cos² = {gap:e} off");
    } else {
        // A realistic size is plausible, and its value is the truth's.
        assert!(
            first.plausible,
            "{what}: size {} of {}",
            first.size, first.limit
        );
        let v = first.values[0].expect("determined");
        let s = first.stds[0].expect("determined");
        assert!(
            (v - value).abs() <= 4.0 * s,
            "{what}: {v} ± {s} for {value}"
        );
    }
    // No other term a cause.
    for (f, s) in d.findings.iter().zip(&status) {
        assert!(
            s != "cause" || f.term == first.term,
            "{what}: {} is a cause",
            f.term.spelling(&m)
        );
    }
    d
}

/// 3 % of the y displacement in the x reading (the x sensor 1.7° off its axis towards y), K4
/// fitted.
#[test]
fn cross_talk_of_3_percent_y_in_x() {
    for seed in SEEDS {
        instrument("SXY", 0.03, seed, 1);
    }
}

/// 5 % of the x displacement in the z reading, K4 fitted.
#[test]
fn cross_talk_of_5_percent_x_in_z() {
    for seed in SEEDS {
        instrument("SZX", 0.05, seed, 1);
    }
}

/// The RMS (µm) of the column of `name` at `value` on K4 (the noise-free displacements of the
/// base truth), and of what is left of it with the base model's columns projected out.
fn left_on_k4(m: &Machine, name: &str, value: f64) -> (f64, f64) {
    let mut clean = base_truth(m);
    clean.noise_mm = 0.0;
    let record = simulate(m, &clean, &path(m, "K4")).expect("simulate");
    let h = |model: Model| h_matrix_auto(m, &model, &record, &m.default_parameters()).unwrap();
    let q = h(base_model(m, &[])).svd(true, false).u.unwrap();
    let c = h(Model {
        terms: vec![term(m, name)],
    });
    let left = &c - &q * (q.transpose() * &c);
    let rms = |x: &DMatrix<f64>| value * x.norm() / (x.nrows() as f64).sqrt() * 1e3;
    (rms(&c), rms(&left))
}

/// A 5 % gain error of the x sensor (an uncalibrated gauge) on K4 alone: the base model takes
/// 99 % of it (0.62 µm RMS on K4, 0.045 µm left after the base fit: a ΔRSS of some 6 σ² over
/// 723 readings, below any corrected test). Nothing else is named a cause, no jump is
/// described, and the held-out records show what K4 does not: not consistent with the noise.
#[test]
fn a_gain_error_of_5_percent_in_x_is_absorbed_on_k4() {
    let m = machine();
    let (signature, left) = left_on_k4(&m, "SXX", 0.05);
    println!("SXX 0.05 on K4: {signature:.3} µm RMS, {left:.3} µm left after the base model");
    assert!(left < 0.1 * signature, "{signature} µm, {left} µm left");
    let hidden = term(&m, "SXX");
    let truth = with_instrument(&m, "SXX", 0.05);
    for seed in SEEDS {
        let recs = records(&m, &truth, &["K4", "K1", "K2"], seed);
        let d = run(&m, &base_model(&m, &[]), &recs, &options());
        let status = statuses(&m, &d);
        let what = format!(
            "SXX 0.05 seed {seed}: {}; status {status:?}",
            summary(&m, &d, &recs)
        );
        println!("{what}");
        for (f, s) in d.findings.iter().zip(&status) {
            assert!(s != "cause" || f.term == hidden, "{what}");
        }
        let a = d.adequacy.as_ref().expect("a noise model");
        assert!(!a.consistent_with_noise, "{what}");
        assert_eq!(jumps(&d), Vec::<usize>::new(), "{what}");
    }
}

/// The same gain error fitted on K4 and K1 together (one set-up), K2 held out: named.
#[test]
fn a_gain_error_of_5_percent_in_x_on_k4_and_k1() {
    for seed in SEEDS {
        instrument("SXX", 0.05, seed, 2);
    }
}

/// The samples at which a jump in time is described on a fitted record (a step in time of the
/// base model's residual).
fn jumps(d: &Diagnosis) -> Vec<usize> {
    d.unexplained
        .iter()
        .filter(|u| u.base && u.follows.as_deref() == Some("time"))
        .filter(|u| matches!(u.shape, Shape::Step { .. }))
        .filter_map(|u| u.sample)
        .collect()
}

/// The ball knocked 3 µm along the set-up error `name` at sample [`KNOCK_AT`] of K4 (see the
/// module documentation).
fn knock(name: &str, seed: u64) {
    let m = machine();
    let truth = base_truth(&m);
    let recs = knocked(&m, &truth, name, 3.0, seed);
    let d = run(&m, &base_model(&m, &[]), &recs, &options());
    let status = statuses(&m, &d);
    let described: Vec<String> = d
        .unexplained
        .iter()
        .map(|u| {
            format!(
                "{} {} {:?} {:?} sample {:?} base {}",
                u.data,
                ["x", "y", "z"][u.direction],
                u.follows,
                u.shape,
                u.sample,
                u.base
            )
        })
        .collect();
    let gains: Vec<String> = d
        .findings
        .iter()
        .map(|f| {
            f.confirmation
                .as_ref()
                .map_or("-".into(), |c| format!("{:.1} sd", c.gain_sd))
        })
        .collect();
    let what = format!(
        "{name} knocked, seed {seed}: {}; status {status:?}; held-out gains {gains:?}; recommended {:?}; unexplained {described:?}",
        summary(&m, &d, &recs),
        d.recommendation.recommended
    );
    println!("{what}");
    assert!(status.iter().all(|s| s != "cause"), "{what}");
    // No finding twice: not the same term, nor two steps of one error within one spacing of its
    // grid on K4 (the same jump).
    let grid = scanned(
        &m,
        &base_model(&m, &[]).terms,
        &recs[0].1,
        &options().dictionary,
    );
    let spacing = |t: &Term| {
        let mut v: Vec<f64> = grid
            .iter()
            .filter(|g| g.effect == t.effect)
            .filter_map(|g| g.basis.step_at())
            .collect();
        v.sort_by(f64::total_cmp);
        (v[v.len() - 1] - v[0]) / (v.len() - 1) as f64
    };
    for (i, a) in d.findings.iter().enumerate() {
        for b in &d.findings[..i] {
            assert_ne!(a.term, b.term, "{what}");
            if let (Some(u), Some(v)) = (a.term.basis.step_at(), b.term.basis.step_at())
                && a.term.effect == b.term.effect
            {
                assert!((u - v).abs() > spacing(&a.term), "{what}");
            }
        }
    }
    let at = jumps(&d);
    assert!(
        !at.is_empty() && at.iter().all(|k| k.abs_diff(KNOCK_AT) <= 5),
        "{what}"
    );
}

/// Knocked along x of the table.
#[test]
fn a_ball_knocked_along_x_is_a_jump_not_a_cause() {
    for seed in SEEDS {
        knock("XOW", seed);
    }
}

/// Knocked along z of the table. The base fit takes part of the knock into the machine's
/// errors, and look-alikes of the knock on K4 (a warm-up of the R-test's z zero, a warm-up of
/// ZOA, a step of EYY) undo that and improve the held-out K1 and K2: at noise seed 5 they were
/// each confirmed on their own and named causes (1.15 → 0.68 µm held out) while the jump was
/// no candidate. The jump `ZOW@jump:149.5` explains the knock whole on K4 and is chosen; the
/// look-alikes add nothing given it (docs/diagnosis.md §7).
#[test]
fn a_ball_knocked_along_z_is_a_jump_not_a_cause() {
    for seed in SEEDS {
        knock("ZOW", seed);
    }
}

/// A smooth misfit the dictionary lacks (3 µm in y seven times per revolution of C, on every
/// record) is not described as a jump.
#[test]
fn a_seventh_harmonic_of_c_is_no_jump() {
    let m = machine();
    let truth = base_truth(&m);
    let c = m.axis_by_name("C").unwrap();
    for seed in SEEDS {
        let mut recs = records(&m, &truth, &["K4", "K1", "K2"], seed);
        for (_, r) in recs.iter_mut() {
            for (s, v) in r.samples.iter().zip(r.measured.iter_mut()) {
                v[1] += 3e-3 * (7.0 * s.commands[c]).cos();
            }
        }
        let d = run(&m, &base_model(&m, &[]), &recs, &options());
        let what = format!("7th harmonic seed {seed}: {}", summary(&m, &d, &recs));
        assert!(!d.unexplained.is_empty(), "{what}");
        assert_eq!(jumps(&d), Vec::<usize>::new(), "{what}");
    }
}
