//! Position against time on a trunnion: on `table-table-bc` (a B trunnion about y carrying a C
//! table), a campaign of `turn-B`, `turn-C` and `pair-B-C` at two ball heights, each height one
//! mounting of the ball. In `turn-B`, B turns from −90° to 90° in time: an angular positioning
//! error of B (`EBB@harmonic:1`, a worm's once-per-turn error) and a drift in time explain the
//! same readings there. The diagnosis must not pass a drift off as the cause: it names B's error,
//! or says that it cannot tell the two apart and names the test that can (`turn-B-back`). With
//! `turn-B-back` in the campaign, B turns there and back in one record, and B's error is named.
//!
//! Five noise seeds, each must pass.

use diagnosis::separable::{self, PositionOrTime, Verdict};
use diagnosis::{DiagnoseOptions, Diagnosis, diagnose};
use formats::progress::Unwatched;
use model_spec::{Machine, builtin};
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::generator::{GeneratorOptions, generate};
use simulation::model::{Model, Term};
use simulation::readings::simulate;
use simulation::truth::Truth;

fn machine() -> Machine {
    builtin("table-table-bc").unwrap().unwrap()
}

/// The machine's errors (µm, µrad): location errors of the trunnion and of the C table, the
/// squareness of the linear axes, and B's angular positioning error once per turn (a worm's
/// eccentricity: 21 µrad of amplitude).
const MACHINE_ERRORS: &str = r#"
COY = 8.0
AOZ = -12.0
BOZ = 6.0
XOB = 15.0
ZOB = -10.0
AOB = 30.0
COB = -14.0
XOC = 9.0
YOC = -11.0
AOC = 12.0
BOC = -16.0
EBB = { "harmonic:1" = [6.0, 20.0] }
"#;

/// The machine's errors with B's error `ebb` (the bases and values of `EBB`) in place of the
/// once-per-turn error of 21 µrad.
fn errors(ebb: Option<&str>) -> String {
    match ebb {
        None => MACHINE_ERRORS.to_string(),
        Some(e) => MACHINE_ERRORS.replace(
            "EBB = { \"harmonic:1\" = [6.0, 20.0] }",
            &format!("EBB = {{ {e} }}"),
        ),
    }
}

/// The truth of one mounting of the ball at height `zw` (mm above the C table) with set-up
/// errors `setup` (µm), noise 0.5 µm, seed `seed`.
fn truth(m: &Machine, zw: f64, setup: [f64; 3], seed: u64, ebb: Option<&str>) -> Truth {
    let text = format!(
        "machine = \"table-table-bc\"\nnoise_um = 0.5\nseed = {seed}\n\n[parameters]\nZw = {zw}\n\n[errors]\n{}XOW = {}\nYOW = {}\nZOW = {}\n",
        errors(ebb),
        setup[0],
        setup[1],
        setup[2]
    );
    formats::truth::parse_truth("<trunnion>", &text, m).unwrap()
}

/// The records of `tests` at one ball height (`zw`, mm), one mounting labelled `setup`.
fn mounting(
    m: &Machine,
    tests: &[&str],
    setup: &str,
    zw: f64,
    errors: [f64; 3],
    seed: u64,
    ebb: Option<&str>,
) -> Vec<CampaignRecord> {
    let mut params = m.default_parameters();
    params[m.symbol_by_name("Zw").unwrap()] = zw;
    tests
        .iter()
        .enumerate()
        .map(|(k, test)| {
            let path = generate(m, test, &params, &GeneratorOptions::default()).unwrap();
            let t = truth(m, zw, errors, seed * 100 + k as u64, ebb);
            let measured = simulate(m, &t, &path).unwrap();
            CampaignRecord::new(
                format!("{test}:{setup}"),
                measured,
                params.clone(),
                setup,
                false,
            )
        })
        .collect()
}

fn campaign(m: &Machine, tests: &[&str], seed: u64, ebb: Option<&str>) -> Campaign {
    let mut records = mounting(m, tests, "low", 120.0, [12.0, -8.0, 5.0], seed, ebb);
    records.extend(mounting(
        m,
        tests,
        "high",
        220.0,
        [-15.0, 9.0, -6.0],
        seed + 50,
        ebb,
    ));
    Campaign::new(records).unwrap()
}

