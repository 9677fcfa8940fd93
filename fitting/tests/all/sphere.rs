//! The sphere fit of a touch probe: exact hits, the covariance against a Monte-Carlo, dirty
//! hits at every position of the default pattern, and the refusals.

use fitting::sphere::{
    Hit, Latch, RadiusMode, SphereFit, SphereFitError, SphereFitOptions, default_pattern,
    fit_sphere,
};
use nalgebra::Vector3;
use simulation::rng::Rng;

const SPHERE_MM: f64 = 12.5;
const TIP_MM: f64 = 1.5;
const SIGMA_MM: f64 = 0.0005;

fn centre() -> Vector3<f64> {
    Vector3::new(312.25, -148.5, 97.125)
}

/// The latches of `pattern` on the sphere at [`centre`] (tip centres at `R + r_tip`), each
/// moved along its outward normal by `errors[i]` mm.
fn latches(pattern: &[Hit], errors: &[f64]) -> Vec<Latch> {
    let r_eff = SPHERE_MM + TIP_MM;
    pattern
        .iter()
        .zip(errors)
        .map(|(h, e)| {
            let n = -h.approach;
            Latch {
                tip_mm: centre() + n * (r_eff + e),
                approach: h.approach,
            }
        })
        .collect()
}

fn options(radius: RadiusMode) -> SphereFitOptions {
    SphereFitOptions {
        radius,
        tip_radius_mm: TIP_MM,
        noise_mm: SIGMA_MM,
    }
}

fn free_calibrated() -> SphereFitOptions {
    options(RadiusMode::Free {
        calibrated_mm: Some(SPHERE_MM),
    })
}

fn dirty(
    hits: &[Hit],
    at: usize,
    error_mm: f64,
    opts: &SphereFitOptions,
) -> Result<SphereFit, SphereFitError> {
    let mut e = vec![0.0; hits.len()];
    e[at] = error_mm;
    fit_sphere(&latches(hits, &e), opts)
}

fn calibrated() -> SphereFitOptions {
    options(RadiusMode::Calibrated {
        sphere_radius_mm: SPHERE_MM,
    })
}

fn pick(hits: &[Hit], which: &[usize]) -> Vec<Hit> {
    which.iter().map(|&i| hits[i]).collect()
}

#[test]
fn default_pattern_is_nine_hits_with_inward_approaches() {
    let hits = default_pattern(2.0);
    assert_eq!(hits.len(), 9);
    let heights: Vec<f64> = hits.iter().map(|h| h.point_mm.z).collect();
    for (i, h) in hits.iter().enumerate() {
        assert!(
            (h.point_mm.norm() - 2.0).abs() < 1e-15,
            "hit {i} on the sphere"
        );
        assert!((h.approach.norm() - 1.0).abs() < 1e-15);
        assert!(
            (h.approach + h.point_mm / 2.0).norm() < 1e-15,
            "hit {i} inward"
        );
    }
    assert_eq!(&heights[..4], &[0.0; 4]);
    assert!(heights[4..8].iter().all(|z| (z - 1.0).abs() < 1e-15));
    assert_eq!(hits[8].approach, -Vector3::z());
    assert!((hits[4].point_mm.x - hits[4].point_mm.y).abs() < 1e-15); // 45°
}

#[test]
fn exact_hits_give_the_centre_and_the_radius() {
    let hits = default_pattern(SPHERE_MM);
    let l = latches(&hits, &[0.0; 9]);
    for opts in [
        free_calibrated(),
        options(RadiusMode::Free {
            calibrated_mm: None,
        }),
        calibrated(),
    ] {
        let f = fit_sphere(&l, &opts).unwrap();
        assert!(
            (f.centre_mm - centre()).amax() < 1e-12,
            "{:?}",
            f.centre_mm - centre()
        );
        assert!((f.sphere_radius_mm - SPHERE_MM).abs() < 1e-12);
        assert!((f.effective_radius_mm - SPHERE_MM - TIP_MM).abs() < 1e-12);
        assert!(f.residuals_mm.iter().all(|r| r.abs() < 1e-12));
        assert!(f.rms_mm < 1e-12);
        assert_eq!(f.residuals_mm.len(), 9);
        assert_eq!(f.radius_fitted, f.radius_std_mm.is_some());
        assert_eq!(f.dof, if f.radius_fitted { 5 } else { 6 });
        assert!(f.sigma_posterior_mm.unwrap() < 1e-12);
        // σ²·(JᵀJ)⁻¹: positive definite, of the order of σ²/n.
        let c = f.covariance_mm2;
        assert!(c.symmetric_eigenvalues().min() > 0.0);
        assert!(c.diagonal().max() < 4.0 * SIGMA_MM * SIGMA_MM);
    }
}

