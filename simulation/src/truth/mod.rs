//! The "truth" of a simulated machine: what the virtual machine's errors really are.
//!
//! A truth is read from a small TOML file (reference and examples: `docs/truth.md`):
//!
//! ```toml
//! machine = "seed-ac"          # optional: the machine it is written for
//! description = "example"      # optional text
//! noise_um = 0.5               # standard deviation of the reading noise per direction, µm
//! noise_phi = 0.8              # its lag-1 autocorrelation (AR(1)); default 0, white
//! seed = 1                     # seed of the noise generator
//! zeroed = false               # readings zeroed at the first sample
//!
//! [parameters]                 # the real machine's kinematic offsets, mm (default: nominal)
//! Zp = 184.7
//!
//! [errors]                     # µm for translations and dx0 dy0 dz0, µrad for angles
//! XOW = 12.0                   # a number: constant
//! ECC = { const = 3.0, "harmonic:2" = [8.0, 6.0], velocity = 0.5 }  # velocity: lag in ms
//! dz0 = { const = 1.0, "time:1" = 0.5, "exp:20" = 2.0 }             # offset, drift, settling
//! SXY = 0.03                   # instrument term (dimensionless): cross-talk
//! ```
//!
//! Inside, a [`Truth`] holds the terms as a [`Model`] and one coefficient per model column in
//! mm (translations, sensor offsets), rad (angles), ms (`velocity`) or 1 (instrument terms,
//! [`Truth::instrument`]). The value of an effect at a sample is `Σ coefficient · basis value`
//! over its terms ([`crate::model::Basis::values`]). Every entry is validated against the
//! machine, and every problem is a [`TruthError`] naming the file, the line and the column.
//!
//! Built-in truths for `seed-ac` ([`BUILTIN_TRUTHS`], files in `simulation/truths/`): `seed-ac-demo`
//! (the documented default of `rtest demo`) and `seed-ac-reduced` (the 11 errors of the reduced
//! model only, constants, no noise).

use crate::model::Basis;
use crate::model::{BasisContext, Effect, Model, Term};
use model_spec::Machine;
use model_spec::units::{format_scaled, parse_scaled};

mod parse;

/// Name and TOML text of every built-in truth.
pub const BUILTIN_TRUTHS: &[(&str, &str)] = &[
    (
        "seed-ac-demo",
        include_str!("../../truths/seed-ac-demo.toml"),
    ),
    (
        "seed-ac-reduced",
        include_str!("../../truths/seed-ac-reduced.toml"),
    ),
    (
        "seed-ac-budget",
        include_str!("../../truths/seed-ac-budget.toml"),
    ),
];

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

/// The largest truth file read, bytes: a truth lists at most a few hundred terms.
pub const MAX_TRUTH_BYTES: u64 = 1 << 20;

/// The largest magnitude of an error value or sensor offset in a truth, µm or µrad (1 m or
/// 1 rad): beyond it a first-order error model has no meaning.
pub const MAX_VALUE: f64 = 1e6;

/// Decimal places between the unit people write and the unit inside: µm → mm is 3, µrad → rad
/// is 6.
fn places(m: &Machine, term: &Term) -> i32 {
    term.places(m)
}

/// A problem with a truth: its file cannot be read, or an entry is invalid.
#[derive(Debug, thiserror::Error)]
pub enum TruthError {
    /// An invalid entry, located in the file (1-based line and column, in characters).
    #[error("{file}:{line}:{column}: {message}")]
    Invalid {
        /// The file (or `<built-in NAME>`).
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column, in characters.
        column: usize,
        /// What is wrong and what would be right.
        message: String,
    },
    /// The file cannot be read, is larger than [`MAX_TRUTH_BYTES`] or is not UTF-8 text.
    #[error("truth file: {0}")]
    Text(#[from] model_spec::text::TextError),
    /// Neither a built-in truth nor an existing file.
    #[error("no built-in truth and no file called `{0}` (built-in: {names})", names = BUILTIN_TRUTHS.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", "))]
    NotFound(String),
}

/// The truth of a simulated machine. Built by [`Truth::parse`] (or [`Truth::nominal`]); the
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

    /// Reads and validates a truth for machine `m`; `file` names the source in error messages.
    ///
    /// # Errors
    /// [`TruthError::Invalid`] for the first problem in the file (TOML syntax, unknown key,
    /// unknown error or symbol, a basis that does not fit the error, an array of the wrong
    /// length, a non-finite or negative number where it is not allowed, a term given twice).
    pub fn parse(file: &str, text: &str, m: &Machine) -> Result<Truth, TruthError> {
        parse::Parser { file, text, m }.parse()
    }

    /// Reads the truth file `path` for machine `m`.
    ///
    /// # Errors
    /// [`TruthError::Text`] when the file cannot be read (or is too large, or not UTF-8); see
    /// [`Truth::parse`].
    pub fn load(path: &std::path::Path, m: &Machine) -> Result<Truth, TruthError> {
        let text = model_spec::text::read_text(path, MAX_TRUTH_BYTES)?;
        Truth::parse(&path.display().to_string(), &text, m)
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
            if matches!(t.effect, Effect::Instrument { .. }) {
                continue;
            }
            let b = t.basis.values(m, t.effect.carrier(m), cx);
            let v = c.iter().zip(b).map(|(c, b)| c * b).sum::<f64>();
            match t.effect {
                Effect::Error(e) => errors[e] += v,
                Effect::SensorOffset(d) => offsets[d.index()] += v,
                // The real lengths are `params`: a truth never has a kinematic offset term.
                Effect::Instrument { .. } | Effect::KinematicOffset(_) => {}
            }
        }
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

