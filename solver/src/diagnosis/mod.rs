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

mod confounded;
pub mod dictionary;
pub mod figures;
pub mod harmonic;
pub mod hidden;
mod options;
pub mod select;
pub mod structure;

use crate::fitting::distributions::f_upper_tail;
use crate::fitting::hmatrix::{GainSource, HMatrixError, h_matrix};
use crate::fitting::refine::{RefineError, RefineOptions, identify_refined_with};
use crate::fitting::validate::{ValidateError, ValidateOptions, validate_with};
use crate::fitting::{
    EstimateError, Identification, IdentifyOptions, measurement_vector, with_offsets,
};
use crate::model::Model;
use crate::record::Record;
use confounded::{confounded_with, same_span, scaled_size};
use dictionary::dictionary;
use model_spec::Machine;
use model_spec::terms::Term;
pub use options::DiagnoseOptions;

use select::{Scored, Span, f_p_value, f_statistic, monte_carlo_p};
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
    /// Its value(s) in the extended model, mm or rad (`[cos, sin]` for a harmonic).
    pub values: Vec<f64>,
    /// Their standard uncertainties (mm or rad).
    pub stds: Vec<Option<f64>>,
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
    let (mut ident, _) =
        identify_refined_with(m, model, record, source, &opts, &RefineOptions::default())?;
    ident.zeroed = o.zeroed;
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
    let base_given = base.clone();
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

    let mut q_base = Span::empty(n);
    for t in 0..nb {
        let d = q_base.new_directions(&group(t));
        q_base.extend(&d);
    }
    let rss_base = q_base.project_out(&y).norm_squared();
    let unexcited: Vec<Term> = (0..candidates.len())
        .filter(|&c| group(nb + c).iter().all(|v| v.abs() < 1e-15))
        .map(|c| candidates[c])
        .collect();
    let candidates_live: Vec<usize> = (0..candidates.len())
        .filter(|&c| !unexcited.contains(&candidates[c]))
        .collect();

    // One selection step on the model `q` (orthonormal) over the candidates `pool`: the
    // significant candidate named, or why there is none.
    let step = |q: &Span, pool: &[usize], seed: u64| -> Result<Chosen, Stop> {
        let r = q.project_out(&y);
        let rss = r.norm_squared();
        let scored: Vec<Scored> = pool
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
            return Err(Stop {
                best: None,
                p_value: 1.0,
                reason: "no candidate left that the model does not span".into(),
            });
        };
        // Candidates of one span explain exactly the same, and which one has the largest ΔRSS
        // is a matter of rounding. Name the one with the fewest parameters (AOC rather than
        // EZC harmonic:1 when the base lacks AOC), then an error of an axis line (location,
        // squareness, set-up: the squareness AOZ rather than the pitch EAY, the straightness
        // EYZ poly:1 or the angular error EAZ poly:1 that read the same at the ball), then
        // another constant, then the one that needs the smallest change to do it (coefficients
        // of its unit-norm columns): the one least entangled with the model (with a base
        // lacking XOW, ECC@reversal, a constant on K4, spans what XOW spans only through YOW,
        // with 0.043 rad for 12 µm).
        let rank = |t: &Term| -> u8 {
            use model_spec::ErrorKind::{Location, Setup, Squareness};
            match (t.effect, t.basis) {
                (model_spec::terms::Effect::Error(e), _)
                    if matches!(
                        m.catalogue[e].kind,
                        Location { .. } | Squareness { .. } | Setup { .. }
                    ) =>
                {
                    0
                }
                (_, model_spec::basis::Basis::Const) => 1,
                _ => 2,
            }
        };
        let prefer = |one: &Scored| -> usize {
            scored
                .iter()
                .enumerate()
                .filter(|(_, s)| same_span(one, s))
                .map(|(k, s)| {
                    let g = group(nb + s.index);
                    (
                        k,
                        (
                            g.ncols(),
                            rank(&candidates[s.index]),
                            scaled_size(q, &g, &r),
                        ),
                    )
                })
                .min_by(|a, b| {
                    (a.1.0, a.1.1)
                        .cmp(&(b.1.0, b.1.1))
                        .then(a.1.2.total_cmp(&b.1.2))
                })
                .map_or(0, |(k, _)| k)
        };
        let best = &scored[prefer(best)];
        let qg = best.directions.ncols();
        let Some(f) = f_statistic(best.delta_rss, rss, qg, n, q.rank()) else {
            return Err(Stop {
                best: Some(candidates[best.index]),
                p_value: 1.0,
                reason: "no degrees of freedom left".into(),
            });
        };
        let tried = scored.len();
        let p_raw = f_p_value(f, qg, n, q.rank());
        let bonferroni = (p_raw * tried as f64).min(1.0);
        let (p, how) = if bonferroni < o.alpha {
            (bonferroni, Correction::Bonferroni)
        } else {
            (
                monte_carlo_p(q, &scored, p_raw, o.draws, seed),
                Correction::MonteCarlo,
            )
        };
        if p >= o.alpha {
            return Err(Stop {
                best: Some(candidates[best.index]),
                p_value: p,
                reason: format!(
                    "the best remaining candidate is not significant (corrected p = {p:.3} ≥ α = {})",
                    o.alpha
                ),
            });
        }
        // What candidate `a` adds beyond candidate `b` (and the model): the ΔRSS of its
        // directions outside their span, how many, and the RSS left with both.
        let beyond = |a: &Scored, b: &Scored| -> (f64, usize, f64, usize) {
            let extra = Span {
                q: b.directions.clone(),
            }
            .new_directions(&a.directions);
            let gain = extra.tr_mul(&r).norm_squared();
            let dim = b.directions.ncols() + extra.ncols();
            (gain, extra.ncols(), rss - b.delta_rss - gain, dim)
        };
        // `true` when that addition is not significant (raw F-test at α).
        let not_needed = |(gain, extra, rest, dim): (f64, usize, f64, usize)| -> bool {
            if extra == 0 {
                return true;
            }
            let Some(dof) = n.checked_sub(q.rank() + dim).filter(|&d| d > 0) else {
                return false;
            };
            let f = (gain.max(0.0) / extra as f64) / (rest / dof as f64);
            f.is_finite() && f_upper_tail(f, extra as f64, dof as f64) >= o.alpha
        };
        // Parsimony: a narrower candidate that explains what the best one explains, as far as
        // the data can tell, is named instead. (EXX poly:1 lies exactly inside the span of EXC
        // harmonic:1 on any path where X follows the ball of an A-C table, and the largest ΔRSS
        // always goes to the wider group.) Narrower: fewer directions; it adds nothing
        // significant to the best one, and the best one adds nothing significant to it. The
        // step's significance (the test above) is unchanged.
        let named = scored
            .iter()
            .filter(|s| s.index != best.index && s.directions.ncols() < qg)
            .filter(|s| not_needed(beyond(s, best)) && not_needed(beyond(best, s)))
            .max_by(|a, b| a.delta_rss.total_cmp(&b.delta_rss))
            .map_or(best, |s| &scored[prefer(s)]);
        // Candidates of the named one's span (the extended model spans them).
        let spanned: Vec<usize> = scored
            .iter()
            .filter(|s| s.index != named.index && same_span(named, s))
            .map(|s| s.index)
            .collect();
        // Candidates the data cannot tell from the named one: those of its span, and those to
        // which the named one adds nothing significant (they explain what it explains); most
        // explaining first.
        let mut alike: Vec<&Scored> = scored
            .iter()
            .filter(|s| s.index != named.index)
            .filter(|s| spanned.contains(&s.index) || not_needed(beyond(named, s)))
            .collect();
        alike.sort_by(|a, b| b.delta_rss.total_cmp(&a.delta_rss));
        let alternatives: Vec<usize> = alike.iter().map(|s| s.index).collect();
        Ok(Chosen {
            index: named.index,
            alternatives,
            fraction: named.delta_rss / rss_base.max(f64::MIN_POSITIVE),
            f,
            correction: how,
            tried,
            p,
        })
    };
    // The model's basis: the base and the chosen terms (but `skip`).
    let basis_of = |chosen: &[Chosen], skip: Option<usize>| -> Span {
        let mut q = Span::empty(n);
        let terms = (0..nb).chain(
            chosen
                .iter()
                .enumerate()
                .filter(|(k, _)| Some(*k) != skip)
                .map(|(_, c)| nb + c.index),
        );
        for t in terms {
            let d = q.new_directions(&group(t));
            q.extend(&d);
        }
        q
    };
    // The candidates a step may take: the excited ones that are not chosen (but `skip`).
    let pool_of = |chosen: &[Chosen], skip: Option<usize>| -> Vec<usize> {
        candidates_live
            .iter()
            .copied()
            .filter(|&c| {
                !chosen
                    .iter()
                    .enumerate()
                    .any(|(k, x)| Some(k) != skip && x.index == c)
            })
            .collect()
    };

    // Forward steps until nothing significant is left; then an exchange pass: each finding in
    // turn is taken out and its slot selected again given all the others, so that a term
    // chosen while another effect was still unexplained (EXC harmonic:1 carrying part of ECC
    // harmonic:2 before it, where EXX poly:1 is the cause) is renamed, or dropped when it is no
    // longer significant. Repeated while the exchange changes something (at most 4 rounds).
    let mut chosen: Vec<Chosen> = Vec::new();
    let mut stop;
    let mut round = 0;
    loop {
        let mut q = basis_of(&chosen, None);
        loop {
            let seed = context_seed(o.seed, &chosen, None);
            match step(&q, &pool_of(&chosen, None), seed) {
                Err(s) => {
                    stop = s;
                    break;
                }
                Ok(c) if chosen.len() >= o.max_findings => {
                    stop = Stop {
                        best: Some(candidates[c.index]),
                        p_value: c.p,
                        reason: format!("the limit of {} findings was reached", o.max_findings),
                    };
                    break;
                }
                Ok(c) => {
                    let d = q.new_directions(&group(nb + c.index));
                    q.extend(&d);
                    chosen.push(c);
                }
            }
        }
        let mut changed = false;
        let mut j = 0;
        while j < chosen.len() {
            let seed = context_seed(o.seed, &chosen, Some(j));
            match step(
                &basis_of(&chosen, Some(j)),
                &pool_of(&chosen, Some(j)),
                seed,
            ) {
                Ok(c) => {
                    changed |= c.index != chosen[j].index;
                    chosen[j] = c;
                    j += 1;
                }
                Err(_) => {
                    chosen.remove(j);
                    changed = true;
                }
            }
        }
        round += 1;
        if !changed || round >= 4 {
            break;
        }
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
        &basis_of(&chosen, None),
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
    })
}

