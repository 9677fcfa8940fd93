//! Whitening by the covariance of each sample's reading (a record read through an instrument,
//! [`simulation::record::Record::covariance`]).
//!
//! With `Σ_i = L_i·L_iᵀ` (Cholesky) the covariance of sample `i`'s error vector, the three rows
//! of the sample in `H` and `y` are multiplied by `c·L_i⁻¹`, `c² = mean_i trace(Σ_i)/3` the
//! mean variance of one component: noise that follows the covariances becomes independent with
//! the same variance `c²` in every row. The covariances give the shape (how the components of
//! one sample compare and correlate), not the scale: the rows keep the units of the readings
//! (mm) and the size of their noise, the residual's σ̂ sets the scale as in an ordinary fit,
//! and a noise model over time ([`super::NoiseModel`]) acts on the whitened rows.

use super::NoiseError;
use nalgebra::{DMatrix, DVector, Matrix3};
use simulation::record::Record;

/// The per-sample whitening of a record with covariances.
#[derive(Clone, Debug, PartialEq)]
pub struct SampleWhitening {
    /// Per sample, `c·L_i⁻¹` (unitless).
    factors: Vec<Matrix3<f64>>,
    /// `c`, the root mean variance of one component of the reading, mm.
    pub scale_mm: f64,
}

impl SampleWhitening {
    /// The whitening of `record`; `None` when the record declares no covariance.
    ///
    /// # Errors
    /// [`NoiseError::Whitening`] when the covariances are not one per sample, or one is not
    /// finite, not symmetric or not positive definite (naming the sample).
    pub fn of(record: &Record) -> Result<Option<SampleWhitening>, NoiseError> {
        let cov = &record.covariance;
        if cov.is_empty() {
            return Ok(None);
        }
        if cov.len() != record.samples.len() {
            return Err(NoiseError::Whitening(format!(
                "the record has {} samples but {} covariances",
                record.samples.len(),
                cov.len()
            )));
        }
        let mut trace = 0.0;
        let mut inverse_factors = Vec::with_capacity(cov.len());
        for (i, c) in cov.iter().enumerate() {
            let m = Matrix3::from_fn(|a, b| c[a][b]);
            let bad = |why: &str| {
                NoiseError::Whitening(format!(
                    "the covariance of the reading at {} {why}",
                    record.place(i)
                ))
            };
            if !m.iter().all(|v| v.is_finite()) {
                return Err(bad("is not finite"));
            }
            if (m - m.transpose()).amax() > 1e-9 * m.amax() {
                return Err(bad("is not symmetric"));
            }
            let l = m
                .cholesky()
                .ok_or_else(|| bad("is not positive definite"))?
                .l();
            let inv = l
                .try_inverse()
                .ok_or_else(|| bad("is not positive definite"))?;
            trace += m.trace();
            inverse_factors.push(inv);
        }
        let scale_mm = (trace / (3.0 * cov.len() as f64)).sqrt();
        if !(scale_mm.is_finite() && scale_mm > 0.0) {
            return Err(NoiseError::Whitening(format!(
                "the covariances have the mean variance {} mm²",
                scale_mm * scale_mm
            )));
        }
        Ok(Some(SampleWhitening {
            factors: inverse_factors.into_iter().map(|f| f * scale_mm).collect(),
            scale_mm,
        }))
    }

    /// Whitens `data` in place: columns of `n_rows` values each, one after the other, whose
    /// rows `3i..3i+3` are sample `i`'s.
    fn whiten_columns(&self, data: &mut [f64], n_rows: usize) -> Result<(), NoiseError> {
        if n_rows != 3 * self.factors.len() {
            return Err(NoiseError::Whitening(format!(
                "{n_rows} rows, but the record has {} samples ({} rows, 3 per sample)",
                self.factors.len(),
                3 * self.factors.len()
            )));
        }
        if n_rows == 0 {
            return Ok(());
        }
        for col in data.chunks_mut(n_rows) {
            for (i, f) in self.factors.iter().enumerate() {
                let r = &mut col[3 * i..3 * i + 3];
                let v = [r[0], r[1], r[2]];
                for (a, out) in r.iter_mut().enumerate() {
                    *out = f[(a, 0)] * v[0] + f[(a, 1)] * v[1] + f[(a, 2)] * v[2];
                }
            }
        }
        Ok(())
    }

    /// Whitens every column of `h` (3 rows per sample) in place.
    ///
    /// # Errors
    /// [`NoiseError::Whitening`] when `h` does not have 3 rows per sample.
    pub fn whiten_matrix(&self, h: &mut DMatrix<f64>) -> Result<(), NoiseError> {
        let n = h.nrows();
        self.whiten_columns(h.as_mut_slice(), n)
    }

    /// Whitens `y` (3 rows per sample) in place.
    ///
    /// # Errors
    /// [`NoiseError::Whitening`] when `y` does not have 3 rows per sample.
    pub fn whiten_vector(&self, y: &mut DVector<f64>) -> Result<(), NoiseError> {
        let n = y.len();
        self.whiten_columns(y.as_mut_slice(), n)
    }
}
