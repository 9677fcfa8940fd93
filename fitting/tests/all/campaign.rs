//! Campaign fits: a campaign of one record is the least-squares fit of its H matrix; the layout names
//! and owns its columns as documented; several records share the machine's errors; bad
//! campaigns are refused with the record named.

use crate::one_record::{identify_one, identify_refined_campaign};
use fitting::campaign::{Owner, design_matrix, identify};
use fitting::hmatrix::{GainSource, h_matrix, parameter_names};
use fitting::identify::fit_rows;
use fitting::noise::{NoiseChoice, NoiseModel};
use fitting::refine::RefineOptions;
use fitting::{
    Constraint, Fit, IdentifyOptions, Tolerances, choose_noise, measurement_vector, with_offsets,
};
use formats::truth::builtin_truth;
use model_spec::{Machine, builtin};
use simulation::campaign::{Campaign, CampaignError, CampaignRecord};
use simulation::model::Model;
use simulation::paths::builtin_path;
use simulation::readings::simulate;
use simulation::record::Record;
use simulation::truth::Truth;

fn machine() -> Machine {
    builtin("seed-ac").unwrap().unwrap()
}

fn path(m: &Machine, name: &str) -> Record {
    builtin_path(m, name).unwrap().unwrap()
}

fn truth(m: &Machine, name: &str, noise_mm: f64, seed: u64, zeroed: bool) -> Truth {
    let mut t = builtin_truth(name, m).unwrap().unwrap();
    t.noise_mm = noise_mm;
    t.seed = seed;
    t.zeroed = zeroed;
    t
}

fn reduced(m: &Machine) -> Model {
    Model::constant(m.model_errors("reduced").unwrap())
}

/// A campaign column's name without its owner (`XOW[ball]` is `XOW`).
fn bare(name: &str) -> &str {
    name.split('[').next().unwrap_or(name)
}

/// The campaign fit's column `name[owner]` (or `name` when shared) against the single fit's
/// `name`: the same values, uncertainties, determination, bit for bit.
fn assert_same(single: &Fit, campaign: &Fit) {
    assert_eq!(single.rank, campaign.rank);
    assert_eq!(single.rss.to_bits(), campaign.rss.to_bits());
    assert_eq!(single.residual, campaign.residual);
    assert_eq!(single.singular_values, campaign.singular_values);
    assert_eq!(single.condition, campaign.condition);
    assert_eq!(single.names.len(), campaign.names.len());
    for (j, name) in single.names.iter().enumerate() {
        let k = campaign
            .names
            .iter()
            .position(|n| bare(n) == name)
            .unwrap_or_else(|| panic!("{name} is in the campaign fit"));
        assert_eq!(single.values[j], campaign.values[k], "{name}");
        assert_eq!(single.std[j], campaign.std[k], "{name}");
        assert_eq!(
            single.identifiability.determined[j], campaign.identifiability.determined[k],
            "{name}"
        );
        for (l, other) in single.names.iter().enumerate() {
            let kl = campaign
                .names
                .iter()
                .position(|n| bare(n) == other)
                .unwrap();
            let (a, b) = (single.covariance[(j, l)], campaign.covariance[(k, kl)]);
            assert!(a.to_bits() == b.to_bits(), "cov {name} {other}: {a} {b}");
        }
    }
    let groups = |f: &Fit| -> Vec<Vec<String>> {
        let mut g: Vec<Vec<String>> = f
            .identifiability
            .confounded
            .iter()
            .map(|g| {
                let mut v: Vec<String> = g.iter().map(|&j| bare(&f.names[j]).to_string()).collect();
                v.sort();
                v
            })
            .collect();
        g.sort();
        g
    };
    assert_eq!(groups(single), groups(campaign));
}

fn one_record(m: &Machine, label: &str, record: Record, zeroed: bool) -> Campaign {
    Campaign::new(vec![CampaignRecord::new(
        label,
        record,
        m.default_parameters(),
        "ball",
        zeroed,
    )])
    .unwrap()
}

