//! Section 3: the identified values with their standard uncertainties (µm, µrad), how well the
//! data determine them, and the groups the data could not separate. A campaign (several
//! records) lists its records with their ball positions and set-ups, then the shared values
//! (the machine's errors), one table per set-up and one per record.

use super::{num, opt, unit, value_std};
use crate::html::{Body, Cell};
use crate::inputs::{Inputs, MachineFacts};
use crate::json::identify::{IdentificationReport, ParameterReport, RecordReport};
use model_spec::units::{fixed, short};

/// What a parameter's status is, in words.
fn status(p: &ParameterReport) -> String {
    let mut s = if p.fixed {
        "fixed to 0 by the constraint".to_string()
    } else if p.determined {
        "determined".to_string()
    } else {
        "not determined by the data".to_string()
    };
    if let Some([lo, hi]) = p.over_mm {
        s.push_str(&format!(
            "; polynomial over the stroke {} to {} mm",
            short(lo),
            short(hi)
        ));
    }
    if let Some(nominal) = p.nominal_mm {
        s.push_str(&format!("; nominal {} mm", short(nominal)));
        match p.identified_mm {
            Some(Some(v)) => s.push_str(&format!(", identified {} mm", short(v))),
            Some(None) => s.push_str(", identified length not determined"),
            None => {}
        }
    }
    s
}

/// Writes the identification section.
pub fn write(b: &mut Body, inputs: &Inputs) {
    let (id, title) = super::SECTIONS[2];
    b.section(id, title);
    let Some((file, r)) = &inputs.identification else {
        b.absent("No identification in this report (rtest identify --json, or identify --report).");
        b.end_section();
        return;
    };
    let rf = &r.refinement;
    let fitted = match (&r.data, r.is_campaign()) {
        (Some(data), false) => format!("{data} ({} samples, {} readings)", r.samples, r.readings),
        _ => format!(
            "{} records on {} set-ups ({} samples, {} readings)",
            r.records.len(),
            r.setups.len(),
            r.samples,
            r.readings
        ),
    };
    let mut facts: Vec<(&str, String)> = vec![
        ("Report", file.clone()),
        (
            if r.is_campaign() {
                "Fitted records"
            } else {
                "Fitted record"
            },
            fitted,
        ),
        ("Residual RMS", format!("{} µm", num(r.residual_rms_um, 3))),
        (
            "σ̂ of a reading",
            r.sigma_um
                .map_or("none (no degree of freedom)".into(), |s| {
                    format!("{} µm", num(s, 3))
                }),
        ),
        (
            "Rank",
            format!(
                "{} of {} free parameters ({} degrees of freedom)",
                r.rank, r.free_parameters, r.dof
            ),
        ),
        ("Condition number", opt(r.condition, 1)),
        ("Constraint", r.constraint.clone()),
        (
            "Refinement",
            if rf.method == "exact" {
                format!(
                    "against the exact virtual machine: {} step{}, {}; first-order residual RMS {} µm",
                    rf.iterations,
                    model_spec::units::plural(rf.iterations, "s"),
                    if rf.converged {
                        "converged"
                    } else {
                        "not converged"
                    },
                    num(rf.first_order_rms_um, 3)
                )
            } else {
                "none: first-order least squares".to_string()
            },
        ),
    ];
    if let Some(n) = &r.noise_model {
        facts.push((
            "Noise model",
            format!(
                "{}{}",
                n.text,
                n.whitened_sigma.map_or(String::new(), |w| format!(
                    "; σ̂ of the whitened residual {}",
                    fixed(w, 2)
                ))
            ),
        ));
    }
    b.facts(&facts);
    if r.is_campaign() {
        campaign(b, r, inputs.machine.as_ref());
    } else {
        if let (Some(rec), Some(m)) = (r.records.first(), &inputs.machine) {
            let at = differing(rec, &r.records, Some(m));
            if !at.is_empty() {
                b.paragraph(&format!(
                    "The record was modelled with the kinematic parameters {} (mm), the others at the machine's defaults.",
                    at.join(", ")
                ));
            }
        }
        let all: Vec<&ParameterReport> = r.parameters.iter().collect();
        values_table(
            b,
            "Identified values and their standard uncertainties (translational errors and offsets in µm, angular errors in µrad)",
            &all,
        );
    }
    b.subheading("What the data could not separate");
    if r.confounded.is_empty() {
        b.paragraph("Every parameter is determined on its own: the data separate them all.");
    } else {
        b.paragraph("Each group below has only its combined effect determined by these data: no value of a member alone is reported (unless a constraint gave one). Another test path, or a constraint, separates them.");
        let groups: Vec<String> = r.confounded.iter().map(|g| g.join(", ")).collect();
        b.list(&groups);
    }
    if !r.near_confounded.is_empty() {
        let rows: Vec<Vec<Cell>> = r
            .near_confounded
            .iter()
            .map(|n| {
                vec![
                    Cell::text(n.parameters[0].clone()),
                    Cell::text(n.parameters[1].clone()),
                    Cell::number(fixed(n.correlation, 4)),
                ]
            })
            .collect();
        b.table(
            "Determined, but nearly confounded: pairs whose estimates correlate beyond 0.99",
            &["Parameter", "Parameter", "Correlation"],
            &rows,
        );
    }
    if !r.swallowed.is_empty() {
        let lines: Vec<String> = r
            .swallowed
            .iter()
            .map(|s| {
                if s.errors.is_empty() {
                    format!("{}: confounded with each other", s.offsets.join(", "))
                } else {
                    format!(
                        "{} swallow {} (readings zeroed at the first sample)",
                        s.offsets.join(", "),
                        s.errors.join(", ")
                    )
                }
            })
            .collect();
        b.subheading("What the zero offsets swallow");
        b.list(&lines);
    }
    if let Some(p) = &r.probe {
        super::probe::write(b, p);
    }
    if !r.notes.is_empty() {
        b.subheading("Notes of the identification");
        b.list(&r.notes);
    }
    b.end_section();
}

