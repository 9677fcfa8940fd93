//! `rtest demo`: the seed's experiment on the virtual seed machine (`seed-ac`) with the
//! documented demo truth: simulate K4, K1 and K2, identify the reduced model on K4, validate on
//! K1 and K2, say what is left unexplained and why, diagnose what the reduced model lacks (with
//! K1 and K2 held out), and write everything to `./rtest-demo/`.

use super::data;
use super::diagnose as diag;
use super::validate::{defaulted_note, residual_table};
use super::{CliError, CliResult, Compiled, EXIT_CODES};
use codegen::table::{self, render};
use model_spec::{FULL_MODEL, Machine};
use solver::diagnosis::{DiagnoseOptions, Diagnosis, diagnose};
use solver::fitting::IdentifyOptions;
use solver::fitting::refine::exact_prediction;
use solver::fitting::validate::{ValidateOptions, Validation, statistics, validate};
use solver::io::csv::format_record;
use solver::io::json::{display_factor, identify_json, validate_json};
use solver::model::Model;
use solver::record::Record;
use solver::simulation::readings::{provenance, simulate};
use solver::simulation::truth::Truth;
use std::path::Path;
use std::time::Instant;

/// The machine of the demo.
const MACHINE: &str = "seed-ac";
/// Its reduced model (Table 2).
const REDUCED: &str = "reduced";
/// Directory the demo writes to, relative to the working directory.
const OUT_DIR: &str = "rtest-demo";
/// The paths simulated, and the offset of each one's noise seed from the truth's.
const PATHS: [(&str, u64); 3] = [("K4", 0), ("K1", 1), ("K2", 2)];
/// The extended machine description the demo writes.
const EXTENDED_FILE: &str = "seed-ac-extended.toml";
/// The seed's deviations (measured minus predicted) on K4, and on K1 and K2, µm.
const SEED_DEVIATION_UM: (f64, f64) = (12.0, 15.0);

/// Flags of `rtest demo`.
#[derive(Debug, clap::Args)]
#[command(
    about = "The seed's experiment on the virtual seed machine; writes ./rtest-demo/",
    long_about = "\
The main job of rtest on the seed's five-axis machine (seed-ac), with the documented demo truth \
seed-ac-demo (docs/truth.md): location errors of A and C and ball set-up errors of 10-30 µm and \
µrad, plus an angular positioning error of C twice per revolution (ECC@harmonic:2, 10 µrad) \
that the reduced model lacks, and 0.5 µm of R-test noise.

1. Simulates K4 (241 samples), K1 (361) and K2 (121) on the exact virtual machine (noise seeds 1, \
2, 3).
2. Identifies the reduced model (the seed's Table 2: XOW YOW ZOW YOA ZOA BOA COA XOC YOC AOC BOC) \
on K4, refined against the exact machine, and prints the values against the truth with their \
standard uncertainties (µm, µrad), like the seed's Table 4.
3. Validates on K1 and K2 (and on K4 itself): residual RMS and max per direction in µm, before \
(nominal machine) and after (identified model, exact prediction), compared with the seed's \
±12 µm (K4) and ±15 µm (K1, K2).
4. Says what is left unexplained and why: the truth's terms the reduced model lacks, how much \
they move the readings and how they bias the 11 values.
5. Diagnoses the reduced model on K4 with K1 and K2 held out (rtest diagnose): the missing term \
found from the data alone, named as an ISO 230 error with its value ± std (µm, µrad), its \
significance, and the residual RMS before and after on K4, K1 and K2; then checks it against the \
truth (known here, not used by the diagnosis).

Writes, in ./rtest-demo/ (created if needed; every file computed first, then replaced \
atomically): k4.csv, k1.csv, k2.csv (the measurements: axes in mm and degrees, readings in µm), \
identify.json (rtest identify --json), validate-k1.json and validate-k2.json (rtest validate \
--json), seed_ac.rs (generated no_std Rust gains of the full and reduced models), \
gains-reduced.md (the Markdown gain table of the reduced model, mm/mm and mm/rad), \
diagnose.json (rtest diagnose --json), seed-ac-extended.toml (the machine with the extended \
model, rtest diagnose --model-out) and the figures of rtest diagnose --plot: k4-path.svg, \
k1-path.svg, k2-path.svg (measured against predicted error, base and extended model) and \
k4-spectrum.svg, k1-spectrum.svg, k2-spectrum.svg (residual components before and after). The \
same steps one by one: rtest simulate / identify / validate / diagnose.",
    after_help = EXIT_CODES
)]
pub struct DemoArgs {}

