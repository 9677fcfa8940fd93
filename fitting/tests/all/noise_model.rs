//! The noise model: the variogram estimator on pure AR(1) series of the lengths of K1, K2 and
//! K4 (σ and φ within the tolerances of `docs/identification.md`, not fooled by a smooth
//! misfit of 3 µm nor by slow noise), Yule–Walker on static records, the prewhitening, and the
//! declared specifications.

use fitting::noise::{
    MIN_STATIC_SAMPLES, NoiseChoice, NoiseError, NoiseModel, NoiseSource, variogram,
};
use simulation::record::{Record, Sample};
use simulation::rng::Rng;
use std::f64::consts::PI;

/// AR(1) noise per direction, stationary start, as `rtest simulate --noise-phi` draws it.
fn ar1(n: usize, phi: f64, sigma: f64, rng: &mut Rng) -> Vec<[f64; 3]> {
    let innovation = sigma * (1.0 - phi * phi).sqrt();
    let mut e = [0.0; 3];
    (0..n)
        .map(|t| {
            for v in &mut e {
                let z = rng.normal();
                *v = if t == 0 {
                    sigma * z
                } else {
                    phi * *v + innovation * z
                };
            }
            e
        })
        .collect()
}

/// Adds a smooth misfit of amplitude `amp` (mm), once per revolution of `per_rev` samples.
fn add_misfit(s: &mut [[f64; 3]], amp: f64, per_rev: f64) {
    for (t, r) in s.iter_mut().enumerate() {
        let th = 2.0 * PI * t as f64 / per_rev;
        r[0] += amp * th.cos();
        r[1] += amp * th.sin();
        r[2] += amp * (th + 1.0).cos();
    }
}

/// (mean, 5th percentile, 95th percentile) of `v`.
fn stats(v: &[f64]) -> (f64, f64, f64) {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let at = |q: f64| s[((s.len() - 1) as f64 * q).round() as usize];
    (v.iter().sum::<f64>() / v.len() as f64, at(0.05), at(0.95))
}

/// σ̂/σ and φ̂ over `seeds` seeds and the three directions.
fn estimates(n: usize, phi: f64, sigma: f64, misfit: Option<(f64, f64)>) -> (Vec<f64>, Vec<f64>) {
    let (mut ratios, mut phis) = (Vec::new(), Vec::new());
    for seed in 0..60 {
        let mut s = ar1(n, phi, sigma, &mut Rng::new(1000 + seed));
        if let Some((amp, per_rev)) = misfit {
            add_misfit(&mut s, amp, per_rev);
        }
        let m = NoiseModel::estimate(&[&s]).unwrap();
        assert!(matches!(m.source, NoiseSource::Estimated { records: 1, samples } if samples == n));
        for d in 0..3 {
            ratios.push(m.sigma_mm[d] / sigma);
            phis.push(m.phi[d]);
        }
    }
    (ratios, phis)
}

const LENGTHS: [(&str, usize); 3] = [("K1", 361), ("K2", 121), ("K4", 241)];

#[test]
fn white_noise_is_estimated_white_with_its_sigma() {
    for (name, n) in LENGTHS {
        let (r, p) = estimates(n, 0.0, 0.5e-3, None);
        let (rm, r5, r95) = stats(&r);
        let (pm, _, p95) = stats(&p);
        println!("{name}: σ̂/σ mean {rm:.3} [{r5:.3}, {r95:.3}], φ̂ mean {pm:.3}, 95 % {p95:.2}");
        assert!((0.96..=1.04).contains(&rm), "{name}: σ̂/σ mean {rm}");
        assert!(
            r5 > 0.8 && r95 < 1.2,
            "{name}: σ̂/σ 90 % range [{r5}, {r95}]"
        );
        assert!(pm < 0.06 && p95 <= 0.2, "{name}: φ̂ mean {pm}, 95 % {p95}");
    }
}

