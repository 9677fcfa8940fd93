//! Terms of a model: an effect (an ISO 230 error of the machine, an R-test sensor zero offset
//! `dx0 dy0 dz0`, an R-test instrument term `SXX` … `SZY`, or a kinematic offset of the
//! description: one of its `[symbols]`, `Zt`, `Xw`) times a basis of the vocabulary
//! ([`crate::basis`]). A term gives one H-matrix column, two for `harmonic:K` and `period:P`.
//! Sub-models of a machine description list terms as `NAME` (constant) or `NAME@BASIS`
//! (`ECC@harmonic:2`, `dx0@time:1`, `EXX@velocity`).
//!
//! **Names.** A term's `NAME` is read, in this order of rules that never overlap:
//! - `dx0 dy0 dz0` (any case) and `SXX` … `SZY` (upper case): effects of the measurement;
//! - an error of the machine's catalogue, without regard to case and with the digit-zero alias
//!   (`xoc`, `X0C` are `XOC`);
//! - a kinematic symbol, exactly as the description writes it (`Zt`; `zt` is another name).
//!
//! The description's validation keeps these apart: a symbol may not be named like an effect of
//! the measurement, nor like an error of the machine in any spelling that reads as that error
//! (`XOC`, `xoc`, `X0C`), so every name means one effect.

use crate::basis::{Basis, BasisError, Carrier};
use crate::{Dir, ErrorId, Machine, SymbolId};

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
    /// A touch probe's pre-travel (`PRE`), in the approach azimuth about the stylus: with
    /// `PRE@harmonic:K` the pre-travel of a hit is `ρ·(a·cos Kφ + b·sin Kφ)` (mm; `φ` the
    /// approach's azimuth about the stylus, `ρ` its part across it, probe frame), and the
    /// term's columns are what that does to each pose's sphere-fit centre, per record of probe
    /// hits (`fitting::probe`). A constant pre-travel moves no centre of a free-radius sphere
    /// fit (the radii show it): harmonics only.
    PreTravel,
    /// A kinematic offset of the machine description: the symbol (index into
    /// `Machine::symbols`) whose value the identification changes. Its coefficient is the
    /// change from the value the record is modelled with (mm inside, µm for people); its gain is
    /// the derivative of the tool-minus-workpiece vector (tool frame) with respect to the
    /// symbol, mm/mm. Constants only: a kinematic offset is one length of the machine's
    /// geometry.
    KinematicOffset(SymbolId),
}

/// The effect names that are no machine error (`dx0 dy0 dz0`, `SXX` … `SZY`): reserved, so a
/// machine description may not give them to a kinematic symbol.
pub const MEASUREMENT_EFFECTS: &[&str] = &[
    "dx0", "dy0", "dz0", "px0", "py0", "pz0", "PRE", "SXX", "SXY", "SXZ", "SYX", "SYY", "SYZ",
    "SZX", "SZY", "SZZ",
];

impl Effect {
    /// The effect called `name` on `m` among the errors and the effects of the measurement: an
    /// error name (digit-zero alias accepted), `dx0 dy0 dz0` or an instrument term `SXX` …
    /// `SZY`. Kinematic offsets are not among them (a truth gives a symbol's real value under
    /// `[parameters]`, not as an error): [`Effect::parse_term`] reads every effect a term may
    /// have.
    pub fn parse(m: &Machine, name: &str) -> Option<Effect> {
        Effect::parse_measurement(name).or_else(|| m.error_by_name(name).map(Effect::Error))
    }

    /// The effect a model term called `name` has on `m`: as [`Effect::parse`], or a kinematic
    /// offset ([`Effect::parse_kinematic`]).
    pub fn parse_term(m: &Machine, name: &str) -> Option<Effect> {
        Effect::parse(m, name).or_else(|| Effect::parse_kinematic(m, name))
    }

    /// The kinematic offset called `name` on `m`: the symbol of that name exactly as the
    /// description writes it (surrounding blanks ignored), or `None`.
    pub fn parse_kinematic(m: &Machine, name: &str) -> Option<Effect> {
        m.symbol_by_name(name.trim()).map(Effect::KinematicOffset)
    }

