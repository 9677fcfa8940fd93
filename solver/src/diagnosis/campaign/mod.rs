//! The diagnosis of a campaign: the base model fitted on several records together (each with
//! its own kinematic parameters, set-up and zero, [`crate::fitting::campaign`]), what it lacks
//! found on all of them, the gain measured on held-out records (a held-out record on a new
//! set-up has its set-up errors, and its zero when zeroed, refitted with the machine's values
//! held).
//!
//! The procedure is the single record's ([`super::diagnose`]), with these differences:
//!
//! - the rows are every fitted record's, whitened record by record under the one noise model
//!   (estimated from every fitted record's residual and every clean held-out record's);
//! - a candidate is a term; its columns are those the campaign layout gives it: one set for a
//!   machine error, one per record for a drift of the R-test's zero (`dx0@time:1`), so that its
//!   F-test counts every column it adds. When a record is zeroed, the constant zero offsets are
//!   base columns (each zeroed record's own) and not candidates;
//! - outliers are found and left out record by record;
//! - scanned parameters (`period:P`, `step:V`, `exp:TAU`) keep the value of the grid they were
//!   selected at: the fine profile of [`super::profile`] is a single record's;
//! - the lack-of-fit test draws each fitted record's noise and fits it with that record's own
//!   columns of the extended design alone (a joint fit of the draws is not made): the draws'
//!   residuals are then a little smaller than the joint fit's, so the test errs towards "not
//!   down to the noise";
//! - the residual structure is that of the records one after the other.

mod heldout;

use super::adequacy;
use super::confounded::confounded_with;
use super::dictionary::dictionary;
use super::heldout::HeldOut;
use super::outliers::{self, Outlier};
use super::select::Span;
use super::{
    Confounded, DiagnoseError, DiagnoseOptions, Diagnosis, Finding, plausible, search, structure,
    unexplained, verdict,
};
use crate::fitting::IdentifyOptions;
use crate::fitting::campaign::design::{design_matrix, measurements};
use crate::fitting::campaign::{Campaign, CampaignIdentification, identify_campaign_refined};
use crate::fitting::noise::{self, NoiseChoice, NoiseModel, NoiseSource};
use crate::fitting::refine::RefineOptions;
use crate::fitting::with_offsets;
use crate::model::{Basis, Effect, Model, Term};
use crate::record::Record;
use heldout::{needed_groups, predict, rms_without};
use model_spec::{Dir, Machine};
use nalgebra::DVector;

/// One fitted record of a campaign diagnosis.
#[derive(Clone, Debug, PartialEq)]
pub struct CampaignRecordDiagnosis {
    /// Its label.
    pub label: String,
    /// Its set-up's label.
    pub setup: String,
    /// Its samples, outliers included.
    pub samples: usize,
    /// Its outliers (left out of every fit and test).
    pub outliers: Vec<Outlier>,
    /// Its residual RMS under the base model and under the extended one (mm, outliers left
    /// out).
    pub rms: (f64, f64),
}

/// What a campaign diagnosis adds to a [`Diagnosis`].
#[derive(Clone, Debug, PartialEq)]
pub struct CampaignPart {
    /// The fitted records.
    pub records: Vec<CampaignRecordDiagnosis>,
    /// Per held-out record: its set-up and whether it was fitted (else its set-up errors were
    /// refitted on it).
    pub held_out_setups: Vec<(String, bool)>,
}

/// The refined fit of `model` on `c` under `noise`.
fn fit(
    m: &Machine,
    model: &Model,
    c: &Campaign,
    o: &DiagnoseOptions,
    noise: &NoiseChoice,
) -> Result<CampaignIdentification, DiagnoseError> {
    let opts = IdentifyOptions {
        zeroed: false,
        constraint: o.constraint.clone(),
        tolerances: o.tolerances,
        params: None,
    };
    Ok(identify_campaign_refined(m, model, c, &opts, &RefineOptions::default(), noise)?.0)
}

