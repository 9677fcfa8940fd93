//! Section 1: the machine (its description when the verb has it) and the model.

use crate::html::{Body, Cell};
use crate::inputs::Inputs;

/// Writes the machine and model section.
pub fn write(b: &mut Body, inputs: &Inputs) {
    let (id, title) = super::SECTIONS[0];
    b.section(id, title);
    let mut facts: Vec<(&str, String)> = Vec::new();
    let name = inputs
        .machine
        .as_ref()
        .map(|m| m.name.clone())
        .or_else(|| {
            inputs
                .identification
                .as_ref()
                .map(|(_, r)| r.machine.clone())
        })
        .or_else(|| inputs.diagnosis.as_ref().map(|(_, r)| r.machine.clone()))
        .or_else(|| inputs.validations.first().map(|(_, r)| r.machine.clone()))
        .or_else(|| inputs.compensation.as_ref().map(|(_, r)| r.machine.clone()))
        .unwrap_or_default();
    facts.push(("Machine", name));
    if let Some(m) = &inputs.machine
        && !m.description.is_empty()
    {
        facts.push(("Description", m.description.clone()));
    }
    let fingerprint = inputs
        .machine
        .as_ref()
        .map(|m| m.fingerprint.clone())
        .or_else(|| {
            inputs
                .identification
                .as_ref()
                .map(|(_, r)| r.fingerprint.clone())
        });
    if let Some(f) = fingerprint {
        facts.push(("Fingerprint", f));
    }
    if let Some((_, r)) = &inputs.identification {
        facts.push(("Identified model", r.model.clone()));
        if r.is_campaign() {
            facts.push((
                "Campaign",
                format!(
                    "{} records on {} set-ups: the machine's errors shared, each set-up its ball set-up errors, each record its R-test zero",
                    r.records.len(),
                    r.setups.len()
                ),
            ));
        }
        if let Some(base) = &r.base_model {
            facts.push(("Base model", base.clone()));
        }
        facts.push(("Terms", r.terms.join(", ")));
        facts.push((
            "Gains",
            match r.gains.as_str() {
                "compiled" => "the compiled (generated) code".to_string(),
                "evaluator" => "the in-process evaluator".to_string(),
                other => other.to_string(),
            },
        ));
    } else if let Some((_, c)) = &inputs.compensation {
        facts.push(("Compensated model", c.model.clone()));
    } else if let Some((_, v)) = inputs.validations.first() {
        facts.push(("Validated model", v.model.clone()));
    }
    if let Some((_, d)) = &inputs.diagnosis {
        facts.push(("Diagnosed model", d.base_model.clone()));
        facts.push(("Extended model", d.extended_model.label.clone()));
    }
    b.facts(&facts);
    match &inputs.machine {
        Some(m) => {
            let rows: Vec<Vec<Cell>> = m
                .axes
                .iter()
                .map(|a| {
                    vec![
                        Cell::text(a[0].clone()),
                        Cell::text(a[1].clone()),
                        Cell::text(a[2].clone()),
                        Cell::number(a[3].clone()),
                    ]
                })
                .collect();
            b.table("Axes", &["Axis", "Kind", "Chain", "Stroke"], &rows);
        }
        None => b.absent(
            "The axes are not listed: the reports name the machine only (give --machine to rtest report to list them).",
        ),
    }
    b.end_section();
}
