//! Whether the extended model is recommended, and why (not).
//!
//! The extended model (the base model plus the plausible findings) is recommended only when
//! all of these hold:
//! 1. there is at least one plausible finding;
//! 2. there is at least one held-out record whose predictions use only what the fits
//!    determined ([`super::heldout`]): without one the gain cannot be checked;
//! 3. no such held-out record is predicted worse than by the base model;
//! 4. the residual moves toward the noise: the RMS pooled over those records (weighted by
//!    their readings) falls, and either the lack-of-fit test finds what remains consistent with
//!    the noise, or on every such record the excess of the RMS over the noise,
//!    `√(max(0, RMS² − σ²))`, at least halves: look-alikes that fit the fitted path and nudge the
//!    others are not a cause;
//! 5. the held-out gain is more than the noise could give: with `Δp` the change of the
//!    prediction on a held-out reading and `r` the base model's residual there, the gain
//!    `Σ (r² − (r − Δp)²)` over the held-out readings must exceed twice its standard deviation
//!    when the findings are spurious (`r` then the noise: `2σ·√(Σ Δp²·(1 + φ)/(1 − φ))`, the
//!    factor the low-frequency power of AR(1) noise over white noise's), so that a false
//!    finding (at rate α) that happens to nudge the held-out records the right way is not
//!    recommended.
//!
//! Otherwise the reasons say which condition failed, with the records and sizes involved.

use super::Finding;
use super::heldout::HeldOut;
use crate::fitting::noise::NoiseModel;
use model_spec::units::UM_PER_MM;

/// The verdict on the extended model.
#[derive(Clone, Debug, PartialEq)]
pub struct Recommendation {
    /// `true`: use the extended model.
    pub recommended: bool,
    /// Why (not), for people, one sentence each.
    pub reasons: Vec<String>,
}

fn um(v: f64) -> String {
    format!("{:.3} µm", v * UM_PER_MM)
}

/// The verdict on the extension of `findings`, from the held-out gain `held` (the records
/// named `names` in the reasons, one per record; their labels where a name is missing);
/// `noise` the noise model the tests assume and `consistent` the lack-of-fit test's verdict,
/// when there is one.
pub fn recommend(
    findings: &[Finding],
    held: &[HeldOut],
    names: &[String],
    noise: Option<&NoiseModel>,
    consistent: Option<bool>,
) -> Recommendation {
    let name = |h: &HeldOut| -> String {
        held.iter()
            .position(|x| std::ptr::eq(x, h))
            .and_then(|i| names.get(i))
            .unwrap_or(&h.name)
            .clone()
    };
    let noise_mm = noise.map(|n| (n.sigma_mm.iter().map(|s| s * s).sum::<f64>() / 3.0).sqrt());
    let mut reasons = Vec::new();
    let implausible = findings.iter().filter(|f| !f.plausible).count();
    if !findings.iter().any(|f| f.plausible) {
        reasons.push(if findings.is_empty() {
            "there is no finding to add".into()
        } else {
            format!(
                "no finding is plausible ({} fit, but beyond the size budget)",
                implausible
            )
        });
        return Recommendation {
            recommended: false,
            reasons,
        };
    }
    if held.is_empty() {
        reasons.push(
            "no held-out record: the gain of the extension cannot be checked (give held-out records)"
                .into(),
        );
    }
    let estimable: Vec<&HeldOut> = held.iter().filter(|h| h.estimable()).collect();
    for h in held.iter().filter(|h| !h.estimable()) {
        let groups: Vec<String> = h
            .undetermined_before
            .iter()
            .chain(&h.undetermined_after)
            .map(|g| g.join(" ≡ "))
            .collect();
        reasons.push(format!(
            "{}: its prediction needs what the fit does not determine ({}); its RMS is not counted",
            name(h),
            groups.join("; ")
        ));
    }
    if !held.is_empty() && estimable.is_empty() {
        reasons.push("no held-out record can check the extension".into());
    }
    for h in &estimable {
        if h.after_rms > h.before_rms {
            reasons.push(format!(
                "{} is predicted worse: {} → {}",
                name(h),
                um(h.before_rms),
                um(h.after_rms)
            ));
        }
    }
    let pooled = |f: fn(&HeldOut) -> f64| -> f64 {
        let s: f64 = estimable
            .iter()
            .map(|h| h.readings as f64 * f(h).powi(2))
            .sum();
        let n: usize = estimable.iter().map(|h| h.readings).sum();
        (s / n.max(1) as f64).sqrt()
    };
    let (before, after) = (pooled(|h| h.before_rms), pooled(|h| h.after_rms));
    if !estimable.is_empty() && after >= before {
        reasons.push(format!(
            "the held-out residual does not fall ({} → {} RMS)",
            um(before),
            um(after)
        ));
    }
    if let (Some(sigma), false) = (noise_mm, consistent == Some(true)) {
        let excess = |rms: f64| (rms * rms - sigma * sigma).max(0.0).sqrt();
        for h in &estimable {
            let (b, a) = (excess(h.before_rms), excess(h.after_rms));
            if a > 0.5 * b {
                reasons.push(format!(
                    "on {} the residual does not move toward the noise: its excess over the noise falls {} → {}, less than half, and what remains is not the noise",
                    name(h),
                    um(b),
                    um(a)
                ));
            }
        }
    }
    if let Some(n) = noise {
        let (mut gain, mut var) = (0.0, 0.0);
        for h in &estimable {
            let drop = super::outliers::samples(&h.outliers);
            for (i, (b, a)) in h.residual_before.iter().zip(&h.residual_after).enumerate() {
                if drop.contains(&i) {
                    continue;
                }
                for d in 0..3 {
                    let dp = b[d] - a[d];
                    gain += b[d] * b[d] - a[d] * a[d];
                    // A smooth Δp meets correlated noise at its low-frequency power, (1 + φ)/(1 − φ)
                    // times the white noise's.
                    let (s, p) = (n.sigma_mm[d], n.phi[d]);
                    var += 4.0 * s * s * (1.0 + p) / (1.0 - p) * dp * dp;
                }
            }
        }
        if !estimable.is_empty() && gain <= 2.0 * var.sqrt() {
            reasons.push(format!(
                "the held-out gain is within what the noise gives ({:.2} standard deviations of a spurious finding's, 2 needed)",
                gain / var.sqrt().max(f64::MIN_POSITIVE)
            ));
        }
    }
    let recommended = reasons.is_empty();
    if recommended {
        reasons.push(format!(
            "every held-out record is predicted at least as well; pooled RMS {} → {}",
            um(before),
            um(after)
        ));
    }
    Recommendation {
        recommended,
        reasons,
    }
}
