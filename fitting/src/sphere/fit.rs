//! The numerics of [`fit_sphere`]: the algebraic start, Gauss–Newton on the exact distances,
//! and the refusal rules.

use super::{
    CONDITION_LIMIT, COPLANAR_RELATIVE, Latch, MAX_ITERATIONS, RADIUS_LIMIT_MM, RESIDUAL_FLOOR_MM,
    RESIDUAL_SIGMAS, RadiusMode, STEP_TOLERANCE_MM, SphereFit, SphereFitError, SphereFitOptions,
};
use nalgebra::{DMatrix, DVector, Vector3};

/// Singular values below this fraction of the largest make the algebraic system's matrix
/// (normalized coordinates) rank deficient: the hits are coplanar.
const ALGEBRAIC_RANK_RELATIVE: f64 = 1e-9;

/// Fits the sphere of one pose to the probe's `latches` (tip centres, mm) under `options`, and
/// applies the refusal rules (module documentation, `docs/probe.md`).
///
/// # Errors
/// [`SphereFitError`]: bad input, too few hits, coplanar hits in free mode, hits that do not
/// determine the centre, no convergence, a dirty hit (residual rule), a fitted radius off the
/// calibrated one (radius rule).
pub fn fit_sphere(
    latches: &[Latch],
    options: &SphereFitOptions,
) -> Result<SphereFit, SphereFitError> {
    check_input(latches, options)?;
    let tip = options.tip_radius_mm;
    let (fixed, calibrated) = match options.radius {
        RadiusMode::Free { calibrated_mm } => (None, calibrated_mm),
        RadiusMode::Calibrated { sphere_radius_mm } => (Some(sphere_radius_mm + tip), None),
    };
    let s = solve(latches, fixed)?;
    let sigma = options.noise_mm;
    let limit_mm = (RESIDUAL_SIGMAS * sigma).max(RESIDUAL_FLOOR_MM);
    let (hit, residual_mm) = largest(&s.residuals);
    if residual_mm.abs() > limit_mm {
        return Err(SphereFitError::Residual {
            hit,
            residual_mm,
            limit_mm,
        });
    }
    if let Some(cal) = calibrated {
        let fitted = s.radius - tip;
        if (fitted - cal).abs() > RADIUS_LIMIT_MM {
            return Err(SphereFitError::Radius {
                fitted_mm: fitted,
                calibrated_mm: cal,
                suspect: suspect(latches, tip, cal, limit_mm),
            });
        }
    }
    let p = if fixed.is_some() { 3 } else { 4 };
    let n = latches.len();
    let centre_block = s.unit_covariance.fixed_view::<3, 3>(0, 0).into_owned();
    let rss: f64 = s.residuals.iter().map(|r| r * r).sum();
    let dof = n - p;
    let sigma_posterior = (dof > 0).then(|| (rss / dof as f64).sqrt());
    Ok(SphereFit {
        centre_mm: s.centre,
        effective_radius_mm: s.radius,
        sphere_radius_mm: s.radius - tip,
        radius_fitted: fixed.is_none(),
        rms_mm: (rss / n as f64).sqrt(),
        residuals_mm: s.residuals,
        covariance_mm2: centre_block * (sigma * sigma),
        radius_std_mm: (p == 4).then(|| sigma * s.unit_covariance[(3, 3)].sqrt()),
        dof,
        sigma_posterior_mm: sigma_posterior,
        covariance_posterior_mm2: sigma_posterior.map(|sp| centre_block * (sp * sp)),
        iterations: s.iterations,
    })
}

/// Refuses NaN or infinite values and radii or σ out of range.
fn check_input(latches: &[Latch], options: &SphereFitOptions) -> Result<(), SphereFitError> {
    let bad = |what: String| Err(SphereFitError::Input(what));
    for (i, l) in latches.iter().enumerate() {
        if l.tip_mm.iter().any(|x| !x.is_finite()) {
            return bad(format!("hit {i}: the tip position is not finite"));
        }
        if l.approach.iter().any(|x| !x.is_finite()) {
            return bad(format!("hit {i}: the approach direction is not finite"));
        }
    }
    let tip = options.tip_radius_mm;
    if !(tip.is_finite() && tip >= 0.0) {
        return bad(format!("the tip radius {tip} mm is not a length ≥ 0"));
    }
    let sigma = options.noise_mm;
    if !(sigma.is_finite() && sigma > 0.0) {
        return bad(format!("the probe noise σ = {sigma} mm is not above 0"));
    }
    let radius = match options.radius {
        RadiusMode::Free { calibrated_mm } => calibrated_mm,
        RadiusMode::Calibrated { sphere_radius_mm } => Some(sphere_radius_mm),
    };
    if let Some(r) = radius.filter(|r| !(r.is_finite() && *r > 0.0)) {
        return bad(format!(
            "the calibrated sphere radius {r} mm is not above 0"
        ));
    }
    Ok(())
}

