//! Measurement plans (`fitting::plan`):
//!
//! - the predicted standard uncertainties agree with the spread of the estimates of 1000
//!   campaigns simulated on the exact virtual machine (a truth made of the model's terms at
//!   tens of µm and µrad, reading noise σ) and fitted first order by `identify`,
//!   within 10 % for every determined parameter; white noise with ordinary least squares, and
//!   AR(1) noise with the generalized fit under the declared model;
//! - following the suggestion (the plan with it, simulated again) reduces the largest
//!   uncertainty, measured by Monte-Carlo;
//! - the suggestion is the best single addition: an independent brute-force evaluation of every
//!   candidate (the whole campaign's design matrix, an SVD and a pseudo-inverse, the criterion
//!   written out again) finds none better;
//! - on the head-head fixture, the variation of Z's tilts along its stroke, which a C turn cannot
//!   see, is determined by the best addition, which moves Z;
//! - the prediction is the uncertainty a fit reports, scaled from its σ̂ to the stated σ;
//! - bad plans are refused naming the test and the sample.
//!
//! The figures: `cargo test -p fitting --test all plan:: -- --nocapture`.

use fitting::campaign::{Owner, design_matrix, fit_design, identify};
use fitting::noise::{NoiseChoice, NoiseModel, NoiseSource};
use fitting::plan::choose::interest;
use fitting::plan::{
    BASE_BALL, BallPosition, CandidateSet, Plan, PlanError, PlannedCampaign, PlannedTest,
    Prediction, Suggestion, Targets, candidates, check_model, predict_design, suggest,
};
use fitting::{IdentifyOptions, Tolerances};
use formats::truth::builtin_truth;
use model_spec::{Machine, builtin};
use nalgebra::{DMatrix, SVD};
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::generator::{GeneratorError, GeneratorOptions, SampleProblem};
use simulation::model::{Model, Term};
use simulation::readings::simulate;
use simulation::truth::Truth;

/// Monte-Carlo campaigns per check. The relative standard error of a sample standard deviation
/// over n values is 1/√(2(n − 1)): 2.2 % at 1000, so the 10 % band is 4.5 standard errors
/// (at 500 it would be 3.2, and one of the some fifty values checked would leave it about once
/// in ten studies).
const RUNS: usize = 1000;

/// The first noise seed of each Monte-Carlo (16 per campaign): every study draws its own noise.
const SEED_ZEROED: u64 = 1;
const SEED_AR1: u64 = 100_001;
const SEED_BEFORE: u64 = 200_001;
const SEED_AFTER: u64 = 300_001;

/// Reading noise, mm.
const SIGMA_MM: f64 = 0.5e-3;

fn seed_ac() -> Machine {
    builtin("seed-ac").unwrap().unwrap()
}

fn head_head() -> Machine {
    model_spec::load_machine(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/machines/head-head-ca.toml"
    ))
    .unwrap()
}

fn reduced(m: &Machine) -> Model {
    Model::constant(m.model_errors("reduced").unwrap())
}

/// The plan of `tests` (`TEST` or `TEST:BALL`) with the ball positions `balls` (name, symbol,
/// value) besides the base.
fn plan(
    m: &Machine,
    tests: &[&str],
    balls: &[(&str, &str, f64)],
    zeroed: bool,
    shared_setup: bool,
) -> Plan {
    let mut positions = vec![BallPosition {
        name: BASE_BALL.into(),
        params: m.default_parameters(),
    }];
    for (name, sym, v) in balls {
        let mut params = m.default_parameters();
        params[m.symbol_by_name(sym).unwrap()] = *v;
        positions.push(BallPosition {
            name: name.to_string(),
            params,
        });
    }
    let tests = tests
        .iter()
        .map(|t| {
            let (test, ball) = t.split_once(':').unwrap_or((t, BASE_BALL));
            PlannedTest {
                test: test.to_string(),
                ball: positions.iter().position(|b| b.name == ball).unwrap(),
            }
        })
        .collect();
    Plan {
        balls: positions,
        tests,
        zeroed,
        shared_setup,
        generator: GeneratorOptions::default(),
    }
}

fn white() -> NoiseModel {
    NoiseModel::white(SIGMA_MM, NoiseSource::Declared)
}

