//! The demo's summary for people: the machine and truth, the identification against the truth
//! (like the seed's Table 4), the residuals on every path against the seed's, what is left
//! unexplained and why, the diagnosis and its check against the truth.

use super::{Run, SEED_DEVIATION_UM};
use diagnosis::Diagnosis;
use diagnosis::hidden::HiddenTerms;
use fitting::{Identification, Refinement};
use model_spec::Machine;
use model_spec::units::plural;
use model_spec::units::{fixed, short, symbol};
use report::json::{DiagnosisReport, IdentificationReport, ValidationReport};
use report::text::diagnose as diag_text;
use report::text::validate::{defaulted_note, residual_table};
use report::text::{header, table, value};
use simulation::truth::Truth;

/// Everything the summary is written from.
pub(crate) struct Summary<'a> {
    pub(crate) m: &'a Machine,
    pub(crate) truth: &'a Truth,
    pub(crate) runs: &'a [Run],
    pub(crate) ident: &'a Identification,
    pub(crate) refinement: &'a Refinement,
    pub(crate) identification: &'a IdentificationReport,
    pub(crate) validations: &'a [ValidationReport],
    pub(crate) hidden: &'a HiddenTerms,
    pub(crate) diagnosis: &'a Diagnosis,
    pub(crate) diagnosis_report: &'a DiagnosisReport,
    /// Per compiled model: name, errors, operation counts.
    pub(crate) operations: &'a [(&'a str, usize, String)],
    /// The compensation step.
    pub(crate) compensation: &'a super::compensation::CompensationStep,
}

/// The whole summary.
pub(crate) fn summary(s: &Summary) -> String {
    let m = s.m;
    let mut out = String::from(
        "rtest demo: the seed's experiment (fit the reduced model on K4, check it on K1 and K2) on the virtual seed machine\n\n",
    );
    out.push_str(&machine_line(m));
    out.push_str(&format!(
        "Truth {} (docs/truth.md): {}\n  {}\n",
        s.truth.source,
        s.truth.description,
        s.truth.summary(m).replace(" um", " µm")
    ));
    let simulated: Vec<String> = s
        .runs
        .iter()
        .map(|r| {
            format!(
                "{} ({} samples, noise seed {})",
                r.name,
                r.record.samples.len(),
                r.truth.seed
            )
        })
        .collect();
    out.push_str(&format!(
        "Simulated on the exact virtual machine: {}.\n\n",
        simulated.join(", ")
    ));
    let steps = s.refinement.iterations;
    out.push_str(&format!(
        "Identified on K4: reduced model (the seed's Table 2), refined against the exact machine ({steps} Gauss-Newton step{}); like the seed's Table 4:\n\n",
        plural(steps, "s")
    ));
    out.push_str(&truth_table(m, s.truth, s.ident, s.hidden.bias.as_deref()));
    let r = s.identification;
    out.push_str(&format!(
        "rank {} of {}, condition number {}, residual RMS {} µm, σ̂ {} µm; confounded groups: {}; near-confounded pairs: {}\n\n",
        r.rank,
        r.parameters.len(),
        r.condition.map_or("undefined".into(), |c| fixed(c, 1)),
        value(r.residual_rms_um),
        r.sigma_um.map_or("undefined".into(), value),
        if r.confounded.is_empty() {
            "none".to_string()
        } else {
            format!("{:?}", r.confounded)
        },
        if r.near_confounded.is_empty() {
            "none".to_string()
        } else {
            r.near_confounded.len().to_string()
        },
    ));
    out.push_str(
        "Residual (measured - predicted), µm: before = nominal machine, after = identified model (exact prediction):\n\n",
    );
    let names: Vec<String> = s
        .runs
        .iter()
        .map(|r| {
            if r.name == "K4" {
                "K4 (fit)".to_string()
            } else {
                r.name.to_string()
            }
        })
        .collect();
    let rows: Vec<(&str, &ValidationReport)> = names
        .iter()
        .map(String::as_str)
        .zip(s.validations)
        .collect();
    out.push_str(&residual_table(&rows));
    for v in s.validations {
        out.push_str(&defaulted_note(v));
    }
    let max_after = |i: usize| s.validations[i].overall.residual_max_um;
    out.push_str(&format!(
        "\nThe seed's real machine left deviations within ±{} µm on K4 and ±{} µm on K1 and K2; here the largest are {} µm (K4), {} µm (K1) and {} µm (K2), with {} µm of noise.\n",
        SEED_DEVIATION_UM.0,
        SEED_DEVIATION_UM.1,
        fixed(max_after(0), 2),
        fixed(max_after(1), 2),
        fixed(max_after(2), 2),
        short(s.truth.noise_mm * 1e3)
    ));
    if s.hidden.model.terms.is_empty() {
        out.push_str(
            "The truth has nothing the reduced model lacks: what is left is the noise of the simulation.\n",
        );
    } else {
        out.push_str(&unexplained(m, s.hidden));
    }
    out.push_str(&diagnosis_text(m, s));
    out.push_str(&compensation_text(s.compensation));
    out.push_str("\nCompiled straight-line code (per evaluation of all gains):\n");
    for (name, n, ops) in s.operations {
        out.push_str(&format!("  {name:<8} {n:>2} errors: {ops}\n"));
    }
    out
}

