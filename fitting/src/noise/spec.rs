//! Declared noise: `white:sigma=S` or `ar1:phi=F,sigma=S` (S in µm, F the lag-1
//! autocorrelation).

use super::{MAX_PHI, NoiseChoice, NoiseError, NoiseModel, NoiseSource};
use model_spec::units::parse_scaled;

/// The largest declared σ, µm: the largest reading noise a truth may have.
const MAX_SIGMA_UM: f64 = simulation::truth::MAX_NOISE_UM;

impl NoiseModel {
    /// A declared noise model: `white:sigma=S` or `ar1:phi=F,sigma=S`, S the marginal standard
    /// deviation of a reading in µm (0 < S ≤ 1000), F the lag-1 autocorrelation
    /// (0 ≤ F < 0.99), the same for the three directions; keys in any order, spaces allowed
    /// around them.
    ///
    /// # Errors
    /// [`NoiseError::Spec`] saying what is wrong (unknown kind or key, a key missing or given
    /// twice, a number that is not one or is out of range).
    pub fn parse(spec: &str) -> Result<NoiseModel, NoiseError> {
        let bad = |why: String| NoiseError::Spec {
            spec: spec.to_string(),
            why,
        };
        let (kind, rest) = spec.trim().split_once(':').unwrap_or((spec.trim(), ""));
        let kind = kind.trim();
        let allowed: &[&str] = match kind {
            "white" => &["sigma"],
            "ar1" => &["phi", "sigma"],
            other => return Err(bad(format!("unknown kind `{other}` (white or ar1)"))),
        };
        let mut sigma: Option<f64> = None;
        let mut phi: Option<f64> = None;
        let parts = rest.split(',').filter(|_| !rest.trim().is_empty());
        for part in parts {
            let (key, value) = part
                .split_once('=')
                .ok_or_else(|| bad(format!("`{}` is not KEY=VALUE", part.trim())))?;
            let (key, value) = (key.trim(), value.trim());
            if !allowed.contains(&key) {
                return Err(bad(format!(
                    "unknown key `{key}` for {kind} (keys: {})",
                    allowed.join(", ")
                )));
            }
            let x: f64 = value
                .parse()
                .ok()
                .filter(|x: &f64| x.is_finite())
                .ok_or_else(|| bad(format!("{key} = `{value}` is not a finite number")))?;
            let slot = if key == "sigma" { &mut sigma } else { &mut phi };
            if slot.is_some() {
                return Err(bad(format!("{key} is given twice")));
            }
            *slot = Some(match key {
                "sigma" => {
                    if !(x > 0.0 && x <= MAX_SIGMA_UM) {
                        return Err(bad(format!(
                            "sigma = {value} µm must be above 0 and at most {MAX_SIGMA_UM} µm"
                        )));
                    }
                    parse_scaled(value, -3)
                        .filter(|s| s.is_finite() && *s > 0.0)
                        .ok_or_else(|| {
                            bad(format!(
                                "sigma = `{value}` is not a plain decimal number (µm)"
                            ))
                        })?
                }
                _ => {
                    if !(0.0..MAX_PHI).contains(&x) {
                        return Err(bad(format!(
                            "phi = {value} must be at least 0 and below {MAX_PHI}"
                        )));
                    }
                    x
                }
            });
        }
        let sigma = sigma.ok_or_else(|| bad("sigma is missing".into()))?;
        let phi = match kind {
            "ar1" => phi.ok_or_else(|| bad("phi is missing".into()))?,
            _ => 0.0,
        };
        Ok(NoiseModel::ar1(phi, sigma, NoiseSource::Declared))
    }
}

impl NoiseChoice {
    /// A noise choice from text: `white` (ordinary least squares, σ from the residual),
    /// `estimate` (estimated from the residual), or a declared model ([`NoiseModel::parse`]).
    ///
    /// # Errors
    /// As [`NoiseModel::parse`].
    pub fn parse(spec: &str) -> Result<NoiseChoice, NoiseError> {
        match spec.trim() {
            "white" => Ok(NoiseChoice::Ordinary),
            "estimate" => Ok(NoiseChoice::Estimate),
            _ => NoiseModel::parse(spec).map(NoiseChoice::Model),
        }
    }
}
