//! A validation for people, of one record or several: residual RMS and max per direction and
//! overall (µm), before (the nominal machine) and after (the model), per record and over all of
//! them, and what was refitted on each record; with a tolerance file, the verdicts
//! ([`super::tolerance`]).

use super::{header, table, value, zeroed_text};
use crate::json::recheck::RecheckReport;
use crate::json::validate::{DirectionReport, RecordValidationReport, ValidationReport};
use model_spec::units::{fixed, plural, readable, symbol};
use simulation::record::Record;

/// The note printed when the first reading of `record` is exactly zero but the readings were not
/// declared `zeroed`; empty otherwise.
pub fn zeroed_note(record: &Record, zeroed: bool) -> &'static str {
    if record.looks_zeroed() && !zeroed {
        "Note: the first reading is exactly 0: if the readings were zeroed at the first sample, give --zeroed.\n"
    } else {
        ""
    }
}

/// The whole validation text: the residual of every record (and over all of them when there
/// are several), then per record where its values came from and what was refitted on it.
pub fn validation(r: &ValidationReport) -> String {
    let mut text = match (&r.data, r.is_campaign()) {
        (Some(data), false) => format!(
            "Validation on {data} ({} samples, readings {}): machine {}, model {} with the values of {}\n",
            r.samples,
            zeroed_text(r.zeroed.unwrap_or(false)),
            r.machine,
            r.model,
            r.params
        ),
        _ => format!(
            "Validation on {} record{} ({} samples): machine {}, model {} with the values of {}\n",
            r.records.len(),
            plural(r.records.len(), "s"),
            r.samples,
            r.machine,
            r.model,
            r.params
        ),
    };
    text.push_str(&format!(
        "Prediction: {}; before = nominal machine (prediction 0), after = identified values.\n",
        if r.prediction == "exact" {
            "the exact virtual machine at the identified values, at each record's kinematic parameters"
        } else {
            "first-order model H·v (--first-order)"
        }
    ));
    text.push_str(
        "Shared values from the identification; a fitted set-up's values from it; a new set-up's errors, and the zero of a zeroed record, refitted on the record with everything else held.\n\n",
    );
    let mut rows: Vec<(String, [(&str, &DirectionReport); 4])> = r
        .records
        .iter()
        .map(|x| (x.label.clone(), x.rows()))
        .collect();
    if r.records.len() > 1 {
        rows.push(("campaign".to_string(), r.rows()));
    }
    text.push_str(&residual_table_rows(&rows));
    let one = r.records.len() == 1;
    for x in &r.records {
        text.push_str(&record_line(x, one));
    }
    if let Some(c) = &r.recheck {
        text.push_str(&recheck(c));
    }
    if let Some(t) = &r.tolerance {
        text.push_str(&super::tolerance::verdicts(t));
    }
    text
}

/// The re-check: the machine parameters refitted beside the calibration's values, their
/// changes, and the scale of the uncertainties.
pub fn recheck(c: &RecheckReport) -> String {
    let mut out = format!(
        "\nRe-check: {} refitted over every record, with each record's set-up when it is new (the preset) and its zero when zeroed, every other value held at the calibration's ({} degree{} of freedom; uncertainties at {}):\n",
        c.refit.join(", "),
        c.dof,
        plural(c.dof, "s"),
        c.scale_text()
    );
    let head = header(&[
        "parameter",
        "unit",
        "calibrated",
        "± σ",
        "re-checked",
        "± σ",
        "change",
        "z",
    ]);
    let opt = |x: Option<f64>| x.map_or_else(|| "undetermined".to_string(), value);
    let cells: Vec<Vec<String>> = c
        .pivot
        .iter()
        .map(|p| {
            vec![
                p.name.clone(),
                symbol(&p.unit).to_string(),
                opt(p.calibrated),
                p.calibrated_std.map_or_else(String::new, value),
                opt(p.value),
                p.std.map_or_else(String::new, value),
                p.change.map_or_else(String::new, value),
                p.change_z.map_or_else(String::new, |z| fixed(z, 2)),
            ]
        })
        .collect();
    out.push_str(&table(&head, &cells));
    out.push_str(
        "The re-check's uncertainties hold its own readings' noise, not the calibration's uncertainty of the held values; z is the change over both uncertainties.\n",
    );
    out
}

/// Where a record's values came from, what was refitted on it, and what was set to 0 (`one`:
/// the only record validated, its sentence without its label).
fn record_line(x: &RecordValidationReport, one: bool) -> String {
    let mut out = String::new();
    let from = match (x.setup_fitted, x.record_fitted) {
        (true, true) => "a fitted record".to_string(),
        (true, false) => format!("set-up {} (fitted)", x.setup),
        (false, _) if x.setup.is_empty() => "set-up not recorded".to_string(),
        (false, _) => format!("set-up {} (new: not fitted)", x.setup),
    };
    if x.refitted.is_empty() {
        out.push_str(&format!(
            "{}: {from}; every value from the identification.\n",
            x.label
        ));
    } else {
        let items: Vec<String> = x
            .refitted
            .iter()
            .map(|p| {
                let unit = symbol(&p.unit);
                match (p.value, p.std) {
                    (Some(v), Some(s)) => {
                        format!("{} = {} ± {} {unit}", p.name, value(v), value(s))
                    }
                    (Some(v), None) => format!("{} = {} {unit}", p.name, value(v)),
                    _ => format!("{} (not separable on this record)", p.name),
                }
            })
            .collect();
        out.push_str(&format!(
            "{}: {from}; refitted on the record ({} parameter{}, the residual is after them): {}\n",
            x.label,
            x.refitted.len(),
            plural(x.refitted.len(), "s"),
            items.join(", ")
        ));
    }
    if !x.unidentified_set_to_zero.is_empty() {
        let who = if one {
            "Set to 0".to_string()
        } else {
            format!("{}: set to 0", x.label)
        };
        out.push_str(&format!(
            "{who} in the prediction (no value: not determined by the identification): {}\n",
            x.unidentified_set_to_zero.join(", ")
        ));
    }
    out
}

/// The line naming the parameters set to 0 (over every record), or nothing.
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
