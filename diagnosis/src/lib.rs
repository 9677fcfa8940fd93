//! Diagnosis: where the model and the measurement disagree, which missing effect explains it,
//! the model extended with it, and the gain measured on data that were not fitted.
//!
//! The fitted records and the held-out records are each a [`Campaign`]: a single record is the
//! campaign of that record, and every stage below is the campaign's (docs/diagnosis.md).
//!
//! 1. Fit the base model on the fitted records together ([`fitting::campaign`]: the
//!    machine's errors shared, each record with its own kinematic parameters, its set-up's
//!    errors and its own zero); find the outliers of every record ([`outliers`]) and leave them
//!    out; choose the noise model with the held-out residuals (`noise_model.rs`).
//! 2. Build the candidate dictionary ([`mod@dictionary`]): every term of the topology the model
//!    lacks, each a group of the campaign's columns (one set for a machine error, one column
//!    per record for a drift of the R-test's zero, one per set-up for a set-up error).
//! 3. Forward selection ([`select`]): add the candidate that explains most of what is left,
//!    if it is significant (F-test against the noise, corrected for the number of candidates
//!    tried); refuse candidates the model spans and report them with what they are confounded
//!    with; stop when nothing significant remains. Naming: among candidates of one span, the
//!    one with the fewest parameters, then an error of an axis line, then the smallest change;
//!    a narrower candidate inside the chosen one's span when the data do not need the chosen
//!    one's extra directions (parsimony); and the candidates the data cannot tell from it, as
//!    its alternatives. Then an exchange pass: each finding is selected again given all the
//!    others (renamed, or dropped when no longer significant), and the selection goes on while
//!    that changes something. A scanned parameter is refined on a fine grid ([`profile`]).
//! 4. Refit the extended model (refined against the exact machine; a finding whose refinement
//!    does not converge is dropped with a note, [`Dropped`]), and measure the residual RMS
//!    before and after on every fitted record and every held-out record ([`heldout`]: a
//!    held-out record on a set-up that was not fitted has its set-up errors refitted on it, and
//!    its own zero and drifts always are).
//! 5. The lack-of-fit test of what remains against the noise ([`adequacy`]), what remains
//!    described ([`unexplained`]), and the verdict ([`verdict`]).
//! 6. Position against time ([`separable`]): a finding that is an error of an axis's position
//!    or a term of time, and a candidate of the other kind that the fitted records cannot tell
//!    from it (the axis moving monotonically in time), reported with the test that separates
//!    them.
//!
//! The modules, beside those named above: [`confirm`] (each finding confirmed by records that
//! were not fitted), `extend` (the refined fits of the base and extended models), [`figures`]
//! (the diagnosis figures' data), [`groups`] (sets of errors tested as one), [`harmonic`]
//! (a harmonic finding as amplitude and phase), [`hidden`] (what a model lacks by a known
//! truth, for simulations), `jump` (a jump in time on a record described), `lack_of_fit`
//! (the test of what remains on every record), `options` ([`DiagnoseOptions`]), `outcome`
//! (what a diagnosis finds: [`Diagnosis`]), `parallel` (independent work on every core, results
//! in order), [`plausible`] (a finding named only at a size a machine can have), `projected`
//! (the candidates with the model's span projected out), `search` (the selection with its
//! exchange pass), [`structure`] (a residual's structure per direction), [`tones`] (periodic
//! disturbances in time), `weights` (per-sample weights of records read through an
//! instrument), `columns` (the design matrices the selection works on), `confounded` (what the
//! data cannot see apart) and `noise_model` (where the noise model comes from).
//!
//! It builds on [`simulation`], [`formats`] (progress of long reads) and [`fitting`]; the
//! compensation and the reports build on it.

#![warn(missing_docs)]

