//! Least squares the way a calibration engineer needs it: column scaling, SVD with a stated
//! numerical rank, residual-based standard uncertainties, covariance and correlation, condition
//! number, and no number for a parameter the data cannot determine (see
//! [`crate::identifiability`] and `docs/identification.md`).
//!
//! Model: `y = H·p + e`, `y` the stacked measured error vectors (mm, 3 rows per sample), `H`
//! from [`crate::hmatrix`], `p` the parameters (mm for translational, rad for angular effects),
//! `e` independent noise of one unknown standard deviation σ.
//!
//! 1. Scaling: `s_j = ‖h_j‖₂` (a zero column keeps `s_j = 1`), `A = H·S⁻¹`; unit-free, so mm
//!    and rad columns compare.
//! 2. SVD `A = U·Σ·Vᵀ` (singular values descending; more parameters than rows: `A` is padded
//!    with zero rows so that `V` is complete). A tall `A` (more rows than free parameters, the
//!    usual case) is first reduced by a Householder QR, `A = Q·R`, folded in blocks of rows as
//!    the streaming identification folds its blocks (one implementation: the first 65 536 rows
//!    by the Householder QR of those rows, then blocks of 256), and the SVD is that of the
//!    small `R = U_R·Σ·Vᵀ`: neither `U = Q·U_R` nor `Q` is kept, `Uᵀ·y =
//!    U_Rᵀ·(Qᵀ·y)` with `Qᵀ·y` folded with `A` (the last column of the factor of `[A | y]`). The
//!    results agree with the SVD of `A` to rounding (5e-14 relative on 10⁶ samples; the fold
//!    with the QR of the whole `A` to 4e-13).
//! 3. Rank `r` = number of `σ_i > τ = σ_max · max(ρ, max(m, n)·ε)`, `ρ` =
//!    [`RANK_RELATIVE_TOLERANCE`] = 1e-8, `ε` = 2.2e-16, `m = 3N` rows, `n` parameters.
//! 4. Estimate (minimum norm in scaled coordinates, restricted to the identifiable subspace):
//!    `p̂ = S⁻¹·V_r·Σ_r⁻¹·U_rᵀ·y`. Residual `ρ = y − H·p̂`, `RSS = ‖ρ‖²`,
//!    `σ̂² = RSS / (3N − r)`.
//! 5. Covariance `C = σ̂²·S⁻¹·V_r·Σ_r⁻²·V_rᵀ·S⁻¹`, std `√C_jj`, correlation
//!    `C_jk / √(C_jj·C_kk)`; condition number `κ = σ_max / σ_r` of the scaled H.

use crate::factored::{Factored, WhitenedFactored, check_readings_of};
use crate::hmatrix::HMatrixError;
use crate::identifiability::{
    CORRELATION_LIMIT, DETERMINED_TOLERANCE, Identifiability, LINK_TOLERANCE,
};
use crate::noise::{NoiseError, NoiseModel};
use nalgebra::{DMatrix, DVector};

/// Default `ρ`: singular values of the scaled H below `ρ·σ_max` count as zero (condition
/// numbers above 1e8 are treated as rank deficiency; see `docs/identification.md`).
pub const RANK_RELATIVE_TOLERANCE: f64 = 1e-8;

/// How parameters the data cannot determine get a value.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub enum Constraint {
    /// They get none (`value: None`) and are named in the confounded groups.
    #[default]
    None,
    /// Every parameter gets the minimum-norm value in scaled coordinates (`‖S·p‖` smallest
    /// among all least-squares solutions): the undetermined part of each confounded group is
    /// set to zero. Their standard uncertainties are those of that estimator, around the
    /// projection of the truth, not around the truth.
    MinimumNorm,
    /// The named parameters ([`crate::hmatrix::parameter_name`]: `XOC`, `ECC@harmonic:1:cos`)
    /// are fixed to zero before the fit (value 0, no uncertainty); the rest is fitted as with
    /// [`Constraint::None`]. The digit-zero spelling of an error (`X0C`) is accepted.
    Zero(Vec<String>),
}

/// The tolerances of the rank and identifiability decisions (`Tolerances::default()`, then set
/// the fields wanted).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct Tolerances {
    /// `ρ` of the rank tolerance `σ_max · max(ρ, max(m, n)·ε)`.
    pub rank_relative: f64,
    /// τ_d: largest null-space weight `‖Nᵀ·e_j‖` of a determined parameter.
    pub determined: f64,
    /// τ_l: smallest `|(N·Nᵀ)_jk|` that links two undetermined parameters into a group.
    pub link: f64,
    /// `|correlation|` above which determined pairs are reported as nearly confounded.
    pub correlation: f64,
}

