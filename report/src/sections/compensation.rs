//! Section 6: the compensation: what was compensated and left out, the corrections per axis,
//! what remains, and the corrected description and tables written.

use super::{num, unit};
use crate::html::{Body, Cell};
use crate::inputs::Inputs;

/// Writes the compensation section.
pub fn write(b: &mut Body, inputs: &Inputs) {
    let (id, title) = super::SECTIONS[5];
    b.section(id, title);
    let Some((file, c)) = &inputs.compensation else {
        b.absent(inputs.no_compensation.as_deref().unwrap_or(
            "No compensation in this report (rtest compensate --json, or compensate --report).",
        ));
        b.end_section();
        return;
    };
    b.facts(&[
        ("Report", file.clone()),
        (
            "Values from",
            format!("{} (model {})", c.params_file, c.model),
        ),
        (
            "Commanded poses",
            format!("{} ({} poses, {})", c.input, c.poses, c.format),
        ),
        ("Corrected poses written to", c.output.clone()),
        (
            "Largest position remainder",
            format!("{} µm", num(c.position_remainder_um, 4)),
        ),
        (
            "Tool-axis orientation",
            if c.orientation_corrected {
                format!(
                    "corrected by the rotary axes; largest remaining tilt {} µrad",
                    num(c.tilt_remainder_urad, 3)
                )
            } else {
                format!(
                    "not corrected; largest tilt {} µrad",
                    num(c.tilt_remainder_urad, 3)
                )
            },
        ),
        (
            "Rotation about the tool axis (no axis removes it)",
            format!(
                "largest {} µrad, RMS {} µrad",
                num(c.roll_largest_urad, 3),
                num(c.roll_rms_urad, 3)
            ),
        ),
        ("Poses refined on the host", c.refined_poses.to_string()),
    ]);
    if !c.tilt_uncorrected_lines.is_empty() {
        let lines: Vec<String> = c
            .tilt_uncorrected_lines
            .iter()
            .map(usize::to_string)
            .collect();
        b.paragraph(&format!(
            "Lines where the tilt could not be fully corrected (near a singular pose): {}.",
            lines.join(", ")
        ));
    }
    if let Some(l) = &c.length_confounded {
        b.paragraph(&format!("Warning: {}", l.warning));
    }
    if !c.clamped.is_empty() {
        let each: Vec<String> = c.clamped.iter().map(|k| k.for_people()).collect();
        b.paragraph(&format!(
            "Corrected commands clamped to a stroke or range limit they passed by at most 0.01 mm or 0.01° (the pose keeps that much of its error): {}.",
            each.join("; ")
        ));
    }
    let rows: Vec<Vec<Cell>> = c
        .axes
        .iter()
        .map(|a| {
            vec![
                Cell::text(a.axis.clone()),
                Cell::number(num(a.largest, 3)),
                Cell::number(a.largest_line.to_string()),
                Cell::number(num(a.rms, 3)),
                Cell::number(a.rounding.map_or("exact (CSV)".into(), |r| num(r, 4))),
                Cell::text(unit(&a.unit)),
            ]
        })
        .collect();
    b.table(
        "Corrections per axis (linear axes in µm, rotary axes in µrad)",
        &["Axis", "Largest", "At line", "RMS", "Rounding", "Unit"],
        &rows,
    );
    b.subheading("Compensated");
    b.paragraph(&if c.compensated.is_empty() {
        "No machine error was compensated.".to_string()
    } else {
        c.compensated.join(", ")
    });
    if !c.left_out.is_empty() {
        let rows: Vec<Vec<Cell>> = c
            .left_out
            .iter()
            .map(|l| vec![Cell::text(l.term.clone()), Cell::text(l.reason.clone())])
            .collect();
        b.table("Left out of the compensation", &["Term", "Why"], &rows);
    }
    if let Some(k) = &c.kinematics {
        b.subheading(&format!("Corrected kinematic description: {}", k.file));
        b.list(&k.folded);
        if !k.not_folded.is_empty() {
            b.paragraph("Not folded into the description:");
            b.list(&k.not_folded);
        }
    }
    if !c.tables.is_empty() {
        b.subheading("Axis compensation tables written");
        b.list(&c.tables);
    }
    b.end_section();
}