/// The hit of the largest |residual| and its residual.
fn largest(residuals: &[f64]) -> (usize, f64) {
    residuals
        .iter()
        .copied()
        .enumerate()
        .fold(
            (0, 0.0),
            |best, (i, r)| {
                if r.abs() > best.1.abs() { (i, r) } else { best }
            },
        )
}

/// The hit whose removal makes a free fit agree with the calibrated radius `cal` within
/// [`RADIUS_LIMIT_MM`] and every residual within `limit_mm` (the closest when several do).
fn suspect(latches: &[Latch], tip: f64, cal: f64, limit_mm: f64) -> Option<usize> {
    if latches.len() < 5 {
        return None;
    }
    let mut best: Option<(usize, f64)> = None;
    for i in 0..latches.len() {
        let rest: Vec<Latch> = (0..latches.len())
            .filter(|&j| j != i)
            .map(|j| latches[j])
            .collect();
        let Ok(s) = solve(&rest, None) else { continue };
        let off = (s.radius - tip - cal).abs();
        if off <= RADIUS_LIMIT_MM
            && largest(&s.residuals).1.abs() <= limit_mm
            && best.is_none_or(|(_, b)| off < b)
        {
            best = Some((i, off));
        }
    }
    best.map(|(i, _)| i)
}

/// A converged fit before the refusal rules on its residuals.
struct Solved {
    /// Centre, mm.
    centre: Vector3<f64>,
    /// Effective radius, mm (the given one when fixed).
    radius: f64,
    /// `‖p_i − c‖ − R_eff`, mm.
    residuals: Vec<f64>,
    /// `(JᵀJ)⁻¹` at the solution (3 × 3 or 4 × 4, the radius last), mm² per mm².
    unit_covariance: DMatrix<f64>,
    /// Gauss–Newton iterations.
    iterations: usize,
}

/// The fit with the effective radius `fixed` (mm) or free: hit count, coplanarity (free),
/// algebraic start, Gauss–Newton, rank; no residual rule.
fn solve(latches: &[Latch], fixed: Option<f64>) -> Result<Solved, SphereFitError> {
    let n = latches.len();
    let (needed, mode) = match fixed {
        None => (4, "free"),
        Some(_) => (3, "calibrated"),
    };
    if n < needed {
        return Err(SphereFitError::TooFewHits {
            hits: n,
            needed,
            mode,
        });
    }
    // Work about the centroid: coordinates of the size of the sphere, whatever the pose.
    let origin = latches.iter().map(|l| l.tip_mm).sum::<Vector3<f64>>() / n as f64;
    let q: Vec<Vector3<f64>> = latches.iter().map(|l| l.tip_mm - origin).collect();
    let extent = (q.iter().map(|v| v.norm_squared()).sum::<f64>() / n as f64).sqrt();
    if extent == 0.0 {
        return Err(SphereFitError::Undetermined {
            condition: f64::INFINITY,
        });
    }
    let out_of_plane = if n >= 3 {
        DMatrix::from_fn(n, 3, |i, j| q[i][j])
            .singular_values()
            .min()
            / (n as f64).sqrt()
    } else {
        0.0
    };
    let coplanar = out_of_plane < COPLANAR_RELATIVE * extent;
    if coplanar && fixed.is_none() {
        return Err(SphereFitError::Coplanar {
            out_of_plane_mm: out_of_plane,
            extent_mm: extent,
        });
    }
    let approach: Vec<Vector3<f64>> = latches.iter().map(|l| l.approach).collect();
    let start = algebraic(&q, &approach, extent, fixed, coplanar);
    let (c0, r0) = start.ok_or(SphereFitError::Undetermined {
        condition: f64::INFINITY,
    })?;
    let (centre, radius, iterations) = gauss_newton(&q, c0, r0, fixed.is_none())?;
    let (j, residuals) = jacobian(&q, &centre, radius, fixed.is_none());
    let svd = j.svd(false, true);
    let condition = condition(&svd.singular_values);
    if condition > CONDITION_LIMIT {
        return Err(SphereFitError::Undetermined { condition });
    }
    let v_t = svd.v_t.ok_or(SphereFitError::Undetermined { condition })?;
    let inv_sq = DMatrix::from_diagonal(&svd.singular_values.map(|s| 1.0 / (s * s)));
    let unit_covariance = v_t.transpose() * inv_sq * v_t;
    Ok(Solved {
        centre: centre + origin,
        radius,
        residuals: residuals.iter().copied().collect(),
        unit_covariance,
        iterations,
    })
}

/// `σ_max/σ_min` (∞ when σ_min = 0).
fn condition(sv: &DVector<f64>) -> f64 {
    let (max, min) = (sv.max(), sv.min());
    if min > 0.0 { max / min } else { f64::INFINITY }
}

