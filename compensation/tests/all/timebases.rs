//! The time bases that mean the same on records of different lengths: `rate` (a drift in µm/s or
//! µrad/s, its column the time since the start) and `warmup:TAU` (a warm-up of time constant
//! TAU from the start, its value the amplitude it tends to).
//!
//! - their H-matrix columns are central differences of the exact machine in their coefficient;
//! - a record whose first sample is not at its time 0 counts from time 0, not from the sample;
//! - on a campaign clock they are rewritten exactly onto each record's own clock;
//! - a truth with `dx0@rate` and `EXZ@warmup:40` is identified back on a record of 60 s and
//!   one of 600 s, on their own clocks and on one campaign clock, each value within 3 standard
//!   uncertainties of the truth; `time:1` fitted to the same drift gives coefficients ten times
//!   apart;
//! - streaming identification reads them in one pass without the record's span;
//! - compensation leaves them out and lists them;
//! - a warm-up refuses samples before its start.

use crate::common;
use crate::one_record::{identify_one, identify_refined_campaign};

use common::builtin;
use compensation::values::MachineErrors;
use fitting::campaign::CampaignValues;
use fitting::campaign::clock::{own_clock_terms, shifted};
use fitting::campaign::design::block;
use fitting::hmatrix::{GainSource, HMatrixError, h_matrix, h_matrix_auto};
use fitting::noise::NoiseChoice;
use fitting::refine::{RefineOptions, exact_prediction};
use fitting::streaming::identify_streaming;
use fitting::{Constraint, IdentifyOptions, Tolerances};
use model_spec::Machine;
use nalgebra::DVector;
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::model::{Basis, Model, Term};
use simulation::paths::builtin_path;
use simulation::readings::simulate;
use simulation::record::Record;
use simulation::truth::Truth;

fn term(m: &Machine, s: &str) -> Term {
    Term::parse(m, s).unwrap_or_else(|e| panic!("{s}: {e}"))
}

fn model(m: &Machine, spellings: &[&str]) -> Model {
    Model {
        terms: spellings.iter().map(|s| term(m, s)).collect(),
    }
}

/// K4 (241 samples) with sample `i` at `t0 + i·dt` s.
fn k4_timed(m: &Machine, dt: f64, t0: f64) -> Record {
    let mut r = builtin_path(m, "K4").unwrap().unwrap();
    for (i, s) in r.samples.iter_mut().enumerate() {
        s.t = t0 + i as f64 * dt;
        s.timed = true;
    }
    r
}

fn max_abs<'a>(v: impl IntoIterator<Item = &'a f64>) -> f64 {
    v.into_iter().fold(0.0, |a, &x| a.max(x.abs()))
}

#[test]
fn columns_are_central_differences_of_the_exact_machine_in_the_coefficient() {
    let m = builtin("seed-ac");
    let p = m.default_parameters();
    // The first sample at 12.5 s: the columns count from the record's time 0, not from it.
    let rec = k4_timed(&m, 0.5, 12.5);
    let spellings = [
        "XOC@rate",
        "BOA@rate",
        "ECC@rate",
        "dx0@rate",
        "EXZ@warmup:40",
        "AOC@warmup:12.5",
        "EYY@warmup:20",
        "dz0@warmup:40",
    ];
    let all = model(&m, &spellings);
    let h = h_matrix_auto(&m, &all, &rec, &p).unwrap();
    let mut worst: f64 = 0.0;
    for (j, s) in spellings.iter().enumerate() {
        let one = model(&m, &[s]);
        // A step that moves the readings by about 0.1 µm (mm/s or rad/s for a rate).
        let step = match one.terms[0].basis {
            Basis::Rate => 1e-6,
            _ => 1e-4,
        };
        let at = |c: f64| exact_prediction(&m, &one, &[Some(c)], &rec, &p).unwrap();
        let (plus, minus) = (at(step), at(-step));
        let col = h.column(j);
        let scale = col.amax();
        assert!(scale > 0.0, "{s}: zero column");
        for i in 0..rec.samples.len() {
            for d in 0..3 {
                let fd = (plus[i][d] - minus[i][d]) / (2.0 * step);
                worst = worst.max((fd - col[3 * i + d]).abs() / scale);
            }
        }
        // What the column holds at the first sample: the basis at t = 12.5 s.
        let b = match one.terms[0].basis {
            Basis::Rate => 12.5,
            other => 1.0 - (-12.5 / other.tau_s().unwrap()).exp(),
        };
        if *s == "dx0@rate" || *s == "dz0@warmup:40" {
            let d = if s.starts_with("dx0") { 0 } else { 2 };
            assert!((col[d] - b).abs() < 1e-12, "{s}: {} against {b}", col[d]);
        }
    }
    eprintln!(
        "largest deviation from central differences: {worst:e} of the column's largest entry"
    );
    assert!(worst < 1e-7, "{worst:e}");
}

