//! Diagnosis: where the model and the measurement disagree, which missing effect explains it,
//! the model extended with it, and the gain measured on data that were not fitted.
//!
//! 1. Fit the base model; analyse the structure of its residual ([`structure`]).
//! 2. Build the candidate dictionary ([`dictionary`]): every term of the topology the model
//!    lacks.
//! 3. Forward selection ([`select`]): add the candidate that explains most of what is left,
//!    if it is significant (F-test against the noise, corrected for the number of candidates
//!    tried); refuse candidates the model spans and report them with what they are confounded
//!    with; name candidates the data cannot tell from the chosen one; stop when nothing
//!    significant remains.
//! 4. Refit the extended model (refined against the exact machine), and measure the residual
//!    RMS before and after on the fitted record and on every held-out record.

pub mod dictionary;
pub mod select;
pub mod structure;

use crate::estimate::{
    EstimateError, Identification, IdentifyOptions, Tolerances, identify_with, measurement_vector,
    with_offsets,
};
use crate::hmatrix::{GainSource, HMatrixError, h_matrix};
use crate::model::Model;
use crate::record::Record;
use crate::refine::{RefineError, RefineOptions, refine};
use crate::validate::{ValidateError, ValidateOptions, validate_with};
use dictionary::{DictionaryOptions, dictionary};
use model_spec::Machine;
use model_spec::terms::Term;
use nalgebra::{DMatrix, DVector};
use select::{Basis, Scored, f_p_value, f_statistic, monte_carlo_p};
use structure::Component;

/// Options of [`diagnose`].
#[derive(Clone, Debug, PartialEq)]
pub struct DiagnoseOptions {
    /// The candidate dictionary's extent.
    pub dictionary: DictionaryOptions,
    /// Significance level α of each step, after the correction for the candidates tried.
    pub alpha: f64,
    /// Most findings.
    pub max_findings: usize,
    /// Monte-Carlo draws for the corrected p-value when Bonferroni is not decisive.
    pub draws: usize,
    /// Seed of the Monte-Carlo draws.
    pub seed: u64,
    /// The readings were zeroed at the first sample (the offsets dx0 dy0 dz0 join the base
    /// model).
    pub zeroed: bool,
    /// Kinematic parameters (mm, symbol order); `None`: the machine's defaults.
    pub params: Option<Vec<f64>>,
    /// Rank and identifiability tolerances of the fits.
    pub tolerances: Tolerances,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        DiagnoseOptions {
            dictionary: DictionaryOptions::default(),
            alpha: 0.01,
            max_findings: 8,
            draws: 1000,
            seed: 0x5eed,
            zeroed: false,
            params: None,
            tolerances: Tolerances::default(),
        }
    }
}

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
    /// Candidates the data cannot tell from this one (same span given the model): the finding
    /// may be any of them.
    pub alternatives: Vec<Term>,
    /// Its value(s) in the extended model, mm or rad (`[cos, sin]` for a harmonic).
    pub values: Vec<f64>,
    /// Their standard uncertainties (mm or rad).
    pub stds: Vec<Option<f64>>,
    /// Share of the base model's residual sum of squares it explains.
    pub explained_fraction: f64,
    /// The F statistic of the step.
    pub f: f64,
    /// The p-value corrected for the number of candidates tried.
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
    /// The extended model (base + findings).
    pub extended: Model,
    /// Its fit (refined).
    pub extended_fit: Identification,
    /// Residual structure after the extension.
    pub structure_after: Vec<Component>,
    /// Residual RMS on the fitted record, before and after (mm).
    pub fit_rms: (f64, f64),
    /// Per held-out record: its name and the residual RMS before and after (mm).
    pub validation: Vec<(String, f64, f64)>,
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
}

/// A step of the selection, before the extended fit gives its values.
struct Chosen {
    index: usize,
    alternatives: Vec<usize>,
    fraction: f64,
    f: f64,
    correction: Correction,
    tried: usize,
    p: f64,
}

fn fit(
    m: &Machine,
    model: &Model,
    record: &Record,
    source: &mut GainSource,
    o: &DiagnoseOptions,
) -> Result<Identification, DiagnoseError> {
    let opts = IdentifyOptions {
        zeroed: false,
        constraint: Default::default(),
        tolerances: o.tolerances,
        params: None,
    };
    let mut ident = identify_with(m, model, record, source, &opts)?;
    ident.zeroed = o.zeroed;
    refine(
        m,
        record,
        &mut ident,
        source,
        &o.tolerances,
        &RefineOptions::default(),
    )?;
    Ok(ident)
}

fn residual_rows(ident: &Identification) -> Vec<[f64; 3]> {
    let r = &ident.fit.residual;
    (0..r.len() / 3)
        .map(|i| [r[3 * i], r[3 * i + 1], r[3 * i + 2]])
        .collect()
}

