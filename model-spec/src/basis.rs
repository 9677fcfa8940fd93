//! The basis vocabulary of position-dependent errors and other effects (docs/conventions.md):
//! - `const`: 1;
//! - `harmonic:K`: the pair cos(K·θ), sin(K·θ) of the effect's own rotary axis;
//! - `poly:K`: the Legendre polynomial of order K of the effect's own linear axis position,
//!   normalised over the stroke to [−1, 1];
//! - `reversal`: the sign of the effect's own axis's direction of motion (+1 or −1);
//! - `time:K`: the Legendre polynomial of order K in time normalised over the record to [−1, 1];
//! - `period:P`: the pair cos(2π·x/P), sin(2π·x/P) of the effect's own linear axis position x
//!   (mm, absolute), P in mm (a ball screw's pitch, a scale's period);
//! - `step:V`: 0 below the own axis's position V, 1 from V on (mm, or degrees for a rotary axis);
//! - `exp:TAU`: 1 − exp(−(t − t₀)/TAU) of the time t since the record's first sample t₀, TAU in
//!   s (a warm-up, a settling set-up), for effects of no axis;
//! - `rate`: the time since the stated start, s: its coefficient is a rate (mm/s or rad/s
//!   inside, µm/s or µrad/s for people), the same physical drift on records of any length;
//! - `warmup:TAU`: 1 − exp(−(t − start)/TAU) of the time since the stated start, TAU in s: its
//!   coefficient is the warm-up's asymptotic amplitude;
//! - `velocity`: −v, the own axis's velocity (mm/ms, rad/ms) with the sign of a lag, for the
//!   axis's positioning error; its coefficient is the servo lag τ in ms;
//! - `jump:T`: 0 before the time T of the record's own clock (its `t_s`, s; the sample's number
//!   on a record whose samples are only numbered), 1 from T on, for effects of no axis: a
//!   set-up error or a zero offset that moved during one record (the ball knocked, a sensor
//!   bumped). It is a term of that record only: a campaign gives every record its own value,
//!   and a record that was not fitted takes none (the jump is an event of the fitted record).
//!
//! A term (effect × basis) is one column of the H matrix, two for `harmonic:K` and `period:P`
//! (cos, then sin). Every basis is evaluated in one place, [`Basis::values`], at a
//! [`BasisContext`] that the H-matrix builder and the simulator fill alike.
//!
//! **The stated start** of `rate` and `warmup:TAU` is time 0 of the clock the term is on: on a
//! record's own clock its `t_s = 0` (the instant the record's times count from, whether or not
//! a sample was taken then), on a campaign clock `T = 0` (the instant the records' starts count
//! from). `time:K` and `exp:TAU` keep their meaning: normalised over the record, and from its
//! first sample. A `rate` before its start continues its line (its value there is negative
//! times the rate); a warm-up before its start is not defined, and a record with a sample there
//! is refused for a `warmup:TAU` term ([`Basis::starts_at_zero`]).
//!
//! The scanned parameters of `period`, `step`, `exp`, `warmup` and `jump` are kept as whole
//! numbers of thousandths (µm, thousandths of mm or degree, ms), so that a basis is `Copy + Eq + Hash +
//! Ord`; they are written with at most three decimals and printed as the shortest decimal
//! (`period:2.5`).

use crate::limits::{MAX_BASIS_ORDER, MAX_LENGTH_MM};
use crate::{AxisKind, Machine};
use std::fmt;

/// Thousandths per unit: the scanned parameters are kept in thousandths of mm, degree or s.
const MILLI: f64 = 1000.0;

