//! A campaign identification and a campaign validation for people: what is shared and what
//! belongs to a set-up or a record, the records with their residuals, the shared values, one
//! block per set-up and per record, then the summary of the whole fit.

use super::identify::{method, parameter_table, summary};
use super::validate::residual_table_rows;
use super::{header, table, value, zeroed_text};
use crate::io::report::campaign::CampaignReport;
use crate::io::report::campaign_validate::CampaignValidationReport;
use crate::io::report::identify::IdentificationReport;
use model_spec::units::{plural, short};

/// The whole campaign identification text.
pub fn campaign_identification(r: &CampaignReport) -> String {
    let n = r.parameters.len();
    let mut out = format!(
        "Campaign identification: {} record{} on {} set-up{} ({} samples): machine {}, model {} ({n} parameter{})\n",
        r.records.len(),
        plural(r.records.len(), "s"),
        r.setups.len(),
        plural(r.setups.len(), "s"),
        r.samples,
        r.machine,
        r.model,
        plural(n, "s"),
    );
    let single = as_single(r);
    out.push_str(&method(&single));
    out.push_str(&format!(
        "Noise model (the uncertainties assume it; records independent): {}{}.\n",
        r.noise_model.text,
        r.noise_model
            .whitened_sigma
            .map_or(String::new(), |w| format!(
                "; σ̂ of the whitened residual {}",
                model_spec::units::fixed(w, 2)
            ))
    ));
    out.push_str(&ownership(r));
    out.push('\n');
    out.push_str(&records(r));
    let shared = r.parameters_of("shared", None);
    if !shared.is_empty() {
        out.push_str("\nShared (the machine's errors, one value for the campaign)\n");
        out.push_str(&parameter_table(&shared, &r.confounded));
    }
    for s in &r.setups {
        let p = r.parameters_of("setup", Some(&s.label));
        if p.is_empty() {
            continue;
        }
        out.push_str(&format!(
            "\nSet-up {} (records {})\n",
            s.label,
            s.records.join(", ")
        ));
        out.push_str(&parameter_table(&p, &r.confounded));
    }
    for rec in &r.records {
        let p = r.parameters_of("record", Some(&rec.label));
        if p.is_empty() {
            continue;
        }
        out.push_str(&format!(
            "\nRecord {} (readings {})\n",
            rec.label,
            zeroed_text(rec.zeroed)
        ));
        out.push_str(&parameter_table(&p, &r.confounded));
    }
    out.push('\n');
    out.push_str(&summary(&single));
    for note in r.notes.iter().filter(|n| n.starts_with("the set-up error")) {
        out.push_str(&format!("{note}\n"));
    }
    out
}

/// What is shared and what belongs to a set-up or a record, in this campaign.
fn ownership(r: &CampaignReport) -> String {
    let distinct = |owner: &str| -> Vec<String> {
        let mut v: Vec<String> = Vec::new();
        for p in r.parameters.iter().filter(|p| p.owner == owner) {
            let bare = p.parameter.name.split('[').next().unwrap_or("").to_string();
            if !v.contains(&bare) {
                v.push(bare);
            }
        }
        v
    };
    let mut out = String::new();
    let setup = distinct("setup");
    if !setup.is_empty() {
        out.push_str(&format!(
            "Per set-up (the ball's set-up errors, one set per set-up; records with the same set-up label share it): {}.\n",
            setup.join(" ")
        ));
    }
    let record = distinct("record");
    if !record.is_empty() {
        out.push_str(&format!(
            "Per record (the R-test's zero of zeroed records{}): {}.\n",
            if r.clock.is_some() {
                ", its drift"
            } else {
                ", drifts on each record's own clock"
            },
            record.join(" ")
        ));
    }
    out.push_str("Shared: every other term, the machine's errors.\n");
    if let Some(c) = &r.clock {
        out.push_str(&format!(
            "Campaign clock: the time bases run over {} .. {} s, every record placed by its start.\n",
            short(c.start_s),
            short(c.end_s)
        ));
    }
    out
}