/// The campaign clock's columns of `model` (coefficients `v`) on `rec` started at `start`
/// against the own-clock model the rewriting gives: first order and on the exact machine.
fn rewriting_error(m: &Machine, model: &Model, v: &[f64], rec: &Record, start: f64) -> (f64, f64) {
    let p = m.default_parameters();
    let span = (-40.0, 2500.0);
    let mut source = GainSource::new(m, &model.errors(), &p).unwrap();
    let campaign = block(m, model, rec, &mut source, Some((span, start))).unwrap()
        * DVector::from_column_slice(v);
    let (own, coef) = own_clock_terms(model, v, rec, start, span);
    let mut source = GainSource::new(m, &own.errors(), &p).unwrap();
    let local = h_matrix(m, &own, rec, &mut source).unwrap() * DVector::from_column_slice(&coef);
    let first = max_abs((&campaign - &local).iter()) / max_abs(campaign.iter());
    // On the exact machine, a truth of the campaign's terms run on the record moved onto the
    // campaign clock (where `rate` and `warmup:TAU` count from T = 0) against the rewritten
    // model on the record's own clock.
    let values: Vec<Option<f64>> = v.iter().copied().map(Some).collect();
    let there = exact_prediction(m, model, &values, &shifted(rec, start), &p).unwrap();
    let c: Vec<Option<f64>> = coef.iter().copied().map(Some).collect();
    let here = exact_prediction(m, &own, &c, rec, &p).unwrap();
    let exact = there
        .iter()
        .zip(&here)
        .flat_map(|(a, b)| (0..3).map(move |d| (a[d] - b[d]).abs()))
        .fold(0.0, f64::max);
    (first, exact)
}

#[test]
fn the_campaign_clock_is_rewritten_exactly_onto_a_record_s_own_clock() {
    let m = builtin("seed-ac");
    let timed = model(
        &m,
        &[
            "XOC@rate",
            "BOA@rate",
            "dx0@rate",
            "EXZ@warmup:40",
            "AOC@warmup:25",
        ],
    );
    // mm/s, rad/s, mm/s, mm, rad.
    let v = [2e-5, -3e-8, 1.5e-5, 3e-3, 2e-5];
    for (dt, t0, start) in [(0.25, 0.0, 1234.5), (2.5, 0.0, 0.0), (0.5, 30.0, 300.0)] {
        let rec = k4_timed(&m, dt, t0);
        let (first, exact) = rewriting_error(&m, &timed, &v, &rec, start);
        eprintln!(
            "start {start} s, record {t0}..{} s: first order {first:e} (relative), exact machine {exact:e} mm",
            t0 + 240.0 * dt
        );
        assert!(first < 1e-12, "{first:e}");
        assert!(exact < 1e-12, "{exact:e} mm");
    }
    // With `time:K` and `exp:TAU` beside them (first order: those two are normalised over the
    // record on the exact machine's own clock, so only the rewriting can compare them).
    let mixed = model(
        &m,
        &[
            "XOC@rate",
            "EXZ@warmup:40",
            "ZOA@time:2",
            "dz0@exp:30",
            "YOA",
        ],
    );
    let rec = k4_timed(&m, 0.25, 0.0);
    let (first, _) = rewriting_error(&m, &mixed, &[2e-5, 3e-3, 4e-3, -2e-3, 1e-2], &rec, 700.0);
    assert!(first < 1e-12, "{first:e}");
}

