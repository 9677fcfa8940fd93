//! The per-sample weights of records read through an instrument: every sample's readings are
//! whitened by the covariance the sensors' noise gives them ([`Campaign::whitening`]) before
//! the noise model, in the selection, the profile and the lack-of-fit test as in the fits.
//! The held-out records are whitened at the fitted records' scale, so that the noise model
//! estimated from both describes one kind of row.

use super::DiagnoseError;
use fitting::campaign::CampaignIdentification;
use fitting::noise::{NoiseChoice, SampleWhitening};
use nalgebra::{DMatrix, DVector};
use simulation::campaign::Campaign;
use simulation::record::Record;

/// The weights of a diagnosis's records; none when no record carries covariances.
pub(super) struct Weights {
    /// The fitted records' (outliers left out), stacked.
    fitted: Option<SampleWhitening>,
}

/// Rows `[x, y, z]` of a vector of 3 rows per sample.
fn rows(v: &DVector<f64>) -> Vec<[f64; 3]> {
    v.as_slice()
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect()
}

impl Weights {
    /// The weights of the fitted records `fitted` and the held-out records `held` under the
    /// noise choice `noise`.
    ///
    /// # Errors
    /// Records with and without covariances together (named), covariances that cannot whiten,
    /// or a declared noise model with covariances (the sensors' σ already declare the noise).
    pub fn of(
        fitted: &Campaign,
        held: &Campaign,
        noise: &NoiseChoice,
    ) -> Result<Weights, DiagnoseError> {
        let w = fitting::campaign::whitening(fitted, noise)?;
        let read = |r: &&simulation::campaign::CampaignRecord| !r.record.covariance.is_empty();
        let odd = if w.is_some() {
            held.records.iter().find(|r| !read(r))
        } else {
            held.records.iter().find(read)
        };
        if let Some(r) = odd {
            return Err(DiagnoseError::Campaign(format!(
                "held-out record `{}` {} read through an instrument (per-sample covariances) and the fitted records {}: read every record through the instrument or none",
                r.label,
                if w.is_some() { "was not" } else { "was" },
                if w.is_some() { "were" } else { "were not" },
            )));
        }
        Ok(Weights { fitted: w })
    }

    /// Whitens the fitted records' rows `v` (3 per sample, stacked) in place.
    ///
    /// # Errors
    /// Rows that are not the fitted records'.
    pub fn fitted_vector(&self, v: &mut DVector<f64>) -> Result<(), DiagnoseError> {
        if let Some(w) = &self.fitted {
            w.whiten_vector(v)?;
        }
        Ok(())
    }

    /// Whitens the columns `h` of the fitted records' rows in place.
    ///
    /// # Errors
    /// Rows that are not the fitted records'.
    pub fn fitted_matrix(&self, h: &mut DMatrix<f64>) -> Result<(), DiagnoseError> {
        if let Some(w) = &self.fitted {
            w.whiten_matrix(h)?;
        }
        Ok(())
    }

    /// The residual of every fitted record of `fit`, whitened, one `[x, y, z]` per sample.
    ///
    /// # Errors
    /// A fit of other records.
    pub fn fitted_rows(
        &self,
        fit: &CampaignIdentification,
    ) -> Result<Vec<Vec<[f64; 3]>>, DiagnoseError> {
        if self.fitted.is_none() {
            return Ok((0..fit.records.len())
                .map(|r| fit.record_residual(r))
                .collect());
        }
        let mut v = fit.fit.residual.clone();
        self.fitted_vector(&mut v)?;
        let all = rows(&v);
        let mut out = Vec::with_capacity(fit.records.len());
        let mut at = 0;
        for r in &fit.records {
            out.push(all[at..at + r.samples].to_vec());
            at += r.samples;
        }
        Ok(out)
    }

    /// The factor that puts a held-out record's whitening `w` at the fitted records' scale.
    fn held_scale(&self, w: &SampleWhitening) -> f64 {
        self.fitted
            .as_ref()
            .map_or(1.0, |f| f.scale_mm / w.scale_mm)
    }

    /// Whitens the rows `v` (3 per sample) of the held-out record `record` in place.
    ///
    /// # Errors
    /// Covariances that cannot whiten, or rows that are not the record's.
    pub fn held_vector(&self, record: &Record, v: &mut DVector<f64>) -> Result<(), DiagnoseError> {
        if let Some(w) = SampleWhitening::of(record)? {
            w.whiten_vector(v)?;
            *v *= self.held_scale(&w);
        }
        Ok(())
    }

    /// Whitens the columns `h` of the held-out record `record`'s rows in place.
    ///
    /// # Errors
    /// As [`Weights::held_vector`].
    pub fn held_matrix(&self, record: &Record, h: &mut DMatrix<f64>) -> Result<(), DiagnoseError> {
        if let Some(w) = SampleWhitening::of(record)? {
            w.whiten_matrix(h)?;
            *h *= self.held_scale(&w);
        }
        Ok(())
    }

    /// The residual `residual` (mm, one `[x, y, z]` per sample) of the held-out record
    /// `record`, whitened.
    ///
    /// # Errors
    /// As [`Weights::held_vector`].
    pub fn held_rows(
        &self,
        record: &Record,
        residual: &[[f64; 3]],
    ) -> Result<Vec<[f64; 3]>, DiagnoseError> {
        if record.covariance.is_empty() {
            return Ok(residual.to_vec());
        }
        let mut v = DVector::from_iterator(3 * residual.len(), residual.iter().flatten().copied());
        self.held_vector(record, &mut v)?;
        Ok(rows(&v))
    }
}
