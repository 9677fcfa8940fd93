//! Forward selection with an exchange pass (docs/diagnosis.md §4–5): one candidate at a time,
//! the one that explains most of what is left, kept when its corrected p-value is below α;
//! then each finding is selected again given all the others.
//!
//! The candidates' columns are held with the model projected out ([`Projected`]) and updated
//! as the model grows or a finding is exchanged; a step of the exchange pass sees the model
//! without its finding without changing what is held. A step is a function of the model it
//! starts from (the set of chosen terms: its candidates, its span and the seed of its draws),
//! so a step already taken on a model (the exchange pass repeats forward steps) is not computed
//! again.

use super::confounded::{SameFinding, same_span, scaled_size};
use super::profile::Scan;
use super::projected::{Model, Projected};
use super::select::{
    SPAN_TOLERANCE, Scored, Span, beyond, coordinates, f_p_value, f_statistic, monte_carlo_p,
};
use super::{Correction, DiagnoseOptions, Stop};
use fitting::distributions::f_upper_tail;
use model_spec::Machine;
use nalgebra::{DMatrix, DVector};
use simulation::model::Term;
use std::collections::HashMap;

/// What the selection works on: the columns of the base model and of every candidate, and the
/// readings.
pub(super) struct Problem<'a> {
    /// The machine.
    pub m: &'a Machine,
    /// The candidates.
    pub candidates: &'a [Term],
    /// Number of base terms: group `t < nb` is base term `t`, group `nb + c` candidate `c`.
    pub nb: usize,
    /// The H-matrix columns of a group.
    pub group: &'a dyn Fn(usize) -> DMatrix<f64>,
    /// The readings (mm; or whitened).
    pub y: &'a DVector<f64>,
    /// The base model's residual sum of squares.
    pub rss_base: f64,
    /// The candidates that vary on the record.
    pub live: &'a [usize],
    /// The options.
    pub o: &'a DiagnoseOptions,
    /// Told of every candidate scored in a step (`selection`, done of the step's pool).
    pub progress: &'a dyn formats::progress::Progress,
    /// A scanned candidate's parameter refined given a model (its span), with the refined
    /// term's columns; `None` for a candidate without a scanned parameter.
    pub refine: &'a dyn Fn(usize, &Span) -> Option<Refined>,
}

/// A scanned candidate's parameter refined with the other terms of the model in place.
#[derive(Clone, Debug)]
pub(super) struct Refined {
    /// The term at the refined value.
    pub term: Term,
    /// The value and its interval.
    pub scan: Scan,
    /// Its columns, as the problem's groups give them.
    pub columns: DMatrix<f64>,
}

/// A step of the selection, before the extended fit gives its values.
#[derive(Clone, Debug)]
pub(super) struct Chosen {
    /// The candidate's index.
    pub index: usize,
    /// The candidates the data cannot tell from it.
    pub alternatives: Vec<usize>,
    /// Share of the base residual sum of squares it explains.
    pub fraction: f64,
    /// Its F statistic.
    pub f: f64,
    /// How its p-value was corrected.
    pub correction: Correction,
    /// Candidates tried at its step.
    pub tried: usize,
    /// Its corrected p-value.
    pub p: f64,
    /// For a scanned candidate, its parameter refined when it was chosen (the model then holds
    /// the refined term's columns).
    pub refined: Option<Refined>,
}

/// The columns of a chosen term: its refined term's, or its candidate's.
fn columns_of(p: &Problem, c: &Chosen) -> DMatrix<f64> {
    match &c.refined {
        Some(r) => r.columns.clone(),
        None => (p.group)(p.nb + c.index),
    }
}

/// The model's basis: the base and the chosen terms (but `skip`; a refined term's columns).
pub(super) fn basis_of(p: &Problem, chosen: &[Chosen], skip: Option<usize>) -> Span {
    let mut span = Span::of_groups(p.y.len(), 0..p.nb, p.group);
    for (_, c) in chosen.iter().enumerate().filter(|(k, _)| Some(*k) != skip) {
        let d = span.new_directions(&columns_of(p, c));
        span.extend(&d);
    }
    span
}