/// One simulated path.
struct Run {
    name: &'static str,
    file: String,
    truth: Truth,
    record: Record,
    csv: String,
}

fn fail(what: impl std::fmt::Display) -> CliError {
    CliError::failure(format!("demo: {what}"))
}

/// Runs `rtest demo`.
pub fn run(_args: &DemoArgs) -> CliResult {
    let start = Instant::now();
    let m = super::load_machine(MACHINE)?;
    let truth = data::default_truth(&m)?;
    let model = Model::of(&m, REDUCED)
        .ok_or_else(|| fail(format!("machine {MACHINE} has no model {REDUCED}")))?;

    // 1. Simulations.
    let mut runs = Vec::new();
    for (name, offset) in PATHS {
        let path = solver::simulation::paths::builtin_path(&m, name)
            .ok_or_else(|| fail(format!("no built-in path {name}")))?
            .map_err(fail)?;
        let mut t = truth.clone();
        t.seed = truth.seed.wrapping_add(offset);
        let record = simulate(&m, &t, &path).map_err(fail)?;
        let comments = provenance(&m, name, &t, record.samples.len());
        let csv = format_record(&m, &record, &comments).map_err(fail)?;
        runs.push(Run {
            name,
            file: format!("{}.csv", name.to_ascii_lowercase()),
            truth: t,
            record,
            csv,
        });
    }
    let k4 = &runs[0];

    // 2. Identification on K4, refined against the exact machine.
    let result = data::identify(&m, &model, &k4.record, &IdentifyOptions::default(), true)?;
    let ident = &result.ident;
    let identify = identify_json(&m, REDUCED, ident);

    // 3. Validation on every path (K4: the fit itself), exact prediction.
    let exact = ValidateOptions {
        exact: true,
        ..Default::default()
    };
    let validations: Vec<Validation> = runs
        .iter()
        .map(|r| validate(&m, &ident.model, &ident.fit.values, &r.record, &exact))
        .collect::<Result<_, _>>()
        .map_err(fail)?;

    // 4. What the reduced model lacks: the truth's other terms, their effect alone, and the fit
    //    with them added.
    let hidden = Model {
        terms: truth
            .model
            .terms
            .iter()
            .filter(|t| !model.terms.contains(t))
            .copied()
            .collect(),
    };
    let hidden_values: Vec<Option<f64>> = hidden
        .terms
        .iter()
        .flat_map(|t| truth.coefficient(t).unwrap_or(&[]).to_vec())
        .map(Some)
        .collect();
    let hidden_rms: Vec<f64> = runs
        .iter()
        .map(|r| {
            let p = exact_prediction(&m, &hidden, &hidden_values, &r.record, &truth.params)?;
            let zeros = vec![[0.0; 3]; p.len()];
            Ok(statistics(&p, &zeros).1.measured_rms)
        })
        .collect::<Result<_, solver::simulation::readings::SimulateError>>()
        .map_err(fail)?;
    // The bias the hidden terms put into the reduced model's values: the first-order fit of
    // their readings alone on K4 (noise-free).
    let bias: Option<Vec<Option<f64>>> = if hidden.terms.is_empty() {
        None
    } else {
        let measured = exact_prediction(&m, &hidden, &hidden_values, &k4.record, &truth.params)
            .map_err(fail)?;
        let alone = Record {
            samples: k4.record.samples.clone(),
            measured,
        };
        let b = data::identify(&m, &model, &alone, &IdentifyOptions::default(), false)?;
        Some(b.ident.fit.values)
    };
    // 5. The diagnosis of the reduced model on K4, K1 and K2 held out: what it lacks, found
    //    from the data alone (the truth is used only for the check printed after it).
    let dir = Path::new(OUT_DIR);
    let path_of = |f: &str| dir.join(f).display().to_string();
    let opts = DiagnoseOptions::default();
    let held: Vec<(String, Record)> = runs[1..]
        .iter()
        .map(|r| (path_of(&r.file), r.record.clone()))
        .collect();
    let diagnosis = diagnose(&m, &model, &k4.record, &held, &opts).map_err(fail)?;
    let extended = diag::extended_terms(&model, &diagnosis);
    let machine_text = diag::machine_text(MACHINE)?;
    let (ext_name, ext_text) = diag::extended_machine(
        &m,
        &machine_text,
        &extended,
        &format!(
            "{} (rtest demo: the diagnosis of the reduced model on K4)",
            diag::extended_label(&m, REDUCED, &diagnosis)
        ),
    )
    .map_err(fail)?;
    let k4_path = path_of(&k4.file);
    let diag_run = diag::Run {
        machine: MACHINE,
        label: REDUCED,
        data: &k4_path,
        samples: k4.record.samples.len(),
        held: held
            .iter()
            .map(|(n, r)| (n.clone(), r.samples.len()))
            .collect(),
        opts: &opts,
        model_out: Some((ext_name, path_of(EXTENDED_FILE))),
    };
    let diag_json = diag::diagnosis_json(&m, &diag_run, &diagnosis, &extended);
    let mut figure_records = vec![(k4_path.clone(), &k4.record, true)];
    figure_records.extend(held.iter().map(|(n, r)| (n.clone(), r, false)));
    let figures = diag::plots(&m, &diag_run, &diagnosis, &figure_records).map_err(fail)?;

    // Files people take away.
    let code = codegen::emit::generate_machine(&m, &[]).map_err(fail)?;
    let full = Compiled::new(&m, &m.errors);
    let reduced = Compiled::new(&m, &model.errors());
    let markdown = render(
        &m,
        &reduced.model,
        &super::gains::title(&m, Some(REDUCED), reduced.model.errors.len()),
        table::Format::Markdown,
    );
    let mut files: Vec<(String, String, String)> = Vec::new();
    for r in &runs {
        files.push((
            r.file.clone(),
            r.csv.clone(),
            format!(
                "{} measurement: {} samples; axes mm and degrees, readings µm",
                r.name,
                r.record.samples.len()
            ),
        ));
    }
    files.push((
        "identify.json".into(),
        serde_json::to_string_pretty(&identify).map_err(fail)? + "\n",
        "the reduced model identified on K4, as rtest identify --json writes it".into(),
    ));
    for (r, v) in runs.iter().zip(&validations).skip(1) {
        let name = format!("validate-{}.json", r.name.to_ascii_lowercase());
        let body = serde_json::to_string_pretty(&validate_json(&path_of(&r.file), v))
            .map_err(fail)?
            + "\n";
        files.push((
            name,
            body,
            format!(
                "validation on {}, as rtest validate --json writes it",
                r.name
            ),
        ));
    }
    files.push((
        "seed_ac.rs".into(),
        code,
        "generated no_std Rust gains of the full and reduced models".into(),
    ));
    files.push((
        "gains-reduced.md".into(),
        markdown,
        "gain table of the reduced model, the seed's Table 2, Markdown".into(),
    ));
    files.push((
        "diagnose.json".into(),
        diag_json.render(),
        "the diagnosis of the reduced model on K4, as rtest diagnose --json writes it".into(),
    ));
    files.push((
        EXTENDED_FILE.into(),
        ext_text,
        "seed-ac with the extended model appended ([models.extended]), as rtest diagnose --model-out writes it".into(),
    ));
    for (name, svg) in figures {
        let what = if name.ends_with("-path.svg") {
            "measured and predicted error along the path (base and extended model), x, y, z"
        } else {
            "residual components before and after the extension"
        };
        files.push((name, svg, format!("figure: {what}")));
    }

    // The summary.
    let mut out = String::from(
        "rtest demo: the seed's experiment (fit the reduced model on K4, check it on K1 and K2) on the virtual seed machine\n\n",
    );
    out.push_str(&machine_line(&m));
    out.push_str(&format!(
        "Truth {} (docs/truth.md): {}\n  {}\n",
        truth.source,
        truth.description,
        truth.summary(&m).replace(" um", " µm")
    ));
    out.push_str(&format!(
        "Simulated on the exact virtual machine: {}.\n\n",
        runs.iter()
            .map(|r| format!(
                "{} ({} samples, noise seed {})",
                r.name,
                r.record.samples.len(),
                r.truth.seed
            ))
            .collect::<Vec<_>>()
            .join(", ")
    ));

    out.push_str(&format!(
        "Identified on K4: reduced model (the seed's Table 2), refined against the exact machine ({}); like the seed's Table 4:\n\n",
        result.refinement.as_ref().map_or("not refined".into(), |r| format!(
            "{} Gauss-Newton step{}",
            r.iterations,
            if r.iterations == 1 { "" } else { "s" }
        ))
    ));
    out.push_str(&truth_table(&m, &truth, &result.ident, bias.as_deref()));
    let fit = &ident.fit;
    out.push_str(&format!(
        "rank {} of {}, condition number {}, residual RMS {} µm, σ̂ {} µm; confounded groups: {}; near-confounded pairs: {}\n\n",
        fit.rank,
        fit.names.len(),
        fit.condition.map_or("undefined".into(), |c| format!("{c:.1}")),
        data::um(fit.residual_rms()),
        fit.sigma.map_or("undefined".into(), data::um),
        if fit.identifiability.confounded.is_empty() {
            "none".to_string()
        } else {
            format!("{:?}", identify.confounded)
        },
        if fit.identifiability.near_confounded.is_empty() {
            "none".to_string()
        } else {
            format!("{}", fit.identifiability.near_confounded.len())
        },
    ));

    out.push_str(
        "Residual (measured - predicted), µm: before = nominal machine, after = identified model (exact prediction):\n\n",
    );
    let rows: Vec<(String, &Validation)> = runs
        .iter()
        .zip(&validations)
        .map(|(r, v)| {
            (
                if r.name == "K4" {
                    "K4 (fit)".to_string()
                } else {
                    r.name.to_string()
                },
                v,
            )
        })
        .collect();
    let rows: Vec<(&str, &Validation)> = rows.iter().map(|(n, v)| (n.as_str(), *v)).collect();
    out.push_str(&residual_table(&rows));
    for v in &validations {
        out.push_str(&defaulted_note(v));
    }
    let max_after = |i: usize| validations[i].overall.residual_max * 1e3;
    out.push_str(&format!(
        "\nThe seed's real machine left deviations within ±{} µm on K4 and ±{} µm on K1 and K2; here the largest are {:.2} µm (K4), {:.2} µm (K1) and {:.2} µm (K2), with {} µm of noise.\n",
        SEED_DEVIATION_UM.0,
        SEED_DEVIATION_UM.1,
        max_after(0),
        max_after(1),
        max_after(2),
        solver::io::csv::format_scaled(truth.noise_mm, 3)
    ));
    if hidden.terms.is_empty() {
        out.push_str("The truth has nothing the reduced model lacks: what is left is the noise.\n");
    } else {
        out.push_str(&unexplained(&m, &hidden, &hidden_values, &hidden_rms));
    }
    out.push_str(&diagnosis_text(
        &m,
        &diag_run,
        &diagnosis,
        &truth,
        &hidden,
        truth.noise_mm,
    ));
    out.push_str("\nCompiled straight-line code (per evaluation of all gains):\n");
    for (name, c) in [(FULL_MODEL, &full), (REDUCED, &reduced)] {
        out.push_str(&format!(
            "  {name:<8} {:>2} errors: {}\n",
            c.model.errors.len(),
            c.program.op_counts()
        ));
    }

    // Everything is computed; now write.
    std::fs::create_dir_all(dir).map_err(|e| {
        CliError::failure(format!("demo: cannot create directory `{OUT_DIR}`: {e}"))
    })?;
    out.push_str(&format!("\nWrote {OUT_DIR}/:\n"));
    for (name, contents, what) in &files {
        super::write_atomic("demo", &dir.join(name), contents)?;
        out.push_str(&format!("  {}  ({what})\n", path_of(name)));
    }
    out.push_str(&format!(
        "\nDone in {:.2} s. The same steps one by one: rtest simulate, rtest identify, rtest validate, rtest diagnose (see --help).\n",
        start.elapsed().as_secs_f64()
    ));
    print!("{out}");
    Ok(())
}

