//! The part of a least-squares fit that depends on H alone, made once and shared by every fit
//! of the same H to other readings: the column scaling, the SVD, the rank, the unit covariance
//! and what the data determine ([`Factored`]); and the same for generalized least squares under
//! a noise model ([`WhitenedFactored`]). A Gauss–Newton refinement fits the same H to a new
//! residual at every step: it factorises once. A fit made from a factorisation is the fit
//! [`super::least_squares()`] makes, bit for bit (the same operations in the same order); the
//! method is in [`mod@super::least_squares`]'s documentation.
//!
//! A tall H (more rows than free columns) is reduced by its QR decomposition folded in blocks
//! of rows, the streaming identification's fold; `Q` is not kept. A fit of readings `y` takes
//! `Qᵀ·y` from the fold of `[A | y]` (A the scaled H): made with the factorisation for the
//! readings given to it (the first fit of a refinement, the only one of an identification),
//! and again, one pass over H's rows, for other readings.

mod rows;

pub use rows::{RowsFactored, WhitenedFactored};

use crate::identifiability::{Identifiability, near_confounded, null_space_groups};
use crate::least_squares::{Constraint, EstimateError, Fit, Tolerances};
use crate::svd::{Left, Scaled, decompose};
use nalgebra::{DMatrix, DVector};

/// The factorisation of one H (m × n, mm per unit of each parameter) under one constraint and
/// set of tolerances: everything of a fit but what the readings change (the solution, the
/// residual, σ̂ and what it scales).
#[derive(Clone, Debug)]
pub struct Factored {
    /// Rows and columns of H.
    shape: (usize, usize),
    /// Parameter names, one per column.
    names: Vec<String>,
    /// The constraint.
    constraint: Constraint,
    /// Fixed to zero by the constraint.
    fixed: Vec<bool>,
    /// The columns not fixed.
    free: Vec<usize>,
    /// `s_j = ‖h_j‖₂` (1 for a zero or fixed column).
    norms: Vec<f64>,
    /// Singular values of the scaled H of the free columns, descending.
    sv: Vec<f64>,
    /// The left singular vectors, as the readings meet them.
    left: Left,
    /// Right singular vectors, as columns.
    v: DMatrix<f64>,
    /// Numerical rank.
    rank: usize,
    /// The rank tolerance τ.
    tau: f64,
    /// The real number of rows (degrees of freedom).
    rows_total: usize,
    /// `V_r Σ_r⁻² V_rᵀ`, unscaled (per unit² of the parameters, per mm²).
    unit: DMatrix<f64>,
    /// Which parameters get a value.
    has_value: Vec<bool>,
    /// The correlation of the estimates (independent of σ̂); NaN where undefined.
    correlation: DMatrix<f64>,
    /// What the data determine.
    identifiability: Identifiability,
}

/// Checks the shapes of `h` (m × n) against `readings` values and `names`.
fn check_shape(h: &DMatrix<f64>, readings: usize, names: usize) -> Result<(), EstimateError> {
    let (m, n) = h.shape();
    if m == 0 || n == 0 {
        return Err(EstimateError::Shape(format!(
            "nothing to fit: H is {m}×{n} (samples × 3 by parameters)"
        )));
    }
    if readings != m || names != n {
        return Err(EstimateError::Shape(format!(
            "H is {m}×{n} but there are {readings} measured values and {names} names"
        )));
    }
    Ok(())
}

/// Whether every entry of `v` is finite: `x·0` is NaN exactly for an infinite or NaN `x`, so
/// a sum of them is 0 exactly when all are finite (in running sums, so that it vectorises).
fn all_finite(v: &[f64]) -> bool {
    let (chunks, rest) = v.as_chunks::<8>();
    let mut sum = [0.0; 8];
    for c in chunks {
        for i in 0..8 {
            sum[i] += c[i] * 0.0;
        }
    }
    sum.iter().all(|s| *s == 0.0) && rest.iter().all(|x| x.is_finite())
}

/// `v` (`cols` columns, or a vector when 0) with no NaN or infinite entry, else the error
/// naming the first one in `what`.
pub(crate) fn check_finite(what: &str, v: &[f64], cols: usize) -> Result<(), EstimateError> {
    if all_finite(v) {
        return Ok(());
    }
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) if cols > 0 => Err(EstimateError::NotFinite(format!(
            "{what}[{}, {}] ({})",
            i % (v.len() / cols),
            i / (v.len() / cols),
            v[i]
        ))),
        Some(i) => Err(EstimateError::NotFinite(format!("{what}[{i}] ({})", v[i]))),
    }
}