#[test]
fn slow_noise_is_estimated_with_its_sigma_and_phi() {
    for (name, n) in LENGTHS {
        let (r, p) = estimates(n, 0.8, 0.3e-3, None);
        let (rm, r5, r95) = stats(&r);
        let (pm, p5, p95) = stats(&p);
        println!(
            "{name}: σ̂/σ mean {rm:.3} [{r5:.3}, {r95:.3}], φ̂ mean {pm:.3} [{p5:.2}, {p95:.2}]"
        );
        assert!((0.9..=1.1).contains(&rm), "{name}: σ̂/σ mean {rm}");
        assert!(
            r5 > 0.6 && r95 < 1.6,
            "{name}: σ̂/σ 90 % range [{r5}, {r95}]"
        );
        assert!((0.72..=0.85).contains(&pm), "{name}: φ̂ mean {pm}");
        assert!(
            p5 > 0.5 && p95 <= 0.95,
            "{name}: φ̂ 90 % range [{p5}, {p95}]"
        );
    }
}

#[test]
fn a_smooth_misfit_of_3_um_does_not_inflate_sigma() {
    // K4: 241 samples at 1.5° (240 per revolution); K1: 361 at 1° (360 per revolution).
    for (name, n, per_rev) in [("K4", 241, 240.0), ("K1", 361, 360.0)] {
        for (phi, sigma) in [(0.0, 0.5e-3), (0.8, 0.3e-3)] {
            let (r, p) = estimates(n, phi, sigma, Some((3e-3, per_rev)));
            let (rm, _, r95) = stats(&r);
            let (pm, _, _) = stats(&p);
            println!(
                "{name} φ = {phi} + 3 µm misfit: σ̂/σ mean {rm:.3}, 95 % {r95:.3}, φ̂ mean {pm:.3}"
            );
            assert!(
                (0.9..=1.12).contains(&rm),
                "{name} φ = {phi}: σ̂/σ mean {rm}"
            );
            assert!(r95 < 1.7, "{name} φ = {phi}: σ̂/σ 95 % {r95}");
            assert!((pm - phi).abs() < 0.08, "{name} φ = {phi}: φ̂ mean {pm}");
            // The misfit alone is more than four times the noise: any estimate from the residual's spread
            // would be far off.
            let s = {
                let mut s = ar1(n, phi, sigma, &mut Rng::new(7));
                add_misfit(&mut s, 3e-3, per_rev);
                s
            };
            let rms = (s.iter().map(|r| r[0] * r[0]).sum::<f64>() / n as f64).sqrt();
            assert!(rms > 4.0 * sigma, "{name}: the misfit dominates the spread");
        }
    }
}

#[test]
fn a_white_only_difference_estimate_is_fooled_by_slow_noise() {
    // What the variogram fit avoids: σ from first differences assuming white noise,
    // √(V(1)/6) of the second differences, is √0.147 of σ at φ = 0.8.
    let mut ratios = Vec::new();
    for seed in 0..40 {
        let s = ar1(241, 0.8, 0.3e-3, &mut Rng::new(seed));
        let v = variogram(&[&s], 1);
        ratios.push((v.values[0][0] / 6.0).sqrt() / 0.3e-3);
    }
    let (m, _, _) = stats(&ratios);
    assert!(
        (m - 0.147f64.sqrt()).abs() < 0.05,
        "white-only estimate {m}"
    );
}

#[test]
fn records_are_pooled_and_a_short_or_flat_residual_is_refused() {
    let a = ar1(121, 0.8, 0.3e-3, &mut Rng::new(1));
    let b = ar1(361, 0.8, 0.3e-3, &mut Rng::new(2));
    let m = NoiseModel::estimate(&[&a, &b]).unwrap();
    assert_eq!(
        m.source,
        NoiseSource::Estimated {
            records: 2,
            samples: 482
        }
    );
    assert!(
        m.to_string()
            .contains("estimated from 2 records (482 samples)"),
        "{m}"
    );
    let short = ar1(30, 0.0, 0.3e-3, &mut Rng::new(3));
    let e = NoiseModel::estimate(&[&short]).unwrap_err();
    assert!(
        matches!(e, NoiseError::Unestimable(_)) && e.to_string().contains("lag"),
        "{e}"
    );
    // A residual at rounding level is no noise.
    let tiny: Vec<[f64; 3]> = ar1(241, 0.0, 1e-13, &mut Rng::new(4));
    let e = NoiseModel::estimate(&[&tiny]).unwrap_err();
    assert!(e.to_string().contains("below the floor"), "{e}");
    let mut nan = a.clone();
    nan[5][1] = f64::NAN;
    assert!(
        NoiseModel::estimate(&[&nan])
            .unwrap_err()
            .to_string()
            .contains("sample 6")
    );
}

