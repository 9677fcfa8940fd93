//! Section 4: the validations: residual RMS and maximum per direction of every validated record,
//! on the nominal machine and with the identified model, µm, and their figure; for each record
//! its set-up (fitted, or new: its set-up errors refitted on it, the machine's values held) and
//! what was refitted; the verdicts against a tolerance file, before and after (ISO 14253-1);
//! the measured error against the identified model's prediction along each path, or at each
//! pose of a touch probe's records.

use super::{num, unit, value_std};
use crate::html::{Body, Cell};
use crate::inputs::{Figure, Inputs};
use crate::json::tolerance::{QuantityReport, VerdictReport};
use model_spec::units::{fixed, significant};

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
    verdicts(b, inputs);
    setups(b, inputs);
    if let Some(f) = figure {
        crate::place_figure(b, f)?;
    }
    paths(b, inputs)?;
    b.end_section();
    Ok(())
}

/// The measured error against the identified model's prediction along each path (at each pose,
/// for a touch probe's records), and the records not drawn with why.
fn paths(b: &mut Body, inputs: &Inputs) -> Result<(), crate::RenderError> {
    if inputs.prediction_figures.is_empty() && inputs.prediction_not_drawn.is_empty() {
        return Ok(());
    }
    let probe = inputs
        .identification
        .as_ref()
        .is_some_and(|(_, id)| id.probe.is_some());
    if probe {
        b.subheading("Measured against predicted at the probe's poses");
        b.paragraph(
            "Per pose, not along a path: the records are a touch probe's, each pose one reading of the error vector through its sphere fit (section 3 gives the fits and the centres' dispersion per rotary axis).",
        );
    } else {
        b.subheading("Measured against predicted along the paths");
    }
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

/// A verdict as a cell: its word, in bold when it is not a pass.
fn verdict_cell(v: VerdictReport) -> Cell {
    let name = v.name();
    Cell::Markup(match v {
        VerdictReport::Pass => format!("<span class=\"verdict-{name}\">{name}</span>"),
        _ => format!("<strong class=\"verdict-{name}\">{name}</strong>"),
    })
}

/// Value, U and verdict of one quantity in one state; empty cells without it.
fn quantity_cells(q: Option<&QuantityReport>) -> [Cell; 3] {
    match q {
        Some(q) => [
            Cell::number(fixed(q.value_um, 3)),
            Cell::number(fixed(q.expanded_um, 3)),
            verdict_cell(q.verdict),
        ],
        None => [Cell::text(""), Cell::text(""), Cell::text("")],
    }
}

/// The verdicts of every validation given a tolerance file: per test and direction, each
/// quantity before (the readings) and after (readings minus prediction), with U, and the
/// test's verdict; the counts, the noise and the rule.
fn verdicts(b: &mut Body, inputs: &Inputs) {
    for (file, v) in &inputs.validations {
        let Some(t) = &v.tolerance else {
            continue;
        };
        b.subheading(&format!("Verdicts against the tolerances of {}", t.file));
        let mut rows: Vec<Vec<Cell>> = Vec::new();
        for x in &t.tests {
            let quantities = [
                (
                    "max |deviation|",
                    x.before.max.as_ref(),
                    x.after.max.as_ref(),
                ),
                ("range", x.before.range.as_ref(), x.after.range.as_ref()),
            ];
            for (what, before, after) in quantities {
                let Some(limit) = before.or(after).map(|q| q.tolerance_um) else {
                    continue;
                };
                let mut row = vec![
                    Cell::text(format!("{} ({})", x.name, x.record)),
                    Cell::text(x.direction.clone()),
                    Cell::text(what),
                    Cell::number(fixed(limit, 3)),
                ];
                row.extend(quantity_cells(before));
                row.extend(quantity_cells(after));
                rows.push(row);
            }
            if x.max_um.is_some() && x.range_um.is_some() {
                let row = vec![
                    Cell::text(format!("{} ({})", x.name, x.record)),
                    Cell::text(x.direction.clone()),
                    Cell::text("the test"),
                    Cell::text(""),
                    Cell::text(""),
                    Cell::text(""),
                    verdict_cell(x.before.verdict),
                    Cell::text(""),
                    Cell::text(""),
                    verdict_cell(x.after.verdict),
                ];
                rows.push(row);
            }
        }
        b.table(
            &format!(
                "Verdict per test and direction (ISO 14253-1, k = {}), µm: before = the readings (the machine as measured), after = readings minus the identified model's prediction (the machine as the model would leave it once compensated); U the expanded uncertainty (report {file})",
                significant(t.coverage_k)
            ),
            &[
                "Test (record)",
                "Direction",
                "Quantity",
                "Tolerance",
                "Before",
                "U",
                "Before verdict",
                "After",
                "U",
                "After verdict",
            ],
            &rows,
        );
        let s = &t.noise.sigma_um;
        let c = &t.counts;
        b.list(&[
            format!(
                "Before: {} pass, {} fail, {} undecided. After: {} pass, {} fail, {} undecided.",
                c.before.pass,
                c.before.fail,
                c.before.undecided,
                c.after.pass,
                c.after.fail,
                c.after.undecided
            ),
            format!(
                "Reading noise σ = {} (x), {} (y), {} µm (z): {}.",
                fixed(s[0], 3),
                fixed(s[1], 3),
                fixed(s[2], 3),
                t.noise.source
            ),
            format!("Rule: {}.", t.rule),
        ]);
    }
}
