//! Every candidate's columns with the model's span projected out, kept up to date as the model
//! changes, so that a selection step costs a rank-q update instead of a projection of every
//! candidate against the whole model.
//!
//! What a step needs of candidate `g` is what [`Span::new_directions`] gives: its columns scaled
//! to unit norm, with the model `Q` projected out, orthonormalised in order (a direction kept
//! when its norm exceeds [`SPAN_TOLERANCE`]). Here the projected columns `P⊥Q·C̃` of every
//! candidate are held in one matrix, before the orthonormalisation (so that what is kept and
//! what is dropped is decided on the same norms as from scratch), and
//!
//! - when the model grows by orthonormal directions `U` (orthogonal to `Q`), each is updated by
//!   `P ← P − U·(Uᵀ·P)`, applied twice (as [`Span::project_out`] projects twice): `P⊥[Q U] =
//!   P⊥U·P⊥Q`;
//! - when a term leaves the model, with `W` the directions it adds to the model without it,
//!   `P ← P + W·(Wᵀ·C̃)`: `P⊥Q' = P⊥Q + W·Wᵀ` for `Q = [Q' W]`. A step of the exchange pass
//!   sees the model without a finding this way without changing what is held
//!   ([`Projected::without`]): only a finding exchanged for another changes it.
//!
//! A step scores each candidate from the small Gram matrix of its projected columns, read where
//! they are held, without making its directions ([`Model::score`]); the directions are made
//! for the few candidates a step compares ([`Model::directions`]). The residual `P⊥Q·y` is
//! computed from the span (one vector).

use super::select::{SPAN_TOLERANCE, Span};
use nalgebra::{DMatrix, DVector, DVectorView};

/// The candidates' columns with a model's span projected out.
#[derive(Clone, Debug)]
pub struct Projected {
    /// The model's span.
    span: Span,
    /// The readings with the span projected out.
    residual: DVector<f64>,
    /// Every held candidate's columns scaled to unit norm (a column of zero or non-finite norm
    /// is zero: it adds no direction), n × total.
    unit: DMatrix<f64>,
    /// The same with the span projected out.
    columns: DMatrix<f64>,
    /// Per candidate: its first column in `unit` and `columns`, and its width (0: not held).
    at: Vec<(usize, usize)>,
}

impl Projected {
    /// Candidates `held` (indices below `count`, `columns(c)` the columns of candidate `c`)
    /// with `span` projected out; `y` the readings.
    pub fn new(
        span: Span,
        y: &DVector<f64>,
        count: usize,
        held: &[usize],
        columns: &dyn Fn(usize) -> DMatrix<f64>,
    ) -> Projected {
        let n = span.rows();
        let mut at = vec![(0usize, 0usize); count];
        // Column after column, as the matrix holds them: one candidate's columns at a time,
        // never all of them twice.
        let mut data = Vec::new();
        let mut total = 0;
        for &c in held {
            let g = columns(c);
            at[c] = (total, g.ncols());
            total += g.ncols();
            // Scaled to unit norm where they are held.
            let from = data.len();
            data.extend_from_slice(g.as_slice());
            to_unit_norm(&mut data[from..], n);
        }
        let unit = DMatrix::from_vec(n, total, data);
        let mut columns = unit.clone();
        project_out(&span.q, &mut columns);
        let residual = span.project_out(y);
        Projected {
            span,
            residual,
            unit,
            columns,
            at,
        }
    }

    /// The model held.
    pub fn model(&self) -> Model<'_> {
        Model {
            state: self,
            span: None,
            residual: None,
            removed: None,
        }
    }

    /// The model held without a term: `without` its span without the term, `directions` what
    /// the term adds to it (`without.new_directions(term's columns)`), so that `without` and
    /// `directions` together span the model held. Nothing held changes.
    pub fn without(&self, without: Span, directions: DMatrix<f64>, y: &DVector<f64>) -> Model<'_> {
        Model {
            state: self,
            residual: Some(without.project_out(y)),
            span: Some(without),
            removed: (directions.ncols() > 0).then_some(directions),
        }
    }

    /// The model grown by `directions` (orthonormal, orthogonal to the span: from
    /// [`Model::directions`] or [`Span::new_directions`]).
    pub fn grow(&mut self, directions: &DMatrix<f64>, y: &DVector<f64>) {
        if directions.ncols() == 0 {
            return;
        }
        project_out(directions, &mut self.columns);
        self.span.extend(directions);
        self.residual = self.span.project_out(y);
    }

    /// The model without a term (as [`Projected::without`]), held from now on.
    pub fn shrink(&mut self, without: Span, directions: &DMatrix<f64>, y: &DVector<f64>) {
        let n = self.span.rows();
        if directions.ncols() > 0 && n > 0 {
            let (unit, columns) = (self.unit.as_slice(), self.columns.as_mut_slice());
            for (from, to) in unit.chunks_exact(n).zip(columns.chunks_exact_mut(n)) {
                add_projection(directions, from, to);
            }
        }
        self.span = without;
        self.residual = self.span.project_out(y);
    }
}