/// A static record of `n` samples of `noise` (one axis standing at 0).
fn static_record(noise: Vec<[f64; 3]>) -> Record {
    Record {
        samples: (0..noise.len())
            .map(|i| Sample {
                commands: vec![0.0, 0.5],
                t: i as f64 * 0.1,
                motion: vec![1, 1],
                timed: true,
            })
            .collect(),
        measured: noise,
        ..Default::default()
    }
}

#[test]
fn a_static_record_gives_sigma_and_phi_by_yule_walker() {
    let (mut r, mut p) = (Vec::new(), Vec::new());
    for seed in 0..60 {
        let mut noise = ar1(400, 0.8, 0.3e-3, &mut Rng::new(seed));
        // A constant offset is removed with the mean.
        noise.iter_mut().for_each(|v| v[2] += 0.05);
        let m = NoiseModel::from_static_record(&static_record(noise)).unwrap();
        assert_eq!(m.source, NoiseSource::StaticRecord { samples: 400 });
        for d in 0..3 {
            r.push(m.sigma_mm[d] / 0.3e-3);
            p.push(m.phi[d]);
        }
    }
    let ((rm, r5, r95), (pm, p5, p95)) = (stats(&r), stats(&p));
    println!("static 400: σ̂/σ {rm:.3} [{r5:.3}, {r95:.3}], φ̂ {pm:.3} [{p5:.3}, {p95:.3}]");
    assert!(
        (rm - 1.0).abs() < 0.05 && r5 > 0.75 && r95 < 1.25,
        "σ̂/σ {rm} [{r5}, {r95}]"
    );
    assert!(
        (pm - 0.8).abs() < 0.03 && p5 > 0.7 && p95 < 0.88,
        "φ̂ {pm} [{p5}, {p95}]"
    );
}

#[test]
fn a_static_record_that_is_short_moves_or_is_flat_is_refused() {
    let short = static_record(ar1(MIN_STATIC_SAMPLES - 1, 0.0, 0.3e-3, &mut Rng::new(1)));
    let e = NoiseModel::from_static_record(&short).unwrap_err();
    assert_eq!(
        e,
        NoiseError::TooShort {
            samples: 99,
            min: 100
        }
    );
    assert!(e.to_string().contains("99 samples; at least 100"), "{e}");
    let mut moving = static_record(ar1(200, 0.0, 0.3e-3, &mut Rng::new(2)));
    moving.samples[17].commands[1] = 0.6;
    let e = NoiseModel::from_static_record(&moving).unwrap_err();
    assert_eq!(
        e,
        NoiseError::NotStatic {
            sample: 18,
            axis: 2
        }
    );
    assert!(e.to_string().contains("not static"), "{e}");
    let flat = static_record(vec![[0.001, 0.0, 0.0]; 200]);
    let e = NoiseModel::from_static_record(&flat).unwrap_err();
    assert!(e.to_string().contains("all equal"), "{e}");
    let walk = static_record(ar1(120, 0.98, 0.3e-3, &mut Rng::new(3)));
    match NoiseModel::from_static_record(&walk) {
        Err(e @ NoiseError::TooCorrelated { .. }) => {
            assert!(e.to_string().contains("record longer"))
        }
        other => panic!("a random walk of 120 samples gave {other:?}"),
    }
}

