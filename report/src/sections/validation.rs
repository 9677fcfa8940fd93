//! Section 4: the validations: residual RMS and maximum per direction, on the nominal machine
//! and with the identified model, µm, and their figure; the measured error against the
//! identified model's prediction along each path.

use super::num;
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
        for (dir, d) in v.rows() {
            rows.push(vec![
                Cell::text(v.data.clone()),
                Cell::text(dir),
                Cell::number(num(d.measured_rms_um, 3)),
                Cell::number(num(d.measured_max_um, 3)),
                Cell::number(num(d.residual_rms_um, 3)),
                Cell::number(num(d.residual_max_um, 3)),
            ]);
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
        let mut s = format!(
            "{}: {} samples, predicted by {}{} (values of {}, report {})",
            v.data,
            v.samples,
            if v.prediction == "exact" {
                "the exact virtual machine at the identified values"
            } else {
                "the first-order model H·v"
            },
            if v.zeroed {
                ", zeroed at the first sample"
            } else {
                ""
            },
            v.params,
            file
        );
        if !v.unidentified_set_to_zero.is_empty() {
            s.push_str(&format!(
                "; not determined by the identification and set to 0: {}",
                v.unidentified_set_to_zero.join(", ")
            ));
        }
        notes.push(s);
    }
    b.list(&notes);
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
