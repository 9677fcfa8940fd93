//! The QR decomposition of a tall system folded block by block: the one implementation behind
//! the streaming identification ([`crate::streaming::StreamingQr`], which folds blocks of rows
//! of `[H | y]` as they are read) and every in-memory least-squares fit of more rows than free
//! columns ([`fold_in_blocks`], which folds blocks of rows of the scaled H held in memory, then
//! of `[H | y]` for each fit: `svd`). Neither keeps `Q`: only the triangular factor.
//!
//! The first block (up to [`Blocks::first`] rows) is factorised by the Householder QR of its
//! rows (nalgebra's, as the whole matrix was before the fold), so that a system of no more rows
//! is factorised exactly as before, bit for bit. Every later block `B` (b rows × c columns,
//! [`Blocks::rest`] rows) replaces `R` by the triangular factor of `[R; B]`: for each column
//! `k`, one Householder reflection `I − τ·u·uᵀ` whose vector `u` is 1 at row `k` of `R`, zero
//! elsewhere in `R`, and `v` in the block's rows (`R` stays upper triangular, so nothing else of
//! `R` is touched). `B` is overwritten by the `v`s, column `k` by the `k`-th. At every step `RᵀR`
//! is the Gram matrix of every row folded; at the end `R` is the triangular factor of the whole
//! system. The work is `2·b·c²` flops per block, over rows that stay in the cache: a block of a
//! few hundred rows is read from memory once, where a Householder QR of the whole tall matrix
//! sweeps it once per column.

use nalgebra::DMatrix;

/// Rows per block of an in-memory fold after the first: 256 rows of 12 columns are 24 kB, so
/// that a block stays in the first-level cache while its reflections are applied.
pub(crate) const BLOCK_ROWS: usize = 256;

/// Rows of the first block of an in-memory fold (2¹⁶, 21 845 samples): a record of no more rows
/// is factorised by one Householder QR of its rows, bit for bit as before the fold (the golden
/// corpus locks every digit of the outputs); a longer one has the rest folded in blocks of
/// [`BLOCK_ROWS`]. The first block of 12 columns is 6.3 MB, within the last-level cache.
pub(crate) const FIRST_ROWS: usize = 1 << 16;

/// How rows are cut into blocks: the first block, then blocks of `rest` rows (both at least 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Blocks {
    /// Rows of the first block, factorised by the Householder QR of its rows.
    pub(crate) first: usize,
    /// Rows of every later block, folded into the factor.
    pub(crate) rest: usize,
}

impl Blocks {
    /// The in-memory fold's: [`FIRST_ROWS`], then [`BLOCK_ROWS`].
    pub(crate) const IN_MEMORY: Blocks = Blocks {
        first: FIRST_ROWS,
        rest: BLOCK_ROWS,
    };
}

/// The upper-triangular factor `R` (c × c, in the units of the columns folded) of the QR
/// decomposition of the rows folded so far.
#[derive(Clone, Debug)]
pub(crate) struct Triangular {
    /// `R`, column-major, `c × c`.
    r: DMatrix<f64>,
    /// Rows folded in so far.
    rows: usize,
}

impl Triangular {
    /// No rows yet, `c` columns.
    pub(crate) fn new(c: usize) -> Triangular {
        Triangular {
            r: DMatrix::zeros(c, c),
            rows: 0,
        }
    }

    /// The factor `R` (c × c).
    pub(crate) fn r(&self) -> &DMatrix<f64> {
        &self.r
    }

    /// Rows folded in so far.
    pub(crate) fn rows(&self) -> usize {
        self.rows
    }