/// The seed's reduced errors, a drift of the R-test's zero in x of 0.02 µm/s and a warm-up of
/// the Z slide's straightness in x of 3 µm with a time constant of 40 s.
const TRUTH: &str = r#"
machine = "seed-ac"
noise_um = 0.2
[errors]
XOW = 12
YOW = -18
ZOW = 15
YOA = 20
ZOA = -15
BOA = 25
COA = -18
XOC = 10
YOC = -22
AOC = 30
BOC = -12
dx0 = { rate = 0.02 }
EXZ = { "warmup:40" = 3.0 }
"#;

#[test]
fn a_truth_with_a_rate_and_a_warm_up_writes_and_reads_back_the_same() {
    let m = builtin("seed-ac");
    let t = truth(&m, 0);
    let text = formats::truth::truth_to_toml(&t, &m);
    assert!(text.contains("dx0 = { \"rate\" = 0.02 }"), "{text}");
    assert!(text.contains("\"warmup:40\" = 3"), "{text}");
    let back = formats::truth::parse_truth("back.toml", &text, &m).unwrap();
    assert_eq!(back.model, t.model);
    assert_eq!(back.coefficients, t.coefficients);
    let units: Vec<(String, &str)> = t
        .entries(&m)
        .into_iter()
        .filter(|e| e.term.basis != Basis::Const)
        .map(|e| (e.term.spelling(&m), e.unit))
        .collect();
    assert_eq!(
        units,
        [
            ("EXZ@warmup:40".to_string(), "um"),
            ("dx0@rate".to_string(), "um/s")
        ]
    );
}

fn truth(m: &Machine, seed: u64) -> Truth {
    let mut t = formats::truth::parse_truth("truth.toml", TRUTH, m).unwrap();
    t.seed = seed;
    t
}

fn reduced_with(m: &Machine, extra: &[&str]) -> Model {
    let mut out = Model::constant(m.model_errors("reduced").unwrap());
    out.terms.extend(extra.iter().map(|s| term(m, s)));
    out
}

/// The value, uncertainty (µm, µm/s) and name of every column whose name starts with `prefix`.
fn values_of(
    ident: &fitting::campaign::CampaignIdentification,
    prefix: &str,
) -> Vec<(String, f64, f64)> {
    ident
        .fit
        .names
        .iter()
        .enumerate()
        .filter(|(_, n)| n.starts_with(prefix))
        .map(|(j, n)| {
            (
                n.clone(),
                ident.fit.values[j].expect("determined") * 1e3,
                ident.fit.std[j].expect("an uncertainty") * 1e3,
            )
        })
        .collect()
}

fn assert_within(found: &[(String, f64, f64)], truth: f64, count: usize) {
    assert_eq!(found.len(), count, "{found:?}");
    for (name, v, s) in found {
        let z = (v - truth) / s;
        eprintln!("{name:>22}: {v:10.5} ± {s:.5} (truth {truth}, z = {z:+.2})");
        assert!(z.abs() < 3.0, "{name}: {v} ± {s}, truth {truth}");
    }
}

