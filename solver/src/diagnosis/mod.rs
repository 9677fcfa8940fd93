//! Diagnosis: where the model and the measurement disagree, which missing effect explains it,
//! the model extended with it, and the gain measured on data that were not fitted.
//!
//! 1. Fit the base model; analyse the structure of its residual ([`structure`]).
//! 2. Build the candidate dictionary ([`mod@dictionary`]): every term of the topology the model
//!    lacks.
//! 3. Forward selection ([`select`]): add the candidate that explains most of what is left,
//!    if it is significant (F-test against the noise, corrected for the number of candidates
//!    tried); refuse candidates the model spans and report them with what they are confounded
//!    with; stop when nothing significant remains. Naming: among candidates of one span, the
//!    one with the fewest parameters, then an error of an axis line, then the smallest change;
//!    a narrower candidate inside the chosen one's span when the data do not need the chosen
//!    one's extra directions (parsimony); and the candidates the data cannot tell from it, as
//!    its alternatives. Then an exchange pass: each finding is selected again given all the
//!    others (renamed, or dropped when no longer significant), and the selection goes on while
//!    that changes something.
//! 4. Refit the extended model (refined against the exact machine), and measure the residual
//!    RMS before and after on the fitted record and on every held-out record.
//!
//! [`campaign::diagnose_campaign`] does the same on a campaign (several records, each with its
//! own set-up and zero).

pub mod adequacy;
pub mod campaign;
mod confounded;
pub mod dictionary;
pub mod figures;
pub mod harmonic;
pub mod heldout;
pub mod hidden;
mod noise_model;
mod options;
pub mod outliers;
pub mod plausible;
pub mod profile;
mod projected;
mod search;
pub mod select;
pub mod structure;
pub mod unexplained;
pub mod verdict;

use crate::fitting::hmatrix::{GainSource, HMatrixError, h_matrix};
use crate::fitting::noise::{NoiseChoice, NoiseError, NoiseModel, NoiseSource};
use crate::fitting::refine::{RefineError, RefineOptions, identify_refined_with_noise};
use crate::fitting::validate::{ValidateError, ValidateOptions};
use crate::fitting::{
    EstimateError, Identification, IdentifyOptions, measurement_vector, with_offsets,
};
use crate::io::progress::{Progress, Unwatched};
use crate::model::{Effect, Model};
use crate::record::Record;
use confounded::confounded_with;
use dictionary::dictionary;
use model_spec::Machine;
use model_spec::terms::Term;
use nalgebra::DVector;
pub use options::DiagnoseOptions;

use select::Span;
use structure::Component;

/// How the corrected p-value of a step was obtained.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Correction {
    /// `p·N` (conservative), decisive on its own.
    Bonferroni,
    /// The Monte-Carlo null of the selection rule (level α exactly under Gaussian noise).
    MonteCarlo,
}

/// One significant effect found.
#[derive(Clone, Debug, PartialEq)]
pub struct Finding {
    /// The term added to the model.
    pub term: Term,
    /// Its name for people (`ECC harmonic:2: angular positioning error of C, twice per revolution`).
    pub description: String,
    /// Candidates the data cannot tell from this one: those of the same span given the model,
    /// and those to which this one adds nothing significant (raw F-test at α: they explain what
    /// it explains, as far as the data can tell). The finding may be any of them.
    pub alternatives: Vec<Term>,
    /// Its value(s) in the extended model, mm or rad (`[cos, sin]` for a harmonic; ms for a
    /// velocity term, a fraction for an instrument term); `None` where the fit cannot determine
    /// it. For an implausible finding, its value(s) with every finding fitted together.
    pub values: Vec<Option<f64>>,
    /// Their standard uncertainties (same units).
    pub stds: Vec<Option<f64>>,
    /// Its size in the unit people see (µm, µrad, ms, 1): `|value|`, or the amplitude of a
    /// pair ([`plausible`]).
    pub size: f64,
    /// The budget of its unit it was compared with.
    pub limit: f64,
    /// `size ≤ limit`: a plausible cause, in the extended model. An implausible finding fits
    /// the data but is not named as a cause and is left out of the extended model.
    pub plausible: bool,
    /// For `period:P`, `step:V`, `exp:TAU`: the refined parameter and its 95 % interval
    /// ([`profile`]); the values' standard uncertainties are conditional on it.
    pub scan: Option<profile::Scan>,
    /// Share of the base model's residual sum of squares it explains beyond all the other
    /// findings (its step in the final exchange pass).
    pub explained_fraction: f64,
    /// The F statistic of that step (given all the other findings).
    pub f: f64,
    /// Its p-value corrected for the number of candidates tried.
    pub p_value: f64,
    /// How the correction was made.
    pub correction: Correction,
    /// Candidates tried at that step.
    pub candidates_tried: usize,
}

