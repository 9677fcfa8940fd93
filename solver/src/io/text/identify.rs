//! An identification for people, like the seed's Table 4: one row per parameter (value ± std in
//! µm or µrad, or why there is none; a kinematic offset's change in µm with its nominal and
//! identified lengths in mm), then rank, condition number, residual RMS, σ̂, the
//! confounded groups, the nearly confounded pairs and what the zero offsets swallow.

use super::{value, zeroed_text};
use crate::io::report::identify::{IdentificationReport, ParameterReport};
use model_spec::units::plural;
use model_spec::units::{fixed, symbol};

/// The whole identification text.
pub fn identification(r: &IdentificationReport) -> String {
    let n = r.parameters.len();
    let mut out = format!(
        "Identification on {} ({} samples, readings {}): machine {}, model {} ({n} parameter{})\n",
        r.data,
        r.samples,
        zeroed_text(r.zeroed),
        r.machine,
        r.model,
        plural(n, "s"),
    );
    out.push_str(&method(r));
    if let Some(n) = &r.noise_model {
        out.push_str(&format!(
            "Noise model (the uncertainties assume it): {}{}.\n",
            n.text,
            n.whitened_sigma.map_or(String::new(), |w| format!(
                "; σ̂ of the whitened residual {}",
                fixed(w, 2)
            ))
        ));
    }
    if let Some(s) = &r.streaming {
        let ahead = if s.first_block > s.block {
            format!(
                " (the first read ahead to {} samples, until every axis had moved)",
                s.first_block
            )
        } else {
            String::new()
        };
        out.push_str(&format!(
            "Read in {} block{} of up to {} sample{}{ahead}, folded into an incremental QR (first order; state {} numbers).\n",
            s.blocks,
            plural(s.blocks, "s"),
            s.block,
            plural(s.block, "s"),
            (n + 1).pow(2)
        ));
    }
    if r.zeroed {
        out.push_str(
            "Zeroed readings: the R-test zero offsets dx0 dy0 dz0 (constant, µm) are fitted with the model.\n",
        );
    }
    out.push('\n');
    out.push_str(&parameters(r));
    out.push('\n');
    out.push_str(&summary(r));
    out
}

/// How the values were computed, one line.
pub(crate) fn method(r: &IdentificationReport) -> String {
    let gains = match r.gains.as_str() {
        "compiled" => "the compiled (generated) code",
        "evaluator" => "the in-process evaluator",
        _ => "the compiled code and the evaluator",
    };
    let f = &r.refinement;
    let ls = match &r.noise_model {
        Some(n) if n.source != "residual" => {
            "Generalized least squares (rows whitened by the noise model)"
        }
        _ => "Least squares",
    };
    if f.method == "first-order" {
        return format!(
            "{ls} on the column-scaled H (gains from {gains}), first order (not refined against the exact machine).\n"
        );
    }
    format!(
        "{ls} on the column-scaled H (gains from {gains}), refined against the exact machine: {} Gauss-Newton step{}{}; residual RMS {} µm (first order) -> {} µm.\n",
        f.iterations,
        plural(f.iterations, "s"),
        if f.converged {
            ", converged".to_string()
        } else {
            format!(
                ", NOT converged (last step {} µm)",
                f.steps_um.last().map_or("?".into(), |s| value(*s))
            )
        },
        value(f.first_order_rms_um),
        value(r.residual_rms_um),
    )
}

/// The table of parameters.
fn parameters(r: &IdentificationReport) -> String {
    let all: Vec<&ParameterReport> = r.parameters.iter().collect();
    parameter_table(&all, &r.confounded)
}

/// The table of `params` (value ± std, or why there is none), `confounded` the fit's groups by
/// name.
pub(crate) fn parameter_table(params: &[&ParameterReport], confounded: &[Vec<String>]) -> String {
    let w = params
        .iter()
        .map(|p| p.name.chars().count())
        .max()
        .unwrap_or(0)
        .max("parameter".len());
    let mut out = format!(
        "{:<w$}  {:>12}     {:>10}  unit\n",
        "parameter", "value", "std"
    );
    out.push_str(&format!("{}\n", "-".repeat(w + 36)));
    for p in params {
        let unit = symbol(&p.unit);
        let name = &p.name;
        let why = || match confounded_with(confounded, name) {
            Some(o) if !o.is_empty() => format!("not determined: confounded with {o}"),
            _ => "not determined: these readings do not see it (no gain along this path)".into(),
        };
        let line = if p.fixed {
            format!(
                "{name:<w$}  {:>12}     {:>10}  {unit}  fixed to 0 by --constraint",
                "0", ""
            )
        } else {
            match p.value {
                None => format!("{name:<w$}  {}{}", why(), length(p)),
                Some(v) => {
                    let std = p.std.map_or("-".to_string(), value);
                    let mut l = format!(
                        "{name:<w$}  {:>12}  ±  {std:>10}  {unit}{}",
                        value(v),
                        length(p)
                    );
                    if !p.determined {
                        l.push_str(&format!(
                            "  ({}; minimum-norm value, a convention, not a measurement)",
                            why()
                        ));
                    } else if p.std.is_none() {
                        l.push_str("  (no degree of freedom left for an uncertainty)");
                    }
                    l
                }
            }
        };
        out.push_str(&line);
        out.push('\n');
    }
    out
}