#[test]
fn three_coplanar_hits_with_the_calibrated_radius_take_the_approaches_side() {
    // Three hits of the upper ring fit two spheres of the calibrated radius, mirrored about
    // their plane; the approaches (downwards) choose the one below.
    let hits = pick(&default_pattern(SPHERE_MM), &[4, 5, 6]);
    let f = fit_sphere(&latches(&hits, &[0.0; 3]), &calibrated()).unwrap();
    assert!(
        (f.centre_mm - centre()).amax() < 1e-12,
        "{:?}",
        f.centre_mm - centre()
    );
    assert_eq!(f.dof, 0);
    assert_eq!(f.sigma_posterior_mm, None);
    assert_eq!(f.covariance_posterior_mm2, None);
}

/// Over 400 seeds with σ = 0.5 µm on every hit: the centre's error, in units of its covariance,
/// has z² of mean 1 per coordinate (and the Mahalanobis distance 3), and σ̂² has mean σ².
#[test]
fn the_centre_covariance_matches_a_monte_carlo() {
    let hits = default_pattern(SPHERE_MM);
    for opts in [free_calibrated(), calibrated()] {
        let mut rng = Rng::new(451);
        let (mut z2, mut maha, mut s2, mut r2) = (0.0, 0.0, 0.0, 0.0);
        let seeds = 400;
        for _ in 0..seeds {
            let e: Vec<f64> = (0..9).map(|_| rng.gaussian(0.0, SIGMA_MM)).collect();
            let f = fit_sphere(&latches(&hits, &e), &opts).unwrap();
            let d = f.centre_mm - centre();
            let c = f.covariance_mm2;
            z2 += (0..3).map(|k| d[k] * d[k] / c[(k, k)]).sum::<f64>() / 3.0;
            maha += (d.transpose() * c.try_inverse().unwrap() * d)[0] / 3.0;
            s2 += (f.sigma_posterior_mm.unwrap() / SIGMA_MM).powi(2);
            if let Some(sr) = f.radius_std_mm {
                r2 += ((f.effective_radius_mm - SPHERE_MM - TIP_MM) / sr).powi(2);
            }
        }
        let n = f64::from(seeds);
        for (what, v) in [
            ("z²", z2 / n),
            ("Mahalanobis/3", maha / n),
            ("σ̂²/σ²", s2 / n),
        ] {
            assert!((0.8..=1.25).contains(&v), "{opts:?}: mean {what} = {v}");
        }
        if opts.radius != calibrated().radius {
            assert!((0.8..=1.25).contains(&(r2 / n)), "radius z² {}", r2 / n);
        }
    }
}

/// A 20 µm error on one hit (along its normal, outwards and inwards), at each of the nine
/// positions: the residual rule refuses it and names that hit, in free mode with the
/// calibrated radius and in calibrated mode. Its residual is 8.9 µm (pole) to 12.9 µm (upper
/// ring) in free mode; the radius moves by at most 4.4 µm (equator hits), so the radius rule
/// alone would catch none of them.
#[test]
fn a_dirty_hit_is_refused_at_every_position() {
    let hits = default_pattern(SPHERE_MM);
    for at in 0..9 {
        for e in [0.02, -0.02] {
            for opts in [free_calibrated(), calibrated()] {
                match dirty(&hits, at, e, &opts) {
                    Err(SphereFitError::Residual {
                        hit,
                        residual_mm,
                        limit_mm,
                    }) => {
                        assert_eq!(hit, at);
                        assert_eq!(limit_mm, 0.005);
                        assert!(residual_mm * e > 0.0 && residual_mm.abs() > 0.0085);
                    }
                    other => panic!("hit {at}, {e} mm: {other:?}"),
                }
            }
            let message = dirty(&hits, at, e, &free_calibrated())
                .unwrap_err()
                .to_string();
            assert!(message.contains("(residual)"), "{message}");
            assert!(message.contains(&format!("hit {at} is ")), "{message}");
            // The radius rule alone: with a σ of 10 µm the residual limit is 40 µm.
            let mut loose = free_calibrated();
            loose.noise_mm = 0.01;
            let f = dirty(&hits, at, e, &loose).unwrap();
            let dr = (f.sphere_radius_mm - SPHERE_MM).abs();
            assert!(dr < 0.0045, "hit {at}: radius off by {dr} mm");
        }
    }
}

