//! The identification report (`rtest identify --json`).
//!
//! ```json
//! {"machine": "seed-ac", "fingerprint": "fa038fe9e24c960a", "model": "reduced", "base_model": "reduced",
//!  "terms": ["XOW", …, "BOC"],
//!  "parameters": [{"name": "XOC", "error": "XOC", "basis": "const", "value": 12.3, "std": 0.05,
//!                  "unit": "um", "determined": true, "fixed": false}, …],
//!  "residual_rms_um": 0.49, "rank": 11, "condition": 4.2, "confounded": [["XOC", "dx0"]], …,
//!  "refinement": {"method": "exact", "iterations": 3, "converged": true, …}, "notes": […]}
//! ```
//! `noise_model` says which noise the uncertainties assume: `{"source": "estimated",
//! "sigma_um": [0.3, 0.3, 0.3], "phi": [0.8, 0.8, 0.8], "whitened_sigma": 1.02, "text": …}`
//! (`source`: `declared`, `static-record`, `estimated`, or `residual`, white with the σ̂ of an
//! ordinary fit).
//! `value` and `std` are `null` where the data do not determine the parameter; `basis` is
//! `const`, `harmonic:K:cos`, `harmonic:K:sin`, `poly:K`, `reversal` or `time:K`; `unit` is
//! `um` (translational errors, sensor offsets, changes of kinematic offsets) or `urad` (angular
//! errors). A kinematic offset (`"error": "Zt"`, a symbol of the description) also has
//! `nominal_mm`, the symbol's value its change `value` is from, and `identified_mm`, the
//! identified length (`null` when the change is not determined). Readers of the values
//! need `machine`, `fingerprint`, `model`, `base_model`, `terms` and `parameters`
//! ([`super::read`]).

use super::{NonFinite, finite, finite_opt};
use crate::fitting::hmatrix::Backend;
use crate::fitting::identifiability::Swallowed;
use crate::fitting::refine::Refinement;
use crate::fitting::{Constraint, Identification};
use model_spec::Machine;
use model_spec::units::UM_PER_MM;
use serde::{Deserialize, Serialize};

/// One parameter (H-matrix column) of an identification, in its term's unit
/// ([`crate::model::Term::unit`]): µm, µrad, ms (`velocity`) or 1 (instrument terms).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParameterReport {
    /// The parameter's name (`XOC`, `ECC@harmonic:2:cos`, `dx0`).
    pub name: String,
    /// Effect name (`XOC`, `dx0`).
    pub error: String,
    /// Basis column (`const`, `harmonic:2:cos`, `reversal`, …).
    pub basis: String,
    /// Estimate, in `unit`; `null` when the data do not determine it (and no constraint gives
    /// it a value).
    pub value: Option<f64>,
    /// Standard uncertainty, in `unit`; `null` when undetermined, fixed, or without a degree
    /// of freedom.
    pub std: Option<f64>,
    /// `um`, `urad`, `ms` (the lag of a `velocity` term) or `1` (an instrument term).
    pub unit: String,
    /// Whether the data determine it (fixed parameters count as determined).
    pub determined: bool,
    /// Fixed to 0 by the constraint.
    pub fixed: bool,
    /// For a `poly:K` column: the stroke of its axis the polynomial is normalised over, mm
    /// (the value means something only over the same stroke); absent for other bases.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub over_mm: Option<[f64; 2]>,
    /// For a kinematic offset (`error` a symbol of the description): the symbol's value the
    /// records were modelled with, mm, from which `value` (µm) is the change; absent for other
    /// parameters.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nominal_mm: Option<f64>,
    /// For a kinematic offset: the identified value of the symbol, `nominal_mm + value`, mm;
    /// `null` when the change is not determined; absent for other parameters.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        with = "present_or_null"
    )]
    pub identified_mm: Option<Option<f64>>,
}

/// An optional field whose value may be `null`: absent (`None`), `null` (`Some(None)`) or a
/// number (`Some(Some(x))`).
mod present_or_null {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(v: &Option<Option<f64>>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            Some(x) => x.serialize(s),
            None => s.serialize_none(),
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Option<f64>>, D::Error> {
        Option::<f64>::deserialize(d).map(Some)
    }
}

/// A pair of determined parameters with a high correlation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NearPairReport {
    /// The two parameter names.
    pub parameters: [String; 2],
    /// Correlation of their estimates, in [−1, 1].
    pub correlation: f64,
}