/// The least-squares fit of `record`'s own H matrix for `model` (with `dx0 dy0 dz0` when
/// zeroed), at the default parameters, by the solver every fit uses: ordinary, or generalized
/// under `noise`.
fn fit_of_h(
    m: &Machine,
    model: &Model,
    record: &Record,
    zeroed: bool,
    noise: Option<&NoiseModel>,
) -> Fit {
    let fitted = if zeroed {
        with_offsets(model)
    } else {
        model.clone()
    };
    let mut source = GainSource::new(m, &fitted.errors(), &m.default_parameters()).unwrap();
    let h = h_matrix(m, &fitted, record, &mut source).unwrap();
    let y = measurement_vector(record).unwrap();
    let names = parameter_names(m, &fitted);
    let tol = Tolerances::default();
    let layout = [record.samples.len()];
    fit_rows(
        &h,
        &y,
        &names,
        &Constraint::None,
        &tol,
        noise,
        &layout,
        None,
    )
    .unwrap()
    .0
}

#[test]
fn one_record_is_the_least_squares_fit_of_its_h_matrix() {
    let m = machine();
    let model = reduced(&m);
    for (zeroed, noise) in [
        (false, NoiseChoice::Ordinary),
        (true, NoiseChoice::Ordinary),
        (false, NoiseChoice::Estimate),
    ] {
        let t = truth(&m, "seed-ac-demo", 0.5e-3, 7, zeroed);
        let k4 = simulate(&m, &t, &path(&m, "K4")).unwrap();
        let c = one_record(&m, "k4", k4.clone(), zeroed);
        let camp = identify(&m, &model, &c, &IdentifyOptions::new().noise(noise.clone())).unwrap();
        // The noise model is the one the record's ordinary fit gives ...
        let ordinary = fit_of_h(&m, &model, &k4, zeroed, None);
        let chosen = choose_noise(&noise, ordinary.residual.as_slice(), ordinary.sigma);
        assert_eq!(camp.noise, chosen);
        // ... and the fit that of the record's H matrix under it, bit for bit.
        let whitened = (noise != NoiseChoice::Ordinary).then_some(&chosen);
        let direct = fit_of_h(&m, &model, &k4, zeroed, whitened);
        assert_same(&direct, &camp.fit);
        // The fit in the record's model order and names is the same fit.
        let single = camp.single_record(&m).unwrap();
        assert_eq!(single.fit.names, direct.names);
        assert_same(&direct, &single.fit);
        assert_eq!(single.samples, k4.samples.len());
        assert_eq!(single.zeroed, zeroed);
        if zeroed {
            // What the offsets swallow, named with the record in the campaign, without it in
            // the record's view.
            assert_eq!(camp.swallowed.len(), single.swallowed.len());
            assert!(
                camp.swallowed
                    .iter()
                    .all(|s| s.offsets[0].ends_with("[k4]"))
            );
            assert!(single.swallowed.iter().all(|s| !s.offsets[0].contains('[')));
        }
        // Refined: the record's view of the refined campaign fit is that fit.
        let refined = IdentifyOptions::new()
            .noise(noise.clone())
            .refined(RefineOptions::default());
        let camp_r = identify(&m, &model, &c, &refined).unwrap();
        let single_r = camp_r.single_record(&m).unwrap();
        assert!(camp_r.refinement.as_ref().is_some_and(|r| r.converged));
        assert_same(&single_r.fit, &camp_r.fit);
        assert_eq!(
            camp_r.records[0].rss.to_bits(),
            single_r.fit.rss.to_bits(),
            "the record's share is all of it"
        );
    }
    // Several records have no single record's view.
    let two = Campaign::new(vec![
        CampaignRecord::new("k4", path(&m, "K4"), m.default_parameters(), "ball", false),
        CampaignRecord::new("k1", path(&m, "K1"), m.default_parameters(), "ball", false),
    ])
    .unwrap();
    let t = truth(&m, "seed-ac-demo", 0.5e-3, 7, false);
    let two = Campaign::new(
        two.records
            .into_iter()
            .map(|mut r| {
                r.record = simulate(&m, &t, &r.record).unwrap();
                r
            })
            .collect(),
    )
    .unwrap();
    let both = identify(&m, &model, &two, &IdentifyOptions::new()).unwrap();
    assert!(both.single_record(&m).is_none());
}