/// Checks readings `y` for a fit of `h` with `names`: their number and that they are finite.
pub(crate) fn check_readings_of(
    h: &DMatrix<f64>,
    y: &DVector<f64>,
    names: &[String],
) -> Result<(), EstimateError> {
    check_shape(h, y.len(), names.len())?;
    check_finite("H", h.as_slice(), h.ncols())?;
    check_finite("y", y.as_slice(), 0)
}

impl Factored {
    /// The factorisation of `h` with parameter `names` under `constraint` with `tol`; `rows_total`
    /// is the real number of rows (for the rank tolerance and the degrees of freedom: more than
    /// `h`'s for a reduced system).
    ///
    /// # Errors
    /// Sizes that do not fit, no rows or no columns, NaN or infinite entries, an unknown name in
    /// [`Constraint::Zero`], an SVD that does not converge.
    pub fn new(
        h: &DMatrix<f64>,
        names: &[String],
        constraint: &Constraint,
        tol: &Tolerances,
        rows_total: usize,
    ) -> Result<Factored, EstimateError> {
        Factored::with_readings(h, None, names, constraint, tol, rows_total)
    }

    /// [`Factored::new`] with the readings `y` (mm, as many as `h` has rows) of the fit to come
    /// folded with H (when H is tall), so that [`Factored::fit`] of those readings needs no
    /// second pass over H's rows; the factorisation is the same, bit for bit.
    ///
    /// # Errors
    /// As [`Factored::new`].
    pub(crate) fn with_readings(
        h: &DMatrix<f64>,
        y: Option<&DVector<f64>>,
        names: &[String],
        constraint: &Constraint,
        tol: &Tolerances,
        rows_total: usize,
    ) -> Result<Factored, EstimateError> {
        let (m, n) = h.shape();
        check_shape(h, m, names.len())?;
        // Every column's norm: all finite when every entry is (and no sum of squares overflows),
        // else the first entry that is not.
        let all_norms: Vec<f64> = h.column_iter().map(|c| c.norm()).collect();
        if !all_norms.iter().all(|s| s.is_finite()) {
            check_finite("H", h.as_slice(), n)?;
        }
        let mut fixed = vec![false; n];
        if let Constraint::Zero(zero) = constraint {
            for z in zero {
                // The exact name, or the canonical spelling of its effect (`X0C` for `XOC`).
                let canonical = match z.trim().split_once('@') {
                    Some((e, b)) => format!("{}@{b}", model_spec::canonical_name(e)),
                    None => model_spec::canonical_name(z),
                };
                let j = names
                    .iter()
                    .position(|x| x == z.trim() || *x == canonical)
                    .ok_or_else(|| EstimateError::UnknownParameter(z.clone(), names.join(", ")))?;
                fixed[j] = true;
            }
        }
        let free: Vec<usize> = (0..n).filter(|&j| !fixed[j]).collect();
        let nf = free.len();
        // Column scaling.
        let mut norms = vec![1.0; n];
        for &j in &free {
            let s = all_norms[j];
            if !s.is_finite() {
                return Err(EstimateError::NotFinite(format!(
                    "the norm of column `{}` of H",
                    names[j]
                )));
            }
            if s > 0.0 {
                norms[j] = s;
            }
        }
        let scaled = Scaled {
            h,
            free: &free,
            norms: &norms,
        };
        let (sv, left, v) = decompose(scaled, y)?;
        let smax = sv.first().copied().unwrap_or(0.0);
        let tau = smax
            * tol
                .rank_relative
                .max(rows_total.max(n) as f64 * f64::EPSILON);
        let rank = sv.iter().take_while(|&&s| s > tau && s > 0.0).count();
        // Unit covariance V_r Σ_r⁻² V_rᵀ in scaled coordinates, then unscaled.
        let mut unit = DMatrix::<f64>::zeros(n, n);
        for (ka, &ja) in free.iter().enumerate() {
            for (kb, &jb) in free.iter().enumerate() {
                let c: f64 = (0..rank)
                    .map(|i| v[(ka, i)] * v[(kb, i)] / (sv[i] * sv[i]))
                    .sum();
                unit[(ja, jb)] = c / (norms[ja] * norms[jb]);
            }
        }
        // Null space (rows: all parameters; fixed rows zero).
        let mut null = DMatrix::<f64>::zeros(n, nf - rank);
        for (k, &j) in free.iter().enumerate() {
            for c in rank..nf {
                null[(j, c - rank)] = v[(k, c)];
            }
        }
        let (null_weight, determined, confounded) =
            null_space_groups(&null, tol.determined, tol.link);
        let has_value: Vec<bool> = (0..n)
            .map(|j| fixed[j] || determined[j] || *constraint == Constraint::MinimumNorm)
            .collect();
        let mut correlation = DMatrix::<f64>::from_element(n, n, f64::NAN);
        for a in 0..n {
            for b in 0..n {
                if !(fixed[a] || fixed[b]) && has_value[a] && has_value[b] {
                    let d = (unit[(a, a)] * unit[(b, b)]).sqrt();
                    if d > 0.0 {
                        correlation[(a, b)] = (unit[(a, b)] / d).clamp(-1.0, 1.0);
                    }
                }
            }
        }
        let eligible: Vec<bool> = (0..n).map(|j| determined[j] && !fixed[j]).collect();
        let near = near_confounded(&correlation, &eligible, tol.correlation);
        Ok(Factored {
            shape: (m, n),
            names: names.to_vec(),
            constraint: constraint.clone(),
            fixed,
            free,
            norms,
            sv,
            left,
            v,
            rank,
            tau,
            rows_total,
            unit,
            has_value,
            correlation,
            identifiability: Identifiability {
                null_space: null,
                null_weight,
                determined,
                confounded,
                near_confounded: near,
            },
        })
    }

