//! Identification end to end on the exact virtual machine: simulate `seed-ac` with a truth,
//! identify the reduced model on K4, check the values and the validation on K1 and K2.

use crate::one_record::{identify_one, identify_refined_one, validate_one};
use fitting::hmatrix::GainSource;
use fitting::hmatrix::h_matrix;
use fitting::refine::RefineOptions;
use fitting::validate::ValidateOptions;
use fitting::{Constraint, Identification, IdentifyOptions};
use formats::truth::builtin_truth;
use model_spec::{Machine, builtin};
use simulation::model::{Effect, Model};
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

fn truth(m: &Machine, name: &str) -> Truth {
    builtin_truth(name, m).unwrap().unwrap()
}

fn reduced(m: &Machine) -> Model {
    Model::constant(m.model_errors("reduced").unwrap())
}

/// Identifies `model` on `record` and refines against the exact machine.
fn refined(m: &Machine, model: &Model, record: &Record, zeroed: bool) -> Identification {
    let opts = IdentifyOptions::new().zeroed(zeroed);
    let (ident, r) =
        identify_refined_one(m, model, record, &opts, &RefineOptions::default()).unwrap();
    assert!(r.converged, "refinement converges: steps {:?}", r.steps_mm);
    ident
}

/// The truth's value (mm or rad) of the constant term of `effect`.
fn true_value(t: &Truth, effect: Effect) -> f64 {
    t.model
        .terms
        .iter()
        .find(|term| term.effect == effect)
        .and_then(|term| t.coefficient(term))
        .map_or(0.0, |c| c[0])
}

#[test]
fn noise_free_reduced_truth_is_recovered_and_validates_on_k1_k2() {
    let m = machine();
    let t = truth(&m, "seed-ac-reduced");
    let k4 = simulate(&m, &t, &path(&m, "K4")).unwrap();
    let model = reduced(&m);

    // The purely linear fit carries the second-order terms: report them, they are the reason
    // for the refinement.
    let linear = identify_one(&m, &model, &k4, &IdentifyOptions::default()).unwrap();
    let linear_worst = model
        .terms
        .iter()
        .zip(&linear.fit.values)
        .map(|(term, v)| {
            ((v.unwrap() - true_value(&t, term.effect)) * term.effect.display_factor(&m)).abs()
        })
        .fold(0.0, f64::max);
    println!("first-order fit: worst error {linear_worst:.2e} µm/µrad");
    assert!(
        linear_worst > 1e-4,
        "a first-order fit of exact data is biased at second order"
    );

    let ident = refined(&m, &model, &k4, false);
    for (term, v) in model.terms.iter().zip(&ident.fit.values) {
        let err_um = (v.unwrap() - true_value(&t, term.effect)) * term.effect.display_factor(&m);
        assert!(
            err_um.abs() < 1e-4,
            "{}: off by {err_um:e} µm or µrad",
            term.effect.name(&m)
        );
    }
    for name in ["K1", "K2"] {
        let data = simulate(&m, &t, &path(&m, name)).unwrap();
        let opts = ValidateOptions::new().exact(true);
        let v = validate_one(&m, &ident.model, &ident.fit.values, &data, false, &opts).unwrap();
        let first_order = validate_one(
            &m,
            &ident.model,
            &ident.fit.values,
            &data,
            false,
            &ValidateOptions::default(),
        )
        .unwrap();
        println!(
            "{name}: residual RMS exact {:.2e} µm, first-order {:.2e} µm",
            v.overall.residual_rms * 1e3,
            first_order.overall.residual_rms * 1e3
        );
        assert!(
            v.overall.residual_rms * 1e3 < 1e-3 && v.overall.residual_max * 1e3 < 1e-3,
            "{name}: {:?}",
            v.overall
        );
        assert!(
            first_order.overall.residual_rms * 1e3 < 1e-2,
            "{name}: the first-order prediction is close too"
        );
    }
}

#[test]
fn with_noise_estimates_are_within_four_uncertainties_and_validation_is_at_noise_level() {
    let m = machine();
    let mut t = truth(&m, "seed-ac-reduced");
    t.noise_mm = 0.5e-3;
    let model = reduced(&m);
    let (k4, k1, k2) = (path(&m, "K4"), path(&m, "K1"), path(&m, "K2"));
    let mut z2 = Vec::new();
    let mut validation = [(0.0, 0.0); 2];
    for seed in 0..40u64 {
        t.seed = seed;
        let data = simulate(&m, &t, &k4).unwrap();
        let ident = refined(&m, &model, &data, false);
        for (j, term) in model.terms.iter().enumerate() {
            let (v, s) = (ident.fit.values[j].unwrap(), ident.fit.std[j].unwrap());
            let z = (v - true_value(&t, term.effect)) / s;
            assert!(
                z.abs() < 4.0,
                "seed {seed} {}: z = {z}",
                term.effect.name(&m)
            );
            z2.push(z * z);
        }
        let sigma_um = ident.fit.sigma.unwrap() * 1e3;
        assert!(
            (sigma_um - 0.5).abs() < 0.05,
            "seed {seed}: σ̂ = {sigma_um} µm"
        );
        // The validation residual is the noise plus the prediction error of the estimate:
        // E[RMS²] = σ² + tr(H_v Cov H_vᵀ) / 3N, where the second term, for one estimate, has few
        // degrees of freedom: compare the means over the seeds, and each run with the noise.
        for (k, (name, p)) in [("K1", &k1), ("K2", &k2)].into_iter().enumerate() {
            t.seed = 1000 + seed;
            let data = simulate(&m, &t, p).unwrap();
            let opts = ValidateOptions::new().exact(true);
            let v = validate_one(&m, &ident.model, &ident.fit.values, &data, false, &opts).unwrap();
            let mut source =
                GainSource::new(&m, &ident.model.errors(), &m.default_parameters()).unwrap();
            let hv = h_matrix(&m, &ident.model, &data, &mut source).unwrap();
            let spread = (&hv * &ident.fit.covariance * hv.transpose()).trace() / hv.nrows() as f64;
            let rms_um = v.overall.residual_rms * 1e3;
            assert!(
                rms_um < 0.75,
                "{name} seed {seed}: residual RMS {rms_um} µm at 0.5 µm noise"
            );
            validation[k].0 += rms_um * rms_um;
            validation[k].1 += (t.noise_mm * t.noise_mm + spread) * 1e6;
        }
    }
    for (k, name) in ["K1", "K2"].iter().enumerate() {
        let (measured, expected) = (validation[k].0 / 40.0, validation[k].1 / 40.0);
        println!(
            "{name}: mean residual RMS² {measured:.4} µm², expected {expected:.4} µm² (noise alone 0.25)"
        );
        assert!(
            (measured / expected - 1.0).abs() < 0.1,
            "{name}: {measured} vs {expected}"
        );
    }
    let mean_z2 = z2.iter().sum::<f64>() / z2.len() as f64;
    assert!(
        (0.8..1.25).contains(&mean_z2),
        "uncertainties calibrated: mean z² = {mean_z2}"
    );
}

