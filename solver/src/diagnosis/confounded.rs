//! What the data cannot see apart: candidates of one span, the size of the change a candidate
//! needs, and the candidates the final model spans with the terms they are a combination of.

use super::Confounded;
use super::projected::{orthonormalise, project_out, unit_columns};
use super::select::{SPAN_TOLERANCE, Scored, Span, gram};
use crate::model::{Model, Term};
use nalgebra::{DMatrix, DVector};

/// `true` when two scored candidates add the same directions to the model (`‖aᵀb‖²` above
/// `q·(1 − 10⁻⁹)`, Frobenius), `rss` the residual sum of squares they were scored on.
///
/// Such spans are within an angle of `√(q·10⁻⁹)` of each other, so their ΔRSS differ by at
/// most that times `√rss` in square root: candidates whose ΔRSS differ by more are not
/// compared further.
pub(super) fn same_span(a: &Scored, b: &Scored, rss: f64) -> bool {
    let q = a.directions.ncols();
    if q != b.directions.ncols() {
        return false;
    }
    let angle = (q as f64 * SAME_SPAN).sqrt();
    if (a.delta_rss.sqrt() - b.delta_rss.sqrt()).abs() > 2.0 * angle * rss.sqrt() {
        return false;
    }
    gram(&a.directions, &b.directions).norm_squared() > q as f64 * (1.0 - SAME_SPAN)
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

/// The candidates the final model spans, each with the model terms it is a combination of.
#[allow(clippy::too_many_arguments)]
pub(super) fn confounded_with(
    extended: &Model,
    candidates: &[Term],
    chosen: &[usize],
    unexcited: &[Term],
    q: &Span,
    group: &dyn Fn(usize) -> DMatrix<f64>,
    nb: usize,
    h_all: &DMatrix<f64>,
    starts: &[usize],
    widths: &[usize],
) -> Vec<Confounded> {
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
    let mut projected = DMatrix::zeros(q.rows(), widths_of.iter().sum());
    let mut at = 0;
    for (&c, &w) in looked.iter().zip(&widths_of) {
        projected
            .columns_mut(at, w)
            .copy_from(&unit_columns(&group(nb + c)));
        at += w;
    }
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
