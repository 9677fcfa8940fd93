//! The re-check part of a validation report (`rtest validate --refit NAMES`): the machine
//! parameters refitted (the pivot) beside the calibration's values, their changes and how the
//! uncertainties are scaled. The preset (each record's new set-up errors) is in the records'
//! `refitted` lists, as a validation's.
//!
//! ```json
//! "recheck": {"refit": ["XOB", "ZOB"], "dof": 7, "scale": "declared", "whitened_sigma": 0.93,
//!             "chi2_upper_tail": 0.48,
//!             "pivot": [{"name": "XOB", "unit": "um", "calibrated": -14.02,
//!                        "calibrated_std": 0.21, "value": -2.11, "std": 0.38,
//!                        "change": 11.91, "change_z": 27.3}]}
//! ```
//!
//! `scale` is `declared` (the instrument's covariances, unrefuted: `whitened_sigma` about 1),
//! `refuted` (the χ² upper tail of the whitened residual below 1 %: the uncertainties keep the
//! residual's scale) or `residual` (readings without covariances). `change` is the re-check's
//! value minus the calibration's, `change_z` that over `√(std² + calibrated_std²)`; both are
//! `null` where either value is.

use super::{NonFinite, finite, finite_opt};
use fitting::campaign::{Recheck, RecheckScale};
use model_spec::Machine;
use serde::{Deserialize, Serialize};

/// A machine parameter the re-check refitted, in its unit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PivotReport {
    /// Its name (`XOB`).
    pub name: String,
    /// `um` or `urad`.
    pub unit: String,
    /// The calibration's value; `null` where it did not determine it.
    pub calibrated: Option<f64>,
    /// The calibration's standard uncertainty.
    pub calibrated_std: Option<f64>,
    /// The re-check's value; `null` where its poses cannot separate it.
    pub value: Option<f64>,
    /// Its standard uncertainty.
    pub std: Option<f64>,
    /// `value − calibrated`.
    pub change: Option<f64>,
    /// `change / √(std² + calibrated_std²)`.
    pub change_z: Option<f64>,
}

/// The re-check of a validation report (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RecheckReport {
    /// The names asked to be refitted, as given.
    pub refit: Vec<String>,
    /// Degrees of freedom of the refit.
    pub dof: usize,
    /// `declared`, `refuted` or `residual`.
    pub scale: String,
    /// σ̂ of the whitened residual (readings with covariances).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub whitened_sigma: Option<f64>,
    /// Its χ² upper tail.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chi2_upper_tail: Option<f64>,
    /// σ̂ of the residual, µm (readings without covariances).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sigma_um: Option<f64>,
    /// The machine parameters refitted.
    pub pivot: Vec<PivotReport>,
}

impl RecheckReport {
    /// The report of `r` on machine `m`, `refit` the names as asked.
    ///
    /// # Errors
    /// [`NonFinite`] when a value is not finite.
    pub fn new(m: &Machine, refit: &[String], r: &Recheck) -> Result<RecheckReport, NonFinite> {
        let mut pivot = Vec::with_capacity(r.pivot.len());
        for (k, p) in r.pivot.iter().enumerate() {
            let f = p.term.display_factor(m);
            let at = |what: &str| format!("recheck.pivot[{k}].{what}");
            let scaled = |what: &str, x: Option<f64>| finite_opt(|| at(what), x.map(|x| x * f));
            let calibrated = scaled("calibrated", p.calibrated)?;
            let calibrated_std = scaled("calibrated_std", p.calibrated_std)?;
            let value = scaled("value", p.value)?;
            let std = scaled("std", p.std)?;
            let change = match (value, calibrated) {
                (Some(v), Some(c)) => Some(finite(|| at("change"), v - c)?),
                _ => None,
            };
            let change_z = match (change, std, calibrated_std) {
                (Some(d), Some(s), Some(c)) if s > 0.0 || c > 0.0 => {
                    Some(finite(|| at("change_z"), d / s.hypot(c))?)
                }
                _ => None,
            };
            pivot.push(PivotReport {
                name: p.name.clone(),
                unit: p.term.unit(m).to_string(),
                calibrated,
                calibrated_std,
                value,
                std,
                change,
                change_z,
            });
        }
        let (scale, whitened_sigma, chi2_upper_tail, sigma_um) = match r.scale {
            RecheckScale::Declared { ratio, p } => ("declared", Some(ratio), Some(p), None),
            RecheckScale::Refuted { ratio, p } => ("refuted", Some(ratio), Some(p), None),
            RecheckScale::Residual(s) => (
                "residual",
                None,
                None,
                s.map(|s| s * model_spec::units::UM_PER_MM),
            ),
        };
        Ok(RecheckReport {
            refit: refit.to_vec(),
            dof: r.dof,
            scale: scale.into(),
            whitened_sigma: finite_opt(|| "recheck.whitened_sigma".into(), whitened_sigma)?,
            chi2_upper_tail: finite_opt(|| "recheck.chi2_upper_tail".into(), chi2_upper_tail)?,
            sigma_um: finite_opt(|| "recheck.sigma_um".into(), sigma_um)?,
            pivot,
        })
    }

