//! Bounds of plausibility for identified values: a fit that "finds" an angular error of 71.7
//! rad or a location error of −2 m does not describe a machine tool, whatever its statistics
//! say. Such a result is refused, not reported.
//!
//! The defaults ([`ValueLimits::default`]): 1 mm for translational values (errors and sensor
//! offsets), 10 mrad for angular values, per coefficient (a harmonic's cos and sin, a
//! polynomial's coefficient). Real geometric errors of machine tools are tens of µm and µrad;
//! the bounds leave two orders of magnitude for set-ups far off nominal. A servo lag
//! (`velocity`) is bounded by 1000 ms (real lags are tens of ms), an instrument term by 0.5
//! (real gain errors and cross-talk are below a few per cent), a `rate` by the bound of its
//! effect per second (1 mm/s, 10 mrad/s: thermal drifts are µm per minute). They are a data
//! sanity check, separate from the diagnosis's plausibility budget of a finding.

use super::identify::Identification;
use model_spec::Machine;
use model_spec::units::{UM_PER_MM, URAD_PER_RAD, short};
use simulation::model::{Basis, Effect, Model};

/// The largest magnitudes an identified value may have.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct ValueLimits {
    /// Translational errors and sensor offsets, mm.
    pub translation_mm: f64,
    /// Angular errors, rad.
    pub angle_rad: f64,
    /// Servo lags of `velocity` terms, ms.
    pub lag_ms: f64,
    /// Instrument terms (dimensionless).
    pub instrument: f64,
}

impl Default for ValueLimits {
    /// 1 mm, 10 mrad, 1000 ms and 0.5.
    fn default() -> Self {
        ValueLimits {
            translation_mm: 1.0,
            angle_rad: 0.01,
            lag_ms: 1000.0,
            instrument: 0.5,
        }
    }
}

impl ValueLimits {
    /// The defaults.
    pub fn new() -> ValueLimits {
        ValueLimits::default()
    }

    /// With the translational bound `um` (µm) and the angular bound `urad` (µrad); the
    /// default bounds of lags and instrument terms.
    pub fn from_display(um: f64, urad: f64) -> ValueLimits {
        ValueLimits {
            translation_mm: um / UM_PER_MM,
            angle_rad: urad / URAD_PER_RAD,
            ..ValueLimits::default()
        }
    }
}

/// Identified values beyond the bounds.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error(
    "{} beyond the plausibility bounds ({} µm, {} µrad{}): {}",
    if .values.len() == 1 { "a value is" } else { "values are" },
    short(.limits.translation_mm * UM_PER_MM),
    short(.limits.angle_rad * URAD_PER_RAD),
    other_bounds(.values, .limits),
    .values.iter().map(|(n, v, u)| format!("{n} = {} {u}", short(*v))).collect::<Vec<_>>().join(", ")
)]
pub struct Implausible {
    /// The offending parameters: name, value in µm, µrad, ms or 1, unit symbol.
    pub values: Vec<(String, f64, &'static str)>,
    /// The bounds.
    pub limits: ValueLimits,
}

/// The bounds of lags and instrument terms, when an offending value is one (`, 1000 ms`).
fn other_bounds(values: &[(String, f64, &'static str)], limits: &ValueLimits) -> String {
    let mut s = String::new();
    if values.iter().any(|v| v.2 == "ms") {
        s += &format!(", {} ms", short(limits.lag_ms));
    }
    if values.iter().any(|v| v.2 == "1") {
        s += &format!(", {} for instrument terms", short(limits.instrument));
    }
    if values.iter().any(|v| v.2.ends_with("/s")) {
        s += ", the same per s for rates";
    }
    s
}

/// Checks the values (`None`: undetermined, not checked) of `model`'s columns against `limits`.
///
/// # Errors
/// [`Implausible`] naming every offending parameter.
pub fn check_model_values(
    m: &Machine,
    model: &Model,
    names: &[String],
    values: &[Option<f64>],
    limits: &ValueLimits,
) -> Result<(), Implausible> {
    let mut bad = Vec::new();
    for (j, (t, _)) in model.columns().into_iter().enumerate() {
        let Some(v) = values.get(j).copied().flatten() else {
            continue;
        };
        let term = model.terms[t];
        let bound = if term.basis == Basis::Velocity {
            limits.lag_ms
        } else if matches!(term.effect, Effect::Instrument { .. }) {
            limits.instrument
        } else if term.effect.is_angular(m) {
            limits.angle_rad
        } else {
            limits.translation_mm
        };
        // A NaN is beyond every bound.
        if v.abs() > bound || v.is_nan() {
            let unit = model_spec::units::symbol(term.unit(m));
            bad.push((names[j].clone(), v * term.display_factor(m), unit));
        }
    }
    if bad.is_empty() {
        Ok(())
    } else {
        Err(Implausible {
            values: bad,
            limits: *limits,
        })
    }
}

/// Checks the values of an identification against `limits`.
///
/// # Errors
/// [`Implausible`] naming every offending parameter.
pub fn check_values(
    m: &Machine,
    ident: &Identification,
    limits: &ValueLimits,
) -> Result<(), Implausible> {
    check_model_values(m, &ident.model, &ident.fit.names, &ident.fit.values, limits)
}
