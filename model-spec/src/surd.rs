//! Exact numbers for the directions of inclined axes: `(num/den)·√radicand`, or a plain `f64`
//! where no such form is known.
//!
//! A direction such as `[0, 1, 1]` normalises to `(0, √2/2, √2/2)`; the rotation about it and
//! its own frame have entries of the same form, so the symbolic engine can keep them exact and
//! the gain tables hold `√2` instead of `0.7071067811865476` (and no `1e-17` where a term
//! cancels). Components written as decimals are read as the rational they spell (`0.5` is
//! `1/2`) or, when they are a long decimal such as `0.7071067811865476`, recognised as the
//! nearest `(p/q)·√m` with small `p`, `q`, `m` if it agrees to a few units in the last place.
//! Anything else stays numeric ([`Real::Numeric`]).

use std::fmt;

/// A real number: exact `(num/den)·√radicand` (radicand square-free, `den > 0`, the fraction
/// reduced; zero is `0/1·√1`), or numeric.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Real {
    /// `(num/den)·√radicand`.
    Surd {
        /// Numerator.
        num: i64,
        /// Denominator, positive.
        den: i64,
        /// Square-free radicand, ≥ 1.
        radicand: u64,
    },
    /// A value known only as a floating-point number.
    Numeric(f64),
}

