//! What the data cannot see apart: scanned candidates that are the same finding, candidates of
//! one span, the size of the change a candidate needs, and the candidates the final model spans
//! with the terms they are a combination of.

use super::Confounded;
use super::columns::Columns;
use super::projected::{orthonormalise, project_out, to_unit_norm};
use super::select::{SPAN_TOLERANCE, Scored, Span, gram};
use nalgebra::{DMatrix, DVector};
use simulation::model::{Basis, Effect, Model, Term};
use std::collections::HashMap;

/// When two scanned candidates of one family are the same effect, and so never two findings:
/// the scanned grids' spacings, taken from the candidates (the dictionary's grids,
/// [`super::dictionary::scanned`]).
///
/// - `step:V` of one error: V within one spacing of the error's step grid (the refinement of
///   either reaches the other, [`super::profile`]: a jump between two grid values is explained
///   by both, and both refine to it);
/// - `period:P` of one error: 1/P within one spacing of the error's period grid in 1/P (the
///   other's refinement interval), or P within 2 % (a period 0.3 % off the chosen one only
///   mops up what the coarse grid left);
/// - `exp:TAU` or `warmup:TAU` of one effect: TAU within a factor 3;
/// - `jump:T` of one effect: T within one spacing of its grid ([`super::dictionary::jumps`]),
///   as steps.
///
/// A spacing is the grid's extent over its number of intervals, with 1 % slack (and, for
/// steps and jumps, two thousandths) for the values' rounding to thousandths.
#[derive(Clone, Debug, Default)]
pub(super) struct SameFinding {
    /// Per effect, the spacing of its `step:V` grid (mm or degrees).
    step: HashMap<Effect, f64>,
    /// Per effect, the spacing of its `period:P` grid in 1/P (1/mm).
    period: HashMap<Effect, f64>,
    /// Per effect, the spacing of its `jump:T` grid (s).
    jump: HashMap<Effect, f64>,
}

impl SameFinding {
    /// The grids of the scanned candidates among `candidates`.
    pub fn of(candidates: &[Term]) -> SameFinding {
        let mut steps: HashMap<Effect, Vec<f64>> = HashMap::new();
        let mut periods: HashMap<Effect, Vec<f64>> = HashMap::new();
        let mut jumps: HashMap<Effect, Vec<f64>> = HashMap::new();
        for t in candidates {
            if let Some(v) = t.basis.step_at() {
                steps.entry(t.effect).or_default().push(v);
            } else if let Some(v) = t.basis.jump_at() {
                jumps.entry(t.effect).or_default().push(v);
            } else if let Some(p) = t.basis.period_mm() {
                periods.entry(t.effect).or_default().push(1.0 / p);
            }
        }
        let spacings = |m: HashMap<Effect, Vec<f64>>| -> HashMap<Effect, f64> {
            m.into_iter()
                .filter_map(|(e, mut v)| {
                    v.sort_by(f64::total_cmp);
                    v.dedup();
                    let (lo, hi) = (v.first()?, v.last()?);
                    (v.len() > 1).then(|| (e, (hi - lo) / (v.len() - 1) as f64))
                })
                .collect()
        };
        SameFinding {
            step: spacings(steps),
            period: spacings(periods),
            jump: spacings(jumps),
        }
    }

    /// `true` when `a` and `b` are the same effect (see the type).
    pub fn test(&self, a: &Term, b: &Term) -> bool {
        if a.effect != b.effect {
            return false;
        }
        match (a.basis, b.basis) {
            (Basis::Step(_), Basis::Step(_)) => {
                let (Some(u), Some(v)) = (a.basis.step_at(), b.basis.step_at()) else {
                    return false;
                };
                self.step
                    .get(&a.effect)
                    .is_some_and(|&s| (u - v).abs() <= 1.01 * s + 2e-3)
            }
            (Basis::Period(p), Basis::Period(q)) => {
                let (p, q) = (f64::from(p), f64::from(q));
                (p - q).abs() < 0.02 * q
                    || self
                        .period
                        .get(&a.effect)
                        .is_some_and(|&s| (1000.0 / p - 1000.0 / q).abs() <= 1.01 * s)
            }
            (Basis::Jump(u), Basis::Jump(v)) => self
                .jump
                .get(&a.effect)
                .is_some_and(|&s| ((u - v) as f64 / 1000.0).abs() <= 1.01 * s + 2e-3),
            (Basis::Exp(p), Basis::Exp(q)) | (Basis::Warmup(p), Basis::Warmup(q)) => {
                f64::from(p.max(q)) / f64::from(p.min(q).max(1)) < 3.0
            }
            _ => false,
        }
    }
}

/// `true` when two scored candidates add the same directions to the model (`‖aᵀb‖²` above
/// `q·(1 − 10⁻⁹)`, Frobenius), `rss` the residual sum of squares they were scored on.
///
/// Such spans are within an angle of `√(q·10⁻⁹)` of each other, so their ΔRSS differ by at
/// most that times `√rss` in square root: candidates whose ΔRSS differ by more are not
/// compared further.
pub(super) fn same_span(a: &Scored, b: &Scored, rss: f64) -> bool {
    let q = a.width;
    if q != b.width {
        return false;
    }
    let angle = (q as f64 * SAME_SPAN).sqrt();
    if (a.delta_rss.sqrt() - b.delta_rss.sqrt()).abs() > 2.0 * angle * rss.sqrt() {
        return false;
    }
    gram(&a.directions(), &b.directions()).norm_squared() > q as f64 * (1.0 - SAME_SPAN)
}

/// Two spans of q directions are the same when `‖aᵀb‖²` exceeds `q·(1 − SAME_SPAN)`.
const SAME_SPAN: f64 = 1e-9;

