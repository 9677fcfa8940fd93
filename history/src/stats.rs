//! The two quantiles the drift flags need: the two-sided quantile of the standard normal
//! distribution (the change against the baseline) and of Student's t (the trend's slope).
//!
//! Both invert the tails of `fitting::distributions` (the normal tail by Numerical
//! Recipes' `erfcc`, fractional error below 1.2e-7; Student's t by the regularized incomplete
//! beta function) by bisection to the last bit, and are checked against tabulated values.

use fitting::distributions::{normal_upper_tail, t_two_sided};

/// The smallest and largest two-sided level the flags accept.
pub const ALPHA_RANGE: (f64, f64) = (1e-6, 0.2);

/// `x` with `tail(x) = alpha` for a tail decreasing from `tail(0) ≥ alpha`, by bisection.
fn invert(alpha: f64, tail: impl Fn(f64) -> f64) -> f64 {
    let mut hi = 1.0;
    while tail(hi) > alpha && hi < 1e12 {
        hi *= 2.0;
    }
    let mut lo = 0.0;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if tail(mid) > alpha {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// `z` with `P(|Z| > z) = alpha` for a standard normal `Z` (2.5758 for `alpha` = 0.01), for
/// `alpha` in (0, 1).
pub fn normal_two_sided(alpha: f64) -> f64 {
    invert(alpha, |z| 2.0 * normal_upper_tail(z))
}

/// `t` with `P(|T| > t) = alpha` for Student's `T` with `nu` degrees of freedom (63.657 for
/// `alpha` = 0.01 and one degree of freedom, 3.169 for ten), for `alpha` in (0, 1) and
/// `nu ≥ 1`.
pub fn student_two_sided(alpha: f64, nu: usize) -> f64 {
    let nu = nu as f64;
    invert(alpha, |t| t_two_sided(t, nu))
}

/// The two-sided p-value `P(|T| > |t|)` of Student's t with `nu` degrees of freedom.
pub fn student_p_value(t: f64, nu: usize) -> f64 {
    t_two_sided(t.abs(), nu as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_quantiles_match_tables() {
        for (alpha, z) in [
            (0.05, 1.959_963_984_540_054),
            (0.01, 2.575_829_303_548_901),
            (0.001, 3.290_526_731_491_926),
            (0.2, 1.281_551_565_544_601),
            (1e-6, 4.891_638_475_692_932),
        ] {
            let got = normal_two_sided(alpha);
            assert!((got - z).abs() < 2e-6 * z, "alpha {alpha}: {got} vs {z}");
        }
    }

    #[test]
    fn student_quantiles_match_tables() {
        // Two-sided critical values (computed to 17 digits with mpmath's regularized incomplete beta function).
        for (alpha, nu, t) in [
            (0.01, 1, 63.656_741_162_871_58),
            (0.01, 2, 9.924_843_200_918_28),
            (0.01, 3, 5.840_909_309_733_35),
            (0.01, 5, 4.032_142_983_555_228),
            (0.01, 10, 3.169_272_672_616_947_5),
            (0.01, 18, 2.878_440_472_738_608),
            (0.01, 30, 2.749_995_653_567_23),
            (0.05, 1, 12.706_204_736_174_707),
            (0.05, 10, 2.228_138_851_986_273_7),
            (0.05, 100, 1.983_971_518_523_552),
            (0.001, 4, 8.610_301_581_379_275),
        ] {
            let got = student_two_sided(alpha, nu);
            assert!(
                (got - t).abs() < 1e-9 * t,
                "alpha {alpha}, nu {nu}: {got} vs {t}"
            );
            assert!((student_p_value(-got, nu) - alpha).abs() < 1e-12);
        }
        // Many degrees of freedom: the normal quantile.
        let z = normal_two_sided(0.01);
        assert!((student_two_sided(0.01, 100_000) - z).abs() < 1e-4);
    }
}
