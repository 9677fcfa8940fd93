//! Diagnosis on a campaign: the reduced model fitted on K4 and K1 together (each its own
//! set-up) lacks the demo truth's twice-per-revolution error of C; the campaign diagnosis finds
//! it and the gain shows on K2, held out on a new set-up whose set-up errors are refitted.

use diagnosis::{DiagnoseOptions, diagnose};
use formats::progress::Unwatched;
use formats::truth::builtin_truth;
use model_spec::{Machine, builtin};
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::model::{Model, Term};
use simulation::paths::builtin_path;
use simulation::readings::simulate;
use simulation::record::Record;

fn machine() -> Machine {
    builtin("seed-ac").unwrap().unwrap()
}

fn measured(m: &Machine, path: &str, seed: u64) -> Record {
    let mut t = builtin_truth("seed-ac-demo", m).unwrap().unwrap();
    t.seed = seed;
    simulate(m, &t, &builtin_path(m, path).unwrap().unwrap()).unwrap()
}

#[test]
fn a_campaign_finds_the_missing_harmonic_and_gains_on_a_new_set_up() {
    let m = machine();
    let base = Model::constant(m.model_errors("reduced").unwrap());
    let p = m.default_parameters();
    let fitted = Campaign::new(vec![
        CampaignRecord::new("k4", measured(&m, "K4", 1), p.clone(), "k4", false),
        CampaignRecord::new("k1", measured(&m, "K1", 2), p.clone(), "k1", false),
    ])
    .unwrap();
    let held = Campaign::new(vec![CampaignRecord::new(
        "k2",
        measured(&m, "K2", 3),
        p,
        "k2",
        false,
    )])
    .unwrap();
    let mut o = DiagnoseOptions::default();
    o.adequacy_draws = 100;
    let d = diagnose(&m, &base, &fitted, &held, &o, &Unwatched).unwrap();
    let ecc2 = Term::parse(&m, "ECC@harmonic:2").unwrap();
    let first = d.findings.first().expect("a finding");
    assert!(
        first.term == ecc2 || first.alternatives.contains(&ecc2),
        "found {} (alternatives {:?})",
        first.term.spelling(&m),
        first
            .alternatives
            .iter()
            .map(|t| t.spelling(&m))
            .collect::<Vec<_>>()
    );
    assert!(first.plausible);
    // The fitted records fall to the noise (0.5 µm), K2 too, its set-up refitted.
    for r in &d.records {
        assert!(
            r.rms.0 > 0.8e-3 && r.rms.1 < 0.56e-3,
            "{}: {:?}",
            r.label,
            r.rms
        );
    }
    let k2 = &d.validation[0];
    assert_eq!((k2.setup.as_str(), k2.setup_fitted), ("k2", false));
    assert!(
        k2.estimable(),
        "{:?} {:?}",
        k2.undetermined_before,
        k2.undetermined_after
    );
    assert!(k2.after_rms < 0.6e-3 && k2.before_rms > 0.65e-3, "{k2:?}");
    println!(
        "campaign diagnosis: {} (p = {:.2e}); fitted RMS {:?} µm; K2 {:.3} -> {:.3} µm",
        first.term.spelling(&m),
        first.p_value,
        d.records
            .iter()
            .map(|r| (r.label.clone(), r.rms.0 * 1e3, r.rms.1 * 1e3))
            .collect::<Vec<_>>(),
        k2.before_rms * 1e3,
        k2.after_rms * 1e3
    );
}