/// A model a step starts from, as [`Projected`] sees it: the model held, or the model held
/// without a term.
#[derive(Clone, Debug)]
pub struct Model<'a> {
    /// What is held.
    state: &'a Projected,
    /// The span without the term (`None`: the span held).
    span: Option<Span>,
    /// The residual without the term (`None`: the residual held).
    residual: Option<DVector<f64>>,
    /// The directions the term adds to `span`, added back to every candidate's columns.
    removed: Option<DMatrix<f64>>,
}

impl Model<'_> {
    /// The model's span.
    pub fn span(&self) -> &Span {
        self.span.as_ref().unwrap_or(&self.state.span)
    }

    /// The readings with the model's span projected out.
    pub fn residual(&self) -> &DVector<f64> {
        self.residual.as_ref().unwrap_or(&self.state.residual)
    }

    /// The columns of candidate `c`: unit norm, the model projected out (a column of zero norm
    /// stays zero).
    pub fn projected(&self, c: usize) -> DMatrix<f64> {
        let n = self.state.span.rows();
        let (start, width) = self.state.at[c];
        // Copied from where they are held (not zeroed first, then copied over).
        let mut out = DMatrix::from_column_slice(
            n,
            width,
            &self.state.columns.as_slice()[n * start..n * (start + width)],
        );
        if let Some(w) = &self.removed {
            let unit = &self.state.unit.as_slice()[n * start..n * (start + width)];
            for (from, to) in unit
                .chunks_exact(n)
                .zip(out.as_mut_slice().chunks_exact_mut(n))
            {
                add_projection(w, from, to);
            }
        }
        out
    }

    /// The orthonormal directions candidate `c` adds to the model: as
    /// `span.new_directions(columns(c))`.
    pub fn directions(&self, c: usize) -> DMatrix<f64> {
        let mut out = self.projected(c);
        let kept = orthonormalise(out.as_mut_slice(), self.state.span.rows());
        if kept < out.ncols() {
            out = out.resize_horizontally(kept, 0.0);
        }
        out
    }

    /// The number of directions candidate `c` adds to the model ([`Model::directions`]) and
    /// the residual's coordinates on them, without making them: from the Gram matrix `CᵀC` of
    /// its projected columns `C` and `Cᵀr`, read where they are held (without a term `W`,
    /// `C' = C + W·A` with `A = Wᵀ·C̃` and `C ⊥ W`: `C'ᵀC' = CᵀC + AᵀA`, `C'ᵀr = Cᵀr + Aᵀ·Wᵀr`).
    /// A Cholesky factorisation `L·Lᵀ` in column order drops a column as [`orthonormalise`]
    /// does (the square root of its pivot is the norm of its part outside the previous
    /// directions), and the coordinates are `L⁻¹·Cᵀr`. `None` when a column of norm above
    /// [`SPAN_TOLERANCE`] has less than a tenth of it outside the previous ones: the Gram
    /// matrix would lose digits that the directions keep, and they are made instead.
    pub fn score(&self, c: usize) -> Option<(usize, DVector<f64>)> {
        let (start, width) = self.state.at[c];
        fn column(m: &DMatrix<f64>, j: usize) -> &[f64] {
            &m.as_slice()[m.nrows() * j..][..m.nrows()]
        }
        let r = self.residual().as_slice();
        // The upper triangle of `CᵀC` (the factorisation reads no other).
        let held = |i: usize| column(&self.state.columns, start + i);
        let mut g = DMatrix::from_fn(width, width, |i, j| {
            if i <= j { dot(held(i), held(j)) } else { 0.0 }
        });
        let mut b = DVector::from_fn(width, |j, _| dot(held(j), r));
        if let Some(w) = &self.removed {
            let a = DMatrix::from_fn(w.ncols(), width, |i, j| {
                dot(w.column(i).as_slice(), column(&self.state.unit, start + j))
            });
            let wr = w.tr_mul(self.residual());
            g += a.tr_mul(&a);
            b += a.tr_mul(&wr);
        }
        // Row j of `l`: column j's coefficients on the directions kept before it.
        let mut l = DMatrix::zeros(width, width);
        let mut kept: Vec<usize> = Vec::with_capacity(width);
        let mut coordinates: Vec<f64> = Vec::with_capacity(width);
        let floor = SPAN_TOLERANCE * SPAN_TOLERANCE;
        for j in 0..width {
            let mut pivot = g[(j, j)];
            for (k, &i) in kept.iter().enumerate() {
                let s: f64 = (0..k).map(|m| l[(j, m)] * l[(i, m)]).sum();
                l[(j, k)] = (g[(i, j)] - s) / l[(i, k)];
                pivot -= l[(j, k)] * l[(j, k)];
            }
            if g[(j, j)] > floor && pivot < 1e-2 * g[(j, j)] {
                return None;
            }
            if pivot > floor {
                let k = kept.len();
                l[(j, k)] = pivot.sqrt();
                let s: f64 = (0..k).map(|m| l[(j, m)] * coordinates[m]).sum();
                coordinates.push((b[j] - s) / l[(j, k)]);
                kept.push(j);
            }
        }
        Some((kept.len(), DVector::from_vec(coordinates)))
    }
}