#[test]
fn layout_owns_and_names_the_columns() {
    let m = machine();
    let mut model = reduced(&m);
    model
        .terms
        .push(simulation::model::Term::parse(&m, "dz0@time:1").unwrap());
    let p = m.default_parameters();
    let k4 = path(&m, "K4");
    let k1 = path(&m, "K1");
    let c = Campaign::new(vec![
        CampaignRecord::new("k4", k4.clone(), p.clone(), "low", true),
        CampaignRecord::new("k1", k1.clone(), p.clone(), "low", false),
        CampaignRecord::new("k4b", k4, p, "high", false),
    ])
    .unwrap();
    // Bare paths: the design matrix needs no readings.
    let d = design_matrix(&m, &model, &c).unwrap();
    assert_eq!(d.rows, vec![241, 361, 241]);
    assert_eq!(d.h.nrows(), 3 * (241 + 361 + 241));
    let names: Vec<&str> = d.names.iter().map(String::as_str).collect();
    assert_eq!(
        names,
        [
            "YOA",
            "ZOA",
            "BOA",
            "COA",
            "XOC",
            "YOC",
            "AOC",
            "BOC", // shared
            "XOW[low]",
            "YOW[low]",
            "ZOW[low]",
            "XOW[high]",
            "YOW[high]",
            "ZOW[high]",
            "dz0@time:1[k4]",
            "dx0[k4]",
            "dy0[k4]",
            "dz0[k4]", // zeroed: its zero
            "dz0@time:1[k1]",
            "dz0@time:1[k4b]",
        ]
    );
    assert_eq!(d.owners[0], Owner::Shared);
    assert_eq!(d.owners[8], Owner::Setup(0));
    assert_eq!(d.owners[11], Owner::Setup(1));
    assert_eq!(d.owners[15], Owner::Record(0));
    assert_eq!(d.owners[19], Owner::Record(2));
    // A record's rows are zero in the columns of other set-ups and records.
    let k1_rows = d.h.rows(3 * 241, 3 * 361);
    for (j, o) in d.owners.iter().enumerate() {
        let zero = k1_rows.column(j).iter().all(|&x| x == 0.0);
        let own = matches!(o, Owner::Shared | Owner::Setup(0) | Owner::Record(1));
        assert_eq!(zero, !own, "{}", d.names[j]);
    }
}

#[test]
fn two_paths_on_one_set_up_share_it_and_determine_what_one_path_cannot() {
    let m = machine();
    let model = reduced(&m);
    let t = truth(&m, "seed-ac-reduced", 0.0, 1, false);
    let k1 = simulate(&m, &t, &path(&m, "K1")).unwrap();
    let k2 = simulate(&m, &t, &path(&m, "K2")).unwrap();
    let p = m.default_parameters();
    let opts = IdentifyOptions::new();
    let alone = identify_one(&m, &model, &k1, &opts).unwrap();
    assert!(
        alone.fit.rank < 11,
        "K1 alone cannot determine the reduced model"
    );
    let c = Campaign::new(vec![
        CampaignRecord::new("k1", k1, p.clone(), "ball", false),
        CampaignRecord::new("k2", k2, p, "ball", false),
    ])
    .unwrap();
    let (ident, _) =
        identify_refined_campaign(&m, &model, &c, &opts, &RefineOptions::default()).unwrap();
    assert_eq!(ident.fit.rank, 11, "K1 and K2 on one ball determine all 11");
    for (j, name) in ident.fit.names.iter().enumerate() {
        let error = name.split('[').next().unwrap();
        let id = m.error_by_name(error).unwrap();
        let term = simulation::model::Term {
            effect: simulation::model::Effect::Error(id),
            basis: simulation::model::Basis::Const,
        };
        let truth_value = t.coefficient(&term).map_or(0.0, |c| c[0]);
        let v = ident.fit.values[j].unwrap();
        assert!(
            (v - truth_value).abs() < 1e-9,
            "{name}: {v} against the truth {truth_value}"
        );
    }
}