/// Diagnoses `base` on `record`, checking the gain on the `held_out` records.
pub fn diagnose(
    m: &Machine,
    base: &Model,
    record: &Record,
    held_out: &[(String, Record)],
    o: &DiagnoseOptions,
) -> Result<Diagnosis, DiagnoseError> {
    let base = if o.zeroed {
        with_offsets(base)
    } else {
        base.clone()
    };
    let candidates = dictionary(m, &base.terms, &o.dictionary);
    // One gain source for every error the base model and the dictionary use.
    let mut all = base.clone();
    all.terms.extend(candidates.iter().copied());
    let params = o.params.clone().unwrap_or_else(|| m.default_parameters());
    let mut source = GainSource::new(m, &all.errors(), &params)?;
    let h_all = h_matrix(m, &all, record, &mut source)?;
    let y = measurement_vector(record)?;
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

    let mut q = Basis::empty(n);
    for t in 0..nb {
        let d = q.new_directions(&group(t));
        q.extend(&d);
    }
    let rss_of = |q: &Basis| q.project_out(&y).norm_squared();
    let rss_base = rss_of(&q);
    let unexcited: Vec<Term> = (0..candidates.len())
        .filter(|&c| group(nb + c).iter().all(|v| v.abs() < 1e-15))
        .map(|c| candidates[c])
        .collect();
    let mut live: Vec<usize> = (0..candidates.len())
        .filter(|&c| !unexcited.contains(&candidates[c]))
        .collect();

    let mut chosen: Vec<Chosen> = Vec::new();
    let stop;
    loop {
        let r = q.project_out(&y);
        let rss = r.norm_squared();
        let scored: Vec<Scored> = live
            .iter()
            .filter_map(|&c| {
                let d = q.new_directions(&group(nb + c));
                (d.ncols() > 0).then(|| {
                    let delta = d.tr_mul(&r).norm_squared();
                    Scored {
                        index: c,
                        directions: d,
                        delta_rss: delta,
                    }
                })
            })
            .collect();
        let Some(best) = scored
            .iter()
            .max_by(|a, b| a.delta_rss.total_cmp(&b.delta_rss))
        else {
            stop = Stop {
                best: None,
                p_value: 1.0,
                reason: "no candidate left that the model does not span".into(),
            };
            break;
        };
        let qg = best.directions.ncols();
        let Some(f) = f_statistic(best.delta_rss, rss, qg, n, q.rank()) else {
            stop = Stop {
                best: Some(candidates[best.index]),
                p_value: 1.0,
                reason: "no degrees of freedom left".into(),
            };
            break;
        };
        let tried = scored.len();
        let p_raw = f_p_value(f, qg, n, q.rank());
        let bonferroni = (p_raw * tried as f64).min(1.0);
        let (p, how) = if bonferroni < o.alpha {
            (bonferroni, Correction::Bonferroni)
        } else {
            (
                monte_carlo_p(&q, &scored, f, o.draws, o.seed ^ chosen.len() as u64),
                Correction::MonteCarlo,
            )
        };
        if p >= o.alpha || chosen.len() >= o.max_findings {
            let reason = if p >= o.alpha {
                format!(
                    "the best remaining candidate is not significant (corrected p = {p:.3} ≥ α = {})",
                    o.alpha
                )
            } else {
                format!("the limit of {} findings was reached", o.max_findings)
            };
            stop = Stop {
                best: Some(candidates[best.index]),
                p_value: p,
                reason,
            };
            break;
        }
        // Candidates the data cannot tell from the chosen one: same number of directions, inside
        // its span.
        let alternatives: Vec<usize> = scored
            .iter()
            .filter(|s| s.index != best.index && s.directions.ncols() == qg)
            .filter(|s| {
                (best.directions.tr_mul(&s.directions)).norm_squared() > qg as f64 * (1.0 - 1e-9)
            })
            .map(|s| s.index)
            .collect();
        chosen.push(Chosen {
            index: best.index,
            alternatives: alternatives.clone(),
            fraction: best.delta_rss / rss_base.max(f64::MIN_POSITIVE),
            f,
            correction: how,
            tried,
            p,
        });
        let d = best.directions.clone();
        q.extend(&d);
        live.retain(|&c| c != best.index && !alternatives.contains(&c));
    }

    let mut extended = base.clone();
    extended
        .terms
        .extend(chosen.iter().map(|c| candidates[c.index]));
    let base_fit = fit(m, &base, record, &mut source, o)?;
    let extended_fit = fit(m, &extended, record, &mut source, o)?;

    let columns = extended.columns();
    let findings = chosen
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let t = nb + k;
            let cols: Vec<usize> = columns
                .iter()
                .enumerate()
                .filter(|(_, (ti, _))| *ti == t)
                .map(|(j, _)| j)
                .collect();
            Finding {
                term: candidates[c.index],
                description: candidates[c.index].describe(m),
                alternatives: c.alternatives.iter().map(|&a| candidates[a]).collect(),
                values: cols
                    .iter()
                    .map(|&j| extended_fit.fit.values[j].unwrap_or(f64::NAN))
                    .collect(),
                stds: cols.iter().map(|&j| extended_fit.fit.std[j]).collect(),
                explained_fraction: c.fraction,
                f: c.f,
                p_value: c.p,
                correction: c.correction,
                candidates_tried: c.tried,
            }
        })
        .collect();

    let confounded = confounded_with(
        &extended,
        &candidates,
        &chosen.iter().map(|c| c.index).collect::<Vec<_>>(),
        &unexcited,
        &q,
        &|t| group(t),
        nb,
        &h_all,
        &starts,
        &widths,
    );

    let mut validation = Vec::new();
    let vopts = ValidateOptions {
        zeroed: o.zeroed,
        exact: true,
        params: Some(params.clone()),
        ..Default::default()
    };
    for (name, rec) in held_out {
        let before = validate_with(
            m,
            &base_fit.model,
            &base_fit.fit.values,
            rec,
            &mut source,
            &vopts,
        )?;
        let after = validate_with(
            m,
            &extended_fit.model,
            &extended_fit.fit.values,
            rec,
            &mut source,
            &vopts,
        )?;
        validation.push((
            name.clone(),
            before.overall.residual_rms,
            after.overall.residual_rms,
        ));
    }
    let rows = n.max(1) as f64;
    let (k, p, t) = (o.dictionary.harmonics, o.dictionary.poly, o.dictionary.time);
    Ok(Diagnosis {
        structure_before: structure::analyse(m, record, &residual_rows(&base_fit), k, p, t),
        structure_after: structure::analyse(m, record, &residual_rows(&extended_fit), k, p, t),
        fit_rms: (
            (base_fit.fit.rss / rows).sqrt(),
            (extended_fit.fit.rss / rows).sqrt(),
        ),
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
    })
}

