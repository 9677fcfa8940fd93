//! What a diagnosis found, for people: the findings with their values, significance and
//! alternatives, what the judging records say of each, and the error groups selected after them.

use super::super::value;
use super::words;
use crate::json::diagnose::{ConfirmationReport, DiagnosisReport, FindingReport};
use model_spec::units::{fixed, p_value, symbol};

/// How the p-value of a finding was corrected, for people.
fn correction(f: &FindingReport, draws: usize) -> String {
    if f.correction == "bonferroni" {
        format!(
            "Bonferroni-corrected: raw p × {} candidates tried",
            f.candidates_tried
        )
    } else {
        format!(
            "corrected by a Monte-Carlo null of the selection over the {} candidates tried ({draws} draws)",
            f.candidates_tried
        )
    }
}

/// `7.7512 ± 0.3012 (cos), 6.1003 ± 0.2710 (sin) µrad`.
pub fn values(f: &FindingReport) -> String {
    let parts: Vec<String> = f
        .values
        .iter()
        .zip(&f.stds)
        .enumerate()
        .map(|(i, (v, s))| {
            let v = v.map_or("not determined".into(), value);
            let s = s.map_or(String::new(), |s| format!(" ± {}", value(s)));
            let suffix = if f.columns.len() > 1 {
                let n = &f.columns[i];
                format!(" ({})", n.rsplit(':').next().unwrap_or(n))
            } else {
                String::new()
            };
            format!("{v}{s}{suffix}")
        })
        .collect();
    format!("{} {}", parts.join(", "), symbol(&f.unit))
}

/// The findings, one block each: name, values, amplitude and phase, share, F and p,
/// alternatives.
pub fn findings(r: &DiagnosisReport) -> String {
    let mut out = String::new();
    for (i, f) in r.findings.iter().enumerate() {
        let unit = symbol(&f.unit);
        out.push_str(&format!("  {}. {}: {}\n", i + 1, f.description, values(f)));
        if let Some(sc) = &f.scan {
            out.push_str(&format!(
                "     {} = {} {} (95 % interval {} .. {} from the profile of the fit; the values' stds are conditional on it)\n",
                sc.parameter,
                fixed(sc.value, 3),
                sc.unit,
                fixed(sc.low, 3),
                fixed(sc.high, 3)
            ));
        }
        if !f.plausible {
            out.push_str(&format!(
                "     fits, but implausible: size {} {unit} beyond the budget of {} {unit}; not a cause, left out of the extended model\n",
                value(f.size),
                value(f.limit)
            ));
        } else {
            out.push_str(&confirmation(f));
        }
        if let (Some(h), Some(k)) = (&f.harmonic, f.basis.strip_prefix("harmonic:")) {
            let pm = |s: Option<f64>, digits: usize| {
                s.map_or(String::new(), |s| format!(" ± {}", fixed(s, digits)))
            };
            let axis = f.axis.as_deref().unwrap_or("θ");
            out.push_str(&format!(
                "     amplitude {}{} {unit}, phase {}{}° (amplitude·cos({k}·{axis} − phase))\n",
                value(h.amplitude),
                pm(h.amplitude_std, 4),
                fixed(h.phase_deg, 1),
                pm(h.phase_std_deg, 1),
            ));
        }
        out.push_str(&format!(
            "     explains {} % of the base model's residual (sum of squares); F = {}, p = {} ({})\n",
            fixed(100.0 * f.explained_fraction, 1),
            fixed(f.f, 1),
            p_value(f.p_value),
            correction(f, r.draws)
        ));
        if !f.alternatives.is_empty() {
            let alts: Vec<String> = f.alternatives.iter().map(|t| words(t)).collect();
            out.push_str(&format!(
                "     the data cannot tell it from: {}\n",
                alts.join(", ")
            ));
        }
    }
    out
}