/// Columns `m` (of `n` rows each, one after the other) scaled to unit norm in place: each
/// divided by its norm; a column of zero or non-finite norm is zero (it adds no direction, as in
/// [`Span::new_directions`]).
pub fn to_unit_norm(m: &mut [f64], n: usize) {
    if n == 0 {
        return;
    }
    for col in m.chunks_exact_mut(n) {
        let norm = DVectorView::from_slice(col, n).norm();
        if norm > 0.0 && norm.is_finite() {
            col.iter_mut().for_each(|x| *x /= norm);
        } else {
            col.fill(0.0);
        }
    }
}

/// Columns `m` (of `n` rows each, one after the other: unit columns with a model projected
/// out) orthonormalised in place, in order, by Gram–Schmidt with re-orthogonalisation; a
/// column whose part outside the previous directions has a norm at most [`SPAN_TOLERANCE`]
/// adds none. The directions kept are moved to the front; their number. With [`project_out`]
/// and [`to_unit_norm`], what [`Span::new_directions`] gives.
pub fn orthonormalise(m: &mut [f64], n: usize) -> usize {
    if n == 0 {
        return 0;
    }
    let width = m.len() / n;
    let mut kept = 0;
    for j in 0..width {
        let (done, rest) = m.split_at_mut(n * j);
        let v = &mut rest[..n];
        for _ in 0..2 {
            for a in done[..n * kept].chunks_exact(n) {
                let d = dot(a, v);
                axpy(-d, a, v);
            }
        }
        let norm = dot(v, v).sqrt();
        if norm > SPAN_TOLERANCE {
            v.iter_mut().for_each(|x| *x /= norm);
            if kept < j {
                let (done, rest) = m.split_at_mut(n * j);
                done[n * kept..n * (kept + 1)].copy_from_slice(&rest[..n]);
            }
            kept += 1;
        }
    }
    kept
}

/// `m` with the span of the orthonormal columns `q` projected out, twice (classical
/// Gram–Schmidt with re-orthogonalisation, as [`Span::project_out`] for each column).
pub fn project_out(q: &DMatrix<f64>, m: &mut DMatrix<f64>) {
    let n = q.nrows();
    if q.ncols() == 0 || m.ncols() == 0 || n == 0 {
        return;
    }
    if q.ncols() > SMALL_RANK {
        // Qᵀ as a matrix of its own: the products then go to the blocked matrix multiplication
        // (`gemm_tr` takes one dot product per coefficient).
        let qt = q.transpose();
        let mut coefficients = DMatrix::zeros(q.ncols(), m.ncols());
        for _ in 0..2 {
            coefficients.gemm(1.0, &qt, m, 0.0);
            m.gemm(-1.0, q, &coefficients, 1.0);
        }
    } else {
        // A few directions: column by column, each column kept in cache for both passes.
        // The columns are independent: shared out over the cores.
        crate::parallel::for_each_column(m.as_mut_slice(), n, |column| {
            let mut c = [0.0f64; SMALL_RANK];
            for _ in 0..2 {
                for (u, c) in q.column_iter().zip(c.iter_mut()) {
                    *c = dot(u.as_slice(), column);
                }
                for (u, c) in q.column_iter().zip(c) {
                    axpy(-c, u.as_slice(), column);
                }
            }
        });
    }
}

/// Up to this many directions, [`project_out`] works column by column (the blocked product
/// needs more than five on every side).
const SMALL_RANK: usize = 8;

/// `to += Q·(Qᵀ·from)`, `Q` orthonormal columns, `from` and `to` columns of its rows.
fn add_projection(q: &DMatrix<f64>, from: &[f64], to: &mut [f64]) {
    for u in q.column_iter() {
        let c = dot(u.as_slice(), from);
        axpy(c, u.as_slice(), to);
    }
}

