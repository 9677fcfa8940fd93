//! What the data can and cannot tell apart, from the singular value decomposition of the
//! column-scaled H matrix `A = H·S⁻¹` (see [`crate`]).
//!
//! - The **null space** `N` (p × (p − r)): the right singular vectors of the singular values
//!   at or below the rank tolerance. A change `δ = S⁻¹·N·c` of the parameters changes the
//!   prediction by (numerically) nothing, so the data cannot see it.
//! - A parameter `j` is **determined** iff its unit vector is orthogonal to the null space:
//!   `w_j = ‖Nᵀ·e_j‖ ≤ τ_d` (default [`DETERMINED_TOLERANCE`] = 1e-6). The projector
//!   `P₀ = N·Nᵀ` does not depend on which basis of the null space the SVD returned, and
//!   `w_j² = (P₀)_jj`. The estimate of a determined parameter (minimum-norm solution restricted
//!   to the identifiable subspace) differs from its true value by at most `w_j·‖Nᵀ·S·p‖`
//!   (scaled units): the undetermined parameters leak into it by a fraction ≤ τ_d.
//! - **Confounded groups**: the undetermined parameters, linked when `|(P₀)_jk| > τ_l` (default
//!   [`LINK_TOLERANCE`] = 1e-6); a group is a connected component. Because `P₀` is
//!   basis-independent, two independent confoundings (XOC with dx0, YOA with dy0) come out as two
//!   groups even when their singular values are equal and the SVD mixes their null vectors.
//! - **Near-confounded pairs**: determined parameters whose estimates have
//!   `|correlation| > 0.99` (default [`CORRELATION_LIMIT`]): the data separate them, but poorly.

use nalgebra::DMatrix;

/// Default τ_d: the largest `‖Nᵀ·e_j‖` of a determined parameter.
pub const DETERMINED_TOLERANCE: f64 = 1e-6;
/// Default τ_l: the smallest `|(N·Nᵀ)_jk|` that links two undetermined parameters.
pub const LINK_TOLERANCE: f64 = 1e-6;
/// Default limit of `|correlation|` above which two determined parameters are reported as
/// nearly confounded.
pub const CORRELATION_LIMIT: f64 = 0.99;

/// Two determined parameters whose estimates are strongly correlated.
#[derive(Clone, Debug, PartialEq)]
pub struct NearPair {
    /// Index of the first parameter.
    pub a: usize,
    /// Index of the second parameter (`a < b`).
    pub b: usize,
    /// Correlation of their estimates, in [−1, 1].
    pub correlation: f64,
}

/// The identifiability of every parameter of a fit. Indices are parameter (column) indices.
#[derive(Clone, Debug, PartialEq)]
pub struct Identifiability {
    /// Orthonormal basis of the null space of the scaled H, one column per deficient
    /// direction (rows: every parameter; rows of parameters fixed by a constraint are zero).
    pub null_space: DMatrix<f64>,
    /// `‖Nᵀ·e_j‖` per parameter (0 for a determined one to rounding, up to 1).
    pub null_weight: Vec<f64>,
    /// Whether the data determine the parameter (`null_weight ≤ τ_d`). Fixed parameters count
    /// as determined.
    pub determined: Vec<bool>,
    /// Groups of undetermined parameters that the data cannot separate, each ascending, ordered
    /// by their first member.
    pub confounded: Vec<Vec<usize>>,
    /// Determined pairs with `|correlation|` above the limit, by decreasing `|correlation|`.
    pub near_confounded: Vec<NearPair>,
}

