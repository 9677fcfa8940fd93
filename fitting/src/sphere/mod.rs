//! The sphere fit of a touch-probe calibration: the centre of a calibration sphere from the
//! probe's latched positions at one pose (as in the kinematics calibration cycles of the
//! controllers: hits on a sphere at each pose, a sphere fit per pose, then the kinematics fit
//! on the centres). See `docs/probe.md`, "Sphere fits".
//!
//! **Geometry.** A probe latches the position of its ball's centre (the tip centre) when the
//! ball touches the sphere, so the latched points lie on a sphere of radius
//! `R_eff = R_sphere + r_tip` about the sphere centre `c` (`R_sphere` the calibrated radius of
//! the sphere, `r_tip` the effective radius of the probe's ball, both mm). The approach
//! direction of a hit is the inward normal at the contact point, pointing towards the centre.
//!
//! **Fit.** Least squares on the exact distances, `r_i = ‖p_i − c‖ − R_eff` (mm, signed: a
//! positive residual is a tip centre farther from the centre than the sphere says), over `c`
//! and `R_eff` ([`RadiusMode::Free`], 4 unknowns) or over `c` alone with `R_eff` given
//! ([`RadiusMode::Calibrated`], 3 unknowns). Gauss–Newton from the algebraic linear fit
//! (`‖p‖² = 2·c·p + k`, `k = R² − ‖c‖²`), stopped when a step is below
//! [`STEP_TOLERANCE_MM`] and refused when it is not within [`MAX_ITERATIONS`].
//!
//! **Refusals** ([`SphereFitError`]): too few hits (4 free, 3 calibrated), coplanar hits in
//! free mode, hits that do not determine the centre (the Jacobian's condition number above
//! [`CONDITION_LIMIT`]), a hit whose |residual| exceeds `max(4σ, 5 µm)`, and, in free mode with
//! a calibrated radius, a fitted sphere radius more than 5 µm from it: a dirty hit (a chip, a
//! drop of coolant, a probe that latched on the way) moves the centre, and a kinematics fit
//! on a wrong centre is wrong everywhere.

mod fit;

pub use fit::fit_sphere;

use nalgebra::{Matrix3, Vector3};

/// The largest step of a converged Gauss–Newton iteration, mm.
pub const STEP_TOLERANCE_MM: f64 = 1e-12;

/// Gauss–Newton iterations before a fit that has not converged is refused.
pub const MAX_ITERATIONS: usize = 100;

/// Residual limit in multiples of the probe's noise σ.
pub const RESIDUAL_SIGMAS: f64 = 4.0;

/// The residual limit's floor, mm (5 µm): the limit is `max(4σ, 5 µm)`.
pub const RESIDUAL_FLOOR_MM: f64 = 0.005;

/// The largest |fitted − calibrated| sphere radius in free mode, mm (5 µm).
pub const RADIUS_LIMIT_MM: f64 = 0.005;

/// The largest condition number `σ_max/σ_min` of the fit's Jacobian (rows: unit normals, and
/// −1 for the radius): above it a noise of σ moves the centre by more than about
/// `10⁴·σ/√n`, and the hits do not determine the centre.
pub const CONDITION_LIMIT: f64 = 1e4;

/// Hits are coplanar (free mode) when the RMS distance of the tip centres from their best
/// plane is below this fraction of their RMS distance from their centroid.
pub const COPLANAR_RELATIVE: f64 = 0.01;

/// One hit of a pattern, relative to the sphere's centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// The point on the sphere (mm, from the centre; on the sphere of the pattern's radius).
    pub point_mm: Vector3<f64>,
    /// The probe's approach direction (unit): the inward normal, towards the centre.
    pub approach: Vector3<f64>,
}