#[test]
fn a_rate_and_a_warm_up_are_identified_on_records_of_60_s_and_600_s() {
    let m = builtin("seed-ac");
    let p = m.default_parameters();
    let (short, long) = (k4_timed(&m, 0.25, 0.0), k4_timed(&m, 2.5, 0.0));
    let records = |truth: &Truth| -> Campaign {
        let a = simulate(&m, truth, &short).unwrap();
        let mut t2 = truth.clone();
        t2.seed += 100;
        let b = simulate(&m, &t2, &long).unwrap();
        Campaign::new(vec![
            CampaignRecord::new("s60", a, p.clone(), "ball", false),
            CampaignRecord::new("s600", b, p.clone(), "ball", false),
        ])
        .unwrap()
    };
    let c = records(&truth(&m, 3));
    let fitted = |model: &Model, c: &Campaign| {
        identify_refined_campaign(
            &m,
            model,
            c,
            &IdentifyOptions::new().noise(NoiseChoice::Ordinary),
            &RefineOptions::default(),
        )
        .unwrap()
        .0
    };
    // Each record's own clock: the drift and the warm-up are each record's.
    let ident = fitted(&reduced_with(&m, &["dx0@rate", "EXZ@warmup:40"]), &c);
    assert_within(&values_of(&ident, "dx0@rate["), 0.02, 2);
    assert_within(&values_of(&ident, "EXZ@warmup:40["), 3.0, 2);
    assert_within(&values_of(&ident, "XOC"), 10.0, 1);

    // The same drift fitted as `time:1` (no warm-up in the truth: one clean line): its
    // coefficient is half the drift over each record, ten times apart between the two.
    let mut only_drift = truth(&m, 5);
    let warm = term(&m, "EXZ@warmup:40");
    let k = only_drift
        .model
        .terms
        .iter()
        .position(|t| *t == warm)
        .unwrap();
    only_drift.model.terms.remove(k);
    only_drift.coefficients.remove(k);
    let c = records(&only_drift);
    let normalised = fitted(&reduced_with(&m, &["dx0@time:1"]), &c);
    let t1 = values_of(&normalised, "dx0@time:1[");
    let ratio = t1[1].1 / t1[0].1;
    eprintln!(
        "dx0@time:1: {:.4} µm over 60 s, {:.4} µm over 600 s (ratio {ratio:.2})",
        t1[0].1, t1[1].1
    );
    assert!((ratio - 10.0).abs() < 0.5, "{t1:?}");
    let rates = fitted(&reduced_with(&m, &["dx0@rate"]), &c);
    assert_within(&values_of(&rates, "dx0@rate["), 0.02, 2);
}

#[test]
fn on_a_campaign_clock_one_warm_up_is_shared_and_the_drifts_stay_each_record_s() {
    let m = builtin("seed-ac");
    let p = m.default_parameters();
    let (short, long) = (k4_timed(&m, 0.25, 0.0), k4_timed(&m, 2.5, 0.0));
    // The short record starts 10 s after the campaign's start, the long one 200 s after: the
    // truth runs on the campaign clock (the records' times moved onto it), each record keeps its
    // own times and says when it started.
    let t = truth(&m, 7);
    let on_clock = |rec: &Record, start: f64, seed: u64| {
        let mut t = t.clone();
        t.seed = seed;
        let mut r = simulate(&m, &t, &shifted(rec, start)).unwrap();
        r.samples = rec.samples.clone();
        r
    };
    let c = Campaign::new(vec![
        CampaignRecord::new("s60", on_clock(&short, 10.0, 7), p.clone(), "ball", false)
            .starting_at(10.0),
        CampaignRecord::new("s600", on_clock(&long, 200.0, 8), p.clone(), "ball", false)
            .starting_at(200.0),
    ])
    .unwrap();
    let (ident, refinement) = identify_refined_campaign(
        &m,
        &reduced_with(&m, &["dx0@rate", "EXZ@warmup:40"]),
        &c,
        &IdentifyOptions::new().noise(NoiseChoice::Ordinary),
        &RefineOptions::default(),
    )
    .unwrap();
    eprintln!("refinement: {refinement:?}");
    assert_within(&values_of(&ident, "dx0@rate["), 0.02, 2);
    // Shared: one column, without an owner.
    assert_within(&values_of(&ident, "EXZ@warmup:40"), 3.0, 1);
    assert!(ident.fit.names.iter().any(|n| n == "EXZ@warmup:40"));
    // The residual is the noise: the exact machine, rewritten onto each record's clock, fits.
    let rms = (ident.fit.rss / ident.fit.residual.len() as f64).sqrt() * 1e3;
    assert!(rms < 0.22, "residual RMS {rms} µm for 0.2 µm noise");
}