/// Which parameters are determined, and the confounded groups, from a null-space basis `null`
/// (rows: parameters; columns: orthonormal null vectors in scaled coordinates), with the
/// tolerances `determined_tol` (τ_d) and `link_tol` (τ_l). Returns `(null_weight, determined,
/// groups)`.
pub fn null_space_groups(
    null: &DMatrix<f64>,
    determined_tol: f64,
    link_tol: f64,
) -> (Vec<f64>, Vec<bool>, Vec<Vec<usize>>) {
    let p = null.nrows();
    let projector = null * null.transpose();
    let weight: Vec<f64> = (0..p).map(|j| projector[(j, j)].max(0.0).sqrt()).collect();
    let determined: Vec<bool> = weight.iter().map(|&w| w <= determined_tol).collect();
    // Union-find over the undetermined parameters.
    let mut parent: Vec<usize> = (0..p).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for j in 0..p {
        for k in j + 1..p {
            if !determined[j] && !determined[k] && projector[(j, k)].abs() > link_tol {
                let (a, b) = (root(&mut parent, j), root(&mut parent, k));
                if a != b {
                    parent[a.max(b)] = a.min(b);
                }
            }
        }
    }
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut group_of_root = vec![usize::MAX; p];
    for j in (0..p).filter(|&j| !determined[j]) {
        let r = root(&mut parent, j);
        if group_of_root[r] == usize::MAX {
            group_of_root[r] = groups.len();
            groups.push(Vec::new());
        }
        groups[group_of_root[r]].push(j);
    }
    (weight, determined, groups)
}

/// Pairs of parameters, both `eligible`, whose correlation (`corr`, p × p; NaN where undefined)
/// exceeds `limit` in absolute value, by decreasing `|correlation|`.
pub fn near_confounded(corr: &DMatrix<f64>, eligible: &[bool], limit: f64) -> Vec<NearPair> {
    let p = corr.nrows().min(eligible.len());
    let mut pairs = Vec::new();
    for a in 0..p {
        for b in a + 1..p {
            let c = corr[(a, b)];
            if eligible[a] && eligible[b] && c.is_finite() && c.abs() > limit {
                pairs.push(NearPair {
                    a,
                    b,
                    correlation: c,
                });
            }
        }
    }
    pairs.sort_by(|x, y| y.correlation.abs().total_cmp(&x.correlation.abs()));
    pairs
}

/// The errors a group of sensor offsets cannot be told from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Swallowed {
    /// The offsets of the group (`dx0`).
    pub offsets: Vec<String>,
    /// The other parameters of the group (`XOC`).
    pub errors: Vec<String>,
}

/// For every confounded group holding a sensor offset (`is_offset[j]`), the offsets and the
/// other parameters they swallow, named by `names`.
pub fn swallowed_by_offsets(
    names: &[String],
    groups: &[Vec<usize>],
    is_offset: &[bool],
) -> Vec<Swallowed> {
    groups
        .iter()
        .filter(|g| {
            g.iter()
                .any(|&j| is_offset.get(j).copied().unwrap_or(false))
        })
        .map(|g| {
            let (off, rest): (Vec<usize>, Vec<usize>) = g
                .iter()
                .partition(|&&j| is_offset.get(j).copied().unwrap_or(false));
            let name = |j: usize| names.get(j).cloned().unwrap_or_else(|| format!("#{j}"));
            Swallowed {
                offsets: off.into_iter().map(name).collect(),
                errors: rest.into_iter().map(name).collect(),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mixed_null_vectors_still_give_separate_groups() {
        // Null space spanned by (e0 + e1)/√2 and (e2 − e3)/√2, returned rotated by 45°.
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let v1 = [h, h, 0.0, 0.0, 0.0];
        let v2 = [0.0, 0.0, h, -h, 0.0];
        let mut n = DMatrix::zeros(5, 2);
        for j in 0..5 {
            n[(j, 0)] = h * (v1[j] + v2[j]);
            n[(j, 1)] = h * (v1[j] - v2[j]);
        }
        let (w, det, groups) = null_space_groups(&n, 1e-6, 1e-6);
        assert_eq!(det, vec![false, false, false, false, true]);
        assert!((w[0] - h).abs() < 1e-15 && w[4] == 0.0);
        assert_eq!(groups, vec![vec![0, 1], vec![2, 3]]);
    }

    #[test]
    fn offsets_name_what_they_swallow() {
        let names: Vec<String> = ["XOC", "BOA", "dx0"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let s = swallowed_by_offsets(&names, &[vec![0, 2]], &[false, false, true]);
        assert_eq!(
            s,
            vec![Swallowed {
                offsets: vec!["dx0".into()],
                errors: vec!["XOC".into()]
            }]
        );
    }
}
