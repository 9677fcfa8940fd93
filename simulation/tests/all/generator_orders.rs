//! The reversed and there-and-back versions of every generated test (`T-rev`, `T-back`): the
//! same poses in the reverse order, or forward then reversed in one record with the turning
//! point once, times from 0; the same checks, the failing sample counted in their own order.

use crate::common;

use common::fixture;
use model_spec::Machine;
use simulation::generator::{
    GeneratorError, GeneratorOptions, MAX_SAMPLES, Order, generate, generate_test, lookup_test,
    tests, tests_with_orders,
};
use simulation::record::Record;

/// Every built-in machine and the fixture machines with rotary axes.
fn machines() -> Vec<Machine> {
    let mut all = model_spec::all_builtin();
    for f in [
        "tests/machines/head-head-ca.toml",
        "codegen/tests/machines/one-rotary.toml",
    ] {
        all.push(fixture(f));
    }
    all
}

fn commands(r: &Record) -> Vec<Vec<u64>> {
    r.samples
        .iter()
        .map(|s| s.commands.iter().map(|x| x.to_bits()).collect())
        .collect()
}

fn times(r: &Record) -> Vec<f64> {
    r.samples.iter().map(|s| s.t).collect()
}

#[test]
fn every_test_reversed_and_there_and_back_is_the_same_poses_in_that_order() {
    let o = GeneratorOptions {
        period_s: 2.0,
        ..GeneratorOptions::default()
    };
    let mut count = 0;
    for m in machines() {
        let p = m.default_parameters();
        for t in tests(&m) {
            let forward = generate_test(&m, &t, &p, &o).unwrap();
            let n = forward.samples.len();
            let fwd = commands(&forward);
            let rev = generate(&m, &format!("{}-rev", t.name), &p, &o)
                .unwrap_or_else(|e| panic!("{} {}-rev: {e}", m.name, t.name));
            let mut expected = fwd.clone();
            expected.reverse();
            assert_eq!(commands(&rev), expected, "{} {}-rev", m.name, t.name);
            let back = generate(&m, &format!("{}-back", t.name), &p, &o)
                .unwrap_or_else(|e| panic!("{} {}-back: {e}", m.name, t.name));
            let mut expected = fwd.clone();
            expected.extend(fwd.iter().rev().skip(1).cloned());
            assert_eq!(commands(&back), expected, "{} {}-back", m.name, t.name);
            assert_eq!(back.samples.len(), 2 * n - 1);
            // Times from 0 again, one period apart.
            for r in [&rev, &back] {
                let want: Vec<f64> = (0..r.samples.len()).map(|i| i as f64 * 2.0).collect();
                assert_eq!(times(r), want, "{} {}", m.name, t.name);
            }
            count += 1;
        }
    }
    assert!(count > 20, "{count} tests");
}

#[test]
fn the_list_has_every_test_then_its_reversed_and_there_and_back_versions() {
    let m = model_spec::builtin("table-table-bc").unwrap().unwrap();
    let all = tests_with_orders(&m, &Default::default());
    let names: Vec<&str> = all.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "turn-B",
            "turn-B-rev",
            "turn-B-back",
            "turn-C",
            "turn-C-rev",
            "turn-C-back",
            "pair-B-C",
            "pair-B-C-rev",
            "pair-B-C-back"
        ]
    );
    let back = &all[2];
    assert_eq!(back.order, Order::ThereAndBack);
    assert_eq!(
        back.description,
        "there and back (the poses forward, then reversed, the turning point once): B turns -90° .. 90° (where the tool axis stays within 90° of the table normal) in 1° steps, C at 0° (361 samples)"
    );
    assert_eq!(
        all[1].description,
        "reversed (the same poses from the last to the first): B turns -90° .. 90° (where the tool axis stays within 90° of the table normal) in 1° steps, C at 0° (181 samples)"
    );
    // Names without regard to case; a version of a version is no test.
    let base = tests(&m);
    assert_eq!(
        lookup_test(&base, "TURN-b-Back").unwrap().name,
        "turn-B-back"
    );
    assert_eq!(
        lookup_test(&base, " pair-b-c-REV ").unwrap().name,
        "pair-B-C-rev"
    );
    assert!(lookup_test(&base, "turn-B-rev-back").is_none());
    assert!(lookup_test(&base, "turn-A-back").is_none());
    let e = generate(
        &m,
        "turn-B-rev-rev",
        &m.default_parameters(),
        &Default::default(),
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("machine table-table-bc has no test `turn-B-rev-rev`"),
        "{e}"
    );
}

#[test]
fn a_sample_out_of_stroke_is_counted_in_the_version_s_own_order() {
    let m = model_spec::builtin("seed-ac").unwrap().unwrap();
    let mut p = m.default_parameters();
    p[m.symbol_by_name("Xw").unwrap()] = -450.0;
    let o = GeneratorOptions::default();
    let at = |name: &str| match generate(&m, name, &p, &o).unwrap_err() {
        GeneratorError::Sample(s) => (s.at.sample, s.at.samples, s.at.test.clone()),
        e => panic!("{e}"),
    };
    let (first, n, _) = at("turn-C");
    assert_eq!(n, 361);
    // Reversed, the first sample out of the stroke is the last of the forward run's
    // excursion, counted from the end.
    let (rev, n_rev, name) = at("turn-C-rev");
    assert_eq!((n_rev, name.as_str()), (361, "turn-C-rev"));
    assert!(rev < n - 1 - first, "{rev} {first}");
    let (back, n_back, _) = at("turn-C-back");
    assert_eq!((back, n_back), (first, 721));
}

#[test]
fn there_and_back_counts_its_samples_against_the_limit() {
    let m = model_spec::builtin("seed-ac").unwrap().unwrap();
    let p = m.default_parameters();
    // 360° / 0.006° = 60 000 steps: 60 001 samples forward, 120 001 there and back.
    let o = GeneratorOptions {
        step_deg: Some(0.006),
        ..GeneratorOptions::default()
    };
    assert_eq!(
        generate(&m, "turn-C", &p, &o).unwrap().samples.len(),
        60_001
    );
    assert_eq!(
        generate(&m, "turn-C-rev", &p, &o).unwrap().samples.len(),
        60_001
    );
    let e = generate(&m, "turn-C-back", &p, &o).unwrap_err();
    assert!(
        matches!(e, GeneratorError::TooManySamples { max, .. } if max == MAX_SAMPLES),
        "{e}"
    );
}