/// The machine and its kinematic parameters, one line.
fn machine_line(m: &Machine) -> String {
    let params: Vec<String> = m
        .symbols
        .iter()
        .filter(|s| s.default != 0.0)
        .map(|s| format!("{} = {}", s.name, super::short(s.default)))
        .collect();
    format!(
        "Machine {}: {}\n  kinematic parameters (the seed's Table 3, mm): {}\n",
        m.name,
        m.description,
        params.join(", ")
    )
}

/// The identified values against the truth: one row per parameter with the truth, the
/// estimate ± std, their difference in std, and (with `bias`: one value per parameter, mm or
/// rad) the shift the truth's hidden terms put into the estimate and the difference without it.
fn truth_table(
    m: &Machine,
    truth: &Truth,
    ident: &solver::fitting::Identification,
    bias: Option<&[Option<f64>]>,
) -> String {
    let fit = &ident.fit;
    let columns = ident.model.columns();
    let mut rows = Vec::new();
    for (j, &(t, k)) in columns.iter().enumerate() {
        let term = ident.model.terms[t];
        let f = display_factor(m, term.effect);
        let true_value = truth.coefficient(&term).map_or(0.0, |c| c[k]) * f;
        let b = bias
            .and_then(|b| b.get(j).copied().flatten())
            .map(|b| b * f);
        let z = |v: f64, s: f64| format!("{:+.2}", v / s);
        let (value, std, z0, z1) = match (fit.values[j], fit.std[j]) {
            (Some(v), Some(s)) => (
                data::people(v * f),
                data::people(s * f),
                z(v * f - true_value, s * f),
                b.map_or("-".into(), |b| z(v * f - true_value - b, s * f)),
            ),
            (Some(v), None) => (data::people(v * f), "-".into(), "-".into(), "-".into()),
            _ => ("not determined".into(), "-".into(), "-".into(), "-".into()),
        };
        let mut row = vec![
            fit.names[j].clone(),
            data::unit(term.effect.unit(m)),
            data::people(true_value),
            value,
            std,
            z0,
        ];
        if bias.is_some() {
            row.push(b.map_or("-".into(), data::people));
            row.push(z1);
        }
        rows.push(row);
    }
    let mut header: Vec<String> = [
        "parameter",
        "unit",
        "truth",
        "identified",
        "± std",
        "(id - truth)/std",
    ]
    .map(String::from)
    .to_vec();
    if bias.is_some() {
        header.push("hidden-term bias".into());
        header.push("(id - truth - bias)/std".into());
    }
    super::gains::text_table(&header, &rows)
}

