//! The reading noise of an R-test and the prewhitening that makes it white.
//!
//! Real R-test noise is not white: thermal drift, vibration and the electronics make successive
//! readings of one sensor correlated. The model here is, per direction `d` (x, y, z of the tool
//! frame) and per record, a stationary AR(1) process of marginal standard deviation `σ_d` (mm)
//! and lag-1 autocorrelation `φ_d` ∈ [0, 0.99):
//!
//! ```text
//! e_0 = σ·n_0,   e_t = φ·e_{t−1} + σ·√(1−φ²)·n_t,   n_t independent standard normal
//! ```
//!
//! with the samples of a record equally spaced (one step of the path between two samples; the
//! model knows samples, not seconds). White noise is `φ = 0`. Directions and records are
//! independent of each other.
//!
//! A [`NoiseModel`] comes from one of three sources (`docs/identification.md`), in this order of
//! precedence: declared ([`NoiseModel::parse`]: `white:sigma=S`, `ar1:phi=F,sigma=S`), a static
//! record ([`NoiseModel::from_static_record`]: the machine standing still while the R-test
//! records), or estimated from the fit residual of the records themselves
//! ([`NoiseModel::estimate`]: the variogram of second differences, which a smooth misfit of the
//! model does not fool). [`NoiseChoice`] says which one an identification uses.
//!
//! The prewhitening ([`NoiseModel::whiten`]) is the Prais–Winsten transform per record and
//! direction, divided by σ: noise that follows the model becomes white with unit variance, so
//! ordinary least squares on whitened rows is the generalized least-squares fit, and every
//! later F-test, Monte-Carlo null and standard uncertainty is the textbook one.
//!
//! A record read through an instrument carries the covariance of each sample's reading (the
//! sensors' noise through the head's geometry). Its rows are first whitened by those
//! covariances ([`SampleWhitening`]: the shape of each sample's noise across x, y, z), keeping
//! the units and the mean size of the noise; the noise model then describes the whitened rows
//! over time (their σ and φ), estimated or from a static record read through the same
//! instrument. A declared model (an absolute σ per direction of the error vector) would declare
//! the noise a second time and is refused ([`NoiseError::DeclaredTwice`]).

use nalgebra::{DMatrix, DVector};
use simulation::record::Record;
use std::fmt;

mod covariance;
mod estimate;
mod spec;

pub use covariance::SampleWhitening;

pub use estimate::{
    MAX_ESTIMATED_PHI, MAX_STATIC_PHI, MIN_STATIC_SAMPLES, NOISE_FLOOR_MM, PHI_GRID_STEP,
    VARIOGRAM_LAGS, VARIOGRAM_MIN_LAGS, VARIOGRAM_MIN_PAIRS, Variogram, variogram,
};

/// The largest lag-1 autocorrelation a noise model may have (exclusive): at φ → 1 the noise is
/// a random walk, which no stationary model describes.
/// The same bound as a simulated truth's ([`simulation::truth::MAX_NOISE_PHI`]).
pub const MAX_PHI: f64 = simulation::truth::MAX_NOISE_PHI;

/// The directions' names, for messages.
pub const DIRECTIONS: [&str; 3] = ["x", "y", "z"];

/// Where a noise model came from.
#[derive(Clone, Debug, PartialEq)]
pub enum NoiseSource {
    /// Declared by the user (`--noise white:sigma=S` or `ar1:phi=F,sigma=S`).
    Declared,
    /// Estimated from a static record (the machine standing still while the R-test records),
    /// by Yule–Walker.
    StaticRecord {
        /// Samples of the static record.
        samples: usize,
    },
    /// Estimated from the fit residual of the records themselves, by the variogram of second
    /// differences.
    Estimated {
        /// Records pooled.
        records: usize,
        /// Samples over all records.
        samples: usize,
    },
    /// The instrument's own: the records' per-sample covariances taken as declared (white
    /// after whitening, its scale theirs), as a touch probe's σ, which its sphere fits check,
    /// declares them.
    Instrument,
    /// White, one σ for every direction: the σ̂ of an ordinary fit's residual (ordinary least
    /// squares, as without a noise model). `why` says why no other model is used.
    Residual {
        /// Why: `ordinary least squares`, or why the estimate failed.
        why: String,
    },
}

impl NoiseSource {
    /// The source's keyword in reports: `declared`, `static-record`, `estimated`, `residual`.
    pub fn keyword(&self) -> &'static str {
        match self {
            NoiseSource::Declared => "declared",
            NoiseSource::StaticRecord { .. } => "static-record",
            NoiseSource::Estimated { .. } => "estimated",
            NoiseSource::Instrument => "instrument",
            NoiseSource::Residual { .. } => "residual",
        }
    }
}

