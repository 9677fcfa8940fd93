//! Terms of a model: an effect (an ISO 230 error of the machine, or an R-test sensor zero offset
//! `dx0 dy0 dz0`) times a basis of the vocabulary ([`crate::basis`]). A term gives one H-matrix
//! column, two for `harmonic:K`. Sub-models of a machine description list terms as `NAME`
//! (constant) or `NAME@BASIS` (`ECC@harmonic:2`, `dx0@time:1`).

use crate::basis::{Basis, BasisError, Carrier};
use crate::{Dir, ErrorId, Machine};

/// Something that moves the measured error vector.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Effect {
    /// An error of the machine's catalogue.
    Error(ErrorId),
    /// The R-test's zero offset along a tool-frame axis (`dx0 dy0 dz0`): adds to the reading,
    /// gain +1 in that direction.
    SensorOffset(Dir),
}

impl Effect {
    /// The effect called `name` on `m`: an error name (digit-zero alias accepted) or
    /// `dx0 dy0 dz0`.
    pub fn parse(m: &Machine, name: &str) -> Option<Effect> {
        Effect::parse_offset(name).or_else(|| m.error_by_name(name).map(Effect::Error))
    }

    /// The sensor offset called `name` (`dx0 dy0 dz0`, any case), or `None`.
    pub fn parse_offset(name: &str) -> Option<Effect> {
        match name.trim().to_ascii_lowercase().as_str() {
            "dx0" => Some(Effect::SensorOffset(Dir::X)),
            "dy0" => Some(Effect::SensorOffset(Dir::Y)),
            "dz0" => Some(Effect::SensorOffset(Dir::Z)),
            _ => None,
        }
    }

    /// Its name (`XOC`, `dx0`).
    pub fn name(self, m: &Machine) -> String {
        match self {
            Effect::Error(e) => m.catalogue[e].name.clone(),
            Effect::SensorOffset(d) => format!("d{d}0"),
        }
    }

    /// `true` for angular errors (rad inside, µrad for people).
    pub fn is_angular(self, m: &Machine) -> bool {
        matches!(self, Effect::Error(e) if m.catalogue[e].is_angular())
    }

    /// The unit people see: `um` or `urad`.
    pub fn unit(self, m: &Machine) -> &'static str {
        if self.is_angular(m) { "urad" } else { "um" }
    }

    /// The factor from the unit inside (mm, rad) to the unit people see (µm, µrad).
    pub fn display_factor(self, m: &Machine) -> f64 {
        if self.is_angular(m) {
            crate::units::URAD_PER_RAD
        } else {
            crate::units::UM_PER_MM
        }
    }

    /// What its basis depends on.
    pub fn carrier(self, m: &Machine) -> Carrier {
        match self {
            Effect::Error(e) => match m.catalogue[e].kind {
                crate::ErrorKind::Component { axis, .. } => Carrier::Axis(axis),
                _ => Carrier::None,
            },
            Effect::SensorOffset(_) => Carrier::None,
        }
    }
}

/// One term of a model: an effect times a basis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Term {
    /// The effect.
    pub effect: Effect,
    /// Its basis.
    pub basis: Basis,
}

impl Term {
    /// A term, checked against the machine (the basis must fit the effect: harmonics of rotary
    /// axes' component errors, polynomials and reversal of component errors of axes).
    pub fn new(m: &Machine, effect: Effect, basis: Basis) -> Result<Term, BasisError> {
        basis.check(m, effect.carrier(m))?;
        Ok(Term { effect, basis })
    }

    /// Parses `NAME` (constant) or `NAME@BASIS` (`ECC@harmonic:2`, `dx0@time:1`).
    pub fn parse(m: &Machine, s: &str) -> Result<Term, BasisError> {
        let (name, basis) = match s.split_once('@') {
            Some((n, b)) => (n, Basis::parse(b)?),
            None => (s, Basis::Const),
        };
        let effect = Effect::parse(m, name).ok_or_else(|| {
            BasisError(format!(
                "`{}` is neither an error of machine {} nor dx0/dy0/dz0",
                name.trim(),
                m.name
            ))
        })?;
        Term::new(m, effect, basis).map_err(|e| BasisError(format!("{}: {}", name.trim(), e.0)))
    }

    /// Its H-matrix column names: `XOC const`, `ECC harmonic:2:cos`, ….
    pub fn column_names(&self, m: &Machine) -> Vec<String> {
        let n = self.effect.name(m);
        self.basis
            .column_names()
            .into_iter()
            .map(|b| format!("{n} {b}"))
            .collect()
    }
}