pub mod adequacy;
mod columns;
pub mod confirm;
mod confounded;
pub mod dictionary;
mod extend;
pub mod figures;
pub mod groups;
pub mod harmonic;
pub mod heldout;
pub mod hidden;
mod jump;
mod lack_of_fit;
mod noise_model;
mod options;
mod outcome;
pub mod outliers;
mod parallel;
pub mod plausible;
pub mod profile;
mod projected;
mod search;
pub mod select;
pub mod separable;
pub mod structure;
pub mod tones;
pub mod unexplained;
pub mod verdict;
mod weights;

use confounded::confounded_with;
use dictionary::dictionary;
use fitting::campaign::CampaignIdentification;
use fitting::hmatrix::HMatrixError;
use fitting::noise::{NoiseChoice, NoiseError, NoiseSource};
use fitting::refine::IdentifyError;
use fitting::validate::ValidateError;
use fitting::{EstimateError, with_offsets};
use formats::progress::Progress;
use model_spec::Machine;
use model_spec::terms::Term;
pub use options::DiagnoseOptions;
use outcome::recommend;
pub use outcome::{Confounded, Correction, Diagnosis, Dropped, Finding, RecordDiagnosis, Stop};
use select::Span;
pub use separable::PositionOrTime;
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::model::Model;
use simulation::record::Record;
use std::borrow::Cow;

