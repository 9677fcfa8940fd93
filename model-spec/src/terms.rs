//! Terms of a model: an effect (an ISO 230 error of the machine, an R-test sensor zero offset
//! `dx0 dy0 dz0`, or an R-test instrument term `SXX` … `SZY`) times a basis of the vocabulary
//! ([`crate::basis`]). A term gives one H-matrix column, two for `harmonic:K` and `period:P`.
//! Sub-models of a machine description list terms as `NAME` (constant) or `NAME@BASIS`
//! (`ECC@harmonic:2`, `dx0@time:1`, `EXX@velocity`).

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
    /// An R-test instrument term, dimensionless, acting on the readings, not on the machine:
    /// the reading in direction `reading` holds this coefficient times the displacement in
    /// direction `displacement`. `SXX SYY SZZ` (equal directions) are the sensor gain errors
    /// (the reading is (1 + S) × the displacement), `SXY SXZ SYX SYZ SZX SZY` the cross-talk
    /// (`SXY`: the x reading holds SXY × the y displacement). Constants only.
    Instrument {
        /// The direction of the reading it changes.
        reading: Dir,
        /// The direction of the displacement it takes.
        displacement: Dir,
    },
}

/// The effect names that are no machine error (`dx0 dy0 dz0`, `SXX` … `SZY`): reserved, so a
/// machine description may not give them to a kinematic symbol.
pub const MEASUREMENT_EFFECTS: &[&str] = &[
    "dx0", "dy0", "dz0", "SXX", "SXY", "SXZ", "SYX", "SYY", "SYZ", "SZX", "SZY", "SZZ",
];

impl Effect {
    /// The effect called `name` on `m`: an error name (digit-zero alias accepted),
    /// `dx0 dy0 dz0` or an instrument term `SXX` … `SZY`.
    pub fn parse(m: &Machine, name: &str) -> Option<Effect> {
        Effect::parse_measurement(name).or_else(|| m.error_by_name(name).map(Effect::Error))
    }

    /// The effect of the measurement (not of the machine) called `name`: a sensor offset
    /// (`dx0 dy0 dz0`, any case) or an instrument term (`SXX` … `SZY`, upper case), or `None`.
    pub fn parse_measurement(name: &str) -> Option<Effect> {
        Effect::parse_offset(name).or_else(|| Effect::parse_instrument(name))
    }

    /// The instrument term called `name` (`SXX` … `SZY`, upper case), or `None`.
    pub fn parse_instrument(name: &str) -> Option<Effect> {
        let dir = |c: u8| match c {
            b'X' => Some(Dir::X),
            b'Y' => Some(Dir::Y),
            b'Z' => Some(Dir::Z),
            _ => None,
        };
        match name.trim().as_bytes() {
            [b'S', r, d] => Some(Effect::Instrument {
                reading: dir(*r)?,
                displacement: dir(*d)?,
            }),
            _ => None,
        }
    }

