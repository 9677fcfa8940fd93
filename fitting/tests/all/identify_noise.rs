//! Honest uncertainties under correlated noise: the reduced model of `seed-ac` identified on K4
//! over 20 noise seeds, white (σ = 0.5 µm) and AR(1) (φ = 0.8, σ = 0.3 µm), with the noise
//! estimated from the residual, declared, or taken from a static record. The mean of
//! z² = ((estimate − truth)/std)² over seeds and errors must lie in [0.5, 1.6] and at most
//! 1 % of the |z| beyond 4 (the band is justified in `docs/identification.md`, section
//! "Noise model"); the ordinary fit fails it under AR(1) noise.

use crate::one_record::{identify_one, identify_refined_one};
use fitting::noise::{NoiseChoice, NoiseModel, NoiseSource};
use fitting::{IdentifyOptions, RefineOptions};
use formats::truth::builtin_truth;
use model_spec::{Machine, builtin};
use simulation::model::Model;
use simulation::paths::builtin_path;
use simulation::readings::simulate;
use simulation::record::Record;
use simulation::truth::Truth;

const SEEDS: u64 = 20;

fn machine() -> Machine {
    builtin("seed-ac").unwrap().unwrap()
}

fn reduced(m: &Machine) -> Model {
    Model::constant(m.model_errors("reduced").unwrap())
}

fn truth(m: &Machine, sigma_mm: f64, phi: f64, seed: u64) -> Truth {
    let mut t = builtin_truth("seed-ac-reduced", m).unwrap().unwrap();
    t.noise_mm = sigma_mm;
    t.noise_phi = phi;
    t.seed = seed;
    t
}

/// The R-test standing still at K4's first pose for `n` samples.
fn static_path(m: &Machine, n: usize) -> Record {
    let k4 = builtin_path(m, "K4").unwrap().unwrap();
    let mut samples = vec![k4.samples[0].clone(); n];
    for (i, s) in samples.iter_mut().enumerate() {
        s.t = i as f64 * 0.1;
    }
    Record {
        samples,
        ..Default::default()
    }
}

/// The z-scores of the 11 errors over the seeds, and the noise models used.
fn z_scores(
    m: &Machine,
    sigma_mm: f64,
    phi: f64,
    choice: &dyn Fn(u64) -> NoiseChoice,
) -> (Vec<f64>, Vec<NoiseModel>) {
    let model = reduced(m);
    let k4 = builtin_path(m, "K4").unwrap().unwrap();
    let (mut z, mut models) = (Vec::new(), Vec::new());
    for seed in 1..=SEEDS {
        let t = truth(m, sigma_mm, phi, seed);
        let data = simulate(m, &t, &k4).unwrap();
        let (ident, r) = identify_refined_one(
            m,
            &model,
            &data,
            &IdentifyOptions::new().noise(choice(seed).clone()),
            &RefineOptions::default(),
        )
        .unwrap();
        assert!(r.converged);
        for (j, term) in model.terms.iter().enumerate() {
            let truth = t.coefficient(term).unwrap()[0];
            z.push((ident.fit.values[j].unwrap() - truth) / ident.fit.std[j].unwrap());
        }
        models.push(ident.noise);
    }
    (z, models)
}

/// Mean z² and the share of |z| > 4.
fn summary(z: &[f64]) -> (f64, f64) {
    let mean = z.iter().map(|v| v * v).sum::<f64>() / z.len() as f64;
    let beyond = z.iter().filter(|v| v.abs() > 4.0).count() as f64 / z.len() as f64;
    (mean, beyond)
}

fn assert_honest(what: &str, z: &[f64]) {
    let (mean, beyond) = summary(z);
    println!(
        "{what}: mean z² {mean:.2}, |z| > 4: {:.1} %",
        100.0 * beyond
    );
    assert!((0.5..=1.6).contains(&mean), "{what}: mean z² {mean}");
    assert!(beyond <= 0.01, "{what}: {:.1} % beyond 4", 100.0 * beyond);
}

#[test]
fn white_noise_estimated_gives_honest_uncertainties() {
    let m = machine();
    let (z, models) = z_scores(&m, 0.5e-3, 0.0, &|_| NoiseChoice::Estimate);
    assert_honest("white 0.5 µm, estimated", &z);
    for n in &models {
        assert!(
            matches!(
                n.source,
                NoiseSource::Estimated {
                    records: 1,
                    samples: 241
                }
            ),
            "{n}"
        );
        assert!(n.phi.iter().all(|&p| p < 0.3), "{n}");
    }
}

#[test]
fn ar1_noise_estimated_gives_honest_uncertainties_where_ordinary_fails() {
    let m = machine();
    let (z, models) = z_scores(&m, 0.3e-3, 0.8, &|_| NoiseChoice::Estimate);
    assert_honest("AR(1) 0.8, 0.3 µm, estimated", &z);
    let mean_phi = models.iter().flat_map(|n| n.phi).sum::<f64>() / (3 * models.len()) as f64;
    assert!((mean_phi - 0.8).abs() < 0.1, "mean φ̂ {mean_phi}");
    // The ordinary fit trusts white noise: its uncertainties are several times too small.
    let (z, _) = z_scores(&m, 0.3e-3, 0.8, &|_| NoiseChoice::Ordinary);
    let (mean, beyond) = summary(&z);
    println!(
        "AR(1) 0.8, 0.3 µm, ordinary: mean z² {mean:.2}, |z| > 4: {:.1} %",
        100.0 * beyond
    );
    assert!(
        mean > 3.0 && beyond > 0.03,
        "ordinary: mean z² {mean}, {beyond}"
    );
}