#[test]
fn bad_campaigns_are_refused_naming_the_record() {
    let m = machine();
    let p = m.default_parameters();
    let k4 = path(&m, "K4");
    let rec =
        |label: &str, setup: &str| CampaignRecord::new(label, k4.clone(), p.clone(), setup, false);
    let err = |c: Result<Campaign, CampaignError>| c.unwrap_err().to_string();
    assert!(err(Campaign::new(vec![])).contains("at least one record"));
    assert!(err(Campaign::new(vec![rec("a", "s"), rec("a", "t")])).contains("`a` is given twice"));
    assert!(err(Campaign::new(vec![rec("a b", "s")])).contains("` ` is not allowed"));
    assert!(err(Campaign::new(vec![rec("a", "s[1]")])).contains("`[` is not allowed"));
    assert!(
        err(Campaign::new(vec![
            rec("a", "s").starting_at(0.0),
            rec("b", "s")
        ]))
        .contains("give every record a start, or none")
    );
    let mut moved = p.clone();
    moved[m.symbol_by_name("Zw").unwrap()] += 100.0;
    let c = Campaign::new(vec![
        rec("a", "s"),
        CampaignRecord::new("b", k4.clone(), moved, "s", false),
    ])
    .unwrap();
    let e = design_matrix(&m, &reduced(&m), &c).unwrap_err().to_string();
    assert!(e.contains("share set-up `s`") && e.contains("`Zw`"), "{e}");
    let mut nan = p.clone();
    nan[m.symbol_by_name("Xw").unwrap()] = f64::NAN;
    let c = Campaign::new(vec![CampaignRecord::new("a", k4.clone(), nan, "s", false)]).unwrap();
    let e = design_matrix(&m, &reduced(&m), &c).unwrap_err().to_string();
    assert!(e.contains("record `a`") && e.contains("`Xw`"), "{e}");
    // Bare paths cannot be identified: the readings are missing, and the record is named.
    let c = Campaign::new(vec![rec("a", "s")]).unwrap();
    let e = identify(
        &m,
        &reduced(&m),
        &c,
        &IdentifyOptions::new().noise(NoiseChoice::Ordinary),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("record `a`"), "{e}");
}

/// `t` with the ball set-up errors replaced by `setup` (µm).
fn with_setup(m: &Machine, t: &Truth, setup: [f64; 3]) -> Truth {
    let mut t = t.clone();
    for (name, um) in ["XOW", "YOW", "ZOW"].iter().zip(setup) {
        let term = simulation::model::Term::parse(m, name).unwrap();
        let at: usize = t
            .model
            .terms
            .iter()
            .take_while(|x| **x != term)
            .map(|x| x.basis.width())
            .sum();
        assert!(t.model.terms.contains(&term), "{name} is in the truth");
        t.coefficients[at] = um / term.display_factor(m);
    }
    t
}