/// The plan made, its design, prediction, candidates and suggestion.
struct Planned {
    planned: PlannedCampaign,
    prediction: Prediction,
    set: CandidateSet,
    suggestion: Suggestion,
}

fn run_plan(m: &Machine, model: &Model, p: &Plan, noise: &NoiseModel) -> Planned {
    let tol = Tolerances::default();
    let predicted = p.predict(m, model, noise, &tol).unwrap();
    let set = candidates::candidates(m, p, 100.0).unwrap();
    let suggestion = suggest(m, model, p, &predicted, &set, &Targets::default(), &tol).unwrap();
    Planned {
        planned: predicted.planned,
        prediction: predicted.prediction,
        set,
        suggestion,
    }
}

/// `p` with the best candidate of `planned` added (its ball position added when new).
fn followed(p: &Plan, planned: &Planned) -> Plan {
    let best = planned.suggestion.best().unwrap();
    let c = &planned.set.candidates[best.candidate];
    let ball = &planned.set.balls[c.ball];
    let mut out = p.clone();
    let b = match ball.planned {
        Some(b) => b,
        None => {
            out.balls.push(BallPosition {
                name: ball.name.clone(),
                params: ball.params.clone(),
            });
            out.balls.len() - 1
        }
    };
    out.tests.push(PlannedTest {
        test: c.test.clone(),
        ball: b,
    });
    out
}

/// The truth of one record of the Monte-Carlo: the built-in `seed-ac-reduced` truth (tens of
/// µm and µrad) with this record's kinematic parameters, its set-up's own ball errors (shifted
/// by 3 µm per set-up), the noise, the seed and zeroing.
fn truth(m: &Machine, rec: &CampaignRecord, setup: usize, noise: (f64, f64), seed: u64) -> Truth {
    let mut t = builtin_truth("seed-ac-reduced", m).unwrap().unwrap();
    for (k, term) in t.model.terms.iter().enumerate() {
        let name = term.effect.name(m);
        if ["XOW", "YOW", "ZOW"].contains(&name.as_str()) {
            t.coefficients[k] += 3e-3 * setup as f64;
        }
    }
    t.params = rec.params.clone();
    t.noise_mm = noise.0;
    t.noise_phi = noise.1;
    t.seed = seed;
    t.zeroed = rec.zeroed;
    t
}

/// The sample standard deviation of every column's estimate over `runs` campaigns of
/// `planned` simulated on the exact machine (noise σ, φ; seeds from `seed0` on, 16 per run) and
/// fitted first order by `fit_design` (`identify` with the campaign's
/// design matrix built once) with `choice`; `None` for a column that never got a value. Panics when
/// a column gets a value in some fits and none in others.
fn monte_carlo(
    m: &Machine,
    model: &Model,
    planned: &Campaign,
    noise: (f64, f64),
    choice: &NoiseChoice,
    runs: usize,
    seed0: u64,
) -> Vec<Option<f64>> {
    let setups = planned.setups();
    // The design matrix needs the poses only: the one `identify` would build for
    // every run.
    let design = design_matrix(m, model, planned).unwrap();
    let mut sum: Vec<f64> = Vec::new();
    let mut sq: Vec<f64> = Vec::new();
    let mut valued: Vec<usize> = Vec::new();
    for run in 0..runs {
        let records: Vec<CampaignRecord> = planned
            .records
            .iter()
            .enumerate()
            .map(|(r, rec)| {
                let s = setups.iter().position(|x| *x == rec.setup).unwrap();
                let seed = seed0 + (run * 16 + r) as u64;
                let measured = simulate(m, &truth(m, rec, s, noise, seed), &rec.record).unwrap();
                CampaignRecord {
                    record: measured,
                    ..rec.clone()
                }
            })
            .collect();
        let campaign = Campaign::new(records).unwrap();
        let fit = fit_design(
            m,
            model,
            &campaign,
            &design,
            &IdentifyOptions::new().noise(choice.clone()),
        )
        .unwrap()
        .fit;
        if sum.is_empty() {
            sum = vec![0.0; fit.values.len()];
            sq = vec![0.0; fit.values.len()];
            valued = vec![0; fit.values.len()];
        }
        for (j, v) in fit.values.iter().enumerate() {
            if let Some(v) = v {
                sum[j] += v;
                sq[j] += v * v;
                valued[j] += 1;
            }
        }
    }
    (0..sum.len())
        .map(|j| {
            assert!(
                valued[j] == 0 || valued[j] == runs,
                "column {j} has a value in {} of {runs} fits",
                valued[j]
            );
            (valued[j] == runs).then(|| {
                let n = runs as f64;
                let mean = sum[j] / n;
                ((sq[j] - n * mean * mean) / (n - 1.0)).max(0.0).sqrt()
            })
        })
        .collect()
}