impl Diagnosis {
    /// The extended model as a sub-model lists it: the base model's terms as given (without
    /// the offsets zeroed readings add) followed by the findings.
    pub fn extended_terms(&self) -> Model {
        let mut out = self.base_given.clone();
        for f in &self.findings {
            if !out.terms.contains(&f.term) {
                out.terms.push(f.term);
            }
        }
        out
    }

    /// The extended model's label: the base model's `label` and the findings
    /// (`reduced + ECC@harmonic:2`).
    pub fn extended_label(&self, m: &Machine, label: &str) -> String {
        std::iter::once(label.to_string())
            .chain(self.findings.iter().map(|f| f.term.spelling(m)))
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

/// The seed of the Monte-Carlo draws of a step: a function of the model the step starts from
/// (the chosen terms but `skip`, in any order), so that the exchange pass, taking a finding out
/// of a model, repeats the forward step of that model exactly (the same draws, the same
/// decision) rather than testing it a second time with other draws.
fn context_seed(seed: u64, chosen: &[Chosen], skip: Option<usize>) -> u64 {
    let mut terms: Vec<usize> = chosen
        .iter()
        .enumerate()
        .filter(|(k, _)| Some(*k) != skip)
        .map(|(_, c)| c.index)
        .collect();
    terms.sort_unstable();
    terms.iter().fold(seed, |h, &t| {
        (h ^ (t as u64 + 1)).wrapping_mul(0x9e37_79b9_7f4a_7c15)
    })
}