/// What the refinement against the exact machine did.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RefinementReport {
    /// `exact` (refined against the exact machine) or `first-order` (not refined).
    pub method: String,
    /// Gauss–Newton steps taken (0 for `first-order`).
    pub iterations: usize,
    /// Whether the last step was below the tolerance (always `true` for `first-order`, whose
    /// linear solution is exact). An identification that did not converge is not a result:
    /// `rtest identify` refuses it (exit code 3) and writes no file.
    pub converged: bool,
    /// Per step, the largest change of the prediction at any reading, µm.
    pub steps_um: Vec<f64>,
    /// The tolerance the steps were compared with, µm (1e-9 µm, or the rounding floor of an
    /// ill-conditioned fit when larger); absent for `first-order`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance_um: Option<f64>,
    /// Residual RMS of the first-order fit, µm.
    pub first_order_rms_um: f64,
}

/// The noise model the uncertainties assume ([`crate::fitting::noise::NoiseModel`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NoiseModelReport {
    /// `declared`, `static-record`, `estimated`, or `residual` (white with the σ̂ of an
    /// ordinary fit: ordinary least squares).
    pub source: String,
    /// Marginal standard deviation of a reading per direction x, y, z, µm.
    pub sigma_um: [f64; 3],
    /// Lag-1 autocorrelation per direction x, y, z (0: white).
    pub phi: [f64; 3],
    /// σ̂ of the whitened residual (unitless, about 1 when the model's σ is right); `null` for
    /// an ordinary fit or without degrees of freedom.
    pub whitened_sigma: Option<f64>,
    /// The model for people, with where it came from.
    pub text: String,
}

/// How a record was read in blocks and folded into an incremental QR decomposition.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StreamingReport {
    /// Blocks read.
    pub blocks: usize,
    /// Samples per block asked for.
    pub block: usize,
    /// Samples of the first block (it reads ahead until every axis has moved).
    pub first_block: usize,
}

/// A group of sensor offsets and the errors they cannot be told from (zeroed readings).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SwallowedReport {
    /// The offsets (`dx0`).
    pub offsets: Vec<String>,
    /// The errors (`XOC`); empty when the offsets are confounded with each other only.
    pub errors: Vec<String>,
}

/// The identification report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IdentificationReport {
    /// Machine name.
    pub machine: String,
    /// The machine's fingerprint (topology and machine-side kinematic defaults): values are
    /// applied only to a machine with the same fingerprint.
    pub fingerprint: String,
    /// The measurement file fitted.
    pub data: String,
    /// The model's label (`reduced`, `reduced + ECC@harmonic:2`, `XOC + EXX@poly:1`).
    pub model: String,
    /// The machine's model it starts from (`--model`); absent when the model is a list of
    /// terms only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_model: Option<String>,
    /// The terms fitted, in order (`XOC`, `ECC@harmonic:2`, `dx0`), offsets of zeroed readings
    /// included.
    pub terms: Vec<String>,
    /// Every parameter (H column), in model order.
    pub parameters: Vec<ParameterReport>,
    /// `√(RSS / 3N)`, µm.
    pub residual_rms_um: f64,
    /// Numerical rank of the column-scaled H.
    pub rank: usize,
    /// Free parameters (not fixed by the constraint).
    pub free_parameters: usize,
    /// Condition number of the scaled H over the identifiable part; `null` when the rank is 0.
    pub condition: Option<f64>,
    /// Groups of parameters the data cannot separate (parameter names).
    pub confounded: Vec<Vec<String>>,
    /// Number of samples fitted.
    pub samples: usize,
    /// Readings fitted (3 per sample).
    pub readings: usize,
    /// Degrees of freedom `3N − rank`.
    pub dof: usize,
    /// Whether the readings were zeroed at the first sample (then `dx0 dy0 dz0` were fitted).
    pub zeroed: bool,
    /// `none`, `minimum-norm` or `zero: NAME, …`.
    pub constraint: String,
    /// σ̂ = √(RSS / (3N − rank)), µm; `null` without degrees of freedom.
    pub sigma_um: Option<f64>,
    /// Determined pairs with |correlation| > 0.99.
    pub near_confounded: Vec<NearPairReport>,
    /// What the sensor offsets swallow (zeroed readings).
    pub swallowed: Vec<SwallowedReport>,
    /// `compiled`, `evaluator` or `mixed`: the code that computed the gains.
    pub gains: String,
    /// The refinement against the exact machine.
    pub refinement: RefinementReport,
    /// The noise model the uncertainties assume; absent in reports written before noise models
    /// existed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise_model: Option<NoiseModelReport>,
    /// How a long record was read in blocks (`--stream`); absent when it was read whole.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub streaming: Option<StreamingReport>,
    /// Statements for people (what was swallowed, what has no value and why, non-convergence).
    pub notes: Vec<String>,
}