/// What the reduced model lacks according to the truth (known in the demo), how much it moves
/// the readings, and the bias it puts into the fit.
fn unexplained(m: &Machine, hidden: &Model, values: &[Option<f64>], hidden_rms: &[f64]) -> String {
    let mut at = 0;
    let mut names = Vec::new();
    for t in &hidden.terms {
        let f = display_factor(m, t.effect);
        let w = t.basis.width();
        let unit = data::unit(t.effect.unit(m));
        let parts: Vec<String> = values[at..at + w]
            .iter()
            .map(|x| x.map_or("?".into(), |x| super::short(x * f)))
            .collect();
        let shown = if w == 2 {
            format!("[{}]", parts.join(", "))
        } else {
            parts.join(", ")
        };
        names.push(format!("{} = {shown} {unit}", t.spelling(m)));
        at += w;
    }
    let rms: Vec<String> = hidden_rms
        .iter()
        .map(|x| format!("{:.2}", x * 1e3))
        .collect();
    format!(
        "Left unexplained: the truth's {}, which the reduced model lacks; alone it moves the readings by {} µm RMS on K4/K1/K2, and the fit on K4 bends the 11 values to absorb what it can of it: the hidden-term bias column, larger than the std, which covers the noise only.\n",
        names.join(", "),
        rms.join("/"),
    )
}

