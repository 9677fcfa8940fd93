//! The covariance of sensor readings in the fit: the whitened fit's uncertainties are those of
//! a Monte-Carlo; identification from a sensor record agrees with the ball-centre record of the
//! same run; a declared noise model is refused; the sensors' gain errors are the instrument
//! terms `S`.

use crate::one_record::{identify_one, identify_refined_one};
use fitting::calibrate::instrument_terms;
use fitting::noise::{NoiseChoice, NoiseError, NoiseModel, NoiseSource};
use fitting::{EstimateError, IdentifyOptions, RefineOptions};
use formats::truth::builtin_truth;
use model_spec::instrument::{Instrument, ReadingsFrame, preset};
use model_spec::{Machine, builtin};
use simulation::instrument::convert::{SensorRecord, to_record};
use simulation::instrument::head::SensorHead;
use simulation::instrument::simulate::simulate_sensors;
use simulation::model::{Effect, Model, Term};
use simulation::record::Record;
use simulation::rng::Rng;
use simulation::{builtin_path, simulate};

fn seed_ac() -> Machine {
    builtin("seed-ac").unwrap().unwrap()
}

fn instrument(name: &str) -> Instrument {
    preset(name).unwrap().unwrap()
}

fn k4_reduced(m: &Machine) -> Record {
    let truth = builtin_truth("seed-ac-reduced", m).unwrap().unwrap();
    simulate(m, &truth, &builtin_path(m, "K4").unwrap().unwrap()).unwrap()
}

