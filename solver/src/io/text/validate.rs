//! A validation for people: residual RMS and max per direction and overall (µm), before (the
//! nominal machine) and after (the model).

use super::{header, table, zeroed_text};
use crate::io::report::validate::{DirectionReport, ValidationReport};
use crate::record::Record;
use model_spec::units::{fixed, readable};

/// The note printed when the first reading of `record` is exactly zero but the readings were not
/// declared `zeroed`; empty otherwise.
pub fn zeroed_note(record: &Record, zeroed: bool) -> &'static str {
    if record.looks_zeroed() && !zeroed {
        "Note: the first reading is exactly 0: if the readings were zeroed at the first sample, give --zeroed.\n"
    } else {
        ""
    }
}

/// The whole validation text.
pub fn validation(r: &ValidationReport) -> String {
    let mut text = format!(
        "Validation on {} ({} samples, readings {}): machine {}, model {} with the values of {}\n",
        r.data,
        r.samples,
        zeroed_text(r.zeroed),
        r.machine,
        r.model,
        r.params
    );
    text.push_str(&format!(
        "Prediction: {}; before = nominal machine (prediction 0), after = identified model.\n\n",
        if r.prediction == "exact" {
            "the exact virtual machine at the identified values"
        } else {
            "first-order model H·v (--first-order)"
        }
    ));
    text.push_str(&residual_table(&[(r.data.as_str(), r)]));
    text.push_str(&defaulted_note(r));
    text
}

/// The line naming the parameters set to 0, or nothing.
pub fn defaulted_note(r: &ValidationReport) -> String {
    if r.unidentified_set_to_zero.is_empty() {
        String::new()
    } else {
        format!(
            "Set to 0 in the prediction (no value: not determined by the identification): {}\n",
            r.unidentified_set_to_zero.join(", ")
        )
    }
}

/// Residual RMS and max per direction and overall (µm), before and after, one block of rows
/// per validation (name, report).
pub fn residual_table(rows: &[(&str, &ValidationReport)]) -> String {
    let blocks: Vec<(String, [(&str, &DirectionReport); 4])> = rows
        .iter()
        .map(|(name, r)| (name.to_string(), r.rows()))
        .collect();
    residual_table_rows(&blocks)
}

/// Residual RMS and max (µm), before and after, one block of rows (x, y, z, all) per name.
pub fn residual_table_rows(blocks: &[(String, [(&str, &DirectionReport); 4])]) -> String {
    let head = header(&[
        "data",
        "dir",
        "before RMS µm",
        "before max µm",
        "after RMS µm",
        "after max µm",
    ]);
    let mut cells = Vec::new();
    for (name, rows) in blocks {
        for (i, (dir, s)) in rows.iter().enumerate() {
            cells.push(vec![
                if i == 0 {
                    name.to_string()
                } else {
                    String::new()
                },
                dir.to_string(),
                fixed(s.measured_rms_um, 3),
                fixed(s.measured_max_um, 3),
                readable(s.residual_rms_um, 3),
                readable(s.residual_max_um, 3),
            ]);
        }
    }
    table(&head, &cells)
}