/// The largest time constant of `exp:TAU` and `warmup:TAU`, s (about 11.6 days).
pub const MAX_TAU_S: f64 = 1e6;

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
    /// cos(2π·x/P), sin(2π·x/P) of the own linear axis position x (mm); the period P in µm
    /// (thousandths of mm), P > 0.
    Period(u32),
    /// 1 from the own axis's position V on, 0 below it; V in thousandths of mm (linear axis) or
    /// of a degree (rotary axis).
    Step(i64),
    /// 1 − exp(−(t − t₀)/TAU), t − t₀ the time since the record's first sample; TAU in ms,
    /// TAU > 0.
    Exp(u32),
    /// −v, v the own axis's velocity (mm/ms or rad/ms); its coefficient is a lag in ms.
    Velocity,
    /// t − start, the time since the stated start (s); its coefficient is a rate, mm/s or
    /// rad/s.
    Rate,
    /// 1 − exp(−(t − start)/TAU), t − start the time since the stated start; TAU in ms,
    /// TAU > 0. Its coefficient is the asymptotic amplitude of the warm-up (mm or rad).
    Warmup(u32),
    /// 0 before the time T on the record's own clock, 1 from T on; T in ms (thousandths of s).
    /// Its coefficient is the size of the jump (mm or rad).
    Jump(i64),
}

/// What a basis needs to know about the effect it multiplies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Carrier {
    /// An error of this axis (index into `Machine::axes`).
    Axis(usize),
    /// An effect of no axis (set-up errors, squareness, sensor offsets, instrument terms).
    None,
}

/// A basis string that is not in the vocabulary, or does not fit the effect.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct BasisError(pub String);

/// One sample as the bases see it, filled alike by the H-matrix builder and the simulator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BasisContext<'a> {
    /// The commanded position of every axis (mm for linear axes, rad for rotary ones).
    pub commands: &'a [f64],
    /// The direction of motion of every axis (+1 or −1).
    pub motion: &'a [i8],
    /// The time normalised over the record, τ ∈ [−1, 1] (`time:K`).
    pub tau: f64,
    /// The time since the record's first sample, s (`exp:TAU`).
    pub elapsed_s: f64,
    /// The time since the stated start of `rate` and `warmup:TAU`, s: the sample's time on the
    /// clock the terms are on (a record's own `t_s`, or its time `T` on a campaign clock).
    pub since_start_s: f64,
    /// The velocity of every axis, mm/ms or rad/ms (`velocity`); empty when no term needs it.
    pub velocity: &'a [f64],
    /// The measured reading x, y, z (mm): to first order the displacement the R-test's
    /// instrument terms multiply. Zero where no reading exists (the simulator, which applies the
    /// instrument terms to the displacement it computes).
    pub reading: [f64; 3],
}

/// A decimal with at most three decimals (`12`, `-2.5`, `0.125`; no exponent), in thousandths.
fn thousandths(text: &str) -> Option<i64> {
    let (neg, rest) = match text.as_bytes().first()? {
        b'-' => (true, &text[1..]),
        b'+' => (false, &text[1..]),
        _ => (false, text),
    };
    let (int, frac) = rest.split_once('.').unwrap_or((rest, ""));
    let digits = |s: &str| s.bytes().all(|b| b.is_ascii_digit());
    if int.is_empty() || !digits(int) || !digits(frac) || frac.len() > 3 || int.len() > 12 {
        return None;
    }
    if rest.contains('.') && frac.is_empty() {
        return None;
    }
    let whole: i64 = int.parse().ok()?;
    let mut part: i64 = if frac.is_empty() {
        0
    } else {
        frac.parse().ok()?
    };
    for _ in frac.len()..3 {
        part *= 10;
    }
    let v = whole * 1000 + part;
    Some(if neg { -v } else { v })
}

/// A number of thousandths as the shortest decimal: 2500 → `2.5`, −12500 → `-12.5`.
fn decimal(v: i64) -> String {
    let sign = if v < 0 { "-" } else { "" };
    let a = v.unsigned_abs();
    let (int, frac) = (a / 1000, a % 1000);
    if frac == 0 {
        return format!("{sign}{int}");
    }
    let f = format!("{frac:03}");
    format!("{sign}{int}.{}", f.trim_end_matches('0'))
}