    /// The nine instrument terms, `SXX SXY SXZ SYX … SZZ`.
    pub fn instruments() -> impl Iterator<Item = Effect> {
        Dir::ALL.into_iter().flat_map(|reading| {
            Dir::ALL
                .into_iter()
                .map(move |displacement| Effect::Instrument {
                    reading,
                    displacement,
                })
        })
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
            Effect::Instrument {
                reading,
                displacement,
            } => format!(
                "S{}{}",
                reading.translation_letter(),
                displacement.translation_letter()
            ),
        }
    }

    /// `true` for angular errors (rad inside, µrad for people).
    pub fn is_angular(self, m: &Machine) -> bool {
        matches!(self, Effect::Error(e) if m.catalogue[e].is_angular())
    }

    /// The unit people see of the effect's value: `um` or `urad`, `1` for an instrument term.
    /// (A term's coefficient may have another unit: [`Term::unit`].)
    pub fn unit(self, m: &Machine) -> &'static str {
        match self {
            Effect::Instrument { .. } => "1",
            _ if self.is_angular(m) => "urad",
            _ => "um",
        }
    }

    /// The factor from the unit inside (mm, rad, 1) to the unit people see (µm, µrad, 1).
    pub fn display_factor(self, m: &Machine) -> f64 {
        10f64.powi(self.places(m))
    }

    /// Decimal places between the unit inside and the unit people see: 3 (mm → µm), 6
    /// (rad → µrad), 0 for an instrument term.
    pub fn places(self, m: &Machine) -> i32 {
        match self {
            Effect::Instrument { .. } => 0,
            _ if self.is_angular(m) => 6,
            _ => 3,
        }
    }

    /// `true` for an axis's positioning error: the component error along (linear axis) or
    /// about (rotary axis) the axis's own direction (`EXX`, `ECC`).
    pub fn is_positioning(self, m: &Machine) -> bool {
        use crate::{AxisKind, ErrorKind, Motion};
        let Effect::Error(e) = self else {
            return false;
        };
        match m.catalogue[e].kind {
            ErrorKind::Component { axis, motion } => {
                let a = &m.axes[axis];
                match (a.kind, motion) {
                    (AxisKind::Linear, Motion::Translation(d))
                    | (AxisKind::Rotary, Motion::Rotation(d)) => d == a.direction.own.dir,
                    _ => false,
                }
            }
            _ => false,
        }
    }

    /// What its basis depends on.
    pub fn carrier(self, m: &Machine) -> Carrier {
        match self {
            Effect::Error(e) => match m.catalogue[e].kind {
                crate::ErrorKind::Component { axis, .. } => Carrier::Axis(axis),
                _ => Carrier::None,
            },
            Effect::SensorOffset(_) | Effect::Instrument { .. } => Carrier::None,
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
    /// A term, checked against the machine ([`Term::check`]).
    pub fn new(m: &Machine, effect: Effect, basis: Basis) -> Result<Term, BasisError> {
        let t = Term { effect, basis };
        t.check(m)?;
        Ok(t)
    }

    /// Checks that the basis fits the effect ([`Basis::check`]: harmonics of rotary axes'
    /// component errors, polynomials and periods of linear axes', reversal and steps of any
    /// axis's, `exp:TAU` of effects of no axis), that `velocity` multiplies a positioning error
    /// and that an instrument term is a constant.
    pub fn check(&self, m: &Machine) -> Result<(), BasisError> {
        if matches!(self.effect, Effect::Instrument { .. }) && self.basis != Basis::Const {
            return Err(BasisError(format!(
                "`{}` is an instrument term of the R-test: constants only, not `{}`",
                self.effect.name(m),
                self.basis
            )));
        }
        self.basis.check(m, self.effect.carrier(m))?;
        if self.basis == Basis::Velocity && !self.effect.is_positioning(m) {
            return Err(BasisError(
                "`velocity` needs the positioning error of an axis (EXX, EYY, ECC …: along or about the axis's own direction)".into(),
            ));
        }
        Ok(())
    }

    /// The unit people see of its coefficient: `ms` for `velocity` (the lag τ), `1` for an
    /// instrument term, else the effect's `um` or `urad`.
    pub fn unit(&self, m: &Machine) -> &'static str {
        match self.basis {
            Basis::Velocity => "ms",
            _ => self.effect.unit(m),
        }
    }

    /// Decimal places between the unit of its coefficient inside (mm, rad; ms for `velocity`;
    /// 1 for an instrument term) and [`Term::unit`]: 3, 6 or 0.
    pub fn places(&self, m: &Machine) -> i32 {
        match self.basis {
            Basis::Velocity => 0,
            _ => self.effect.places(m),
        }
    }

    /// The factor from its coefficient inside to [`Term::unit`]: 1000 (mm → µm), 1e6
    /// (rad → µrad), 1 (ms, instrument terms).
    pub fn display_factor(&self, m: &Machine) -> f64 {
        10f64.powi(self.places(m))
    }

    /// Parses `NAME` (constant) or `NAME@BASIS` (`ECC@harmonic:2`, `dx0@time:1`).
    pub fn parse(m: &Machine, s: &str) -> Result<Term, BasisError> {
        let (name, basis) = match s.split_once('@') {
            Some((n, b)) => (n, Basis::parse(b)?),
            None => (s, Basis::Const),
        };
        let effect = Effect::parse(m, name).ok_or_else(|| {
            BasisError(format!(
                "`{}` is neither an error of machine {} nor dx0/dy0/dz0 nor an instrument term SXX … SZY",
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
            Effect::SensorOffset(_) | Effect::Instrument { .. } => None,
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
        Effect::Instrument {
            reading,
            displacement,
        } if reading == displacement => return format!("R-test sensor gain in {reading}"),
        Effect::Instrument {
            reading,
            displacement,
        } => {
            return format!(
                "R-test cross-talk: the {displacement} displacement in the {reading} reading"
            );
        }
        Effect::Error(e) => &m.catalogue[e],
    };
    match e.kind {
        ErrorKind::Component { axis, motion } => {
            let a = &m.axes[axis];
            let own = a.direction.own.dir;
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
        Basis::Period(_) => format!(
            "periodic in position, period {} mm",
            basis.to_string().trim_start_matches("period:")
        ),
        Basis::Step(_) => format!(
            "a step at position {}",
            basis.to_string().trim_start_matches("step:")
        ),
        Basis::Exp(_) => format!(
            "settling exponentially, time constant {} s",
            basis.to_string().trim_start_matches("exp:")
        ),
        Basis::Velocity => "with the axis velocity (servo lag, coefficient in ms)".into(),
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
