//! The trend of one error and its flags: which checks make a series (and why the others are
//! left out), the three tests on hand-made series, their false-alarm rates on 2000 stable
//! series, how soon they see a drift of 0.5 µm per check on 2000 drifting series, and the same
//! drift through the real pipeline (simulated K4 records on seed-ac, identified, recorded,
//! read back, flagged).

use crate::common;
use crate::one_record::identify_refined_one;

use common::{TempDir, check};
use history::trend::{
    Assessment, Options, Point, Series, SeriesHead, Test, TrendError, assess, select, slope,
};
use history::{Check, Provenance, RecordedCheck, Store, Timestamp};
use simulation::rng::Rng;

const ALPHA: f64 = 0.01;

/// Monday 2025-01-06, 08:00 UTC: the first check.
fn start() -> Timestamp {
    Timestamp::parse("2025-01-06T08:00:00Z").unwrap()
}

/// A series of XOC values (µm) with their uncertainties, one check a week.
fn series(values: &[(f64, f64)]) -> Series {
    Series {
        head: SeriesHead {
            machine_id: "M123".into(),
            parameter: "XOC".into(),
            unit: "um".into(),
            fingerprint: "fa038fe9e24c960a".into(),
            machine: "seed-ac".into(),
            model: "reduced".into(),
            terms: vec!["XOC".into()],
            paths: vec!["K4".into()],
            constraint: "none".into(),
        },
        reference: 1,
        points: values
            .iter()
            .enumerate()
            .map(|(i, &(value, std))| Point {
                id: i as i64 + 1,
                at: Timestamp(start().0 + 7 * 86_400 * i as i64),
                value,
                std,
            })
            .collect(),
        left_out: vec![],
    }
}

fn recorded(id: i64, check: Check) -> RecordedCheck {
    RecordedCheck { id, check }
}

fn flagged(a: &Assessment, row: usize, test: Test) -> bool {
    a.rows[row].flags.iter().any(|f| f.test == test)
}

/// The 1-based check of the first flag of `test`, 0 for none.
fn first(a: &Assessment, test: Test) -> usize {
    a.rows
        .iter()
        .position(|r| r.flags.iter().any(|f| f.test == test))
        .map_or(0, |i| i + 1)
}

#[test]
fn a_series_keeps_comparable_checks_and_says_why_it_leaves_the_others_out() {
    let mut checks = Vec::new();
    checks.push(recorded(1, check("M123", 0, 10.0, 0.3)));
    let mut other_machine = check("M124", 1, 99.0, 0.3);
    other_machine.fingerprint = "0000000000000000".into();
    checks.push(recorded(2, other_machine));
    let mut description = check("M123", 7, 10.1, 0.3);
    description.fingerprint = "1111111111111111".into();
    checks.push(recorded(3, description));
    let mut model = check("M123", 14, 10.2, 0.3);
    model.terms.push("ECC@harmonic:2".into());
    model.model = "reduced + ECC@harmonic:2".into();
    checks.push(recorded(4, model));
    let mut paths = check("M123", 21, 10.3, 0.3);
    paths.paths = vec!["K1".into(), "K2".into()];
    checks.push(recorded(5, paths));
    let mut constraint = check("M123", 28, 10.4, 0.3);
    constraint.constraint = "zero: YOA".into();
    checks.push(recorded(6, constraint));
    let mut undetermined = check("M123", 35, 10.5, 0.3);
    undetermined.parameters[0].value = None;
    undetermined.parameters[0].std = None;
    undetermined.parameters[0].determined = false;
    checks.push(recorded(7, undetermined));
    let mut no_std = check("M123", 42, 10.6, 0.3);
    no_std.parameters[0].std = None;
    checks.push(recorded(8, no_std));
    // Same model and paths, spelled in another order and case: in the series.
    let mut same = check("M123", 49, 10.7, 0.3);
    same.terms.reverse();
    same.paths = vec!["k4".into()];
    checks.push(recorded(9, same));
    checks.push(recorded(10, check("M123", 56, 10.8, 0.3)));

    let s = select(&checks, "M123", "x0c", None, false).unwrap();
    assert_eq!(s.head.parameter, "XOC");
    assert_eq!(s.head.unit, "um");
    assert_eq!(s.reference, 10);
    assert_eq!(
        s.points.iter().map(|p| p.id).collect::<Vec<_>>(),
        [1, 9, 10]
    );
    let reasons: Vec<(i64, &str)> = s
        .left_out
        .iter()
        .map(|l| (l.id, l.reason.as_str()))
        .collect();
    let expect = [
        (3, "another machine description"),
        (4, "another model (reduced + ECC@harmonic:2"),
        (5, "other test paths (K1, K2; the series measured K4)"),
        (6, "another constraint (zero: YOA; the series' is none)"),
        (7, "XOC was not determined by the data"),
        (8, "XOC has no uncertainty"),
    ];
    assert_eq!(reasons.len(), expect.len(), "{reasons:?}");
    for ((id, reason), (eid, needle)) in reasons.iter().zip(expect) {
        assert_eq!(*id, eid);
        assert!(reason.contains(needle), "{id}: {reason}");
    }
    // A chosen baseline defines the series: check 4's model.
    let s = select(&checks, "M123", "XOC", Some(4), false).unwrap();
    assert_eq!(s.points.iter().map(|p| p.id).collect::<Vec<_>>(), [4]);
    assert_eq!(s.head.model, "reduced + ECC@harmonic:2");

    // Errors, each with what is known.
    match select(&checks, "M999", "XOC", None, false).unwrap_err() {
        TrendError::UnknownMachine { known, .. } => assert_eq!(known, ["M123", "M124"]),
        e => panic!("{e}"),
    }
    let e = select(&checks, "M123", "XOD", None, false).unwrap_err();
    assert_eq!(
        e.to_string(),
        "no check of machine `M123` identified `XOD` (its parameters: XOC, AOC)"
    );
    assert_eq!(
        select(&[], "M123", "XOC", None, false).unwrap_err(),
        TrendError::EmptyHistory
    );
    for (id, needle) in [
        (2, "not a check of machine M123"),
        (7, "not determined"),
        (8, "no uncertainty"),
    ] {
        let e = select(&checks, "M123", "XOC", Some(id), false)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("check {id} cannot be the baseline")) && e.contains(needle),
            "{e}"
        );
    }
    let only_undetermined = vec![recorded(7, checks[6].check.clone())];
    let e = select(&only_undetermined, "M123", "XOC", None, false).unwrap_err();
    assert!(matches!(e, TrendError::NeverDetermined { .. }), "{e}");
}