/// A candidate the model spans: the data cannot see it apart from what is already there.
#[derive(Clone, Debug, PartialEq)]
pub struct Confounded {
    /// The candidate.
    pub term: Term,
    /// The model's terms it is a combination of (largest share first).
    pub with: Vec<Term>,
}

/// What a step stopped on (the best candidate not significant), for the report.
#[derive(Clone, Debug, PartialEq)]
pub struct Stop {
    /// The best remaining candidate, if any.
    pub best: Option<Term>,
    /// Its corrected p-value.
    pub p_value: f64,
    /// Why the selection stopped, for people.
    pub reason: String,
}

/// A diagnosis.
#[derive(Clone, Debug)]
pub struct Diagnosis {
    /// The base model as given (without the offsets of zeroed readings).
    pub base_given: Model,
    /// The base model as fitted (with the offsets when zeroed).
    pub base: Model,
    /// The base model's fit (refined against the exact machine).
    pub base_fit: Identification,
    /// Residual structure of the base fit, largest first.
    pub structure_before: Vec<Component>,
    /// Candidates in the dictionary.
    pub dictionary_size: usize,
    /// The findings, in the order they were added.
    pub findings: Vec<Finding>,
    /// Candidates spanned by the final model.
    pub confounded: Vec<Confounded>,
    /// Candidates that do not vary at all on the fitted path.
    pub unexcited: Vec<Term>,
    /// Why the selection stopped.
    pub stop: Stop,
    /// The extended model (base + the plausible findings).
    pub extended: Model,
    /// Its fit (refined).
    pub extended_fit: Identification,
    /// Residual structure after the extension.
    pub structure_after: Vec<Component>,
    /// Residual RMS on the fitted record (outliers left out), before and after (mm).
    pub fit_rms: (f64, f64),
    /// Residual RMS of the base fit with the outliers in the fit, mm.
    pub fit_rms_with_outliers: f64,
    /// Isolated readings of the fitted record far outside the base residual's scale; their
    /// samples are left out of every fit and test (`sample` indexes the record as given).
    pub outliers: Vec<outliers::Outlier>,
    /// Per held-out record: the residual RMS before and after, what it needs that the fits do
    /// not determine, its outliers.
    pub validation: Vec<heldout::HeldOut>,
    /// Whether the extended model is recommended, and why (not).
    pub recommendation: verdict::Recommendation,
    /// The noise model every test assumes (the readings and columns are whitened by it).
    pub noise: NoiseModel,
    /// The lack-of-fit test of the extended model's residual against the noise; `Err(why)`
    /// when there is no noise model independent of the fit (noise-free data, or ordinary least
    /// squares asked for).
    pub adequacy: Result<adequacy::Adequacy, String>,
    /// What remains in each direction the adequacy test finds inconsistent with the noise.
    pub unexplained: Vec<unexplained::Unexplained>,
}

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
    Refine(#[from] RefineError),
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

/// The refined fit of `model` on `record`, by generalized least squares under `noise`.
fn fit(
    m: &Machine,
    model: &Model,
    record: &Record,
    source: &mut GainSource,
    o: &DiagnoseOptions,
    noise: &NoiseChoice,
) -> Result<Identification, DiagnoseError> {
    let opts = IdentifyOptions {
        zeroed: false,
        constraint: o.constraint.clone(),
        tolerances: o.tolerances,
        params: None,
    };
    let (mut ident, _) = identify_refined_with_noise(
        m,
        model,
        record,
        source,
        &opts,
        &RefineOptions::default(),
        noise,
    )?;
    ident.zeroed = o.zeroed;
    Ok(ident)
}

fn residual_rows(ident: &Identification) -> Vec<[f64; 3]> {
    let r = &ident.fit.residual;
    (0..r.len() / 3)
        .map(|i| [r[3 * i], r[3 * i + 1], r[3 * i + 2]])
        .collect()
}

/// The values and standard uncertainties of term `t` of a fit (mm or rad).
fn term_values(ident: &Identification, t: usize) -> (Vec<Option<f64>>, Vec<Option<f64>>) {
    let cols: Vec<usize> = ident
        .model
        .columns()
        .iter()
        .enumerate()
        .filter(|(_, (ti, _))| *ti == t)
        .map(|(j, _)| j)
        .collect();
    (
        cols.iter().map(|&j| ident.fit.values[j]).collect(),
        cols.iter().map(|&j| ident.fit.std[j]).collect(),
    )
}

/// Diagnoses `base` on `record`, checking the gain on the `held_out` records.
pub fn diagnose(
    m: &Machine,
    base: &Model,
    record: &Record,
    held_out: &[(String, Record)],
    o: &DiagnoseOptions,
) -> Result<Diagnosis, DiagnoseError> {
    diagnose_with_progress(m, base, record, held_out, o, &Unwatched)
}

/// The stages of a diagnosis, in order, as [`diagnose_with_progress`] reports them.
pub const STAGES: [&str; 7] = [
    "base fit",
    "noise model",
    "candidates' columns",
    "selection",
    "extended fit",
    "held-out records",
    "lack of fit",
];

/// [`diagnose`], telling `progress` where it is: `diagnosis` with the number of [`STAGES`]
/// begun (done of total), and within the selection every candidate scored (`selection`, done
/// of the candidates of the step; each step starts again from 0).
///
/// # Errors
/// As [`diagnose`].
pub fn diagnose_with_progress(
    m: &Machine,
    base: &Model,
    record: &Record,
    held_out: &[(String, Record)],
    o: &DiagnoseOptions,
    progress: &dyn Progress,
) -> Result<Diagnosis, DiagnoseError> {
    let stage = |k: usize| progress.update("diagnosis", k as u64, STAGES.len() as u64);
    stage(0);
    let base_given = base.clone();
    let base = if o.zeroed {
        with_offsets(base)
    } else {
        base.clone()
    };
    let mut candidates = dictionary(m, &base.terms, &o.dictionary);
    candidates.extend(dictionary::scanned(m, &base.terms, record, &o.dictionary));
    // One gain source for every error the base model and the dictionary use.
    let mut all = base.clone();
    all.terms.extend(candidates.iter().copied());
    let params = o.params.clone().unwrap_or_else(|| m.default_parameters());
    let mut source = GainSource::new(m, &all.errors(), &params)?;

    // Outliers of the fitted record, from the base fit's residual: everything after works
    // without their samples.
    let first_fit = fit(m, &base, record, &mut source, o, &NoiseChoice::Ordinary)?;
    let outliers = outliers::find_in(record, &residual_rows(&first_fit));
    let fit_rms_with_outliers = first_fit.fit.residual_rms();
    let cleaned;
    let (record, base_fit) = if outliers.is_empty() {
        (record, first_fit)
    } else {
        cleaned = record.without(&outliers::samples(&outliers));
        let f = fit(m, &base, &cleaned, &mut source, o, &NoiseChoice::Ordinary)?;
        (&cleaned, f)
    };

    stage(1);
    // The noise model, and the readings and columns whitened by it: every test after is the
    // textbook one on white noise of unit variance.
    let vopts = ValidateOptions {
        zeroed: o.zeroed,
        exact: true,
        params: Some(params.clone()),
        ..Default::default()
    };
    let before = heldout::predict(m, &base_fit, held_out, &mut source, &vopts)?;
    let (noise, estimated) = noise_model::choose(&o.noise, &base_fit, held_out, &before);
    // Every fit from here on is the generalized least-squares fit under that model, so that
    // the standard uncertainties assume it.
    let gls = match noise.source {
        NoiseSource::Residual { .. } => NoiseChoice::Ordinary,
        _ => NoiseChoice::Model(noise.clone()),
    };
    let (base_fit, before) = if gls == NoiseChoice::Ordinary {
        (base_fit, before)
    } else {
        let f = fit(m, &base, record, &mut source, o, &gls)?;
        let b = heldout::predict(m, &f, held_out, &mut source, &vopts)?;
        (f, b)
    };
    stage(2);
    let layout = [record.samples.len()];
    let mut y = measurement_vector(record)?;
    let mut h_raw = h_matrix(m, &all, record, &mut source)?;
    // The instrument candidates act on the displacement, which the H matrix takes from the
    // readings; those carry the very misfit the selection looks for, so that a gain term
    // "explains" a share of any residual. Here the displacement is the base model's
    // prediction instead (first order in S all the same).
    let predicted = &y - &base_fit.fit.residual;
    let mut at = 0;
    for t in &all.terms {
        if let Effect::Instrument {
            reading,
            displacement,
        } = t.effect
        {
            let mut col = h_raw.column_mut(at);
            col.fill(0.0);
            for i in 0..predicted.len() / 3 {
                col[3 * i + reading.index()] = predicted[3 * i + displacement.index()];
            }
        }
        at += t.basis.width();
    }
    let mut h_all = h_raw.clone();
    let whitening = if estimated {
        noise_model::conservative(&noise)
    } else {
        noise.clone()
    };
    whitening.whiten(&layout, &mut h_all, &mut y)?;
    let n = y.len();

    // Column ranges: base terms first, then one group per candidate.
    let widths: Vec<usize> = all.terms.iter().map(|t| t.basis.width()).collect();
    let starts: Vec<usize> = widths
        .iter()
        .scan(0, |s, &w| {
            let a = *s;
            *s += w;
            Some(a)
        })
        .collect();
    let group = |t: usize| h_all.columns(starts[t], widths[t]).into_owned();
    let nb = base.terms.len();

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
    let candidates_live: Vec<usize> = (0..candidates.len())
        .filter(|&c| !unexcited.contains(&candidates[c]))
        .collect();

    let problem = search::Problem {
        m,
        candidates: &candidates,
        nb,
        group: &group,
        y: &y,
        rss_base,
        live: &candidates_live,
        o,
        progress,
    };
    stage(3);
    let (chosen, stop) = search::select(&problem);
    // A scanned parameter refined on a fine grid, with every other finding in place.
    let mut refined = Vec::new();
    for k in 0..chosen.len() {
        let q = search::basis_of(&problem, &chosen, Some(k));
        let coarse = candidates[chosen[k].index];
        refined.push(
            match profile::refine(m, coarse, record, &mut source, &whitening, &q, &y)? {
                Some((t, scan)) => (t, Some(scan)),
                None => (coarse, None),
            },
        );
    }

    stage(4);
    // Every finding fitted together; the implausible ones are then left out of the extended
    // model, which is fitted again.
    let mut with_all = base.clone();
    with_all.terms.extend(refined.iter().map(|r| r.0));
    let all_fit = fit(m, &with_all, record, &mut source, o, &gls)?;
    let mut findings: Vec<Finding> = chosen
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let (term, scan) = refined[k];
            let (values, stds) = term_values(&all_fit, nb + k);
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
                scan,
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
        let e = fit(m, &extended, record, &mut source, o, &gls)?;
        for f in findings.iter_mut().filter(|f| f.plausible) {
            let t = e.model.terms.iter().position(|t| *t == f.term);
            if let Some(t) = t {
                (f.values, f.stds) = term_values(&e, t);
            }
        }
        e
    };

    // The extended model's findings as candidates (their coarse grid values: the spans the
    // selection saw).
    let kept: Vec<usize> = chosen
        .iter()
        .zip(&findings)
        .filter(|(_, f)| f.plausible)
        .map(|(c, _)| c.index)
        .collect();
    let mut as_candidates = base.clone();
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
        nb,
        &h_all,
        &starts,
        &widths,
    );

    stage(5);
    let validation = heldout::held_out_gain(
        m,
        &base_fit,
        &before,
        &extended_fit,
        held_out,
        &mut source,
        &vopts,
    )?;
    stage(6);
    // Lack of fit of the extended model against the noise on every record, and what remains
    // where it fails, described.
    let adequacy = match &noise.source {
        NoiseSource::Residual { why } => Err(why.clone()),
        _ if o.adequacy_draws == 0 => Err("not asked for (no bootstrap draws)".into()),
        _ => {
            let cols: Vec<usize> = (0..nb)
                .chain(kept.iter().map(|&c| nb + c))
                .flat_map(|g| starts[g]..starts[g] + widths[g])
                .collect();
            let h_ext = h_raw.select_columns(&cols);
            let held: Vec<DVector<f64>> = validation
                .iter()
                .map(heldout::HeldOut::residual_after_without_outliers)
                .collect();
            // The extended model's columns on every held-out record (outliers' samples left
            // out): the bootstrap carries the fit's own uncertainty into those predictions.
            let mut predicted = Vec::new();
            for (h, (_, rec)) in validation.iter().zip(held_out) {
                let drop = outliers::samples(&h.outliers);
                match h_matrix(m, &as_candidates, &rec.without(&drop), &mut source) {
                    Ok(hh) => predicted.push(hh),
                    Err(e) => return Err(DiagnoseError::HMatrix(e)),
                }
            }
            let data = o.data_name.as_str();
            let mut residuals = vec![adequacy::Residual {
                name: data,
                residual: &extended_fit.fit.residual,
                fitted: Some(&h_ext),
                predicted: None,
                zeroed: false,
            }];
            residuals.extend(validation.iter().zip(held.iter().zip(&predicted)).map(
                |(h, (r, p))| adequacy::Residual {
                    name: &h.name,
                    residual: r,
                    fitted: None,
                    predicted: Some(p),
                    zeroed: o.zeroed,
                },
            ));
            // Drawn with φ raised as for the selection: an estimate of φ that runs low would make
            // the draws too tame and the test too eager.
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
            let mut records = vec![(o.data_name.as_str(), record, residual_rows(&extended_fit))];
            records.extend(
                validation
                    .iter()
                    .zip(held_out)
                    .map(|(h, (_, rec))| (h.name.as_str(), rec, h.residual_after.clone())),
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
    // The verdict under the noise the tests assume (φ raised when estimated), with σ the
    // lack-of-fit test's reference.
    let verdict_noise = adequacy.as_ref().ok().map(|a| {
        let mut n = whitening.clone();
        if let Some(r) = a.records.first() {
            n.sigma_mm = r.noise_sigma_mm;
        }
        n
    });
    let consistent = adequacy.as_ref().ok().map(|a| a.consistent_with_noise);
    let recommendation =
        verdict::recommend(&findings, &validation, verdict_noise.as_ref(), consistent);
    let (k, p, t) = (o.dictionary.harmonics, o.dictionary.poly, o.dictionary.time);
    Ok(Diagnosis {
        structure_before: structure::analyse(m, record, &residual_rows(&base_fit), k, p, t),
        structure_after: structure::analyse(m, record, &residual_rows(&extended_fit), k, p, t),
        fit_rms,
        fit_rms_with_outliers,
        outliers,
        base_given,
        base,
        base_fit,
        dictionary_size: candidates.len(),
        findings,
        confounded,
        unexcited,
        stop,
        extended,
        extended_fit,
        validation,
        recommendation,
        noise,
        adequacy,
        unexplained,
    })
}

impl Diagnosis {
    /// The extended model as a sub-model lists it: the base model's terms as given (without
    /// the offsets zeroed readings add) followed by the plausible findings.
    pub fn extended_terms(&self) -> Model {
        let mut out = self.base_given.clone();
        for f in self.findings.iter().filter(|f| f.plausible) {
            if !out.terms.contains(&f.term) {
                out.terms.push(f.term);
            }
        }
        out
    }

    /// The extended model's label: the base model's `label` and the plausible findings
    /// (`reduced + ECC@harmonic:2`).
    pub fn extended_label(&self, m: &Machine, label: &str) -> String {
        std::iter::once(label.to_string())
            .chain(
                self.findings
                    .iter()
                    .filter(|f| f.plausible)
                    .map(|f| f.term.spelling(m)),
            )
            .collect::<Vec<_>>()
            .join(" + ")
    }

    /// The machine description `text` of `m` with the extended model appended as a sub-model
    /// ([`model_spec::write::append_model`]), described by its label and `context` (`rtest
    /// diagnose on k4.csv`): the model's name and the new text.
    ///
    /// # Errors
    /// [`model_spec::write::AppendError`] when the text does not read back as the same machine
    /// with that model.
    pub fn extended_machine(
        &self,
        m: &Machine,
        text: &str,
        label: &str,
        context: &str,
    ) -> Result<(String, String), model_spec::write::AppendError> {
        let terms: Vec<String> = self
            .extended_terms()
            .terms
            .iter()
            .map(|t| t.spelling(m))
            .collect();
        let description = format!("{} ({context})", self.extended_label(m, label));
        model_spec::write::append_model(m, text, &terms, &description)
    }
}
