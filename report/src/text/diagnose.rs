//! A diagnosis for people: the base fit, the residual structure, the findings with their
//! significance, what the data cannot see, the gain on the fitted and held-out records, and the
//! commands that use the extended model.

mod found;

use super::{header, indent, shell, table, value, wrap, zeroed_text};
use crate::json::diagnose::{DiagnosisReport, FindingReport, GainRow, RecordReport};
use model_spec::units::{fixed, p_value};

/// `ECC harmonic:2` from `ECC@harmonic:2` (a constant term is its name).
fn words(spelling: &str) -> String {
    spelling.replacen('@', " ", 1)
}

pub use found::{findings, values};

/// The residual RMS before and after, fitted and held out, as a table.
pub fn gain(r: &DiagnosisReport) -> String {
    let row = |name: String, g: &GainRow| {
        let (b, a) = (g.residual_rms_um_before, g.residual_rms_um_after);
        vec![
            name,
            value(b),
            value(a),
            if !g.estimable {
                "not counted: needs undetermined parameters".into()
            } else if b > 0.0 {
                format!("{:+.1} %", 100.0 * (a - b) / b)
            } else {
                "-".into()
            },
        ]
    };
    let mut rows = vec![row(format!("{} (fitted)", r.data), &r.gain.fit)];
    for g in &r.gain.validation {
        rows.push(row(format!("{} (held out)", g.data), g));
    }
    for g in &r.gain.left_out {
        rows.push(row(
            format!("{} (left out, fitted on the others)", g.data),
            g,
        ));
    }
    indent(
        &table(&header(&["data", "before µm", "after µm", "change"]), &rows),
        "  ",
    )
}

/// The verdict on the extended model: recommended or not, and why.
pub fn recommendation(r: &DiagnosisReport) -> String {
    let mut out = String::new();
    for g in r.gain.validation.iter().filter(|g| !g.estimable) {
        let groups: Vec<String> = g.undetermined.iter().map(|x| x.join(" ≡ ")).collect();
        out.push_str(&format!(
            "{}: the predictions need combinations the fit does not determine ({}); its RMS is not the model's error.\n",
            g.data,
            groups.join("; ")
        ));
    }
    if r.findings.is_empty() {
        return out;
    }
    if r.recommended {
        out.push_str(&format!("Recommended: {}.\n", r.recommendation.join("; ")));
    } else if r.findings.iter().all(|f| f.status == "jump") {
        out.push_str(&format!(
            "Not recommended: {}. The machine's errors fitted with the jump in place are the best this record gives (the gain above); no cause is named from a record that jumped.\n",
            r.recommendation.join("; ")
        ));
    } else {
        out.push_str(&format!(
            "Not recommended: {}. A finding may stand for one of the candidates the data cannot tell it from, or the fitted path does not separate the cause; try those alternatives (identify --terms) on the held-out data.\n",
            r.recommendation.join("; ")
        ));
    }
    out
}

/// The lack-of-fit test, and what remains where it fails.
pub fn adequacy(r: &DiagnosisReport) -> String {
    let Some(a) = &r.adequacy else {
        return format!(
            "Noise: no lack-of-fit test ({}); whether what remains is noise is not known.\n",
            r.adequacy_unavailable
                .as_deref()
                .unwrap_or("no noise model")
        );
    };
    let mut out = String::from(
        "Residual of the extended model against the noise (RMS, µm; bootstrap p-value):\n",
    );
    for rec in &a.records {
        let per: Vec<String> = (0..3)
            .map(|d| {
                format!(
                    "{} {} vs {} (p = {})",
                    ["x", "y", "z"][d],
                    fixed(rec.residual_sigma_um[d], 3),
                    fixed(rec.noise_sigma_um[d], 3),
                    p_value(rec.p_values[d])
                )
            })
            .collect();
        let role = if rec.fitted { "fitted" } else { "held out" };
        out.push_str(&format!("  {} ({role}): {}\n", rec.data, per.join("; ")));
    }
    if a.consistent_with_noise {
        out.push_str(&format!(
            "  Consistent with the noise (p = {} ≥ α = {}): the model explains the data down to the noise.\n",
            p_value(a.p_value),
            r.alpha
        ));
        if !r.unexplained.is_empty() {
            out.push_str("  The extended model holds a jump in time; the base model's residual where it jumped:\n");
            out.push_str(&unexplained(r));
        }
        return out;
    }
    let over: Vec<String> = a
        .records
        .iter()
        .flat_map(|rec| {
            rec.over_noise
                .iter()
                .map(move |d| format!("{} {d}", rec.data))
        })
        .collect();
    if a.p_value >= r.alpha && !over.is_empty() {
        out.push_str(&format!(
            "  NOT consistent with the noise: the residual is more than twice the noise in {} (p = {}). Unexplained:\n",
            over.join(", "),
            p_value(a.p_value)
        ));
    } else {
        out.push_str(&format!(
            "  NOT consistent with the noise (p = {} < α = {}). Unexplained:\n",
            p_value(a.p_value),
            r.alpha
        ));
    }
    out.push_str(&unexplained(r));
    out
}

