//! Forward selection of candidate groups with orthogonal projections.
//!
//! All columns are scaled to unit norm. `Q` is an orthonormal basis of the current model's
//! columns (modified Gram–Schmidt, re-orthogonalised; a column whose part outside the span of
//! the previous ones is below `SPAN_TOLERANCE` adds nothing). For a candidate group `C`, its
//! columns with `Q` projected out are orthonormalised the same way into `Q_g`: an empty `Q_g`
//! means the model already spans the candidate (confounded). With `r` the residual of the model:
//!
//! ```text
//! ΔRSS_g = ‖Q_gᵀ r‖²                      what the candidate would explain
//! F_g    = (ΔRSS_g / q_g) / ((RSS − ΔRSS_g) / (n − rank − q_g))
//! ```
//!
//! The step takes the candidate with the largest ΔRSS (the name it is given among candidates the
//! data cannot tell apart is decided in [`super::diagnose`]). Its significance is corrected for the
//! number of candidates tried: first by Bonferroni (`p·N`, conservative); when that is not
//! decisive, by the null distribution of the selection rule itself — the raw p-value of the
//! largest-ΔRSS candidate on pure Gaussian noise, projected like the data — estimated by Monte
//! Carlo (a seeded generator, so results are reproducible). Under Gaussian noise this test has
//! level α exactly, whatever the correlation between candidates.

use super::projected::dot;
use fitting::distributions::f_upper_tail;
use nalgebra::{DMatrix, DMatrixView, DVector};
use simulation::rng::Rng;
use std::cell::OnceCell;

/// A column whose part outside the span of the others is below this (relative to its norm) adds
/// nothing: the model spans it.
pub const SPAN_TOLERANCE: f64 = 1e-7;

/// The span of a model's columns, held as an orthonormal basis grown column by column.
#[derive(Clone, Debug)]
pub struct Span {
    /// Orthonormal columns, n × r.
    pub q: DMatrix<f64>,
}

impl Span {
    /// An empty basis in n dimensions.
    pub fn empty(n: usize) -> Span {
        Span {
            q: DMatrix::zeros(n, 0),
        }
    }

    /// The number of rows.
    pub fn rows(&self) -> usize {
        self.q.nrows()
    }

    /// `v` with the span of the basis projected out (twice, for orthogonality to rounding).
    pub fn project_out(&self, v: &DVector<f64>) -> DVector<f64> {
        let mut out = v.clone();
        if self.q.ncols() > 0 {
            let mut c = DVector::zeros(self.q.ncols());
            for _ in 0..2 {
                c.gemv_tr(1.0, &self.q, &out, 0.0);
                out.gemv(-1.0, &self.q, &c, 1.0);
            }
        }
        out
    }

    /// The orthonormal directions that the columns of `c` add to this basis (each column scaled
    /// to unit norm first; a direction is kept when its norm after projection exceeds
    /// [`SPAN_TOLERANCE`]). Does not change `self`.
    pub fn new_directions(&self, c: &DMatrix<f64>) -> DMatrix<f64> {
        let mut added: Vec<DVector<f64>> = Vec::new();
        for j in 0..c.ncols() {
            let col = DVector::from_column_slice(c.column(j).as_slice());
            let norm = col.norm();
            if norm == 0.0 || !norm.is_finite() {
                continue;
            }
            let mut v = self.project_out(&(col / norm));
            for _ in 0..2 {
                for a in &added {
                    let d = a.dot(&v);
                    v.axpy(-d, a, 1.0);
                }
            }
            let nv = v.norm();
            if nv > SPAN_TOLERANCE {
                added.push(v / nv);
            }
        }
        if added.is_empty() {
            DMatrix::zeros(self.rows(), 0)
        } else {
            DMatrix::from_columns(&added)
        }
    }

    /// The basis of the column groups `groups` (in order) of `n` rows, `group(g)` giving the
    /// columns of group `g`.
    pub fn of_groups(
        n: usize,
        groups: impl IntoIterator<Item = usize>,
        group: &dyn Fn(usize) -> DMatrix<f64>,
    ) -> Span {
        let mut q = Span::empty(n);
        for g in groups {
            let d = q.new_directions(&group(g));
            q.extend(&d);
        }
        q
    }

    /// Appends orthonormal directions orthogonal to the basis (from [`Span::new_directions`]).
    pub fn extend(&mut self, directions: &DMatrix<f64>) {
        if directions.ncols() == 0 {
            return;
        }
        let (n, r) = self.q.shape();
        let mut q = DMatrix::zeros(n, r + directions.ncols());
        q.columns_mut(0, r).copy_from(&self.q);
        q.columns_mut(r, directions.ncols()).copy_from(directions);
        self.q = q;
    }