/// The machine errors `terms` use, ascending (catalogue order), each once; sensor offsets are
/// not machine errors.
pub fn errors_of(terms: &[Term]) -> Vec<ErrorId> {
    let mut errors: Vec<ErrorId> = terms
        .iter()
        .filter_map(|t| match t.effect {
            Effect::Error(e) => Some(e),
            Effect::SensorOffset(_) => None,
        })
        .collect();
    errors.sort_unstable();
    errors.dedup();
    errors
}

/// What an effect is, in a machine-tool engineer's words (`angular positioning error of C`,
/// `straightness of X in y`, `squareness of X to the reference`, `ball set-up error in x`).
pub fn describe_effect(m: &Machine, effect: Effect) -> String {
    use crate::{AxisKind, ErrorKind, Motion};
    let e = match effect {
        Effect::SensorOffset(d) => return format!("R-test zero offset in {d}"),
        Effect::Error(e) => &m.catalogue[e],
    };
    match e.kind {
        ErrorKind::Component { axis, motion } => {
            let a = &m.axes[axis];
            let own = a.direction.dir;
            match (a.kind, motion) {
                (AxisKind::Linear, Motion::Translation(d)) if d == own => {
                    format!("positioning error of {}", a.name)
                }
                (AxisKind::Linear, Motion::Translation(d)) => {
                    format!("straightness of {} in {d}", a.name)
                }
                (AxisKind::Linear, Motion::Rotation(d)) if d == own => {
                    format!("roll of {} (about {d})", a.name)
                }
                (AxisKind::Linear, Motion::Rotation(d)) => {
                    format!("angular error of {} about {d}", a.name)
                }
                (AxisKind::Rotary, Motion::Rotation(d)) if d == own => {
                    format!("angular positioning error of {}", a.name)
                }
                (AxisKind::Rotary, Motion::Rotation(d)) => {
                    format!("tilt (wobble) of {} about {d}", a.name)
                }
                (AxisKind::Rotary, Motion::Translation(d)) if d == own => {
                    format!("axial motion error of {}", a.name)
                }
                (AxisKind::Rotary, Motion::Translation(d)) => {
                    format!("radial motion error of {} in {d}", a.name)
                }
            }
        }
        ErrorKind::Location { axis, motion } => match motion {
            Motion::Translation(d) => {
                format!("position of the {} axis line in {d}", m.axes[axis].name)
            }
            Motion::Rotation(d) => format!(
                "orientation of the {} axis line about {d}",
                m.axes[axis].name
            ),
        },
        ErrorKind::Squareness { axis, about } => {
            format!(
                "squareness of {} (rotation about {about})",
                m.axes[axis].name
            )
        }
        ErrorKind::Setup { along } => format!("workpiece (ball) set-up error in {along}"),
    }
}

/// What a basis means for people: `constant`, `twice per revolution`, `linear over the stroke`.
pub fn describe_basis(basis: Basis) -> String {
    match basis {
        Basis::Const => "constant".into(),
        Basis::Harmonic(1) => "once per revolution".into(),
        Basis::Harmonic(2) => "twice per revolution".into(),
        Basis::Harmonic(k) => format!("{k} times per revolution"),
        Basis::Poly(1) => "linear over the stroke".into(),
        Basis::Poly(2) => "quadratic over the stroke".into(),
        Basis::Poly(k) => format!("order-{k} polynomial over the stroke"),
        Basis::Reversal => "with the direction of motion (reversal)".into(),
        Basis::Time(1) => "drifting linearly in time".into(),
        Basis::Time(k) => format!("order-{k} polynomial in time"),
    }
}

impl Term {
    /// `ECC harmonic:2: angular positioning error of C, twice per revolution`.
    pub fn describe(&self, m: &Machine) -> String {
        format!(
            "{} {}: {}, {}",
            self.effect.name(m),
            self.basis,
            describe_effect(m, self.effect),
            describe_basis(self.basis)
        )
    }

    /// `ECC@harmonic:2` (`XOC` for a constant term): the spelling of sub-model lists.
    pub fn spelling(&self, m: &Machine) -> String {
        match self.basis {
            Basis::Const => self.effect.name(m),
            b => format!("{}@{b}", self.effect.name(m)),
        }
    }
}