/// Why a diagnosis could not be made.
#[derive(Debug, thiserror::Error)]
pub enum DiagnoseError {
    /// The H matrix could not be built.
    #[error(transparent)]
    HMatrix(#[from] HMatrixError),
    /// A fit failed.
    #[error(transparent)]
    Estimate(#[from] EstimateError),
    /// The refinement failed.
    #[error(transparent)]
    Refine(#[from] IdentifyError),
    /// A validation failed.
    #[error(transparent)]
    Validate(#[from] ValidateError),
    /// The noise model cannot whiten the readings.
    #[error("noise model: {0}")]
    Noise(#[from] NoiseError),
    /// The campaign cannot be diagnosed as given.
    #[error("{0}")]
    Campaign(String),
}

/// The stages of a diagnosis, in order, as [`diagnose`] reports them.
pub const STAGES: [&str; 7] = [
    "base fit",
    "noise model",
    "candidates' columns",
    "selection",
    "extended fit",
    "held-out records",
    "lack of fit",
];

/// The campaigns of a single record `record` labelled `label` (at kinematic parameters
/// `params`, mm; zeroed or not) and of the records `held_out` (name, record) measured on its
/// set-up, the ball not moved: what [`diagnose`] takes for the diagnosis of one record.
///
/// # Errors
/// [`DiagnoseError::Campaign`] for a label that is not one (letters, digits and `- _ . + :`)
/// or given twice.
pub fn one_record(
    label: &str,
    record: Record,
    held_out: Vec<(String, Record)>,
    params: Vec<f64>,
    zeroed: bool,
) -> Result<(Campaign, Campaign), DiagnoseError> {
    let fitted = Campaign::new(vec![CampaignRecord::new(
        label,
        record,
        params.clone(),
        label,
        zeroed,
    )])
    .map_err(|e| DiagnoseError::Campaign(e.0))?;
    let held: Vec<CampaignRecord> = held_out
        .into_iter()
        .map(|(name, r)| CampaignRecord::new(name, r, params.clone(), label, zeroed))
        .collect();
    let held = if held.is_empty() {
        Campaign { records: held }
    } else {
        Campaign::new(held).map_err(|e| DiagnoseError::Campaign(e.0))?
    };
    check_held_out(&fitted, &held)?;
    Ok((fitted, held))
}

/// Refuses held-out records that bear a fitted record's label (a held-out record is not
/// fitted).
fn check_held_out(fitted: &Campaign, held: &Campaign) -> Result<(), DiagnoseError> {
    if let Some(r) = held
        .records
        .iter()
        .find(|r| fitted.records.iter().any(|f| f.label == r.label))
    {
        return Err(DiagnoseError::Campaign(format!(
            "held-out record `{}` has the label of a fitted record: a held-out record is not fitted (rename one)",
            r.label
        )));
    }
    Ok(())
}

/// The records of `c` one after the other as one record (times continued), for the residual
/// structure and the scanned candidates' grids: the record itself for a campaign of one.
fn joined(c: &Campaign) -> Cow<'_, Record> {
    if let [only] = c.records.as_slice() {
        return Cow::Borrowed(&only.record);
    }
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
    Cow::Owned(out)
}

/// The sample times of every record of `c`, each on its own clock (s), sorted: the instants a
/// jump is scanned over.
fn own_times(c: &Campaign) -> Vec<f64> {
    let mut t: Vec<f64> = c
        .records
        .iter()
        .flat_map(|r| r.record.samples.iter().map(|s| s.t))
        .collect();
    t.sort_by(f64::total_cmp);
    t
}

/// The residuals of every record of `fit`, one after the other (mm, one `[x, y, z]` per sample).
fn flat_residual(fit: &CampaignIdentification) -> Vec<[f64; 3]> {
    (0..fit.records.len())
        .flat_map(|r| fit.record_residual(r))
        .collect()
}

/// Diagnoses `base` on the records of `fitted`, checking the gain on the records of `held_out`
/// (see the module documentation), telling `progress` where it is: `diagnosis` with the number
/// of [`STAGES`] begun (done of total), and within the selection every candidate scored
/// (`selection`, done of the candidates of the step; each step starts again from 0). The
/// records carry their zeroing, set-ups and kinematic parameters.
///
/// # Errors
/// A campaign that does not fit `m`; the base model's fit failing (its refinement not
/// converging included: without it there is nothing to diagnose); a noise model that cannot
/// whiten; a held-out prediction that cannot be made. A finding whose extended fit does not
/// converge is no error: it is dropped ([`Diagnosis::dropped`]).
pub fn diagnose(
    m: &Machine,
    base: &Model,
    fitted: &Campaign,
    held_out: &Campaign,
    o: &DiagnoseOptions,
    progress: &dyn Progress,
) -> Result<Diagnosis, DiagnoseError> {
    let stage = |k: usize| progress.update("diagnosis", k as u64, STAGES.len() as u64);
    stage(0);
    fitted.check(m).map_err(|e| DiagnoseError::Campaign(e.0))?;
    if !held_out.records.is_empty() {
        held_out
            .check(m)
            .map_err(|e| DiagnoseError::Campaign(e.0))?;
    }
    check_held_out(fitted, held_out)?;
    let base_given = base.clone();
    // The dictionary leaves out what the base model has; with zeroed records the constant zero
    // offsets are base columns (each zeroed record's own).
    let base_terms = if fitted.records.iter().any(|r| r.zeroed) {
        with_offsets(base)
    } else {
        base.clone()
    };
    let mut candidates = dictionary(m, &base_terms.terms, &o.dictionary);
    candidates.extend(dictionary::scanned(
        m,
        &base_terms.terms,
        &joined(fitted),
        &o.dictionary,
    ));
    // A touch probe's records: no candidate they cannot carry (a linear axis's reversal, a
    // servo lag), and the probe's lobing among the candidates when every record is a probe's.
    if fitted.records.iter().any(|r| !r.record.probe.is_empty()) {
        candidates.retain(|t| fitting::hmatrix::probe_term(m, t).is_ok());
        let lobing = Term {
            effect: simulation::model::Effect::PreTravel,
            basis: simulation::model::Basis::Harmonic(3),
        };
        if fitted.records.iter().all(|r| !r.record.probe.is_empty())
            && !base_terms.terms.contains(&lobing)
        {
            candidates.push(lobing);
        }
    }
    // A jump in time where one record is fitted (`dictionary::jumps`).
    if let [one] = fitted.records.as_slice() {
        let times: Vec<f64> = one.record.samples.iter().map(|s| s.t).collect();
        candidates.extend(dictionary::jumps(
            m,
            &base_terms.terms,
            &times,
            &o.dictionary,
        ));
    }

    // Outliers of every fitted record, from the base fit's residual: everything after works
    // without their samples.
    let first = extend::fit(m, base, fitted, o, &NoiseChoice::Ordinary)?;
    let fit_rms_with_outliers = first.fit.residual_rms();
    let mut record_outliers = Vec::with_capacity(fitted.records.len());
    let mut cleaned = fitted.clone();
    for (r, rec) in fitted.records.iter().enumerate() {
        let found = outliers::find_in(&rec.record, &first.record_residual(r));
        if !found.is_empty() {
            cleaned.records[r].record = rec.record.without(&outliers::samples(&found));
        }
        record_outliers.push(found);
    }
    let base_fit = if record_outliers.iter().all(Vec::is_empty) {
        first
    } else {
        extend::fit(m, base, &cleaned, o, &NoiseChoice::Ordinary)?
    };
    let weights = weights::Weights::of(&cleaned, held_out, &o.noise)?;

    stage(1);
    // The noise model, from every fitted record's residual and every clean held-out residual;
    // every fit from here on is the generalized least-squares fit under it.
    let before = heldout::predict(m, &base_fit, held_out)?;
    let mut series = weights.fitted_rows(&base_fit)?;
    for (rec, v) in held_out.records.iter().zip(&before) {
        if outliers::find_in(&rec.record, &v.validation.residual).is_empty() {
            series.push(weights.held_rows(&rec.record, &v.validation.residual)?);
        }
    }
    let refs: Vec<&[[f64; 3]]> = series.iter().map(Vec::as_slice).collect();
    let (noise, estimated) = noise_model::choose(&o.noise, base_fit.fit.sigma, &refs);
    let gls = match noise.source {
        NoiseSource::Residual { .. } => NoiseChoice::Ordinary,
        _ => NoiseChoice::Model(noise.clone()),
    };
    let (base_fit, before) = if gls == NoiseChoice::Ordinary {
        (base_fit, before)
    } else {
        let f = extend::fit(m, base, &cleaned, o, &gls)?;
        let b = heldout::predict(m, &f, held_out)?;
        (f, b)
    };
    // The selection whitens with φ raised when the noise was estimated.
    let whitening = if estimated {
        noise_model::conservative(&noise)
    } else {
        noise.clone()
    };

    stage(2);
    let cols = columns::Columns::new(
        m,
        base,
        &candidates,
        &cleaned,
        &base_fit,
        &weights,
        &whitening,
    )?;
    let nb = cols.nb;
    let group = |t: usize| cols.group(t);
    let n = cols.y.len();
    let rss_base = Span::of_groups(n, 0..nb, &group)
        .project_out(&cols.y)
        .norm_squared();
    let unexcited: Vec<Term> = (0..candidates.len())
        .filter(|&c| cols.unexcited(nb + c))
        .map(|c| candidates[c])
        .collect();
    let live: Vec<usize> = (0..candidates.len())
        .filter(|&c| !unexcited.contains(&candidates[c]))
        .collect();
    // A scanned candidate's parameter refined on a fine grid given a model, in the selection
    // (after each step) and after it (with every other finding in place).
    let grid_record = joined(&cleaned);
    let grid = profile::Grid {
        record: &grid_record,
        times: &own_times(&cleaned),
    };
    let term_columns = |t: Term| cols.term_columns(m, t, &cleaned, &weights, &whitening);
    let refine_step = |c: usize, q: &Span| -> Option<search::Refined> {
        let mut columns = term_columns;
        let (term, scan) =
            profile::refine(m, candidates[c], &grid, &mut columns, q, &cols.y).ok()??;
        let columns = term_columns(term).ok()?;
        Some(search::Refined {
            term,
            scan,
            columns,
        })
    };
    let problem = search::Problem {
        m,
        candidates: &candidates,
        nb,
        group: &group,
        y: &cols.y,
        rss_base,
        live: &live,
        o,
        progress,
        refine: &refine_step,
    };
    stage(3);
    let (chosen, stop) = search::select(&problem);
    // A scanned parameter refined again, with every other finding in place.
    let mut refined = Vec::with_capacity(chosen.len());
    for k in 0..chosen.len() {
        let q = search::basis_of(&problem, &chosen, Some(k));
        let coarse = candidates[chosen[k].index];
        let mut columns = |t: Term| cols.term_columns(m, t, &cleaned, &weights, &whitening);
        refined.push(
            match profile::refine(m, coarse, &grid, &mut columns, &q, &cols.y)? {
                Some((t, scan)) => (t, Some(scan)),
                None => chosen[k]
                    .refined
                    .as_ref()
                    .map_or((coarse, None), |r| (r.term, Some(r.scan))),
            },
        );
    }

    stage(4);
    let mut fit_model = |model: &Model| extend::fit(m, model, &cleaned, o, &gls);
    let extend::Extension {
        mut findings,
        mut dropped,
        fit: mut extended_fit,
        kept,
    } = extend::extend(
        &extend::Selected {
            m,
            o,
            base,
            candidates: &candidates,
            chosen: &chosen,
            refined: &refined,
        },
        &mut fit_model,
        &base_fit,
    )?;
    // Each finding confirmed on its own by the held-out records (or every fitted record left
    // out in turn); the extended model holds the confirmed ones.
    let selected: Vec<(Term, usize)> = findings
        .iter()
        .filter(|f| f.plausible)
        .map(|f| f.term)
        .zip(kept.iter().copied())
        .collect();
    let all: Vec<Term> = selected.iter().map(|s| s.0).collect();
    let mut left_out = Vec::new();
    let mut group_findings: Vec<groups::GroupFinding> = Vec::new();
    if let Some(mut folds) = confirm::Folds::new(m, o, &gls, base, &cleaned, held_out, &base_fit)? {
        folds.seed(&all, &extended_fit)?;
        let terms = confirm::confirm(&mut folds, &mut findings, &whitening)?;
        for f in findings.iter_mut() {
            f.in_model = terms.contains(&f.term);
        }
        if terms != all {
            let (e, more) = match folds.whole(&terms) {
                Some(e) => (e, Vec::new()),
                None => extend::fit_dropping(&mut fit_model, base, &terms, &base_fit)?,
            };
            findings.retain(|f| !more.iter().any(|d| d.term == f.term));
            dropped.extend(more);
            extended_fit = e;
        }
        if o.groups {
            let (found, fit) = groups::grouped(
                &groups::Grouped {
                    m,
                    o,
                    base,
                    candidates: &candidates,
                    live: &live,
                    cols: &cols,
                    group: &group,
                    rss_base,
                    terms: &extended_terms_of(&findings),
                    cleaned: &cleaned,
                    gls: &gls,
                    whitening: &whitening,
                    weights: &weights,
                },
                &mut folds,
            )?;
            if let Some(fit) = fit {
                extended_fit = fit;
            }
            group_findings = found;
        }
        for f in findings.iter_mut().filter(|f| f.in_model) {
            (f.values, f.stds) = extend::term_values(&extended_fit, &f.term);
            let known: Vec<f64> = f.values.iter().map(|v| v.unwrap_or(0.0)).collect();
            (f.size, f.limit) = plausible::size_and_limit(m, &f.term, &known, &o.budget);
        }
        let mut terms = extended_terms_of(&findings);
        terms.extend(groups::group_terms(&group_findings));
        left_out = folds.left_out_rows(&terms)?;
    }
    // The candidates of the findings in the extended model (a finding chosen among the
    // alternatives by the held-out records is that candidate).
    let kept: Vec<usize> = findings
        .iter()
        .filter(|f| f.in_model)
        .filter_map(|f| match f.confirmation.as_ref().and_then(|c| c.replaces) {
            Some(_) => candidates.iter().position(|&c| c == f.term),
            None => selected.iter().find(|s| s.0 == f.term).map(|s| s.1),
        })
        .collect();
    let mut kept = kept;
    kept.extend(
        groups::group_terms(&group_findings)
            .iter()
            .filter_map(|t| candidates.iter().position(|c| c == t)),
    );
    let mut extended = base.clone();
    extended.terms.extend(extended_terms_of(&findings));
    extended.terms.extend(groups::group_terms(&group_findings));

    // The extended model's findings as candidates (their coarse grid values: the spans the
    // selection saw).
    let mut as_candidates = Model {
        terms: cols.terms[..nb].to_vec(),
    };
    as_candidates
        .terms
        .extend(kept.iter().map(|&c| candidates[c]));
    let confounded = confounded_with(
        &as_candidates,
        &candidates,
        &kept,
        &unexcited,
        &Span::of_groups(n, (0..nb).chain(kept.iter().map(|&c| nb + c)), &group),
        &|t| group(t),
        &cols,
    );

    stage(5);
    let validation = heldout::held_out_gain(m, &base_fit, &before, &extended_fit, held_out)?;
    stage(6);
    // Lack of fit of the extended model against the noise on every record, and what remains
    // where it fails, described.
    let groups: Vec<usize> = (0..nb).chain(kept.iter().map(|&c| nb + c)).collect();
    let (adequacy, unexplained) = lack_of_fit::test(&lack_of_fit::Inputs {
        m,
        o,
        noise: &noise,
        whitening: &whitening,
        estimated,
        cols: &cols,
        groups: &groups,
        as_candidates: &as_candidates,
        cleaned: &cleaned,
        base_fit: &base_fit,
        extended_fit: &extended_fit,
        held_out,
        validation: &validation,
        weights: &weights,
    })?;
    // A position error of an axis and a drift in time that these records cannot tell apart.
    let found: Vec<(Term, usize, Vec<Term>)> = findings
        .iter()
        .filter_map(|f| {
            let k = refined.iter().position(|r| r.0 == f.term)?;
            Some((f.term, chosen[k].index, f.alternatives.clone()))
        })
        .collect();
    let position_or_time = separable::find(&separable::Inputs {
        m,
        cols: &cols,
        candidates: &candidates,
        live: &live,
        findings: &found,
        model: &groups,
        records: &cleaned,
        alpha: o.alpha,
    });
    separable::name_alternatives(&mut findings, &position_or_time);
    let rows = n.max(1) as f64;
    let fit_rms = (
        (base_fit.fit.rss / rows).sqrt(),
        (extended_fit.fit.rss / rows).sqrt(),
    );
    let judging = if validation.is_empty() {
        &left_out
    } else {
        &validation
    };
    let labels: Vec<String> = judging.iter().map(|h| h.name.clone()).collect();
    let recommendation = recommend(&findings, judging, &adequacy, &labels);
    let (k, p, t) = (o.dictionary.harmonics, o.dictionary.poly, o.dictionary.time);
    let records = cleaned
        .records
        .iter()
        .enumerate()
        .map(|(r, rec)| RecordDiagnosis {
            label: rec.label.clone(),
            setup: rec.setup.clone(),
            samples: fitted.records[r].record.samples.len(),
            zeroed: rec.zeroed,
            params: rec.params.clone(),
            outliers: record_outliers[r].clone(),
            rms: (
                base_fit.records[r].residual_rms(),
                extended_fit.records[r].residual_rms(),
            ),
        })
        .collect();
    Ok(Diagnosis {
        structure_before: structure::analyse(m, &grid_record, &flat_residual(&base_fit), k, p, t),
        structure_after: structure::analyse(
            m,
            &grid_record,
            &flat_residual(&extended_fit),
            k,
            p,
            t,
        ),
        records,
        fit_rms,
        fit_rms_with_outliers,
        base_given,
        base: base_terms,
        base_fit,
        dictionary_size: candidates.len(),
        findings,
        groups: group_findings,
        dropped,
        confounded,
        unexcited,
        stop,
        extended,
        extended_fit,
        validation,
        left_out,
        recommendation,
        noise,
        adequacy,
        unexplained,
        position_or_time,
    })
}

/// The terms the findings in the extended model add, in order.
fn extended_terms_of(findings: &[Finding]) -> Vec<Term> {
    findings
        .iter()
        .filter(|f| f.in_model)
        .map(|f| f.term)
        .collect()
}