    /// The noise model in words, for people and the history.
    pub fn scale_text(&self) -> String {
        match (
            self.scale.as_str(),
            self.whitened_sigma,
            self.chi2_upper_tail,
        ) {
            ("declared", Some(w), Some(p)) => format!(
                "the instrument's declared covariances (σ̂ of the whitened residual {w:.3}, χ² upper tail {p:.2})"
            ),
            ("refuted", Some(w), Some(p)) => format!(
                "the residual's scale: the instrument's declared σ is refuted (σ̂ of the whitened residual {w:.3}, χ² upper tail {p:.1e} < 0.01)"
            ),
            _ => match self.sigma_um {
                Some(s) => format!("the residual's scale (σ̂ {s:.3} µm)"),
                None => "the residual's scale (no degree of freedom)".into(),
            },
        }
    }
}

/// The calibration's identification report `calibration` (its JSON text; `file` names it in
/// messages) with the re-check's pivot in place of its values: each machine parameter of
/// `recheck.pivot` that the re-check determined gets the re-checked `value` and `std`, and the
/// report gains `"rechecked": {"calibration": FILE, "data": [...], "refit": [...],
/// "changed": [...]}` saying what changed and from which records. Everything else, its fit
/// statistics among them, stays the calibration's: `rtest compensate` takes the file as it
/// takes any identification. A parameter the re-check did not determine keeps the calibration's
/// value and is not listed in `changed`.
///
/// # Errors
/// A text that is not an identification report's JSON, or a pivot parameter it does not list
/// as a machine parameter.
pub fn updated_identification(
    file: &str,
    calibration: &str,
    recheck: &RecheckReport,
    data: &[String],
) -> Result<String, String> {
    let mut json: serde_json::Value =
        serde_json::from_str(calibration).map_err(|e| format!("{file}: {e}"))?;
    let parameters = json
        .get_mut("parameters")
        .and_then(serde_json::Value::as_array_mut)
        .ok_or_else(|| format!("{file}: no `parameters` list"))?;
    let mut changed = Vec::new();
    for p in &recheck.pivot {
        let (Some(value), Some(std)) = (p.value, p.std) else {
            continue;
        };
        let entry = parameters
            .iter_mut()
            .find(|q| {
                q.get("name").and_then(serde_json::Value::as_str) == Some(p.name.as_str())
                    && q.get("owner")
                        .and_then(serde_json::Value::as_str)
                        .is_none_or(|o| o == "shared")
            })
            .ok_or_else(|| format!("{file}: no machine parameter `{}`", p.name))?;
        entry["value"] = serde_json::json!(value);
        entry["std"] = serde_json::json!(std);
        entry["determined"] = serde_json::json!(true);
        changed.push(p.name.clone());
    }
    json["rechecked"] = serde_json::json!({
        "calibration": file,
        "data": data,
        "refit": recheck.refit,
        "changed": changed,
    });
    serde_json::to_string_pretty(&json).map_err(|e| format!("{file}: {e}"))
}
