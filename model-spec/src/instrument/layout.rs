//! The first-order map of an instrument: how each reading moves with the displacement at zero,
//! and how well the sensors' directions span the three dimensions.

use super::{Instrument, Tip, dot};

/// The first-order matrix of the instrument: one row per sensor, the change of its reading per
/// change of the error vector at zero displacement (mm/mm, nest frame). A flat tip gives
/// `gain·m`; a ball tip `gain·q/(m·q)`, `q` its centre at zero reading (which is `gain·m` when
/// the plunger axis passes through the nest centre).
pub fn first_order_matrix(instrument: &Instrument) -> Vec<[f64; 3]> {
    let r = instrument.ball_radius_mm;
    instrument
        .sensors
        .iter()
        .map(|s| match s.tip {
            Tip::Flat { .. } => s.direction.map(|v| s.gain * v),
            Tip::Sphere { .. } => {
                let q = s.tip_at_zero(r);
                let along = dot(s.direction, q);
                q.map(|v| s.gain * v / along)
            }
        })
        .collect()
}

/// The smallest singular value of the matrix whose rows are `rows` (three columns): the least
/// root-sum-square change of the rows' products with a unit vector. 0 when the rows do not span
/// the three dimensions.
pub fn smallest_singular_value(rows: &[[f64; 3]]) -> f64 {
    let mut g = [[0.0; 3]; 3];
    for r in rows {
        for i in 0..3 {
            for j in 0..3 {
                g[i][j] += r[i] * r[j];
            }
        }
    }
    let eigen = symmetric_eigenvalues(g);
    eigen
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min)
        .max(0.0)
        .sqrt()
}

/// The eigenvalues of a symmetric 3×3 matrix, by cyclic Jacobi rotations.
fn symmetric_eigenvalues(mut a: [[f64; 3]; 3]) -> [f64; 3] {
    for _ in 0..64 {
        let off = a[0][1].powi(2) + a[0][2].powi(2) + a[1][2].powi(2);
        let diag = a[0][0].powi(2) + a[1][1].powi(2) + a[2][2].powi(2);
        if off <= 1e-30 * diag.max(f64::MIN_POSITIVE) {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A ← Jᵀ·A·J with the rotation J in the (p, q) plane: columns, then rows.
            for row in a.iter_mut() {
                let (akp, akq) = (row[p], row[q]);
                row[p] = c * akp - s * akq;
                row[q] = s * akp + c * akq;
            }
            let (rp, rq) = (a[p], a[q]);
            a[p] = std::array::from_fn(|k| c * rp[k] - s * rq[k]);
            a[q] = std::array::from_fn(|k| s * rp[k] + c * rq[k]);
        }
    }
    [a[0][0], a[1][1], a[2][2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn singular_values_of_known_layouts() {
        let orthogonal = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]];
        assert!((smallest_singular_value(&orthogonal) - 1.0).abs() < 1e-15);
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let inclined: Vec<[f64; 3]> = [0.0f64, 120.0, 240.0]
            .iter()
            .map(|a| {
                let (s, c) = a.to_radians().sin_cos();
                [-h * c, -h * s, -h]
            })
            .collect();
        // Gram matrix diag(0.75, 0.75, 1.5): the smallest singular value is √0.75.
        assert!((smallest_singular_value(&inclined) - 0.75f64.sqrt()).abs() < 1e-14);
        let flat = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
        assert!(smallest_singular_value(&flat) < 1e-12);
        let skew = [[2.0, 1.0, 0.5], [1.0, 3.0, 0.25], [0.5, 0.25, 4.0]];
        let e = symmetric_eigenvalues(skew);
        let trace: f64 = e.iter().sum();
        assert!((trace - 9.0).abs() < 1e-12);
        let det = 2.0 * (12.0 - 0.0625) - 1.0 * (4.0 - 0.125) + 0.5 * (0.25 - 1.5);
        assert!((e[0] * e[1] * e[2] - det).abs() < 1e-10);
    }
}
