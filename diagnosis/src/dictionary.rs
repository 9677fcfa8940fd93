//! The candidate dictionary: every term of the machine's topology that a model lacks, each a
//! group of H-matrix columns.
//!
//! - component errors of rotary axes: `harmonic:1..K`;
//! - component errors of linear axes: `poly:1..P`, and `const` for their angular errors (a
//!   constant pitch, yaw or roll is a misalignment, and its gains vary with the pose);
//! - positioning errors of every axis (`EXX`, `ECC`, …): also `reversal`;
//! - location, squareness and set-up errors: `const`;
//! - the R-test's zero offsets `dx0 dy0 dz0`: `const` and `time:2..T` (a curved drift); their
//!   linear drift depends on the record ([`scanned`]).
//!
//! Constant translational component errors, and constant angular component errors of rotary
//! axes, are not candidates: they are the location and set-up errors under other names.
//!
//! The record-dependent candidates ([`scanned`]):
//! - the linear drift of `dx0 dy0 dz0` (when T ≥ 1) and, with the scanned families, of every
//!   location error (thermal drift of an axis line): `rate` on a record with real times, so
//!   that a finding reads as a physical rate (µm/s, µrad/s) that means the same on a record of
//!   any length; `time:1` on a record whose samples are only numbered (a drift over the
//!   record, normalised to it). Given a constant in the same direction, the two have one span:
//!   `rate` is `time:1` renamed, with a value that does not depend on the record's length.
//!
//! Families with a scanned parameter ([`scanned`], when [`DictionaryOptions::scans`] is on):
//! every scanned value is a candidate of its own, so the multiple-testing correction counts
//! the scan. The grids follow the fitted record:
//! - `period:P` of the positioning error of every linear axis that moves: P on a grid
//!   uniform in 1/P (spacing a fifth of 1/range, so that the best grid value is within a tenth
//!   of a cycle of the true period over the range and explains at least 80 % of it; the
//!   profile refines it, [`super::profile`]), from two median steps of the axis
//!   between samples (the sampling limit: near it, periods alias) to two thirds of its range, within
//!   [`PERIOD_RANGE_MM`];
//! - `step:V` of the positioning error of every axis that moves: [`STEPS`] positions evenly
//!   between the 5 % and 95 % quantiles of the positions the record covers;
//! - `warmup:TAU` of `dx0 dy0 dz0` and of every location error (records with real times
//!   only): [`TAUS`] time constants, geometric from two sample intervals to half the record's
//!   duration (a longer warm-up is a linear drift over the record: `rate`); the warm-up counts
//!   from the record's time 0, so that a finding reads as a time constant and the amplitude
//!   the warm-up tends to. A record with samples before its time 0 gets `exp:TAU` instead
//!   (from its first sample: a warm-up before its start is not defined);
//! - `velocity` of the positioning error of every axis that moves (records with real times);
//! - the R-test's instrument terms `SXX … SZY`, constant.
//!
//! And a jump in time of the fitted record ([`jumps`], with the scanned families, where one
//! record is fitted): `jump:T` of the ball's set-up errors `XOW YOW ZOW` and of the zero
//! offsets `dx0 dy0 dz0` (the ball knocked, a sensor bumped), T at [`JUMPS`] instants evenly
//! between the 5 % and 95 % quantiles of its sample times. A jump is a term of that record
//! and of no other: it predicts nothing elsewhere. (On a campaign of several records a
//! `jump:T` would be a jump at T of every record's own clock, a look-alike of a position error
//! on records that repeat a path: it is not offered there.)

use model_spec::basis::Basis;
use model_spec::terms::{Effect, Term};
use model_spec::{AxisKind, Dir, ErrorKind, Machine, Motion};

/// How far the dictionary goes (`DictionaryOptions::default()` or [`DictionaryOptions::new`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct DictionaryOptions {
    /// Highest harmonic K of rotary-axis errors.
    pub harmonics: u32,
    /// Highest Legendre order P of linear-axis errors.
    pub poly: u32,
    /// Highest order T of the sensor offsets' drift: the linear drift (`rate`, or `time:1` on a
    /// record without real times) when T ≥ 1, and `time:2..T`.
    pub time: u32,
    /// The scanned families (period, step, warm-up), servo lag, thermal drift of axis lines
    /// and the instrument terms.
    pub scans: bool,
}

impl DictionaryOptions {
    /// Harmonics 1..`harmonics` of rotary-axis errors, Legendre orders 1..`poly` of
    /// linear-axis errors, drifts of orders 1..`time` of the sensor offsets.
    pub fn new(harmonics: u32, poly: u32, time: u32) -> DictionaryOptions {
        DictionaryOptions {
            harmonics,
            poly,
            time,
            scans: true,
        }
    }
}