/// The default hit pattern on a sphere of radius `radius_mm` (mm; the sphere's radius for the
/// contact points, `R_sphere + r_tip` for the tip centres at the latch), 9 hits, in order:
///
/// - 0–3: at the centre's height, along +X, +Y, −X, −Y;
/// - 4–7: at the centre's height + R/2 (horizontal distance R·√3/2 from the axis), azimuths
///   45°, 135°, 225°, 315°;
/// - 8: at the pole, +Z (approach −Z).
///
/// Each approach direction is the inward normal, `−point/R`. The three heights and nine
/// directions determine the centre and the radius (5 degrees of freedom are left in free mode)
/// and let one dirty hit show in the residuals or the radius (`docs/probe.md`).
pub fn default_pattern(radius_mm: f64) -> Vec<Hit> {
    let r = radius_mm;
    let mut dirs: Vec<Vector3<f64>> = (0..4)
        .map(|k| {
            let a = f64::from(k) * std::f64::consts::FRAC_PI_2;
            Vector3::new(a.cos(), a.sin(), 0.0)
        })
        .collect();
    let h: f64 = 0.5; // z / R
    let rho = (1.0 - h * h).sqrt();
    dirs.extend((0..4).map(|k| {
        let a = std::f64::consts::FRAC_PI_4 + f64::from(k) * std::f64::consts::FRAC_PI_2;
        Vector3::new(rho * a.cos(), rho * a.sin(), h)
    }));
    dirs.push(Vector3::z());
    dirs.into_iter()
        .map(|n| Hit {
            point_mm: n * r,
            approach: -n,
        })
        .collect()
}

/// One latched position of the probe at one pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Latch {
    /// The tip centre's position when the probe latched (mm, machine or pose frame).
    pub tip_mm: Vector3<f64>,
    /// The commanded approach direction (unit or not; only its sense towards the centre is
    /// used, to choose between two centres that fit three or coplanar hits equally).
    pub approach: Vector3<f64>,
}

/// What the fit does with the radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RadiusMode {
    /// The effective radius is an unknown (4 unknowns, at least 4 non-coplanar hits). With
    /// `calibrated_mm` (the sphere's calibrated radius `R_sphere`), a fitted sphere radius more
    /// than [`RADIUS_LIMIT_MM`] from it is refused.
    Free {
        /// The sphere's calibrated radius, mm, when known.
        calibrated_mm: Option<f64>,
    },
    /// The sphere's radius is the calibrated one (3 unknowns, at least 3 hits).
    Calibrated {
        /// The sphere's calibrated radius `R_sphere`, mm.
        sphere_radius_mm: f64,
    },
}

/// The settings of a sphere fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereFitOptions {
    /// Free or calibrated radius.
    pub radius: RadiusMode,
    /// The effective radius of the probe's ball `r_tip`, mm (≥ 0).
    pub tip_radius_mm: f64,
    /// The probe's noise σ (standard deviation of a latched distance), mm (> 0): the scale of
    /// [`SphereFit::covariance_mm2`] and of the residual limit `max(4σ, 5 µm)`.
    pub noise_mm: f64,
}

/// A sphere fit of one pose. Lengths in mm (reports show residuals in µm).
#[derive(Clone, Debug, PartialEq)]
pub struct SphereFit {
    /// The sphere's centre `c`, mm.
    pub centre_mm: Vector3<f64>,
    /// The effective radius `R_eff = R_sphere + r_tip`, mm: fitted in free mode, the given one
    /// in calibrated mode.
    pub effective_radius_mm: f64,
    /// The sphere's radius `R_eff − r_tip`, mm (fitted in free mode).
    pub sphere_radius_mm: f64,
    /// Whether the radius was fitted (free mode).
    pub radius_fitted: bool,
    /// Per hit, `‖p_i − c‖ − R_eff`, mm (signed; positive: the tip centre latched farther out).
    pub residuals_mm: Vec<f64>,
    /// RMS of the residuals, `√(Σr_i²/n)`, mm.
    pub rms_mm: f64,
    /// The centre's covariance from the given probe noise, `σ²·[(JᵀJ)⁻¹]_cc`, mm² (the centre
    /// block of the inverse; in free mode the radius's correlation with the centre is
    /// included). What the centre's uncertainty is when the probe's σ is right.
    pub covariance_mm2: Matrix3<f64>,
    /// The fitted effective radius's standard uncertainty from the given noise, mm (free mode).
    pub radius_std_mm: Option<f64>,
    /// Degrees of freedom `n − p` (p = 4 free, 3 calibrated).
    pub dof: usize,
    /// The a-posteriori σ̂ = `√(Σr_i² / dof)`, mm, when dof > 0: what the residuals say the
    /// noise was at this pose (a check of the given σ, few degrees of freedom: not used for
    /// the covariance).
    pub sigma_posterior_mm: Option<f64>,
    /// The centre's covariance from the residuals, `σ̂²·[(JᵀJ)⁻¹]_cc`, mm², when dof > 0.
    pub covariance_posterior_mm2: Option<Matrix3<f64>>,
    /// Gauss–Newton iterations used.
    pub iterations: usize,
}