#[test]
fn ar1_noise_declared_gives_honest_uncertainties() {
    let m = machine();
    let declared = NoiseModel::parse("ar1:phi=0.8,sigma=0.3").unwrap();
    let (z, models) = z_scores(&m, 0.3e-3, 0.8, &|_| NoiseChoice::Model(declared.clone()));
    assert_honest("AR(1) 0.8, 0.3 µm, declared", &z);
    assert!(models.iter().all(|n| *n == declared));
}

#[test]
fn ar1_noise_from_a_static_record_gives_honest_uncertainties() {
    let m = machine();
    let still = static_path(&m, 400);
    let choice = |seed: u64| {
        // Another seed than the measurement's: the static record is another run.
        let record = simulate(&m, &truth(&m, 0.3e-3, 0.8, 1000 + seed), &still).unwrap();
        NoiseChoice::Model(NoiseModel::from_static_record(&record).unwrap())
    };
    let (z, models) = z_scores(&m, 0.3e-3, 0.8, &choice);
    assert_honest("AR(1) 0.8, 0.3 µm, static record", &z);
    assert!(
        models
            .iter()
            .all(|n| n.source == NoiseSource::StaticRecord { samples: 400 })
    );
}

#[test]
fn white_noise_gls_values_stay_within_noise_of_the_ordinary_ones() {
    let m = machine();
    let model = reduced(&m);
    let k4 = builtin_path(&m, "K4").unwrap().unwrap();
    let data = simulate(&m, &truth(&m, 0.5e-3, 0.0, 3), &k4).unwrap();
    let opts = IdentifyOptions::new();
    let ordinary = identify_one(
        &m,
        &model,
        &data,
        &opts.clone().noise(NoiseChoice::Ordinary),
    )
    .unwrap();
    let gls = identify_one(
        &m,
        &model,
        &data,
        &opts.clone().noise(NoiseChoice::Estimate),
    )
    .unwrap();
    assert_eq!(gls.fit.rank, ordinary.fit.rank);
    assert_eq!(gls.fit.condition, ordinary.fit.condition);
    for j in 0..model.terms.len() {
        let (a, b) = (ordinary.fit.values[j].unwrap(), gls.fit.values[j].unwrap());
        let (sa, sb) = (ordinary.fit.std[j].unwrap(), gls.fit.std[j].unwrap());
        assert!(
            (a - b).abs() < 0.3 * sa,
            "parameter {j}: {a} vs {b} (std {sa})"
        );
        assert!(
            (sb / sa - 1.0).abs() < 0.15,
            "parameter {j}: std {sa} vs {sb}"
        );
    }
    let w = gls.whitened_sigma.unwrap();
    assert!((w - 1.0).abs() < 0.1, "whitened σ̂ {w}");
}

#[test]
fn noise_free_data_fall_back_to_white_and_stay_exact() {
    let m = machine();
    let model = reduced(&m);
    let k4 = builtin_path(&m, "K4").unwrap().unwrap();
    let t = truth(&m, 0.0, 0.0, 1);
    let data = simulate(&m, &t, &k4).unwrap();
    let (ident, _) = identify_refined_one(
        &m,
        &model,
        &data,
        &IdentifyOptions::new().noise(NoiseChoice::Estimate),
        &RefineOptions::default(),
    )
    .unwrap();
    match &ident.noise.source {
        NoiseSource::Residual { why } => assert!(why.contains("below the floor"), "{why}"),
        other => panic!("noise-free data gave a noise model {other:?}"),
    }
    assert!(ident.noise.is_uniform_white());
    for (j, term) in model.terms.iter().enumerate() {
        let err = ident.fit.values[j].unwrap() - t.coefficient(term).unwrap()[0];
        assert!(err.abs() < 1e-10, "parameter {j}: off by {err:e}");
        assert!(ident.fit.std[j].unwrap().is_finite());
    }
}

#[test]
fn ar1_simulation_has_its_marginal_sigma_and_phi_and_phi_zero_keeps_the_white_draws() {
    let m = machine();
    let still = static_path(&m, 4000);
    let record = simulate(&m, &truth(&m, 0.3e-3, 0.8, 5), &still).unwrap();
    let n = NoiseModel::from_static_record(&record).unwrap();
    for d in 0..3 {
        assert!((n.sigma_mm[d] / 0.3e-3 - 1.0).abs() < 0.1, "{n}");
        assert!((n.phi[d] - 0.8).abs() < 0.03, "{n}");
    }
    // φ = 0 draws exactly what white noise always drew: σ·n_t.
    let white = simulate(&m, &truth(&m, 0.3e-3, 0.0, 5), &still).unwrap();
    let clean = simulate(&m, &truth(&m, 0.0, 0.0, 5), &still).unwrap();
    let mut rng = simulation::rng::Rng::new(5);
    for (w, c) in white.measured.iter().zip(&clean.measured) {
        for d in 0..3 {
            assert_eq!(w[d], c[d] + 0.3e-3 * rng.normal());
        }
    }
}