    /// The rank.
    pub fn rank(&self) -> usize {
        self.q.ncols()
    }
}

/// One candidate at one step: its new directions and what they explain.
pub struct Scored<'a> {
    /// Index in the candidate list.
    pub index: usize,
    /// q, the number of its directions outside the model.
    pub width: usize,
    /// `Q_g`: its orthonormal directions outside the model (n × q), given or made when first
    /// asked for ([`Scored::directions`]).
    directions: Directions<'a>,
    /// `Q_gᵀ r`: the residual's coordinates on them (mm; q).
    pub coordinates: DVector<f64>,
    /// ΔRSS = ‖Q_gᵀ r‖², mm².
    pub delta_rss: f64,
}

/// A candidate's directions: given, or made from its index when first asked for (a step scores
/// every candidate, and looks at the directions of a few).
enum Directions<'a> {
    Given(DMatrix<f64>),
    Made(&'a dyn Fn(usize) -> DMatrix<f64>, OnceCell<DMatrix<f64>>),
}

impl<'a> Scored<'a> {
    /// Candidate `index` with directions `directions` (orthonormal, outside the model) against
    /// the model's residual `r`.
    pub fn new(index: usize, directions: DMatrixView<'_, f64>, r: &DVector<f64>) -> Scored<'a> {
        let coordinates = coordinates(&directions, r);
        Scored {
            index,
            width: directions.ncols(),
            delta_rss: coordinates.norm_squared(),
            directions: Directions::Given(directions.clone_owned()),
            coordinates,
        }
    }

    /// Candidate `index` with `width` directions on which the residual has `coordinates`
    /// ([`coordinates`]), the directions made by `make(index)` when first asked for (the same
    /// directions, to the bit, as those the coordinates were computed on).
    pub fn made_by(
        index: usize,
        width: usize,
        coordinates: DVector<f64>,
        make: &'a dyn Fn(usize) -> DMatrix<f64>,
    ) -> Scored<'a> {
        Scored {
            index,
            width,
            delta_rss: coordinates.norm_squared(),
            directions: Directions::Made(make, OnceCell::new()),
            coordinates,
        }
    }

    /// Its directions (n × q, as [`Scored::directions`]) appended to `out`, column after
    /// column: directions made already are copied; the others are made for this and not kept
    /// (the same directions, to the bit: a step appends every candidate's, and looks again at
    /// the directions of a few).
    fn append_directions(&self, out: &mut Vec<f64>) {
        match &self.directions {
            Directions::Given(d) => out.extend_from_slice(d.as_slice()),
            Directions::Made(make, cell) => match cell.get() {
                Some(d) => out.extend_from_slice(d.as_slice()),
                None => out.extend_from_slice(make(self.index).as_slice()),
            },
        }
    }

    /// `Q_g`, its directions (n × q).
    pub fn directions(&self) -> DMatrixView<'_, f64> {
        let d = match &self.directions {
            Directions::Given(d) => d,
            Directions::Made(make, cell) => cell.get_or_init(|| make(self.index)),
        };
        d.columns(0, d.ncols())
    }
}

/// `Dᵀ·r` for directions `D` of contiguous columns.
pub fn coordinates(directions: &DMatrixView<'_, f64>, r: &DVector<f64>) -> DVector<f64> {
    DVector::from_iterator(
        directions.ncols(),
        directions
            .column_iter()
            .map(|d| dot(d.as_slice(), r.as_slice())),
    )
}

/// What the directions of `a` add beyond those of `b` (two candidates scored on one model with
/// residual `r`): the ΔRSS of `r` on them and their number, as
/// `Span { q: b.directions }.new_directions(&a.directions)` gives them.
///
/// When `b` lies far from `a` (`‖bᵀa‖²` at most ½, Frobenius: every direction of `a` keeps a
/// part of norm at least 1/√2 outside `b`, so none is dropped) this is computed on the q × q
/// Gram matrices: with `G = bᵀa`, the part of `a` outside `b` is `M = a − b·G`, `MᵀM = I − GᵀG`
/// (well conditioned), `Mᵀr = aᵀr − Gᵀ·bᵀr`, and the ΔRSS is `(Mᵀr)ᵀ (MᵀM)⁻¹ (Mᵀr)`.
/// Otherwise the directions are made explicitly.
pub fn beyond(a: &Scored, b: &Scored, r: &DVector<f64>) -> (f64, usize) {
    let (da, db) = (a.directions(), b.directions());
    let g = gram(&db, &da);
    if g.norm_squared() <= 0.5 {
        let qa = a.width;
        let t = &a.coordinates - g.tr_mul(&b.coordinates);
        let gram = DMatrix::identity(qa, qa) - g.tr_mul(&g);
        if let Some(c) = gram.cholesky() {
            return (t.dot(&c.solve(&t)), qa);
        }
    }
    let extra = Span {
        q: db.clone_owned(),
    }
    .new_directions(&da.clone_owned());
    (extra.tr_mul(r).norm_squared(), extra.ncols())
}