/// What remains, described: one line per record and direction.
fn unexplained(r: &DiagnosisReport) -> String {
    let mut out = String::new();
    for u in &r.unexplained {
        let what = match (u.follows.as_deref(), u.shape.as_str()) {
            (None, _) | (_, "irregular") => "follows nothing simple (no shape of an axis position, velocity, direction of motion or time beats the noise)".to_string(),
            (Some(_), "local") => {
                let [a, b] = u.samples.unwrap_or([0, 0]);
                format!("a local deviation over samples {a}–{b}")
            }
            (Some(f), "periodic") => format!(
                "follows {f}: periodic, period {} {}",
                fixed(u.period.unwrap_or(f64::NAN), 3),
                u.unit
            ),
            (Some(f), "step") => format!(
                "follows {f}: a step near {} {}{}",
                fixed(u.at.unwrap_or(f64::NAN), 3),
                u.unit,
                u.sample
                    .map(|i| format!(" (a jump at sample {i})"))
                    .unwrap_or_default()
            ),
            (Some(f), shape) => format!("follows {f}: {shape}"),
        };
        let whose = if u.residual == "base" {
            " (base model, fitted record)"
        } else {
            ""
        };
        out.push_str(&format!(
            "  {} {}{whose}: {} µm RMS; {what} (explains {} µm RMS)\n",
            u.data,
            u.direction,
            fixed(u.rms_um, 3),
            fixed(u.explained_rms_um, 3)
        ));
    }
    out
}

/// The outliers found and left out, one line each.
pub fn outliers(r: &DiagnosisReport) -> String {
    if r.outliers.is_empty() {
        return String::new();
    }
    let mut out = format!(
        "Outliers ({}: isolated readings beyond {} robust scales of the residual's local deviation; left out of every fit, test and RMS):\n",
        r.outliers.len(),
        diagnosis::outliers::THRESHOLD
    );
    for o in &r.outliers {
        let place = o
            .line
            .map_or(format!("sample {}", o.sample), |l| format!("line {l}"));
        out.push_str(&format!(
            "  {}:{place} {}: residual {} µm (threshold {} µm)\n",
            o.data,
            o.direction,
            value(o.residual_um),
            value(o.threshold_um)
        ));
    }
    out
}

/// What to do with the result: the commands that use the extended model, or that nothing was
/// found.
pub fn next_steps(r: &DiagnosisReport) -> String {
    let data: Vec<String> = r.data_arguments.iter().map(|w| shell(w)).collect();
    let data = data.join(" ");
    let mut out = String::new();
    let causes: Vec<&FindingReport> = r.findings.iter().filter(|f| f.status == "cause").collect();
    if r.findings.is_empty() {
        out.push_str(&format!(
            "Nothing to add: no candidate of the dictionary is significant at α = {} after the correction for the candidates tried. {}\n",
            r.alpha,
            match &r.adequacy {
                Some(a) if a.consistent_with_noise => format!(
                    "The residual of model {} on {} ({} µm RMS) is consistent with the noise.",
                    r.base_model,
                    r.data,
                    value(r.base_fit.residual_rms_um)
                ),
                Some(_) => format!(
                    "The residual of model {} on {} ({} µm RMS) is not the noise: what remains is described above, and no candidate explains it.",
                    r.base_model,
                    r.data,
                    value(r.base_fit.residual_rms_um)
                ),
                None => format!(
                    "Whether the residual of model {} on {} ({} µm RMS) is noise is not known.",
                    r.base_model,
                    r.data,
                    value(r.base_fit.residual_rms_um)
                ),
            }
        ));
    } else if r.recommended {
        let terms: Vec<String> = causes
            .iter()
            .map(|f| {
                if f.basis == "const" {
                    f.error.clone()
                } else {
                    format!("{}@{}", f.error, f.basis)
                }
            })
            .collect();
        out.push_str(&format!(
            "Use the extended model: rtest identify --machine {} --model {} --terms {} {data}\n",
            shell(&r.machine_source),
            shell(&r.base_model),
            terms.join(","),
        ));
    }
    if let (Some(name), Some(file)) = (&r.extended_model.name, &r.extended_model.file) {
        out.push_str(&format!(
            "The extended model is `{name}` of {file}: rtest identify --machine {} --model {name} {data}; rtest generate --machine {} --model {name}\n",
            shell(file),
            shell(file)
        ));
    }
    out
}