/// The stroke (mm) a `poly:K` term's polynomial is normalised over: its axis's; `None` for
/// other bases.
pub fn poly_stroke(m: &Machine, term: &crate::model::Term) -> Option<[f64; 2]> {
    match (term.basis, term.effect.carrier(m)) {
        (crate::model::Basis::Poly(_), crate::model::Carrier::Axis(a)) => Some(m.axes[a].limits),
        _ => None,
    }
}

/// The text of a constraint, as the report writes it.
pub fn constraint_text(c: &Constraint) -> String {
    match c {
        Constraint::None => "none".into(),
        Constraint::MinimumNorm => "minimum-norm".into(),
        Constraint::Zero(names) => format!("zero: {}", names.join(", ")),
    }
}

/// The name of a gain backend in reports.
pub fn backend_name(b: Backend) -> &'static str {
    match b {
        Backend::Compiled => "compiled",
        Backend::Evaluator => "evaluator",
        Backend::Mixed => "mixed",
    }
}

/// What an identification report says besides the identification.
#[derive(Clone, Copy, Debug)]
pub struct IdentificationSource<'a> {
    /// The measurement file fitted.
    pub data: &'a str,
    /// The model's label.
    pub label: &'a str,
    /// The machine's model it starts from (`--model`), if any.
    pub base_model: Option<&'a str>,
}

impl IdentificationReport {
    /// The report of `ident` on machine `m`, refined as `refinement` says (`None`: first
    /// order).
    ///
    /// # Errors
    /// [`NonFinite`] when a value, uncertainty or statistic is not finite.
    pub fn new(
        m: &Machine,
        source: IdentificationSource,
        ident: &Identification,
        refinement: Option<&Refinement>,
    ) -> Result<IdentificationReport, NonFinite> {
        let fit = &ident.fit;
        let mut parameters = Vec::with_capacity(fit.names.len());
        for (j, (t, k)) in ident.model.columns().into_iter().enumerate() {
            let nominal = ident.nominal_mm.get(j).copied().flatten();
            parameters.push(parameter_report(
                m,
                &ident.model.terms[t],
                k,
                fit,
                j,
                nominal,
            )?);
        }
        let refinement = refinement_report(refinement, fit)?;
        let mut report = fit_report(fit)?;
        report.notes = notes(fit, &ident.swallowed, &refinement);
        Ok(IdentificationReport {
            machine: m.name.clone(),
            fingerprint: m.fingerprint(),
            data: source.data.to_string(),
            model: source.label.to_string(),
            base_model: source.base_model.map(str::to_string),
            terms: ident.model.terms.iter().map(|t| t.spelling(m)).collect(),
            parameters,
            residual_rms_um: report.residual_rms_um,
            rank: report.rank,
            free_parameters: report.free_parameters,
            condition: report.condition,
            confounded: report.confounded,
            samples: ident.samples,
            readings: report.readings,
            dof: report.dof,
            zeroed: ident.zeroed,
            constraint: report.constraint,
            sigma_um: report.sigma_um,
            near_confounded: report.near_confounded,
            swallowed: FitSummary::swallowed_of(&ident.swallowed),
            gains: backend_name(ident.backend).into(),
            notes: report.notes,
            refinement,
            noise_model: Some(noise_report(&ident.noise, ident.whitened_sigma)?),
            streaming: None,
        })
    }
}