    /// The numerical rank.
    pub fn rank(&self) -> usize {
        self.rank
    }

    /// Which parameters the data determine.
    pub fn determined(&self) -> &[bool] {
        &self.identifiability.determined
    }

    /// The fit of readings `y` (mm; as many as `h` has rows) by `h`, the matrix factorised;
    /// `rss_outside` adds to the residual sum of squares (mm²). Readings other than those the
    /// factorisation was made with are folded with `h`'s rows again (a pass over them).
    ///
    /// # Errors
    /// Readings of another number than `h`'s rows, or not finite.
    pub fn fit(
        &self,
        h: &DMatrix<f64>,
        y: &DVector<f64>,
        rss_outside: f64,
    ) -> Result<Fit, EstimateError> {
        let (m, n) = self.shape;
        check_shape(h, y.len(), self.names.len())?;
        check_finite("y", y.as_slice(), 0)?;
        let (free, norms, sv, rank) = (&self.free, &self.norms, &self.sv, self.rank);
        let nf = free.len();
        // Minimum-norm solution in the identifiable subspace (scaled coordinates).
        let padded;
        let ypad = if m >= nf {
            y
        } else {
            padded = y.clone().resize_vertically(nf, 0.0);
            &padded
        };
        let mut z = DVector::<f64>::zeros(nf);
        let scaled = Scaled { h, free, norms };
        for (i, (uty, s)) in self
            .left
            .project(scaled, ypad, rank)
            .iter()
            .zip(sv)
            .enumerate()
        {
            z.axpy(uty / s, &self.v.column(i), 1.0);
        }
        let mut x = vec![0.0; n];
        for (k, &j) in free.iter().enumerate() {
            x[j] = z[k] / norms[j];
        }
        let residual = y - h * DVector::from_column_slice(&x);
        let rss = residual.norm_squared() + rss_outside;
        let dof = self.rows_total.saturating_sub(rank);
        let sigma = (dof > 0).then(|| (rss / dof as f64).sqrt());
        let (fixed, has_value) = (&self.fixed, &self.has_value);
        let values: Vec<Option<f64>> = (0..n).map(|j| has_value[j].then_some(x[j])).collect();
        let std: Vec<Option<f64>> = (0..n)
            .map(|j| match sigma {
                Some(s) if has_value[j] && !fixed[j] => Some(s * self.unit[(j, j)].max(0.0).sqrt()),
                _ => None,
            })
            .collect();
        let mut covariance = DMatrix::<f64>::from_element(n, n, f64::NAN);
        for a in 0..n {
            for b in 0..n {
                if fixed[a] || fixed[b] {
                    covariance[(a, b)] = 0.0;
                } else if has_value[a]
                    && has_value[b]
                    && let Some(s) = sigma
                {
                    covariance[(a, b)] = s * s * self.unit[(a, b)];
                }
            }
        }
        let smax = sv.first().copied().unwrap_or(0.0);
        Ok(Fit {
            names: self.names.clone(),
            values,
            solution: x,
            std,
            fixed: fixed.clone(),
            column_norms: norms.clone(),
            rank_tolerance: self.tau,
            condition: (rank > 0).then(|| smax / sv[rank - 1]),
            singular_values: sv.clone(),
            rank,
            covariance,
            correlation: self.correlation.clone(),
            residual,
            rss,
            dof,
            sigma,
            identifiability: self.identifiability.clone(),
            constraint: self.constraint.clone(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use simulation::rng::Rng;

    /// A 300 × 6 H of random columns, the sixth `2·h₀ − 3·h₁`, the third 1000 times the others,
    /// random readings, and the parameter names `p0` … `p5`.
    fn rank_deficient() -> (DMatrix<f64>, DVector<f64>, Vec<String>) {
        let mut rng = Rng::new(5);
        let (m, n) = (300, 6);
        let mut h = DMatrix::from_fn(m, n, |_, _| rng.normal());
        let combined = h.column(0) * 2.0 - h.column(1) * 3.0;
        h.set_column(5, &combined);
        h.column_mut(2).scale_mut(1e3);
        let y = DVector::from_fn(m, |_, _| rng.normal());
        (h, y, (0..n).map(|j| format!("p{j}")).collect())
    }

    /// A square upper-triangular H with a dependent column (the reduced system the streaming
    /// fold hands over) fits as the tall H it came from: the SVD that does not rebuild it is
    /// not used.
    #[test]
    fn a_triangular_factor_fits_as_the_tall_system() {
        let (h, y, names) = rank_deficient();
        let (m, n) = h.shape();
        let qr = h.clone().qr();
        let r = qr.r();
        let mut qty = y.clone();
        qr.q_tr_mul(&mut qty);
        let top = qty.rows(0, n).into_owned();
        let c = Constraint::MinimumNorm;
        let tall = Factored::new(&h, &names, &c, &Tolerances::default(), m).unwrap();
        let square = Factored::new(&r, &names, &c, &Tolerances::default(), m).unwrap();
        let (a, b) = (
            tall.fit(&h, &y, 0.0).unwrap(),
            square.fit(&r, &top, 0.0).unwrap(),
        );
        assert_eq!((tall.rank(), square.rank()), (5, 5));
        for j in 0..n {
            assert!(
                (a.solution[j] - b.solution[j]).abs() <= 1e-10 * a.solution[j].abs().max(1e-3),
                "{j}: {} vs {}",
                a.solution[j],
                b.solution[j]
            );
        }
        let gradient = h.transpose() * (&y - &h * DVector::from_column_slice(&a.solution));
        assert!(
            gradient.norm() < 1e-9 * y.norm(),
            "not a least-squares solution"
        );
    }

    /// A fit made from a factorisation is the minimum-norm least-squares solution with the
    /// singular values and rank of the scaled H; a column that is a combination of two others
    /// leaves them undetermined.
    #[test]
    fn a_factorisation_fits_as_the_svd_solves() {
        let (h, y, names) = rank_deficient();
        let (m, n) = h.shape();
        let f = Factored::new(
            &h,
            &names,
            &Constraint::MinimumNorm,
            &Tolerances::default(),
            m,
        )
        .unwrap();
        assert_eq!(f.rank(), 5);
        assert!(!f.determined()[0] && !f.determined()[1] && !f.determined()[5]);
        assert!(f.determined()[2] && f.determined()[3] && f.determined()[4]);
        let fit = f.fit(&h, &y, 0.0).unwrap();
        // The minimum-norm solution in scaled coordinates, from the SVD of the scaled H.
        let norms: Vec<f64> = h.column_iter().map(|c| c.norm()).collect();
        let a = DMatrix::from_fn(m, n, |i, j| h[(i, j)] / norms[j]);
        let svd = a.clone().svd(true, true);
        let z = svd.solve(&y, 1e-8 * svd.singular_values.max()).unwrap();
        for j in 0..n {
            let want = z[j] / norms[j];
            assert!(
                (fit.solution[j] - want).abs() <= 1e-10 * want.abs().max(1e-3),
                "{j}: {} vs {want}",
                fit.solution[j]
            );
        }
        let mut sv = svd.singular_values.as_slice().to_vec();
        sv.sort_by(|a, b| b.total_cmp(a));
        for (got, want) in fit.singular_values.iter().zip(&sv).take(5) {
            assert!((got - want).abs() <= 1e-12 * want, "{got} vs {want}");
        }
        let residual = &y - &h * DVector::from_column_slice(&fit.solution);
        assert!((fit.rss - residual.norm_squared()).abs() <= 1e-12 * fit.rss);
    }
}
