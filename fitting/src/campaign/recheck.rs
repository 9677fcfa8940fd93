//! A re-check: a few poses measured again (one sphere at a few positions of the rotary axes, as
//! a controller's preset cycle does after a head change or a crash) refit named machine
//! parameters (the **pivot**: a head's offsets, an axis's location) together over every record
//! of the re-check, each record's new set-up (the **preset**: where the sphere is) and its zero
//! as [`super::validate()`] refits them, and every other value held at the calibration's.
//!
//! The columns refitted are, over the re-check's records, the named shared parameters (one value
//! for all records) and each record's own refits (its set-up errors when its set-up was not
//! fitted by the calibration, its zero when zeroed). Their least-squares fit is the fit of the
//! readings minus the prediction at the held values (first order), refined against the exact
//! machine by Gauss–Newton when the prediction is exact, as a validation's refit is. Readings
//! through an instrument (a probe's sphere fits) are weighted by their covariances, and the
//! uncertainties are at the instrument's declared scale unless the residual refutes it (the
//! χ² upper tail below [`super::fit::DECLARED_REFUTED`]); readings without covariances give
//! uncertainties at the residual's scale.
//!
//! A parameter the re-check cannot separate from the others has no value (`None`), never a
//! number: the re-check's poses must see it.

use super::design::Owner;
use super::validate::{CampaignValidation, CampaignValues, prepare, refit_held};
use crate::hmatrix::parameter_name;
use crate::validate::{ValidateError, ValidateOptions};
use formats::progress::Progress;
use model_spec::Machine;
use simulation::campaign::Campaign;
use simulation::model::Term;

/// A machine parameter the re-check refitted.
#[derive(Clone, Debug, PartialEq)]
pub struct PivotRefit {
    /// Its name (`ZOB`, `XOC`).
    pub name: String,
    /// Its term.
    pub term: Term,
    /// Which of the term's columns.
    pub component: usize,
    /// The calibration's value (mm, rad); `None` when the calibration did not determine it.
    pub calibrated: Option<f64>,
    /// The calibration's standard uncertainty.
    pub calibrated_std: Option<f64>,
    /// The re-check's value (mm, rad); `None` when the re-check cannot separate it.
    pub value: Option<f64>,
    /// Its standard uncertainty.
    pub std: Option<f64>,
}

/// How the re-check's uncertainties are scaled.
#[derive(Clone, Debug, PartialEq)]
pub enum RecheckScale {
    /// The readings carry no covariances: the residual's σ̂ (mm).
    Residual(Option<f64>),
    /// The instrument's declared covariances; `ratio` is the σ̂ of the whitened residual (about
    /// 1 when the declared σ is right), and its χ² upper tail `p`.
    Declared {
        /// σ̂ of the whitened residual (unitless).
        ratio: f64,
        /// Its χ² upper tail.
        p: f64,
    },
    /// The declared covariances refuted by the residual (χ² upper tail `p` below
    /// [`super::fit::DECLARED_REFUTED`]): the uncertainties keep the residual's scale.
    Refuted {
        /// σ̂ of the whitened residual (unitless).
        ratio: f64,
        /// Its χ² upper tail.
        p: f64,
    },
}

/// A re-check's result.
#[derive(Clone, Debug, PartialEq)]
pub struct Recheck {
    /// The machine parameters refitted, in the order asked.
    pub pivot: Vec<PivotRefit>,
    /// Per record, the validation after the re-check: its own refits (the set-up: the preset;
    /// the zero) and its residual with every value at the re-check's.
    pub validation: CampaignValidation,
    /// Degrees of freedom of the refit (readings minus rank).
    pub dof: usize,
    /// How the uncertainties are scaled.
    pub scale: RecheckScale,
}