    /// The truth as a TOML file that [`Truth::parse`] reads back to the same truth, bit for bit
    /// (numbers are written in µm / µrad with the decimal point moved, never rounded).
    pub fn to_toml(&self, m: &Machine) -> String {
        let mut s = format!("machine = \"{}\"\n", m.name);
        if !self.description.is_empty() {
            s += &format!("description = {}\n", toml_string(&self.description));
        }
        s += &format!(
            "noise_um = {}\nseed = {}\nzeroed = {}\n",
            format_scaled(self.noise_mm, 3),
            self.seed,
            self.zeroed
        );
        if self.noise_phi > 0.0 {
            s += &format!("noise_phi = {}\n", toml_float(self.noise_phi));
        }
        let defaults = m.default_parameters();
        let changed: Vec<usize> = (0..m.symbols.len())
            .filter(|&i| self.params[i].to_bits() != defaults[i].to_bits())
            .collect();
        if !changed.is_empty() {
            s += "\n[parameters]\n";
            for i in changed {
                s += &format!("{} = {}\n", m.symbols[i].name, toml_float(self.params[i]));
            }
        }
        s += "\n[errors]\n";
        // Terms are sorted, so the terms of one effect are adjacent.
        let mut at = 0;
        let mut lines: Vec<(Effect, Vec<(Basis, String)>)> = Vec::new();
        for t in &self.model.terms {
            let w = t.basis.width();
            let p = places(m, t);
            let v: Vec<String> = self.coefficients[at..at + w]
                .iter()
                .map(|&c| format_scaled(c, p))
                .collect();
            let value = if w == 2 {
                format!("[{}]", v.join(", "))
            } else {
                v[0].clone()
            };
            let part = (t.basis, value);
            match lines.last_mut() {
                Some((e, parts)) if *e == t.effect => parts.push(part),
                _ => lines.push((t.effect, vec![part])),
            }
            at += w;
        }
        for (effect, parts) in lines {
            let value = match parts.as_slice() {
                [(Basis::Const, v)] => v.clone(),
                _ => {
                    let p: Vec<String> = parts
                        .iter()
                        .map(|(b, v)| format!("\"{b}\" = {v}"))
                        .collect();
                    format!("{{ {} }}", p.join(", "))
                }
            };
            s += &format!("{} = {value}\n", effect.name(m));
        }
        s
    }
}

/// A TOML basic string.
fn toml_string(s: &str) -> String {
    serde_json::to_string(s).unwrap_or_else(|_| "\"\"".into())
}

/// An `f64` as a TOML float that reads back to the same bits.
fn toml_float(x: f64) -> String {
    let s = format!("{x:?}");
    if s.contains(['.', 'e', 'E', 'i', 'n']) {
        s
    } else {
        format!("{s}.0")
    }
}

/// The built-in truth called `name`, for machine `m`.
pub fn builtin_truth(name: &str, m: &Machine) -> Option<Result<Truth, TruthError>> {
    BUILTIN_TRUTHS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(n, text)| {
            let mut t = Truth::parse(&format!("<built-in {n}>"), text, m)?;
            t.source = n.to_string();
            Ok(t)
        })
}

/// A truth given by built-in name ([`BUILTIN_TRUTHS`]) or by the path of a TOML file.
///
/// # Errors
/// [`TruthError::NotFound`] when it is neither; see [`Truth::load`].
pub fn load_truth(name_or_path: &str, m: &Machine) -> Result<Truth, TruthError> {
    if let Some(t) = builtin_truth(name_or_path, m) {
        return t;
    }
    let path = std::path::Path::new(name_or_path);
    // Anything that exists and is not a directory is read (a file, a FIFO, a link to one).
    if !path.exists() || path.is_dir() {
        return Err(TruthError::NotFound(name_or_path.to_string()));
    }
    Truth::load(path, m)
}

/// The default truth of machine `m`: its built-in demo truth `<machine>-demo` if there is one
/// (`seed-ac-demo`), else the nominal machine.
///
/// # Errors
/// A built-in demo truth that does not fit this description of the machine (a machine file
/// named like a built-in machine but different from it).
pub fn default_truth(m: &Machine) -> Result<Truth, TruthError> {
    let name = format!("{}-demo", m.name);
    match builtin_truth(&name, m) {
        Some(t) => t,
        None => Ok(Truth::nominal(m)),
    }
}

/// The default demo truth of `seed-ac` (`simulation/truths/seed-ac-demo.toml`, documented in
/// `docs/truth.md`): location errors of A and C and ball set-up errors of 10–30 µm and µrad,
/// an angular positioning error of C twice per revolution (`ECC@harmonic:2`, amplitude
/// 10 µrad) that the reduced model lacks, and 0.5 µm noise, seed 1, not zeroed. Parsed against
/// the built-in `seed-ac`.
pub fn seed_ac_demo_truth() -> Truth {
    seed_ac_builtin("seed-ac-demo")
}

/// The reduced truth of `seed-ac` (`simulation/truths/seed-ac-reduced.toml`): only the 11 errors of
/// the reduced model, as constants of 10–40 µm and µrad, no noise, not zeroed.
pub fn seed_ac_reduced_truth() -> Truth {
    seed_ac_builtin("seed-ac-reduced")
}

fn seed_ac_builtin(name: &str) -> Truth {
    let m = model_spec::builtin("seed-ac")
        .expect("seed-ac is built in")
        .expect("built-in machines are valid");
    builtin_truth(name, &m)
        .expect("listed")
        .expect("built-in truths are valid (tested)")
}