/// The algebraic fit `‖q‖² = 2·c·q + k` in coordinates divided by `scale` (mm): centre and
/// radius (mm). With a `fixed` radius and `coplanar` hits (exactly, or within noise: then the
/// plane's offset is set by noise, and the full solution's centre can be anywhere along the
/// plane's normal), the centre on the line of solutions along the smallest singular direction
/// at that radius, on the side the approaches point to. `None` when no sphere comes out.
fn algebraic(
    q: &[Vector3<f64>],
    approach: &[Vector3<f64>],
    scale: f64,
    fixed: Option<f64>,
    coplanar: bool,
) -> Option<(Vector3<f64>, f64)> {
    let n = q.len();
    let u: Vec<Vector3<f64>> = q.iter().map(|v| v / scale).collect();
    let a = DMatrix::from_fn(n.max(4), 4, |i, j| match (i < n, j) {
        (false, _) => 0.0,
        (true, 3) => 1.0,
        (true, j) => 2.0 * u[i][j],
    });
    let b = DVector::from_fn(
        n.max(4),
        |i, _| if i < n { u[i].norm_squared() } else { 0.0 },
    );
    let svd = a.svd(true, true);
    let (u_m, v_t) = (svd.u.as_ref()?, svd.v_t.as_ref()?);
    let sv = &svd.singular_values;
    let cut = if coplanar && fixed.is_some() {
        sv.min()
    } else {
        sv.max() * ALGEBRAIC_RANK_RELATIVE
    };
    let utb = u_m.transpose() * &b;
    let mut x = DVector::<f64>::zeros(4);
    for k in 0..4 {
        if sv[k] > cut {
            x += v_t.row(k).transpose() * (utb[k] / sv[k]);
        }
    }
    let xc = Vector3::new(x[0], x[1], x[2]);
    let deficient: Vec<usize> = (0..4).filter(|&k| sv[k] <= cut).collect();
    let (c, r) = match (deficient.as_slice(), fixed) {
        ([], None) => (xc, (x[3] + xc.norm_squared()).sqrt()),
        ([], Some(r)) => (xc, r / scale),
        ([k], Some(r)) => {
            // c(t) = xc + t·vc, k(t) = x₃ + t·v₃, and R² = k + ‖c‖².
            let v = v_t.row(*k).transpose();
            let vc = Vector3::new(v[0], v[1], v[2]);
            let rho = r / scale;
            let qa = vc.norm_squared();
            let qb = 2.0 * xc.dot(&vc) + v[3];
            let qc = x[3] + xc.norm_squared() - rho * rho;
            if qa == 0.0 {
                return None;
            }
            let disc = (qb * qb - 4.0 * qa * qc).max(0.0).sqrt();
            let ahead = |t: f64| {
                let c = xc + vc * t;
                u.iter()
                    .zip(approach)
                    .map(|(p, d)| d.dot(&(c - p)))
                    .sum::<f64>()
            };
            let (t1, t2) = ((-qb + disc) / (2.0 * qa), (-qb - disc) / (2.0 * qa));
            let t = if ahead(t1) >= ahead(t2) { t1 } else { t2 };
            (xc + vc * t, rho)
        }
        _ => return None,
    };
    (c.iter().all(|x| x.is_finite()) && r.is_finite() && r > 0.0).then(|| (c * scale, r * scale))
}

/// The Jacobian of the residuals (rows `−n_iᵀ` and `−1` for a free radius) and the residuals
/// `‖q_i − c‖ − R`, mm.
fn jacobian(
    q: &[Vector3<f64>],
    c: &Vector3<f64>,
    r: f64,
    free: bool,
) -> (DMatrix<f64>, DVector<f64>) {
    let p = if free { 4 } else { 3 };
    let mut j = DMatrix::zeros(q.len(), p);
    let mut res = DVector::zeros(q.len());
    for (i, qi) in q.iter().enumerate() {
        let d = qi - c;
        let dist = d.norm();
        let normal = if dist > 0.0 { d / dist } else { d };
        for k in 0..3 {
            j[(i, k)] = -normal[k];
        }
        if free {
            j[(i, 3)] = -1.0;
        }
        res[i] = dist - r;
    }
    (j, res)
}

/// Gauss–Newton from `(c, r)` until a step is at most [`STEP_TOLERANCE_MM`]: centre, radius,
/// iterations.
fn gauss_newton(
    q: &[Vector3<f64>],
    mut c: Vector3<f64>,
    mut r: f64,
    free: bool,
) -> Result<(Vector3<f64>, f64, usize), SphereFitError> {
    let mut last = f64::INFINITY;
    for it in 1..=MAX_ITERATIONS {
        let (j, res) = jacobian(q, &c, r, free);
        let svd = j.svd(true, true);
        let condition = condition(&svd.singular_values);
        if condition > CONDITION_LIMIT {
            return Err(SphereFitError::Undetermined { condition });
        }
        let step = svd
            .solve(&(-res), 0.0)
            .map_err(|_| SphereFitError::Undetermined { condition })?;
        c += Vector3::new(step[0], step[1], step[2]);
        if free {
            r += step[3];
        }
        last = step.norm();
        if !last.is_finite() {
            break;
        }
        if last <= STEP_TOLERANCE_MM {
            return Ok((c, r, it));
        }
    }
    Err(SphereFitError::NotConverged {
        iterations: MAX_ITERATIONS,
        last_step_mm: last,
    })
}
