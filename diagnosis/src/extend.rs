//! The fits of a diagnosis: a model refined against the exact machine on the fitted records,
//! and the extended model, from which a finding whose refinement does not converge is dropped
//! (the diagnosis goes on without it; only the base model's fit failing stops it), and the
//! findings with their values and sizes.

use super::profile::Scan;
use super::search::Chosen;
use super::{DiagnoseError, DiagnoseOptions, Dropped, Finding, plausible};
use fitting::IdentifyOptions;
use fitting::campaign::{CampaignIdentification, identify};
use fitting::noise::NoiseChoice;
use fitting::refine::{IdentifyError, RefineOptions};
use model_spec::Machine;
use simulation::campaign::Campaign;
use simulation::model::{Model, Term};

/// The refined fit of `model` on `c` under `noise` (the records carry their zeroing and
/// kinematic parameters).
///
/// # Errors
/// As [`identify`].
pub(super) fn fit(
    m: &Machine,
    model: &Model,
    c: &Campaign,
    o: &DiagnoseOptions,
    noise: &NoiseChoice,
) -> Result<CampaignIdentification, DiagnoseError> {
    fit_refined(m, model, c, o, noise, &RefineOptions::default())
}

/// [`fit`] refined as `refine` says.
///
/// # Errors
/// As [`identify`].
pub(super) fn fit_refined(
    m: &Machine,
    model: &Model,
    c: &Campaign,
    o: &DiagnoseOptions,
    noise: &NoiseChoice,
    refine: &RefineOptions,
) -> Result<CampaignIdentification, DiagnoseError> {
    let mut opts = IdentifyOptions::default();
    opts.zeroed = false;
    opts.constraint = o.constraint.clone();
    opts.tolerances = o.tolerances;
    opts.params = None;
    opts.noise = noise.clone();
    opts.refine = Some(*refine);
    Ok(identify(m, model, c, &opts)?)
}

/// The values and standard uncertainties of `term` in `fit` (mm or rad; every owner's columns
/// in the campaign's column order).
pub(super) fn term_values(
    fit: &CampaignIdentification,
    term: &Term,
) -> (Vec<Option<f64>>, Vec<Option<f64>>) {
    let cols: Vec<usize> = (0..fit.layout.columns.len())
        .filter(|&j| fit.layout.columns[j].term == *term)
        .collect();
    (
        cols.iter().map(|&j| fit.fit.values[j]).collect(),
        cols.iter().map(|&j| fit.fit.std[j]).collect(),
    )
}

/// `Some(why)` when `e` is a refinement that did not converge (or diverged): a fit without a
/// result, which a candidate may cause and the diagnosis survives.
pub(super) fn not_converged(e: &DiagnoseError) -> Option<String> {
    match e {
        DiagnoseError::Refine(
            r @ (IdentifyError::NotConverged { .. } | IdentifyError::NotFinite { .. }),
        ) => Some(r.to_string()),
        _ => None,
    }
}

/// The fit of `base` plus `terms` (in order) by `fit`, and the terms dropped: when the fit with
/// every term does not converge, the terms are added one at a time and each one whose fit does
/// not converge is dropped with the reason. `base_fit` is the fit of `base` alone (the result
/// when every term is dropped).
///
/// # Errors
/// Any other failure of `fit`.
pub(super) fn fit_dropping(
    fit: &mut dyn FnMut(&Model) -> Result<CampaignIdentification, DiagnoseError>,
    base: &Model,
    terms: &[Term],
    base_fit: &CampaignIdentification,
) -> Result<(CampaignIdentification, Vec<Dropped>), DiagnoseError> {
    let with = |kept: &[Term]| {
        let mut model = base.clone();
        model.terms.extend_from_slice(kept);
        model
    };
    if terms.is_empty() {
        return Ok((base_fit.clone(), Vec::new()));
    }
    match fit(&with(terms)) {
        Ok(f) => return Ok((f, Vec::new())),
        Err(e) if not_converged(&e).is_some() => {}
        Err(e) => return Err(e),
    }
    let mut kept: Vec<Term> = Vec::new();
    let mut dropped = Vec::new();
    let mut last = None;
    for &t in terms {
        let mut trial = kept.clone();
        trial.push(t);
        match fit(&with(&trial)) {
            Ok(f) => {
                kept = trial;
                last = Some(f);
            }
            Err(e) => match not_converged(&e) {
                Some(why) => dropped.push(Dropped { term: t, why }),
                None => return Err(e),
            },
        }
    }
    Ok((last.unwrap_or_else(|| base_fit.clone()), dropped))
}

/// What the selection made: the findings in order (`chosen`, indices into `candidates`) and
/// each one's term with its scanned parameter refined (`refined`).
pub(super) struct Selected<'a> {
    /// The machine.
    pub m: &'a Machine,
    /// The options (the size budget).
    pub o: &'a DiagnoseOptions,
    /// The base model as given.
    pub base: &'a Model,
    /// The candidates.
    pub candidates: &'a [Term],
    /// The selection's steps.
    pub chosen: &'a [Chosen],
    /// Per step, the term and its refined scan.
    pub refined: &'a [(Term, Option<Scan>)],
}

/// The extension: the findings kept (with their values in the extended fit), those dropped,
/// the extended model's fit, and the plausible findings' candidates (their coarse grid values:
/// the spans the selection saw).
pub(super) struct Extension {
    /// The findings, in order.
    pub findings: Vec<Finding>,
    /// The findings dropped.
    pub dropped: Vec<Dropped>,
    /// The fit of the base model and the plausible findings.
    pub fit: CampaignIdentification,
    /// The candidates (indices) of the plausible findings.
    pub kept: Vec<usize>,
}

