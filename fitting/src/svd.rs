//! The SVD of a scaled H (rows × free columns): for a tall H, its QR decomposition folded in
//! blocks of rows (`crate::fold`) and the SVD of the small triangular factor, neither
//! `U = Q·U_R` nor `Q` formed; every SVD checked by rebuilding its matrix. [`super::factored`]
//! builds a fit on it.

use crate::fold::{Blocks, Triangular, fold_in_blocks};
use crate::least_squares::EstimateError;
use nalgebra::{DMatrix, DVector, SVD};

/// The scaled H of the free columns: `A = H·S⁻¹` restricted to the columns not fixed.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Scaled<'a> {
    /// H (m × n, mm per unit of each parameter).
    pub(crate) h: &'a DMatrix<f64>,
    /// The free columns of H, in order.
    pub(crate) free: &'a [usize],
    /// `s_j` per column of H (mm per unit × √rows; 1 for a zero column).
    pub(crate) norms: &'a [f64],
}

impl Scaled<'_> {
    /// Writes rows `start .. start + len` of the scaled H into the first `len` rows of `out`
    /// (one column per free column), and `y`'s rows into the next column when given.
    fn fill(&self, start: usize, len: usize, y: Option<&[f64]>, out: &mut DMatrix<f64>) {
        let (m, ld) = (self.h.nrows(), out.nrows());
        let columns = self.free.len() + usize::from(y.is_some());
        if out.ncols() != columns || len > ld || start + len > m {
            return;
        }
        let (h, out) = (self.h.as_slice(), out.as_mut_slice());
        for (k, &j) in self.free.iter().enumerate() {
            let s = self.norms[j];
            let from = &h[j * m + start..j * m + start + len];
            for (o, x) in out[k * ld..k * ld + len].iter_mut().zip(from) {
                *o = x / s;
            }
        }
        if let Some(y) = y {
            let k = self.free.len();
            out[k * ld..k * ld + len].copy_from_slice(&y[start..start + len]);
        }
    }

    /// The triangular factor of the scaled H (or of `[scaled H | y]`), folded in `blocks`.
    fn fold(&self, y: Option<&[f64]>, blocks: Blocks) -> Triangular {
        let (m, nf) = (self.h.nrows(), self.free.len());
        let c = nf + usize::from(y.is_some());
        fold_in_blocks(m, c, blocks, |start, len, out| {
            self.fill(start, len, y, out)
        })
    }

    /// The whole scaled H, padded with zero rows to at least as many rows as free columns.
    fn matrix(&self) -> DMatrix<f64> {
        let (m, nf) = (self.h.nrows(), self.free.len());
        let mut a = DMatrix::<f64>::zeros(m.max(nf), nf);
        self.fill(0, m, None, &mut a);
        a
    }
}

/// The SVD of the scaled H `a` (padded with zero rows when the record has fewer readings than
/// free columns): its singular values (descending), its left singular vectors as the readings
/// meet them, and its right singular vectors as columns. More rows than free columns (every
/// real record): the SVD of the triangular factor of the QR decomposition folded in blocks
/// ([`Blocks::IN_MEMORY`]: up to 65 536 rows factorised as before the fold, bit for bit), with
/// `y` (readings, as many as rows) folded along when given, so that their fit needs no second
/// fold.
///
/// # Errors
/// [`EstimateError::Svd`]: an SVD that does not converge, or none that rebuilds the matrix.
pub(crate) fn decompose(
    a: Scaled,
    y: Option<&DVector<f64>>,
) -> Result<(Vec<f64>, Left, DMatrix<f64>), EstimateError> {
    decompose_in(a, y, Blocks::IN_MEMORY)
}

