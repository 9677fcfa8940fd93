//! Truth files: what a simulated machine's errors really are ([`Truth`]), read from and
//! written to a small TOML file (reference and examples: `docs/truth.md`):
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
//! Inside, a [`Truth`] holds the terms as a [`Model`](simulation::model::Model) and one coefficient
//! per model column in mm (translations, sensor offsets), rad (angles), ms (`velocity`) or 1
//! (instrument terms, [`Truth::instrument`]). The value of an effect at a sample is
//! `Σ coefficient · basis value` over its terms ([`simulation::model::Basis::values`]). Every
//! entry is validated against the machine, and every problem is a [`TruthError`] naming the
//! file, the line and the column.
//!
//! Built-in truths for `seed-ac` ([`BUILTIN_TRUTHS`], files in `formats/truths/`): `seed-ac-demo`
//! (the documented default of `rtest demo`) and `seed-ac-reduced` (the 11 errors of the reduced
//! model only, constants, no noise).

use model_spec::Machine;
use model_spec::units::format_scaled;
use simulation::model::{Basis, Effect};
use simulation::truth::{Truth, places};

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

/// The largest truth file read, bytes: a truth lists at most a few hundred terms.
pub const MAX_TRUTH_BYTES: u64 = 1 << 20;

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

impl From<crate::located::Located> for TruthError {
    fn from(e: crate::located::Located) -> Self {
        TruthError::Invalid {
            file: e.file,
            line: e.line,
            column: e.column,
            message: e.message,
        }
    }
}

/// Reads and validates a truth for machine `m`; `file` names the source in error messages.
///
/// # Errors
/// [`TruthError::Invalid`] for the first problem in the file (TOML syntax, unknown key,
/// unknown error or symbol, a basis that does not fit the error, an array of the wrong
/// length, a non-finite or negative number where it is not allowed, a term given twice).
pub fn parse_truth(file: &str, text: &str, m: &Machine) -> Result<Truth, TruthError> {
    parse::Parser {
        t: crate::located::TomlText::new(file, text),
        m,
    }
    .parse()
}

/// Reads the truth file `path` for machine `m`.
///
/// # Errors
/// [`TruthError::Text`] when the file cannot be read (or is too large, or not UTF-8); see
/// [`parse_truth`].
pub fn read_truth(path: &std::path::Path, m: &Machine) -> Result<Truth, TruthError> {
    let text = model_spec::text::read_text(path, MAX_TRUTH_BYTES)?;
    parse_truth(&path.display().to_string(), &text, m)
}

/// The truth as a TOML file that [`parse_truth`] reads back to the same truth, bit for bit
/// (numbers are written in µm / µrad with the decimal point moved, never rounded).
pub fn truth_to_toml(truth: &Truth, m: &Machine) -> String {
    let mut s = format!("machine = \"{}\"\n", m.name);
    if !truth.description.is_empty() {
        s += &format!("description = {}\n", toml_string(&truth.description));
    }
    s += &format!(
        "noise_um = {}\nseed = {}\nzeroed = {}\n",
        format_scaled(truth.noise_mm, 3),
        truth.seed,
        truth.zeroed
    );
    if truth.noise_phi > 0.0 {
        s += &format!("noise_phi = {}\n", toml_float(truth.noise_phi));
    }
    let defaults = m.default_parameters();
    let changed: Vec<usize> = (0..m.symbols.len())
        .filter(|&i| truth.params[i].to_bits() != defaults[i].to_bits())
        .collect();
    if !changed.is_empty() {
        s += "\n[parameters]\n";
        for i in changed {
            s += &format!("{} = {}\n", m.symbols[i].name, toml_float(truth.params[i]));
        }
    }
    s += "\n[errors]\n";
    // Terms are sorted, so the terms of one effect are adjacent.
    let mut at = 0;
    let mut lines: Vec<(Effect, Vec<(Basis, String)>)> = Vec::new();
    for t in &truth.model.terms {
        let w = t.basis.width();
        let p = places(m, t);
        let v: Vec<String> = truth.coefficients[at..at + w]
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
            let mut t = parse_truth(&format!("<built-in {n}>"), text, m)?;
            t.source = n.to_string();
            Ok(t)
        })
}

/// A truth given by built-in name ([`BUILTIN_TRUTHS`]) or by the path of a TOML file.
///
/// # Errors
/// [`TruthError::NotFound`] when it is neither; see [`read_truth`].
pub fn load_truth(name_or_path: &str, m: &Machine) -> Result<Truth, TruthError> {
    if let Some(t) = builtin_truth(name_or_path, m) {
        return t;
    }
    let path = std::path::Path::new(name_or_path);
    // Anything that exists and is not a directory is read (a file, a FIFO, a link to one).
    if !path.exists() || path.is_dir() {
        return Err(TruthError::NotFound(name_or_path.to_string()));
    }
    read_truth(path, m)
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

/// The default demo truth of `seed-ac` (`formats/truths/seed-ac-demo.toml`, documented in
/// `docs/truth.md`): location errors of A and C and ball set-up errors of 10–30 µm and µrad,
/// an angular positioning error of C twice per revolution (`ECC@harmonic:2`, amplitude
/// 10 µrad) that the reduced model lacks, and 0.5 µm noise, seed 1, not zeroed. Parsed against
/// the built-in `seed-ac`.
pub fn seed_ac_demo_truth() -> Truth {
    seed_ac_builtin("seed-ac-demo")
}

/// The reduced truth of `seed-ac` (`formats/truths/seed-ac-reduced.toml`): only the 11 errors of
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