/// The candidates the final model spans, each with the model terms it is a combination of.
#[allow(clippy::too_many_arguments)]
fn confounded_with(
    extended: &Model,
    candidates: &[Term],
    chosen: &[usize],
    unexcited: &[Term],
    q: &Basis,
    group: &dyn Fn(usize) -> DMatrix<f64>,
    nb: usize,
    h_all: &DMatrix<f64>,
    starts: &[usize],
    widths: &[usize],
) -> Vec<Confounded> {
    // The extended model's columns, scaled to unit norm, with their term indices in `extended`.
    let mut cols: Vec<DVector<f64>> = Vec::new();
    let mut owner: Vec<usize> = Vec::new();
    for (ti, t) in extended.terms.iter().enumerate() {
        let all_index = if ti < nb { ti } else { nb + chosen[ti - nb] };
        debug_assert_eq!(widths[all_index], t.basis.width());
        for k in 0..widths[all_index] {
            let c = h_all.column(starts[all_index] + k).into_owned();
            let norm = c.norm();
            if norm > 0.0 {
                cols.push(c / norm);
                owner.push(ti);
            }
        }
    }
    if cols.is_empty() {
        return Vec::new();
    }
    let hm = DMatrix::from_columns(&cols);
    let svd = hm.clone().svd(true, true);
    let eps = svd.singular_values.max() * 1e-10;
    let mut out = Vec::new();
    for (c, term) in candidates.iter().enumerate() {
        if chosen.contains(&c) || unexcited.contains(term) {
            continue;
        }
        let g = group(nb + c);
        if q.new_directions(&g).ncols() > 0 {
            continue;
        }
        let mut share = vec![0.0f64; extended.terms.len()];
        for k in 0..g.ncols() {
            let col = g.column(k).into_owned();
            let norm = col.norm();
            if norm == 0.0 {
                continue;
            }
            if let Ok(beta) = svd.solve(&(col / norm), eps) {
                for (j, b) in beta.iter().enumerate() {
                    share[owner[j]] += b.abs();
                }
            }
        }
        let top = share.iter().cloned().fold(0.0, f64::max);
        let mut with: Vec<(usize, f64)> = share
            .iter()
            .enumerate()
            .filter(|(_, s)| **s >= 0.1 * top && **s > 0.0)
            .map(|(j, s)| (j, *s))
            .collect();
        with.sort_by(|a, b| b.1.total_cmp(&a.1));
        out.push(Confounded {
            term: *term,
            with: with.into_iter().map(|(j, _)| extended.terms[j]).collect(),
        });
    }
    out
}
