//! Section 4: the validations: residual RMS and maximum per direction of every validated record,
//! on the nominal machine and with the identified model, µm, and their figure; for each record
//! its set-up (fitted, or new: its set-up errors refitted on it, the machine's values held) and
//! what was refitted; the measured error against the identified model's prediction along each
//! path.

use super::{num, unit, value_std};
use crate::html::{Body, Cell};
use crate::inputs::{Figure, Inputs};

/// Writes the validation section, with `figure` (the residual RMS per direction) when there
/// is one.
pub fn write(
    b: &mut Body,
    inputs: &Inputs,
    figure: Option<&Figure>,
) -> Result<(), crate::RenderError> {
    let (id, title) = super::SECTIONS[3];
    b.section(id, title);
    if inputs.validations.is_empty() {
        b.absent("No validation in this report (rtest validate --json).");
        paths(b, inputs)?;
        b.end_section();
        return Ok(());
    }
    let mut rows: Vec<Vec<Cell>> = Vec::new();
    for (_, v) in &inputs.validations {
        for x in &v.records {
            for (dir, d) in x.rows() {
                rows.push(vec![
                    Cell::text(x.data.clone()),
                    Cell::text(dir),
                    Cell::number(num(d.measured_rms_um, 3)),
                    Cell::number(num(d.measured_max_um, 3)),
                    Cell::number(num(d.residual_rms_um, 3)),
                    Cell::number(num(d.residual_max_um, 3)),
                ]);
            }
        }
    }
    b.table(
        "Residual per direction of the tool frame, µm: nominal machine (the measured error) and identified model (measured minus predicted)",
        &[
            "Record",
            "Direction",
            "Nominal RMS",
            "Nominal max",
            "Model RMS",
            "Model max",
        ],
        &rows,
    );
    let mut notes = Vec::new();
    for (file, v) in &inputs.validations {
        for x in &v.records {
            let mut s = format!(
                "{}: {} samples, predicted by {}{} (values of {}, report {})",
                x.data,
                x.samples,
                if v.prediction == "exact" {
                    "the exact virtual machine at the identified values"
                } else {
                    "the first-order model H·v"
                },
                if x.zeroed {
                    ", zeroed at the first sample"
                } else {
                    ""
                },
                v.params,
                file
            );
            if !x.unidentified_set_to_zero.is_empty() {
                s.push_str(&format!(
                    "; not determined by the identification and set to 0: {}",
                    x.unidentified_set_to_zero.join(", ")
                ));
            }
            notes.push(s);
        }
    }
    b.list(&notes);
    setups(b, inputs);
    if let Some(f) = figure {
        crate::place_figure(b, f)?;
    }
    paths(b, inputs)?;
    b.end_section();
    Ok(())
}

/// The measured error against the identified model's prediction along each path, and the
/// records not drawn with why.
fn paths(b: &mut Body, inputs: &Inputs) -> Result<(), crate::RenderError> {
    if inputs.prediction_figures.is_empty() && inputs.prediction_not_drawn.is_empty() {
        return Ok(());
    }
    b.subheading("Measured against predicted along the paths");
    if !inputs.prediction_not_drawn.is_empty() {
        b.list(&inputs.prediction_not_drawn);
    }
    for f in &inputs.prediction_figures {
        crate::place_figure(b, f)?;
    }
    Ok(())
}

/// Each validated record's set-up: one the identification fitted (its values used), or a new
/// one whose set-up errors (and the record's zero) were refitted on the record with the
/// machine's values held, with the refitted values.
fn setups(b: &mut Body, inputs: &Inputs) {
    let records: Vec<_> = inputs
        .validations
        .iter()
        .flat_map(|(_, v)| v.records.iter())
        .filter(|x| !x.setup.is_empty())
        .collect();
    if records.is_empty() {
        return;
    }
    b.subheading("Set-ups of the validated records");
    let rows: Vec<Vec<Cell>> = records
        .iter()
        .map(|x| {
            let from = match (x.setup_fitted, x.record_fitted) {
                (true, true) => "a fitted record: every value from the identification".to_string(),
                (true, false) => "fitted: its set-up values from the identification".to_string(),
                (false, _) => {
                    "new: its set-up errors refitted on the record, the machine's values held"
                        .to_string()
                }
            };
            let refitted = if x.refitted.is_empty() {
                "none".to_string()
            } else {
                x.refitted
                    .iter()
                    .map(|p| {
                        format!(
                            "{} = {} {}",
                            p.name,
                            value_std(p.value, p.std),
                            unit(&p.unit)
                        )
                    })
                    .collect::<Vec<_>>()
                    .join("; ")
            };
            vec![
                Cell::text(x.label.clone()),
                Cell::text(x.setup.clone()),
                Cell::text(from),
                Cell::text(refitted),
            ]
        })
        .collect();
    b.table(
        "Where each record's values came from: the identification's set-up, or a new set-up refitted on the record (the residual is then after those parameters: smaller than an independent prediction's by about √(1 − k/3N) for k refitted parameters)",
        &["Record", "Set-up", "Set-up values", "Refitted on the record"],
        &rows,
    );
}