/// The diagnosis's own result (what it found, its gain, the command that uses it), then the
/// check against the truth, which the diagnosis did not use.
fn diagnosis_text(
    m: &Machine,
    run: &diag::Run,
    d: &Diagnosis,
    truth: &Truth,
    hidden: &Model,
    noise_mm: f64,
) -> String {
    let held: Vec<&str> = run.held.iter().map(|(n, _)| n.as_str()).collect();
    let mut out = format!(
        "\nDiagnosis (rtest diagnose --machine {} --model {} --data {} --validate {}): {} candidate terms the reduced model lacks, tried one at a time at α = {} (corrected for the candidates tried); the truth is not used.\n",
        run.machine,
        run.label,
        run.data,
        held.join(","),
        d.dictionary_size,
        run.opts.alpha
    );
    if d.findings.is_empty() {
        out.push_str("  no finding\n");
    } else {
        out.push_str("Found:\n");
        out.push_str(&diag::findings_text(m, d, run.opts.draws));
    }
    out.push_str(&diag::stop_text(m, d));
    out.push_str(&format!(
        "Gain: residual RMS, reduced → {}:\n",
        diag::extended_label(m, run.label, d)
    ));
    out.push_str(&diag::gain_text(run, d));
    out.push_str(&diag::worse_text(d));
    out.push_str(&diag::use_text(m, run, d));

    // The check against the truth.
    let mut checks = Vec::new();
    for t in &hidden.terms {
        let f = display_factor(m, t.effect);
        let unit = data::unit(t.effect.unit(m));
        let want: Vec<f64> = truth
            .coefficient(t)
            .unwrap_or(&[])
            .iter()
            .map(|v| v * f)
            .collect();
        let shown: Vec<String> = want.iter().map(|&v| super::short(v)).collect();
        match d.findings.iter().find(|x| x.term == *t) {
            Some(x) => {
                let z: Vec<String> = x
                    .values
                    .iter()
                    .zip(&x.stds)
                    .zip(&want)
                    .map(|((v, s), w)| match s {
                        Some(s) if *s > 0.0 => format!("{:+.2}", (v * f - w) / (s * f)),
                        _ => "-".into(),
                    })
                    .collect();
                checks.push(format!(
                    "{} found: {} against the truth {} {unit}, (found - truth)/std = {}",
                    t.spelling(m),
                    diag::values_text(m, x),
                    shown.join(", "),
                    z.join(", ")
                ));
            }
            None => checks.push(format!(
                "{} (truth {} {unit}) NOT found",
                t.spelling(m),
                shown.join(", ")
            )),
        }
    }
    for x in &d.findings {
        if !hidden.terms.contains(&x.term) {
            checks.push(format!(
                "{} found but not in the truth (a false finding)",
                x.term.spelling(m)
            ));
        }
    }
    let after: Vec<String> = std::iter::once(d.fit_rms.1)
        .chain(d.validation.iter().map(|v| v.2))
        .map(|x| format!("{:.2}", x * 1e3))
        .collect();
    out.push_str(&format!(
        "Check against the truth (known here only): {}; residual RMS after {} µm on K4/K1/K2, against {} µm of noise.\n",
        checks.join("; "),
        after.join("/"),
        solver::io::csv::format_scaled(noise_mm, 3)
    ));
    out
}