/// The display factor and unit of column `j` of `p`.
fn display(m: &Machine, p: &Prediction, j: usize) -> (f64, &'static str) {
    let t = &p.layout.columns[j].term;
    (t.display_factor(m), t.unit(m))
}

/// Checks the prediction `p` against the Monte-Carlo `spread`: every determined column within
/// 10 %, every undetermined one without a value; prints the table; returns the largest ratio
/// deviation.
fn check_spread(m: &Machine, what: &str, p: &Prediction, spread: &[Option<f64>]) -> f64 {
    println!("{what}: predicted std against the spread of {RUNS} simulated campaigns");
    let mut worst: f64 = 0.0;
    assert_eq!(spread.len(), p.names.len());
    for (j, &e) in spread.iter().enumerate() {
        let (f, unit) = display(m, p, j);
        match (p.std[j], e) {
            (Some(s), Some(e)) => {
                let ratio = e / s;
                println!(
                    "  {:>14}: predicted {:8.4} {unit}, Monte-Carlo {:8.4} {unit}, ratio {ratio:.3}",
                    p.names[j],
                    s * f,
                    e * f
                );
                assert!(
                    (ratio - 1.0).abs() <= 0.10,
                    "{what}: {} predicted {} against the spread {}",
                    p.names[j],
                    s * f,
                    e * f
                );
                worst = worst.max((ratio - 1.0).abs());
            }
            (None, None) => {
                assert!(!p.determined[j], "{}", p.names[j]);
                println!(
                    "  {:>14}: not determined; no fit gave it a value",
                    p.names[j]
                );
            }
            (s, e) => panic!(
                "{what}: {}: predicted {s:?} but the fits give {e:?}",
                p.names[j]
            ),
        }
    }
    println!("  largest |ratio − 1|: {worst:.3}");
    worst
}