/// The position errors of axes and the terms of time that the fitted records cannot tell apart
/// (or where the data prefer the term the selection did not choose), with the test that
/// separates them; empty when there is none.
pub fn position_or_time(r: &DiagnosisReport) -> String {
    let mut out = String::new();
    for e in &r.position_or_time {
        let other = if e.chosen == e.position {
            &e.time
        } else {
            &e.position
        };
        let why = format!(
            "{} moves monotonically in time on {}, so that there its position is a function of time: what each explains lies within the other's span to cosines {} and {} (given the rest of the model; nearly collinear from {} on)",
            e.axis,
            e.monotonic.join(", "),
            fixed(e.time_in_position, 4),
            fixed(e.position_in_time, 4),
            fixed(e.threshold, 2),
        );
        let tests = format!(
            "{} adds to {}: p = {}; {} adds to {}: p = {}",
            words(&e.position),
            words(&e.time),
            p_value(e.position_beyond_time_p),
            words(&e.time),
            words(&e.position),
            p_value(e.time_beyond_position_p),
        );
        let head = match e.verdict.as_str() {
            "cannot be told apart" => format!(
                "Cannot be told apart on these records: {} (an error of axis {} that depends on its position) and {} (a term of time). {why}, and neither adds significantly to the other ({tests}). The selection chose {}, {} is its alternative. A position error of an axis holds on every record, a drift is a record's own: {} is the physical reading, not confirmed by these records.",
                words(&e.position),
                e.axis,
                words(&e.time),
                words(&e.chosen),
                words(other),
                words(&e.position),
            ),
            _ => format!(
                "The data prefer {} to {} ({}): {why}, and only the one preferred adds significantly ({tests}). The selection chose {}, which the extended model keeps; {} is its alternative: refit with it in its place, or confirm with the test below.",
                words(other),
                words(&e.chosen),
                e.verdict,
                words(&e.chosen),
                words(other),
            ),
        };
        out.push_str(&format!("\n{head}\n"));
        if e.separating.is_empty() {
            out.push_str(
                "  To separate them, measure the same path reversed, or there and back in one record.\n",
            );
        } else {
            out.push_str(&format!(
                "  To separate them, measure {} (there and back in one record) or {} (the same poses reversed) with the campaign.\n",
                e.separating[0],
                e.separating.get(1).map_or("", String::as_str)
            ));
        }
        if let Some(c) = &e.plan_command {
            out.push_str(&format!("  Plan it first: {c}\n"));
        }
    }
    out
}

/// Why the selection stopped, one line.
pub fn stop(r: &DiagnosisReport) -> String {
    let best = r.stop.best_remaining.as_ref().map_or(String::new(), |t| {
        format!("; best remaining candidate: {}", words(t))
    });
    format!("Stopped: {}{best}.\n", r.stop.reason)
}

/// The residual components of the base fit, each with its size after the extension.
fn structure(r: &DiagnosisReport) -> String {
    let rows: Vec<Vec<String>> = r
        .structure
        .before
        .iter()
        .take(8)
        .map(|c| {
            vec![
                c.source.clone(),
                c.shape.clone(),
                c.direction.clone(),
                fixed(c.explained_rms_um, 4),
                c.extended_rms_um.map_or("-".into(), |a| fixed(a, 4)),
            ]
        })
        .collect();
    if rows.is_empty() {
        return "  none (nothing moves on this path)\n".into();
    }
    indent(
        &table(
            &header(&["axis", "shape", "dir", "base µm", "extended µm"]),
            &rows,
        ),
        "  ",
    )
}

