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
//! 6. when the held-out records judged the findings one by one ([`super::confirm`]), at least
//!    one is confirmed on its own (the extended model then holds only those);
//! 7. no plausible finding is a jump in time of a fitted record (`ZOW@jump:149.5`): the ball
//!    or the sensor moved during the record. The fit with the jump gives the machine's errors
//!    as well as that record can, and a machine term confirmed beside it may be real, but a
//!    record that jumped is measured again before anything of it is named a cause.
//!
//! The held-out records are those given, or with none and several fitted records, every fitted
//! record predicted by the fit on the others ([`super::confirm::Judges`]).
//!
//! Otherwise the reasons say which condition failed, with the records and sizes involved.

use super::Finding;
use super::heldout::HeldOut;
use fitting::noise::NoiseModel;
use model_spec::units::UM_PER_MM;

/// The verdict on the extended model.
#[derive(Clone, Debug, PartialEq)]
pub struct Recommendation {
    /// `true`: use the extended model.
    pub recommended: bool,
    /// Why (not), for people, one sentence each.
    pub reasons: Vec<String>,
}

/// How many standard deviations of a spurious gain a held-out gain must exceed (condition 5;
/// and a finding's own gain, [`super::confirm`]).
pub const CONFIRM_SD: f64 = 2.0;

/// Whether a finding (or an error group) that no judging record can judge (none's fit
/// determines what it predicts there, [`super::confirm`]) enters the extended model on the
/// fitted records alone: its corrected p-value `p` below `alpha·Φ̄(CONFIRM_SD)`. A finding that
/// is judged enters after two tests, the selection's at `alpha` and its own held-out gain
/// beyond [`CONFIRM_SD`] standard deviations, which a spurious one passes with probability
/// `Φ̄(CONFIRM_SD)` (2.3 %); one that is not judged must reach the same rate of false entry
/// on the one test it has. The judging records' word is needed all the same where the fitted
/// records are one path with records held out (`confirm::Folds::enters_unjudged`).
pub fn enters_unjudged(p: f64, alpha: f64) -> bool {
    p < alpha * fitting::distributions::normal_upper_tail(CONFIRM_SD)
}

/// The gain of a change of prediction on held-out readings and its standard deviation were the
/// change spurious (condition 5): per record the residuals `before` and `after` the change (mm,
/// one `[x, y, z]` per sample) and the samples left out (outliers). With `Δp = before − after`,
/// the gain is `Σ (before² − after²)` and its standard deviation, `before` then the noise,
/// `2σ·√(Σ Δp²·(1 + φ)/(1 − φ))` (mm²); and `Σ Δp²` (mm²), the gain were `after` right.
pub fn gain_against_noise<'a>(
    noise: &NoiseModel,
    records: impl IntoIterator<Item = (&'a [[f64; 3]], &'a [[f64; 3]], Vec<usize>)>,
) -> (f64, f64, f64) {
    let (mut gain, mut var, mut spread) = (0.0, 0.0, 0.0);
    for (before, after, drop) in records {
        for (i, (b, a)) in before.iter().zip(after).enumerate() {
            if drop.contains(&i) {
                continue;
            }
            for d in 0..3 {
                let dp = b[d] - a[d];
                gain += b[d] * b[d] - a[d] * a[d];
                spread += dp * dp;
                // A smooth Δp meets correlated noise at its low-frequency power, (1 + φ)/(1 − φ)
                // times the white noise's.
                let (s, p) = (noise.sigma_mm[d], noise.phi[d]);
                var += 4.0 * s * s * (1.0 + p) / (1.0 - p) * dp * dp;
            }
        }
    }
    (gain, var.sqrt(), spread)
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
            "no held-out record: the gain of the extension cannot be checked (give held-out records, or fit several records: each is then predicted by the others)"
                .into(),
        );
    }
    let judged: Vec<&Finding> = findings
        .iter()
        .filter(|f| f.plausible && f.confirmation.is_some())
        .collect();
    if !judged.is_empty() && !judged.iter().any(|f| f.confirmed()) {
        let gains: Vec<String> = judged
            .iter()
            .filter_map(|f| {
                f.confirmation.as_ref().map(|c| {
                    format!(
                        "{} {:.2}",
                        f.description.split(": ").next().unwrap_or(""),
                        c.gain_sd
                    )
                })
            })
            .collect();
        reasons.push(format!(
            "no finding is confirmed on its own by the held-out records (held-out gain given the others, in standard deviations of a spurious one's: {}; {CONFIRM_SD} needed)",
            gains.join(", ")
        ));
    }
    let jumps: Vec<&str> = findings
        .iter()
        .filter(|f| f.plausible && f.term.basis.jump_at().is_some())
        .map(|f| f.description.split(": ").next().unwrap_or(""))
        .collect();
    if !jumps.is_empty() {
        reasons.push(format!(
            "a fitted record holds a jump in time ({}): the ball or the sensor moved during the record, or something the dictionary lacks changed at once; measure it again",
            jumps.join(", ")
        ));
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
        let (gain, sd, _) = gain_against_noise(
            n,
            estimable.iter().map(|h| {
                (
                    h.residual_before.as_slice(),
                    h.residual_after.as_slice(),
                    super::outliers::samples(&h.outliers),
                )
            }),
        );
        if !estimable.is_empty() && gain <= CONFIRM_SD * sd {
            reasons.push(format!(
                "the held-out gain is within what the noise gives ({:.2} standard deviations of a spurious finding's, {CONFIRM_SD} needed)",
                gain / sd.max(f64::MIN_POSITIVE)
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