#[test]
fn zeroed_readings_name_the_swallowed_errors_and_the_rest_is_right() {
    let m = machine();
    let mut t = truth(&m, "seed-ac-reduced");
    t.zeroed = true;
    let k4 = simulate(&m, &t, &path(&m, "K4")).unwrap();
    assert_eq!(k4.measured[0], [0.0; 3]);
    let ident = refined(&m, &reduced(&m), &k4, true);
    let mut swallowed: Vec<(String, Vec<String>)> = ident
        .swallowed
        .iter()
        .map(|s| (s.offsets.join(" "), s.errors.clone()))
        .collect();
    swallowed.sort();
    assert_eq!(
        swallowed,
        vec![
            ("dx0".to_string(), vec!["XOC".to_string()]),
            ("dy0".to_string(), vec!["YOA".to_string()]),
            ("dz0".to_string(), vec!["ZOA".to_string()]),
        ]
    );
    for (j, name) in ident.fit.names.iter().enumerate() {
        let term = ident.model.terms[j];
        match name.as_str() {
            "XOC" | "YOA" | "ZOA" | "dx0" | "dy0" | "dz0" => {
                assert_eq!(
                    ident.fit.values[j], None,
                    "{name} cannot be determined from zeroed readings"
                )
            }
            _ => {
                let err = (ident.fit.values[j].unwrap() - true_value(&t, term.effect))
                    * term.effect.display_factor(&m);
                assert!(err.abs() < 1e-4, "{name}: off by {err:e}");
            }
        }
    }
}

#[test]
fn a_path_that_cannot_separate_the_model_is_reported_not_solved_into_nonsense() {
    // The reduced model on K1 alone: A stays at 0, only C turns.
    let m = machine();
    let t = truth(&m, "seed-ac-reduced");
    let k1 = simulate(&m, &t, &path(&m, "K1")).unwrap();
    let ident = identify_one(&m, &reduced(&m), &k1, &IdentifyOptions::default()).unwrap();
    assert!(ident.fit.rank < 11, "rank {}", ident.fit.rank);
    let groups: Vec<Vec<String>> = ident
        .fit
        .identifiability
        .confounded
        .iter()
        .map(|g| g.iter().map(|&j| ident.fit.names[j].clone()).collect())
        .collect();
    assert!(!groups.is_empty());
    for g in &groups {
        for name in g {
            let j = ident.fit.names.iter().position(|n| n == name).unwrap();
            assert_eq!(
                ident.fit.values[j], None,
                "{name} is in a confounded group {g:?} and gets no number"
            );
        }
    }
    // What K1 does determine (AOC: the tilt of C about x, seen as a once-per-turn wobble) is
    // right, and exactly so after the refinement against the exact machine, which iterates on
    // the whole minimum-norm solution (the undetermined groups included).
    let refined = refined(&m, &reduced(&m), &k1, false);
    let j = refined.fit.names.iter().position(|n| n == "AOC").unwrap();
    let aoc_refined = refined.fit.values[j].expect("AOC is determined on K1");
    assert!(
        (aoc_refined * 1e6 - 30.0).abs() < 1e-4,
        "refined AOC {} µrad",
        aoc_refined * 1e6
    );
    assert!(
        refined.fit.residual_rms() * 1e3 < 1e-6,
        "the exact residual vanishes: {}",
        refined.fit.residual_rms()
    );
    let j = ident.fit.names.iter().position(|n| n == "AOC").unwrap();
    let aoc = ident.fit.values[j].expect("AOC is determined on K1");
    assert!((aoc * 1e6 - 30.0).abs() < 0.01, "AOC {} µrad", aoc * 1e6);
    // A constraint chosen by the user gives numbers, and says so.
    let opts = IdentifyOptions::new().constraint(Constraint::MinimumNorm);
    let forced = identify_one(&m, &reduced(&m), &k1, &opts).unwrap();
    assert!(forced.fit.values.iter().all(Option::is_some));
}