/// The records: set-up, samples, zeroing, kinematic parameters that differ from the machine's
/// defaults, residual RMS.
fn records(r: &CampaignReport) -> String {
    let head = header(&[
        "record",
        "set-up",
        "data",
        "samples",
        "readings",
        "residual RMS µm",
        "parameters (mm)",
    ]);
    let rows: Vec<Vec<String>> = r
        .records
        .iter()
        .map(|x| {
            // The parameters that differ between the records (the ball's position).
            let params: Vec<String> = x
                .params
                .0
                .iter()
                .filter(|(k, v)| {
                    r.records
                        .iter()
                        .any(|o| o.params.0.iter().any(|(ok, ov)| ok == k && ov != v))
                })
                .map(|(k, v)| format!("{k} = {}", short(*v)))
                .collect();
            vec![
                x.label.clone(),
                x.setup.clone(),
                x.data.clone(),
                x.samples.to_string(),
                if x.zeroed { "zeroed" } else { "not zeroed" }.into(),
                value(x.residual_rms_um),
                if params.is_empty() {
                    "as the others".into()
                } else {
                    params.join(", ")
                },
            ]
        })
        .collect();
    table(&head, &rows)
}

/// The campaign report as a single report, for the lines they share (method, summary).
fn as_single(r: &CampaignReport) -> IdentificationReport {
    IdentificationReport {
        machine: r.machine.clone(),
        fingerprint: r.fingerprint.clone(),
        data: String::new(),
        model: r.model.clone(),
        base_model: r.base_model.clone(),
        terms: r.terms.clone(),
        parameters: r.parameters.iter().map(|p| p.parameter.clone()).collect(),
        residual_rms_um: r.residual_rms_um,
        rank: r.rank,
        free_parameters: r.free_parameters,
        condition: r.condition,
        confounded: r.confounded.clone(),
        samples: r.samples,
        readings: r.readings,
        dof: r.dof,
        zeroed: r.records.iter().any(|x| x.zeroed),
        constraint: r.constraint.clone(),
        sigma_um: r.sigma_um,
        near_confounded: r.near_confounded.clone(),
        swallowed: r.swallowed.clone(),
        gains: r.gains.clone(),
        refinement: r.refinement.clone(),
        noise_model: Some(r.noise_model.clone()),
        streaming: None,
        notes: r.notes.clone(),
    }
}

/// The whole campaign validation text.
pub fn campaign_validation(r: &CampaignValidationReport) -> String {
    let mut out = format!(
        "Validation on {} record{} ({} samples): machine {}, model {} with the values of {}\n",
        r.records.len(),
        plural(r.records.len(), "s"),
        r.samples,
        r.machine,
        r.model,
        r.params
    );
    out.push_str(&format!(
        "Prediction: {}; before = nominal machine (prediction 0), after = identified values.\n",
        if r.prediction == "exact" {
            "the exact virtual machine at each record's kinematic parameters"
        } else {
            "first-order model H·v (--first-order)"
        }
    ));
    out.push_str(
        "Shared values from the identification; a fitted set-up's values from it; a new set-up's errors, and the zero of a zeroed record, refitted on the record with everything else held.\n\n",
    );
    let mut rows: Vec<(
        String,
        [(&str, &crate::io::report::validate::DirectionReport); 4],
    )> = r
        .records
        .iter()
        .map(|x| (x.label.clone(), x.rows()))
        .collect();
    if r.records.len() > 1 {
        rows.push((
            "campaign".to_string(),
            [
                ("x", &r.per_direction.x),
                ("y", &r.per_direction.y),
                ("z", &r.per_direction.z),
                ("all", &r.overall),
            ],
        ));
    }
    out.push_str(&residual_table_rows(&rows));
    for x in &r.records {
        let from = match (x.setup_fitted, x.record_fitted) {
            (true, true) => "a fitted record".to_string(),
            (true, false) => format!("set-up {} (fitted)", x.setup),
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
                    let unit = model_spec::units::symbol(&p.unit);
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
            out.push_str(&format!(
                "{}: set to 0 in the prediction (no value: not determined by the identification): {}\n",
                x.label,
                x.unidentified_set_to_zero.join(", ")
            ));
        }
    }
    out
}
