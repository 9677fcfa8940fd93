//! Section 2: the data: every record the reports name with its samples (a campaign's each with
//! its label and set-up), and every input file with its size and SHA-256.

use crate::html::{Body, Cell};
use crate::inputs::Inputs;

/// Writes the data section.
pub fn write(b: &mut Body, inputs: &Inputs) {
    let (id, title) = super::SECTIONS[1];
    b.section(id, title);
    let mut rows: Vec<Vec<Cell>> = Vec::new();
    let mut row = |role: &str, file: &str, samples: String, note: String| {
        rows.push(vec![
            Cell::text(role),
            Cell::text(file),
            Cell::number(samples),
            Cell::text(note),
        ]);
    };
    if let Some((_, r)) = &inputs.identification {
        for x in &r.records {
            row(
                "identification: fitted",
                &x.data,
                x.samples.to_string(),
                format!(
                    "{} readings{}{}",
                    3 * x.samples,
                    if x.zeroed {
                        ", zeroed at the first sample"
                    } else {
                        ""
                    },
                    if r.is_campaign() {
                        format!("; record {}, set-up {}", x.label, x.setup)
                    } else {
                        String::new()
                    }
                ),
            );
        }
    }
    for (_, v) in &inputs.validations {
        for x in &v.records {
            let mut note = Vec::new();
            if x.zeroed {
                note.push("zeroed at the first sample".to_string());
            }
            if !x.setup.is_empty() {
                note.push(format!(
                    "set-up {}{}",
                    x.setup,
                    if x.setup_fitted { "" } else { " (new)" }
                ));
            }
            row(
                "validation",
                &x.data,
                x.samples.to_string(),
                note.join("; "),
            );
        }
    }
    if let Some((_, d)) = &inputs.diagnosis {
        row(
            "diagnosis: fitted",
            &d.data,
            d.samples.to_string(),
            if d.zeroed {
                "zeroed at the first sample".into()
            } else {
                String::new()
            },
        );
        for (f, n) in &d.held_out {
            row("diagnosis: held out", f, n.to_string(), String::new());
        }
    }
    if let Some((_, c)) = &inputs.compensation {
        row(
            "compensation: commanded poses",
            &c.input,
            c.poses.to_string(),
            format!("format {}", c.format),
        );
    }
    b.table(
        "Records (paths as the verbs were given them)",
        &["Role", "File", "Samples", "Note"],
        &rows,
    );
    if inputs.files.is_empty() {
        b.absent("No input file was hashed.");
    } else {
        let rows: Vec<Vec<Cell>> = inputs
            .files
            .iter()
            .map(|f| match &f.digest {
                Ok(digest) => vec![
                    Cell::text(f.role.clone()),
                    Cell::text(f.path.clone()),
                    Cell::number(digest.bytes.to_string()),
                    Cell::text(f.modified.clone().unwrap_or_else(|| "–".into())),
                    Cell::Markup(format!(
                        "<span class=\"hash\">{}</span>",
                        crate::html::escape(&digest.sha256)
                    )),
                ],
                Err(why) => vec![
                    Cell::text(f.role.clone()),
                    Cell::text(f.path.clone()),
                    Cell::number("–"),
                    Cell::text(f.modified.clone().unwrap_or_else(|| "–".into())),
                    Cell::text(format!("not hashed: {why}")),
                ],
            })
            .collect();
        b.table(
            "Input files: size, last modification (UTC, as the file system gives it) and SHA-256, as read when this report was written",
            &["Role", "Path", "Bytes", "Modified", "SHA-256"],
            &rows,
        );
    }
    if let Some(t) = &inputs.written_at {
        b.facts(&[("Report written", t.clone())]);
    }
    b.end_section();
}
