//! Exact rational coefficients (`i128` numerator and denominator, always reduced, denominator
//! positive). Machine descriptions give decimal numbers; [`Rational::from_decimal`] reads the
//! shortest decimal that round-trips the `f64` exactly, so `211.537` is `211537/1000`, not the
//! binary expansion.

use std::cmp::Ordering;
use std::fmt;

/// An exact rational number.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Rational {
    num: i128,
    den: i128,
}

/// `a / b`, exact, in 64 bits when both fit (a 128-bit division is a slow library call).
fn div(a: i128, b: i128) -> i128 {
    match (i64::try_from(a), i64::try_from(b)) {
        (Ok(x), Ok(y)) if y != -1 => i128::from(x / y),
        _ => a / b,
    }
}

/// The greatest common divisor of `|a|` and `|b|` (binary: shifts and subtractions, no
/// 128-bit division).
fn gcd(a: i128, b: i128) -> i128 {
    let (mut a, mut b) = (a.unsigned_abs(), b.unsigned_abs());
    if a == 0 || b == 0 {
        return (a | b) as i128;
    }
    if let (Ok(x), Ok(y)) = (u64::try_from(a), u64::try_from(b)) {
        return i128::from(gcd64(x, y));
    }
    let shift = (a | b).trailing_zeros();
    a >>= a.trailing_zeros();
    loop {
        b >>= b.trailing_zeros();
        if a > b {
            std::mem::swap(&mut a, &mut b);
        }
        b -= a;
        if b == 0 {
            return (a << shift) as i128;
        }
    }
}

/// The binary greatest common divisor of two non-zero `u64`.
fn gcd64(mut a: u64, mut b: u64) -> u64 {
    let shift = (a | b).trailing_zeros();
    a >>= a.trailing_zeros();
    loop {
        b >>= b.trailing_zeros();
        if a > b {
            std::mem::swap(&mut a, &mut b);
        }
        b -= a;
        if b == 0 {
            return a << shift;
        }
    }
}

/// Arithmetic left the range of `i128` (coefficients of first-order gains stay tiny; this only
/// happens for absurd inputs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("rational arithmetic overflow")]
pub struct Overflow;

impl Rational {
    /// Zero.
    pub const ZERO: Rational = Rational { num: 0, den: 1 };
    /// One.
    pub const ONE: Rational = Rational { num: 1, den: 1 };

    /// `num / den`, reduced. Panics if `den` is zero (a bug, never user input).
    pub fn new(num: i128, den: i128) -> Rational {
        assert!(den != 0, "zero denominator");
        let g = gcd(num, den).max(1);
        let s = if den < 0 { -1 } else { 1 };
        Rational {
            num: s * div(num, g),
            den: s * div(den, g),
        }
    }

    /// An integer.
    pub fn int(n: i64) -> Rational {
        Rational {
            num: n as i128,
            den: 1,
        }
    }

    /// The exact value of the shortest decimal that round-trips `x` (`None` if not finite or
    /// too many digits for `i128`).
    pub fn from_decimal(x: f64) -> Option<Rational> {
        if !x.is_finite() {
            return None;
        }
        // `{:e}` prints the shortest round-trip digits in scientific form: d.ddddde±k.
        let s = format!("{x:e}");
        let (mantissa, exp) = s.split_once('e')?;
        let exp: i32 = exp.parse().ok()?;
        let negative = mantissa.starts_with('-');
        let digits: String = mantissa.chars().filter(char::is_ascii_digit).collect();
        let frac_len = mantissa.split_once('.').map_or(0, |(_, f)| f.len()) as i32;
        let mut num: i128 = digits.parse().ok()?;
        if negative {
            num = -num;
        }
        let shift = exp - frac_len;
        let pow = |k: i32| 10i128.checked_pow(k as u32);
        if shift >= 0 {
            Some(Rational::new(num.checked_mul(pow(shift)?)?, 1))
        } else {
            Some(Rational::new(num, pow(-shift)?))
        }
    }

    /// Numerator.
    pub fn numer(self) -> i128 {
        self.num
    }

    /// Denominator (positive).
    pub fn denom(self) -> i128 {
        self.den
    }

    /// `true` for zero.
    pub fn is_zero(self) -> bool {
        self.num == 0
    }

    /// `true` for one.
    pub fn is_one(self) -> bool {
        self.num == 1 && self.den == 1
    }

    /// `true` below zero.
    pub fn is_negative(self) -> bool {
        self.num < 0
    }