/// The norm of the least-squares coefficients (minimum norm) of `r` on the columns `projected`
/// (a candidate's columns scaled to unit norm, with the model projected out,
/// [`super::projected::Model::projected`]; a zero column, of a column of zero norm, is left
/// out): how large a change of the candidate explains what it explains.
pub(super) fn scaled_size(projected: &DMatrix<f64>, r: &DVector<f64>) -> f64 {
    let cols: Vec<DVector<f64>> = projected
        .column_iter()
        .filter(|c| c.iter().any(|v| *v != 0.0))
        .map(|c| c.into_owned())
        .collect();
    if cols.is_empty() {
        return f64::INFINITY;
    }
    let svd = DMatrix::from_columns(&cols).svd(true, true);
    let eps = svd.singular_values.max() * SPAN_TOLERANCE;
    svd.solve(r, eps).map_or(f64::INFINITY, |c| c.norm())
}

/// The candidates the final model spans, each with the model terms it is a combination of:
/// `extended` is the base model with the `chosen` candidates, whose whitened columns are those
/// of `columns`.
pub(super) fn confounded_with(
    extended: &Model,
    candidates: &[Term],
    chosen: &[usize],
    unexcited: &[Term],
    q: &Span,
    group: &dyn Fn(usize) -> DMatrix<f64>,
    columns: &Columns,
) -> Vec<Confounded> {
    let (nb, h_all, starts, widths) =
        (columns.nb, &columns.h_all, &columns.starts, &columns.widths);
    // The extended model's columns, scaled to unit norm, with their term indices in `extended`.
    let mut cols: Vec<DVector<f64>> = Vec::new();
    let mut owner: Vec<usize> = Vec::new();
    for ti in 0..extended.terms.len() {
        let all_index = if ti < nb { ti } else { nb + chosen[ti - nb] };
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
    // The candidates to look at, with the final model projected out (all in one product).
    let looked: Vec<usize> = (0..candidates.len())
        .filter(|&c| !chosen.contains(&c) && !unexcited.contains(&candidates[c]))
        .collect();
    let widths_of: Vec<usize> = looked.iter().map(|&c| widths[nb + c]).collect();
    // Each candidate's columns scaled to unit norm where they are held.
    let total: usize = widths_of.iter().sum();
    let mut data = Vec::with_capacity(q.rows() * total);
    for &c in &looked {
        let from = data.len();
        data.extend_from_slice(group(nb + c).as_slice());
        to_unit_norm(&mut data[from..], q.rows());
    }
    let mut projected = DMatrix::from_vec(q.rows(), total, data);
    project_out(&q.q, &mut projected);
    let mut at = 0;
    let mut out = Vec::new();
    let n = q.rows();
    for (&c, &w) in looked.iter().zip(&widths_of) {
        let spanned = orthonormalise(&mut projected.as_mut_slice()[n * at..n * (at + w)], n) == 0;
        at += w;
        if !spanned {
            continue;
        }
        let term = &candidates[c];
        let g = group(nb + c);
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

#[cfg(test)]
mod tests {
    use super::*;
    use model_spec::ErrorId;

    fn term(error: ErrorId, basis: Basis) -> Term {
        Term {
            effect: Effect::Error(error),
            basis,
        }
    }

    /// Steps within one spacing of their grid are one finding, two spacings apart are two;
    /// periods within one step of their 1/P grid or 2 % are one; warm-ups within a factor 3.
    #[test]
    fn same_finding_follows_the_grids() {
        // Steps of error 0 every 15° from 7.5°, of error 1 every 1°; periods of error 2 on a
        // grid in 1/P of spacing 0.001/mm from 1/100 mm.
        let mut candidates: Vec<Term> = (0..24)
            .map(|k| term(0, Basis::Step(7_500 + 15_000 * k)))
            .collect();
        candidates.extend((0..10).map(|k| term(1, Basis::Step(1000 * k))));
        candidates.extend((0..40).map(|k| {
            let p = 1.0 / (0.01 + 0.001 * k as f64);
            term(2, Basis::Period((p * 1000.0).round() as u32))
        }));
        let same = SameFinding::of(&candidates);
        let step = |e, v: f64| term(e, Basis::Step((v * 1000.0).round() as i64));
        assert!(same.test(&step(0, 217.5), &step(0, 232.5)));
        assert!(same.test(&step(0, 224.25), &step(0, 232.5)));
        assert!(!same.test(&step(0, 217.5), &step(0, 247.5)));
        assert!(!same.test(&step(0, 217.5), &step(1, 217.5)));
        assert!(same.test(&step(1, 3.0), &step(1, 4.0)));
        assert!(!same.test(&step(1, 3.0), &step(1, 5.0)));
        let period = |e, p: f64| term(e, Basis::Period((p * 1000.0).round() as u32));
        // 1/100 and 1/90.909: 0.001/mm apart (10 %, beyond 2 %).
        assert!(same.test(&period(2, 100.0), &period(2, 90.909)));
        assert!(!same.test(&period(2, 100.0), &period(2, 83.333)));
        // Near 20 mm one step of the grid is 2 %: the 2 % rule.
        assert!(same.test(&period(2, 20.0), &period(2, 20.3)));
        assert!(!same.test(&period(2, 20.0), &period(2, 21.0)));
        let exp = |e, t: u32| term(e, Basis::Exp(t));
        assert!(same.test(&exp(3, 10_000), &exp(3, 25_000)));
        assert!(!same.test(&exp(3, 10_000), &exp(3, 35_000)));
        // Different families are never the same finding.
        assert!(!same.test(&step(0, 217.5), &term(0, Basis::Harmonic(2))));
    }
}
