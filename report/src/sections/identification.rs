//! Section 3: the identified values with their standard uncertainties (µm, µrad), how well the
//! data determine them, and the groups the data could not separate.

use super::{num, opt, unit, value_std};
use crate::html::{Body, Cell};
use crate::inputs::Inputs;
use model_spec::units::{fixed, short};
use solver::io::report::identify::ParameterReport;

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
    let mut facts: Vec<(&str, String)> = vec![
        ("Report", file.clone()),
        (
            "Fitted record",
            format!(
                "{} ({} samples, {} readings)",
                r.data, r.samples, r.readings
            ),
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
    let rows: Vec<Vec<Cell>> = r
        .parameters
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
        "Identified values and their standard uncertainties (translational errors and offsets in µm, angular errors in µrad)",
        &["Parameter", "Value ± std", "Unit", "Status"],
        &rows,
    );
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
    if !r.notes.is_empty() {
        b.subheading("Notes of the identification");
        b.list(&r.notes);
    }
    b.end_section();
}
