//! The SVD of a scaled H (rows × free columns): for a tall H, a Householder QR first and the
//! SVD of its small triangular factor, `U = Q·U_R` never formed; every SVD checked by rebuilding
//! its matrix. [`super::factored`] builds a fit on it.

use crate::least_squares::EstimateError;
use nalgebra::{DMatrix, DVector, Dyn, QR, SVD};

/// The SVD of the scaled H `a` (rows × nf; rows ≥ nf, padded with zero rows when the record has
/// fewer readings than free columns) of `m` readings: its singular values (descending), its left
/// singular vectors as the readings meet them, and its right singular vectors as columns.
///
/// # Errors
/// [`EstimateError::Svd`]: an SVD that does not converge, or none that rebuilds the matrix.
pub(crate) fn decompose(
    a: DMatrix<f64>,
    m: usize,
) -> Result<(Vec<f64>, Left, DMatrix<f64>), EstimateError> {
    let (rows, nf) = a.shape();
    if nf == 0 {
        return Ok((
            Vec::new(),
            Left::Vectors(DMatrix::zeros(rows, 0)),
            DMatrix::zeros(0, 0),
        ));
    }
    if rows > nf {
        let qr = a.qr();
        let r = qr.r();
        if let Some((sv, u_r, v)) = checked_svd(&r, m, true)? {
            return Ok((sv, Left::Qr { qr, u_r }, v));
        }
        // The SVD of the whole scaled H, rebuilt from its factors.
        let (sv, u, v) = checked_svd(&(qr.q() * r), m, false)?.ok_or(EstimateError::Svd(m, nf))?;
        return Ok((sv, Left::Vectors(u), v));
    }
    let (sv, u, v) = checked_svd(&a, m, false)?.ok_or(EstimateError::Svd(m, nf))?;
    Ok((sv, Left::Vectors(u), v))
}

/// The left singular vectors of the scaled H of the free columns.
#[derive(Clone, Debug)]
pub(crate) enum Left {
    /// `U` itself, of a system with no more rows than free columns (padded with zero rows to
    /// as many), or of a tall one whose triangular factor's SVD failed its check.
    Vectors(DMatrix<f64>),
    /// A tall system (more rows than free columns): the Householder QR of the scaled H and the
    /// left singular vectors of its small triangular factor R, so that `U = Q·U_R`. The SVD then
    /// costs what it costs for n × n, and `U` (rows × n) is never formed: the tall part of the
    /// work is the QR (as in the streaming fold) and one `Qᵀ·y` per fit.
    Qr {
        /// The QR of the scaled H.
        qr: QR<f64, Dyn, Dyn>,
        /// The left singular vectors of R (n × n).
        u_r: DMatrix<f64>,
    },
}

impl Left {
    /// `Uᵀ·y` for the first `rank` singular vectors (`y` padded to the rows of the scaled H).
    pub(crate) fn project(&self, y: &DVector<f64>, rank: usize) -> Vec<f64> {
        match self {
            Left::Vectors(u) => (0..rank).map(|i| u.column(i).dot(y)).collect(),
            Left::Qr { qr, u_r } => {
                let mut qty = y.clone();
                qr.q_tr_mul(&mut qty);
                let top = qty.rows(0, u_r.nrows());
                (0..rank).map(|i| u_r.column(i).dot(&top)).collect()
            }
        }
    }
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
