//! Held-out records: what the base and the extended model predict there, with only what the
//! fit determined.
//!
//! - **Estimable predictions.** A fit of a rank-deficient model determines combinations of its
//!   parameters, not every parameter. The prediction uses the values the fit gave, and for the
//!   parameters it could not determine the minimum-norm solution (which carries exactly the
//!   determined combinations: its undetermined part is zero). Setting undetermined values to
//!   0, as a plain validation does, would throw away the combinations the fit did determine.
//! - **What the prediction needs.** With `N` the null space of the fit's scaled H (`A = H·S⁻¹`)
//!   and `B = H_h·S⁻¹` the same model on the held-out record, a null direction `n` changes the
//!   held-out prediction by `B·n`: the fit cannot say what that part is. When `‖B·n‖` exceeds
//!   `NEEDS_TOLERANCE` times the largest column norm of `B`, the held-out record needs an
//!   undetermined combination, and the confounded groups `n` involves are named; that
//!   record's RMS is then not the model's error and does not count in the gain.
//! - **Outliers** of the held-out record (from the base prediction's residual,
//!   [`super::outliers`]) are listed and left out of both RMS.

use super::outliers::{self, Outlier};
use crate::fitting::Identification;
use crate::fitting::hmatrix::{GainSource, h_matrix};
use crate::fitting::validate::{
    ValidateError, ValidateOptions, Validation, statistics, validate_with,
};
use crate::record::Record;
use model_spec::Machine;

/// Relative size of `‖B·n‖` above which a held-out record needs a null direction of the fit.
pub const NEEDS_TOLERANCE: f64 = 1e-6;

/// One held-out record's gain.
#[derive(Clone, Debug, PartialEq)]
pub struct HeldOut {
    /// Its name (file).
    pub name: String,
    /// Readings counted in the RMS (three per sample, outliers' samples left out).
    pub readings: usize,
    /// Residual RMS of the base model's prediction, mm (outliers left out).
    pub before_rms: f64,
    /// Residual RMS of the extended model's prediction, mm (outliers left out).
    pub after_rms: f64,
    /// Isolated readings far outside the base prediction's residual, left out of both RMS.
    pub outliers: Vec<Outlier>,
    /// Confounded groups of the base fit (parameter names) its prediction needs: when not
    /// empty, `before_rms` is not the base model's error.
    pub undetermined_before: Vec<Vec<String>>,
    /// The same for the extended fit.
    pub undetermined_after: Vec<Vec<String>>,
    /// The extended model's residual per sample, mm (outliers included).
    pub residual_after: Vec<[f64; 3]>,
    /// The base model's residual per sample, mm (outliers included).
    pub residual_before: Vec<[f64; 3]>,
}

impl HeldOut {
    /// The extended model's residual without the outliers' samples: 3 rows per sample, mm.
    pub fn residual_after_without_outliers(&self) -> nalgebra::DVector<f64> {
        let drop = outliers::samples(&self.outliers);
        nalgebra::DVector::from_iterator(
            3 * (self.residual_after.len() - drop.len()),
            (0..self.residual_after.len())
                .filter(|i| !drop.contains(i))
                .flat_map(|i| self.residual_after[i]),
        )
    }

    /// `true` when both predictions use only what the fits determined, so that the change of
    /// RMS is the extension's gain.
    pub fn estimable(&self) -> bool {
        self.undetermined_before.is_empty() && self.undetermined_after.is_empty()
    }
}

/// The values a prediction uses: the fit's values, the minimum-norm solution where the fit
/// gave none.
pub fn estimable_values(ident: &Identification) -> Vec<Option<f64>> {
    let fit = &ident.fit;
    fit.values
        .iter()
        .zip(&fit.solution)
        .map(|(v, s)| Some(v.unwrap_or(*s)))
        .collect()
}

