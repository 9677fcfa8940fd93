//! The plan separates a position error of an axis from a drift in time: on `turn-B` of
//! `table-table-bc`, B turns monotonically in time, so that B's angular error and a drift of the
//! C table's tilt explain nearly the same readings; the plan's candidates include `turn-B-rev`
//! and `turn-B-back`, and the addition it names is one of them.

use fitting::Tolerances;
use fitting::noise::{NoiseModel, NoiseSource};
use fitting::plan::separate::{self, Separation};
use fitting::plan::{BASE_BALL, BallPosition, CandidateSet, Plan, PlannedTest, candidates};
use model_spec::{Machine, builtin};
use simulation::generator::GeneratorOptions;
use simulation::model::{Model, Term};

fn machine() -> Machine {
    builtin("table-table-bc").unwrap().unwrap()
}

fn plan(m: &Machine, tests: &[&str]) -> Plan {
    Plan {
        balls: vec![BallPosition {
            name: BASE_BALL.into(),
            params: m.default_parameters(),
        }],
        tests: tests
            .iter()
            .map(|t| PlannedTest {
                test: t.to_string(),
                ball: 0,
            })
            .collect(),
        zeroed: false,
        shared_setup: false,
        generator: GeneratorOptions::default(),
    }
}

/// The plan of `terms` on `tests` at the base ball position: its separation.
fn separation(m: &Machine, terms: &str, tests: &[&str]) -> (Option<Separation>, CandidateSet) {
    let model = Model {
        terms: terms
            .split(',')
            .map(|t| Term::parse(m, t).unwrap())
            .collect(),
    };
    let p = plan(m, tests);
    let noise = NoiseModel::white(0.5e-3, NoiseSource::Declared);
    let tol = Tolerances::default();
    let predicted = p.predict(m, &model, &noise, &tol).unwrap();
    let set = candidates::candidates(m, &p, 100.0).unwrap();
    let sep =
        separate::separation(m, &model, &p, &predicted.prediction, &set, &noise, &tol).unwrap();
    (sep, set)
}

#[test]
fn the_plan_names_turn_b_there_and_back_to_separate_b_s_error_from_a_record_s_drift() {
    let m = machine();
    let (sep, set) = separation(&m, "EBB@harmonic:1,BOC@time:1", &["turn-B"]);
    let sep = sep.expect("turn-B does not separate B's error from the drift");
    let first = &sep.pairs[0];
    assert_eq!(first.time, "BOC@time:1[turn-B]");
    assert!(first.position.starts_with("EBB@harmonic:1:"));
    assert!(first.correlation.abs() > 0.95, "{first:?}");
    // The candidates: turn-B reversed and there and back at the planned position.
    let tests: Vec<&str> = sep
        .candidates
        .iter()
        .map(|c| set.candidates[c.candidate].test.as_str())
        .collect();
    assert_eq!(tests, ["turn-B-back", "turn-B-rev"]);
    // There and back on the record's clock separates a record's own drift; reversed, on a clock
    // of its own with a drift of its own, it does not.
    let (back, rev) = (&sep.candidates[0], &sep.candidates[1]);
    assert!(back.largest < 0.7, "{back:?}");
    assert!(rev.largest > 0.9, "{rev:?}");
    println!(
        "turn-B: {:.4}; with turn-B-back {:.4}, with turn-B-rev {:.4}",
        first.correlation, back.largest, rev.largest
    );
}

#[test]
fn a_plan_that_separates_them_says_nothing() {
    let m = machine();
    let (sep, _) = separation(&m, "EBB@harmonic:1,BOC@time:1", &["turn-B-back"]);
    assert!(sep.is_none(), "{sep:?}");
    // Nor a model without a term of time.
    let (sep, _) = separation(&m, "EBB@harmonic:1,BOC", &["turn-B"]);
    assert!(sep.is_none(), "{sep:?}");
}

#[test]
fn the_candidates_hold_the_other_orders_of_the_planned_tests() {
    let m = machine();
    let p = plan(&m, &["turn-B", "pair-B-C-rev"]);
    let tests = candidates::candidate_tests(&m, &p);
    let names: Vec<&str> = tests.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "turn-B",
            "turn-C",
            "pair-B-C",
            "turn-B-rev",
            "turn-B-back",
            "pair-B-C-rev",
            "pair-B-C-back"
        ]
    );
}
