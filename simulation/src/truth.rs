//! The "truth" of a simulated machine: what the virtual machine's errors really are.
//!
//! A [`Truth`] holds the terms as a [`Model`] and one coefficient per model column in mm
//! (translations, sensor offsets), rad (angles), ms (`velocity`) or 1 (instrument terms,
//! [`Truth::instrument`]). The value of an effect at a sample is `Σ coefficient · basis value`
//! over its terms ([`crate::model::Basis::values`]). Truths are read from and written to TOML
//! files (and the built-in truths are such files) by the `formats` crate (`docs/truth.md`); the
//! bounds below are the ones its reader enforces.

use crate::model::Basis;
use crate::model::{BasisContext, Effect, Model, Term};
use model_spec::Machine;
use model_spec::units::{format_scaled, parse_scaled};

/// The largest seed of the noise generator: a TOML integer is at most `i64::MAX`, so truth
/// files and the command line share this range.
pub const MAX_SEED: u64 = i64::MAX as u64;

/// The largest standard deviation of the reading noise a truth may have, µm: larger noise
/// would give readings beyond any plausible R-test reading.
pub const MAX_NOISE_UM: f64 = 1000.0;

/// The largest lag-1 autocorrelation of the reading noise (exclusive), for simulated and
/// fitted noise alike: at φ → 1 the noise is a random walk, which no stationary model
/// describes.
pub const MAX_NOISE_PHI: f64 = 0.99;

/// The largest magnitude of an error value or sensor offset in a truth, µm or µrad (1 m or
/// 1 rad): beyond it a first-order error model has no meaning.
pub const MAX_VALUE: f64 = 1e6;

/// Decimal places between the unit people write and the unit inside: µm → mm is 3, µrad → rad
/// is 6.
pub fn places(m: &Machine, term: &Term) -> i32 {
    term.places(m)
}

/// The truth of a simulated machine. Read from a truth file, or [`Truth::nominal`]; the
/// fields are public so that a caller can override the noise, the seed or zeroing.
#[derive(Clone, Debug, PartialEq)]
pub struct Truth {
    /// Where it came from (file name or `<built-in NAME>`), for reports.
    pub source: String,
    /// What it is, for people (may be empty).
    pub description: String,
    /// The real machine's kinematic parameters, one per [`Machine::symbols`] entry (mm): the
    /// defaults with the file's `[parameters]` overrides. Paths are planned with the defaults
    /// (what the controller believes), the virtual machine runs with these.
    pub params: Vec<f64>,
    /// The terms (effect × basis), sorted, each at most once.
    pub model: Model,
    /// One coefficient per column of `model` (`Model::columns` order): mm for translational
    /// errors and sensor offsets, rad for angular errors, ms for `velocity`, 1 for instrument
    /// terms; `harmonic:K` and `period:P` have two (cos, sin).
    pub coefficients: Vec<f64>,
    /// Marginal standard deviation of the Gaussian reading noise, per direction, mm.
    pub noise_mm: f64,
    /// Lag-1 autocorrelation of the reading noise, in [0, [`MAX_NOISE_PHI`]): an AR(1)
    /// process per direction and record ([`crate::readings`]); 0 is white.
    pub noise_phi: f64,
    /// Seed of the noise generator ([`crate::rng::Rng`]).
    pub seed: u64,
    /// `true`: the readings are zeroed at the first sample (subtracted from every sample).
    pub zeroed: bool,
}

/// One term of a truth in the units people see, for reports.
#[derive(Clone, Debug, PartialEq)]
pub struct TruthEntry {
    /// The term.
    pub term: Term,
    /// Effect name (`XOC`, `dx0`).
    pub name: String,
    /// Its value(s): one, or `[cos, sin]` for `harmonic:K` and `period:P`; in `unit`.
    pub values: Vec<f64>,
    /// `um`, `urad`, `ms` (`velocity`) or `1` (instrument terms): [`Term::unit`].
    pub unit: &'static str,
}

impl Truth {
    /// The nominal machine: no errors, default kinematic parameters, no noise, seed 0, not
    /// zeroed.
    pub fn nominal(m: &Machine) -> Truth {
        Truth {
            source: "<nominal>".into(),
            description: "no errors".into(),
            params: m.default_parameters(),
            model: Model::default(),
            coefficients: Vec::new(),
            noise_mm: 0.0,
            noise_phi: 0.0,
            seed: 0,
            zeroed: false,
        }
    }

    /// The coefficient(s) of `term` (mm or rad; two for `harmonic:K`), if the truth has it.
    pub fn coefficient(&self, term: &Term) -> Option<&[f64]> {
        let mut at = 0;
        for t in &self.model.terms {
            let w = t.basis.width();
            if t == term {
                return self.coefficients.get(at..at + w);
            }
            at += w;
        }
        None
    }