/// The largest `std / target` among the parameters of interest of `p`, from `std` (one per
/// column, internal units), with its name.
fn largest(m: &Machine, p: &Prediction, std: &[Option<f64>]) -> (String, f64) {
    let targets = Targets::default();
    interest(p)
        .into_iter()
        .filter_map(|j| {
            let (f, unit) = display(m, p, j);
            std[j].map(|s| (p.names[j].clone(), s * f / targets.of(unit)))
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap()
}

#[test]
fn predicted_uncertainties_match_the_spread_of_simulated_zeroed_campaigns() {
    // K4 and K2, zeroed, each record its own set-up: the sensor zeros swallow what has a
    // constant gain, the rest is determined.
    let m = seed_ac();
    let model = reduced(&m);
    let p = plan(&m, &["K4", "K2"], &[], true, false);
    let planned = p.campaign(&m).unwrap();
    let design = design_matrix(&m, &model, &planned.campaign).unwrap();
    let prediction = predict_design(&design, &white(), &Tolerances::default()).unwrap();
    assert!(prediction.determined.iter().any(|d| !d));
    assert!(prediction.determined.iter().filter(|d| **d).count() >= 10);
    let spread = monte_carlo(
        &m,
        &model,
        &planned.campaign,
        (SIGMA_MM, 0.0),
        &NoiseChoice::Ordinary,
        RUNS,
        SEED_ZEROED,
    );
    check_spread(&m, "K4 + K2, zeroed", &prediction, &spread);
}

#[test]
fn predicted_uncertainties_under_ar1_noise_match_the_generalized_fits() {
    // AR(1) noise φ = 0.8, σ = 0.3 µm; the fits whiten by the declared model.
    let m = seed_ac();
    let model = reduced(&m);
    let p = plan(&m, &["K4"], &[], false, false);
    let planned = p.campaign(&m).unwrap();
    let noise = NoiseModel::ar1(0.8, 0.3e-3, NoiseSource::Declared);
    let design = design_matrix(&m, &model, &planned.campaign).unwrap();
    let prediction = predict_design(&design, &noise, &Tolerances::default()).unwrap();
    let white = predict_design(
        &design,
        &NoiseModel::white(0.3e-3, NoiseSource::Declared),
        &Tolerances::default(),
    )
    .unwrap();
    // Correlated noise averages out more slowly: every uncertainty is close to 3 times what
    // white noise of the same σ gives (√((1 + φ)/(1 − φ)) = 3 for the mean of a long AR(1)
    // series).
    for j in 0..prediction.names.len() {
        let ratio = prediction.std[j].unwrap() / white.std[j].unwrap();
        println!("  {}: AR(1) / white {ratio:.3}", prediction.names[j]);
        assert!(
            (2.5..3.0).contains(&ratio),
            "{}: {ratio}",
            prediction.names[j]
        );
    }
    let spread = monte_carlo(
        &m,
        &model,
        &planned.campaign,
        (0.3e-3, 0.8),
        &NoiseChoice::Model(noise),
        RUNS,
        SEED_AR1,
    );
    check_spread(&m, "K4, AR(1) φ = 0.8", &prediction, &spread);
}

#[test]
fn following_the_suggestion_reduces_the_largest_uncertainty() {
    // K4 alone determines the reduced model; the suggestion then adds what shrinks its largest
    // uncertainty most.
    let m = seed_ac();
    let model = reduced(&m);
    let p = plan(&m, &["K4"], &[], false, false);
    let before = run_plan(&m, &model, &p, &white());
    assert!(before.prediction.determined.iter().all(|d| *d));
    let best = before.suggestion.best().unwrap();
    let c = &before.set.candidates[best.candidate];
    println!(
        "suggestion: {} at {}",
        c.test, before.set.balls[c.ball].name
    );
    let q = followed(&p, &before);
    let after = run_plan(&m, &model, &q, &white());
    let mc_before = monte_carlo(
        &m,
        &model,
        &before.planned.campaign,
        (SIGMA_MM, 0.0),
        &NoiseChoice::Ordinary,
        RUNS,
        SEED_BEFORE,
    );
    check_spread(&m, "K4", &before.prediction, &mc_before);
    let mc_after = monte_carlo(
        &m,
        &model,
        &after.planned.campaign,
        (SIGMA_MM, 0.0),
        &NoiseChoice::Ordinary,
        RUNS,
        SEED_AFTER,
    );
    check_spread(&m, "K4 + the suggestion", &after.prediction, &mc_after);
    let (pb, pb_x) = largest(&m, &before.prediction, &before.prediction.std);
    let (pa, pa_x) = largest(&m, &after.prediction, &after.prediction.std);
    let (mb, mb_x) = largest(&m, &before.prediction, &mc_before);
    let (ma, ma_x) = largest(&m, &after.prediction, &mc_after);
    println!(
        "largest std/target: predicted {pb} {pb_x:.4} -> {pa} {pa_x:.4}; Monte-Carlo {mb} {mb_x:.4} -> {ma} {ma_x:.4}"
    );
    // What the suggestion's score says is what the plan with it gives.
    let l = best.score.largest.as_ref().unwrap();
    assert!((l.relative - pa_x).abs() <= 1e-9 * pa_x && l.name == pa);
    assert!(
        ma_x < 0.5 * mb_x,
        "the Monte-Carlo largest goes from {mb_x} to {ma_x}"
    );
}

/// An independent evaluation of a campaign's design matrix `h` (names `names`): rank and
/// determination from the SVD of the column-scaled matrix, the null-space projector `I − A⁺A`,
/// and standard uncertainties `σ·‖row_j(A⁺)‖ / s_j` from nalgebra's pseudo-inverse.
fn brute(h: &DMatrix<f64>, sigma: f64) -> (usize, Vec<bool>, Vec<Option<f64>>) {
    let n = h.ncols();
    let s: Vec<f64> = (0..n)
        .map(|j| {
            let x = h.column(j).norm();
            if x > 0.0 { x } else { 1.0 }
        })
        .collect();
    let a = DMatrix::from_fn(h.nrows(), n, |i, j| h[(i, j)] / s[j]);
    let svd = SVD::new(a.clone(), true, true);
    let smax = svd.singular_values.max();
    let tau = smax * 1e-8f64.max(h.nrows().max(n) as f64 * f64::EPSILON);
    let rank = svd.singular_values.iter().filter(|&&x| x > tau).count();
    let pinv = svd.pseudo_inverse(tau).unwrap();
    let projector = DMatrix::identity(n, n) - &pinv * &a;
    let determined: Vec<bool> = (0..n)
        .map(|j| projector[(j, j)].max(0.0).sqrt() <= 1e-6)
        .collect();
    let std = (0..n)
        .map(|j| determined[j].then(|| sigma * pinv.row(j).norm() / s[j]))
        .collect();
    (rank, determined, std)
}

/// A campaign evaluated by [`brute`]: its column names, which are determined, their standard
/// uncertainties (internal units) and terms.
struct Evaluated<'a> {
    names: &'a [String],
    determined: &'a [bool],
    std: &'a [Option<f64>],
    terms: &'a [Term],
}

/// The criterion written out again: (newly determined, largest std/target, Σ (std/target)²)
/// of the plan with a candidate (`after`) against the plan alone.
fn criterion(
    m: &Machine,
    plan_names: &[String],
    plan_determined: &[bool],
    interest: &[String],
    after: Evaluated,
) -> (usize, f64, f64) {
    let Evaluated {
        names,
        determined,
        std,
        terms,
    } = after;
    let targets = Targets::default();
    let mut newly = 0;
    let mut worst = f64::NEG_INFINITY;
    let mut sum = 0.0;
    for name in interest {
        let b = plan_names.iter().position(|n| n == name).unwrap();
        let a = names.iter().position(|n| n == name).unwrap();
        if !determined[a] {
            continue;
        }
        if !plan_determined[b] {
            newly += 1;
        }
        let r = std[a].unwrap() * terms[a].display_factor(m) / targets.of(terms[a].unit(m));
        worst = worst.max(r);
        sum += r * r;
    }
    (newly, worst, sum)
}

/// Checks that the suggestion of `p` is the best single addition by a brute-force evaluation
/// of every candidate, and that every candidate's score matches.
fn check_brute_force(m: &Machine, model: &Model, p: &Plan) {
    let planned = run_plan(m, model, p, &white());
    let plan_design = design_matrix(m, model, &planned.planned.campaign).unwrap();
    let (_, plan_determined, _) = brute(&plan_design.h, SIGMA_MM);
    assert_eq!(plan_determined, planned.prediction.determined);
    let wanted: Vec<String> = plan_design
        .names
        .iter()
        .zip(&plan_design.owners)
        .filter(|(_, o)| **o == Owner::Shared)
        .map(|(n, _)| n.clone())
        .collect();
    assert_eq!(wanted, planned.suggestion.interest);
    let zeroed = p.zeroed;
    let mut scores: Vec<(usize, (usize, f64, f64))> = Vec::new();
    for (c, cand) in planned.set.candidates.iter().enumerate() {
        let ball = &planned.set.balls[cand.ball];
        let setup = if p.shared_setup {
            ball.name.clone()
        } else {
            "brute".to_string()
        };
        let mut records = planned.planned.campaign.records.clone();
        records.push(CampaignRecord::new(
            "brute",
            cand.record.clone(),
            ball.params.clone(),
            setup,
            zeroed,
        ));
        let campaign = Campaign::new(records).unwrap();
        let design = design_matrix(m, model, &campaign).unwrap();
        let (rank, determined, std) = brute(&design.h, SIGMA_MM);
        let terms: Vec<Term> = design.layout.columns.iter().map(|c| c.term).collect();
        let score = criterion(
            m,
            &plan_design.names,
            &plan_determined,
            &wanted,
            Evaluated {
                names: &design.names,
                determined: &determined,
                std: &std,
                terms: &terms,
            },
        );
        // The library's score of the same candidate.
        let lib = &planned
            .suggestion
            .ranking
            .iter()
            .find(|r| r.candidate == c)
            .unwrap()
            .score;
        assert_eq!(lib.rank, rank, "candidate {c}: rank");
        assert_eq!(lib.newly_determined.len(), score.0, "candidate {c}");
        match &lib.largest {
            Some(l) => assert!(
                (l.relative - score.1).abs() <= 1e-7 * score.1,
                "candidate {c}: largest {} against {}",
                l.relative,
                score.1
            ),
            None => assert_eq!(score.1, f64::NEG_INFINITY, "candidate {c}"),
        }
        assert!((lib.sum_squares - score.2).abs() <= 1e-7 * score.2);
        scores.push((c, score));
    }
    // The brute-force best: most newly determined, then the smallest largest, then the sum.
    let better = |a: &(usize, f64, f64), b: &(usize, f64, f64)| {
        a.0 > b.0
            || a.0 == b.0
                && (a.1 < b.1 * (1.0 - 1e-7)
                    || (a.1 - b.1).abs() <= 1e-7 * b.1 && a.2 < b.2 * (1.0 - 1e-7))
    };
    let chosen = planned.suggestion.best().unwrap().candidate;
    let chosen_score = scores.iter().find(|(c, _)| *c == chosen).unwrap().1;
    for (c, s) in &scores {
        assert!(
            !better(s, &chosen_score),
            "candidate {c} {s:?} is better than the chosen {chosen} {chosen_score:?}"
        );
    }
    let cand = &planned.set.candidates[chosen];
    println!(
        "{:?}: chosen {} at {} {chosen_score:?} among {} candidates ({} skipped)",
        p.tests.iter().map(|t| t.test.as_str()).collect::<Vec<_>>(),
        cand.test,
        planned.set.balls[cand.ball].name,
        scores.len(),
        planned.set.skipped.len()
    );
}

#[test]
fn the_suggestion_is_the_best_single_addition_by_brute_force() {
    let m = seed_ac();
    let model = reduced(&m);
    // K1 leaves groups: the suggestion separates the most.
    check_brute_force(&m, &model, &plan(&m, &["K1"], &[], false, false));
    // Zeroed, shared set-ups at two ball heights: the largest uncertainty decides.
    check_brute_force(
        &m,
        &model,
        &plan(&m, &["K4", "K2:high"], &[("high", "Zw", 260.0)], true, true),
    );
    // A machine given as a file (gains from the evaluator), a model with terms along Z's
    // stroke.
    let hh = head_head();
    let mut model = Model::of(&hh, "location").unwrap();
    for t in ["EAZ@poly:1", "EBZ@poly:1", "ECZ@poly:1"] {
        model.terms.push(Term::parse(&hh, t).unwrap());
    }
    check_brute_force(&hh, &model, &plan(&hh, &["turn-C"], &[], false, false));
}

#[test]
fn on_the_head_head_machine_the_suggestion_moves_z_along_its_stroke() {
    // A C turn with the A fork at rest keeps Z still: the variation of Z's tilts along its
    // stroke looks like constant tilts and cannot be seen. The best single addition tilts the
    // fork while C turns (Z then follows the ball up and down) and determines them.
    let hh = head_head();
    let mut model = Model::of(&hh, "location").unwrap();
    for t in ["EAZ@poly:1", "EBZ@poly:1", "ECZ@poly:1"] {
        model.terms.push(Term::parse(&hh, t).unwrap());
    }
    let p = plan(&hh, &["turn-C"], &[], false, false);
    let planned = run_plan(&hh, &model, &p, &white());
    let poly = ["EAZ@poly:1", "EBZ@poly:1", "ECZ@poly:1"];
    for name in poly {
        let j = planned.prediction.column(name).unwrap();
        assert!(!planned.prediction.determined[j] && planned.prediction.std[j].is_none());
    }
    let best = planned.suggestion.best().unwrap();
    for name in poly {
        assert!(
            best.score.newly_determined.iter().any(|n| n == name),
            "{name}"
        );
    }
    let c = &planned.set.candidates[best.candidate];
    let a = hh.axis_by_name("A").unwrap();
    let z = hh.axis_by_name("Z").unwrap();
    let moves = |axis: usize| {
        let q: Vec<f64> = c.record.samples.iter().map(|s| s.commands[axis]).collect();
        q.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            - q.iter().copied().fold(f64::INFINITY, f64::min)
    };
    assert!(moves(a) > 0.1 && moves(z) > 10.0, "{}", c.test);
    let ball = &planned.set.balls[c.ball];
    let zw = hh.symbol_by_name("Zw").unwrap();
    println!(
        "turn-C: the best addition is {} at {} (Zw = {} mm), determining {:?}",
        c.test, ball.name, ball.params[zw], best.score.newly_determined
    );
}

#[test]
fn the_prediction_is_what_a_fit_reports_scaled_to_the_stated_noise() {
    // A fit's std is σ̂ times the unit uncertainty; the prediction is σ times it.
    let m = seed_ac();
    let model = reduced(&m);
    let p = plan(&m, &["K4", "K2"], &[], true, false);
    let planned = p.campaign(&m).unwrap();
    let design = design_matrix(&m, &model, &planned.campaign).unwrap();
    let prediction = predict_design(&design, &white(), &Tolerances::default()).unwrap();
    let records: Vec<CampaignRecord> = planned
        .campaign
        .records
        .iter()
        .enumerate()
        .map(|(r, rec)| CampaignRecord {
            record: simulate(
                &m,
                &truth(&m, rec, r, (SIGMA_MM, 0.0), 7 + r as u64),
                &rec.record,
            )
            .unwrap(),
            ..rec.clone()
        })
        .collect();
    let ident = identify(
        &m,
        &model,
        &Campaign::new(records).unwrap(),
        &IdentifyOptions::new().noise(NoiseChoice::Ordinary),
    )
    .unwrap();
    let fit = &ident.fit;
    assert_eq!(fit.names, prediction.names);
    assert_eq!(fit.rank, prediction.rank);
    assert_eq!(fit.identifiability.determined, prediction.determined);
    assert_eq!(fit.identifiability.confounded, prediction.confounded);
    let sigma_hat = fit.sigma.unwrap();
    for j in 0..fit.names.len() {
        match (fit.std[j], prediction.std[j]) {
            (Some(s), Some(p)) => {
                let scaled = s / sigma_hat * SIGMA_MM;
                assert!((scaled - p).abs() <= 1e-9 * p, "{}", fit.names[j]);
            }
            (None, None) => {}
            other => panic!("{}: {other:?}", fit.names[j]),
        }
    }
}

#[test]
fn bad_plans_are_refused_naming_the_test_and_the_sample() {
    let m = seed_ac();
    // An unknown test: the machine's tests are listed.
    let e = plan(&m, &["K5"], &[], false, false)
        .campaign(&m)
        .unwrap_err();
    let PlanError::Generator { error, .. } = &e else {
        panic!("{e}")
    };
    assert!(matches!(error, GeneratorError::UnknownTest { .. }));
    assert!(e.to_string().contains("K1, K2, K4"), "{e}");
    // A ball position that puts K4 out of the Y stroke: the test, the position and the sample.
    let e = plan(&m, &["K1", "K4:up"], &[("up", "Zw", 311.537)], false, false)
        .campaign(&m)
        .unwrap_err();
    let PlanError::Generator { error, .. } = &e else {
        panic!("{e}")
    };
    let GeneratorError::Sample(s) = error else {
        panic!("{e}")
    };
    assert!(matches!(s.problem, SampleProblem::Limits(_)), "{e}");
    let text = e.to_string();
    for needle in [
        "K4 at ball position `up`",
        "sample 170 of 241",
        "Y = 400.002",
    ] {
        assert!(text.contains(needle), "`{needle}` not in {text}");
    }
    // A ball position no test uses.
    let mut p = plan(&m, &["K1"], &[("up", "Zw", 260.0)], false, false);
    let e = p.campaign(&m).unwrap_err();
    assert!(e.to_string().contains("`up` is not used"), "{e}");
    // No test.
    p.tests.clear();
    assert!(p.campaign(&m).is_err());
    // An instrument term: its column is the readings.
    let mut model = reduced(&m);
    model.terms.push(Term::parse(&m, "SXY").unwrap());
    let e = check_model(&m, &model).unwrap_err();
    assert!(e.to_string().contains("`SXY` is an instrument term"), "{e}");
    // The candidates the generator refuses are skipped with its reason.
    let p = plan(&m, &["K4"], &[], false, false);
    let set = candidates::candidates(&m, &p, 100.0).unwrap();
    let k4_up = set
        .skipped
        .iter()
        .find(|s| s.test == "K4" && set.balls[s.ball].name == "base.Zw+100")
        .expect("K4 at base.Zw+100 is skipped");
    assert!(
        k4_up.reason.contains("outside its stroke"),
        "{}",
        k4_up.reason
    );
    assert!(candidates::candidates(&m, &p, 0.0).is_err());
    assert!(candidates::candidates(&m, &p, f64::NAN).is_err());
}