/// For a kinematic offset: `  (change; nominal -250 mm, identified -250.0400 mm)`, the
/// identified length to 0.1 µm; empty for other parameters.
fn length(p: &ParameterReport) -> String {
    let Some(n) = p.nominal_mm else {
        return String::new();
    };
    match p.identified_mm.flatten() {
        Some(x) => format!(
            "  (change; nominal {} mm, identified {} mm)",
            model_spec::units::short(n),
            fixed(x, 4)
        ),
        None => format!("  (nominal {} mm)", model_spec::units::short(n)),
    }
}

/// The other members of `name`'s confounded group, joined, or `None`.
fn confounded_with(confounded: &[Vec<String>], name: &str) -> Option<String> {
    let g = confounded.iter().find(|g| g.iter().any(|n| n == name))?;
    let others: Vec<&str> = g
        .iter()
        .filter(|n| *n != name)
        .map(String::as_str)
        .collect();
    Some(others.join(", "))
}

/// Rank, condition, residual, σ̂, confounded groups, near pairs, swallowed errors.
pub(crate) fn summary(r: &IdentificationReport) -> String {
    let n = r.parameters.len();
    let mut out = format!(
        "rank {} of {}{}; condition number {} (column-scaled H)\n",
        r.rank,
        r.free_parameters,
        if r.free_parameters == n {
            String::new()
        } else {
            format!(" free parameters ({} fixed)", n - r.free_parameters)
        },
        r.condition
            .map_or("undefined (rank 0)".into(), |c| fixed(c, 1))
    );
    out.push_str(&format!(
        "residual RMS {} µm over {} readings; σ̂ = {} ({} degrees of freedom)\n",
        value(r.residual_rms_um),
        r.readings,
        r.sigma_um
            .map_or("undefined".into(), |s| format!("{} µm", value(s))),
        r.dof
    ));
    if r.confounded.is_empty() {
        out.push_str("confounded groups: none (every free parameter is determined)\n");
    } else {
        let groups: Vec<String> = r
            .confounded
            .iter()
            .map(|g| format!("[{}]", g.join(", ")))
            .collect();
        out.push_str(&format!(
            "confounded groups (the data cannot separate them{}): {}\n",
            if r.constraint == "minimum-norm" {
                "; values above are minimum-norm"
            } else {
                "; no value without --constraint"
            },
            groups.join(" ")
        ));
    }
    if r.near_confounded.is_empty() {
        out.push_str("near-confounded pairs (|corr| > 0.99): none\n");
    } else {
        let pairs: Vec<String> = r
            .near_confounded
            .iter()
            .map(|p| {
                format!(
                    "{}-{} ({:+.4})",
                    p.parameters[0], p.parameters[1], p.correlation
                )
            })
            .collect();
        out.push_str(&format!(
            "near-confounded pairs (|corr| > 0.99: determined, but poorly separated): {}\n",
            pairs.join(", ")
        ));
    }
    if !r.swallowed.is_empty() {
        let parts: Vec<String> = r
            .swallowed
            .iter()
            .map(|s| {
                format!(
                    "{} swallows {}",
                    s.offsets.join(" and "),
                    if s.errors.is_empty() {
                        "nothing else (the offsets are confounded with each other)".into()
                    } else {
                        s.errors.join(", ")
                    }
                )
            })
            .collect();
        let swallowed: Vec<&str> = r
            .swallowed
            .iter()
            .flat_map(|s| s.errors.iter().map(String::as_str))
            .collect();
        out.push_str(&format!(
            "zeroed readings: {} (constant gains: the zeroed R-test cannot tell them from its own zero{})\n",
            parts.join("; "),
            if swallowed.is_empty() {
                String::new()
            } else {
                format!(
                    "; --constraint zero:{} fixes those errors to 0 and determines the offsets",
                    swallowed.join(",")
                )
            }
        ));
    }
    out
}