/// The records one after the other as one record (times continued), for the residual
/// structure and the scanned candidates' grids.
fn concatenated(c: &Campaign) -> Record {
    let mut out = Record::default();
    let mut offset = 0.0;
    for r in &c.records {
        let (first, last) = match (r.record.samples.first(), r.record.samples.last()) {
            (Some(a), Some(b)) => (a.t, b.t),
            _ => continue,
        };
        for s in &r.record.samples {
            let mut s = s.clone();
            s.t = s.t - first + offset;
            out.samples.push(s);
        }
        out.measured.extend(r.record.measured.iter().copied());
        offset += last - first + 1.0;
    }
    out
}

/// The columns of `term` in `layout` order (every owner), for a finding's values.
fn term_columns(ident: &CampaignIdentification, term: &Term) -> Vec<usize> {
    (0..ident.layout.columns.len())
        .filter(|&j| ident.layout.columns[j].term == *term)
        .collect()
}

/// Diagnoses `base` on the records of `fitted`, checking the gain on the records of `held_out`
/// (see the module documentation). The records carry their zeroing and kinematic parameters:
/// `o.zeroed` and `o.params` are not used.
///
/// # Errors
/// As [`super::diagnose`].
pub fn diagnose_campaign(
    m: &Machine,
    base: &Model,
    fitted: &Campaign,
    held_out: &Campaign,
    o: &DiagnoseOptions,
) -> Result<(Diagnosis, CampaignPart), DiagnoseError> {
    for c in [fitted, held_out] {
        c.refuse_covariances("a diagnosis")
            .map_err(|e| DiagnoseError::Campaign(e.0))?;
    }
    let any_zeroed = fitted.records.iter().any(|r| r.zeroed);
    let base_given = base.clone();
    // The dictionary leaves out what the base model has; with zeroed records the constant zero
    // offsets are base columns.
    let base_terms = if any_zeroed {
        with_offsets(base)
    } else {
        base.clone()
    };
    let first = fit(m, base, fitted, o, &NoiseChoice::Ordinary)?;
    let fit_rms_with_outliers = first.fit.residual_rms();
    let mut record_outliers = Vec::with_capacity(fitted.records.len());
    let mut cleaned = fitted.clone();
    for (r, rec) in fitted.records.iter().enumerate() {
        let found = outliers::find_in(&rec.record, &first.record_residual(r));
        cleaned.records[r].record = rec.record.without(&outliers::samples(&found));
        record_outliers.push(found);
    }
    let base_fit = if record_outliers.iter().all(Vec::is_empty) {
        first
    } else {
        fit(m, base, &cleaned, o, &NoiseChoice::Ordinary)?
    };
    let before = predict(m, &base_fit, held_out)?;
    // The noise model: every fitted record's residual and every clean held-out residual.
    let sigma = base_fit
        .fit
        .sigma
        .filter(|s| *s > 0.0)
        .unwrap_or(noise::NOISE_FLOOR_MM);
    let (noise_model, estimated) = match &o.noise {
        NoiseChoice::Model(n) => (n.clone(), false),
        NoiseChoice::Ordinary => (NoiseModel::residual(sigma, "ordinary least squares"), false),
        NoiseChoice::Estimate => {
            let fitted_rows: Vec<Vec<[f64; 3]>> = (0..cleaned.records.len())
                .map(|r| base_fit.record_residual(r))
                .collect();
            let mut series: Vec<&[[f64; 3]]> = fitted_rows.iter().map(Vec::as_slice).collect();
            for (rec, v) in held_out.records.iter().zip(&before) {
                if outliers::find_in(&rec.record, &v.residual).is_empty() {
                    series.push(&v.residual);
                }
            }
            match adequacy::estimate_records(&series) {
                Ok(model) => (model, true),
                Err(e) => (
                    NoiseModel::residual(sigma, format!("the noise cannot be estimated: {e}")),
                    false,
                ),
            }
        }
    };
    let gls = match noise_model.source {
        NoiseSource::Residual { .. } => NoiseChoice::Ordinary,
        _ => NoiseChoice::Model(noise_model.clone()),
    };
    let (base_fit, before) = if gls == NoiseChoice::Ordinary {
        (base_fit, before)
    } else {
        let f = fit(m, base, &cleaned, o, &gls)?;
        let b = predict(m, &f, held_out)?;
        (f, b)
    };

    // The candidates and the design of the base model with all of them.
    let whole = concatenated(&cleaned);
    let mut candidates = dictionary(m, &base_terms.terms, &o.dictionary);
    candidates.extend(super::dictionary::scanned(
        m,
        &base_terms.terms,
        &whole,
        &o.dictionary,
    ));
    let mut all = base.clone();
    all.terms.extend(candidates.iter().copied());
    let design = design_matrix(m, &all, &cleaned)?;
    let mut y = measurements(&cleaned)?;
    let mut h_raw = design.h.clone();
    // Instrument candidates: the displacement from the base model's prediction, not from the
    // readings (as for one record).
    let predicted = &y - &base_fit.fit.residual;
    for (j, c) in design.layout.columns.iter().enumerate() {
        if let Effect::Instrument {
            reading,
            displacement,
        } = c.term.effect
        {
            let mut col = h_raw.column_mut(j);
            col.fill(0.0);
            for i in 0..predicted.len() / 3 {
                col[3 * i + reading.index()] = predicted[3 * i + displacement.index()];
            }
        }
    }
    // Groups: base terms (and the zeroed records' zero offsets), then one per candidate.
    let mut group_terms: Vec<Term> = base.terms.clone();
    if any_zeroed {
        for d in Dir::ALL {
            let t = Term {
                effect: Effect::SensorOffset(d),
                basis: Basis::Const,
            };
            if !group_terms.contains(&t) {
                group_terms.push(t);
            }
        }
    }
    let nb = group_terms.len();
    group_terms.extend(candidates.iter().copied());
    let group_columns: Vec<Vec<usize>> = group_terms
        .iter()
        .map(|t| {
            (0..design.layout.columns.len())
                .filter(|&j| design.layout.columns[j].term == *t)
                .collect()
        })
        .collect();
    let order: Vec<usize> = group_columns.iter().flatten().copied().collect();
    let h_raw = h_raw.select_columns(&order);
    let widths: Vec<usize> = group_columns.iter().map(Vec::len).collect();
    let starts: Vec<usize> = widths
        .iter()
        .scan(0, |s, &w| {
            let a = *s;
            *s += w;
            Some(a)
        })
        .collect();
    let whitening = if estimated {
        super::noise_model::conservative(&noise_model)
    } else {
        noise_model.clone()
    };
    let mut h_all = h_raw.clone();
    whitening.whiten(&design.rows, &mut h_all, &mut y)?;
    let n = y.len();
    let group = |t: usize| h_all.columns(starts[t], widths[t]).into_owned();
    let rss_base = Span::of_groups(n, 0..nb, &group)
        .project_out(&y)
        .norm_squared();
    let unexcited: Vec<Term> = (0..candidates.len())
        .filter(|&c| {
            h_raw
                .columns(starts[nb + c], widths[nb + c])
                .iter()
                .all(|v| v.abs() < 1e-15)
        })
        .map(|c| candidates[c])
        .collect();
    let live: Vec<usize> = (0..candidates.len())
        .filter(|&c| !unexcited.contains(&candidates[c]))
        .collect();
    let problem = search::Problem {
        m,
        candidates: &candidates,
        nb,
        group: &group,
        y: &y,
        rss_base,
        live: &live,
        o,
        progress: &crate::io::progress::Unwatched,
    };
    let (chosen, stop) = search::select(&problem);

    // Every finding fitted together; the implausible ones are then left out.
    let mut with_all = base.clone();
    with_all
        .terms
        .extend(chosen.iter().map(|c| candidates[c.index]));
    let all_fit = fit(m, &with_all, &cleaned, o, &gls)?;
    let values_of = |f: &CampaignIdentification, t: &Term| {
        let cols = term_columns(f, t);
        (
            cols.iter().map(|&j| f.fit.values[j]).collect::<Vec<_>>(),
            cols.iter().map(|&j| f.fit.std[j]).collect::<Vec<_>>(),
        )
    };
    let mut findings: Vec<Finding> = chosen
        .iter()
        .map(|c| {
            let term = candidates[c.index];
            let (values, stds) = values_of(&all_fit, &term);
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
                scan: None,
                explained_fraction: c.fraction,
                f: c.f,
                p_value: c.p,
                correction: c.correction,
                candidates_tried: c.tried,
            }
        })
        .collect();
    let mut extended = base.clone();
    extended
        .terms
        .extend(findings.iter().filter(|f| f.plausible).map(|f| f.term));
    let extended_fit = if extended.terms.len() == with_all.terms.len() {
        all_fit
    } else {
        let e = fit(m, &extended, &cleaned, o, &gls)?;
        for f in findings.iter_mut().filter(|f| f.plausible) {
            (f.values, f.stds) = values_of(&e, &f.term);
        }
        e
    };
    let kept: Vec<usize> = chosen
        .iter()
        .zip(&findings)
        .filter(|(_, f)| f.plausible)
        .map(|(c, _)| c.index)
        .collect();
    let mut as_candidates = Model {
        terms: group_terms[..nb].to_vec(),
    };
    as_candidates
        .terms
        .extend(kept.iter().map(|&c| candidates[c]));
    let confounded: Vec<Confounded> = confounded_with(
        &as_candidates,
        &candidates,
        &kept,
        &unexcited,
        &Span::of_groups(n, (0..nb).chain(kept.iter().map(|&c| nb + c)), &group),
        &|t| group(t),
        nb,
        &h_all,
        &starts,
        &widths,
    );

    // The gain on every held-out record.
    let after = predict(m, &extended_fit, held_out)?;
    let mut validation = Vec::with_capacity(held_out.records.len());
    for ((rec, b), a) in held_out.records.iter().zip(&before).zip(&after) {
        let out = outliers::find_in(&rec.record, &b.residual);
        let drop = outliers::samples(&out);
        validation.push(HeldOut {
            name: rec.label.clone(),
            readings: 3 * (rec.record.samples.len() - drop.len()),
            before_rms: rms_without(&b.residual, &drop),
            after_rms: rms_without(&a.residual, &drop),
            residual_after: a.residual.clone(),
            residual_before: b.residual.clone(),
            outliers: out,
            undetermined_before: needed_groups(m, &base_fit, rec)?,
            undetermined_after: needed_groups(m, &extended_fit, rec)?,
        });
    }
    // Lack of fit against the noise, record by record.
    let adequacy = match &noise_model.source {
        NoiseSource::Residual { why } => Err(why.clone()),
        _ if o.adequacy_draws == 0 => Err("not asked for (no bootstrap draws)".into()),
        _ => {
            let ext_design = design_matrix(m, &extended, &cleaned)?;
            let mut residuals_fitted = Vec::new();
            let mut blocks = Vec::new();
            let mut at = 0;
            for (r, rc) in ext_design.layout.records.iter().enumerate() {
                let rows = 3 * rc.samples;
                let mut cols = rc.columns.clone();
                cols.sort_unstable();
                cols.dedup();
                blocks.push(
                    ext_design
                        .h
                        .rows(at, rows)
                        .into_owned()
                        .select_columns(&cols),
                );
                residuals_fitted.push(DVector::from_vec(
                    extended_fit
                        .record_residual(r)
                        .into_iter()
                        .flatten()
                        .collect(),
                ));
                at += rows;
            }
            let held: Vec<DVector<f64>> = validation
                .iter()
                .map(HeldOut::residual_after_without_outliers)
                .collect();
            let mut residuals: Vec<adequacy::Residual> = cleaned
                .records
                .iter()
                .enumerate()
                .map(|(r, rec)| adequacy::Residual {
                    name: &rec.label,
                    residual: &residuals_fitted[r],
                    fitted: Some(&blocks[r]),
                    predicted: None,
                    zeroed: false,
                })
                .collect();
            residuals.extend(
                validation
                    .iter()
                    .zip(&held)
                    .map(|(h, r)| adequacy::Residual {
                        name: &h.name,
                        residual: r,
                        fitted: None,
                        predicted: None,
                        zeroed: false,
                    }),
            );
            adequacy::adequacy(
                &whitening,
                estimated,
                &residuals,
                o.alpha,
                o.seed,
                o.adequacy_draws,
            )
            .map_err(|e| e.to_string())
        }
    };
    let unexplained = match &adequacy {
        Ok(a) => {
            let mut records: Vec<(&str, &Record, Vec<[f64; 3]>)> = cleaned
                .records
                .iter()
                .enumerate()
                .map(|(r, rec)| {
                    (
                        rec.label.as_str(),
                        &rec.record,
                        extended_fit.record_residual(r),
                    )
                })
                .collect();
            records.extend(
                validation
                    .iter()
                    .zip(&held_out.records)
                    .map(|(h, rec)| (h.name.as_str(), &rec.record, h.residual_after.clone())),
            );
            unexplained::describe_failures(m, a, &records, o.alpha)
        }
        Err(_) => Vec::new(),
    };
    let rows = n.max(1) as f64;
    let fit_rms = (
        (base_fit.fit.rss / rows).sqrt(),
        (extended_fit.fit.rss / rows).sqrt(),
    );
    let verdict_noise = adequacy.as_ref().ok().map(|a| {
        let mut nm = whitening.clone();
        if let Some(r) = a.records.first() {
            nm.sigma_mm = r.noise_sigma_mm;
        }
        nm
    });
    let consistent = adequacy.as_ref().ok().map(|a| a.consistent_with_noise);
    let recommendation =
        verdict::recommend(&findings, &validation, verdict_noise.as_ref(), consistent);
    let (k, p, t) = (o.dictionary.harmonics, o.dictionary.poly, o.dictionary.time);
    let flat = |f: &CampaignIdentification| -> Vec<[f64; 3]> {
        (0..cleaned.records.len())
            .flat_map(|r| f.record_residual(r))
            .collect()
    };
    let part = CampaignPart {
        records: cleaned
            .records
            .iter()
            .enumerate()
            .map(|(r, rec)| CampaignRecordDiagnosis {
                label: rec.label.clone(),
                setup: rec.setup.clone(),
                samples: fitted.records[r].record.samples.len(),
                outliers: record_outliers[r].clone(),
                rms: (
                    base_fit.records[r].residual_rms(),
                    extended_fit.records[r].residual_rms(),
                ),
            })
            .collect(),
        held_out_setups: held_out
            .records
            .iter()
            .map(|r| (r.setup.clone(), base_fit.layout.setups.contains(&r.setup)))
            .collect(),
    };
    let diagnosis = Diagnosis {
        structure_before: structure::analyse(m, &whole, &flat(&base_fit), k, p, t),
        structure_after: structure::analyse(m, &whole, &flat(&extended_fit), k, p, t),
        fit_rms,
        fit_rms_with_outliers,
        outliers: Vec::new(),
        base_given,
        base: base_terms,
        base_fit: base_fit.as_identification(),
        dictionary_size: candidates.len(),
        findings,
        confounded,
        unexcited,
        stop,
        extended,
        extended_fit: extended_fit.as_identification(),
        validation,
        recommendation,
        noise: noise_model,
        adequacy,
        unexplained,
    };
    Ok((diagnosis, part))
}
