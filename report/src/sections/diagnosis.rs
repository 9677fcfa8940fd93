//! Section 5: the diagnosis: the findings with their significance, the gain on the fitted and
//! the held-out records, the verdict against the noise, what remains unexplained, and the
//! figures.

use super::{num, unit, value_std};
use crate::html::{Body, Cell};
use crate::inputs::{Figure, Inputs};
use crate::json::diagnose::{DiagnosisReport, FindingReport, GroupReport};
use model_spec::units::{fixed, p_value, short};

/// A finding's value(s) with uncertainties; a harmonic with its amplitude and phase.
fn finding_value(f: &FindingReport) -> String {
    let mut parts: Vec<String> = f
        .columns
        .iter()
        .zip(f.values.iter().zip(&f.stds))
        .map(|(c, (v, s))| {
            if f.columns.len() > 1 {
                format!(
                    "{}: {}",
                    c.rsplit(':').next().unwrap_or(c),
                    value_std(*v, *s)
                )
            } else {
                value_std(*v, *s)
            }
        })
        .collect();
    if let Some(h) = &f.harmonic {
        parts.push(format!(
            "amplitude {}, phase {}°",
            value_std(Some(h.amplitude), h.amplitude_std),
            value_std(Some(h.phase_deg), h.phase_std_deg)
        ));
    }
    if let Some(s) = &f.scan {
        parts.push(format!(
            "{} = {} {} (95 % interval {} to {})",
            s.parameter,
            short(s.value),
            s.unit,
            short(s.low),
            short(s.high)
        ));
    }
    parts.join("; ")
}