/// A 3 µm error on one hit is not refused, at any position, alone or with σ = 0.5 µm noise on
/// every hit.
#[test]
fn a_three_micron_error_is_not_refused() {
    let hits = default_pattern(SPHERE_MM);
    let mut rng = Rng::new(996);
    for at in 0..9 {
        for e in [0.003, -0.003] {
            for opts in [free_calibrated(), calibrated()] {
                let f = dirty(&hits, at, e, &opts).unwrap();
                assert!(f.residuals_mm.iter().all(|r| r.abs() < 0.0022));
                for _ in 0..20 {
                    let mut errors: Vec<f64> =
                        (0..9).map(|_| rng.gaussian(0.0, SIGMA_MM)).collect();
                    errors[at] += e;
                    fit_sphere(&latches(&hits, &errors), &opts).unwrap();
                }
            }
        }
    }
}

/// With the five hits of a common short pattern (four at the equator, one at the pole), a
/// 20 µm pole error moves the centre by 20 µm along z and changes neither the radius nor a
/// residual: no rule can see it. The nine hits of the default pattern refuse it. A 20 µm
/// equator error leaves ±5 µm (a quarter) on each of the four equator hits alike, at the
/// residual limit and without telling which hit it was, and moves the radius by 5 µm.
#[test]
fn five_hits_cannot_see_a_pole_error() {
    let five = pick(&default_pattern(SPHERE_MM), &[0, 1, 2, 3, 8]);
    let f = dirty(&five, 4, 0.02, &free_calibrated()).unwrap();
    assert!(((f.centre_mm - centre()).z - 0.02).abs() < 1e-4);
    assert!((f.sphere_radius_mm - SPHERE_MM).abs() < 1e-4);
    assert!(f.residuals_mm.iter().all(|r| r.abs() < 1e-4));
    let mut loose = options(RadiusMode::Free {
        calibrated_mm: None,
    });
    loose.noise_mm = 0.01;
    let f = dirty(&five, 0, 0.02, &loose).unwrap();
    assert!((f.sphere_radius_mm - SPHERE_MM - 0.005).abs() < 1e-5);
    for (i, r) in f.residuals_mm[..4].iter().enumerate() {
        assert!((r.abs() - 0.005).abs() < 1e-5, "hit {i}: {r}");
    }
    assert!(f.residuals_mm[4].abs() < 1e-5);
}

#[test]
fn the_radius_rule_names_the_hit_whose_removal_agrees() {
    let hits = default_pattern(SPHERE_MM);
    // σ = 5 µm: the residual limit is 20 µm; a 30 µm error at hit 1 changes the radius by
    // 6.7 µm.
    let mut opts = free_calibrated();
    opts.noise_mm = 0.005;
    match dirty(&hits, 1, 0.03, &opts) {
        Err(SphereFitError::Radius {
            fitted_mm,
            calibrated_mm,
            suspect,
        }) => {
            assert_eq!(calibrated_mm, SPHERE_MM);
            assert!((fitted_mm - SPHERE_MM).abs() > 0.005);
            assert_eq!(suspect, Some(1));
        }
        other => panic!("{other:?}"),
    }
    // A calibrated radius 8 µm off: every hit agrees with the fit, no removal helps.
    let mut wrong = free_calibrated();
    wrong.radius = RadiusMode::Free {
        calibrated_mm: Some(SPHERE_MM + 0.008),
    };
    let err = fit_sphere(&latches(&hits, &[0.0; 9]), &wrong).unwrap_err();
    assert!(
        matches!(err, SphereFitError::Radius { suspect: None, .. }),
        "{err:?}"
    );
    assert!(err.to_string().contains("(radius)"), "{err}");
}