/// The standard deviation of `v`.
fn spread(v: &[f64]) -> f64 {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

/// Per parameter, the mean reported uncertainty and the Monte-Carlo spread of the values.
type Spreads = Vec<(f64, f64)>;

/// The parameters' names, their [`Spreads`] weighted (with covariances) and unweighted (the
/// same records without them), over `seeds`, and the mean whitened σ̂ of the weighted fits.
fn monte_carlo(i: &Instrument, seeds: u64) -> (Vec<String>, [Spreads; 2], f64) {
    let m = seed_ac();
    let model = Model::of(&m, "reduced").unwrap();
    let clean = k4_reduced(&m);
    let head = SensorHead::new(i);
    let readings: Vec<Vec<f64>> = clean
        .measured
        .iter()
        .map(|e| head.readings(*e).unwrap())
        .collect();
    let opts = IdentifyOptions::default();
    let p = model.width();
    let mut values = [vec![Vec::new(); p], vec![Vec::new(); p]];
    let mut stds = [vec![0.0; p], vec![0.0; p]];
    let mut whitened = 0.0;
    let mut names = Vec::new();
    for seed in 0..seeds {
        let mut rng = Rng::new(1000 + seed);
        let noisy = SensorRecord {
            record: Record {
                samples: clean.samples.clone(),
                ..Default::default()
            },
            readings: readings
                .iter()
                .map(|r| {
                    r.iter()
                        .zip(&head.noise_mm)
                        .map(|(v, s)| v + s * rng.normal())
                        .collect()
                })
                .collect(),
        };
        let weighted = to_record(&head, &m, ReadingsFrame::Tool, &noisy).unwrap();
        let mut unweighted = weighted.clone();
        unweighted.covariance.clear();
        for (k, r) in [weighted, unweighted].iter().enumerate() {
            let id = identify_one(&m, &model, r, &opts).unwrap();
            for j in 0..p {
                values[k][j].push(id.fit.values[j].unwrap());
                stds[k][j] += id.fit.std[j].unwrap() / seeds as f64;
            }
            if k == 0 {
                whitened += id.whitened_sigma.unwrap() / seeds as f64;
            }
            names.clone_from(&id.fit.names);
        }
    }
    let pairs = |k: usize| -> Vec<(f64, f64)> {
        (0..p)
            .map(|j| (stds[k][j], spread(&values[k][j])))
            .collect()
    };
    (names, [pairs(0), pairs(1)], whitened)
}

/// With 45° sensors the whitened fit's uncertainties match the Monte-Carlo spread of 300
/// seeds within 10 %; the unweighted fit's spread is larger and its reported uncertainties
/// are off.
#[test]
fn the_whitened_fit_is_honest_and_more_efficient() {
    // One sensor three times noisier than the others: the error vector's noise is then
    // correlated across x, y, z (the symmetric layout with equal σ is only anisotropic).
    let mut i = instrument("inclined-45");
    i.sensors[0].noise_mm = 0.3e-3;
    let (names, [weighted, unweighted], whitened) = monte_carlo(&i, 300);
    let mut worst_weighted: f64 = 0.0;
    let mut worst_unweighted: f64 = 0.0;
    let mut least_gain = f64::INFINITY;
    for (j, name) in names.iter().enumerate() {
        let (std_w, mc_w) = weighted[j];
        let (std_u, mc_u) = unweighted[j];
        eprintln!(
            "{name}: weighted std/MC {:.3}, unweighted std/MC {:.3}, MC spread unweighted/weighted {:.3}",
            std_w / mc_w,
            std_u / mc_u,
            mc_u / mc_w
        );
        worst_weighted = worst_weighted.max((std_w / mc_w - 1.0).abs());
        worst_unweighted = worst_unweighted.max((std_u / mc_u - 1.0).abs());
        least_gain = least_gain.min(mc_u / mc_w);
    }
    eprintln!(
        "worst |std/MC − 1|: weighted {worst_weighted:.3}, unweighted {worst_unweighted:.3}; whitened σ̂ {whitened:.3}"
    );
    assert!(worst_weighted < 0.10, "{worst_weighted}");
    assert!(worst_unweighted > 0.10, "{worst_unweighted}");
    // Generalized least squares is the best linear unbiased estimator: no parameter is
    // estimated better without the weights (within the Monte-Carlo's own spread).
    assert!(least_gain > 0.95, "{least_gain}");
    // The instrument's σ are the truth's: the whitened residual has σ̂ ≈ 1.
    assert!((whitened - 1.0).abs() < 0.02, "{whitened}");
}

/// The symmetric preset with equal σ: measured, reported in the docs.
#[test]
fn the_symmetric_preset_weighted_and_unweighted() {
    let (names, [weighted, unweighted], _) = monte_carlo(&instrument("inclined-45"), 300);
    for (j, name) in names.iter().enumerate() {
        let ((std_w, mc_w), (std_u, mc_u)) = (weighted[j], unweighted[j]);
        eprintln!(
            "{name}: weighted std/MC {:.3}, unweighted std/MC {:.3}, unweighted/weighted spread {:.3}",
            std_w / mc_w,
            std_u / mc_u,
            mc_u / mc_w
        );
        assert!((std_w / mc_w - 1.0).abs() < 0.1, "{name}");
    }
}

#[test]
fn a_sensor_record_identifies_what_the_ball_centre_record_of_the_same_run_does() {
    let m = seed_ac();
    let model = Model::of(&m, "reduced").unwrap();
    let path = builtin_path(&m, "K4").unwrap().unwrap();
    let mut truth = builtin_truth("seed-ac-reduced", &m).unwrap().unwrap();
    let opts = IdentifyOptions::default();
    let refine = RefineOptions::default();
    // Noise-free sensors (σ 1e-6 µm) and displacement: the two identifications are one.
    let mut quiet = instrument("inclined-45");
    for s in &mut quiet.sensors {
        s.noise_mm = 1e-9;
    }
    let ball = simulate(&m, &truth, &path).unwrap();
    let sensors = simulate_sensors(&m, &truth, &path, &quiet, ReadingsFrame::Tool).unwrap();
    let read = to_record(&SensorHead::new(&quiet), &m, ReadingsFrame::Tool, &sensors).unwrap();
    let (a, _) = identify_refined_one(&m, &model, &ball, &opts, &refine).unwrap();
    let (b, _) = identify_refined_one(&m, &model, &read, &opts, &refine).unwrap();
    for (j, name) in a.fit.names.iter().enumerate() {
        let (x, y) = (a.fit.values[j].unwrap(), b.fit.values[j].unwrap());
        assert!((x - y).abs() < 1e-8, "{name}: {x} vs {y}");
    }
    // The same run with noise: the displacement's (0.3 µm) and the sensors' (0.1 µm).
    truth.noise_mm = 0.3e-3;
    truth.seed = 17;
    let i = instrument("inclined-45");
    let ball = simulate(&m, &truth, &path).unwrap();
    let sensors = simulate_sensors(&m, &truth, &path, &i, ReadingsFrame::Tool).unwrap();
    let read = to_record(&SensorHead::new(&i), &m, ReadingsFrame::Tool, &sensors).unwrap();
    let (a, _) = identify_refined_one(
        &m,
        &model,
        &ball,
        &opts.clone().noise(NoiseChoice::Estimate),
        &refine,
    )
    .unwrap();
    let (b, _) = identify_refined_one(
        &m,
        &model,
        &read,
        &opts.clone().noise(NoiseChoice::Estimate),
        &refine,
    )
    .unwrap();
    for (j, name) in a.fit.names.iter().enumerate() {
        let (x, y) = (a.fit.values[j].unwrap(), b.fit.values[j].unwrap());
        // The difference is the sensors' noise alone, about a third of the total: well
        // within the identification's own uncertainty.
        let std = b.fit.std[j].unwrap();
        eprintln!(
            "{name}: ball {x:e}, sensors {y:e}, difference {:.2} std",
            (x - y) / std
        );
        assert!((x - y).abs() < 2.0 * std, "{name}: {x} vs {y} (std {std})");
    }
}

#[test]
fn a_declared_noise_model_is_refused_for_readings_with_covariances() {
    let m = seed_ac();
    let model = Model::of(&m, "reduced").unwrap();
    let truth = builtin_truth("seed-ac-reduced", &m).unwrap().unwrap();
    let path = builtin_path(&m, "K4").unwrap().unwrap();
    let i = instrument("inclined-45");
    let sensors = simulate_sensors(&m, &truth, &path, &i, ReadingsFrame::Tool).unwrap();
    let read = to_record(&SensorHead::new(&i), &m, ReadingsFrame::Tool, &sensors).unwrap();
    let declared = NoiseChoice::Model(NoiseModel::white(1e-4, NoiseSource::Declared));
    let e = identify_one(
        &m,
        &model,
        &read,
        &IdentifyOptions::default().noise(declared.clone()),
    )
    .unwrap_err();
    assert!(
        matches!(e, EstimateError::Noise(NoiseError::DeclaredTwice)),
        "{e}"
    );
    let e = identify_refined_one(
        &m,
        &model,
        &read,
        &IdentifyOptions::default().noise(declared.clone()),
        &RefineOptions::default(),
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .contains("declare the reading noise a second time"),
        "{e}"
    );
    // Estimated (over time, from the whitened rows) and ordinary are fine.
    for choice in [NoiseChoice::Estimate, NoiseChoice::Ordinary] {
        identify_one(
            &m,
            &model,
            &read,
            &IdentifyOptions::default().noise(choice.clone()),
        )
        .unwrap();
    }
}

/// Gain errors δg of the sensors, read with the described head, are the instrument terms
/// `S = (AᵀWA)⁻¹AᵀW·diag(δg)·A`: exactly for flat tips, to first order for ball tips.
#[test]
fn sensor_gain_errors_are_the_instrument_terms() {
    let mut rng = Rng::new(8);
    // Flat tips: exact to rounding. Ball tips: the second-order terms of the geometry
    // (|e|/(R + r) ≤ 1 % here) times the gain errors' effect.
    for (name, relative) in [
        ("orthogonal", 1e-12),
        ("inclined-45", 2e-2),
        ("four-45", 2e-2),
    ] {
        let described = instrument(name);
        let mut real = described.clone();
        let dg: Vec<f64> = real.sensors.iter().map(|_| 2e-3 * rng.normal()).collect();
        for (s, d) in real.sensors.iter_mut().zip(&dg) {
            s.gain *= 1.0 + d;
        }
        let (nominal, actual) = (SensorHead::new(&described), SensorHead::new(&real));
        let s = instrument_terms(&nominal, &dg).unwrap();
        let s_norm = s.iter().flatten().map(|v| v * v).sum::<f64>().sqrt();
        for _ in 0..50 {
            let e = [0.0; 3].map(|_: f64| 0.05 * rng.normal());
            let read = nominal
                .displacement(&actual.readings(e).unwrap(), false)
                .unwrap()
                .displacement;
            let size = (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt();
            for a in 0..3 {
                let predicted = e[a] + (0..3).map(|b| s[a][b] * e[b]).sum::<f64>();
                assert!(
                    (read[a] - predicted).abs() <= relative * s_norm * size + 1e-15,
                    "{name}: {} vs {predicted}",
                    read[a]
                );
            }
        }
    }
    // Three sensors: S = A⁻¹·diag(δg)·A; orthogonal: S is diag(δg).
    let h = SensorHead::new(&instrument("orthogonal"));
    let s = instrument_terms(&h, &[1e-3, -2e-3, 3e-3]).unwrap();
    assert_eq!(s, [[1e-3, 0.0, 0.0], [0.0, -2e-3, 0.0], [0.0, 0.0, 3e-3]]);
}

/// Identifying `S` with the machine from the records of a head whose gains are off gives the
/// `S` of its gain errors, except its isotropic part: `(I + c·I)` scales every reading as the
/// machine's errors scaled by `1 + c` do, so no R-test record tells them apart (a length
/// reference, a calibration, does). With `SZZ` left out (its gauge), the fit finds
/// `S' = (S − c·I)/(1 + c)`, `c` the true `SZZ`, and the errors scaled by `1 + c`.
#[test]
fn identifying_s_with_the_machine_identifies_the_gain_errors_but_their_scale() {
    let m = seed_ac();
    let reduced = Model::of(&m, "reduced").unwrap();
    let mut model = reduced.clone();
    for reading in model_spec::Dir::ALL {
        for displacement in model_spec::Dir::ALL {
            if reading == model_spec::Dir::Z && displacement == model_spec::Dir::Z {
                continue;
            }
            model.terms.push(Term {
                effect: Effect::Instrument {
                    reading,
                    displacement,
                },
                basis: simulation::model::Basis::Const,
            });
        }
    }
    // Three sensors at 45° with flat tips, whose readings are linear: the gain errors are then
    // exactly S (ball tips add a term δg·|e⊥|²/(2(R + r)) that S cannot hold, about 2e-7 mm
    // here, which the fit's conditioning turns into deviations of S up to 9e-5).
    let mut described = instrument("inclined-45");
    for s in &mut described.sensors {
        s.tip = model_spec::instrument::Tip::Flat {
            face_radius_mm: 4.0,
        };
        s.position_mm = s.direction.map(|v| -12.7 * v);
    }
    let mut real = described.clone();
    let dg = [4e-3, -3e-3, 2e-3];
    for (s, d) in real.sensors.iter_mut().zip(dg) {
        s.gain *= 1.0 + d;
        s.noise_mm = 1e-8;
    }
    let truth = builtin_truth("seed-ac-reduced", &m).unwrap().unwrap();
    let path = builtin_path(&m, "K4").unwrap().unwrap();
    let sensors = simulate_sensors(&m, &truth, &path, &real, ReadingsFrame::Tool).unwrap();
    let read = to_record(
        &SensorHead::new(&described),
        &m,
        ReadingsFrame::Tool,
        &sensors,
    )
    .unwrap();
    let (id, _) = identify_refined_one(
        &m,
        &model,
        &read,
        &IdentifyOptions::default().noise(NoiseChoice::Ordinary),
        &RefineOptions::default(),
    )
    .unwrap();
    let s = instrument_terms(&SensorHead::new(&described), &dg).unwrap();
    let c = s[2][2];
    let value = |name: &str| {
        let j = id.fit.names.iter().position(|n| n == name).unwrap();
        id.fit.values[j].unwrap()
    };
    for (a, ra) in ["X", "Y", "Z"].iter().enumerate() {
        for (b, rb) in ["X", "Y", "Z"].iter().enumerate() {
            if a == 2 && b == 2 {
                continue;
            }
            let name = format!("S{ra}{rb}");
            let want = (s[a][b] - if a == b { c } else { 0.0 }) / (1.0 + c);
            let v = value(&name);
            let j = id.fit.names.iter().position(|n| *n == name).unwrap();
            let std = id.fit.std[j].unwrap();
            eprintln!("{name}: identified {v:.6e} ± {std:.1e}, from the gains {want:.6e}");
            assert!(
                (v - want).abs() < 4.0 * std,
                "{name}: {v} vs {want} (std {std})"
            );
        }
    }
    for (k, t) in reduced.terms.iter().enumerate() {
        let name = t.spelling(&m);
        let want = truth.coefficient(t).unwrap()[0] * (1.0 + c);
        let v = value(&name);
        assert!(
            (v - want).abs() < 1e-5 * want.abs(),
            "{k} {name}: {v} vs {want}"
        );
    }
}
