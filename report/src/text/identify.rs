//! An identification for people, like the seed's Table 4, of one record or of a campaign of
//! several: what is shared and what belongs to a set-up or a record, the records with their
//! residuals, then one row per parameter (value ± std in µm or µrad, or why there is none; a
//! kinematic offset's change in µm with its nominal and identified lengths in mm): the shared
//! values, one block per set-up and per record; then rank, condition number, residual RMS, σ̂,
//! the confounded groups, the nearly confounded pairs, what the zero offsets swallow and which
//! set-up errors the records cannot tell from the machine's.

use super::{header, table, value, zeroed_text};
use crate::json::identify::{IdentificationReport, ParameterReport};
use model_spec::units::plural;
use model_spec::units::{fixed, short, symbol};

/// The whole identification text.
pub fn identification(r: &IdentificationReport) -> String {
    let n = r.parameters.len();
    let mut out = match (&r.data, r.is_campaign()) {
        (Some(data), false) => format!(
            "Identification on {data} ({} samples, readings {}): machine {}, model {} ({n} parameter{})\n",
            r.samples,
            zeroed_text(r.any_zeroed()),
            r.machine,
            r.model,
            plural(n, "s"),
        ),
        _ => format!(
            "Campaign identification: {} record{} on {} set-up{} ({} samples): machine {}, model {} ({n} parameter{})\n",
            r.records.len(),
            plural(r.records.len(), "s"),
            r.setups.len(),
            plural(r.setups.len(), "s"),
            r.samples,
            r.machine,
            r.model,
            plural(n, "s"),
        ),
    };
    out.push_str(&method(r));
    if let Some(nm) = &r.noise_model {
        out.push_str(&format!(
            "Noise model (the uncertainties assume it{}): {}{}.\n",
            if r.is_campaign() {
                "; records independent"
            } else {
                ""
            },
            nm.text,
            nm.whitened_sigma.map_or(String::new(), |w| format!(
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
    if r.is_campaign() {
        out.push_str(&ownership(r));
        out.push('\n');
        out.push_str(&records(r));
        let shared = r.parameters_of("shared", None);
        if !shared.is_empty() {
            out.push_str("\nShared (the machine's errors, one value for the campaign)\n");
            out.push_str(&parameter_table(&shared, &r.confounded));
        }
        for s in &r.setups {
            let p = r.parameters_of("setup", Some(&s.label));
            if p.is_empty() {
                continue;
            }
            out.push_str(&format!(
                "\nSet-up {} (records {})\n",
                s.label,
                s.records.join(", ")
            ));
            out.push_str(&parameter_table(&p, &r.confounded));
        }
        for rec in &r.records {
            let p = r.parameters_of("record", Some(&rec.label));
            if p.is_empty() {
                continue;
            }
            out.push_str(&format!(
                "\nRecord {} (readings {})\n",
                rec.label,
                zeroed_text(rec.zeroed)
            ));
            out.push_str(&parameter_table(&p, &r.confounded));
        }
    } else {
        if r.any_zeroed() {
            out.push_str(
                "Zeroed readings: the R-test zero offsets dx0 dy0 dz0 (constant, µm) are fitted with the model.\n",
            );
        }
        out.push('\n');
        let all: Vec<&ParameterReport> = r.parameters.iter().collect();
        out.push_str(&parameter_table(&all, &r.confounded));
    }
    out.push('\n');
    out.push_str(&summary(r));
    for note in r.notes.iter().filter(|n| n.starts_with("the set-up error")) {
        out.push_str(&format!("{note}\n"));
    }
    out
}

/// What is shared and what belongs to a set-up or a record, in a campaign.
fn ownership(r: &IdentificationReport) -> String {
    let distinct = |owner: &str| -> Vec<String> {
        let mut v: Vec<String> = Vec::new();
        for p in r
            .parameters
            .iter()
            .filter(|p| p.owner.as_deref() == Some(owner))
        {
            let bare = p.name.split('[').next().unwrap_or("").to_string();
            if !v.contains(&bare) {
                v.push(bare);
            }
        }
        v
    };
    let mut out = String::new();
    let setup = distinct("setup");
    if !setup.is_empty() {
        out.push_str(&format!(
            "Per set-up (the ball's set-up errors, one set per set-up; records with the same set-up label share it): {}.\n",
            setup.join(" ")
        ));
    }
    let record = distinct("record");
    if !record.is_empty() {
        out.push_str(&format!(
            "Per record (the R-test's zero of zeroed records{}): {}.\n",
            if r.clock.is_some() {
                ", its drift"
            } else {
                ", drifts on each record's own clock"
            },
            record.join(" ")
        ));
    }
    out.push_str("Shared: every other term, the machine's errors.\n");
    if let Some(c) = &r.clock {
        out.push_str(&format!(
            "Campaign clock: the time bases run over {} .. {} s, every record placed by its start.\n",
            short(c.start_s),
            short(c.end_s)
        ));
    }
    out
}

/// The records: set-up, samples, zeroing, kinematic parameters that differ between them,
/// residual RMS.
fn records(r: &IdentificationReport) -> String {
    let head = header(&[
        "record",
        "set-up",
        "data",
        "samples",
        "readings",
        "residual RMS µm",
        "parameters (mm)",
    ]);
    let rows: Vec<Vec<String>> = r
        .records
        .iter()
        .map(|x| {
            // The parameters that differ between the records (the ball's position).
            let params: Vec<String> = x
                .params
                .0
                .iter()
                .filter(|(k, v)| {
                    r.records
                        .iter()
                        .any(|o| o.params.0.iter().any(|(ok, ov)| ok == k && ov != v))
                })
                .map(|(k, v)| format!("{k} = {}", short(*v)))
                .collect();
            vec![
                x.label.clone(),
                x.setup.clone(),
                x.data.clone(),
                x.samples.to_string(),
                if x.zeroed { "zeroed" } else { "not zeroed" }.into(),
                value(x.residual_rms_um),
                if params.is_empty() {
                    "as the others".into()
                } else {
                    params.join(", ")
                },
            ]
        })
        .collect();
    table(&head, &rows)
}

/// How the values were computed, one line.
fn method(r: &IdentificationReport) -> String {
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

/// The table of `params` (value ± std, or why there is none), `confounded` the fit's groups by
/// name.
pub fn parameter_table(params: &[&ParameterReport], confounded: &[Vec<String>]) -> String {
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
fn summary(r: &IdentificationReport) -> String {
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