/// Re-checks `values` (a calibration) on `campaign`: the shared parameters `pivot` (names as
/// the calibration's report gives them, any case, `X0C` for `XOC`) refitted with each record's
/// own refits, every other value held (see the module documentation). `opts` as for
/// [`super::validate()`]; records are reported to `progress`.
///
/// # Errors
/// A name that is not a machine parameter of the calibration, or given twice; no name; as
/// [`super::validate()`]; fewer readings than refitted parameters plus one; a refinement that
/// does not converge.
pub fn recheck(
    m: &Machine,
    values: &CampaignValues,
    campaign: &Campaign,
    pivot: &[String],
    opts: &ValidateOptions,
    progress: &dyn Progress,
) -> Result<Recheck, ValidateError> {
    campaign.check(m).map_err(|e| ValidateError::Shape(e.0))?;
    let layout = &values.layout;
    let shared = pivot_columns(m, values, pivot).map_err(ValidateError::Shape)?;
    let total = campaign.records.len() as u64;
    let mut prepared = Vec::with_capacity(campaign.records.len());
    for (i, r) in campaign.records.iter().enumerate() {
        progress.update("re-checking records", i as u64, total);
        prepared.push(prepare(m, values, r, opts)?);
    }
    let f = refit_held(m, &prepared, &shared, opts.exact, "the re-check")?
        .ok_or_else(|| ValidateError::Shape("the re-check has nothing to refit".into()))?;
    let fit = &f.fit;
    let (scale, factor) = scale_of(f.weighted, f.weighted_sigma, fit.sigma, fit.dof);
    let pivot_out = shared
        .iter()
        .enumerate()
        .map(|(u, (j, name))| {
            let c = &layout.columns[*j];
            PivotRefit {
                name: name.clone(),
                term: c.term,
                component: c.component,
                calibrated: values.values[*j],
                calibrated_std: values.std[*j],
                value: fit.values[u],
                std: fit.std[u].map(|s| s * factor),
            }
        })
        .collect();
    let mut records = Vec::with_capacity(prepared.len());
    for (r, (p, v)) in prepared
        .iter()
        .zip(f.values(&prepared, &fit.solution))
        .enumerate()
    {
        records.push(p.finish(m, &v, f.refitted(&prepared, r, factor), opts.exact)?);
    }
    progress.update("re-checking records", total, total);
    Ok(Recheck {
        pivot: pivot_out,
        validation: CampaignValidation::of(&campaign.records, records),
        dof: fit.dof,
        scale,
    })
}

/// The layout columns of `values` that the names `pivot` refit: each a machine parameter
/// (shared) of the calibration, named as its report names it (any case, `X0C` for `XOC`), at
/// most once; at least one name.
///
/// # Errors
/// What is wrong, naming the name and the calibration's machine parameters.
pub fn pivot_columns(
    m: &Machine,
    values: &CampaignValues,
    pivot: &[String],
) -> Result<Vec<(usize, String)>, String> {
    let shared: Vec<(usize, String)> = values
        .layout
        .columns
        .iter()
        .enumerate()
        .filter(|(_, c)| c.owner == Owner::Shared)
        .map(|(j, c)| (j, parameter_name(m, &c.term, c.component)))
        .collect();
    if pivot.is_empty() {
        return Err("a re-check refits at least one machine parameter".into());
    }
    let mut out: Vec<(usize, String)> = Vec::with_capacity(pivot.len());
    for name in pivot {
        let key = canonical(name);
        let Some((j, found)) = shared.iter().find(|(_, n)| canonical(n) == key) else {
            let names: Vec<&str> = shared.iter().map(|(_, n)| n.as_str()).collect();
            return Err(format!(
                "`{name}` is not a machine parameter of the calibration (its machine parameters: {})",
                names.join(", ")
            ));
        };
        let j = *j;
        if out.iter().any(|(c, _)| *c == j) {
            return Err(format!("`{name}` is named twice"));
        }
        if values.layout.columns[j].term.effect.symbol().is_some() {
            return Err(format!(
                "`{name}` is the change of a kinematic length, which a re-check does not refit: refit the location errors it moves"
            ));
        }
        out.push((j, found.clone()));
    }
    Ok(out)
}

/// The scale of the uncertainties and the factor the fit's own (at the residual's scale)
/// take: with covariances, the declared scale (÷ the whitened σ̂) unless the χ² of the
/// whitened residual refutes it; without, the residual's.
fn scale_of(
    weighted: bool,
    ratio: Option<f64>,
    sigma: Option<f64>,
    dof: usize,
) -> (RecheckScale, f64) {
    match ratio.filter(|r| weighted && *r > 0.0 && r.is_finite() && dof > 0) {
        Some(ratio) => {
            let p = crate::distributions::chi2_upper_tail(ratio * ratio * dof as f64, dof as f64);
            if p < super::fit::DECLARED_REFUTED {
                (RecheckScale::Refuted { ratio, p }, 1.0)
            } else {
                (RecheckScale::Declared { ratio, p }, 1.0 / ratio)
            }
        }
        None => (RecheckScale::Residual(sigma), 1.0),
    }
}

/// A name as compared: the canonical spelling of its effect (`X0C` is `XOC`), any case.
fn canonical(name: &str) -> String {
    let name = name.trim();
    match name.split_once('@') {
        Some((e, b)) => format!("{}@{}", model_spec::canonical_name(e), b.to_lowercase()),
        None => model_spec::canonical_name(name),
    }
}