/// The reading noise per direction x, y, z: the marginal standard deviation σ (mm) and the
/// lag-1 autocorrelation φ of an AR(1) process, and where they came from.
#[derive(Clone, Debug, PartialEq)]
pub struct NoiseModel {
    /// Marginal standard deviation per direction x, y, z, mm (the standard deviation of one
    /// reading, whatever φ).
    pub sigma_mm: [f64; 3],
    /// Lag-1 autocorrelation per direction, in [0, [`MAX_PHI`]); 0 is white noise.
    pub phi: [f64; 3],
    /// Where the model came from.
    pub source: NoiseSource,
}

/// Which noise model an identification assumes.
#[derive(Clone, Debug, PartialEq, Default)]
pub enum NoiseChoice {
    /// Ordinary least squares: white noise of one σ, estimated from the residual (the
    /// behaviour without a noise model).
    #[default]
    Ordinary,
    /// Estimated from the residual of an ordinary fit ([`NoiseModel::estimate`]), then a
    /// generalized least-squares fit; white with the residual's σ̂ when it cannot be estimated.
    Estimate,
    /// This model (declared or from a static record), then a generalized least-squares fit.
    Model(NoiseModel),
    /// The records' covariances as their instrument declares them, scale included (a touch
    /// probe's σ, checked by its sphere fits): the generalized least-squares fit of the rows
    /// whitened by them, with no scale estimated from the residual; ordinary least squares for
    /// records without covariances.
    Instrument,
}

/// A noise specification, a static record or a whitening that cannot be used.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum NoiseError {
    /// A declared specification that cannot be read.
    #[error(
        "`{spec}`: {why}; expected white:sigma=S or ar1:phi=F,sigma=S (S the marginal standard deviation of a reading in µm, > 0; F the lag-1 autocorrelation, 0 ≤ F < 0.99)"
    )]
    Spec {
        /// The specification as given.
        spec: String,
        /// What is wrong with it.
        why: String,
    },
    /// A static record too short for a σ and φ worth using.
    #[error(
        "the static record has {samples} samples; at least {min} are needed to estimate the noise (σ and φ of each direction)"
    )]
    TooShort {
        /// Samples of the record.
        samples: usize,
        /// Samples needed.
        min: usize,
    },
    /// A static record too short for the correlation it shows.
    #[error(
        "direction {direction}: the static record's {samples} samples span too few correlation times for φ = {phi:.2} (the mean of the record is then not the mean of the noise); record longer"
    )]
    TooCorrelated {
        /// `x`, `y` or `z`.
        direction: &'static str,
        /// Samples of the record.
        samples: usize,
        /// The lag-1 autocorrelation found.
        phi: f64,
    },
    /// A static record in which the machine moves.
    #[error(
        "the static record is not static: the command of axis {axis} (counted from 1 in the machine's axis order) at sample {sample} differs from that at sample 1; the machine must stand still while the noise is recorded"
    )]
    NotStatic {
        /// The sample that differs (1-based).
        sample: usize,
        /// The axis (1-based).
        axis: usize,
    },
    /// A record without measured readings, or with a reading that is not finite.
    #[error("{0}")]
    Readings(String),
    /// The noise cannot be estimated from these residuals.
    #[error("the noise cannot be estimated: {0}")]
    Unestimable(String),
    /// The rows to whiten do not follow the layout (3 rows per sample, records one after the
    /// other), or the model cannot whiten (σ not positive, φ out of range).
    #[error("whitening: {0}")]
    Whitening(String),
    /// A noise model declared for a record whose readings already carry their covariance (an
    /// instrument's sensor noise): the two would declare the reading noise twice.
    #[error(
        "the readings carry the covariance of the instrument's sensor noise (each sensor's σ through the head's geometry); a declared noise model would declare the reading noise a second time: leave the declared model out (the noise is then estimated over time from the rows whitened by the covariances) or ask for ordinary least squares (the covariances' shape, the residual's scale)"
    )]
    DeclaredTwice,
    /// The whitened fit found another rank or other undetermined parameters than the ordinary
    /// one (a noise model that makes the data numerically singular).
    #[error(
        "the fit whitened by the noise model has rank {whitened}, the ordinary fit {ordinary}: the noise model makes the data numerically singular"
    )]
    RankChanged {
        /// Rank of the ordinary fit.
        ordinary: usize,
        /// Rank of the whitened fit.
        whitened: usize,
    },
}