/// What the held-out (or left-out) records say of a plausible finding, and its status when it
/// is not a cause.
fn confirmation(f: &FindingReport) -> String {
    let mut out = String::new();
    if f.status == "jump" {
        out.push_str("     a jump in time of the fitted record: the ball or the sensor moved during the record; it predicts nothing on another record and is no cause of the machine: measure the record again
");
    }
    let Some(c) = &f.confirmation else {
        if f.status != "cause" && f.status != "jump" {
            out.push_str("     fits the fitted record, but not confirmed: no record was held out to check it; not a cause\n");
        }
        return out;
    };
    let by = if c.judged_by == "left-out" {
        "the fitted records (each left out in turn, predicted by the others)"
    } else {
        "the held-out records"
    };
    let tried = |c: &ConfirmationReport| -> String {
        c.tried
            .iter()
            .map(|t| format!("{} {}", words(&t.term), fixed(t.gain_sd, 1)))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if !c.unjudged.is_empty() {
        out.push_str(&format!(
            "     {} cannot judge it: the fit on the other records does not determine what it predicts there{}\n",
            c.unjudged.join(", "),
            if c.not_judged {
                " (determined only by the record left out: no other record can confirm it)"
            } else {
                ""
            }
        ));
    }
    if c.not_judged {
        out.push_str(if c.confirmed {
            "     in the extended model on the fitted records alone: its corrected p-value is below α·Φ̄(2), the rate a judged finding's two tests allow\n"
        } else {
            "     not in the extended model: judged by no record, and its corrected p-value is not below α·Φ̄(2), the rate a judged finding's two tests allow\n"
        });
    } else if let Some(original) = &c.replaces {
        out.push_str(&format!(
            "     chosen by {by} among the alternatives of {}: held-out gain {} standard deviations of a spurious one's (tried: {})\n",
            words(original),
            fixed(c.gain_sd, 1),
            tried(c)
        ));
    } else if c.confirmed {
        out.push_str(&format!(
            "     confirmed on its own by {by}: held-out gain given the other findings {} standard deviations of a spurious one's\n",
            fixed(c.gain_sd, 1)
        ));
    } else {
        out.push_str(&format!(
            "     fits the fitted record, but not confirmed on its own by {by}: held-out gain given the other findings {} standard deviations of a spurious one's (2 needed); not a cause{}\n",
            fixed(c.gain_sd, 1),
            if c.tried.is_empty() {
                String::new()
            } else {
                format!(
                    "; in its place, given the confirmed findings: {} (none chosen)",
                    tried(c)
                )
            }
        ));
    }
    if c.confirmed && f.status != "cause" && f.status != "jump" {
        out.push_str("     not a cause: the extended model is not recommended (below)\n");
    }
    out
}

/// The error groups selected after the findings, each with what the judging records say.
pub(super) fn groups(r: &DiagnosisReport) -> String {
    let mut out = String::new();
    if r.groups.is_empty() {
        return out;
    }
    out.push_str("Error groups, each one candidate of its directions after the findings:\n");
    for g in &r.groups {
        out.push_str(&format!(
            "  {} ({}): {} directions, F = {}, p = {}; {}{}{}\n",
            g.name,
            g.terms.join(" "),
            g.directions,
            fixed(g.f, 1),
            p_value(g.p_value),
            match g.gain_sd {
                Some(z) => format!(
                    "gain on the records that judge it {} standard deviations",
                    fixed(z, 1)
                ),
                None =>
                    "no record can judge it: in the model on its p-value only below α·Φ̄(2)".into(),
            },
            if g.unjudged.is_empty() {
                String::new()
            } else {
                format!(" ({} cannot judge it)", g.unjudged.join(", "))
            },
            if g.confirmed {
                "; in the extended model"
            } else {
                "; not in the extended model"
            }
        ));
        if g.confirmed && !g.undetermined.is_empty() {
            out.push_str(&format!(
                "    not determined by these records: {} (identify with --constraint min-norm)\n",
                g.undetermined.join(" ")
            ));
        }
    }
    out
}
