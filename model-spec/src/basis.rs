//! The basis vocabulary of position-dependent errors and other effects (docs/conventions.md):
//! - `const`: 1;
//! - `harmonic:K`: the pair cos(K·θ), sin(K·θ) of the effect's own rotary axis;
//! - `poly:K`: the Legendre polynomial of order K of the effect's own linear axis position,
//!   normalised over the stroke to [−1, 1];
//! - `reversal`: the sign of the effect's own axis's direction of motion (+1 or −1);
//! - `time:K`: the Legendre polynomial of order K in time normalised over the record to [−1, 1].
//!
//! A term (effect × basis) is one column of the H matrix, two for `harmonic:K` (cos, then sin).

use crate::limits::MAX_BASIS_ORDER;
use crate::{AxisKind, Machine};
use std::fmt;

/// One basis of the vocabulary.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Basis {
    /// Constant.
    Const,
    /// cos(Kθ), sin(Kθ) of the own rotary axis, K ≥ 1.
    Harmonic(u32),
    /// Legendre P_K of the own linear axis, normalised over the stroke, K ≥ 1.
    Poly(u32),
    /// Sign of the own axis's direction of motion.
    Reversal,
    /// Legendre P_K of normalised time, K ≥ 1.
    Time(u32),
}

/// What a basis needs to know about the effect it multiplies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Carrier {
    /// An error of this axis (index into `Machine::axes`).
    Axis(usize),
    /// An effect of no axis (set-up errors, squareness, sensor offsets).
    None,
}

/// A basis string that is not in the vocabulary, or does not fit the effect.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct BasisError(pub String);

impl Basis {
    /// Parses `const`, `harmonic:K`, `poly:K`, `reversal`, `time:K` (K ≥ 1).
    pub fn parse(s: &str) -> Result<Basis, BasisError> {
        let s = s.trim();
        let order = |k: &str, name: &str| -> Result<u32, BasisError> {
            match k.parse::<u32>() {
                Ok(k) if (1..=MAX_BASIS_ORDER).contains(&k) => Ok(k),
                _ => Err(BasisError(format!(
                    "`{s}`: the order of `{name}:K` must be a whole number from 1 to {MAX_BASIS_ORDER}"
                ))),
            }
        };
        match s.split_once(':') {
            None if s == "const" => Ok(Basis::Const),
            None if s == "reversal" => Ok(Basis::Reversal),
            Some(("harmonic", k)) => Ok(Basis::Harmonic(order(k, "harmonic")?)),
            Some(("poly", k)) => Ok(Basis::Poly(order(k, "poly")?)),
            Some(("time", k)) => Ok(Basis::Time(order(k, "time")?)),
            _ => Err(BasisError(format!(
                "unknown basis `{s}` (expected const, harmonic:K, poly:K, reversal or time:K)"
            ))),
        }
    }

    /// Number of H-matrix columns: 2 for `harmonic:K` (cos, sin), else 1.
    pub fn width(self) -> usize {
        if matches!(self, Basis::Harmonic(_)) {
            2
        } else {
            1
        }
    }

    /// Names of the columns: `["harmonic:2:cos", "harmonic:2:sin"]`, or `[self]`.
    pub fn column_names(self) -> Vec<String> {
        match self {
            Basis::Harmonic(_) => vec![format!("{self}:cos"), format!("{self}:sin")],
            _ => vec![self.to_string()],
        }
    }

    /// Checks that the basis fits an effect carried by `carrier` of machine `m`: harmonics need
    /// a rotary axis, polynomials a linear axis, reversal an axis.
    pub fn check(self, m: &Machine, carrier: Carrier) -> Result<(), BasisError> {
        let kind = match carrier {
            Carrier::Axis(a) => Some(m.axes[a].kind),
            Carrier::None => None,
        };
        match (self, kind) {
            (Basis::Const | Basis::Time(_), _) => Ok(()),
            (Basis::Harmonic(_), Some(AxisKind::Rotary)) => Ok(()),
            (Basis::Poly(_), Some(AxisKind::Linear)) => Ok(()),
            (Basis::Reversal, Some(_)) => Ok(()),
            (Basis::Harmonic(_), _) => Err(BasisError(format!(
                "`{self}` needs an error of a rotary axis"
            ))),
            (Basis::Poly(_), _) => Err(BasisError(format!(
                "`{self}` needs an error of a linear axis"
            ))),
            (Basis::Reversal, None) => {
                Err(BasisError("`reversal` needs an error of an axis".into()))
            }
        }
    }

    /// The values of the basis columns (one or two) for an effect carried by `carrier`, at a
    /// sample with `commands` (mm, rad), direction of motion `motion` (per axis: +1, −1) and
    /// normalised time `tau` ∈ [−1, 1]. The basis must fit the carrier ([`Basis::check`]).
    pub fn values(
        self,
        m: &Machine,
        carrier: Carrier,
        commands: &[f64],
        motion: &[i8],
        tau: f64,
    ) -> [f64; 2] {
        let axis = match carrier {
            Carrier::Axis(a) => a,
            Carrier::None => usize::MAX,
        };
        match self {
            Basis::Const => [1.0, 0.0],
            Basis::Harmonic(k) => {
                let (s, c) = (k as f64 * commands[axis]).sin_cos();
                [c, s]
            }
            Basis::Poly(k) => {
                let [lo, hi] = m.axes[axis].limits;
                let u = 2.0 * (commands[axis] - lo) / (hi - lo) - 1.0;
                [legendre(k, u), 0.0]
            }
            Basis::Reversal => [if motion[axis] < 0 { -1.0 } else { 1.0 }, 0.0],
            Basis::Time(k) => [legendre(k, tau), 0.0],
        }
    }
}

impl fmt::Display for Basis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Basis::Const => write!(f, "const"),
            Basis::Harmonic(k) => write!(f, "harmonic:{k}"),
            Basis::Poly(k) => write!(f, "poly:{k}"),
            Basis::Reversal => write!(f, "reversal"),
            Basis::Time(k) => write!(f, "time:{k}"),
        }
    }
}

/// The Legendre polynomial P_k(x), by the three-term recurrence.
pub fn legendre(k: u32, x: f64) -> f64 {
    let (mut p0, mut p1) = (1.0, x);
    if k == 0 {
        return p0;
    }
    for n in 1..k {
        let n = n as f64;
        let p2 = ((2.0 * n + 1.0) * x * p1 - n * p0) / (n + 1.0);
        p0 = p1;
        p1 = p2;
    }
    p1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_and_print() {
        for s in ["const", "harmonic:2", "poly:3", "reversal", "time:1"] {
            assert_eq!(Basis::parse(s).unwrap().to_string(), s);
        }
        assert!(Basis::parse("harmonic:0").is_err());
        assert!(Basis::parse("harmonic").is_err());
        assert!(Basis::parse("cubic:2").is_err());
    }

    #[test]
    fn legendre_values() {
        assert_eq!(legendre(2, 0.5), 0.5 * (3.0 * 0.25 - 1.0));
        assert!((legendre(3, 0.3) - 0.5 * (5.0 * 0.027 - 3.0 * 0.3)).abs() < 1e-15);
        for k in 1..8 {
            assert!((legendre(k, 1.0) - 1.0).abs() < 1e-12);
        }
    }
}