impl Basis {
    /// Parses `const`, `harmonic:K`, `poly:K`, `reversal`, `time:K` (K ≥ 1), `period:P`
    /// (P > 0 mm), `step:V` (mm or degrees), `exp:TAU` (TAU > 0 s), `velocity`, `rate` and
    /// `warmup:TAU` (TAU > 0 s) and `jump:T` (s). P, V, TAU and T are decimals with at most
    /// three decimals.
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
        // A decimal of at most three decimals within ±max, in thousandths.
        let value = |v: &str, what: &str, max: f64| -> Result<i64, BasisError> {
            match thousandths(v) {
                Some(x) if (x as f64).abs() <= max * MILLI => Ok(x),
                Some(_) => Err(BasisError(format!(
                    "`{s}`: {what} must be at most {max} in magnitude"
                ))),
                None => Err(BasisError(format!(
                    "`{s}`: {what} must be a decimal number with at most three decimals (`10`, `2.5`, `-0.125`)"
                ))),
            }
        };
        let positive = |v: &str, what: &str, max: f64| -> Result<u32, BasisError> {
            let x = value(v, what, max)?;
            u32::try_from(x)
                .ok()
                .filter(|&x| x > 0)
                .ok_or_else(|| BasisError(format!("`{s}`: {what} must be positive")))
        };
        match s.split_once(':') {
            None if s == "const" => Ok(Basis::Const),
            None if s == "reversal" => Ok(Basis::Reversal),
            None if s == "velocity" => Ok(Basis::Velocity),
            None if s == "rate" => Ok(Basis::Rate),
            Some(("harmonic", k)) => Ok(Basis::Harmonic(order(k, "harmonic")?)),
            Some(("poly", k)) => Ok(Basis::Poly(order(k, "poly")?)),
            Some(("time", k)) => Ok(Basis::Time(order(k, "time")?)),
            Some(("period", p)) => Ok(Basis::Period(positive(
                p,
                "the period P of `period:P` (mm)",
                MAX_LENGTH_MM,
            )?)),
            Some(("step", v)) => Ok(Basis::Step(value(
                v,
                "the position V of `step:V` (mm or degrees)",
                MAX_LENGTH_MM,
            )?)),
            Some(("exp", t)) => Ok(Basis::Exp(positive(
                t,
                "the time constant TAU of `exp:TAU` (s)",
                MAX_TAU_S,
            )?)),
            Some(("warmup", t)) => Ok(Basis::Warmup(positive(
                t,
                "the time constant TAU of `warmup:TAU` (s)",
                MAX_TAU_S,
            )?)),
            Some(("jump", t)) => Ok(Basis::Jump(value(
                t,
                "the time T of `jump:T` (s)",
                MAX_TAU_S,
            )?)),
            _ => Err(BasisError(format!(
                "unknown basis `{s}` (expected {})",
                VOCABULARY
            ))),
        }
    }

    /// Number of H-matrix columns: 2 for `harmonic:K` and `period:P` (cos, sin), else 1.
    pub fn width(self) -> usize {
        if matches!(self, Basis::Harmonic(_) | Basis::Period(_)) {
            2
        } else {
            1
        }
    }

    /// Names of the columns: `["harmonic:2:cos", "harmonic:2:sin"]`, `["period:5:cos",
    /// "period:5:sin"]`, or `[self]`.
    pub fn column_names(self) -> Vec<String> {
        match self {
            Basis::Harmonic(_) | Basis::Period(_) => {
                vec![format!("{self}:cos"), format!("{self}:sin")]
            }
            _ => vec![self.to_string()],
        }
    }

    /// `true` for bases that need the real sample times (`velocity`, `exp:TAU`, `rate`,
    /// `warmup:TAU`), not sample numbers.
    pub fn needs_times(self) -> bool {
        matches!(
            self,
            Basis::Velocity | Basis::Exp(_) | Basis::Rate | Basis::Warmup(_)
        )
    }

    /// `true` for bases of time (`time:K`, `exp:TAU`, `rate`, `warmup:TAU`): the effect changes
    /// over the record, not with the pose; on a campaign clock they run on it.
    pub fn of_time(self) -> bool {
        matches!(
            self,
            Basis::Time(_) | Basis::Exp(_) | Basis::Rate | Basis::Warmup(_)
        )
    }

    /// `true` for a basis that is not defined before its start (`warmup:TAU`): a record with a
    /// sample before time 0 of the term's clock is refused for it.
    pub fn starts_at_zero(self) -> bool {
        matches!(self, Basis::Warmup(_))
    }

    /// The period P of `period:P`, mm.
    pub fn period_mm(self) -> Option<f64> {
        match self {
            Basis::Period(p) => Some(f64::from(p) / MILLI),
            _ => None,
        }
    }

    /// The time constant TAU of `exp:TAU` and `warmup:TAU`, s.
    pub fn tau_s(self) -> Option<f64> {
        match self {
            Basis::Exp(t) | Basis::Warmup(t) => Some(f64::from(t) / MILLI),
            _ => None,
        }
    }

    /// The time T of `jump:T` on the record's own clock, s.
    pub fn jump_at(self) -> Option<f64> {
        match self {
            Basis::Jump(t) => Some(t as f64 / MILLI),
            _ => None,
        }
    }

    /// The position V of `step:V`: mm, or degrees for a rotary axis.
    pub fn step_at(self) -> Option<f64> {
        match self {
            Basis::Step(v) => Some(v as f64 / MILLI),
            _ => None,
        }
    }

    /// Checks that the basis fits an effect carried by `carrier` of machine `m`: harmonics need
    /// a rotary axis, polynomials and periods a linear axis, reversal, steps and velocity an
    /// axis, `exp:TAU` and `jump:T` an effect of no axis; `const`, `time:K`, `rate` and `warmup:TAU` fit
    /// every effect. (That `velocity` needs the positioning error, and that instrument terms
    /// and kinematic offsets are constants, is checked by [`crate::terms::Term::new`].)
    pub fn check(self, m: &Machine, carrier: Carrier) -> Result<(), BasisError> {
        let kind = match carrier {
            Carrier::Axis(a) => Some(m.axes[a].kind),
            Carrier::None => None,
        };
        match (self, kind) {
            (Basis::Const | Basis::Time(_) | Basis::Rate | Basis::Warmup(_), _) => Ok(()),
            (Basis::Harmonic(_), Some(AxisKind::Rotary)) => Ok(()),
            (Basis::Poly(_) | Basis::Period(_), Some(AxisKind::Linear)) => Ok(()),
            (Basis::Reversal | Basis::Step(_) | Basis::Velocity, Some(_)) => Ok(()),
            (Basis::Exp(_) | Basis::Jump(_), None) => Ok(()),
            (Basis::Harmonic(_), _) => Err(BasisError(format!(
                "`{self}` needs an error of a rotary axis"
            ))),
            (Basis::Poly(_) | Basis::Period(_), _) => Err(BasisError(format!(
                "`{self}` needs an error of a linear axis"
            ))),
            (Basis::Reversal | Basis::Step(_) | Basis::Velocity, None) => {
                Err(BasisError(format!("`{self}` needs an error of an axis")))
            }
            (Basis::Exp(_) | Basis::Jump(_), Some(_)) => Err(BasisError(format!(
                "`{self}` needs an effect of no axis (dx0 dy0 dz0, a location, squareness or set-up error)"
            ))),
        }
    }

    /// The values of the basis columns (one or two) for an effect carried by `carrier`, at the
    /// sample `cx`. The basis must fit the carrier ([`Basis::check`]); `cx.velocity` must have
    /// one entry per axis for `velocity`.
    pub fn values(self, m: &Machine, carrier: Carrier, cx: &BasisContext<'_>) -> [f64; 2] {
        let axis = match carrier {
            Carrier::Axis(a) => a,
            Carrier::None => usize::MAX,
        };
        match self {
            Basis::Const => [1.0, 0.0],
            Basis::Harmonic(k) => {
                let (s, c) = (k as f64 * cx.commands[axis]).sin_cos();
                [c, s]
            }
            Basis::Poly(k) => {
                let [lo, hi] = m.axes[axis].limits;
                let u = 2.0 * (cx.commands[axis] - lo) / (hi - lo) - 1.0;
                [legendre(k, u), 0.0]
            }
            Basis::Reversal => [if cx.motion[axis] < 0 { -1.0 } else { 1.0 }, 0.0],
            Basis::Time(k) => [legendre(k, cx.tau), 0.0],
            Basis::Period(p) => {
                let phase = std::f64::consts::TAU * cx.commands[axis] * MILLI / f64::from(p);
                let (s, c) = phase.sin_cos();
                [c, s]
            }
            Basis::Step(v) => {
                let at = v as f64 / MILLI;
                let edge = match m.axes[axis].kind {
                    AxisKind::Linear => at,
                    AxisKind::Rotary => at.to_radians(),
                };
                [if cx.commands[axis] >= edge { 1.0 } else { 0.0 }, 0.0]
            }
            Basis::Exp(t) => [-(-cx.elapsed_s * MILLI / f64::from(t)).exp_m1(), 0.0],
            Basis::Velocity => [-cx.velocity[axis], 0.0],
            Basis::Rate => [cx.since_start_s, 0.0],
            Basis::Warmup(t) => [-(-cx.since_start_s * MILLI / f64::from(t)).exp_m1(), 0.0],
            Basis::Jump(t) => [
                if cx.since_start_s * MILLI >= t as f64 {
                    1.0
                } else {
                    0.0
                },
                0.0,
            ],
        }
    }
}