/// The report of column `j` of `fit`, the component `k` of `term` (in the term's unit);
/// `nominal` (mm) is the value a kinematic offset's change is relative to (`None` for other
/// terms).
///
/// # Errors
/// [`NonFinite`] for a value or uncertainty that is not finite.
pub(crate) fn parameter_report(
    m: &Machine,
    term: &crate::model::Term,
    k: usize,
    fit: &crate::fitting::Fit,
    j: usize,
    nominal: Option<f64>,
) -> Result<ParameterReport, NonFinite> {
    let f = term.display_factor(m);
    let names = term.basis.column_names();
    let field = |what: &str| format!("parameters[{j}].{what}");
    let nominal = match term.effect.symbol() {
        Some(_) => finite_opt(|| field("nominal_mm"), nominal)?,
        None => None,
    };
    let identified_mm = match nominal {
        Some(n) => Some(finite_opt(
            || field("identified_mm"),
            fit.values[j].map(|v| n + v),
        )?),
        None => None,
    };
    Ok(ParameterReport {
        name: fit.names[j].clone(),
        error: term.effect.name(m),
        basis: names.get(k).unwrap_or(&names[0]).clone(),
        value: finite_opt(|| field("value"), fit.values[j].map(|v| v * f))?,
        std: finite_opt(|| field("std"), fit.std[j].map(|v| v * f))?,
        unit: term.unit(m).to_string(),
        determined: fit.identifiability.determined[j],
        fixed: fit.fixed[j],
        over_mm: poly_stroke(m, term),
        nominal_mm: nominal,
        identified_mm,
    })
}

/// What every fit report says of its fit, in report units (the fields of
/// [`IdentificationReport`] of the same names).
pub(crate) struct FitSummary {
    /// `√(RSS / 3N)`, µm.
    pub residual_rms_um: f64,
    /// Numerical rank.
    pub rank: usize,
    /// Free parameters.
    pub free_parameters: usize,
    /// Condition number.
    pub condition: Option<f64>,
    /// Confounded groups, by name.
    pub confounded: Vec<Vec<String>>,
    /// Readings fitted.
    pub readings: usize,
    /// Degrees of freedom.
    pub dof: usize,
    /// The constraint's text.
    pub constraint: String,
    /// σ̂, µm.
    pub sigma_um: Option<f64>,
    /// Near-confounded pairs.
    pub near_confounded: Vec<NearPairReport>,
    /// Statements for people.
    pub notes: Vec<String>,
}

impl FitSummary {
    /// The swallowed groups as reported.
    pub(crate) fn swallowed_of(swallowed: &[Swallowed]) -> Vec<SwallowedReport> {
        swallowed
            .iter()
            .map(|s: &Swallowed| SwallowedReport {
                offsets: s.offsets.clone(),
                errors: s.errors.clone(),
            })
            .collect()
    }
}

/// The summary of `fit` (notes left empty).
///
/// # Errors
/// [`NonFinite`] for a statistic that is not finite.
pub(crate) fn fit_report(fit: &crate::fitting::Fit) -> Result<FitSummary, NonFinite> {
    let id = &fit.identifiability;
    let name = |j: usize| fit.names[j].clone();
    Ok(FitSummary {
        residual_rms_um: finite(|| "residual_rms_um".into(), fit.residual_rms() * UM_PER_MM)?,
        rank: fit.rank,
        free_parameters: fit.fixed.iter().filter(|f| !**f).count(),
        condition: finite_opt(|| "condition".into(), fit.condition)?,
        confounded: id
            .confounded
            .iter()
            .map(|g| g.iter().map(|&j| name(j)).collect())
            .collect(),
        readings: fit.rows(),
        dof: fit.dof,
        constraint: constraint_text(&fit.constraint),
        sigma_um: finite_opt(|| "sigma_um".into(), fit.sigma.map(|s| s * UM_PER_MM))?,
        near_confounded: id
            .near_confounded
            .iter()
            .map(|p| {
                Ok(NearPairReport {
                    parameters: [name(p.a), name(p.b)],
                    correlation: finite(|| "near_confounded.correlation".into(), p.correlation)?,
                })
            })
            .collect::<Result<_, NonFinite>>()?,
        notes: Vec::new(),
    })
}

