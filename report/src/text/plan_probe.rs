//! A probe plan for people: the probe and what one pose's sphere fit gives, the intervals and
//! the poses, the poses skipped, every parameter's predicted uncertainty and valuation number,
//! the valuation of every rotary axis, and how the number of positions per axis was chosen.

use super::{header, table, value};
use crate::json::plan_probe::PlanProbeReport;
use model_spec::units::{fixed, plural, short, symbol};

/// The whole probe plan text.
pub fn plan_probe(r: &PlanProbeReport) -> String {
    let mut out = intro(r);
    out.push('\n');
    out.push_str(&poses(r));
    out.push('\n');
    out.push_str(&parameters(r));
    out.push('\n');
    out.push_str(&summary(r));
    out
}

/// What is planned and what the numbers assume.
fn intro(r: &PlanProbeReport) -> String {
    let how = match &r.auto {
        Some(_) => format!(
            " (auto: the least number from 3 to 12 that leaves no parameter of interest confounded and gives each a valuation of {} or more)",
            short(r.min_valuation)
        ),
        None => String::new(),
    };
    let p = &r.probe;
    let c = p.centre_std_um;
    let held = if r.constraint.is_empty() {
        String::new()
    } else {
        format!(" Held at 0 (--constraint): {}.", r.constraint.join(", "))
    };
    format!(
        "Probe plan on machine {}, model {} ({} parameter{}): {} positions per rotary axis{how}, {} pose{} ({} readings).\n\
         Probe{}: tip radius {} mm, sphere radius {} mm, σ {} µm; the default 9-hit pattern gives a pose's centre with a standard uncertainty of {}, {}, {} µm (x, y, z of the probe frame: across and along the stylus). \
         The uncertainties are those a fit of these readings would report, each pose weighted by its covariance (first order); nothing is measured.{held}\n",
        r.machine,
        r.model,
        r.columns,
        plural(r.columns, "s"),
        r.per_axis,
        r.samples,
        plural(r.samples, "s"),
        r.readings,
        p.name
            .as_ref()
            .map(|n| format!(" `{n}`"))
            .unwrap_or_default(),
        short(p.tip_radius_mm),
        short(p.sphere_radius_mm),
        short(p.noise_um),
        value(c[0]),
        value(c[1]),
        value(c[2]),
    )
}

/// The intervals, the poses kept (every axis's command) and the poses skipped.
fn poses(r: &PlanProbeReport) -> String {
    let mut out = String::from(
        "Poses: each rotary axis stepped over its interval, the other rotary axes at rest, the linear axes putting the probe tip on the sphere's centre:\n",
    );
    for s in &r.sweeps {
        let list: Vec<String> = s.positions_deg.iter().map(|a| short(*a)).collect();
        let span = if s.full_turn {
            format!(
                "a full turn from {}° in {} equal steps",
                short(s.from_deg),
                s.positions_deg.len()
            )
        } else {
            format!("{}° .. {}°, both ends", short(s.from_deg), short(s.to_deg))
        };
        out.push_str(&format!("  {}: {span}: {}°\n", s.axis, list.join(", ")));
    }
    if let Some(first) = r.poses.first() {
        let mut cells = vec!["pose".to_string()];
        cells.extend(first.commands.0.iter().map(|(a, _)| a.clone()));
        let rows: Vec<Vec<String>> = r
            .poses
            .iter()
            .map(|p| {
                let mut row = vec![p.label.clone()];
                row.extend(p.commands.0.iter().map(|(_, x)| fixed(*x, 3)));
                row
            })
            .collect();
        // `table` aligns its first two columns left; a pose row is a label, then numbers.
        let mut head = cells.clone();
        head.insert(1, String::new());
        let rows: Vec<Vec<String>> = rows
            .into_iter()
            .map(|mut row| {
                row.insert(1, String::new());
                row
            })
            .collect();
        out.push_str("\n(linear axes in mm, rotary axes in degrees)\n");
        out.push_str(&table(&head, &rows));
    }
    if !r.skipped.is_empty() {
        out.push_str(&format!(
            "\nSkipped ({} pose{} out of a stroke or range, or not reachable):\n",
            r.skipped.len(),
            plural(r.skipped.len(), "s")
        ));
        for s in &r.skipped {
            out.push_str(&format!("  {}: {}\n", s.label, s.reason));
        }
    }
    out
}