/// Every finding of `s` fitted together by `fit` (a finding whose fit does not converge is
/// dropped), each compared with the size budget; the implausible ones are then left out of the
/// extended model, which is fitted again. `base_fit` is the base model's fit.
///
/// # Errors
/// A fit that fails otherwise than by not converging.
pub(super) fn extend(
    s: &Selected,
    fit: &mut dyn FnMut(&Model) -> Result<CampaignIdentification, DiagnoseError>,
    base_fit: &CampaignIdentification,
) -> Result<Extension, DiagnoseError> {
    let Selected {
        m,
        o,
        base,
        candidates,
        chosen,
        refined,
    } = *s;
    let terms: Vec<Term> = refined.iter().map(|r| r.0).collect();
    let (all_fit, mut dropped) = fit_dropping(fit, base, &terms, base_fit)?;
    let kept_chosen: Vec<usize> = (0..chosen.len())
        .filter(|&k| !dropped.iter().any(|d| d.term == refined[k].0))
        .collect();
    let mut findings: Vec<Finding> = kept_chosen
        .iter()
        .map(|&k| {
            let c = &chosen[k];
            let (term, scan) = refined[k];
            let (values, stds) = term_values(&all_fit, &term);
            let known: Vec<f64> = values.iter().map(|v| v.unwrap_or(0.0)).collect();
            let (size, limit) = plausible::size_and_limit(m, &term, &known, &o.budget);
            Finding {
                term,
                description: term.describe(m),
                alternatives: c.alternatives.iter().map(|&a| candidates[a]).collect(),
                values,
                stds,
                size,
                limit,
                plausible: size <= limit,
                confirmation: None,
                in_model: size <= limit,
                scan,
                explained_fraction: c.fraction,
                f: c.f,
                p_value: c.p,
                correction: c.correction,
                candidates_tried: c.tried,
            }
        })
        .collect();
    let plausible: Vec<Term> = findings
        .iter()
        .filter(|f| f.plausible)
        .map(|f| f.term)
        .collect();
    let extended_fit = if plausible.len() == findings.len() {
        all_fit
    } else {
        let (e, more) = fit_dropping(fit, base, &plausible, base_fit)?;
        findings.retain(|f| !more.iter().any(|d| d.term == f.term));
        dropped.extend(more);
        for f in findings.iter_mut().filter(|f| f.plausible) {
            (f.values, f.stds) = term_values(&e, &f.term);
        }
        e
    };
    let kept = kept_chosen
        .iter()
        .filter(|&&k| {
            findings
                .iter()
                .any(|f| f.plausible && f.term == refined[k].0)
        })
        .map(|&k| chosen[k].index)
        .collect();
    Ok(Extension {
        findings,
        dropped,
        fit: extended_fit,
        kept,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use formats::truth::builtin_truth;
    use simulation::campaign::CampaignRecord;
    use simulation::paths::builtin_path;
    use simulation::readings::simulate;

    #[test]
    fn a_finding_whose_fit_does_not_converge_is_dropped_and_the_others_kept() {
        let m = model_spec::builtin("seed-ac").unwrap().unwrap();
        let mut t = builtin_truth("seed-ac-demo", &m).unwrap().unwrap();
        t.seed = 1;
        let record = simulate(&m, &t, &builtin_path(&m, "K4").unwrap().unwrap()).unwrap();
        let c = Campaign::new(vec![CampaignRecord::on_own_setup(&m, "k4", record)]).unwrap();
        let base = Model::of(&m, "reduced").unwrap();
        let o = DiagnoseOptions::default();
        let ecc2 = Term::parse(&m, "ECC@harmonic:2").unwrap();
        let eyc3 = Term::parse(&m, "EYC@harmonic:3").unwrap();
        let base_fit = fit(&m, &base, &c, &o, &NoiseChoice::Ordinary).unwrap();
        // A fit that "does not converge" whenever EYC harmonic:3 is in the model.
        let calls = std::cell::RefCell::new(Vec::new());
        let mut fake = |model: &Model| {
            calls.borrow_mut().push(model.terms.len());
            if model.terms.contains(&eyc3) {
                return Err(DiagnoseError::Refine(IdentifyError::NotConverged {
                    iterations: 8,
                    last_step_mm: 3e-6,
                    tolerance_mm: 1e-9,
                }));
            }
            fit(&m, model, &c, &o, &NoiseChoice::Ordinary)
        };
        let (f, dropped) = fit_dropping(&mut fake, &base, &[eyc3, ecc2], &base_fit).unwrap();
        assert_eq!(dropped.len(), 1);
        assert_eq!(dropped[0].term, eyc3);
        assert!(
            dropped[0].why.contains("did not converge"),
            "{}",
            dropped[0].why
        );
        assert!(f.model.terms.contains(&ecc2) && !f.model.terms.contains(&eyc3));
        // All together, then one at a time.
        assert_eq!(*calls.borrow(), vec![13, 12, 12]);
        // Every term dropped: the base fit.
        let (f, dropped) = fit_dropping(&mut fake, &base, &[eyc3], &base_fit).unwrap();
        assert_eq!(dropped.len(), 1);
        assert_eq!(f.fit.values, base_fit.fit.values);
        // Another error is an error.
        let mut failing = |_: &Model| -> Result<CampaignIdentification, DiagnoseError> {
            Err(DiagnoseError::Campaign("no".into()))
        };
        assert!(fit_dropping(&mut failing, &base, &[ecc2], &base_fit).is_err());
    }
}