/// The confounded groups of `ident` (parameter names) the prediction on `record` needs
/// (`zeroed`: the prediction is zeroed at the first sample, so constant directions cancel).
pub fn needed_groups(
    m: &Machine,
    ident: &Identification,
    record: &Record,
    source: &mut GainSource,
    zeroed: bool,
) -> Result<Vec<Vec<String>>, ValidateError> {
    let fit = &ident.fit;
    let null = &fit.identifiability.null_space;
    if null.ncols() == 0 {
        return Ok(Vec::new());
    }
    let mut b = h_matrix(m, &ident.model, record, source)?;
    if zeroed {
        let first = b.rows(0, 3).into_owned();
        for i in 0..b.nrows() / 3 {
            let mut rows = b.rows_mut(3 * i, 3);
            rows -= &first;
        }
    }
    for (j, s) in fit.column_norms.iter().enumerate() {
        b.column_mut(j).scale_mut(1.0 / s);
    }
    let scale = (0..b.ncols())
        .map(|j| b.column(j).norm())
        .fold(0.0, f64::max);
    let mut groups: Vec<usize> = Vec::new();
    for k in 0..null.ncols() {
        let n = null.column(k);
        if (&b * n).norm() <= NEEDS_TOLERANCE * scale {
            continue;
        }
        for (g, members) in fit.identifiability.confounded.iter().enumerate() {
            if members.iter().any(|&j| n[j].abs() > NEEDS_TOLERANCE) && !groups.contains(&g) {
                groups.push(g);
            }
        }
    }
    groups.sort_unstable();
    Ok(groups
        .iter()
        .map(|&g| {
            fit.identifiability.confounded[g]
                .iter()
                .map(|&j| fit.names[j].clone())
                .collect()
        })
        .collect())
}

/// The RMS of `residual` without the readings of `outliers`' samples, mm.
fn rms_without(residual: &[[f64; 3]], outliers: &[Outlier]) -> f64 {
    let drop = outliers::samples(outliers);
    let kept: Vec<[f64; 3]> = (0..residual.len())
        .filter(|i| !drop.contains(i))
        .map(|i| residual[i])
        .collect();
    statistics(&kept, &vec![[0.0; 3]; kept.len()])
        .1
        .measured_rms
}

/// The prediction of `fit` on every held-out record (exact machine, estimable values).
pub fn predict(
    m: &Machine,
    fit: &Identification,
    held_out: &[(String, Record)],
    source: &mut GainSource,
    opts: &ValidateOptions,
) -> Result<Vec<Validation>, ValidateError> {
    held_out
        .iter()
        .map(|(_, rec)| validate_with(m, &fit.model, &estimable_values(fit), rec, source, opts))
        .collect()
}

/// The gain on every held-out record: the base predictions `before` ([`predict`]) and the
/// extended ones, outliers left out, undetermined needs named.
pub fn held_out_gain(
    m: &Machine,
    base: &Identification,
    before: &[Validation],
    extended: &Identification,
    held_out: &[(String, Record)],
    source: &mut GainSource,
    opts: &ValidateOptions,
) -> Result<Vec<HeldOut>, ValidateError> {
    let mut out = Vec::new();
    for ((name, rec), before) in held_out.iter().zip(before) {
        let after = validate_with(
            m,
            &extended.model,
            &estimable_values(extended),
            rec,
            source,
            opts,
        )?;
        let outliers = outliers::find_in(rec, &before.residual);
        out.push(HeldOut {
            name: name.clone(),
            readings: 3 * (rec.samples.len() - outliers::samples(&outliers).len()),
            before_rms: rms_without(&before.residual, &outliers),
            after_rms: rms_without(&after.residual, &outliers),
            residual_after: after.residual,
            residual_before: before.residual.clone(),
            outliers,
            undetermined_before: needed_groups(m, base, rec, source, opts.zeroed)?,
            undetermined_after: needed_groups(m, extended, rec, source, opts.zeroed)?,
        });
    }
    Ok(out)
}