/// Writes the diagnosis section, with its spectrum figure and the path figures.
pub fn write(
    b: &mut Body,
    inputs: &Inputs,
    spectrum: Option<&Figure>,
) -> Result<(), crate::RenderError> {
    let (id, title) = super::SECTIONS[4];
    b.section(id, title);
    let Some((file, d)) = &inputs.diagnosis else {
        b.absent("No diagnosis in this report (rtest diagnose --json, or diagnose --report).");
        b.end_section();
        return Ok(());
    };
    let fitted = d.records.iter().filter(|r| r.role == "fitted").count();
    b.facts(&[
        ("Report", file.clone()),
        (
            if fitted > 1 {
                "Fitted records"
            } else {
                "Fitted record"
            },
            format!("{} ({} samples)", d.data, d.samples),
        ),
        (
            "Base model",
            format!(
                "{}: residual RMS {} µm ({} µm with the outliers' samples)",
                d.base_model,
                num(d.base_fit.residual_rms_um, 3),
                num(d.base_fit.residual_rms_um_with_outliers, 3)
            ),
        ),
        ("Noise model", d.noise_model.clone()),
        (
            "Search",
            format!(
                "{} candidates (harmonics up to {}, Legendre order up to {}, time order up to {}); significance {} per step after the correction for the candidates tried",
                d.dictionary_size,
                d.dictionary_extent[0],
                d.dictionary_extent[1],
                d.dictionary_extent[2],
                short(d.alpha)
            ),
        ),
        ("Stopped", d.stop.reason.clone()),
    ]);
    records(b, d);
    if !d.notes.is_empty() {
        b.list(&d.notes);
    }
    b.subheading("Findings");
    if d.findings.is_empty() {
        b.paragraph("No significant effect beyond the base model.");
    } else {
        let rows: Vec<Vec<Cell>> = d
            .findings
            .iter()
            .map(|f| {
                vec![
                    Cell::text(format!("{}@{}", f.error, f.basis)),
                    Cell::text(f.description.clone()),
                    Cell::text(finding_value(f)),
                    Cell::text(unit(&f.unit)),
                    Cell::number(format!("{} %", fixed(100.0 * f.explained_fraction, 1))),
                    Cell::number(p_value(f.p_value)),
                    Cell::text(if f.alternatives.is_empty() {
                        f.status.clone()
                    } else {
                        format!("{}; not told from {}", f.status, f.alternatives.join(", "))
                    }),
                ]
            })
            .collect();
        b.table(
            "Effects found, in the order added (values in the extended model)",
            &[
                "Term",
                "What it is",
                "Value ± std",
                "Unit",
                "Explains",
                "p (corrected)",
                "Status",
            ],
            &rows,
        );
    }
    groups(b, d);
    if !d.dropped.is_empty() {
        let lines: Vec<String> = d
            .dropped
            .iter()
            .map(|x| format!("{}: {}", x.term, x.why))
            .collect();
        b.paragraph(
            "Selected, but left out: the fit of the extended model with them did not converge (the other findings were selected with them in the model):",
        );
        b.list(&lines);
    }
    if !d.confounded.is_empty() {
        let lines: Vec<String> = d
            .confounded
            .iter()
            .map(|c| {
                format!(
                    "{}@{}: a combination of {}",
                    c.error,
                    c.basis,
                    c.with.join(", ")
                )
            })
            .collect();
        b.paragraph(
            "Candidates the extended model already spans (the data cannot see them apart):",
        );
        b.list(&lines);
    }
    position_or_time(b, d);
    b.subheading("Gain");
    let mut rows = vec![gain_row("fitted", &d.gain.fit)];
    rows.extend(d.gain.validation.iter().map(|g| gain_row("held out", g)));
    b.table(
        &format!(
            "Residual RMS, µm: base model {} and extended model {}",
            d.base_model, d.extended_model.label
        ),
        &["Record", "Role", "Base", "Extended", "Counted"],
        &rows,
    );
    b.paragraph(&format!(
        "The extended model is {}.",
        if d.recommended {
            "recommended"
        } else {
            "not recommended"
        }
    ));
    b.list(&d.recommendation);
    b.subheading("What remains");
    match (&d.adequacy, &d.adequacy_unavailable) {
        (Some(a), _) => b.paragraph(&format!(
            "Test of the extended model's residual against the noise ({}): p = {} over {} record{} ({} draws): {}.",
            a.test,
            p_value(a.p_value),
            a.records.len(),
            model_spec::units::plural(a.records.len(), "s"),
            a.draws,
            if a.consistent_with_noise {
                "what remains is consistent with the noise"
            } else {
                "what remains is more than the noise"
            }
        )),
        (None, Some(why)) => b.paragraph(&format!("No test against the noise: {why}")),
        (None, None) => b.paragraph("No test against the noise."),
    }
    if !d.unexplained.is_empty() {
        let rows: Vec<Vec<Cell>> = d
            .unexplained
            .iter()
            .map(|u| {
                let mut shape = u.shape.clone();
                if let Some(p) = u.period {
                    shape.push_str(&format!(", period {} {}", short(p), u.unit));
                }
                if let Some(at) = u.at {
                    shape.push_str(&format!(", at {} {}", short(at), u.unit));
                }
                if let Some([a, z]) = u.samples {
                    shape.push_str(&format!(", samples {a} to {z}"));
                }
                vec![
                    Cell::text(u.data.clone()),
                    Cell::text(u.direction.clone()),
                    Cell::number(num(u.rms_um, 3)),
                    Cell::text(u.follows.clone().unwrap_or_else(|| "nothing simple".into())),
                    Cell::text(shape),
                    Cell::number(num(u.explained_rms_um, 3)),
                ]
            })
            .collect();
        b.table(
            "Unexplained: per direction the noise does not account for (RMS in µm)",
            &[
                "Record",
                "Direction",
                "RMS",
                "Follows",
                "Shape",
                "Shape explains",
            ],
            &rows,
        );
    }
    if !d.outliers.is_empty() {
        let rows: Vec<Vec<Cell>> = d
            .outliers
            .iter()
            .map(|o| {
                vec![
                    Cell::text(o.data.clone()),
                    Cell::number(o.line.map_or("–".into(), |l| l.to_string())),
                    Cell::number(o.sample.to_string()),
                    Cell::text(o.direction.clone()),
                    Cell::number(num(o.residual_um, 3)),
                    Cell::number(num(o.threshold_um, 3)),
                ]
            })
            .collect();
        b.table(
            "Outliers, left out of the fits (µm)",
            &[
                "Record",
                "Line",
                "Sample",
                "Direction",
                "Residual",
                "Threshold",
            ],
            &rows,
        );
    }
    if let Some(f) = spectrum {
        crate::place_figure(b, f)?;
    }
    b.subheading("Measured against predicted along the paths");
    if inputs.path_figures.is_empty() {
        b.absent(inputs.no_path_figures.as_deref().unwrap_or(
            "No path figures: they need the measurements, which the JSON reports do not hold; rtest diagnose --report draws them.",
        ));
    }
    for f in &inputs.path_figures {
        crate::place_figure(b, f)?;
    }
    b.end_section();
    Ok(())
}