/// The vocabulary as error messages list it.
const VOCABULARY: &str = "const, harmonic:K, poly:K, reversal, time:K, period:P, step:V, exp:TAU, velocity, rate, warmup:TAU or jump:T";

impl fmt::Display for Basis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Basis::Const => write!(f, "const"),
            Basis::Harmonic(k) => write!(f, "harmonic:{k}"),
            Basis::Poly(k) => write!(f, "poly:{k}"),
            Basis::Reversal => write!(f, "reversal"),
            Basis::Time(k) => write!(f, "time:{k}"),
            Basis::Period(p) => write!(f, "period:{}", decimal(i64::from(*p))),
            Basis::Step(v) => write!(f, "step:{}", decimal(*v)),
            Basis::Exp(t) => write!(f, "exp:{}", decimal(i64::from(*t))),
            Basis::Velocity => write!(f, "velocity"),
            Basis::Rate => write!(f, "rate"),
            Basis::Warmup(t) => write!(f, "warmup:{}", decimal(i64::from(*t))),
            Basis::Jump(t) => write!(f, "jump:{}", decimal(*t)),
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
        for s in [
            "const",
            "harmonic:2",
            "poly:3",
            "reversal",
            "time:1",
            "velocity",
        ] {
            assert_eq!(Basis::parse(s).unwrap().to_string(), s);
        }
        assert!(Basis::parse("harmonic:0").is_err());
        assert!(Basis::parse("harmonic").is_err());
        assert!(Basis::parse("cubic:2").is_err());
    }

    #[test]
    fn scanned_parameters_round_trip_as_shortest_decimals() {
        for (s, b) in [
            ("period:10", Basis::Period(10_000)),
            ("period:2.5", Basis::Period(2_500)),
            ("period:0.001", Basis::Period(1)),
            ("step:90", Basis::Step(90_000)),
            ("step:-12.5", Basis::Step(-12_500)),
            ("step:0", Basis::Step(0)),
            ("step:-0.125", Basis::Step(-125)),
            ("exp:20", Basis::Exp(20_000)),
            ("exp:0.5", Basis::Exp(500)),
            ("velocity", Basis::Velocity),
            ("rate", Basis::Rate),
            ("warmup:40", Basis::Warmup(40_000)),
            ("warmup:0.125", Basis::Warmup(125)),
            ("warmup:1000000", Basis::Warmup(1_000_000_000)),
            ("jump:149.5", Basis::Jump(149_500)),
            ("jump:-2", Basis::Jump(-2_000)),
        ] {
            assert_eq!(Basis::parse(s).unwrap(), b, "{s}");
            assert_eq!(b.to_string(), s);
        }
        // Other spellings of the same value print the shortest way.
        assert_eq!(
            Basis::parse("period:2.50").unwrap().to_string(),
            "period:2.5"
        );
        assert_eq!(Basis::parse("step:+7.000").unwrap().to_string(), "step:7");
        assert_eq!(
            Basis::parse("warmup:40.500").unwrap().to_string(),
            "warmup:40.5"
        );
        assert_eq!(Basis::Rate.column_names(), ["rate"]);
        assert_eq!(Basis::Warmup(40_000).width(), 1);
        assert_eq!(Basis::Warmup(40_000).tau_s(), Some(40.0));
        assert_eq!(
            Basis::Period(2500).column_names(),
            ["period:2.5:cos", "period:2.5:sin"]
        );
        assert_eq!(Basis::Period(2500).width(), 2);
    }

    #[test]
    fn scanned_parameters_refused() {
        for (s, why) in [
            ("period:2.5001", "three decimals"),
            ("period:0", "positive"),
            ("period:-5", "positive"),
            ("exp:0", "positive"),
            ("exp:-1", "positive"),
            ("exp:1e3", "three decimals"),
            ("step:", "three decimals"),
            ("step:1.", "three decimals"),
            ("step:x", "three decimals"),
            ("step:1000000", "at most"),
            ("exp:2000000", "at most"),
            ("velocity:2", "unknown basis"),
            ("rate:1", "unknown basis"),
            ("Rate", "unknown basis"),
            ("warmup", "unknown basis"),
            ("warmup:", "three decimals"),
            ("warmup:0", "positive"),
            ("warmup:-40", "positive"),
            ("warmup:4e1", "three decimals"),
            ("warmup:40.0001", "three decimals"),
            ("warmup:2000000", "at most"),
        ] {
            let e = Basis::parse(s).unwrap_err().0;
            assert!(e.contains(why), "{s}: {e}");
        }
    }

    #[test]
    fn rate_and_warmup_count_from_the_start() {
        let m = crate::builtin("seed-ac").unwrap().unwrap();
        let (commands, motion) = (vec![0.0; m.axes.len()], vec![1i8; m.axes.len()]);
        let at = |since_start_s: f64| BasisContext {
            commands: &commands,
            motion: &motion,
            tau: 0.3,
            elapsed_s: 7.0,
            since_start_s,
            velocity: &[],
            reading: [0.0; 3],
        };
        let v = |b: Basis, t: f64| b.values(&m, Carrier::None, &at(t))[0];
        assert_eq!(v(Basis::Rate, 125.5), 125.5);
        assert_eq!(v(Basis::Rate, -2.0), -2.0);
        assert_eq!(v(Basis::Warmup(40_000), 0.0), 0.0);
        assert!((v(Basis::Warmup(40_000), 40.0) - (1.0 - (-1.0f64).exp())).abs() < 1e-15);
        // `time:K` and `exp:TAU` keep their own clocks: the start does not enter them.
        assert_eq!(v(Basis::Exp(40_000), 1e6), -(-7.0f64 / 40.0).exp_m1());
        assert_eq!(v(Basis::Time(1), 1e6), 0.3);
        for b in [Basis::Rate, Basis::Warmup(1)] {
            assert!(b.needs_times() && b.of_time());
        }
        assert!(Basis::Warmup(1).starts_at_zero() && !Basis::Rate.starts_at_zero());
        assert!(!Basis::Exp(1).starts_at_zero() && Basis::Exp(1).of_time());
        // A jump: 0 before T on the record's own clock, 1 from T on; a term of one record, not
        // of a clock.
        assert_eq!(v(Basis::Jump(149_500), 149.0), 0.0);
        assert_eq!(v(Basis::Jump(149_500), 149.5), 1.0);
        assert_eq!(v(Basis::Jump(149_500), 150.0), 1.0);
        assert_eq!(Basis::Jump(149_500).jump_at(), Some(149.5));
        assert!(!Basis::Jump(1).of_time() && !Basis::Jump(1).needs_times());
        assert!(Basis::Jump(1).check(&m, Carrier::None).is_ok());
        assert!(Basis::Jump(1).check(&m, Carrier::Axis(0)).is_err());
    }

    #[test]
    fn rate_and_warmup_fit_every_effect() {
        let m = crate::builtin("seed-ac").unwrap().unwrap();
        for b in [Basis::Rate, Basis::Warmup(40_000)] {
            assert!(b.check(&m, Carrier::None).is_ok());
            for a in 0..m.axes.len() {
                assert!(b.check(&m, Carrier::Axis(a)).is_ok());
            }
        }
        // `exp:TAU` keeps its carriers.
        assert!(Basis::Exp(1).check(&m, Carrier::Axis(0)).is_err());
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