/// Why a pose's sphere fit is refused. Hit indices are 0-based positions in the latches given
/// (the caller maps them to a file and line).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SphereFitError {
    /// A NaN or infinite value, a negative tip radius, a σ not above 0, or a radius not above 0.
    #[error("sphere fit: {0}")]
    Input(String),
    /// Fewer hits than the mode needs (4 free, 3 calibrated).
    #[error(
        "sphere fit refused (too few hits): {hits} hits, {mode} radius needs at least {needed}"
    )]
    TooFewHits {
        /// Hits given.
        hits: usize,
        /// Hits needed.
        needed: usize,
        /// "free" or "calibrated".
        mode: &'static str,
    },
    /// Free mode: the tip centres lie in one plane, which does not fix the radius.
    #[error(
        "sphere fit refused (coplanar hits, free radius): the hits lie within {:.3} µm RMS of one plane, {:.3} mm RMS from their centroid (limit: {} of it); fix the radius or hit out of the plane",
        out_of_plane_mm * 1e3,
        extent_mm,
        COPLANAR_RELATIVE
    )]
    Coplanar {
        /// RMS distance of the tip centres from their best plane, mm.
        out_of_plane_mm: f64,
        /// RMS distance of the tip centres from their centroid, mm.
        extent_mm: f64,
    },
    /// The hits do not determine the centre (the Jacobian's condition number, ∞ for rank
    /// deficiency, is above [`CONDITION_LIMIT`]).
    #[error(
        "sphere fit refused (rank): the hits do not determine the centre (condition number {condition:.3e} > {CONDITION_LIMIT:e})"
    )]
    Undetermined {
        /// `σ_max/σ_min` of the Jacobian.
        condition: f64,
    },
    /// Gauss–Newton did not converge.
    #[error(
        "sphere fit refused (no convergence): the last of {iterations} Gauss–Newton steps was {last_step_mm:.3e} mm (tolerance {STEP_TOLERANCE_MM:e} mm)"
    )]
    NotConverged {
        /// Iterations made.
        iterations: usize,
        /// The last step's length, mm.
        last_step_mm: f64,
    },
    /// A hit's |residual| is above `max(4σ, 5 µm)`: a dirty hit.
    #[error(
        "sphere fit refused (residual): hit {hit} is {:.3} µm off the fitted sphere (limit {:.3} µm = max(4σ, 5 µm))",
        residual_mm * 1e3,
        limit_mm * 1e3
    )]
    Residual {
        /// The hit of the largest |residual| (0-based).
        hit: usize,
        /// Its residual, mm (signed).
        residual_mm: f64,
        /// The limit, mm.
        limit_mm: f64,
    },
    /// Free mode with a calibrated radius: the fitted sphere radius is off by more than
    /// [`RADIUS_LIMIT_MM`].
    #[error(
        "sphere fit refused (radius): fitted sphere radius {fitted_mm:.6} mm, calibrated {calibrated_mm:.6} mm, {:.3} µm apart (limit {:.3} µm){}",
        (fitted_mm - calibrated_mm) * 1e3,
        RADIUS_LIMIT_MM * 1e3,
        suspect.map(|h| format!("; without hit {h} the fit agrees")).unwrap_or_default()
    )]
    Radius {
        /// The fitted sphere radius, mm.
        fitted_mm: f64,
        /// The calibrated sphere radius, mm.
        calibrated_mm: f64,
        /// The hit whose removal makes the fit agree with the calibrated radius within both
        /// limits (the one closest to it when several do); `None` when no single removal
        /// does, or too few hits are left.
        suspect: Option<usize>,
    },
}