    /// Folds rows `start .. start + len` of `a` (as many columns as `R`) into `R`, overwriting
    /// them with their Householder vectors `v` and `tau` (one per column) with their `τ`
    /// (0: no reflection, `v` zero). Rows out of `a`, or another number of columns, fold
    /// nothing (callers pass their own blocks).
    pub(crate) fn fold(&mut self, a: &mut DMatrix<f64>, start: usize, len: usize, tau: &mut [f64]) {
        let (m, c) = a.shape();
        if c != self.r.ncols() || tau.len() != c || start.saturating_add(len) > m {
            return;
        }
        let r = self.r.as_mut_slice();
        let data = a.as_mut_slice();
        for k in 0..c {
            let (left, right) = data.split_at_mut((k + 1) * m);
            let v = &mut left[k * m + start..k * m + start + len];
            let alpha = r[k + k * c];
            let sigma2 = dot(v, v);
            if sigma2 == 0.0 {
                tau[k] = 0.0;
                continue;
            }
            let norm = (alpha * alpha + sigma2).sqrt();
            let beta = if alpha >= 0.0 { -norm } else { norm };
            let scale = 1.0 / (alpha - beta);
            v.iter_mut().for_each(|x| *x *= scale);
            let t = (beta - alpha) / beta;
            tau[k] = t;
            r[k + k * c] = beta;
            for j in k + 1..c {
                let off = (j - k - 1) * m + start;
                let col = &mut right[off..off + len];
                let tw = t * (r[k + j * c] + dot(v, col));
                r[k + j * c] -= tw;
                axpy(col, -tw, v);
            }
        }
        self.rows += len;
    }

    /// Folds `rows` more rows of a matrix held elsewhere (as many columns as `R`), cut as
    /// `blocks` says (the first block only while no row has been folded): `fill(start, len,
    /// scratch)` writes its rows `start .. start + len` into the first `len` rows of `scratch`
    /// (`len` rows for the first block, `blocks.rest` after it; c columns), which is then
    /// folded. Only one block is held, whatever the rows: the rows are read once, from the
    /// caller's matrix, and the Householder vectors are not kept.
    pub(crate) fn fold_blocks(
        &mut self,
        rows: usize,
        blocks: Blocks,
        mut fill: impl FnMut(usize, usize, &mut DMatrix<f64>),
    ) {
        let c = self.r.ncols();
        let mut start = 0;
        if self.rows == 0 && rows > 0 && c > 0 {
            let len = blocks.first.max(1).min(rows);
            let mut first = DMatrix::from_vec(len, c, vec![0.0; len * c]);
            fill(0, len, &mut first);
            let r = first.qr().r();
            self.r.rows_mut(0, r.nrows()).copy_from(&r);
            self.rows = len;
            start = len;
        }
        let block = blocks.rest.max(1).min((rows - start).max(1));
        let mut scratch = DMatrix::zeros(block, c);
        let mut tau = vec![0.0; c];
        while start < rows {
            let len = block.min(rows - start);
            fill(start, len, &mut scratch);
            self.fold(&mut scratch, 0, len, &mut tau);
            start += len;
        }
    }
}

/// The triangular factor of a matrix of `rows` rows and `c` columns held elsewhere, folded in
/// `blocks` ([`Triangular::fold_blocks`]).
pub(crate) fn fold_in_blocks(
    rows: usize,
    c: usize,
    blocks: Blocks,
    fill: impl FnMut(usize, usize, &mut DMatrix<f64>),
) -> Triangular {
    let mut r = Triangular::new(c);
    r.fold_blocks(rows, blocks, fill);
    r
}

/// `xᵀ·y` of two slices of one length, in four running sums (so that it vectorises).
#[inline]
fn dot(x: &[f64], y: &[f64]) -> f64 {
    let (xc, xr) = x.as_chunks::<4>();
    let (yc, yr) = y.as_chunks::<4>();
    let mut s = [0.0; 4];
    for (a, b) in xc.iter().zip(yc) {
        for i in 0..4 {
            s[i] += a[i] * b[i];
        }
    }
    let tail: f64 = xr.iter().zip(yr).map(|(a, b)| a * b).sum();
    (s[0] + s[2]) + (s[1] + s[3]) + tail
}

/// `y ← y + α·x` for two slices of one length.
#[inline]
fn axpy(y: &mut [f64], alpha: f64, x: &[f64]) {
    for (y, x) in y.iter_mut().zip(x) {
        *y += alpha * x;
    }
}