/// `aᵀ·b` of two matrices of contiguous columns (directions of candidates), by dot products of
/// their columns.
pub fn gram(a: &DMatrixView<'_, f64>, b: &DMatrixView<'_, f64>) -> DMatrix<f64> {
    DMatrix::from_fn(a.ncols(), b.ncols(), |i, k| {
        dot(a.column(i).as_slice(), b.column(k).as_slice())
    })
}

/// The F statistic of adding `q` directions that explain `delta_rss` of `rss`, with `n` rows and
/// a model of rank `rank`.
pub fn f_statistic(delta_rss: f64, rss: f64, q: usize, n: usize, rank: usize) -> Option<f64> {
    let dof = n.checked_sub(rank + q).filter(|&d| d > 0)? as f64;
    let rest = (rss - delta_rss).max(0.0);
    if rest <= 0.0 {
        return Some(f64::INFINITY);
    }
    Some((delta_rss / q as f64) / (rest / dof))
}

/// The number of draws at least as extreme at which the Monte-Carlo null stops.
pub const SEQUENTIAL_H: usize = 10;

/// The p-value of the chosen candidate under the null of the selection rule, by Monte Carlo:
/// the share of `draws` pure-noise vectors (projected out of `model`) whose largest-ΔRSS
/// candidate (among `scored`) has a raw p-value ([`f_p_value`] of its F with its own number of
/// directions) at most `p_observed`, the raw p-value of the chosen candidate. Returns
/// `(count + 1) / (draws + 1)`, or, sequentially (Besag and Clifford, 1991), `h / l` as soon
/// as the `h`-th draw at least as extreme turns up at draw `l` ([`SEQUENTIAL_H`] = 10): a
/// candidate far from significant is settled in tens of draws instead of `draws`, and the
/// p-value stays valid (`P(p ≤ t) ≤ t`); p-values below `h / draws` are those of the full run.
///
/// The statistic is the raw p-value rather than F so that the Bonferroni bound is a bound of
/// this p-value whatever the widths of the candidates: `P(p_sel ≤ t) ≤ P(min_g p_g ≤ t) ≤ N·t`.
/// Bonferroni decisive (`N·p_observed < α`) then implies this p-value below α, and the two
/// corrections together keep level α. (With F as the statistic, a two-column candidate's F
/// and a one-column candidate's F are on different scales, and the bound does not hold.)
pub fn monte_carlo_p(
    model: &Span,
    scored: &[Scored],
    p_observed: f64,
    draws: usize,
    seed: u64,
) -> f64 {
    monte_carlo_p_stopping(model, scored, p_observed, draws, seed, SEQUENTIAL_H)
}

/// As [`monte_carlo_p`], stopping at the `h`-th draw at least as extreme (`usize::MAX`: never).
fn monte_carlo_p_stopping(
    model: &Span,
    scored: &[Scored],
    p_observed: f64,
    draws: usize,
    seed: u64,
    h: usize,
) -> f64 {
    let n = model.rows();
    let rank = model.rank();
    let widths: Vec<usize> = scored.iter().map(|s| s.width).collect();
    let total: usize = widths.iter().sum();
    if total == 0 || draws == 0 {
        return 1.0;
    }
    let mut all = Vec::with_capacity(n * total);
    for s in scored {
        s.append_directions(&mut all);
    }
    let all = DMatrix::from_vec(n, total, all);
    let mut rng = Rng::new(seed);
    let mut exceed = 0usize;
    // Blocks of draws: one matrix product per block (small at first, where the sequential
    // stop usually falls).
    let mut block = 32;
    let mut done = 0;
    while done < draws {
        let b = block.min(draws - done);
        let e = DMatrix::from_fn(n, b, |_, _| rng.normal());
        // The draws as rows: the products below then go to the blocked matrix multiplication
        // (`tr_mul` would take one dot product per coefficient).
        let et = e.transpose();
        let proj = &et * &all;
        let in_model = &et * &model.q;
        for d in 0..b {
            let rss = e.column(d).norm_squared() - in_model.row(d).norm_squared();
            let (mut best, mut best_q, mut off) = (-1.0f64, 1usize, 0usize);
            for &w in &widths {
                let s: f64 = (0..w).map(|k| proj[(d, off + k)].powi(2)).sum();
                if s > best {
                    best = s;
                    best_q = w;
                }
                off += w;
            }
            if let Some(f) = f_statistic(best, rss, best_q, n, rank)
                && f_p_value(f, best_q, n, rank) <= p_observed
            {
                exceed += 1;
                if exceed == h {
                    return h as f64 / (done + d + 1) as f64;
                }
            }
        }
        done += b;
        block = 128;
    }
    (exceed + 1) as f64 / (draws + 1) as f64
}