/// The refinement as reported: refined as `refinement` says, or first order (`None`).
///
/// # Errors
/// [`NonFinite`] for a step or RMS that is not finite.
pub(crate) fn refinement_report(
    refinement: Option<&Refinement>,
    fit: &crate::fitting::Fit,
) -> Result<RefinementReport, NonFinite> {
    Ok(match refinement {
        Some(r) => RefinementReport {
            method: "exact".into(),
            iterations: r.iterations,
            converged: r.converged,
            steps_um: r
                .steps_mm
                .iter()
                .enumerate()
                .map(|(i, s)| finite(|| format!("refinement.steps_um[{i}]"), s * UM_PER_MM))
                .collect::<Result<_, _>>()?,
            tolerance_um: Some(finite(
                || "refinement.tolerance_um".into(),
                r.tolerance_mm * UM_PER_MM,
            )?),
            first_order_rms_um: finite(
                || "refinement.first_order_rms_um".into(),
                r.rms_mm.0 * UM_PER_MM,
            )?,
        },
        None => RefinementReport {
            method: "first-order".into(),
            iterations: 0,
            converged: true,
            steps_um: Vec::new(),
            tolerance_um: None,
            first_order_rms_um: finite(
                || "refinement.first_order_rms_um".into(),
                fit.residual_rms() * UM_PER_MM,
            )?,
        },
    })
}

/// The noise model `n` in µm, with the σ̂ of the whitened residual `whitened`.
///
/// # Errors
/// [`NonFinite`] for a σ that is not finite.
pub(crate) fn noise_report(
    n: &crate::fitting::noise::NoiseModel,
    whitened: Option<f64>,
) -> Result<NoiseModelReport, NonFinite> {
    let mut sigma_um = [0.0; 3];
    for (d, s) in sigma_um.iter_mut().enumerate() {
        *s = finite(
            || format!("noise_model.sigma_um[{d}]"),
            n.sigma_mm[d] * UM_PER_MM,
        )?;
    }
    Ok(NoiseModelReport {
        source: n.source.keyword().into(),
        sigma_um,
        phi: n.phi,
        whitened_sigma: finite_opt(|| "noise_model.whitened_sigma".into(), whitened)?,
        text: n.to_string(),
    })
}

/// The statements for people: what the offsets swallow, what has no value, no uncertainty,
/// no convergence.
pub(crate) fn notes(
    fit: &crate::fitting::Fit,
    swallowed: &[Swallowed],
    refinement: &RefinementReport,
) -> Vec<String> {
    let id = &fit.identifiability;
    let mut notes = Vec::new();
    if !refinement.converged {
        notes.push(format!(
            "the refinement against the exact machine did not converge in {} steps (last step {} µm): these values are not an identification",
            refinement.iterations,
            refinement.steps_um.last().map_or("?".into(), |s| format!("{s:.3e}"))
        ));
    }
    for s in swallowed {
        notes.push(format!(
            "zeroed readings: the sensor offset{} {} cannot be told from {} (constant gains)",
            if s.offsets.len() > 1 { "s" } else { "" },
            s.offsets.join(", "),
            if s.errors.is_empty() {
                "each other".to_string()
            } else {
                s.errors.join(", ")
            }
        ));
    }
    let undetermined: Vec<&str> = (0..fit.names.len())
        .filter(|&j| !id.determined[j])
        .map(|j| fit.names[j].as_str())
        .collect();
    if !undetermined.is_empty() {
        notes.push(match fit.constraint {
            Constraint::MinimumNorm => format!(
                "{} are not determined by the data; their values are the minimum-norm (scaled) solution, not measurements",
                undetermined.join(", ")
            ),
            _ => format!(
                "no value for {}: the data cannot determine them (see `confounded`)",
                undetermined.join(", ")
            ),
        });
    }
    if fit.sigma.is_none() {
        notes.push("no degree of freedom left (3N = rank): no uncertainties".into());
    }
    notes
}