/// [`decompose`] folding in `blocks`.
pub(crate) fn decompose_in(
    a: Scaled,
    y: Option<&DVector<f64>>,
    blocks: Blocks,
) -> Result<(Vec<f64>, Left, DMatrix<f64>), EstimateError> {
    let (m, nf) = (a.h.nrows(), a.free.len());
    if nf == 0 {
        return Ok((
            Vec::new(),
            Left::Vectors(DMatrix::zeros(m.max(nf), 0)),
            DMatrix::zeros(0, 0),
        ));
    }
    if m > nf {
        let y = y.filter(|y| y.len() == m);
        let folded = a.fold(y.map(|y| y.as_slice()), blocks);
        let r = folded.r().view((0, 0), (nf, nf)).into_owned();
        if let Some((sv, u_r, v)) = checked_svd(&r, m, true)? {
            let first = y.map(|y| Readings {
                y: y.clone(),
                top: folded.r().view((0, nf), (nf, 1)).column(0).into_owned(),
            });
            let left = Left::Fold {
                u_r,
                blocks,
                first: first.map(Box::new),
            };
            return Ok((sv, left, v));
        }
        // The SVD of the whole scaled H.
        let (sv, u, v) = checked_svd(&a.matrix(), m, false)?.ok_or(EstimateError::Svd(m, nf))?;
        return Ok((sv, Left::Vectors(u), v));
    }
    let (sv, u, v) = checked_svd(&a.matrix(), m, false)?.ok_or(EstimateError::Svd(m, nf))?;
    Ok((sv, Left::Vectors(u), v))
}

/// Readings folded with the scaled H, and the first rows of `Qᵀ·y` for them.
#[derive(Clone, Debug)]
pub(crate) struct Readings {
    /// The readings (mm).
    y: DVector<f64>,
    /// The first n rows of `Qᵀ·y` (mm).
    top: DVector<f64>,
}

/// The left singular vectors of the scaled H of the free columns.
#[derive(Clone, Debug)]
pub(crate) enum Left {
    /// `U` itself, of a system with no more rows than free columns (padded with zero rows to
    /// as many), or of a tall one whose triangular factor's SVD failed its check.
    Vectors(DMatrix<f64>),
    /// A tall system (more rows than free columns): the left singular vectors of the
    /// triangular factor R of its QR decomposition `A = Q·R`, so that `U = Q·U_R`. Neither `U`
    /// (rows × n) nor `Q` is kept: `Qᵀ·y` is the last column of the triangular factor of
    /// `[A | y]`, folded for each fit exactly as `A` was (the same operations on A's columns,
    /// so the same R and Q, bit for bit), except for the readings folded with `A` at first.
    Fold {
        /// The left singular vectors of R (n × n).
        u_r: DMatrix<f64>,
        /// How the fold cuts the rows into blocks.
        blocks: Blocks,
        /// The readings folded with A, if any.
        first: Option<Box<Readings>>,
    },
}

impl Left {
    /// `Uᵀ·y` for the first `rank` singular vectors of the scaled H `a` (`y`: the readings,
    /// padded with zeros to the rows of `a` when it has fewer than free columns).
    pub(crate) fn project(&self, a: Scaled, y: &DVector<f64>, rank: usize) -> Vec<f64> {
        match self {
            Left::Vectors(u) => (0..rank).map(|i| u.column(i).dot(y)).collect(),
            Left::Fold { u_r, blocks, first } => {
                let nf = u_r.nrows();
                let top = match first {
                    Some(f) if same(&f.y, y) => f.top.clone(),
                    _ => a
                        .fold(Some(y.as_slice()), *blocks)
                        .r()
                        .view((0, nf), (nf, 1))
                        .column(0)
                        .into_owned(),
                };
                (0..rank).map(|i| u_r.column(i).dot(&top)).collect()
            }
        }
    }
}

/// Whether `a` and `b` are the same numbers, bit for bit.
fn same(a: &DVector<f64>, b: &DVector<f64>) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b.iter())
            .all(|(x, y)| x.to_bits() == y.to_bits())
}

/// Singular values (descending), left and right singular vectors (as columns).
type Svd = (Vec<f64>, DMatrix<f64>, DMatrix<f64>);