/// The raw p-value of an F statistic with `q` and `n − rank − q` degrees of freedom.
pub fn f_p_value(f: f64, q: usize, n: usize, rank: usize) -> f64 {
    let dof = n.saturating_sub(rank + q) as f64;
    if dof <= 0.0 {
        return 1.0;
    }
    if f.is_infinite() {
        return 0.0;
    }
    f_upper_tail(f, q as f64, dof)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spanned_columns_add_no_direction() {
        let mut b = Span::empty(4);
        let h = DMatrix::from_row_slice(4, 2, &[1.0, 0.0, 1.0, 1.0, 0.0, 1.0, 0.0, 0.0]);
        let d = b.new_directions(&h);
        assert_eq!(d.ncols(), 2);
        b.extend(&d);
        // A combination of the two columns is spanned; a new direction is not.
        let c = DMatrix::from_row_slice(4, 2, &[2.0, 0.0, 3.0, 0.0, 1.0, 0.0, 0.0, 1.0]);
        let nd = b.new_directions(&c);
        assert_eq!(nd.ncols(), 1);
        assert!((nd[(3, 0)].abs() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn monte_carlo_level_for_a_single_candidate_matches_the_f_distribution() {
        // One candidate of one column: the Monte-Carlo p must equal the F-distribution p.
        let n = 200;
        let model = Span::empty(n);
        let dir = DMatrix::from_fn(n, 1, |i, _| if i == 0 { 1.0 } else { 0.0 });
        let scored = vec![Scored::new(0, dir.columns(0, 1), &DVector::zeros(n))];
        for f in [1.0, 4.0, 7.0] {
            let exact = f_p_value(f, 1, n, 0);
            // Stopped sequentially, the p-value is coarser, and never below h / draws.
            let sequential = monte_carlo_p(&model, &scored, exact, 20_000, 3);
            assert!(sequential >= SEQUENTIAL_H as f64 / 20_000.0);
            assert!(
                (sequential - exact).abs() < 0.6 * exact + 1e-3,
                "F {f}: {sequential}"
            );
            let mc = monte_carlo_p_stopping(&model, &scored, exact, 20_000, 3, usize::MAX);
            assert!(
                (mc - exact).abs() < 4.0 * (exact * (1.0 - exact) / 20_000.0).sqrt() + 1e-3,
                "F {f}: {mc} vs {exact}"
            );
        }
    }

    /// `beyond` on the Gram matrices (candidates far apart) gives what the directions made
    /// explicitly give; near candidates go the explicit way.
    #[test]
    fn beyond_agrees_with_explicit_directions() {
        let n = 60;
        let mut rng = Rng::new(7);
        let mut random = |w: usize| DMatrix::from_fn(n, w, |_, _| rng.normal());
        let r = random(1).column(0).into_owned();
        let model = Span::empty(n);
        for (wa, wb, near) in [
            (1, 1, 0.0),
            (2, 1, 0.3),
            (1, 2, 0.0),
            (2, 2, 0.5),
            (2, 2, 3.0),
        ] {
            let b_cols = random(wb);
            // `a` leans towards `b` by `near`.
            let mut a_cols = random(wa);
            for k in 0..wa {
                let lean = b_cols.column(k % wb) * near;
                a_cols.column_mut(k).axpy(1.0, &lean, 1.0);
            }
            let da = model.new_directions(&a_cols);
            let db = model.new_directions(&b_cols);
            let (a, b) = (
                Scored::new(0, da.columns(0, wa), &r),
                Scored::new(1, db.columns(0, wb), &r),
            );
            let explicit = Span { q: db.clone() }.new_directions(&da);
            let want = explicit.tr_mul(&r).norm_squared();
            let (gain, extra) = beyond(&a, &b, &r);
            assert_eq!(extra, explicit.ncols());
            assert!((gain - want).abs() < 1e-10 * want, "{gain} vs {want}");
        }
        // `a` inside `b`: nothing added.
        let b_cols = random(2);
        let db = model.new_directions(&b_cols);
        let a_cols = b_cols.column(0) * 2.0 - b_cols.column(1);
        let da = model.new_directions(&DMatrix::from_columns(&[a_cols]));
        let (a, b) = (
            Scored::new(0, da.columns(0, 1), &r),
            Scored::new(1, db.columns(0, 2), &r),
        );
        assert_eq!(beyond(&a, &b, &r).1, 0);
    }
}