/// The records, when there is more to say than their files: several fitted records, or held-out
/// records with parameters refitted on them (a new set-up's errors, their own zero and drifts).
/// A position error of an axis and a term of time that the records cannot tell apart (or that
/// the data tell apart against the selection's choice): both named, the records on which the
/// axis moves one way in time, and the test that separates them.
fn position_or_time(b: &mut Body, d: &DiagnosisReport) {
    if d.position_or_time.is_empty() {
        return;
    }
    let lines: Vec<String> = d
        .position_or_time
        .iter()
        .map(|e| {
            let mut line = format!(
                "{} (an error of {}'s position) and {} (in time): {}; the selection chose {}; {} moves one way in time on {}. To separate them, measure {}.",
                e.position,
                e.axis,
                e.time,
                e.verdict,
                e.chosen,
                e.axis,
                e.monotonic.join(", "),
                e.separating.join(" or ")
            );
            if let Some(c) = &e.plan_command {
                line.push_str(&format!(" Plan it first: {c}"));
            }
            line
        })
        .collect();
    b.paragraph("Position against time:");
    b.list(&lines);
}

fn records(b: &mut Body, d: &DiagnosisReport) {
    let fitted = d.records.iter().filter(|r| r.role == "fitted").count();
    let refitted = d.records.iter().any(|r| !r.refitted.is_empty());
    if fitted < 2 && !refitted {
        return;
    }
    let rows: Vec<Vec<Cell>> = d
        .records
        .iter()
        .map(|r| {
            vec![
                Cell::text(r.label.clone()),
                Cell::text(r.data.clone()),
                Cell::text(r.role.clone()),
                Cell::text(if r.setup_fitted || r.role == "fitted" {
                    r.setup.clone()
                } else {
                    format!("{} (new: refitted)", r.setup)
                }),
                Cell::number(r.samples.to_string()),
                Cell::number(num(r.residual_rms_before_um, 3)),
                Cell::number(num(r.residual_rms_after_um, 3)),
                Cell::text(if r.refitted.is_empty() {
                    "–".to_string()
                } else {
                    r.refitted.join(", ")
                }),
            ]
        })
        .collect();
    b.table(
        "Records: the machine's errors shared; each record with its own kinematic parameters, its set-up's errors and its own zero (residual RMS in µm)",
        &[
            "Record",
            "File",
            "Role",
            "Set-up",
            "Samples",
            "Base",
            "Extended",
            "Refitted on it",
        ],
        &rows,
    );
}

fn gain_row(role: &str, g: &crate::json::diagnose::GainRow) -> Vec<Cell> {
    vec![
        Cell::text(g.data.clone()),
        Cell::text(role),
        Cell::number(num(g.residual_rms_um_before, 3)),
        Cell::number(num(g.residual_rms_um_after, 3)),
        Cell::text(if g.estimable {
            "yes".to_string()
        } else {
            format!(
                "no: the prediction needs {} (not determined)",
                g.undetermined
                    .iter()
                    .map(|u| u.join(" + "))
                    .collect::<Vec<_>>()
                    .join("; ")
            )
        }),
    ]
}

/// The error groups selected after the findings: each one candidate of its directions, what
/// the judging records say of it, and whether it is in the extended model.
fn groups(b: &mut Body, d: &DiagnosisReport) {
    if d.groups.is_empty() {
        return;
    }
    b.subheading("Error groups");
    let rows: Vec<Vec<Cell>> = d.groups.iter().map(group_row).collect();
    b.table(
        "Error groups, each one candidate of its directions after the findings",
        &[
            "Group",
            "Members",
            "Directions",
            "F",
            "p (corrected)",
            "Judging records",
            "Extended model",
        ],
        &rows,
    );
    let undetermined: Vec<String> = d
        .groups
        .iter()
        .filter(|g| g.confirmed && !g.undetermined.is_empty())
        .map(|g| format!("{}: {}", g.name, g.undetermined.join(", ")))
        .collect();
    if !undetermined.is_empty() {
        b.paragraph(
            "Members these records do not determine (the extended model is identified with --constraint min-norm):",
        );
        b.list(&undetermined);
    }
}

/// One group's row.
fn group_row(g: &GroupReport) -> Vec<Cell> {
    let judged = match g.gain_sd {
        Some(z) => format!("gain {} standard deviations", fixed(z, 1)),
        None => "none can judge it: in the model on its p-value only below α·Φ̄(2)".into(),
    };
    let judged = if g.unjudged.is_empty() {
        judged
    } else {
        format!("{judged}; {} cannot judge it", g.unjudged.join(", "))
    };
    vec![
        Cell::text(g.name.clone()),
        Cell::text(g.terms.join(" ")),
        Cell::number(g.directions.to_string()),
        Cell::number(fixed(g.f, 1)),
        Cell::number(p_value(g.p_value)),
        Cell::text(judged),
        Cell::text(if g.confirmed { "in" } else { "left out" }.to_string()),
    ]
}
