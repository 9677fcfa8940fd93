//! What the data cannot see apart: candidates of one span, the size of the change a candidate
//! needs, and the candidates the final model spans with the terms they are a combination of.

use super::Confounded;
use super::select::{SPAN_TOLERANCE, Scored, Span};
use crate::model::{Model, Term};
use nalgebra::{DMatrix, DVector};

/// `true` when two scored candidates add the same directions to the model.
pub(super) fn same_span(a: &Scored, b: &Scored) -> bool {
    let q = a.directions.ncols();
    q == b.directions.ncols()
        && (a.directions.tr_mul(&b.directions)).norm_squared() > q as f64 * (1.0 - 1e-9)
}

/// The norm of the least-squares coefficients (minimum norm) of `r` on the columns of `g`, each
/// scaled to unit norm and with the model `q` projected out: how large a change of the
/// candidate explains what it explains.
pub(super) fn scaled_size(q: &Span, g: &DMatrix<f64>, r: &DVector<f64>) -> f64 {
    let cols: Vec<DVector<f64>> = g
        .column_iter()
        .filter_map(|c| {
            let norm = c.norm();
            (norm > 0.0 && norm.is_finite()).then(|| q.project_out(&(c.into_owned() / norm)))
        })
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