impl NoiseModel {
    /// White noise of standard deviation `sigma_mm` (mm) in every direction.
    pub fn white(sigma_mm: f64, source: NoiseSource) -> NoiseModel {
        NoiseModel {
            sigma_mm: [sigma_mm; 3],
            phi: [0.0; 3],
            source,
        }
    }

    /// AR(1) noise of lag-1 autocorrelation `phi` and marginal standard deviation `sigma_mm`
    /// (mm) in every direction.
    pub fn ar1(phi: f64, sigma_mm: f64, source: NoiseSource) -> NoiseModel {
        NoiseModel {
            sigma_mm: [sigma_mm; 3],
            phi: [phi; 3],
            source,
        }
    }

    /// White noise of one σ (mm), the σ̂ of an ordinary fit's residual; `why` says why.
    pub fn residual(sigma_mm: f64, why: impl Into<String>) -> NoiseModel {
        NoiseModel::white(sigma_mm, NoiseSource::Residual { why: why.into() })
    }

    /// `true` when every direction is white with the same σ: whitening is then one common
    /// factor, and a generalized least-squares fit is the ordinary one.
    pub fn is_uniform_white(&self) -> bool {
        self.phi.iter().all(|&p| p == 0.0) && self.sigma_mm.iter().all(|&s| s == self.sigma_mm[0])
    }

    /// Checks that the model can whiten: σ finite and positive, φ in [0, [`MAX_PHI`]).
    ///
    /// # Errors
    /// [`NoiseError::Whitening`] naming the direction.
    pub fn check(&self) -> Result<(), NoiseError> {
        for (d, name) in DIRECTIONS.iter().enumerate() {
            let (s, p) = (self.sigma_mm[d], self.phi[d]);
            if !(s.is_finite() && s > 0.0) {
                return Err(NoiseError::Whitening(format!(
                    "σ of direction {name} is {s} mm; it must be finite and positive"
                )));
            }
            if !(0.0..MAX_PHI).contains(&p) {
                return Err(NoiseError::Whitening(format!(
                    "φ of direction {name} is {p}; it must be in [0, {MAX_PHI})"
                )));
            }
        }
        Ok(())
    }

    /// Whitens the rows of `h` and `y` in place ([`NoiseModel::whiten_series`] on every column
    /// of `h` and on `y`); `layout` is the number of samples of each record, in row order.
    ///
    /// # Errors
    /// As [`NoiseModel::whiten_series`]; `h` and `y` with different numbers of rows.
    pub fn whiten(
        &self,
        layout: &[usize],
        h: &mut DMatrix<f64>,
        y: &mut DVector<f64>,
    ) -> Result<(), NoiseError> {
        if h.nrows() != y.len() {
            return Err(NoiseError::Whitening(format!(
                "H has {} rows, y {}",
                h.nrows(),
                y.len()
            )));
        }
        self.whiten_matrix(layout, h)?;
        self.whiten_vector(layout, y)
    }

    /// Whitens every column of `a` in place (see [`NoiseModel::whiten_series`]).
    ///
    /// # Errors
    /// As [`NoiseModel::whiten_series`].
    pub fn whiten_matrix(&self, layout: &[usize], a: &mut DMatrix<f64>) -> Result<(), NoiseError> {
        let rows = a.nrows();
        self.check_layout(layout, rows)?;
        if rows == 0 {
            return Ok(());
        }
        // Column-major: every column is a contiguous slice of `rows` values.
        for col in a.as_mut_slice().chunks_mut(rows) {
            self.whiten_series(layout, col)?;
        }
        Ok(())
    }

    /// Whitens `v` in place (see [`NoiseModel::whiten_series`]).
    ///
    /// # Errors
    /// As [`NoiseModel::whiten_series`].
    pub fn whiten_vector(&self, layout: &[usize], v: &mut DVector<f64>) -> Result<(), NoiseError> {
        self.whiten_series(layout, v.as_mut_slice())
    }