#[test]
fn validation_uses_a_fitted_set_up_and_refits_a_new_one() {
    use fitting::campaign::CampaignValues;
    use fitting::validate::ValidateOptions;
    let m = machine();
    let model = reduced(&m);
    let p = m.default_parameters();
    let t = truth(&m, "seed-ac-reduced", 0.0, 1, false);
    let k4 = simulate(&m, &t, &path(&m, "K4")).unwrap();
    let fitted = Campaign::new(vec![CampaignRecord::new("k4", k4, p.clone(), "a", false)]).unwrap();
    let (ident, _) = identify_refined_campaign(
        &m,
        &model,
        &fitted,
        &IdentifyOptions::new().noise(NoiseChoice::Ordinary),
        &RefineOptions::default(),
    )
    .unwrap();
    let values = CampaignValues::of(&ident);
    // K1 on the same ball, K1 on a ball set up anew (zeroed, so its zero is refitted too).
    let k1_same = simulate(&m, &t, &path(&m, "K1")).unwrap();
    let mut moved = with_setup(&m, &t, [40.0, -25.0, 12.0]);
    moved.zeroed = true;
    let k1_new = simulate(&m, &moved, &path(&m, "K1")).unwrap();
    let check = Campaign::new(vec![
        CampaignRecord::new("k1", k1_same, p.clone(), "a", false),
        CampaignRecord::new("k1-new", k1_new, p, "b", true),
    ])
    .unwrap();
    let mut opts = ValidateOptions::default();
    opts.exact = true;
    let v = fitting::validate(&m, &values, &check, &opts, &formats::progress::Unwatched).unwrap();
    let same = &v.records[0];
    assert!(same.setup_fitted && same.refitted.is_empty());
    assert!(
        same.validation.overall.residual_rms < 1e-9,
        "{:?}",
        same.validation.overall
    );
    let new = &v.records[1];
    assert!(!new.setup_fitted);
    let names: Vec<&str> = new.refitted.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "XOW[b]",
            "YOW[b]",
            "ZOW[b]",
            "dx0[k1-new]",
            "dy0[k1-new]",
            "dz0[k1-new]"
        ]
    );
    assert!(new.validation.overall.measured_rms > 1e-3);
    assert!(
        new.validation.overall.residual_rms < 1e-9,
        "{:?}",
        new.validation.overall
    );
    // Without a refit (the new ball taken for the old one) the prediction is off by the set-up
    // change.
    let wrong = Campaign::new(vec![CampaignRecord::new(
        "k1-new",
        check.records[1].record.clone(),
        m.default_parameters(),
        "a",
        true,
    )])
    .unwrap();
    let w = fitting::validate(&m, &values, &wrong, &opts, &formats::progress::Unwatched).unwrap();
    assert!(w.records[0].validation.overall.residual_rms > 1e-3);
}

#[test]
fn a_drift_on_the_campaign_clock_is_one_drift_over_the_records() {
    use fitting::campaign::clock::own_clock_terms;
    let m = machine();
    let mut model = reduced(&m);
    let drift = simulation::model::Term::parse(&m, "XOC@time:1").unwrap();
    model.terms.push(drift);
    let base = truth(&m, "seed-ac-reduced", 0.0, 1, false);
    // The truth: the reduced errors and XOC drifting by 8 µm over the campaign clock.
    let mut t = base.clone();
    t.model.terms.push(drift);
    t.coefficients.push(8e-3);
    let records = [("k4", "K4", 0.0), ("k1", "K1", 900.0), ("k2", "K2", 1500.0)];
    let span = (0.0, 1500.0 + 120.0);
    let mut rs = Vec::new();
    for (label, name, start) in records {
        let p = path(&m, name);
        let (own, coef) = own_clock_terms(&t.model, &t.coefficients, &p, start, span);
        let mut local = t.clone();
        local.model = own;
        local.coefficients = coef;
        let measured = simulate(&m, &local, &p).unwrap();
        rs.push(
            CampaignRecord::new(label, measured, m.default_parameters(), "ball", false)
                .starting_at(start),
        );
    }
    let c = Campaign::new(rs).unwrap();
    let (ident, _) = identify_refined_campaign(
        &m,
        &model,
        &c,
        &IdentifyOptions::new().noise(NoiseChoice::Ordinary),
        &RefineOptions::default(),
    )
    .unwrap();
    assert_eq!(ident.layout.clock, Some(span));
    let j = ident
        .fit
        .names
        .iter()
        .position(|n| n == "XOC@time:1")
        .unwrap();
    assert!(
        (ident.fit.values[j].unwrap() - 8e-3).abs() < 1e-9,
        "one shared drift: {:?}",
        ident.fit.values[j]
    );
    assert!(ident.fit.residual.amax() < 1e-9);
}