    /// Evaluates every machine error and sensor offset at the sample `cx`: `errors` (one per
    /// catalogue entry, mm or rad) and `offsets` (`dx0 dy0 dz0`, mm) are overwritten. The
    /// instrument terms act on the reading, not here ([`Truth::instrument`]). `cx` must carry
    /// what the truth's bases need (commands and motion per axis, velocities for `velocity`).
    ///
    /// # Panics
    /// When `errors` is not one per catalogue entry, or `cx` does not have one command,
    /// direction (and velocity, for `velocity` terms) per axis of the machine the truth was
    /// parsed for.
    pub fn evaluate_into(
        &self,
        m: &Machine,
        cx: &BasisContext<'_>,
        errors: &mut [f64],
        offsets: &mut [f64; 3],
    ) {
        errors.fill(0.0);
        *offsets = [0.0; 3];
        let mut at = 0;
        for t in &self.model.terms {
            let w = t.basis.width();
            let c = &self.coefficients[at..at + w];
            at += w;
            if matches!(t.effect, Effect::Instrument { .. } | Effect::PreTravel) {
                continue;
            }
            let b = t.basis.values(m, t.effect.carrier(m), cx);
            let v = c.iter().zip(b).map(|(c, b)| c * b).sum::<f64>();
            match t.effect {
                Effect::Error(e) => errors[e] += v,
                Effect::SensorOffset(d) => offsets[d.index()] += v,
                // The real lengths are `params`: a truth never has a kinematic offset term.
                Effect::Instrument { .. } | Effect::PreTravel | Effect::KinematicOffset(_) => {}
            }
        }
    }

    /// Checks that the truth fits machine `m`: one kinematic parameter per symbol, one
    /// coefficient per model column, errors of its catalogue, terms valid on it.
    ///
    /// # Errors
    /// What does not fit, for a message that names the truth.
    pub fn fits(&self, m: &Machine) -> Result<(), String> {
        if self.params.len() != m.symbols.len() {
            return Err(format!(
                "it has {} kinematic parameters, the machine {}",
                self.params.len(),
                m.symbols.len()
            ));
        }
        if self.coefficients.len() != self.model.width() {
            return Err(format!(
                "it has {} coefficients for {} model columns",
                self.coefficients.len(),
                self.model.width()
            ));
        }
        for t in &self.model.terms {
            if let Effect::Error(e) = t.effect
                && e >= m.catalogue.len()
            {
                return Err(format!(
                    "it names error #{e}, the catalogue has {} errors",
                    m.catalogue.len()
                ));
            }
            if let Err(e) = t.check(m) {
                return Err(format!("term {}: {}", t.effect.name(m), e.0));
            }
        }
        Ok(())
    }

    /// Every catalogue error's value at the sample `cx` (catalogue order; mm or rad).
    pub fn error_values(&self, m: &Machine, cx: &BasisContext<'_>) -> Vec<f64> {
        let mut e = vec![0.0; m.catalogue.len()];
        let mut o = [0.0; 3];
        self.evaluate_into(m, cx, &mut e, &mut o);
        e
    }

    /// The R-test zero offsets `dx0 dy0 dz0` at the sample `cx` (mm, tool frame; added to the
    /// reading).
    pub fn sensor_offsets(&self, m: &Machine, cx: &BasisContext<'_>) -> [f64; 3] {
        let mut e = vec![0.0; m.catalogue.len()];
        let mut o = [0.0; 3];
        self.evaluate_into(m, cx, &mut e, &mut o);
        o
    }

    /// The instrument matrix `S` (dimensionless, constant): `S[i][j]` is the instrument term
    /// `S<i><j>`, so that the reading is `(I + S) · displacement` plus the offsets.
    pub fn instrument(&self) -> [[f64; 3]; 3] {
        let mut s = [[0.0; 3]; 3];
        let mut at = 0;
        for t in &self.model.terms {
            if let Effect::Instrument {
                reading,
                displacement,
            } = t.effect
            {
                s[reading.index()][displacement.index()] += self.coefficients[at];
            }
            at += t.basis.width();
        }
        s
    }

    /// `true` when a term needs the real sample times (`velocity`, `exp:TAU`).
    pub fn needs_times(&self) -> bool {
        self.model.terms.iter().any(|t| t.basis.needs_times())
    }

    /// The terms in the units people see (µm, µrad), model order.
    pub fn entries(&self, m: &Machine) -> Vec<TruthEntry> {
        let mut at = 0;
        let mut out = Vec::new();
        for t in &self.model.terms {
            let w = t.basis.width();
            let p = places(m, t);
            out.push(TruthEntry {
                term: *t,
                name: t.effect.name(m),
                // The decimal point moved in the shortest decimal: 0.012 mm is 12 µm exactly.
                values: self.coefficients[at..at + w]
                    .iter()
                    .map(|&c| parse_scaled(&format_scaled(c, p), 0).unwrap_or(c * 10f64.powi(p)))
                    .collect(),
                unit: t.unit(m),
            });
            at += w;
        }
        out
    }

    /// One line for people: source, number of terms, noise (with its φ when not white), seed,
    /// zeroing.
    pub fn summary(&self, m: &Machine) -> String {
        let names: Vec<String> = self
            .model
            .terms
            .iter()
            .map(|t| match t.basis {
                Basis::Const => t.effect.name(m),
                b => format!("{}@{b}", t.effect.name(m)),
            })
            .collect();
        let phi = if self.noise_phi > 0.0 {
            format!(" AR(1) phi {}", self.noise_phi)
        } else {
            String::new()
        };
        format!(
            "truth {}: {} term(s) [{}], noise {} um{phi}, seed {}, {}",
            self.source,
            names.len(),
            names.join(" "),
            format_scaled(self.noise_mm, 3),
            self.seed,
            if self.zeroed {
                "zeroed at the first sample"
            } else {
                "not zeroed"
            }
        )
    }
}
