//! A candidate's prediction as an update of the plan's information
//! (`fitting::plan::update`) against the whole campaign predicted again
//! (`predict_design` of the plan with the candidate): the same rank, the same parameters of
//! interest determined, their standard uncertainties within 1e-9 (relative), for every
//! candidate of plans with their own set-ups, shared and zeroed set-ups, and AR(1) noise.

use fitting::Tolerances;
use fitting::campaign::design_matrix;
use fitting::noise::{NoiseModel, NoiseSource};
use fitting::plan::choose::interest;
use fitting::plan::update::Information;
use fitting::plan::{BASE_BALL, BallPosition, Plan, PlannedTest, candidates, predict_design};
use model_spec::{Machine, builtin};
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::generator::GeneratorOptions;
use simulation::model::Model;

fn plan(m: &Machine, tests: &[&str], high: Option<f64>, zeroed: bool, shared: bool) -> Plan {
    let mut balls = vec![BallPosition {
        name: BASE_BALL.into(),
        params: m.default_parameters(),
    }];
    if let Some(z) = high {
        let mut params = m.default_parameters();
        params[m.symbol_by_name("Zw").unwrap()] = z;
        balls.push(BallPosition {
            name: "high".into(),
            params,
        });
    }
    let tests = tests
        .iter()
        .map(|t| {
            let (test, ball) = t.split_once(':').unwrap_or((t, BASE_BALL));
            PlannedTest {
                test: test.into(),
                ball: balls.iter().position(|b| b.name == ball).unwrap(),
            }
        })
        .collect();
    Plan {
        balls,
        tests,
        zeroed,
        shared_setup: shared,
        generator: GeneratorOptions::default(),
    }
}

/// Every candidate of `p` evaluated both ways; returns how many were compared.
fn compare(m: &Machine, model: &Model, p: &Plan, noise: &NoiseModel) -> usize {
    let tol = Tolerances::default();
    let predicted = p.predict(m, model, noise, &tol).unwrap();
    let set = candidates::candidates(m, p, 100.0).unwrap();
    let wanted = interest(&predicted.prediction);
    let layout = &predicted.design.layout;
    let joins = |b: usize| {
        let planned = set.balls[b].planned?;
        let name = &p.balls[planned].name;
        p.shared_setup
            .then(|| layout.setups.iter().position(|s| s == name))
            .flatten()
    };
    let joinable: Vec<bool> = (0..layout.setups.len())
        .map(|s| (0..set.balls.len()).any(|b| joins(b) == Some(s)))
        .collect();
    let info = Information::new(&predicted.design, wanted.clone(), &joinable, noise, &tol).unwrap();
    for (c, cand) in set.candidates.iter().enumerate() {
        let ball = &set.balls[cand.ball];
        let setup = if p.shared_setup {
            ball.name.clone()
        } else {
            "candidate".to_string()
        };
        let record = CampaignRecord::new(
            "candidate",
            cand.record.clone(),
            ball.params.clone(),
            setup,
            p.zeroed,
        );
        let batch = design_matrix(m, model, &Campaign::new(vec![record.clone()]).unwrap()).unwrap();
        let got = info.outcome(&batch, 0, joins(cand.ball)).unwrap();
        let mut records = predicted.planned.campaign.records.clone();
        records.push(record);
        let design = design_matrix(m, model, &Campaign::new(records).unwrap()).unwrap();
        let full = predict_design(&design, noise, &tol).unwrap();
        let what = format!("candidate {c}: {} at {}", cand.test, ball.name);
        assert_eq!(got.rank, full.rank, "{what}: rank");
        assert_eq!(got.columns, full.names.len(), "{what}: columns");
        for (i, &j) in wanted.iter().enumerate() {
            let name = &predicted.prediction.names[j];
            let f = full.column(name).unwrap();
            match (got.std[i], full.determined[f], full.std[f]) {
                (None, false, _) => {}
                (Some(a), true, Some(b)) => assert!(
                    (a - b).abs() <= 1e-9 * b,
                    "{what}: {name}: {a} against {b} (relative {})",
                    (a - b).abs() / b
                ),
                (a, d, b) => panic!("{what}: {name}: {a:?} against determined {d}, {b:?}"),
            }
        }
    }
    set.candidates.len()
}

#[test]
fn the_update_predicts_what_the_whole_campaign_predicts() {
    let m = builtin("seed-ac").unwrap().unwrap();
    let model = Model::constant(m.model_errors("reduced").unwrap());
    let white = NoiseModel::white(0.5e-3, NoiseSource::Declared);
    let ar1 = NoiseModel::ar1(0.8, 0.3e-3, NoiseSource::Declared);
    let mut n = 0;
    n += compare(
        &m,
        &model,
        &plan(&m, &["K4", "K2"], None, true, false),
        &white,
    );
    n += compare(&m, &model, &plan(&m, &["K1"], None, false, false), &white);
    n += compare(
        &m,
        &model,
        &plan(&m, &["K4", "K2:high"], Some(260.0), true, true),
        &white,
    );
    n += compare(
        &m,
        &model,
        &plan(&m, &["K4", "K4", "K1:high"], Some(260.0), false, false),
        &ar1,
    );
    n += compare(
        &m,
        &model,
        &plan(&m, &["K2", "K4:high"], Some(260.0), true, true),
        &ar1,
    );
    assert!(n > 100, "{n} candidates compared");
}