    /// Whitens `rows` in place: row `3·i + d` is direction `d` of sample `i`, the records are
    /// consecutive ranges of `3·layout[r]` rows. Per record and direction, with `u_t` the rows
    /// of that direction (mm):
    ///
    /// ```text
    /// w_0 = u_0 / σ,   w_t = (u_t − φ·u_{t−1}) / (σ·√(1−φ²))   (Prais–Winsten, divided by σ)
    /// ```
    ///
    /// Noise that follows the model becomes independent with unit variance (unitless).
    ///
    /// # Errors
    /// [`NoiseError::Whitening`] when the rows are not `3·Σ layout`, or the model cannot whiten
    /// ([`NoiseModel::check`]).
    pub fn whiten_series(&self, layout: &[usize], rows: &mut [f64]) -> Result<(), NoiseError> {
        self.check_layout(layout, rows.len())?;
        let mut start = 0;
        for &n in layout {
            let record = &mut rows[start..start + 3 * n];
            for d in 0..3 {
                let (s, p) = (self.sigma_mm[d], self.phi[d]);
                let innovation = s * (1.0 - p * p).sqrt();
                // Backwards, so that u_{t−1} is still the original.
                for t in (1..n).rev() {
                    record[3 * t + d] =
                        (record[3 * t + d] - p * record[3 * (t - 1) + d]) / innovation;
                }
                if n > 0 {
                    record[d] /= s;
                }
            }
            start += 3 * n;
        }
        Ok(())
    }

    fn check_layout(&self, layout: &[usize], rows: usize) -> Result<(), NoiseError> {
        self.check()?;
        let samples: usize = layout.iter().sum();
        if 3 * samples != rows {
            return Err(NoiseError::Whitening(format!(
                "{rows} rows, but the records have {samples} samples ({} rows, 3 per sample)",
                3 * samples
            )));
        }
        Ok(())
    }
}

/// Per-direction values `v` (already in the display unit) as `a` when all equal, else
/// `a (x), b (y), c (z)`; `unit` after the last value.
fn per_direction(v: [f64; 3], decimals: usize, unit: &str) -> String {
    let f = |x: f64| format!("{x:.decimals$}");
    if v.iter().all(|x| f(*x) == f(v[0])) {
        format!("{}{unit} (x, y, z)", f(v[0]))
    } else {
        format!("{} (x), {} (y), {}{unit} (z)", f(v[0]), f(v[1]), f(v[2]))
    }
}

impl fmt::Display for NoiseModel {
    /// `AR(1) φ = 0.80 (x, y, z), σ = 0.30 µm (x, y, z), estimated from 1 record (241
    /// samples)`, or `white, σ = 0.50 µm (x, y, z), declared`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sigma_um = self.sigma_mm.map(|s| s * 1e3);
        let decimals = if sigma_um.iter().all(|&s| s >= 0.01 || s == 0.0) {
            2
        } else {
            6
        };
        if self.phi.iter().all(|&p| p == 0.0) {
            write!(f, "white")?;
        } else {
            write!(f, "AR(1) φ = {}", per_direction(self.phi, 2, ""))?;
        }
        write!(f, ", σ = {}, ", per_direction(sigma_um, decimals, " µm"))?;
        match &self.source {
            NoiseSource::Declared => write!(f, "declared"),
            NoiseSource::StaticRecord { samples } => {
                write!(f, "from a static record of {samples} samples")
            }
            NoiseSource::Estimated { records, samples } => write!(
                f,
                "estimated from {records} record{} ({samples} samples)",
                if *records == 1 { "" } else { "s" }
            ),
            NoiseSource::Residual { why } => write!(f, "the σ̂ of the residual ({why})"),
            NoiseSource::Instrument => {
                write!(
                    f,
                    "declared by the instrument (the readings' covariances as they are)"
                )
            }
        }
    }
}

impl NoiseModel {
    /// The noise of a static record (the machine standing still while the R-test records):
    /// per direction, mean removed, σ and φ by Yule–Walker (see `docs/identification.md`).
    ///
    /// # Errors
    /// A record without finite readings, shorter than [`MIN_STATIC_SAMPLES`], in which the
    /// commands change, or too short for the correlation it shows.
    pub fn from_static_record(record: &Record) -> Result<NoiseModel, NoiseError> {
        estimate::from_static_record(record)
    }

    /// The noise estimated from residual series (one slice per record, one `[x, y, z]` per
    /// sample, mm; equally spaced samples) by the variogram of second differences, which a
    /// smooth misfit of the model does not fool (see [`variogram`] and
    /// `docs/identification.md`).
    ///
    /// # Errors
    /// [`NoiseError::Unestimable`] when the records are too short for [`VARIOGRAM_MIN_LAGS`]
    /// lags, a value is not finite, or a direction's σ is below [`NOISE_FLOOR_MM`] (noise-free
    /// data: the residual is rounding and second-order terms).
    pub fn estimate(residuals: &[&[[f64; 3]]]) -> Result<NoiseModel, NoiseError> {
        estimate::estimate(residuals)
    }
}