/// `c` with its scanned parameter refined given `model` (without it), and the directions it
/// adds to that model.
fn refined(p: &Problem, mut c: Chosen, model: &Model) -> (Chosen, DMatrix<f64>) {
    c.refined = (p.refine)(c.index, model.span());
    let d = match &c.refined {
        Some(r) => model.span().new_directions(&r.columns),
        None => model.directions(c.index),
    };
    (c, d)
}

/// The forward selection and its exchange pass: the findings in order, and why it stopped.
pub(super) fn select(p: &Problem) -> (Vec<Chosen>, Stop) {
    let Problem {
        m,
        candidates,
        nb,
        group,
        y,
        rss_base,
        live: candidates_live,
        o,
        progress,
        refine: _,
    } = *p;
    let n = y.len();
    // One selection step on `model` over the candidates `pool`: the significant candidate
    // named, or why there is none.
    let step = |model: &Model, pool: &[usize], seed: u64| -> Result<Chosen, Stop> {
        let q = model.span();
        let r = model.residual();
        let rss = r.norm_squared();
        let total = pool.len() as u64;
        progress.update("selection", 0, total);
        // Every candidate's number of directions and the residual's coordinates on them, from
        // its Gram matrix ([`Model::score`]; or from its directions where that would lose
        // digits); the directions of the few candidates a step looks at are made when asked
        // for ([`Scored::directions`]).
        let make = |c: usize| model.directions(c);
        // Scored on every core (each candidate alone), taken in the pool's order.
        let scores = crate::parallel::map_in_order(pool, |&c| {
            model.score(c).unwrap_or_else(|| {
                let d = model.directions(c);
                (d.ncols(), coordinates(&d.columns(0, d.ncols()), r))
            })
        });
        progress.update("selection", total, total);
        let scored: Vec<Scored> = pool
            .iter()
            .zip(scores)
            .filter(|(_, (width, _))| *width > 0)
            .map(|(&c, (width, on))| Scored::made_by(c, width, on, &make))
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
        // EZC harmonic:1 when the base lacks AOC), then a drift of the R-test's zero (below),
        // then an error of an axis line (location,
        // squareness, set-up: the squareness AOZ rather than the pitch EAY, the straightness
        // EYZ poly:1 or the angular error EAZ poly:1 that read the same at the ball), then
        // another constant, then the one that needs the smallest change to do it (coefficients
        // of its unit-norm columns): the one least entangled with the model (with a base
        // lacking XOW, ECC@reversal, a constant on K4, spans what XOW spans only through YOW,
        // with 0.043 rad for 12 µm), then the first in the dictionary's order (columns that
        // are the same to rounding need the same change: the straightness EXZ poly:4 rather
        // than the pitch EBZ poly:4).
        // A drift or warm-up that the zero offsets of the R-test explain as well as an axis
        // line is named as the instrument's: the first suspect of a slow change over a record,
        // and a random-walk drift of the instrument is never named a geometric cause.
        // A jump in time of one record comes last: a term of the machine or a drift that the
        // fitted records cannot tell from it is named, with the jump among its alternatives,
        // and the judging records decide between them (the jump predicts nothing on them).
        let rank = |t: &Term| -> u8 {
            use model_spec::ErrorKind::{Location, Setup, Squareness};
            match (t.effect, t.basis) {
                (_, b) if b.jump_at().is_some() => 3,
                (model_spec::terms::Effect::SensorOffset(_), b) if b.of_time() => 0,
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
                .filter(|(_, s)| same_span(one, s, rss))
                .map(|(k, s)| {
                    let g = model.projected(s.index);
                    (
                        k,
                        (g.ncols(), rank(&candidates[s.index]), scaled_size(&g, r)),
                    )
                })
                .min_by(|a, b| {
                    (a.1.0, a.1.1)
                        .cmp(&(b.1.0, b.1.1))
                        .then(rounded_cmp(a.1.2, b.1.2))
                })
                .map_or(0, |(k, _)| k)
        };
        let best = &scored[prefer(best)];
        let qg = best.width;
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
            let (gain, extra) = beyond(a, b, r);
            let dim = b.width + extra;
            (gain, extra, rss - b.delta_rss - gain, dim)
        };
        // The raw F-test at α of an addition of `extra` directions explaining `gain`, `dim` in
        // all with `b`: `true` when it is not significant.
        let not_significant = |gain: f64, extra: usize, rest: f64, dim: usize| -> bool {
            let Some(dof) = n.checked_sub(q.rank() + dim).filter(|&d| d > 0) else {
                return false;
            };
            let f = (gain.max(0.0) / extra as f64) / (rest / dof as f64);
            f.is_finite() && f_upper_tail(f, extra as f64, dof as f64) >= o.alpha
        };
        // `true` when `a` adds nothing significant to `b` (raw F-test at α).
        let adds_nothing = |a: &Scored, b: &Scored| -> bool {
            // What `a` adds is at least `(√ΔRSS_a − δ)² − ΔRSS_b`, δ what directions of `a`
            // within the span tolerance of `b` can hide (then at least one direction is
            // added). When that bound is significant whatever the number of directions added
            // (the F-test's p-value falls as the gain grows), the directions are not made:
            // most candidates are far from one another.
            let qa = a.width;
            let delta = 2.0 * (qa as f64).sqrt() * SPAN_TOLERANCE * rss.sqrt();
            let low = (a.delta_rss.sqrt() - delta).max(0.0).powi(2) - b.delta_rss;
            let qb = b.width;
            let rest = rss - b.delta_rss - low;
            if a.delta_rss.sqrt() - b.delta_rss.sqrt() > delta
                && rest > 0.0
                && (1..=qa).all(|extra| !not_significant(low, extra, rest, qb + extra))
            {
                return false;
            }
            let (gain, extra, rest, dim) = beyond(a, b);
            extra == 0 || not_significant(gain, extra, rest, dim)
        };
        // Parsimony: a narrower candidate that explains what the best one explains, as far as
        // the data can tell, is named instead. (EXX poly:1 lies exactly inside the span of EXC
        // harmonic:1 on any path where X follows the ball of an A-C table, and the largest ΔRSS
        // always goes to the wider group.) Narrower: fewer directions; it adds nothing
        // significant to the best one, and the best one adds nothing significant to it. The
        // step's significance (the test above) is unchanged.
        let named = scored
            .iter()
            .filter(|s| s.index != best.index && s.width < qg)
            .filter(|s| adds_nothing(best, s) && adds_nothing(s, best))
            .max_by(|a, b| a.delta_rss.total_cmp(&b.delta_rss))
            .map_or(best, |s| &scored[prefer(s)]);
        // A jump in time of one record is named only where no other candidate explains what it
        // explains as far as the data can tell (each adds nothing significant to the other, at
        // no more directions): on K4, where C turns with time, a step of C is a jump of the
        // ball's set-up at the instant C passes it. The other is named, the jump among its
        // alternatives, and the judging records decide (the jump predicts nothing on them).
        let is_jump = |s: &Scored| candidates[s.index].basis.jump_at().is_some();
        let named = if is_jump(named) {
            scored
                .iter()
                .filter(|s| !is_jump(s) && s.width <= named.width)
                .filter(|s| adds_nothing(named, s) && adds_nothing(s, named))
                .max_by(|a, b| a.delta_rss.total_cmp(&b.delta_rss))
                .map_or(named, |s| &scored[prefer(s)])
        } else {
            named
        };
        // Candidates of the named one's span (the extended model spans them).
        let spanned: Vec<usize> = scored
            .iter()
            .filter(|s| s.index != named.index && same_span(named, s, rss))
            .map(|s| s.index)
            .collect();
        // Candidates the data cannot tell from the named one: those of its span, and those to
        // which the named one adds nothing significant (they explain what it explains); most
        // explaining first.
        let mut alike: Vec<&Scored> = scored
            .iter()
            .filter(|s| s.index != named.index)
            .filter(|s| spanned.contains(&s.index) || adds_nothing(named, s))
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
            refined: None,
        })
    };
    // The candidates a step may take: the excited ones that are not chosen (but `skip`), nor
    // the same finding as a chosen one: a scanned candidate next to a chosen one of the same
    // effect only mops up what the coarse grid left ([`SameFinding`]).
    let same = SameFinding::of(candidates);
    let pool_of = |chosen: &[Chosen], skip: Option<usize>| -> Vec<usize> {
        candidates_live
            .iter()
            .copied()
            .filter(|&c| {
                !chosen.iter().enumerate().any(|(k, x)| {
                    Some(k) != skip
                        && (x.index == c || same.test(&candidates[c], &candidates[x.index]))
                })
            })
            .collect()
    };
    // The steps taken, by the model they start from (its `context`): a step is a function of
    // that model, and the exchange pass repeats forward steps.
    let mut taken: HashMap<Vec<usize>, Result<Chosen, Stop>> = HashMap::new();

    // Forward steps until nothing significant is left; then an exchange pass: each finding in
    // turn is taken out and its slot selected again given all the others, so that a term
    // chosen while another effect was still unexplained (EXC harmonic:1 carrying part of ECC
    // harmonic:2 before it, where EXX poly:1 is the cause) is renamed, or dropped when it is no
    // longer significant. Repeated while the exchange changes something (at most 4 rounds).
    // `state` holds the model of the base and every chosen term.
    let mut state = Projected::new(
        basis_of(p, &[], None),
        y,
        candidates.len(),
        candidates_live,
        &|c| group(nb + c),
    );
    let mut chosen: Vec<Chosen> = Vec::new();
    let mut stop;
    let mut round = 0;
    loop {
        loop {
            let context = context(&chosen, None);
            let result = match taken.get(&context) {
                Some(known) => known.clone(),
                None => {
                    let seed = context_seed(o.seed, &context);
                    let r = step(&state.model(), &pool_of(&chosen, None), seed);
                    taken.insert(context, r.clone());
                    r
                }
            };
            match result {
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
                    // A scanned parameter refined at once, the model grown by the refined term:
                    // the next step sees the refined residual.
                    let (c, d) = refined(p, c, &state.model());
                    state.grow(&d, y);
                    chosen.push(c);
                }
            }
        }
        let mut changed = false;
        let mut j = 0;
        while j < chosen.len() {
            // The model without finding `j`: its span, and what the finding adds to it.
            let without = || {
                let span = basis_of(p, &chosen, Some(j));
                let d = span.new_directions(&columns_of(p, &chosen[j]));
                (span, d)
            };
            let context = context(&chosen, Some(j));
            let result = match taken.get(&context) {
                Some(known) => known.clone(),
                None => {
                    let (span, d) = without();
                    let seed = context_seed(o.seed, &context);
                    let model = state.without(span, d, y);
                    let r = step(&model, &pool_of(&chosen, Some(j)), seed);
                    taken.insert(context, r.clone());
                    r
                }
            };
            // The state changes only when the finding does.
            match result {
                Ok(mut c) if c.index == chosen[j].index => {
                    c.refined = chosen[j].refined.take();
                    chosen[j] = c;
                    j += 1;
                }
                Ok(c) => {
                    let (span, d) = without();
                    state.shrink(span, &d, y);
                    let (c, d) = refined(p, c, &state.model());
                    state.grow(&d, y);
                    chosen[j] = c;
                    changed = true;
                    j += 1;
                }
                Err(_) => {
                    let (span, d) = without();
                    state.shrink(span, &d, y);
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

    (chosen, stop)
}

/// `a` against `b`, equal when within a relative 10⁻⁹: sizes of candidates whose columns are the
/// same to rounding (an angular error of Z and a straightness of Z read at the ball) are equal,
/// and the first candidate in the dictionary's order is named rather than the one rounding
/// favours.
fn rounded_cmp(a: f64, b: f64) -> std::cmp::Ordering {
    if (a - b).abs() <= 1e-9 * a.abs().max(b.abs()) {
        std::cmp::Ordering::Equal
    } else {
        a.total_cmp(&b)
    }
}

/// The model a step starts from: the chosen terms but `skip`, sorted (the base is in every
/// model).
fn context(chosen: &[Chosen], skip: Option<usize>) -> Vec<usize> {
    let mut terms: Vec<usize> = chosen
        .iter()
        .enumerate()
        .filter(|(k, _)| Some(*k) != skip)
        .map(|(_, c)| c.index)
        .collect();
    terms.sort_unstable();
    terms
}

/// The seed of the Monte-Carlo draws of a step: a function of the model the step starts from
/// (its [`context`]), so that the exchange pass, taking a finding out
/// of a model, repeats the forward step of that model exactly (the same draws, the same
/// decision) rather than testing it a second time with other draws.
fn context_seed(seed: u64, context: &[usize]) -> u64 {
    context.iter().fold(seed, |h, &t| {
        (h ^ (t as u64 + 1)).wrapping_mul(0x9e37_79b9_7f4a_7c15)
    })
}
