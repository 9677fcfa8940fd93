//! A diagnosis for people: the base fit, the residual structure, the findings with their
//! significance, what the data cannot see, the gain on the fitted and held-out records, and the
//! commands that use the extended model.

use super::{header, indent, shell, table, value, wrap, zeroed_text};
use crate::io::report::diagnose::{
    ConfirmationReport, DiagnosisReport, FindingReport, GainRow, RecordReport,
};
use model_spec::units::{fixed, p_value, symbol};

/// `ECC harmonic:2` from `ECC@harmonic:2` (a constant term is its name).
fn words(spelling: &str) -> String {
    spelling.replacen('@', " ", 1)
}

/// How the p-value of a finding was corrected, for people.
fn correction(f: &FindingReport, draws: usize) -> String {
    if f.correction == "bonferroni" {
        format!(
            "Bonferroni-corrected: raw p × {} candidates tried",
            f.candidates_tried
        )
    } else {
        format!(
            "corrected by a Monte-Carlo null of the selection over the {} candidates tried ({draws} draws)",
            f.candidates_tried
        )
    }
}

/// `7.7512 ± 0.3012 (cos), 6.1003 ± 0.2710 (sin) µrad`.
pub fn values(f: &FindingReport) -> String {
    let parts: Vec<String> = f
        .values
        .iter()
        .zip(&f.stds)
        .enumerate()
        .map(|(i, (v, s))| {
            let v = v.map_or("not determined".into(), value);
            let s = s.map_or(String::new(), |s| format!(" ± {}", value(s)));
            let suffix = if f.columns.len() > 1 {
                let n = &f.columns[i];
                format!(" ({})", n.rsplit(':').next().unwrap_or(n))
            } else {
                String::new()
            };
            format!("{v}{s}{suffix}")
        })
        .collect();
    format!("{} {}", parts.join(", "), symbol(&f.unit))
}

/// The findings, one block each: name, values, amplitude and phase, share, F and p,
/// alternatives.
pub fn findings(r: &DiagnosisReport) -> String {
    let mut out = String::new();
    for (i, f) in r.findings.iter().enumerate() {
        let unit = symbol(&f.unit);
        out.push_str(&format!("  {}. {}: {}\n", i + 1, f.description, values(f)));
        if let Some(sc) = &f.scan {
            out.push_str(&format!(
                "     {} = {} {} (95 % interval {} .. {} from the profile of the fit; the values' stds are conditional on it)\n",
                sc.parameter,
                fixed(sc.value, 3),
                sc.unit,
                fixed(sc.low, 3),
                fixed(sc.high, 3)
            ));
        }
        if !f.plausible {
            out.push_str(&format!(
                "     fits, but implausible: size {} {unit} beyond the budget of {} {unit}; not a cause, left out of the extended model\n",
                value(f.size),
                value(f.limit)
            ));
        } else {
            out.push_str(&confirmation(f));
        }
        if let (Some(h), Some(k)) = (&f.harmonic, f.basis.strip_prefix("harmonic:")) {
            let pm = |s: Option<f64>, digits: usize| {
                s.map_or(String::new(), |s| format!(" ± {}", fixed(s, digits)))
            };
            let axis = f.axis.as_deref().unwrap_or("θ");
            out.push_str(&format!(
                "     amplitude {}{} {unit}, phase {}{}° (amplitude·cos({k}·{axis} − phase))\n",
                value(h.amplitude),
                pm(h.amplitude_std, 4),
                fixed(h.phase_deg, 1),
                pm(h.phase_std_deg, 1),
            ));
        }
        out.push_str(&format!(
            "     explains {} % of the base model's residual (sum of squares); F = {}, p = {} ({})\n",
            fixed(100.0 * f.explained_fraction, 1),
            fixed(f.f, 1),
            p_value(f.p_value),
            correction(f, r.draws)
        ));
        if !f.alternatives.is_empty() {
            let alts: Vec<String> = f.alternatives.iter().map(|t| words(t)).collect();
            out.push_str(&format!(
                "     the data cannot tell it from: {}\n",
                alts.join(", ")
            ));
        }
    }
    out
}