#[test]
fn whitening_makes_model_noise_white_with_unit_variance() {
    let model = NoiseModel {
        sigma_mm: [0.3e-3, 0.5e-3, 0.2e-3],
        phi: [0.8, 0.0, 0.5],
        source: NoiseSource::Declared,
    };
    // Two records, rows 3·i + d, one after the other.
    let layout = [300, 500];
    let mut rows = Vec::new();
    let mut rng = Rng::new(11);
    for &n in &layout {
        let per: Vec<Vec<[f64; 3]>> = (0..3)
            .map(|d| ar1(n, model.phi[d], model.sigma_mm[d], &mut rng))
            .collect();
        for i in 0..n {
            for (d, series) in per.iter().enumerate() {
                rows.push(series[i][d]);
            }
        }
    }
    let mut y = nalgebra::DVector::from_vec(rows.clone());
    let mut h =
        nalgebra::DMatrix::from_fn(rows.len(), 2, |i, j| if j == 0 { rows[i] } else { 1.0 });
    model.whiten(&layout, &mut h, &mut y).unwrap();
    assert_eq!(h.column(0), y.column(0), "columns and vector whiten alike");
    for d in 0..3 {
        let w: Vec<f64> = (0..y.len() / 3).map(|i| y[3 * i + d]).collect();
        let var = w.iter().map(|v| v * v).sum::<f64>() / w.len() as f64;
        let lag1 = w.windows(2).map(|p| p[0] * p[1]).sum::<f64>() / w.len() as f64 / var;
        println!("direction {d}: variance {var:.3}, lag-1 autocorrelation {lag1:+.3}");
        assert!((var - 1.0).abs() < 0.15, "direction {d}: variance {var}");
        assert!(
            lag1.abs() < 0.1,
            "direction {d}: lag-1 autocorrelation {lag1}"
        );
    }
    // A constant column becomes (1−φ)/(σ√(1−φ²)) after the first sample of each record.
    let c = h.column(1);
    assert!((c[0] - 1.0 / 0.3e-3).abs() < 1e-6);
    assert!((c[3] - 0.2 / (0.3e-3 * 0.6)).abs() < 1e-6);
    assert!(
        (c[900] - 1.0 / 0.3e-3).abs() < 1e-6,
        "the second record starts afresh"
    );
    // The layout must fit the rows; σ must be positive.
    let e = model.whiten(&[300, 499], &mut h, &mut y).unwrap_err();
    assert!(e.to_string().contains("799 samples"), "{e}");
    let mut zero = model.clone();
    zero.sigma_mm[1] = 0.0;
    let e = zero.whiten_vector(&layout, &mut y).unwrap_err();
    assert!(e.to_string().contains("σ of direction y"), "{e}");
}

#[test]
fn declared_specifications_parse_and_bad_ones_say_why() {
    let m = NoiseModel::parse("ar1:phi=0.8,sigma=0.3").unwrap();
    assert_eq!(m, NoiseModel::ar1(0.8, 0.0003, NoiseSource::Declared));
    assert_eq!(
        m.to_string(),
        "AR(1) φ = 0.80 (x, y, z), σ = 0.30 µm (x, y, z), declared"
    );
    let w = NoiseModel::parse(" white : sigma = 0.5 ").unwrap();
    assert_eq!(w, NoiseModel::white(0.0005, NoiseSource::Declared));
    assert!(w.is_uniform_white() && !m.is_uniform_white());
    assert_eq!(w.to_string(), "white, σ = 0.50 µm (x, y, z), declared");
    assert_eq!(
        NoiseModel::parse("ar1:sigma=0.3,phi=0").unwrap(),
        NoiseModel::white(0.0003, NoiseSource::Declared)
    );
    assert_eq!(NoiseChoice::parse("white").unwrap(), NoiseChoice::Ordinary);
    assert_eq!(
        NoiseChoice::parse("estimate").unwrap(),
        NoiseChoice::Estimate
    );
    assert_eq!(
        NoiseChoice::parse("ar1:phi=0.8,sigma=0.3").unwrap(),
        NoiseChoice::Model(m)
    );
    for (spec, why) in [
        ("pink:sigma=1", "unknown kind `pink`"),
        ("ar1:phi=0.8", "sigma is missing"),
        ("ar1:sigma=0.3", "phi is missing"),
        ("white:sigma=0.3,phi=0.5", "unknown key `phi` for white"),
        ("ar1:phi=0.99,sigma=0.3", "below 0.99"),
        ("ar1:phi=-0.1,sigma=0.3", "at least 0"),
        ("white:sigma=0", "above 0"),
        ("white:sigma=nan", "not a finite number"),
        ("white:sigma=1e400", "not a finite number"),
        ("white:sigma=0.3,sigma=0.4", "given twice"),
        ("white:sigma", "not KEY=VALUE"),
        ("white", "sigma is missing"),
    ] {
        let e = NoiseModel::parse(spec).unwrap_err();
        let text = e.to_string();
        assert!(text.contains(why) && text.contains(spec), "{spec}: {text}");
        assert!(text.contains("ar1:phi=F,sigma=S"), "{spec}: {text}");
    }
}