/// The rows of `params` in a table captioned `caption`.
fn values_table(b: &mut Body, caption: &str, params: &[&ParameterReport]) {
    let rows: Vec<Vec<Cell>> = params
        .iter()
        .map(|p| {
            vec![
                Cell::text(p.name.clone()),
                Cell::number(value_std(p.value, p.std)),
                Cell::text(unit(&p.unit)),
                Cell::text(status(p)),
            ]
        })
        .collect();
    b.table(
        caption,
        &["Parameter", "Value ± std", "Unit", "Status"],
        &rows,
    );
}

/// The kinematic parameters of `rec` that differ from the machine's defaults (when the machine
/// is known) or from another record's (when it is not), `Zw = 400` (mm); "as the machine's
/// defaults" (or "as the other records") when none does.
pub fn ball_position(
    rec: &RecordReport,
    records: &[RecordReport],
    machine: Option<&MachineFacts>,
) -> String {
    let parts = differing(rec, records, machine);
    if !parts.is_empty() {
        parts.join(", ")
    } else if machine.is_some() {
        "as the machine's defaults".into()
    } else {
        "as the other records".into()
    }
}

/// The kinematic parameters of `rec` that differ from the machine's defaults (when the machine
/// is known) or from another record's (when it is not), each `Zw = 400` (mm).
fn differing(
    rec: &RecordReport,
    records: &[RecordReport],
    machine: Option<&MachineFacts>,
) -> Vec<String> {
    let differs = |k: &str, v: f64| match machine {
        Some(m) => m
            .symbols
            .iter()
            .any(|(s, d)| s == k && d.to_bits() != v.to_bits()),
        None => records
            .iter()
            .any(|o| o.params.0.iter().any(|(ok, ov)| ok == k && *ov != v)),
    };
    rec.params
        .0
        .iter()
        .filter(|(k, v)| differs(k, *v))
        .map(|(k, v)| format!("{k} = {}", short(*v)))
        .collect()
}

/// A campaign's records and set-ups, its shared values and the values of each set-up and
/// record.
fn campaign(b: &mut Body, r: &IdentificationReport, machine: Option<&MachineFacts>) {
    let rows: Vec<Vec<Cell>> = r
        .records
        .iter()
        .map(|x| {
            vec![
                Cell::text(x.label.clone()),
                Cell::text(x.setup.clone()),
                Cell::text(x.data.clone()),
                Cell::number(x.samples.to_string()),
                Cell::text(if x.zeroed {
                    "zeroed at the first sample"
                } else {
                    "not zeroed"
                }),
                Cell::number(num(x.residual_rms_um, 3)),
                Cell::text(ball_position(x, &r.records, machine)),
            ]
        })
        .collect();
    b.table(
        if machine.is_some() {
            "Records: each with its ball set-up (records of one set-up share its set-up errors), its R-test zero, its residual RMS (µm) and the kinematic parameters (mm, the ball's position) that differ from the machine's defaults"
        } else {
            "Records: each with its ball set-up (records of one set-up share its set-up errors), its R-test zero, its residual RMS (µm) and the kinematic parameters (mm, the ball's position) that differ between the records"
        },
        &[
            "Record",
            "Set-up",
            "File",
            "Samples",
            "Readings",
            "Residual RMS",
            "Ball position",
        ],
        &rows,
    );
    if let Some(c) = &r.clock {
        b.paragraph(&format!(
            "The time bases run on one campaign clock, from {} s to {} s, every record placed by its start.",
            short(c.start_s),
            short(c.end_s)
        ));
    }
    let shared = r.parameters_of("shared", None);
    if !shared.is_empty() {
        b.subheading("Shared values: the machine's errors");
        values_table(
            b,
            "One value for the whole campaign, with its standard uncertainty (translational errors in µm, angular errors in µrad)",
            &shared,
        );
    }
    for s in &r.setups {
        let p = r.parameters_of("setup", Some(&s.label));
        if p.is_empty() {
            continue;
        }
        b.subheading(&format!("Set-up {}", s.label));
        values_table(
            b,
            &format!(
                "The ball's set-up errors of set-up {} (records {}), µm",
                s.label,
                s.records.join(", ")
            ),
            &p,
        );
    }
    for x in &r.records {
        let p = r.parameters_of("record", Some(&x.label));
        if p.is_empty() {
            continue;
        }
        b.subheading(&format!("Record {}", x.label));
        values_table(
            b,
            &format!(
                "The values of record {} alone: its R-test zero and drifts",
                x.label
            ),
            &p,
        );
    }
}
