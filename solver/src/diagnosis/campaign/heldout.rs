//! The held-out records of a campaign diagnosis: the predictions of a campaign fit (with the
//! minimum-norm solution where it determined combinations only), and what a prediction needs
//! that the fit did not determine, once the record's refitted columns have taken what they can.

use crate::diagnosis::DiagnoseError;
use crate::diagnosis::heldout::NEEDS_TOLERANCE;
use crate::diagnosis::select::Span;
use crate::fitting::campaign::design::block;
use crate::fitting::campaign::{
    Campaign, CampaignIdentification, CampaignRecord, CampaignValues, record_plan, validate_record,
};
use crate::fitting::hmatrix::GainSource;
use crate::fitting::validate::{ValidateError, ValidateOptions, Validation, statistics};
use model_spec::Machine;
use nalgebra::DMatrix;

/// The values a prediction uses: every column's minimum-norm solution (the fit's values where
/// it has them; the determined combinations carried where it does not).
pub(super) fn estimable(ident: &CampaignIdentification) -> CampaignValues {
    let mut v = CampaignValues::of(ident);
    v.values = ident
        .fit
        .values
        .iter()
        .zip(&ident.fit.solution)
        .map(|(v, s)| Some(v.unwrap_or(*s)))
        .collect();
    v
}

/// The exact predictions of `ident` on every held-out record.
pub(super) fn predict(
    m: &Machine,
    ident: &CampaignIdentification,
    held: &Campaign,
) -> Result<Vec<Validation>, ValidateError> {
    let values = estimable(ident);
    let opts = ValidateOptions {
        exact: true,
        ..Default::default()
    };
    held.records
        .iter()
        .map(|r| validate_record(m, &values, r, &opts).map(|v| v.validation))
        .collect()
}

/// The confounded groups of `ident` (by name) the prediction on held-out record `r` needs: a
/// null direction of the fit that changes the prediction, once the record's refitted columns
/// have taken what they can.
pub(super) fn needed_groups(
    m: &Machine,
    ident: &CampaignIdentification,
    r: &CampaignRecord,
) -> Result<Vec<Vec<String>>, DiagnoseError> {
    let fit = &ident.fit;
    let null = &fit.identifiability.null_space;
    if null.ncols() == 0 {
        return Ok(Vec::new());
    }
    let values = estimable(ident);
    let plan = record_plan(m, &values, r)?;
    let mut source = GainSource::new(m, &plan.model.errors(), &r.params)?;
    let h = block(m, &plan.model, &r.record, &mut source, plan.clock)?;
    let rows = h.nrows();
    let mut b = DMatrix::zeros(rows, fit.names.len());
    let mut refit = Vec::new();
    for (k, s) in plan.sources.iter().enumerate() {
        match s {
            Some(c) => {
                let col = h.column(k) / fit.column_norms[*c];
                let mut target = b.column_mut(*c);
                target += col;
            }
            None => refit.push(k),
        }
    }
    let refit_span = Span::of_groups(rows, 0..refit.len(), &|i| {
        h.columns(refit[i], 1).into_owned()
    });
    let scale = (0..b.ncols())
        .map(|j| b.column(j).norm())
        .fold(0.0, f64::max);
    let mut groups: Vec<usize> = Vec::new();
    for k in 0..null.ncols() {
        let n = null.column(k);
        let moved = refit_span.project_out(&(&b * n));
        if moved.norm() <= NEEDS_TOLERANCE * scale {
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

/// RMS of `residual` without the samples of `drop`, mm.
pub(super) fn rms_without(residual: &[[f64; 3]], drop: &[usize]) -> f64 {
    let kept: Vec<[f64; 3]> = (0..residual.len())
        .filter(|i| !drop.contains(i))
        .map(|i| residual[i])
        .collect();
    statistics(&kept, &vec![[0.0; 3]; kept.len()])
        .1
        .measured_rms
}