impl Default for Tolerances {
    /// 1e-8, 1e-6, 1e-6, 0.99.
    fn default() -> Self {
        Tolerances {
            rank_relative: RANK_RELATIVE_TOLERANCE,
            determined: DETERMINED_TOLERANCE,
            link: LINK_TOLERANCE,
            correlation: CORRELATION_LIMIT,
        }
    }
}

/// Why a fit could not be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EstimateError {
    /// The H matrix could not be built.
    #[error(transparent)]
    HMatrix(#[from] HMatrixError),
    /// Sizes that do not fit together, or nothing to fit.
    #[error("{0}")]
    Shape(String),
    /// A NaN or infinite input.
    #[error("{0} is not finite")]
    NotFinite(String),
    /// A parameter named in [`Constraint::Zero`] is not in the model.
    #[error("constraint: `{0}` is not a parameter of the model (parameters: {1})")]
    UnknownParameter(String, String),
    /// Fewer readings than parameters plus one: no degree of freedom would be left for σ̂.
    #[error(
        "too few samples: {samples} samples give {readings} readings (3 per sample) for {parameters} parameters; at least {} readings ({} samples) are needed",
        parameters + 1,
        (parameters + 3) / 3
    )]
    TooFewReadings {
        /// Samples of the record.
        samples: usize,
        /// Readings (3 per sample).
        readings: usize,
        /// Parameters of the model.
        parameters: usize,
    },
    /// The SVD did not converge.
    #[error("the singular value decomposition of the {0}×{1} scaled H matrix did not converge")]
    Svd(usize, usize),
    /// The noise model cannot whiten these rows, or whitening changed the rank.
    #[error(transparent)]
    Noise(#[from] NoiseError),
}

/// The result of a least-squares fit. Internal units: parameters in mm or rad, residuals mm.
#[derive(Clone, Debug, PartialEq)]
pub struct Fit {
    /// Parameter names, one per H column.
    pub names: Vec<String>,
    /// Estimates (mm or rad); `None` for a parameter the data cannot determine (unless the
    /// constraint gives it a value).
    pub values: Vec<Option<f64>>,
    /// The minimum-norm solution in the identifiable subspace for every parameter, determined
    /// or not (mm or rad; fixed parameters 0): what `H·p̂` is made of. Undetermined entries are
    /// one representative of their confounded group, not values to report.
    pub solution: Vec<f64>,
    /// Standard uncertainties (mm or rad); `None` where there is no value, for fixed
    /// parameters, and when `3N = r` leaves no degree of freedom for σ̂.
    pub std: Vec<Option<f64>>,
    /// Fixed to zero by [`Constraint::Zero`].
    pub fixed: Vec<bool>,
    /// `s_j = ‖h_j‖₂` (mm per unit of the parameter × √rows), 1 for a zero column.
    pub column_norms: Vec<f64>,
    /// Singular values of the scaled H of the free parameters, descending.
    pub singular_values: Vec<f64>,
    /// Numerical rank r.
    pub rank: usize,
    /// The absolute tolerance τ the singular values were compared with.
    pub rank_tolerance: f64,
    /// `σ_max / σ_r` of the scaled H (over the identifiable part); `None` when r = 0.
    pub condition: Option<f64>,
    /// Covariance of the estimates (mm², mm·rad, rad²); NaN where a parameter has no value or
    /// σ̂ is unknown; 0 in rows and columns of fixed parameters.
    pub covariance: DMatrix<f64>,
    /// Correlation of the estimates (independent of σ̂); NaN where undefined.
    pub correlation: DMatrix<f64>,
    /// `y − H·p̂`, mm, 3 rows per sample.
    pub residual: DVector<f64>,
    /// Residual sum of squares, mm².
    pub rss: f64,
    /// Degrees of freedom `3N − r`.
    pub dof: usize,
    /// σ̂ = √(RSS / dof), mm; `None` when dof = 0.
    pub sigma: Option<f64>,
    /// What the data determine (indices are parameter indices).
    pub identifiability: Identifiability,
    /// The constraint used.
    pub constraint: Constraint,
}

impl Fit {
    /// RMS of the residual over all rows, `√(RSS / 3N)`, mm.
    pub fn residual_rms(&self) -> f64 {
        (self.rss / self.rows().max(1) as f64).sqrt()
    }