impl Default for DictionaryOptions {
    fn default() -> Self {
        DictionaryOptions {
            harmonics: 4,
            poly: 3,
            time: 2,
            scans: true,
        }
    }
}

/// The bases a candidate effect gets.
fn bases(m: &Machine, effect: Effect, o: &DictionaryOptions) -> Vec<Basis> {
    let e = match effect {
        Effect::SensorOffset(_) => {
            return std::iter::once(Basis::Const)
                .chain((2..=o.time).map(Basis::Time))
                .collect();
        }
        Effect::Instrument { .. } | Effect::KinematicOffset(_) => return vec![Basis::Const],
        // A three-point probe's lobing.
        Effect::PreTravel => return vec![Basis::Harmonic(3)],
        Effect::Error(e) => &m.catalogue[e],
    };
    match e.kind {
        ErrorKind::Component { axis, motion } => {
            let a = &m.axes[axis];
            let positioning = match (a.kind, motion) {
                (AxisKind::Linear, Motion::Translation(d))
                | (AxisKind::Rotary, Motion::Rotation(d)) => d == a.direction.own.dir,
                _ => false,
            };
            let mut out: Vec<Basis> = match a.kind {
                AxisKind::Rotary => (1..=o.harmonics).map(Basis::Harmonic).collect(),
                AxisKind::Linear => {
                    let constant = motion.is_angular().then_some(Basis::Const);
                    constant
                        .into_iter()
                        .chain((1..=o.poly).map(Basis::Poly))
                        .collect()
                }
            };
            if positioning {
                out.push(Basis::Reversal);
            }
            out
        }
        ErrorKind::Location { .. } | ErrorKind::Squareness { .. } | ErrorKind::Setup { .. } => {
            vec![Basis::Const]
        }
    }
}

/// The candidate terms for `model` on machine `m`: every dictionary term not already in it, in
/// catalogue order, then the sensor offsets.
pub fn dictionary(m: &Machine, model_terms: &[Term], o: &DictionaryOptions) -> Vec<Term> {
    let effects = (0..m.catalogue.len())
        .map(Effect::Error)
        .chain(Dir::ALL.into_iter().map(Effect::SensorOffset));
    effects
        .flat_map(|effect| {
            bases(m, effect, o)
                .into_iter()
                .map(move |basis| Term { effect, basis })
        })
        .filter(|t| !model_terms.contains(t))
        .collect()
}

/// The range of periods scanned, mm.
pub const PERIOD_RANGE_MM: [f64; 2] = [1.0, 100.0];

/// Positions scanned per axis for `step:V`.
pub const STEPS: usize = 24;

/// Time constants scanned for `warmup:TAU`.
pub const TAUS: usize = 8;

/// Instants scanned for `jump:T`.
pub const JUMPS: usize = 24;

/// The jumps in time that `model_terms` lacks, on a fitted record whose samples are at the
/// times `times` (s, on its own clock): `jump:T` of every
/// set-up error and zero offset, T at [`JUMPS`] instants evenly between the 5 % and 95 %
/// quantiles of `times` (see the module documentation). None without the scanned families or
/// with fewer than 20 samples.
pub fn jumps(m: &Machine, model_terms: &[Term], times: &[f64], o: &DictionaryOptions) -> Vec<Term> {
    if !o.scans || times.len() < 20 {
        return Vec::new();
    }
    let t = sorted(times.to_vec());
    let (q0, q1) = (t[t.len() / 20], t[t.len() - 1 - t.len() / 20]);
    if q1 - q0 <= 0.0 {
        return Vec::new();
    }
    let effects: Vec<Effect> = (0..m.catalogue.len())
        .filter(|&e| matches!(m.catalogue[e].kind, ErrorKind::Setup { .. }))
        .map(Effect::Error)
        .chain(Dir::ALL.into_iter().map(Effect::SensorOffset))
        .collect();
    let mut out = Vec::with_capacity(effects.len() * JUMPS);
    for effect in effects {
        for k in 0..JUMPS {
            let at = q0 + (q1 - q0) * (k as f64 + 0.5) / JUMPS as f64;
            out.push(Term {
                effect,
                basis: Basis::Jump((at * 1000.0).round() as i64),
            });
        }
    }
    out.retain(|t| !model_terms.contains(t) && t.check(m).is_ok());
    out
}

/// Sorted copy.
fn sorted(mut v: Vec<f64>) -> Vec<f64> {
    v.sort_by(f64::total_cmp);
    v
}