/// [`run`] at noise seeds 1 to 5, in seed order: shared out over as many threads as the
/// machine has cores (at most five; thread `w` takes the seeds `w + 1`, `w + 1 + threads`, …).
/// A whole campaign's diagnosis holds about a gigabyte at its peak: five at once took 5.2 GB
/// (two at a time: 2.1 GB) in the same time on two cores.
fn run_seeds(m: &Machine, tests: &[&str], ebb: Option<&str>) -> Vec<(u64, Diagnosis)> {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get().min(5));
    let mut all: Vec<(u64, Diagnosis)> = std::thread::scope(|scope| {
        let runs: Vec<_> = (0..threads)
            .map(|w| {
                scope.spawn(move || {
                    (1..=5u64)
                        .skip(w)
                        .step_by(threads)
                        .map(|seed| (seed, run(m, tests, seed, ebb)))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        runs.into_iter()
            .flat_map(|r| r.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
            .collect()
    });
    all.sort_by_key(|(seed, _)| *seed);
    all
}

fn run(m: &Machine, tests: &[&str], seed: u64, ebb: Option<&str>) -> Diagnosis {
    let base = Model::of(m, "location").unwrap();
    let mut o = DiagnoseOptions::default();
    o.adequacy_draws = 100;
    diagnose(
        m,
        &base,
        &campaign(m, tests, seed, ebb),
        &Campaign { records: vec![] },
        &o,
        &Unwatched,
    )
    .unwrap()
}

fn describe(m: &Machine, d: &Diagnosis) -> String {
    let mut s = String::new();
    for f in &d.findings {
        s += &format!(
            "  {} (plausible {}, size {:.3}) alternatives [{}]\n",
            f.term.spelling(m),
            f.plausible,
            f.size,
            f.alternatives
                .iter()
                .map(|t| t.spelling(m))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    s
}

fn report(m: &Machine, seed: u64, d: &Diagnosis) {
    let fit = &d.extended_fit.fit;
    let value = |n: &str| {
        let j = fit.names.iter().position(|x| x == n)?;
        Some((fit.values[j]? * 1e6, fit.std[j]? * 1e6))
    };
    println!(
        "seed {seed}: sigma {:?} base {:?}; AOZ {:?} AOB {:?}\n{}",
        fit.sigma.map(|s| s * 1e3),
        d.base_fit.fit.sigma.map(|s| s * 1e3),
        value("AOZ"),
        value("AOB"),
        describe(m, d)
    );
    for e in &d.position_or_time {
        println!(
            "  apart? {:?} {} / {} chosen {} on {:?}: {:.4} {:.4} p {:.3e} {:.3e}",
            e.verdict,
            e.position.spelling(m),
            e.time.spelling(m),
            e.chosen.spelling(m),
            e.monotonic,
            e.time_in_position,
            e.position_in_time,
            e.position_beyond_time_p,
            e.time_beyond_position_p
        );
    }
}

/// B's angular positioning error: a term of effect `EBB` that depends on B's position.
fn is_b_error(m: &Machine, t: &Term) -> bool {
    t.effect.name(m) == "EBB" && separable::position_axis(m, t).is_some()
}

/// Whether `d` names B's angular error (a finding of it, or a finding whose alternatives hold it
/// with the pair reported as one these records cannot tell apart) or reports that it cannot
/// separate it from a drift and names `turn-B-back`; why not, when it does not.
fn names_b_or_says_it_cannot(m: &Machine, d: &Diagnosis) -> Result<(), String> {
    let entry_of_b = |e: &PositionOrTime| {
        is_b_error(m, &e.position)
            && e.axis == "B"
            && e.separating.first().map(String::as_str) == Some("turn-B-back")
    };
    let found = d.findings.iter().any(|f| is_b_error(m, &f.term));
    let reported = d.position_or_time.iter().any(entry_of_b);
    let as_alternative = d.findings.iter().any(|f| {
        f.alternatives.iter().any(|a| is_b_error(m, a))
            && d.position_or_time
                .iter()
                .any(|e| entry_of_b(e) && e.chosen == f.term)
    });
    if found || reported || as_alternative {
        Ok(())
    } else {
        Err(format!(
            "B's error neither named nor reported as inseparable:\n{}",
            describe(m, d)
        ))
    }
}

/// The extended fit's value and standard uncertainty of `name` (µrad).
fn urad(d: &Diagnosis, name: &str) -> Option<(f64, f64)> {
    let fit = &d.extended_fit.fit;
    let j = fit.names.iter().position(|x| x == name)?;
    Some((fit.values[j]? * 1e6, fit.std[j]? * 1e6))
}

#[test]
fn the_trunnion_campaign_names_b_s_error_or_says_it_cannot_tell_it_from_a_drift() {
    let m = machine();
    for (seed, d) in run_seeds(&m, &["turn-B", "turn-C", "pair-B-C"], None) {
        report(&m, seed, &d);
        names_b_or_says_it_cannot(&m, &d).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        // Where B's error is the finding and nothing is left undecided, the trunnion's location
        // is what the machine has (a drift standing in for it biased AOZ and AOB).
        let undecided = d
            .position_or_time
            .iter()
            .any(|e| e.verdict == Verdict::Undecided);
        if d.findings.iter().any(|f| is_b_error(&m, &f.term)) && !undecided {
            for (name, truth) in [("AOZ", -12.0), ("AOB", 30.0)] {
                let (v, s) = urad(&d, name).unwrap();
                assert!(
                    (v - truth).abs() < 4.0 * s,
                    "seed {seed}: {name} = {v} ± {s} µrad, truth {truth}"
                );
            }
        }
    }
}

#[test]
fn with_turn_b_there_and_back_in_the_campaign_b_s_error_is_named() {
    let m = machine();
    for (seed, d) in run_seeds(&m, &["turn-B", "turn-B-back", "turn-C", "pair-B-C"], None) {
        report(&m, seed, &d);
        assert!(
            d.findings.iter().any(|f| is_b_error(&m, &f.term)),
            "seed {seed}: {}",
            describe(&m, &d)
        );
        assert!(
            d.position_or_time.iter().all(|e| e.axis != "B"),
            "seed {seed}: B's error reported as not told apart with turn-B-back measured"
        );
    }
}

/// A small error of B (2.5 µrad) measured on `turn-B` alone at two heights: B turns
/// monotonically in time on every record, and the data are weak. Every seed names B's error or
/// says that it cannot tell it from a drift, with the test and the plan that separate them.
#[test]
fn a_small_error_of_b_on_turn_b_alone_is_reported_as_not_told_apart_from_a_drift() {
    let m = machine();
    let mut entries = 0;
    for seed in 1..=5 {
        let d = run(&m, &["turn-B"], seed, Some(r#""harmonic:1" = [0.5, 2.5]"#));
        report(&m, seed, &d);
        names_b_or_says_it_cannot(&m, &d).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        for e in &d.position_or_time {
            entries += 1;
            assert_eq!(e.monotonic, ["turn-B:low", "turn-B:high"], "seed {seed}");
            assert_eq!(e.separating, ["turn-B-back", "turn-B-rev"], "seed {seed}");
            assert_eq!(
                e.plan_arguments,
                [
                    "--terms".to_string(),
                    format!("{},{}", e.position.spelling(&m), e.time.spelling(&m)),
                    "--paths".into(),
                    "turn-B".into()
                ],
                "seed {seed}"
            );
            assert!(e.time.basis.of_time(), "seed {seed}");
            let finding = d.findings.iter().find(|f| f.term == e.chosen).unwrap();
            let other = if e.chosen == e.position {
                e.time
            } else {
                e.position
            };
            assert!(finding.alternatives.contains(&other), "seed {seed}");
        }
    }
    assert!(entries > 0, "no seed reported a pair it cannot tell apart");
}