fn gcd(mut a: i128, mut b: i128) -> i128 {
    (a, b) = (a.abs(), b.abs());
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

/// `n = k²·s` with `s` square-free, for `1 ≤ n ≤ 10^18`: `(k, s)`. Trial division up to 10^6
/// leaves a cofactor that is 1, a prime, the square of a prime or the product of two distinct
/// primes (three primes above 10^6 would exceed 10^18), so the split is exact.
fn square_free(n: i128) -> Option<(i128, i128)> {
    if !(1..=1_000_000_000_000_000_000).contains(&n) {
        return None;
    }
    let (mut rest, mut k, mut s) = (n, 1i128, 1i128);
    let mut p = 2i128;
    while p <= 1_000_000 && p * p <= rest {
        let mut e = 0;
        while rest % p == 0 {
            rest /= p;
            e += 1;
        }
        k *= p.pow(e / 2);
        if e % 2 == 1 {
            s *= p;
        }
        p += if p == 2 { 1 } else { 2 };
    }
    let r = (rest as f64).sqrt().round() as i128;
    if r * r == rest {
        k *= r;
    } else {
        s *= rest;
    }
    Some((k, s))
}

impl Real {
    /// Zero.
    pub const ZERO: Real = Real::Surd {
        num: 0,
        den: 1,
        radicand: 1,
    };

    /// `(num/den)·√radicand` reduced (the radicand's square factors taken out), or `None` when a
    /// part leaves the `i64` range or the radicand is not in `1..=10^18`.
    pub fn surd(num: i128, den: i128, radicand: i128) -> Option<Real> {
        if den == 0 {
            return None;
        }
        if num == 0 {
            return Some(Real::ZERO);
        }
        let (k, s) = square_free(radicand)?;
        let num = num.checked_mul(k)?;
        let g = gcd(num, den);
        let sign = if den < 0 { -1 } else { 1 };
        let (num, den) = (sign * num / g, sign * den / g);
        Some(Real::Surd {
            num: i64::try_from(num).ok()?,
            den: i64::try_from(den).ok()?,
            radicand: u64::try_from(s).ok()?,
        })
    }

    /// The exact number a component written as `x` stands for (see the module docs): the
    /// rational its decimal spells when that has at most 12 significant digits, else the
    /// nearest `(p/q)·√m` (`q ≤ 12`, `m ≤ 30` square-free, `|p| ≤ 120`) within four units in the
    /// last place, else numeric.
    pub fn recognise(x: f64) -> Real {
        if x == 0.0 {
            return Real::ZERO;
        }
        if let Some(r) = short_decimal(x) {
            return r;
        }
        for m in (2..=30i128).filter(|&m| square_free(m) == Some((1, m))) {
            for q in 1..=12i128 {
                let p = (x * q as f64 / (m as f64).sqrt()).round();
                if p == 0.0 || p.abs() > 120.0 {
                    continue;
                }
                let value = p * (m as f64).sqrt() / q as f64;
                if (value - x).abs() <= 4.0 * f64::EPSILON * x.abs()
                    && let Some(r) = Real::surd(p as i128, q, m)
                {
                    return r;
                }
            }
        }
        Real::Numeric(x)
    }

    /// The value as a floating-point number.
    pub fn to_f64(self) -> f64 {
        match self {
            Real::Surd { num, den, radicand } => num as f64 * (radicand as f64).sqrt() / den as f64,
            Real::Numeric(x) => x,
        }
    }

    /// `true` for the exact zero.
    pub fn is_zero(self) -> bool {
        matches!(self, Real::Surd { num: 0, .. })
    }

    /// `true` when exact.
    pub fn is_exact(self) -> bool {
        matches!(self, Real::Surd { .. })
    }

    /// The square, a rational `(num, den)`, when exact.
    fn square(self) -> Option<(i128, i128)> {
        match self {
            Real::Surd { num, den, radicand } => Some((
                (num as i128)
                    .checked_mul(num as i128)?
                    .checked_mul(radicand as i128)?,
                (den as i128).checked_mul(den as i128)?,
            )),
            Real::Numeric(_) => None,
        }
    }

    /// `self · o`: exact when both are and the result stays in range, numeric otherwise.
    pub fn times(self, o: Real) -> Real {
        if let (
            Real::Surd {
                num: a,
                den: b,
                radicand: m,
            },
            Real::Surd {
                num: c,
                den: d,
                radicand: n,
            },
        ) = (self, o)
        {
            let g = gcd(m as i128, n as i128);
            let exact = (|| {
                let num = (a as i128).checked_mul(c as i128)?.checked_mul(g)?;
                let den = (b as i128).checked_mul(d as i128)?;
                let rad = (m as i128 / g).checked_mul(n as i128 / g)?;
                Real::surd(num, den, rad)
            })();
            if let Some(r) = exact {
                return r;
            }
        }
        Real::Numeric(self.to_f64() * o.to_f64())
    }

    /// `−self`.
    pub fn negated(self) -> Real {
        match self {
            Real::Surd { num, den, radicand } => Real::Surd {
                num: -num,
                den,
                radicand,
            },
            Real::Numeric(x) => Real::Numeric(-x),
        }
    }

    /// `1/self` (`None` for zero).
    pub fn recip(self) -> Option<Real> {
        match self {
            _ if self.is_zero() => None,
            // 1/((p/q)·√m) = (q/(p·m))·√m
            Real::Surd { num, den, radicand } => Some(
                (num as i128)
                    .checked_mul(radicand as i128)
                    .and_then(|d| Real::surd(den as i128, d, radicand as i128))
                    .unwrap_or(Real::Numeric(1.0 / self.to_f64())),
            ),
            Real::Numeric(x) => Some(Real::Numeric(1.0 / x)),
        }
    }

    /// `√(num/den)` for a positive rational, exact when in range.
    fn sqrt_rational(num: i128, den: i128) -> Real {
        // √(n/d) = √(n·d)/d
        num.checked_mul(den)
            .and_then(|nd| Real::surd(1, den, nd))
            .unwrap_or(Real::Numeric((num as f64 / den as f64).sqrt()))
    }
}

/// The rational a decimal with at most 12 significant digits spells, or `None`.
fn short_decimal(x: f64) -> Option<Real> {
    let text = format!("{:e}", x.abs());
    let (mantissa, exponent) = text.split_once('e')?;
    let digits: String = mantissa.chars().filter(char::is_ascii_digit).collect();
    if digits.len() > 12 {
        return None;
    }
    let decimals = mantissa.split_once('.').map_or(0, |(_, f)| f.len()) as i32;
    let shift = exponent.parse::<i32>().ok()? - decimals;
    let mut num: i128 = digits.parse().ok()?;
    let mut den: i128 = 1;
    if shift >= 0 {
        num = num.checked_mul(10i128.checked_pow(shift as u32)?)?;
    } else {
        den = 10i128.checked_pow((-shift) as u32)?;
    }
    let sign = if x < 0.0 { -1 } else { 1 };
    Real::surd(sign * num, den, 1)
}

/// A unit vector and the orthonormal frame around it, exact where the components allow.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnitFrame {
    /// The frame's axes `x'`, `y'`, `z'` in the parent frame: `z'` the normalised direction,
    /// `x'` the parent x projected perpendicular to it, `y' = z' × x'`.
    pub axes: [[Real; 3]; 3],
}

/// The orthonormal frame of the direction `v` (finite, non-zero, not along x): see
/// [`UnitFrame::axes`]. Exact when every component is recognised as exact and the
/// normalisations stay in range; numeric (each entry [`Real::Numeric`]) otherwise.
pub fn unit_frame(v: [f64; 3]) -> UnitFrame {
    let exact = || -> Option<UnitFrame> {
        let c = v.map(Real::recognise);
        let squares = c.map(|x| x.square());
        let (mut n, mut d) = (0i128, 1i128);
        for s in squares {
            let (a, b) = s?;
            // n/d + a/b
            n = n.checked_mul(b)?.checked_add(a.checked_mul(d)?)?;
            d = d.checked_mul(b)?;
            let g = gcd(n, d).max(1);
            (n, d) = (n / g, d / g);
        }
        let inv_norm = Real::sqrt_rational(n, d).recip()?;
        let u = c.map(|x| x.times(inv_norm));
        // |x'|² = 1 − u_x²
        let (a, b) = u[0].square()?;
        let len = Real::sqrt_rational(b.checked_sub(a)?, b);
        let inv_len = len.recip()?;
        let x_axis = [
            len,
            u[0].times(u[1]).times(inv_len).negated(),
            u[0].times(u[2]).times(inv_len).negated(),
        ];
        // y' = z' × x' = (0, u_z/n, −u_y/n)
        let y_axis = [
            Real::ZERO,
            u[2].times(inv_len),
            u[1].times(inv_len).negated(),
        ];
        let frame = [x_axis, y_axis, u];
        frame
            .iter()
            .flatten()
            .all(|r| r.is_exact())
            .then_some(UnitFrame { axes: frame })
    };
    exact().unwrap_or_else(|| numeric_frame(v))
}