/// The scanned and record-dependent candidates of `m` on `record` that `model_terms` lacks
/// (see the module documentation).
pub fn scanned(
    m: &Machine,
    model_terms: &[Term],
    record: &simulation::record::Record,
    o: &DictionaryOptions,
) -> Vec<Term> {
    // A linear drift: a rate where the record has real times, else over the record.
    let drift = if record.has_times() {
        Basis::Rate
    } else {
        Basis::Time(1)
    };
    let offsets: Vec<Term> = Dir::ALL
        .into_iter()
        .filter(|_| o.time >= 1)
        .map(|d| Term {
            effect: Effect::SensorOffset(d),
            basis: drift,
        })
        .filter(|t| !model_terms.contains(t))
        .collect();
    if !o.scans || record.samples.len() < 3 {
        return offsets;
    }
    let mut out = Vec::new();
    let positioning = |axis: usize| -> Option<Effect> {
        (0..m.catalogue.len())
            .map(Effect::Error)
            .find(|e| e.is_positioning(m) && e.carrier(m) == model_spec::basis::Carrier::Axis(axis))
    };
    for (a, axis) in m.axes.iter().enumerate() {
        let Some(effect) = positioning(a) else {
            continue;
        };
        let rotary = axis.kind == AxisKind::Rotary;
        let unit = if rotary {
            180.0 / std::f64::consts::PI
        } else {
            1.0
        };
        let x = sorted(
            record
                .samples
                .iter()
                .map(|s| s.commands[a] * unit)
                .collect(),
        );
        let (lo, hi) = (x[0], x[x.len() - 1]);
        if hi - lo < 1e-6 {
            continue;
        }
        // step:V between the 5 % and 95 % quantiles.
        let (q0, q1) = (x[x.len() / 20], x[x.len() - 1 - x.len() / 20]);
        for k in 0..STEPS {
            let v = q0 + (q1 - q0) * (k as f64 + 0.5) / STEPS as f64;
            out.push(Term {
                effect,
                basis: Basis::Step((v * 1000.0).round() as i64),
            });
        }
        if record.has_times() {
            out.push(Term {
                effect,
                basis: Basis::Velocity,
            });
        }
        if !rotary {
            // period:P, uniform in 1/P.
            let mut steps: Vec<f64> = record
                .samples
                .windows(2)
                .map(|w| ((w[1].commands[a] - w[0].commands[a]) * unit).abs())
                .filter(|d| *d > 0.0)
                .collect();
            steps = sorted(steps);
            let median = steps.get(steps.len() / 2).copied().unwrap_or(0.0);
            let range = hi - lo;
            let p_min = (2.0 * median).max(PERIOD_RANGE_MM[0]);
            let p_max = (range / 1.5).min(PERIOD_RANGE_MM[1]);
            if median > 0.0 && p_max > p_min {
                let df = 0.2 / range;
                let mut f = 1.0 / p_max;
                while f <= 1.0 / p_min {
                    let p_um = (1000.0 / f).round() as u32;
                    let t = Term {
                        effect,
                        basis: Basis::Period(p_um),
                    };
                    if !out.contains(&t) {
                        out.push(t);
                    }
                    f += df;
                }
            }
        }
    }
    let location: Vec<Effect> = (0..m.catalogue.len())
        .filter(|&e| matches!(m.catalogue[e].kind, ErrorKind::Location { .. }))
        .map(Effect::Error)
        .collect();
    // The R-test's zero first: where its drift and an axis line's explain alike, the
    // instrument's is named (the selection takes the first of equals).
    out.extend(offsets);
    for &effect in &location {
        out.push(Term {
            effect,
            basis: drift,
        });
    }
    if record.has_times() {
        let t0 = record.samples[0].t;
        // A warm-up from the record's time 0; from its first sample (`exp:TAU`) when samples
        // come before time 0, where a warm-up is not defined.
        let warmup = |ms: u32| {
            if t0 >= 0.0 {
                Basis::Warmup(ms)
            } else {
                Basis::Exp(ms)
            }
        };
        let duration = record.samples[record.samples.len() - 1].t - t0;
        let dt = duration / (record.samples.len() - 1) as f64;
        if duration > 0.0 && dt > 0.0 {
            let (a, b) = (2.0 * dt, 0.5 * duration);
            let taus: Vec<u32> = (0..TAUS)
                .map(|k| {
                    let tau = a * (b / a).powf(k as f64 / (TAUS - 1) as f64);
                    (tau * 1000.0).round().max(1.0) as u32
                })
                .collect();
            for effect in Dir::ALL
                .into_iter()
                .map(Effect::SensorOffset)
                .chain(location.iter().copied())
            {
                for &ms in &taus {
                    out.push(Term {
                        effect,
                        basis: warmup(ms),
                    });
                }
            }
        }
    }
    out.extend(Effect::instruments().map(|effect| Term {
        effect,
        basis: Basis::Const,
    }));
    out.retain(|t| !model_terms.contains(t) && t.check(m).is_ok());
    out
}
