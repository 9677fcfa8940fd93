//! What every identification report says of its fit, in report units: the summary statistics,
//! the refinement, the noise model, one parameter's row and the notes for people. Shared by
//! [`super::identify`] (the identification report) and [`super::plan`] (what a plan will
//! determine); names are given by the caller, so that a record's report names its columns
//! `XOW` and a campaign's `XOW[k4]`.

use super::identify::{NearPairReport, NoiseModelReport, ParameterReport, RefinementReport};
use super::{NonFinite, finite, finite_opt};
use fitting::Constraint;
use fitting::refine::Refinement;
use model_spec::Machine;
use model_spec::units::UM_PER_MM;

/// The stroke (mm) a `poly:K` term's polynomial is normalised over: its axis's; `None` for
/// other bases.
pub fn poly_stroke(m: &Machine, term: &simulation::model::Term) -> Option<[f64; 2]> {
    match (term.basis, term.effect.carrier(m)) {
        (simulation::model::Basis::Poly(_), simulation::model::Carrier::Axis(a)) => {
            Some(m.axes[a].limits)
        }
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

/// The report of column `j` of `fit`, named `name`, the component `k` of `term` (in the term's
/// unit); `nominal` (mm) is the value a kinematic offset's change is relative to (`None` for
/// other terms); `owner` and `of` as a campaign report writes them (`None` in a record's).
///
/// # Errors
/// [`NonFinite`] for a value or uncertainty that is not finite.
#[allow(clippy::too_many_arguments)]
pub(crate) fn parameter_report(
    m: &Machine,
    term: &simulation::model::Term,
    k: usize,
    fit: &fitting::Fit,
    j: usize,
    name: String,
    nominal: Option<f64>,
    owner: Option<(&str, Option<&str>)>,
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
        owner: owner.map(|(o, _)| o.to_string()),
        of: owner.and_then(|(_, of)| of.map(str::to_string)),
        name,
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

/// What every fit report says of its fit, in report units.
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
}

/// The summary of `fit`, its columns named `names`.
///
/// # Errors
/// [`NonFinite`] for a statistic that is not finite.
pub(crate) fn fit_report(fit: &fitting::Fit, names: &[String]) -> Result<FitSummary, NonFinite> {
    let id = &fit.identifiability;
    let name = |j: usize| names[j].clone();
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
    })
}

/// The refinement as reported: refined as `refinement` says, or first order (`None`).
///
/// # Errors
/// [`NonFinite`] for a step or RMS that is not finite.
pub(crate) fn refinement_report(
    refinement: Option<&Refinement>,
    fit: &fitting::Fit,
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
    n: &fitting::noise::NoiseModel,
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

/// The statements for people: what the offsets swallow (`swallowed`: offsets and errors, by
/// name), what has no value, no uncertainty, no convergence; `names` name the fit's columns.
pub(crate) fn notes(
    fit: &fitting::Fit,
    names: &[String],
    swallowed: &[(Vec<String>, Vec<String>)],
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
    for (offsets, errors) in swallowed {
        notes.push(format!(
            "zeroed readings: the sensor offset{} {} cannot be told from {} (constant gains)",
            if offsets.len() > 1 { "s" } else { "" },
            offsets.join(", "),
            if errors.is_empty() {
                "each other".to_string()
            } else {
                errors.join(", ")
            }
        ));
    }
    let undetermined: Vec<&str> = (0..names.len())
        .filter(|&j| !id.determined[j])
        .map(|j| names[j].as_str())
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