    /// The absolute value.
    pub fn abs(self) -> Rational {
        Rational {
            num: self.num.abs(),
            den: self.den,
        }
    }

    /// The nearest `f64`.
    pub fn to_f64(self) -> f64 {
        // Both parts are exact in f64 for all coefficients that occur (|n|, d < 2^53);
        // otherwise the division rounds once more, which is still within an ulp or two.
        self.num as f64 / self.den as f64
    }

    /// `self + o`, or an overflow.
    pub fn checked_add(self, o: Rational) -> Result<Rational, Overflow> {
        if self.den == 1 && o.den == 1 {
            let num = self.num.checked_add(o.num).ok_or(Overflow)?;
            return Ok(Rational { num, den: 1 });
        }
        let g = gcd(self.den, o.den);
        let l = (self.den / g).checked_mul(o.den).ok_or(Overflow)?;
        let a = self.num.checked_mul(l / self.den).ok_or(Overflow)?;
        let b = o.num.checked_mul(l / o.den).ok_or(Overflow)?;
        Ok(Rational::new(a.checked_add(b).ok_or(Overflow)?, l))
    }

    /// `self * o`, or an overflow.
    pub fn checked_mul(self, o: Rational) -> Result<Rational, Overflow> {
        if self.den == 1 && o.den == 1 {
            let num = self.num.checked_mul(o.num).ok_or(Overflow)?;
            return Ok(Rational { num, den: 1 });
        }
        // Both factors are reduced, so dividing out the cross common factors leaves the
        // product reduced.
        let g1 = gcd(self.num, o.den).max(1);
        let g2 = gcd(o.num, self.den).max(1);
        let n = div(self.num, g1)
            .checked_mul(div(o.num, g2))
            .ok_or(Overflow)?;
        let d = div(self.den, g2)
            .checked_mul(div(o.den, g1))
            .ok_or(Overflow)?;
        Ok(Rational { num: n, den: d })
    }
}

impl std::ops::Neg for Rational {
    type Output = Rational;
    fn neg(self) -> Rational {
        Rational {
            num: -self.num,
            den: self.den,
        }
    }
}

impl Ord for Rational {
    fn cmp(&self, o: &Rational) -> Ordering {
        (self.num * o.den).cmp(&(o.num * self.den))
    }
}

impl PartialOrd for Rational {
    fn partial_cmp(&self, o: &Rational) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

impl fmt::Display for Rational {
    /// Integers as integers, terminating fractions as exact decimals (`211.537`), the others
    /// as `n/d`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.den == 1 {
            return write!(f, "{}", self.num);
        }
        let (mut d, mut k) = (self.den, 0u32);
        let (mut twos, mut fives) = (0u32, 0u32);
        while d % 2 == 0 {
            d /= 2;
            twos += 1;
        }
        while d % 5 == 0 {
            d /= 5;
            fives += 1;
        }
        if d != 1 {
            return write!(f, "{}/{}", self.num, self.den);
        }
        k += twos.max(fives);
        let scale = 10i128.pow(k) / self.den;
        let n = self.num * scale;
        let sign = if n < 0 { "-" } else { "" };
        let n = n.abs();
        let p = 10i128.pow(k);
        write!(f, "{sign}{}.{:0width$}", n / p, n % p, width = k as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimals_are_exact() {
        assert_eq!(
            Rational::from_decimal(211.537),
            Some(Rational::new(211537, 1000))
        );
        assert_eq!(
            Rational::from_decimal(-0.279),
            Some(Rational::new(-279, 1000))
        );
        assert_eq!(Rational::from_decimal(0.1), Some(Rational::new(1, 10)));
        assert_eq!(
            Rational::from_decimal(1e20),
            Some(Rational::new(100_000_000_000_000_000_000, 1))
        );
        assert_eq!(Rational::from_decimal(f64::NAN), None);
        assert_eq!(Rational::new(211537, 1000).to_string(), "211.537");
        assert_eq!(Rational::new(-1, 3).to_string(), "-1/3");
        assert_eq!(Rational::new(-7, 4).to_string(), "-1.75");
        assert_eq!(Rational::new(6, -4), Rational::new(-3, 2));
    }

    #[test]
    fn arithmetic() {
        let a = Rational::new(1, 6);
        let b = Rational::new(1, 10);
        assert_eq!(a.checked_add(b), Ok(Rational::new(4, 15)));
        assert_eq!(a.checked_mul(b), Ok(Rational::new(1, 60)));
        assert_eq!(
            Rational::new(i128::MAX, 1).checked_add(Rational::ONE),
            Err(Overflow)
        );
    }
}