/// What the held-out (or left-out) records say of a plausible finding, and its status when it
/// is not a cause.
fn confirmation(f: &FindingReport) -> String {
    let mut out = String::new();
    if f.status == "jump" {
        out.push_str("     a jump in time of the fitted record: the ball or the sensor moved during the record; it predicts nothing on another record and is no cause of the machine: measure the record again
");
    }
    let Some(c) = &f.confirmation else {
        if f.status != "cause" && f.status != "jump" {
            out.push_str("     fits the fitted record, but not confirmed: no record was held out to check it; not a cause\n");
        }
        return out;
    };
    let by = if c.judged_by == "left-out" {
        "the fitted records (each left out in turn, predicted by the others)"
    } else {
        "the held-out records"
    };
    let tried = |c: &ConfirmationReport| -> String {
        c.tried
            .iter()
            .map(|t| format!("{} {}", words(&t.term), fixed(t.gain_sd, 1)))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if !c.unjudged.is_empty() {
        out.push_str(&format!(
            "     {} cannot judge it: the fit on the other records does not determine what it predicts there{}\n",
            c.unjudged.join(", "),
            if c.not_judged {
                " (determined only by the record left out: no other record can confirm it)"
            } else {
                ""
            }
        ));
    }
    if c.not_judged {
        out.push_str(if c.confirmed {
            "     in the extended model on the fitted records alone: its corrected p-value is below α·Φ̄(2), the rate a judged finding's two tests allow\n"
        } else {
            "     not in the extended model: judged by no record, and its corrected p-value is not below α·Φ̄(2), the rate a judged finding's two tests allow\n"
        });
    } else if let Some(original) = &c.replaces {
        out.push_str(&format!(
            "     chosen by {by} among the alternatives of {}: held-out gain {} standard deviations of a spurious one's (tried: {})\n",
            words(original),
            fixed(c.gain_sd, 1),
            tried(c)
        ));
    } else if c.confirmed {
        out.push_str(&format!(
            "     confirmed on its own by {by}: held-out gain given the other findings {} standard deviations of a spurious one's\n",
            fixed(c.gain_sd, 1)
        ));
    } else {
        out.push_str(&format!(
            "     fits the fitted record, but not confirmed on its own by {by}: held-out gain given the other findings {} standard deviations of a spurious one's (2 needed); not a cause{}\n",
            fixed(c.gain_sd, 1),
            if c.tried.is_empty() {
                String::new()
            } else {
                format!(
                    "; in its place, given the confirmed findings: {} (none chosen)",
                    tried(c)
                )
            }
        ));
    }
    if c.confirmed && f.status != "cause" && f.status != "jump" {
        out.push_str("     not a cause: the extended model is not recommended (below)\n");
    }
    out
}

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
        crate::diagnosis::outliers::THRESHOLD
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
    out.push_str(&groups(r));
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

/// The error groups selected after the findings, each with what the judging records say.
fn groups(r: &DiagnosisReport) -> String {
    let mut out = String::new();
    if r.groups.is_empty() {
        return out;
    }
    out.push_str("Error groups, each one candidate of its directions after the findings:\n");
    for g in &r.groups {
        out.push_str(&format!(
            "  {} ({}): {} directions, F = {}, p = {}; {}{}{}\n",
            g.name,
            g.terms.join(" "),
            g.directions,
            fixed(g.f, 1),
            p_value(g.p_value),
            match g.gain_sd {
                Some(z) => format!(
                    "gain on the records that judge it {} standard deviations",
                    fixed(z, 1)
                ),
                None =>
                    "no record can judge it: in the model on its p-value only below α·Φ̄(2)".into(),
            },
            if g.unjudged.is_empty() {
                String::new()
            } else {
                format!(" ({} cannot judge it)", g.unjudged.join(", "))
            },
            if g.confirmed {
                "; in the extended model"
            } else {
                "; not in the extended model"
            }
        ));
        if g.confirmed && !g.undetermined.is_empty() {
            out.push_str(&format!(
                "    not determined by these records: {} (identify with --constraint min-norm)\n",
                g.undetermined.join(" ")
            ));
        }
    }
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