#[test]
fn too_few_or_coplanar_hits_are_refused_with_the_rule_named() {
    let hits = default_pattern(SPHERE_MM);
    let three = latches(&pick(&hits, &[0, 4, 8]), &[0.0; 3]);
    let err = fit_sphere(&three, &free_calibrated()).unwrap_err();
    assert_eq!(
        err,
        SphereFitError::TooFewHits {
            hits: 3,
            needed: 4,
            mode: "free"
        }
    );
    assert!(err.to_string().contains("too few hits"));
    let two = latches(&pick(&hits, &[0, 8]), &[0.0; 2]);
    let err = fit_sphere(&two, &calibrated()).unwrap_err();
    assert!(matches!(
        err,
        SphereFitError::TooFewHits {
            hits: 2,
            needed: 3,
            ..
        }
    ));

    // The four equator hits: coplanar (free); through the centre's plane, they leave its
    // height undetermined (calibrated).
    let equator = latches(&pick(&hits, &[0, 1, 2, 3]), &[0.0; 4]);
    let err = fit_sphere(&equator, &free_calibrated()).unwrap_err();
    assert!(matches!(err, SphereFitError::Coplanar { .. }), "{err:?}");
    assert!(err.to_string().contains("coplanar"));
    let err = fit_sphere(&equator, &calibrated()).unwrap_err();
    assert!(
        matches!(err, SphereFitError::Undetermined { .. }),
        "{err:?}"
    );
    assert!(err.to_string().contains("(rank)"));
    // The upper ring alone: coplanar in free mode, determined with the calibrated radius.
    let ring = latches(&pick(&hits, &[4, 5, 6, 7]), &[0.0; 4]);
    assert!(matches!(
        fit_sphere(&ring, &free_calibrated()),
        Err(SphereFitError::Coplanar { .. })
    ));
    let f = fit_sphere(&ring, &calibrated()).unwrap();
    assert!((f.centre_mm - centre()).amax() < 1e-12);
}

#[test]
fn bad_input_is_refused() {
    let hits = default_pattern(SPHERE_MM);
    let mut l = latches(&hits, &[0.0; 9]);
    l[3].tip_mm.y = f64::NAN;
    let err = fit_sphere(&l, &free_calibrated()).unwrap_err();
    assert!(err.to_string().contains("hit 3"), "{err}");
    let l = latches(&hits, &[0.0; 9]);
    let mut opts = free_calibrated();
    opts.noise_mm = 0.0;
    assert!(matches!(
        fit_sphere(&l, &opts),
        Err(SphereFitError::Input(_))
    ));
    let mut opts = calibrated();
    opts.radius = RadiusMode::Calibrated {
        sphere_radius_mm: -1.0,
    };
    assert!(matches!(
        fit_sphere(&l, &opts),
        Err(SphereFitError::Input(_))
    ));
}

/// Four hits of the upper ring with σ = 0.5 µm noise and the calibrated radius: coplanar within
/// noise, they fit the centre below and its mirror above equally well; the fit finds the one
/// the approaches point to, within 5 standard uncertainties, over 200 seeds.
#[test]
fn noisy_coplanar_hits_with_the_calibrated_radius_find_the_centre_not_its_mirror() {
    let hits = pick(&default_pattern(SPHERE_MM), &[4, 5, 6, 7]);
    let mut rng = Rng::new(3);
    for seed in 0..200 {
        let e: Vec<f64> = (0..4).map(|_| rng.gaussian(0.0, SIGMA_MM)).collect();
        let f = fit_sphere(&latches(&hits, &e), &calibrated()).unwrap();
        let d = f.centre_mm - centre();
        for k in 0..3 {
            let sd = f.covariance_mm2[(k, k)].sqrt();
            assert!(d[k].abs() < 5.0 * sd, "seed {seed}: {d:?}, sd {sd}");
        }
    }
}