#[test]
fn the_three_tests_on_a_hand_made_series() {
    // 0.3 µm each; a step of 2 µm at check 4 (z = 2/√0.18 = 4.71 > 2.576).
    let s = series(&[(4.0, 0.3), (4.2, 0.3), (3.9, 0.3), (6.0, 0.3), (5.4, 0.3)]);
    let a = assess(
        &s,
        &Options {
            alpha: ALPHA,
            baseline: None,
            tolerance: Some(5.0),
        },
    )
    .unwrap();
    assert_eq!(a.baseline, 1);
    assert!((a.z - 2.575_829_3).abs() < 1e-6);
    assert_eq!(a.rows[0].change_z, None);
    for (row, tol, base) in [
        (0, false, false),
        (1, false, false),
        (2, false, false),
        (3, true, true),
        (4, true, true),
    ] {
        assert_eq!(flagged(&a, row, Test::Tolerance), tol, "row {row}");
        assert_eq!(flagged(&a, row, Test::Baseline), base, "row {row}");
    }
    let t4 = &a.rows[3].flags[0];
    assert_eq!(t4.test, Test::Tolerance);
    assert!(t4.text.contains("nonconformance proven"), "{}", t4.text);
    let t5 = &a.rows[4].flags[0];
    assert!(t5.text.contains("not proven"), "{}", t5.text); // 5.4 − 0.6 < 5
    let b4 = &a.rows[3].flags[1];
    assert!((b4.statistic - 2.0 / 0.18f64.sqrt()).abs() < 1e-12);
    assert!(
        b4.text.contains("changed by +2.000 µm since check 1"),
        "{}",
        b4.text
    );
    // Fewer than three checks: no slope.
    assert!(a.rows[1].slope.is_none());
    assert!(a.rows[2].slope.is_some());

    // Another baseline: check 4; the rows before it are compared, but get no trend.
    let a = assess(
        &s,
        &Options {
            baseline: Some(4),
            ..Options::default()
        },
    )
    .unwrap();
    assert_eq!(a.baseline, 4);
    assert!(flagged(&a, 0, Test::Baseline));
    assert!(!flagged(&a, 4, Test::Baseline));
    assert!(a.rows[..4].iter().all(|r| r.slope.is_none()));
    assert!(a.trend.is_none(), "two checks from the baseline on");
    let e = assess(
        &s,
        &Options {
            baseline: Some(9),
            ..Options::default()
        },
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("check 9 cannot be the baseline"),
        "{e}"
    );
    for bad in [0.0, 0.5, f64::NAN] {
        assert!(
            assess(
                &s,
                &Options {
                    alpha: bad,
                    ..Options::default()
                }
            )
            .is_err()
        );
    }
    // Numbers in the message are short.
    let e = assess(
        &s,
        &Options {
            alpha: 1e-320,
            ..Options::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.ends_with("the level alpha must be between 1e-6 and 0.2, not 9.99989e-321"),
        "{e}"
    );
    assert!(
        assess(
            &s,
            &Options {
                tolerance: Some(-1.0),
                ..Options::default()
            }
        )
        .is_err()
    );
}

#[test]
fn the_slope_is_weighted_least_squares_scaled_by_the_scatter() {
    // Equal weights: ordinary least squares, by hand. x = 0, 7, 14, 21 days.
    let ys = [1.0, 1.9, 3.2, 3.9];
    let s = series(&ys.map(|y| (y, 0.5)));
    let fit = slope(&s.points, ALPHA).unwrap();
    let xs = [0.0, 7.0, 14.0, 21.0];
    let (xm, ym) = (10.5, ys.iter().sum::<f64>() / 4.0);
    let sxx: f64 = xs.iter().map(|x| (x - xm) * (x - xm)).sum();
    let b = xs
        .iter()
        .zip(&ys)
        .map(|(x, y)| (x - xm) * (y - ym))
        .sum::<f64>()
        / sxx;
    let rss: f64 = xs
        .iter()
        .zip(&ys)
        .map(|(x, y)| (y - ym - b * (x - xm)).powi(2))
        .sum();
    let se = (rss / 2.0 / sxx).sqrt(); // the scale from the scatter; σ cancels
    assert!((fit.per_day - b).abs() < 1e-12);
    assert!((fit.std_per_day - se).abs() < 1e-12);
    assert!((fit.scatter_ratio - (rss / 2.0 / 0.25).sqrt()).abs() < 1e-12);
    assert_eq!((fit.checks, fit.dof, fit.from, fit.to), (4, 2, 1, 4));
    assert!((fit.critical - 9.924_843_200_918_29).abs() < 1e-9);
    assert!((fit.t - b / se).abs() < 1e-9);
    assert_eq!(fit.flagged, fit.t.abs() > fit.critical);
    // Weights: a check 10 times less precise hardly moves the slope.
    let w = series(&[(0.0, 0.1), (1.0, 0.1), (2.0, 0.1), (30.0, 1.0)]);
    let fit = slope(&w.points, ALPHA).unwrap();
    assert!(fit.per_day < 0.5, "{}", fit.per_day);
    // Checks exactly on a line: the recorded uncertainties give the standard error.
    let line = series(&[(0.0, 0.5), (0.7, 0.5), (1.4, 0.5)]);
    let fit = slope(&line.points, ALPHA).unwrap();
    assert!((fit.per_day - 0.1).abs() < 1e-12);
    assert!((fit.std_per_day - (0.25f64 / 98.0).sqrt()).abs() < 1e-12);
    // No time span: no slope.
    let mut same_time = series(&[(0.0, 0.5), (1.0, 0.5), (2.0, 0.5)]);
    for p in &mut same_time.points {
        p.at = start();
    }
    assert!(slope(&same_time.points, ALPHA).is_none());
}

#[test]
fn a_row_depends_only_on_the_checks_before_it() {
    let mut rng = Rng::new(11);
    let values: Vec<(f64, f64)> = (0..12)
        .map(|k| (k as f64 * 0.3 + 0.4 * rng.normal(), 0.4))
        .collect();
    let whole = assess(&series(&values), &Options::default()).unwrap();
    for n in 1..values.len() {
        let part = assess(&series(&values[..n]), &Options::default()).unwrap();
        assert_eq!(
            part.rows[..],
            whole.rows[..n],
            "rows of the first {n} checks"
        );
    }
}

/// 20 checks a week apart, σ drawn in [0.3, 0.5] µm; from check 8 on the error drifts by
/// `drift` µm per check (check 8 is `drift` above the first seven), `extra` times σ of
/// scatter between checks added that the recorded σ does not hold.
fn simulated(rng: &mut Rng, drift: f64, extra: f64) -> Vec<(f64, f64)> {
    (1..=20)
        .map(|k: i32| {
            let std = rng.uniform_in(0.3, 0.5);
            let d = drift * f64::from((k - 7).max(0));
            (
                10.0 + d + std * rng.normal() + extra * std * rng.normal(),
                std,
            )
        })
        .collect()
}

/// Rates of flags on `n` stable series: (baseline per check, its standard error from the
/// spread between series, trend per row, whole-series trend, series with any baseline flag,
/// series with any trend flag).
fn false_alarms(seed: u64, n: usize, extra: f64) -> [f64; 6] {
    let mut rng = Rng::new(seed);
    let (mut per_series, mut trend_rows, mut rows, mut whole, mut any_b, mut any_t) =
        (Vec::new(), 0usize, 0usize, 0usize, 0usize, 0usize);
    for _ in 0..n {
        let a = assess(
            &series(&simulated(&mut rng, 0.0, extra)),
            &Options::default(),
        )
        .unwrap();
        let b = (1..20).filter(|&i| flagged(&a, i, Test::Baseline)).count();
        let t = (0..20).filter(|&i| flagged(&a, i, Test::Trend)).count();
        per_series.push(b as f64 / 19.0);
        trend_rows += t;
        rows += a.rows.iter().filter(|r| r.slope.is_some()).count();
        whole += usize::from(a.trend.as_ref().unwrap().flagged);
        any_b += usize::from(b > 0);
        any_t += usize::from(t > 0);
    }
    let nf = n as f64;
    let mean = per_series.iter().sum::<f64>() / nf;
    let var = per_series.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / (nf - 1.0);
    [
        mean,
        (var / nf).sqrt(),
        trend_rows as f64 / rows as f64,
        whole as f64 / nf,
        any_b as f64 / nf,
        any_t as f64 / nf,
    ]
}

#[test]
fn false_alarm_rates_on_2000_stable_series_are_alpha() {
    // Values simulated directly (the identified value is its truth plus Gaussian noise of the
    // recorded σ; the real pipeline's σ are checked honest in the pipeline test below).
    let n = 2000;
    let [b, b_se, rows, whole, any_b, any_t] = false_alarms(2024, n, 0.0);
    println!(
        "2000 stable series of 20 checks, α = {ALPHA}: baseline test per check {b:.4} (± {b_se:.4}); trend test per row {rows:.4}, over the whole series {whole:.4}; series with any baseline flag {any_b:.3}, with any trend flag {any_t:.3}"
    );
    // Both tests have the level α by construction: the measured rates agree within their
    // sampling error (3 standard errors above, none is below what chance allows).
    assert!(b <= ALPHA + 3.0 * b_se, "baseline {b} ± {b_se}");
    assert!(b >= ALPHA - 3.0 * b_se, "baseline {b} ± {b_se}");
    let whole_se = (ALPHA * (1.0 - ALPHA) / n as f64).sqrt();
    assert!(
        whole <= ALPHA + 3.0 * whole_se,
        "whole-series trend {whole}"
    );
    assert!((rows - ALPHA).abs() <= 0.003, "trend per row {rows}");
    // Repeated tests add up: a series of 20 checks shows some flag far more often than α
    // (at most 19 tests of each kind at α each).
    assert!(any_b > 3.0 * ALPHA && any_b < 19.0 * ALPHA, "{any_b}");
    assert!(any_t > 3.0 * ALPHA && any_t < 18.0 * ALPHA, "{any_t}");

    // Checks that scatter twice as much again as their σ say (set-up, temperature): the trend
    // test, scaled by the scatter, keeps its level; the baseline test, by its definition
    // (the check's own σ), does not.
    let [b, _, rows, whole, _, _] = false_alarms(2025, n, 2.0);
    println!(
        "with twice σ of extra scatter: baseline per check {b:.4}; trend per row {rows:.4}, over the whole series {whole:.4}"
    );
    assert!(b > 0.15, "{b}");
    assert!(whole <= ALPHA + 3.0 * whole_se, "{whole}");
    assert!((rows - ALPHA).abs() <= 0.003, "trend per row {rows}");
}

/// The detectable size of a change against the baseline at the largest σ (0.5 µm): the change
/// the baseline test sees half of the time, `z·√(σ_b² + σ²)`; and the first check whose drift
/// reaches it at 0.5 µm per check from check 8.
fn detectable() -> (f64, usize) {
    let size = history::stats::normal_two_sided(ALPHA) * (2.0f64 * 0.5 * 0.5).sqrt();
    let check = (8..=20).find(|&k| 0.5 * (k - 7) as f64 >= size).unwrap();
    (size, check)
}

#[test]
fn a_drift_of_half_a_micrometre_per_check_is_flagged_soon_after_it_is_detectable() {
    let (size, crossing) = detectable();
    assert_eq!(crossing, 11, "{size}");
    let mut rng = Rng::new(7);
    let n = 2000;
    let (mut hb, mut ht) = ([0usize; 21], [0usize; 21]);
    for _ in 0..n {
        let a = assess(&series(&simulated(&mut rng, 0.5, 0.0)), &Options::default()).unwrap();
        hb[first(&a, Test::Baseline)] += 1;
        ht[first(&a, Test::Trend)] += 1;
    }
    println!("detectable change {size:.3} µm, reached at check {crossing}");
    println!("first baseline flag, series per check (0: none): {hb:?}");
    println!("first trend flag, series per check (0: none):    {ht:?}");
    let share = |h: &[usize; 21], r: std::ops::RangeInclusive<usize>| {
        h[r].iter().sum::<usize>() as f64 / n as f64
    };
    // Before the drift starts (checks 2-7) only false alarms: at most six tests at α each.
    let bound = 6.0 * ALPHA + 3.0 * (6.0 * ALPHA / n as f64).sqrt();
    assert!(share(&hb, 1..=7) <= bound, "{hb:?}");
    assert!(share(&ht, 1..=7) <= bound, "{ht:?}");
    // Every series is flagged: the change within two checks of reaching the detectable size
    // in 99 % of the series, the trend within three.
    assert_eq!(hb[0] + ht[0], 0);
    assert!(share(&hb, 1..=crossing + 2) >= 0.99, "{hb:?}");
    assert!(share(&ht, 1..=crossing + 3) >= 0.99, "{ht:?}");
}

/// The reduced truth of seed-ac with XOC = `xoc` µm and reading noise `noise_um`.
fn truth_text(xoc: f64, noise_um: f64, seed: u64) -> String {
    format!(
        "machine = \"seed-ac\"\nnoise_um = {noise_um}\nseed = {seed}\n[errors]\nXOW = 12.0\nYOW = -18.0\nZOW = 15.0\nYOA = 20.0\nZOA = -15.0\nBOA = 25.0\nCOA = -18.0\nXOC = {xoc}\nYOC = -22.0\nAOC = 30.0\nBOC = -12.0\n"
    )
}

#[test]
fn the_real_pipeline_flags_a_drifting_location_error() {
    use crate::one_report::{IdentificationSource, report_of_one};
    use fitting::{IdentifyOptions, RefineOptions};
    use simulation::model::Model;
    use simulation::{builtin_path, simulate};

    let m = model_spec::builtin("seed-ac").unwrap().unwrap();
    let model = Model::of(&m, "reduced").unwrap();
    let k4 = builtin_path(&m, "K4").unwrap().unwrap();
    let d = TempDir::new("trend", "pipeline");
    let db = d.join("h.sqlite");
    let mut store = Store::open_or_create(&db).unwrap();
    let mut rng = Rng::new(42);
    let series_count = 10;
    // Reading noise 0.5-0.8 µm: the identified σ of XOC on K4 is then 0.3-0.5 µm.
    for s in 0..series_count {
        for k in 1..=20i64 {
            let noise = rng.uniform_in(0.5, 0.8);
            let xoc = 10.0 + 0.5 * (k - 7).max(0) as f64;
            let seed = 1000 * s + k as u64;
            let t =
                formats::truth::parse_truth("truth", &truth_text(xoc, noise, seed), &m).unwrap();
            let record = simulate(&m, &t, &k4).unwrap();
            let (ident, refinement) = identify_refined_one(
                &m,
                &model,
                &record,
                &IdentifyOptions::default(),
                &RefineOptions::default(),
            )
            .unwrap();
            let source = IdentificationSource {
                data: "k4.csv",
                label: "reduced",
                base_model: Some("reduced"),
            };
            let report = report_of_one(&m, source, &ident, Some(&refinement)).unwrap();
            let at = Timestamp(start().0 + 7 * 86_400 * (k - 1));
            let check = Check::from_identification(
                &report,
                Provenance {
                    machine_id: format!("S{s}"),
                    paths: vec!["K4".into()],
                    measured_at: at,
                    recorded_at: at,
                    rtest_version: "test".into(),
                    inputs: vec![],
                },
            );
            store.record(&check).unwrap();
        }
    }
    drop(store);
    let store = Store::open(&db).unwrap();
    let all = store.checks(None).unwrap();
    assert_eq!(all.len(), 20 * series_count as usize);
    let (_, crossing) = detectable();
    let (mut zs, mut firsts) = (Vec::new(), Vec::new());
    for s in 0..series_count {
        let series = select(&all, &format!("S{s}"), "XOC", None, false).unwrap();
        assert_eq!(series.points.len(), 20);
        assert!(series.left_out.is_empty());
        for (k, p) in series.points.iter().enumerate() {
            assert!((0.25..=0.6).contains(&p.std), "σ {}", p.std);
            let truth = 10.0 + 0.5 * (k as f64 + 1.0 - 7.0).max(0.0);
            zs.push((p.value - truth) / p.std);
        }
        let a = assess(&series, &Options::default()).unwrap();
        firsts.push((first(&a, Test::Baseline), first(&a, Test::Trend)));
    }
    println!("first (baseline, trend) flags per series, checks 1-20: {firsts:?}");
    // The recorded σ are honest: the values scatter about the truth by their σ.
    let var = zs.iter().map(|z| z * z).sum::<f64>() / zs.len() as f64;
    println!(
        "mean square of (v − truth)/σ over {} checks: {var:.3}",
        zs.len()
    );
    assert!(
        (0.75..=1.3).contains(&var),
        "variance of (v − truth)/σ: {var}"
    );
    // Every series flags the drift by two (change) and three (trend) checks after it reached
    // the detectable size; early flags (false alarms before check 8) in at most 2 series of 10.
    assert!(
        firsts
            .iter()
            .all(|&(b, t)| b > 0 && b <= crossing + 2 && t > 0 && t <= crossing + 3),
        "{firsts:?}"
    );
    let early = firsts.iter().filter(|&&(b, t)| b < 8 || t < 8).count();
    assert!(early <= 2, "{firsts:?}");
}

/// A drift's rate (`um/s`) names its CSV columns with `_per_` for the slash, so that every
/// header name is a plain identifier; a fraction (`1`) has no suffix.
#[test]
fn the_csv_header_names_a_rate_unit_without_a_slash() {
    let header = |unit: &str| {
        let mut s = series(&[(4.0, 0.3), (4.2, 0.3), (3.9, 0.3)]);
        s.head.unit = unit.into();
        let a = assess(&s, &Options::default()).unwrap();
        let csv = history::report::TrendReport::new("h.db", &s, a, None).csv();
        csv.lines().nth(1).unwrap().to_string()
    };
    let rate = header("um/s");
    assert!(
        rate.starts_with("check,measured_at,value_um_per_s,std_um_per_s,change_um_per_s,"),
        "{rate}"
    );
    assert!(rate.contains(",slope_um_per_s_per_day,"), "{rate}");
    assert!(!rate.contains('/'), "{rate}");
    let fraction = header("1");
    assert!(
        fraction.starts_with("check,measured_at,value,std,change,"),
        "{fraction}"
    );
}

/// Re-checks make their own series: the calibrations' series leaves them out and says why, and
/// `rechecks` trends them alone, the calibrations left out.
#[test]
fn rechecks_and_calibrations_are_two_series() {
    let mut checks = Vec::new();
    for (id, day, recheck) in [(1, 0, false), (2, 7, true), (3, 14, true), (4, 21, false)] {
        let mut c = check("M123", day, 10.0 + id as f64 * 0.1, 0.3);
        c.recheck = recheck;
        checks.push(recorded(id, c));
    }
    let s = select(&checks, "M123", "XOC", None, false).unwrap();
    assert_eq!(s.points.iter().map(|p| p.id).collect::<Vec<_>>(), [1, 4]);
    assert_eq!(s.reference, 4);
    assert!(
        s.left_out
            .iter()
            .all(|l| l.reason.contains("a re-check (its own series")),
        "{:?}",
        s.left_out
    );
    let s = select(&checks, "M123", "XOC", None, true).unwrap();
    assert_eq!(s.points.iter().map(|p| p.id).collect::<Vec<_>>(), [2, 3]);
    assert_eq!(s.reference, 3);
    assert_eq!(
        s.left_out.iter().map(|l| l.id).collect::<Vec<_>>(),
        [1, 4],
        "{:?}",
        s.left_out
    );
    assert!(
        s.left_out[0]
            .reason
            .contains("a calibration, not a re-check")
    );
}