    /// Rows of the system fitted (3 per sample): `dof + rank`, also for a reduced (streaming)
    /// system whose [`Fit::residual`] is shorter.
    pub fn rows(&self) -> usize {
        self.dof + self.rank
    }
}

/// Fits `y ≈ H·p` (H: m × n, mm per unit; y: m, mm) with parameter `names` (one per column),
/// under `constraint`, with `tol`. See the module documentation for the method.
///
/// # Errors
/// Sizes that do not fit, no rows or no columns, NaN or infinite inputs, an unknown name in
/// [`Constraint::Zero`], an SVD that does not converge.
pub fn least_squares(
    h: &DMatrix<f64>,
    y: &DVector<f64>,
    names: &[String],
    constraint: &Constraint,
    tol: &Tolerances,
) -> Result<Fit, EstimateError> {
    solve(h, y, names, constraint, tol, h.nrows(), 0.0)
}

/// A generalized least-squares fit ([`least_squares_whitened`]): the fit, and the σ̂ of the
/// whitened residual.
#[derive(Clone, Debug, PartialEq)]
pub struct WhitenedFit {
    /// The fit: values, uncertainties, covariance and correlation of the whitened system; rank,
    /// singular values, condition number and identifiability of the ordinary H; residual, RSS
    /// and σ̂ of the readings themselves (mm).
    pub fit: Fit,
    /// σ̂ of the whitened residual, `√(RSS_w / dof)` (unitless): 1 when the noise model's σ is
    /// right, the factor its σ is off otherwise (the uncertainties use it, so they do not
    /// depend on the model's overall scale); `None` when dof = 0.
    pub whitened_sigma: Option<f64>,
}

/// Generalized least squares under `noise`: `y` and `H` whitened by
/// [`NoiseModel::whiten`] (`layout`: samples per record, in row order), then fitted by
/// [`least_squares`]. The estimates, standard uncertainties, covariance, correlation and
/// near-confounded pairs are those of the whitened system (its σ̂ sets the scale). The rank,
/// singular values, condition number, column norms and what the data determine are the
/// ordinary H's (the path's geometry, as without a noise model): the whitened fit must find the
/// same rank and the same undetermined parameters. The residual, RSS and σ̂ are those of the
/// readings, `y − H·p̂` (mm). A uniform white model (one σ, φ = 0) whitens by one factor: the
/// fit is then the ordinary one, bit for bit.
///
/// # Errors
/// As [`least_squares`]; [`EstimateError::Noise`] when the layout does not fit the rows, the
/// model cannot whiten, or the whitened fit has another rank or other undetermined parameters.
pub fn least_squares_whitened(
    h: &DMatrix<f64>,
    y: &DVector<f64>,
    names: &[String],
    constraint: &Constraint,
    tol: &Tolerances,
    noise: &NoiseModel,
    layout: &[usize],
) -> Result<WhitenedFit, EstimateError> {
    check_readings_of(h, y, names)?;
    WhitenedFactored::for_readings(h, y, names, constraint, tol, noise, layout)?
        .fit(h, y, noise, layout)
}

/// [`least_squares`] on a reduced system: `r` (p × p or (p+1) × p) and `z` with `rᵀr = HᵀH`
/// and `rᵀz = Hᵀy` for the real `H` (`rows` rows) and `y`, and `rss_outside` the part of
/// `‖y‖²` no combination of H's columns reaches (the triangular factor of a streaming QR,
/// [`crate::streaming`]). Estimates, rank, uncertainties, covariance and identifiability are
/// those of the full system; [`Fit::residual`] is the reduced system's (length of `z`).
pub fn least_squares_reduced(
    r: &DMatrix<f64>,
    z: &DVector<f64>,
    names: &[String],
    constraint: &Constraint,
    tol: &Tolerances,
    rows: usize,
    rss_outside: f64,
) -> Result<Fit, EstimateError> {
    solve(r, z, names, constraint, tol, rows, rss_outside)
}

/// The solver behind both: `rows` is the real number of rows (for the rank tolerance and the
/// degrees of freedom), `rss_outside` adds to the residual sum of squares.
fn solve(
    h: &DMatrix<f64>,
    y: &DVector<f64>,
    names: &[String],
    constraint: &Constraint,
    tol: &Tolerances,
    rows_total: usize,
    rss_outside: f64,
) -> Result<Fit, EstimateError> {
    check_readings_of(h, y, names)?;
    Factored::with_readings(h, Some(y), names, constraint, tol, rows_total)?.fit(h, y, rss_outside)
}
