//! The candidate dictionary: every term of the machine's topology that a model lacks, each a
//! group of H-matrix columns.
//!
//! - component errors of rotary axes: `harmonic:1..K`;
//! - component errors of linear axes: `poly:1..P`, and `const` for their angular errors (a
//!   constant pitch, yaw or roll is a misalignment, and its gains vary with the pose);
//! - positioning errors of every axis (`EXX`, `ECC`, …): also `reversal`;
//! - location, squareness and set-up errors: `const`;
//! - the R-test's zero offsets `dx0 dy0 dz0`: `const` and `time:1..T` (drift).
//!
//! Constant translational component errors, and constant angular component errors of rotary
//! axes, are not candidates: they are the location and set-up errors under other names.

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
    /// Highest Legendre order T in time of the sensor offsets.
    pub time: u32,
}

impl DictionaryOptions {
    /// Harmonics 1..`harmonics` of rotary-axis errors, Legendre orders 1..`poly` of
    /// linear-axis errors, orders 1..`time` in time of the sensor offsets.
    pub fn new(harmonics: u32, poly: u32, time: u32) -> DictionaryOptions {
        DictionaryOptions {
            harmonics,
            poly,
            time,
        }
    }
}

impl Default for DictionaryOptions {
    fn default() -> Self {
        DictionaryOptions {
            harmonics: 4,
            poly: 3,
            time: 2,
        }
    }
}

/// The bases a candidate effect gets.
fn bases(m: &Machine, effect: Effect, o: &DictionaryOptions) -> Vec<Basis> {
    let e = match effect {
        Effect::SensorOffset(_) => {
            return std::iter::once(Basis::Const)
                .chain((1..=o.time).map(Basis::Time))
                .collect();
        }
        Effect::Instrument { .. } => return vec![Basis::Const],
        Effect::Error(e) => &m.catalogue[e],
    };
    match e.kind {
        ErrorKind::Component { axis, motion } => {
            let a = &m.axes[axis];
            let positioning = match (a.kind, motion) {
                (AxisKind::Linear, Motion::Translation(d))
                | (AxisKind::Rotary, Motion::Rotation(d)) => d == a.direction.dir,
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