fn numeric_frame(v: [f64; 3]) -> UnitFrame {
    let norm = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let u = v.map(|x| x / norm);
    // |x'| = √(1 − u_x²) = √(u_y² + u_z²), the second form exact also near x.
    let len = u[1].hypot(u[2]);
    let x_axis = [len, -u[0] * u[1] / len, -u[0] * u[2] / len];
    let y_axis = [0.0, u[2] / len, -u[1] / len];
    UnitFrame {
        axes: [x_axis, y_axis, u].map(|a| a.map(Real::Numeric)),
    }
}

impl fmt::Display for Real {
    /// `√2/2`, `-1/2`, `3√6/4`, `0`; numeric values as the shortest round-trip decimal.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Real::Surd { num, den, radicand } => {
                let root = if radicand == 1 {
                    String::new()
                } else {
                    format!("√{radicand}")
                };
                let n = match (num.abs(), root.is_empty()) {
                    (k, true) => format!("{k}"),
                    (1, false) => root,
                    (k, false) => format!("{k}{root}"),
                };
                let sign = if num < 0 { "-" } else { "" };
                if den == 1 {
                    write!(f, "{sign}{n}")
                } else {
                    write!(f, "{sign}{n}/{den}")
                }
            }
            Real::Numeric(x) => write!(f, "{x}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recognises_the_usual_components() {
        assert_eq!(Real::recognise(0.5).to_string(), "1/2");
        assert_eq!(
            Real::recognise(std::f64::consts::FRAC_1_SQRT_2).to_string(),
            "√2/2"
        );
        assert_eq!(Real::recognise(3f64.sqrt() / 2.0).to_string(), "√3/2");
        assert_eq!(Real::recognise(-3f64.sqrt() / 2.0).to_string(), "-√3/2");
        assert_eq!(Real::recognise(2.0).to_string(), "2");
        assert!(!Real::recognise(0.123_456_789_012_345_67).is_exact());
        assert!(!Real::recognise(std::f64::consts::PI).is_exact());
    }

    #[test]
    fn frames_are_exact_and_orthonormal() {
        for v in [
            [0.0, 1.0, 1.0],
            [0.0, -2.0, 2.0],
            [1.0, 0.0, 1.0],
            [0.0, 0.5, 3f64.sqrt() / 2.0],
            [1.0, 2.0, 3.0],
            [0.0, 0.766_044_443_118_978, 0.642_787_609_686_539_4],
        ] {
            let f = unit_frame(v);
            let a = f.axes.map(|r| r.map(Real::to_f64));
            for i in 0..3 {
                for j in 0..3 {
                    let dot: f64 = (0..3).map(|k| a[i][k] * a[j][k]).sum();
                    let want = if i == j { 1.0 } else { 0.0 };
                    assert!((dot - want).abs() < 1e-15, "{v:?} {i} {j} {dot}");
                }
            }
            let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            for k in 0..3 {
                assert!((a[2][k] - v[k] / norm).abs() < 1e-15);
            }
            // right-handed: x' × y' = z'
            let cross = [
                a[0][1] * a[1][2] - a[0][2] * a[1][1],
                a[0][2] * a[1][0] - a[0][0] * a[1][2],
                a[0][0] * a[1][1] - a[0][1] * a[1][0],
            ];
            for k in 0..3 {
                assert!((cross[k] - a[2][k]).abs() < 1e-15);
            }
        }
        // Within rounding of x: the exact form leaves the integer range, the numeric frame is
        // still orthonormal with x' close to -y.
        let near_x = unit_frame([1.0, 1e-9, 0.0])
            .axes
            .map(|r| r.map(Real::to_f64));
        assert!((near_x[0][1] + 1.0).abs() < 1e-12, "{near_x:?}");
        let f = unit_frame([0.0, 1.0, 1.0]);
        assert!(f.axes.iter().flatten().all(|r| r.is_exact()));
        assert_eq!(f.axes[2][1].to_string(), "√2/2");
        assert_eq!(f.axes[0][0].to_string(), "1");
        let g = unit_frame([1.0, 2.0, 3.0]);
        assert_eq!(g.axes[2][0].to_string(), "√14/14");
        assert!(
            !unit_frame([0.0, 0.766_044_443_118_978, 0.642_787_609_686_539_4]).axes[2][1]
                .is_exact()
        );
    }
}