/// What compensation left of the machine's error on the held-out paths.
fn compensation_text(c: &super::compensation::CompensationStep) -> String {
    let mut out = format!(
        "\nCompensated (rtest compensate) with {} identified on K4: {} machine error(s) put back onto the machine ({}); set-up, sensor and time terms left out. The machine's own error (the ball's set-up aside), RMS on the exact machine:\n",
        c.label,
        c.compensated.len(),
        c.compensated.join(" ")
    );
    for p in &c.paths {
        out.push_str(&format!(
            "  {}: {} µm commanded -> {} µm compensated ({:.1} % less)\n",
            p.name,
            fixed(p.before * 1e3, 3),
            fixed(p.after * 1e3, 3),
            100.0 * (1.0 - p.after / p.before)
        ));
    }
    out
}

/// The machine and its kinematic parameters, one line each.
fn machine_line(m: &Machine) -> String {
    let params: Vec<String> = m
        .symbols
        .iter()
        .filter(|s| s.default != 0.0)
        .map(|s| format!("{} = {}", s.name, short(s.default)))
        .collect();
    format!(
        "Machine {}: {}\n  kinematic parameters (the seed's Table 3, mm): {}\n",
        m.name,
        m.description,
        params.join(", ")
    )
}

/// The identified values against the truth: one row per parameter with the truth, the
/// estimate ± std, their difference in std, and (with `bias`: one value per parameter, mm or
/// rad) the shift the truth's hidden terms put into the estimate and the difference without it.
fn truth_table(
    m: &Machine,
    truth: &Truth,
    ident: &Identification,
    bias: Option<&[Option<f64>]>,
) -> String {
    let fit = &ident.fit;
    let mut rows = Vec::new();
    for (j, (t, k)) in ident.model.columns().into_iter().enumerate() {
        let term = ident.model.terms[t];
        let f = term.display_factor(m);
        let true_value = truth.coefficient(&term).map_or(0.0, |c| c[k]) * f;
        let b = bias
            .and_then(|b| b.get(j).copied().flatten())
            .map(|b| b * f);
        let z = |v: f64, s: f64| format!("{:+.2}", v / s);
        let (shown, std, z0, z1) = match (fit.values[j], fit.std[j]) {
            (Some(v), Some(s)) => (
                value(v * f),
                value(s * f),
                z(v * f - true_value, s * f),
                b.map_or("-".into(), |b| z(v * f - true_value - b, s * f)),
            ),
            (Some(v), None) => (value(v * f), "-".into(), "-".into(), "-".into()),
            _ => ("not determined".into(), "-".into(), "-".into(), "-".into()),
        };
        let mut row = vec![
            fit.names[j].clone(),
            symbol(term.unit(m)).to_string(),
            value(true_value),
            shown,
            std,
            z0,
        ];
        if bias.is_some() {
            row.push(b.map_or("-".into(), value));
            row.push(z1);
        }
        rows.push(row);
    }
    let mut head = header(&[
        "parameter",
        "unit",
        "truth",
        "identified",
        "± std",
        "(id - truth)/std",
    ]);
    if bias.is_some() {
        head.push("hidden-term bias".into());
        head.push("(id - truth - bias)/std".into());
    }
    table(&head, &rows)
}