/// The SVD of `a` (rows × nf, nf ≥ 1), to the iteration limit of `m` readings.
fn svd_of(a: DMatrix<f64>, m: usize) -> Result<Svd, EstimateError> {
    let nf = a.ncols();
    let svd = SVD::try_new(a, true, true, f64::EPSILON, 1000 + 200 * nf)
        .ok_or(EstimateError::Svd(m, nf))?;
    let (Some(u), Some(vt)) = (svd.u, svd.v_t) else {
        return Err(EstimateError::Svd(m, nf));
    };
    Ok((svd.singular_values.as_slice().to_vec(), u, vt.transpose()))
}

/// The SVD of `a` (rows × nf, rows ≥ nf ≥ 1) that rebuilds `a` to 1e-10 of its norm, taken
/// directly or as the SVD of `aᵀ` (`aᵀ = U'·Σ·V'ᵀ`, so `a = V'·Σ·U'ᵀ`), in the order
/// `transposed_first` says; `None` when neither rebuilds it. nalgebra's SVD of an
/// upper-triangular factor with an exactly dependent column has been seen to return a wrong
/// largest singular value (the factor rebuilt 7 % off) while its SVD of the transpose was right:
/// no factorisation is used unchecked.
fn checked_svd(
    a: &DMatrix<f64>,
    m: usize,
    transposed_first: bool,
) -> Result<Option<Svd>, EstimateError> {
    let norm = a.norm();
    for transposed in [transposed_first, !transposed_first] {
        let (sv, u, v) = if transposed && a.nrows() == a.ncols() {
            let (sv, u_t, v_t) = svd_of(a.transpose(), m)?;
            (sv, v_t, u_t)
        } else if transposed {
            continue;
        } else {
            svd_of(a.clone(), m)?
        };
        let mut rebuilt = u.columns(0, sv.len()).into_owned();
        for (j, s) in sv.iter().enumerate() {
            rebuilt.column_mut(j).scale_mut(*s);
        }
        if (rebuilt * v.transpose() - a).norm() <= 1e-10 * norm {
            return Ok(Some((sv, u, v)));
        }
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;
    use simulation::rng::Rng;

    /// A 301 × 6 H of random columns with the third 1000 times the others, and readings; with
    /// `deficient`, the sixth column `2·h₀ − 3·h₁` (rank 5).
    fn system(deficient: bool) -> (DMatrix<f64>, DVector<f64>, DVector<f64>) {
        let mut rng = Rng::new(if deficient { 5 } else { 6 });
        let (m, n) = (301, 6);
        let mut h = DMatrix::from_fn(m, n, |_, _| rng.normal());
        if deficient {
            let combined = h.column(0) * 2.0 - h.column(1) * 3.0;
            h.set_column(5, &combined);
        }
        h.column_mut(2).scale_mut(1e3);
        let y = DVector::from_fn(m, |_, _| rng.normal());
        let other = DVector::from_fn(m, |_, _| rng.normal());
        (h, y, other)
    }

    /// The minimum-norm solution (scaled coordinates) of `y` over the first `rank` singular
    /// triplets.
    fn solve(
        sv: &[f64],
        left: &Left,
        v: &DMatrix<f64>,
        a: Scaled,
        y: &DVector<f64>,
        rank: usize,
    ) -> DVector<f64> {
        let mut z = DVector::zeros(v.nrows());
        for (i, uty) in left.project(a, y, rank).iter().enumerate() {
            z.axpy(uty / sv[i], &v.column(i), 1.0);
        }
        z
    }

    /// The folded QR decomposition, for every block size (one row, fewer rows than columns, as
    /// many, a last partial block, one block of all rows, a block longer than the rows), gives
    /// the triangular factor of the Householder QR of the whole matrix (up to the signs of its
    /// rows), the same singular values and rank, and the same least-squares solutions: of the
    /// readings folded with H, and of other readings (folded again at the fit), as the SVD of
    /// the whole QR's factor; full rank, and rank deficient.
    #[test]
    fn the_fold_agrees_with_the_qr_of_the_whole_matrix() {
        for deficient in [false, true] {
            let (h, y, other) = system(deficient);
            let (m, n) = h.shape();
            let norms: Vec<f64> = h.column_iter().map(|c| c.norm()).collect();
            let free: Vec<usize> = (0..n).collect();
            let a = Scaled {
                h: &h,
                free: &free,
                norms: &norms,
            };
            let whole = a.matrix();
            // The old direct path: Householder QR of the whole scaled H, SVD of its R.
            let qr = whole.clone().qr();
            let r_whole = qr.r();
            let (sv_whole, u_r, v_whole) = checked_svd(&r_whole, m, true).unwrap().unwrap();
            let rank = sv_whole
                .iter()
                .take_while(|&&s| s > 1e-8 * sv_whole[0])
                .count();
            assert_eq!(rank, if deficient { 5 } else { 6 });
            let direct = |y: &DVector<f64>| {
                let mut qty = y.clone();
                qr.q_tr_mul(&mut qty);
                let top = qty.rows(0, n).into_owned();
                let mut z = DVector::zeros(n);
                for (i, s) in sv_whole.iter().enumerate().take(rank) {
                    z.axpy(u_r.column(i).dot(&top) / s, &v_whole.column(i), 1.0);
                }
                z
            };
            // First blocks of one row, fewer rows than columns, as many, more, all rows and
            // more; later blocks of one row, fewer than columns, as many, and longer (the last
            // one partial for every size but 1).
            let cuts = [1, 2, 5, 6, 7, 100]
                .into_iter()
                .flat_map(|first| [1, 5, 6, 64].map(|rest| (first, rest)))
                .chain([(301, 256), (1000, 1)]);
            for (first, rest) in cuts {
                let block = Blocks { first, rest };
                let folded = a.fold(None, block);
                assert_eq!(folded.rows(), m);
                for i in 0..n {
                    let sign = folded.r()[(i, i)].signum() * r_whole[(i, i)].signum();
                    for j in i..n {
                        let (f, w) = (folded.r()[(i, j)], r_whole[(i, j)]);
                        assert!(
                            (f - sign * w).abs() <= 1e-12 * r_whole.norm(),
                            "{block:?}, R[{i},{j}]: {f} vs {w}"
                        );
                    }
                }
                for given in [None, Some(&y)] {
                    let (sv, left, v) = decompose_in(a, given, block).unwrap();
                    assert!(matches!(left, Left::Fold { .. }), "{block:?}");
                    for (s, w) in sv.iter().zip(&sv_whole).take(rank) {
                        assert!(
                            (s - w).abs() <= 1e-12 * sv_whole[0],
                            "{block:?}: σ {s} vs {w}"
                        );
                    }
                    for readings in [&y, &other] {
                        let z = solve(&sv, &left, &v, a, readings, rank);
                        let want = direct(readings);
                        assert!(
                            (&z - &want).norm() <= 1e-10 * want.norm(),
                            "{block:?}, deficient {deficient}: {z} vs {want}"
                        );
                    }
                }
                // The readings folded with H give the fold's own Qᵀ·y, bit for bit.
                let (_, memo, _) = decompose_in(a, Some(&y), block).unwrap();
                let (_, again, _) = decompose_in(a, None, block).unwrap();
                assert_eq!(memo.project(a, &y, rank), again.project(a, &y, rank));
                if first >= m {
                    // One block: the Householder QR of the whole matrix, bit for bit.
                    assert_eq!(folded.r(), &r_whole, "{block:?}");
                    let (sv, left, v) = decompose_in(a, Some(&y), block).unwrap();
                    assert_eq!((&sv, &v), (&sv_whole, &v_whole));
                    for readings in [&y, &other] {
                        let z = solve(&sv, &left, &v, a, readings, rank);
                        assert_eq!(z, direct(readings), "{block:?}");
                    }
                }
            }
            if !deficient {
                // And the normal equations of the well-conditioned full-rank system.
                let (sv, left, v) = decompose(a, Some(&y)).unwrap();
                let z = solve(&sv, &left, &v, a, &y, rank);
                let normal = (whole.transpose() * &whole)
                    .cholesky()
                    .unwrap()
                    .solve(&(whole.transpose() * &y));
                assert!(
                    (&z - &normal).norm() <= 1e-9 * normal.norm(),
                    "{z} vs {normal}"
                );
            }
        }
    }
}