#[test]
fn streaming_reads_rates_and_warm_ups_in_one_pass_without_the_span() {
    let m = builtin("seed-ac");
    let rec = simulate(&m, &truth(&m, 11), &k4_timed(&m, 2.5, 30.0)).unwrap();
    let model = reduced_with(&m, &["dx0@rate", "EXZ@warmup:40"]);
    let whole = identify_one(&m, &model, &rec, &IdentifyOptions::new()).unwrap();
    let blocks: Vec<Result<Record, std::convert::Infallible>> = (0..rec.samples.len())
        .step_by(50)
        .map(|a| {
            let b = (a + 50).min(rec.samples.len());
            Ok(Record {
                samples: rec.samples[a..b].to_vec(),
                measured: rec.measured[a..b].to_vec(),
                ..Default::default()
            })
        })
        .collect();
    let mut source = GainSource::new(&m, &model.errors(), &m.default_parameters()).unwrap();
    let run = identify_streaming(
        &m,
        &model,
        blocks,
        None,
        &mut source,
        &Constraint::None,
        &Tolerances::default(),
    )
    .unwrap();
    assert_eq!(run.blocks, 5);
    for (j, n) in whole.fit.names.iter().enumerate() {
        let (a, b) = (whole.fit.values[j].unwrap(), run.fit.values[j].unwrap());
        assert!((a - b).abs() <= 1e-9 * a.abs().max(1e-6), "{n}: {a} vs {b}");
    }
}

#[test]
fn compensation_leaves_rates_and_warm_ups_out_and_lists_them() {
    let m = builtin("seed-ac");
    let model = model(&m, &["XOC", "XOC@rate", "BOA@warmup:40", "ECC@rate"]);
    let values = vec![Some(1e-2), Some(2e-5), Some(3e-5), Some(4e-8)];
    let id = CampaignValues::of_model(&m, &model, &values, "k4", m.default_parameters()).unwrap();
    let (errors, left_out) = MachineErrors::from_values(&m, &id, "id.json").unwrap();
    let out: Vec<&str> = left_out.iter().map(|l| l.term.as_str()).collect();
    assert_eq!(out, ["XOC@rate", "BOA@warmup:40", "ECC@rate"]);
    for l in &left_out {
        assert!(
            l.reason.contains("changes with time"),
            "{}: {}",
            l.term,
            l.reason
        );
    }
    assert_eq!(left_out[0].values, [Some(2e-5)]);
    let kept: Vec<&str> = errors.terms().iter().map(|t| t.spelling.as_str()).collect();
    assert_eq!(kept, ["XOC"]);
}

#[test]
fn a_warm_up_refuses_samples_before_its_start_and_a_rate_does_not() {
    let m = builtin("seed-ac");
    let rec = k4_timed(&m, 1.0, -3.0);
    let p = m.default_parameters();
    let e = h_matrix_auto(&m, &model(&m, &["XOC", "EXZ@warmup:40"]), &rec, &p).unwrap_err();
    match &e {
        HMatrixError::Times { term, message } => {
            assert_eq!(term, "EXZ@warmup:40");
            assert!(
                message.contains("sample 1 is at -3 s, before it"),
                "{message}"
            );
        }
        other => panic!("{other}"),
    }
    let h = h_matrix_auto(&m, &model(&m, &["dx0@rate"]), &rec, &p).unwrap();
    assert_eq!(h[(0, 0)], -3.0);
    let t = formats::truth::parse_truth("t.toml", "[errors]\nEXZ = { \"warmup:40\" = 3.0 }\n", &m)
        .unwrap();
    let e = simulate(&m, &t, &rec).unwrap_err().to_string();
    assert!(e.contains("before it"), "{e}");
    // Without real times neither can be evaluated.
    let mut numbered = k4_timed(&m, 1.0, 0.0);
    for s in &mut numbered.samples {
        s.timed = false;
    }
    for s in ["dx0@rate", "EXZ@warmup:40"] {
        let e = h_matrix_auto(&m, &model(&m, &[s]), &numbered, &p).unwrap_err();
        assert!(e.to_string().contains("needs the real sample times"), "{e}");
    }
}