/// What the reduced model lacks according to the truth, how much it moves the readings, and the
/// bias it puts into the fit.
fn unexplained(m: &Machine, hidden: &HiddenTerms) -> String {
    let mut at = 0;
    let mut names = Vec::new();
    for t in &hidden.model.terms {
        let f = t.display_factor(m);
        let w = t.basis.width();
        let parts: Vec<String> = hidden.values[at..at + w]
            .iter()
            .map(|x| x.map_or("?".into(), |x| short(x * f)))
            .collect();
        let shown = if w == 2 {
            format!("[{}]", parts.join(", "))
        } else {
            parts.join(", ")
        };
        names.push(format!("{} = {shown} {}", t.spelling(m), symbol(t.unit(m))));
        at += w;
    }
    let rms: Vec<String> = hidden.rms_mm.iter().map(|x| fixed(x * 1e3, 2)).collect();
    format!(
        "Left unexplained: the truth's {}, which the reduced model lacks; alone it moves the readings by {} µm RMS on K4/K1/K2, and the fit on K4 bends the 11 values to absorb what it can of it: the hidden-term bias column, larger than the std, which covers the noise only.\n",
        names.join(", "),
        rms.join("/"),
    )
}

/// The diagnosis's own result, then its check against the truth, which it did not use.
fn diagnosis_text(m: &Machine, s: &Summary) -> String {
    let r = s.diagnosis_report;
    let d = s.diagnosis;
    let held: Vec<&str> = r.held_out.iter().map(|(n, _)| n.as_str()).collect();
    let mut out = format!(
        "\nDiagnosis (rtest diagnose --machine {} --model {} --data {} --validate {}): {} candidate terms the reduced model lacks, tried one at a time at α = {} (corrected for the candidates tried); the truth is not used.\n",
        r.machine_source,
        r.base_model,
        r.data,
        held.join(","),
        r.dictionary_size,
        r.alpha
    );
    if r.findings.is_empty() {
        out.push_str("  no finding\n");
    } else {
        out.push_str("Found:\n");
        out.push_str(&diag_text::findings(r));
    }
    out.push_str(&diag_text::stop(r));
    out.push_str(&format!(
        "Gain: residual RMS, reduced → {}:\n",
        r.extended_model.label
    ));
    out.push_str(&diag_text::gain(r));
    out.push_str(&diag_text::recommendation(r));
    out.push_str(&diag_text::next_steps(r));

    // The check against the truth.
    let mut checks = Vec::new();
    for t in &s.hidden.model.terms {
        let f = t.display_factor(m);
        let unit = symbol(t.unit(m));
        let want: Vec<f64> = s
            .truth
            .coefficient(t)
            .unwrap_or(&[])
            .iter()
            .map(|v| v * f)
            .collect();
        let shown: Vec<String> = want.iter().map(|&v| short(v)).collect();
        match d.findings.iter().position(|x| x.term == *t) {
            Some(i) => {
                let x = &d.findings[i];
                let z: Vec<String> = x
                    .values
                    .iter()
                    .zip(&x.stds)
                    .zip(&want)
                    .map(|((v, sd), w)| match (v, sd) {
                        (Some(v), Some(sd)) if *sd > 0.0 => {
                            format!("{:+.2}", (v * f - w) / (sd * f))
                        }
                        _ => "-".into(),
                    })
                    .collect();
                checks.push(format!(
                    "{} found: {} against the truth {} {unit}, (found - truth)/std = {}",
                    t.spelling(m),
                    diag_text::values(&r.findings[i]),
                    shown.join(", "),
                    z.join(", ")
                ));
            }
            None => checks.push(format!(
                "{} (truth {} {unit}) NOT found",
                t.spelling(m),
                shown.join(", ")
            )),
        }
    }
    for x in &d.findings {
        if !s.hidden.model.terms.contains(&x.term) {
            checks.push(format!(
                "{} found but not in the truth (a false finding)",
                x.term.spelling(m)
            ));
        }
    }
    let after: Vec<String> = std::iter::once(r.gain.fit.residual_rms_um_after)
        .chain(r.gain.validation.iter().map(|v| v.residual_rms_um_after))
        .map(|x| fixed(x, 2))
        .collect();
    out.push_str(&format!(
        "Check against the truth (known here only): {}; residual RMS after {} µm on K4/K1/K2, against {} µm of noise.\n",
        checks.join("; "),
        after.join("/"),
        short(s.truth.noise_mm * 1e3)
    ));
    out
}