/// The table of parameters: std and valuation, or why there is none.
fn parameters(r: &PlanProbeReport) -> String {
    let rows: Vec<[String; 4]> = r
        .parameters
        .iter()
        .map(|p| {
            let (std, val) = match (p.std, p.valuation) {
                (Some(s), Some(v)) => (
                    format!("{} {}", value(s), symbol(&p.unit)),
                    format!(
                        "{} ({})",
                        fixed(v, 2),
                        p.grade.as_deref().unwrap_or_default()
                    ),
                ),
                _ if p.fixed => ("held at 0 (--constraint)".to_string(), String::new()),
                _ => {
                    let others = r
                        .confounded
                        .iter()
                        .find(|g| g.contains(&p.name))
                        .map(|g| {
                            g.iter()
                                .filter(|n| **n != p.name)
                                .cloned()
                                .collect::<Vec<_>>()
                                .join(", ")
                        })
                        .unwrap_or_default();
                    let why = if others.is_empty() {
                        "not determined: these poses do not see it".to_string()
                    } else {
                        format!("not determined: confounded with {others}")
                    };
                    (why, String::new())
                }
            };
            [p.name.clone(), p.owner.clone(), std, val]
        })
        .collect();
    table(
        &header(&["parameter", "owner", "predicted std", "valuation"]),
        &rows,
    )
}

/// Rank, groups, the valuation per axis, the targets and how N was chosen.
fn summary(r: &PlanProbeReport) -> String {
    let mut out = format!(
        "rank {} of {} parameters; condition number {} (column-scaled H)\n",
        r.rank,
        r.columns,
        r.condition
            .map_or("undefined (rank 0)".to_string(), |c| fixed(c, 1))
    );
    if !r.confounded.is_empty() {
        let groups: Vec<String> = r
            .confounded
            .iter()
            .map(|g| format!("[{}]", g.join(", ")))
            .collect();
        out.push_str(&format!(
            "confounded groups (these poses cannot separate them; no uncertainty for them): {}\n",
            groups.join(" ")
        ));
    }
    let axes: Vec<String> = r
        .axes
        .iter()
        .map(|a| match (a.valuation, &a.parameter) {
            (Some(v), Some(p)) => format!(
                "{} {} ({p}; {})",
                a.axis,
                fixed(v, 2),
                a.grade.as_deref().unwrap_or_default()
            ),
            _ if a.parameters.is_empty() => {
                format!("{} none (no parameter of it in the model)", a.axis)
            }
            _ => format!("{} none (none of its parameters is determined)", a.axis),
        })
        .collect();
    out.push_str(&format!(
        "valuation per rotary axis (target ÷ predicted std, the least among its determined parameters; the controllers need 2 or more, 4 or more is desirable): {}\n",
        axes.join(", ")
    ));
    out.push_str(&format!(
        "targets: {} µm, {} µrad\n",
        short(r.targets.um),
        short(r.targets.urad)
    ));
    if let Some(a) = &r.auto {
        let tried: Vec<String> = a
            .tried
            .iter()
            .map(|t| match (t.valuation, &t.parameter) {
                (Some(v), Some(p)) => format!("{}: {} ({p})", t.per_axis, fixed(v, 2)),
                _ => format!(
                    "{}: too few readings or nothing of interest determined",
                    t.per_axis
                ),
            })
            .collect();
        out.push_str(&format!(
            "auto: least valuation of interest per number of positions: {}\n",
            tried.join("; ")
        ));
        if a.met {
            out.push_str(&format!(
                "auto: {} positions per rotary axis give every determined parameter of interest a valuation of {} or more.\n",
                r.per_axis,
                short(r.min_valuation)
            ));
        } else {
            out.push_str(&format!(
                "auto: not even {} positions per rotary axis give every determined parameter of interest a valuation of {}: below it: {} (raise the targets, or move the sphere farther from the rotary axes).\n",
                r.per_axis,
                short(r.min_valuation),
                a.below.join(", ")
            ));
        }
    }
    out
}