    /// The effect of the measurement (not of the machine) called `name`: a sensor offset
    /// (`dx0 dy0 dz0`, any case) or an instrument term (`SXX` … `SZY`, upper case), or `None`.
    pub fn parse_measurement(name: &str) -> Option<Effect> {
        if name.trim() == "PRE" {
            return Some(Effect::PreTravel);
        }
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

    /// The sensor offset called `name` (`dx0 dy0 dz0`, any case; `px0 py0 pz0`, a touch
    /// probe's zero, are the same offsets of the reading in the tool frame), or `None`.
    pub fn parse_offset(name: &str) -> Option<Effect> {
        match name.trim().to_ascii_lowercase().as_str() {
            "dx0" | "px0" => Some(Effect::SensorOffset(Dir::X)),
            "dy0" | "py0" => Some(Effect::SensorOffset(Dir::Y)),
            "dz0" | "pz0" => Some(Effect::SensorOffset(Dir::Z)),
            _ => None,
        }
    }

    /// Its name (`XOC`, `dx0`, `Zt`).
    pub fn name(self, m: &Machine) -> String {
        match self {
            Effect::Error(e) => m.catalogue[e].name.clone(),
            Effect::KinematicOffset(s) => m.symbols[s].name.clone(),
            Effect::SensorOffset(d) => format!("d{d}0"),
            Effect::PreTravel => "PRE".into(),
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

    /// The unit people see of the effect's value: `um` or `urad`, `1` for an instrument term;
    /// `um` for a kinematic offset (its change; the symbol itself is in mm). (A term's
    /// coefficient may have another unit: [`Term::unit`].)
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
            Effect::SensorOffset(_)
            | Effect::Instrument { .. }
            | Effect::PreTravel
            | Effect::KinematicOffset(_) => Carrier::None,
        }
    }

    /// The kinematic symbol of a kinematic offset, or `None`.
    pub fn symbol(self) -> Option<SymbolId> {
        match self {
            Effect::KinematicOffset(s) => Some(s),
            _ => None,
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
    /// axis's, `exp:TAU` of effects of no axis; `time:K`, `rate` and `warmup:TAU` of any
    /// error or sensor offset), that `velocity` multiplies a positioning error and that an
    /// instrument term or a kinematic offset (a symbol of `m`) is a constant.
    pub fn check(&self, m: &Machine) -> Result<(), BasisError> {
        if let Effect::KinematicOffset(s) = self.effect {
            if s >= m.symbols.len() {
                return Err(BasisError(format!(
                    "symbol #{s} is not a kinematic symbol of machine {} ({} symbols)",
                    m.name,
                    m.symbols.len()
                )));
            }
            if self.basis != Basis::Const {
                return Err(BasisError(format!(
                    "`{}` is a kinematic offset of the machine (a length of its description, mm): constants only, not `{}`; a length does not change with position, direction of motion or time (what does is an error of an axis or a drift)",
                    m.symbols[s].name, self.basis
                )));
            }
            return Ok(());
        }
        if self.effect == Effect::PreTravel {
            return match self.basis {
                Basis::Harmonic(_) => Ok(()),
                Basis::Const => Err(BasisError(
                    "`PRE` alone is a constant pre-travel of the probe: it moves no centre of a free-radius sphere fit (every hit pre-travels alike, and the fitted radius takes it), so the centres cannot determine it; the sphere fits' radii give it (the probe's part of the identification). Its lobing in the approach azimuth is `PRE@harmonic:K` (K = 3 for a three-point kinematic probe)".into(),
                )),
                other => Err(BasisError(format!(
                    "`PRE` (a touch probe's pre-travel) varies with the approach azimuth about the stylus: `PRE@harmonic:K` only, not `{other}`"
                ))),
            };
        }
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

    /// The unit people see of its coefficient: `ms` for `velocity` (the lag τ), `um/s` or
    /// `urad/s` for `rate` (a rate of the effect per second), `1` for an instrument term, else
    /// the effect's `um` or `urad`.
    pub fn unit(&self, m: &Machine) -> &'static str {
        match self.basis {
            Basis::Velocity => "ms",
            Basis::Rate => match self.effect.unit(m) {
                "urad" => "urad/s",
                _ => "um/s",
            },
            _ => self.effect.unit(m),
        }
    }

    /// Decimal places between the unit of its coefficient inside (mm, rad; mm/s, rad/s for
    /// `rate`; ms for `velocity`; 1 for an instrument term) and [`Term::unit`]: 3, 6 or 0.
    pub fn places(&self, m: &Machine) -> i32 {
        match self.basis {
            Basis::Velocity => 0,
            _ => self.effect.places(m),
        }
    }

    /// The factor from its coefficient inside to [`Term::unit`]: 1000 (mm → µm, mm/s →
    /// µm/s), 1e6 (rad → µrad, rad/s → µrad/s), 1 (ms, instrument terms).
    pub fn display_factor(&self, m: &Machine) -> f64 {
        10f64.powi(self.places(m))
    }

    /// Parses `NAME` (constant) or `NAME@BASIS` (`ECC@harmonic:2`, `dx0@time:1`, `Zt`): `NAME`
    /// as [`Effect::parse_term`] reads it.
    pub fn parse(m: &Machine, s: &str) -> Result<Term, BasisError> {
        let (name, basis) = match s.split_once('@') {
            Some((n, b)) => (n, Basis::parse(b)?),
            None => (s, Basis::Const),
        };
        let effect = Effect::parse_term(m, name).ok_or_else(|| unknown_effect(m, name))?;
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

/// Why `name` is no effect of `m`: what a name may be; when it is a kinematic symbol's name in
/// another case, how the symbol is written.
pub fn unknown_effect(m: &Machine, name: &str) -> BasisError {
    if let Some(s) = m
        .symbols
        .iter()
        .find(|s| s.name.eq_ignore_ascii_case(name.trim()))
    {
        return BasisError(format!(
            "`{}` is no effect of machine {}; its kinematic symbol is written `{}` (symbols are named exactly as the description writes them)",
            name.trim(),
            m.name,
            s.name
        ));
    }
    BasisError(format!(
        "`{}` is neither an error of machine {} nor dx0/dy0/dz0 nor an instrument term SXX … SZY",
        name.trim(),
        m.name
    ))
}

/// The machine errors `terms` use, ascending (catalogue order), each once; sensor offsets,
/// instrument terms and kinematic offsets are not machine errors.
pub fn errors_of(terms: &[Term]) -> Vec<ErrorId> {
    let mut errors: Vec<ErrorId> = terms
        .iter()
        .filter_map(|t| match t.effect {
            Effect::Error(e) => Some(e),
            Effect::SensorOffset(_)
            | Effect::Instrument { .. }
            | Effect::PreTravel
            | Effect::KinematicOffset(_) => None,
        })
        .collect();
    errors.sort_unstable();
    errors.dedup();
    errors
}

/// What an effect is, in a machine-tool engineer's words (`angular positioning error of C`,
/// `straightness of X in y`, `squareness of X to the reference`, `ball set-up error in x`,
/// `kinematic offset Zt: z of the offset of the end probe (tool chain)`).
pub fn describe_effect(m: &Machine, effect: Effect) -> String {
    use crate::{AxisKind, ErrorKind, Motion};
    let e = match effect {
        Effect::KinematicOffset(s) => {
            let uses = symbol_uses(m, s);
            let ball = m.workpiece_symbols().contains(&s);
            return format!(
                "{} {}{}",
                if ball {
                    "ball position"
                } else {
                    "kinematic offset"
                },
                m.symbols[s].name,
                if uses.is_empty() {
                    " (used in no offset)".to_string()
                } else {
                    format!(": {}", uses.join(", "))
                }
            );
        }
        Effect::SensorOffset(d) => return format!("R-test zero offset in {d}"),
        Effect::PreTravel => {
            return "touch probe pre-travel in the approach azimuth about the stylus".into();
        }
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

/// Where the description uses symbol `s`: `z of the offset of the end probe (tool chain)`,
/// `x of the offset of axis A`, `x of the offset of the link holder`, in chain order (work
/// chain first, each from the bed outwards).
pub fn symbol_uses(m: &Machine, s: SymbolId) -> Vec<String> {
    use crate::{Link, Side, Value};
    let mut out = Vec::new();
    let mut add = |offset: &crate::Offset, what: String| {
        for (k, v) in offset.iter().enumerate() {
            if *v == Value::Symbol(s) {
                out.push(format!("{} of the offset of {what}", ["x", "y", "z"][k]));
            }
        }
    };
    for side in [Side::Work, Side::Tool] {
        let chain = m.chain(side);
        let which = match side {
            Side::Work => "work chain",
            Side::Tool => "tool chain",
        };
        for link in &chain.links {
            match link {
                Link::Axis(a) => add(&m.axes[*a].offset, format!("axis {}", m.axes[*a].name)),
                Link::Fixed { name, offset } => add(offset, format!("the link {name} ({which})")),
            }
        }
        add(
            &chain.end_offset,
            format!("the end {} ({which})", chain.end_name),
        );
    }
    out
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
        Basis::Rate => "drifting at a constant rate from the start (per second)".into(),
        Basis::Warmup(_) => format!(
            "warming up from the start, time constant {} s (coefficient: the amplitude it tends to)",
            basis.to_string().trim_start_matches("warmup:")
        ),
        Basis::Jump(_) => format!(
            "a jump at {} s of the record's own clock (the ball or the sensor moved during the record)",
            basis.to_string().trim_start_matches("jump:")
        ),
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