/// `a · b`, with sixteen partial sums (so that the compiler keeps several vector
/// accumulators busy).
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    const LANES: usize = 16;
    let mut s = [0.0f64; LANES];
    let (ca, cb) = (a.chunks_exact(LANES), b.chunks_exact(LANES));
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in ca.zip(cb) {
        for k in 0..LANES {
            s[k] += x[k] * y[k];
        }
    }
    let mut width = LANES;
    while width > 1 {
        width /= 2;
        for k in 0..width {
            s[k] += s[k + width];
        }
    }
    s[0] + tail
}

/// `y += alpha · x`.
fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    for (y, x) in y.iter_mut().zip(x) {
        *y += alpha * x;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic matrix of rows × cols with entries in (−1, 1).
    fn matrix(rows: usize, cols: usize, seed: u64) -> DMatrix<f64> {
        let mut rng = simulation::rng::Rng::new(seed);
        DMatrix::from_fn(rows, cols, |_, _| rng.normal())
    }

    fn groups() -> Vec<DMatrix<f64>> {
        let mut g: Vec<DMatrix<f64>> = (0..6).map(|k| matrix(40, 1 + k % 3, k as u64)).collect();
        // A candidate inside the span of candidates 0 and 1, one with a zero column, one
        // nearly inside candidate 0, one of two nearly dependent columns.
        let inside = &g[0].column(0) * 2.0 - &g[1].column(1) * 0.5;
        g.push(DMatrix::from_columns(&[inside]));
        let mut zero = matrix(40, 2, 9);
        zero.column_mut(0).fill(0.0);
        g.push(zero);
        let near = g[0].column(0) + matrix(40, 1, 10).column(0) * 1e-9;
        g.push(DMatrix::from_columns(&[near]));
        let x = matrix(40, 1, 11).column(0).into_owned();
        let close = &x + matrix(40, 1, 12).column(0) * 1e-3;
        g.push(DMatrix::from_columns(&[x, close]));
        g
    }

    /// The directions of every held candidate agree with `Span::new_directions` from scratch
    /// (same number, same span, same ΔRSS) as the model grows and as a term leaves it, seen
    /// without it or held without it.
    #[test]
    fn updates_agree_with_projections_from_scratch() {
        let g = groups();
        let y = matrix(40, 1, 20).column(0).into_owned();
        let held: Vec<usize> = (0..g.len()).collect();
        let span = |model: &[usize]| Span::of_groups(40, model.iter().copied(), &|t| g[t].clone());
        let check = |p: &Model, model: &[usize]| {
            let q = span(model);
            assert_eq!(p.span().rank(), q.rank(), "model {model:?}");
            let r = q.project_out(&y);
            assert!((p.residual() - &r).norm() < 1e-12);
            for (c, gc) in g.iter().enumerate() {
                let scratch = q.new_directions(gc);
                let here = p.directions(c);
                assert_eq!(
                    here.ncols(),
                    scratch.ncols(),
                    "candidate {c}, model {model:?}"
                );
                // The score from the Gram matrix: the same width, the same coordinates (where
                // it is made that way: not for the one of two nearly dependent columns).
                let on = here.tr_mul(p.residual());
                match (c, p.score(c)) {
                    (9, score) => assert!(score.is_none(), "model {model:?}"),
                    (_, Some((width, coordinates))) => {
                        assert_eq!(width, here.ncols(), "candidate {c}");
                        assert!((coordinates - &on).norm() <= 1e-12 * on.norm().max(1.0));
                    }
                    (_, None) => panic!("candidate {c}, model {model:?}"),
                }
                if here.ncols() > 0 {
                    let same = here.tr_mul(&scratch).norm_squared();
                    assert!((same - here.ncols() as f64).abs() < 1e-9, "{c}: {same}");
                    let a = here.tr_mul(&r).norm_squared();
                    let b = scratch.tr_mul(&r).norm_squared();
                    assert!((a - b).abs() <= 1e-12 * b.max(1e-30), "{c}: {a} vs {b}");
                }
            }
        };
        let mut p = Projected::new(span(&[3]), &y, g.len(), &held, &|c| g[c].clone());
        check(&p.model(), &[3]);
        let mut model = vec![3];
        for t in [0, 1, 4] {
            let d = p.model().directions(t);
            p.grow(&d, &y);
            model.push(t);
            check(&p.model(), &model);
        }
        // Candidate 1 seen out, then taken out and 5 in its place.
        let d = span(&[3, 0, 4]).new_directions(&g[1]);
        check(&p.without(span(&[3, 0, 4]), d.clone(), &y), &[3, 0, 4]);
        check(&p.model(), &[3, 0, 1, 4]);
        p.shrink(span(&[3, 0, 4]), &d, &y);
        check(&p.model(), &[3, 0, 4]);
        let d = p.model().directions(5);
        p.grow(&d, &y);
        check(&p.model(), &[3, 0, 4, 5]);
    }
}