/// The whole diagnosis text.
pub fn diagnosis(r: &DiagnosisReport) -> String {
    let mut out = format!(
        "Diagnosis on {} ({} samples, readings {}): machine {}, model {} ({} terms)\n",
        r.data,
        r.samples,
        zeroed_text(r.zeroed),
        r.machine,
        r.base_model,
        r.base_fit.terms.len()
    );
    if r.held_out.is_empty() {
        out.push_str("Held out: none (--validate gives files to measure the gain on)\n");
    } else {
        let h: Vec<String> = r
            .held_out
            .iter()
            .map(|(n, s)| format!("{n} ({s} samples)"))
            .collect();
        out.push_str(&format!("Held out (not fitted): {}\n", h.join(", ")));
    }
    out.push_str(&records(r));
    for n in &r.notes {
        out.push_str(&format!("Note: {n}.\n"));
    }
    out.push_str(&outliers(r));
    out.push_str(&format!("Noise model of every test: {}\n", r.noise_model));
    out.push_str(&format!(
        "\nBase fit: model {} on {}, refined against the exact machine: residual RMS {} µm, σ̂ {} ({} degrees of freedom)\n",
        r.base_model,
        r.data,
        value(r.base_fit.residual_rms_um),
        r.base_fit
            .sigma_um
            .map_or("undefined".into(), |s| format!("{} µm", value(s))),
        r.base_fit.dof
    ));
    out.push_str(
        "\nResidual structure of the base fit: the largest shapes, each fitted alone per direction (RMS of what it explains, µm; shapes of axes that move together overlap, so these are indications: the selection decides):\n",
    );
    out.push_str(&structure(r));
    let [k, p, t] = r.dictionary_extent;
    out.push_str(&format!(
        "\nCandidates: {} terms the model lacks (harmonic:1..{k} of rotary-axis errors, poly:1..{p} of linear-axis errors, reversal of positioning errors, const location, squareness and set-up errors, dx0 dy0 dz0 const and time:1..{t}; scanned: period:P and step:V of positioning errors, exp:TAU of the zero offsets and location errors, time:1 of location errors, velocity of positioning errors, the instrument terms SXX..SZY, jump:T of the set-up errors and zero offsets where one record is fitted); {} do not vary on {} (unexcited).\n",
        r.dictionary_size,
        r.unexcited.len(),
        r.data
    ));
    if !r.unexcited.is_empty() {
        out.push_str(&format!(
            "Unexcited ({}: their columns are zero at every sample of {}, so the data cannot excite them and no test is made of them; they are no finding, and not shown to be absent):\n",
            r.unexcited.len(),
            r.data
        ));
        out.push_str(&wrap(&r.unexcited, ", ", "  ", 100));
    }
    out.push_str(&format!(
        "Forward selection, significance α = {} per step after the correction for the candidates tried:\n",
        r.alpha
    ));
    if r.findings.is_empty() {
        out.push_str("  no finding\n");
    } else {
        out.push_str(&findings(r));
    }
    out.push_str(&stop(r));
    out.push_str(&found::groups(r));
    for x in &r.dropped {
        out.push_str(&format!(
            "Dropped: {} (selected, but the fit of the extended model with it failed: {}).\n",
            words(&x.term),
            x.why
        ));
    }
    if r.confounded.is_empty() {
        out.push_str("\nConfounded: none (the model spans no candidate)\n");
    } else {
        out.push_str(&format!(
            "\nConfounded ({}: the extended model spans them, the data cannot see them apart from what it has; candidate [model terms it is a combination of]):\n",
            r.confounded.len()
        ));
        let items: Vec<String> = r
            .confounded
            .iter()
            .map(|c| format!("{} {} [{}]", c.error, c.basis, c.with.join(" ")))
            .collect();
        out.push_str(&wrap(&items, "; ", "  ", 100));
    }
    out.push_str(&position_or_time(r));
    out.push_str(&format!(
        "\nGain: residual RMS, base model {} → extended model {}:\n",
        r.base_model, r.extended_model.label
    ));
    out.push_str(&gain(r));
    out.push_str(&adequacy(r));
    out.push_str(&recommendation(r));
    out.push('\n');
    out.push_str(&next_steps(r));
    out
}

/// The records of the diagnosis, when there is more to say than the file names: several fitted
/// records (set-up, samples, outliers, residual RMS before and after), or held-out records with
/// parameters refitted on them (a new set-up's errors, their own zero and drifts).
fn records(r: &DiagnosisReport) -> String {
    let fitted: Vec<&RecordReport> = r.records.iter().filter(|x| x.role == "fitted").collect();
    let held: Vec<&RecordReport> = r.records.iter().filter(|x| x.role != "fitted").collect();
    let mut out = String::new();
    if fitted.len() > 1 {
        let head = header(&[
            "record",
            "set-up",
            "data",
            "samples",
            "outliers",
            "base RMS µm",
            "extended RMS µm",
        ]);
        let rows: Vec<Vec<String>> = fitted
            .iter()
            .map(|x| {
                vec![
                    x.label.clone(),
                    x.setup.clone(),
                    x.data.clone(),
                    x.samples.to_string(),
                    r.outliers
                        .iter()
                        .filter(|o| o.data == x.data)
                        .count()
                        .to_string(),
                    value(x.residual_rms_before_um),
                    value(x.residual_rms_after_um),
                ]
            })
            .collect();
        out.push_str(
            "Campaign: the machine's errors shared; each record with its own kinematic parameters, its set-up's errors and its own zero.\n",
        );
        out.push_str(&table(&head, &rows));
    }
    for h in &held {
        if fitted.len() < 2 && h.refitted.is_empty() {
            continue;
        }
        let setup = if h.setup_fitted {
            format!("set-up {} (fitted: its values predict)", h.setup)
        } else {
            format!(
                "set-up {} (new: its set-up errors refitted on it, the machine's values held)",
                h.setup
            )
        };
        let refitted = if h.refitted.is_empty() {
            String::new()
        } else {
            format!(
                "; refitted on it (its residual is after them): {}",
                h.refitted.join(", ")
            )
        };
        out.push_str(&format!("Held out {}: {setup}{refitted}\n", h.label));
    }
    out
}
