//! `rtest diagnose`: where the model and the measurement disagree, the missing effect named as
//! an engineer reads it, the extended model (as a machine description `identify` and
//! `generate` accept) and its gain on the fitted and the held-out data (solver::diagnosis).

use super::data;
use super::json::Json;
use super::{CliError, CliResult, EXIT_CODES};
use model_spec::Machine;
use model_spec::basis::Basis;
use solver::diagnosis::dictionary::DictionaryOptions;
use solver::diagnosis::structure::{self, Component};
use solver::diagnosis::{Correction, DiagnoseOptions, Diagnosis, Finding, diagnose};
use solver::fitting::validate::{ValidateOptions, validate};
use solver::io::json::display_factor;
use solver::model::{Model, Term};
use solver::record::Record;
use std::path::{Path, PathBuf};

const LONG_ABOUT: &str = "\
Finds what a model lacks from a measurement CSV (--data, the fitted path, e.g. K4: axes in mm \
and degrees, dx_um,dy_um,dz_um in µm), extends the model with it and measures the gain on the \
fitted data and on held-out measurements (--validate, e.g. K1 and K2).

1. Base fit: the model --model is identified on --data (least squares, refined against the \
exact machine); its residual RMS (µm).
2. Residual structure: the residual per direction x, y, z of the tool frame against every axis \
that moves (harmonics 1..K of rotary angles, Legendre polynomials 1..P of linear positions), \
time (1..T) and direction of motion (reversal); the largest components in µm.
3. Candidates: every term of the machine's topology the model lacks: harmonic:1..K of rotary-axis \
component errors, poly:1..P of linear-axis component errors (and const of their angular ones), \
reversal of positioning errors (backlash), const location, squareness and ball set-up errors, \
and the R-test's zero offsets dx0 dy0 dz0 (const and time:1..T: drift).
4. Selection: one candidate at a time, the one that explains most of what is left; kept if its \
F-test against the noise is significant at --alpha after a correction for the number of \
candidates tried (Bonferroni, else a Monte-Carlo null of the selection itself). Candidates the \
model already spans are refused and listed as confounded (with what); candidates the data cannot \
tell from a finding are named with it. The selection stops when nothing significant remains.
5. Gain: the extended model (model + findings) is fitted on --data and predicts every --validate \
file (exact prediction); residual RMS before and after, µm.

Values of findings are in µm (translational errors, offsets) and µrad (angular errors); a \
harmonic is printed as its cos and sin coefficients, its amplitude √(cos² + sin²) and phase φ \
(cos·cos kθ + sin·sin kθ = amplitude·cos(kθ − φ)).

--json writes {machine, data, base_model, zeroed, alpha, base_fit, structure, dictionary_size, \
unexcited, findings: [{error, basis, description, values, stds, unit, columns, amplitude, \
amplitude_std, phase_deg, phase_std_deg, explained_fraction, f, p_value, correction, \
candidates_tried, alternatives}], stop, confounded: [{error, basis, with}], extended_model: \
{label, terms, added, name, file}, gain: {fit: {data, residual_rms_um_before, \
residual_rms_um_after}, validation: [{data, residual_rms_um_before, residual_rms_um_after}]}}. \
--model-out writes the machine description (the text of --machine) with the extended model \
appended as [models.extended] (extended2, … if that name is taken): `rtest identify --machine \
FILE --model extended` fits it and `rtest generate --machine FILE` emits its gains. --plot DIR \
writes SVG figures: per record (fitted and held out) the measured error against the base and \
extended predictions along the path, x, y and z (<name>-path.svg), and the residual spectrum \
before and after (<name>-spectrum.svg). Every file is computed first and written atomically; \
if one cannot be written, none is.

Exit codes for this verb: 2 for a wrong command line (a missing flag, an unknown machine or \
model, --alpha not strictly between 0 and 1, --harmonics above 36, --poly or --time above 12, \
an empty or repeated --validate item); 1 for a machine file, --data or --validate file that \
cannot be read or does not fit the machine, a diagnosis that cannot be computed, or an output \
that cannot be written (--plot naming a file, --json or --model-out naming a directory or an \
unwritable place).";

/// Flags of `rtest diagnose`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Find what a model lacks (named ISO 230 error, µm/µrad), extend it, and measure the gain on held-out data",
    long_about = LONG_ABOUT,
    after_help = EXIT_CODES
)]
pub struct DiagnoseArgs {
    /// Built-in machine (see `rtest machines`) or path of a machine TOML file.
    #[arg(long, value_name = "NAME|FILE")]
    machine: String,
    /// The base model to diagnose (`reduced`, `full`, or a model of the machine file).
    #[arg(long, value_name = "NAME")]
    model: String,
    /// The measurement CSV the models are fitted on (axes in mm and degrees, dx_um,dy_um,dz_um
    /// in µm).
    #[arg(long, value_name = "FILE")]
    data: PathBuf,
    /// Held-out measurement CSVs (comma list) on which the gain is measured; not fitted.
    #[arg(long, value_name = "FILE,FILE")]
    validate: Option<String>,
    /// The readings were zeroed at the first sample: the zero offsets dx0 dy0 dz0 join the base
    /// model and the held-out predictions are zeroed at their first sample too.
    #[arg(long)]
    zeroed: bool,
    /// Significance level of each step, after the correction for the candidates tried.
    #[arg(long, value_name = "A", default_value = "0.01", value_parser = parse_alpha,
          allow_negative_numbers = true)]
    alpha: f64,
    /// Highest harmonic K of rotary-axis candidates (harmonic:1..K, cycles per revolution).
    #[arg(long, value_name = "K", default_value = "4",
          value_parser = clap::value_parser!(u32).range(0..=36))]
    harmonics: u32,
    /// Highest Legendre order P of linear-axis candidates (poly:1..P over the stroke).
    #[arg(long, value_name = "P", default_value = "3",
          value_parser = clap::value_parser!(u32).range(0..=12))]
    poly: u32,
    /// Highest Legendre order T in time of the zero-offset drift candidates (time:1..T).
    #[arg(long, value_name = "T", default_value = "2",
          value_parser = clap::value_parser!(u32).range(0..=12))]
    time: u32,
    /// Also write the diagnosis as JSON to FILE (values in µm and µrad).
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Write the machine description with the extended model appended ([models.extended]).
    #[arg(long, value_name = "FILE")]
    model_out: Option<PathBuf>,
    /// Write SVG plots (measured against predicted along each path; residual spectra) to DIR
    /// (created if missing).
    #[arg(long, value_name = "DIR")]
    plot: Option<PathBuf>,
}

/// `--alpha`: a number strictly between 0 and 1.
fn parse_alpha(s: &str) -> Result<f64, String> {
    let a: f64 = s
        .trim()
        .parse()
        .map_err(|_| "expected a number strictly between 0 and 1, e.g. 0.01".to_string())?;
    if a.is_finite() && a > 0.0 && a < 1.0 {
        Ok(a)
    } else {
        Err("expected a number strictly between 0 and 1, e.g. 0.01".into())
    }
}

/// Parses `--validate`: a comma list of files, none empty, none twice.
fn parse_files(list: &str) -> CliResult<Vec<PathBuf>> {
    let mut out: Vec<PathBuf> = Vec::new();
    for item in list.split(',') {
        let item = item.trim();
        if item.is_empty() {
            return Err(CliError::usage(format!(
                "--validate: empty item in `{list}` (expected a comma list of measurement CSV files, e.g. k1.csv,k2.csv)"
            )));
        }
        let p = PathBuf::from(item);
        if out.contains(&p) {
            return Err(CliError::usage(format!(
                "--validate: `{item}` is given twice"
            )));
        }
        out.push(p);
    }
    Ok(out)
}

/// Runs `rtest diagnose`.
pub fn run(args: &DiagnoseArgs) -> CliResult {
    let m = super::load_machine(&args.machine)?;
    let (label, model) = data::model(&m, Some(&args.model), None)?;
    let held_files = match &args.validate {
        Some(list) => parse_files(list)?,
        None => Vec::new(),
    };
    // Outputs that cannot be written are found before the work.
    for (flag, p) in [("--json", &args.json), ("--model-out", &args.model_out)] {
        if let Some(p) = p
            && p.is_dir()
        {
            return Err(CliError::failure(format!(
                "{flag}: cannot write `{}`: it is a directory",
                p.display()
            )));
        }
    }
    if let Some(dir) = &args.plot
        && dir.exists()
        && !dir.is_dir()
    {
        return Err(CliError::failure(format!(
            "--plot: `{}` exists and is not a directory",
            dir.display()
        )));
    }
    let machine_text = if args.model_out.is_some() {
        Some(machine_text(&args.machine)?)
    } else {
        None
    };

    let record = data::measurement("--data", &m, &args.data)?;
    let mut held = Vec::new();
    for f in &held_files {
        held.push((
            f.display().to_string(),
            data::measurement("--validate", &m, f)?,
        ));
    }
    let opts = DiagnoseOptions {
        dictionary: DictionaryOptions {
            harmonics: args.harmonics,
            poly: args.poly,
            time: args.time,
        },
        alpha: args.alpha,
        zeroed: args.zeroed,
        ..Default::default()
    };
    let data_name = args.data.display().to_string();
    let d = diagnose(&m, &model, &record, &held, &opts)
        .map_err(|e| CliError::failure(format!("--data: cannot diagnose: {e}")))?;
    let extended = extended_terms(&model, &d);

    // Everything is computed before anything is written.
    let mut files: Vec<Output> = Vec::new();
    let mut model_out = None;
    if let (Some(path), Some(text)) = (&args.model_out, &machine_text) {
        let description = format!(
            "{} (rtest diagnose on {data_name})",
            extended_label(&m, &label, &d)
        );
        let (name, contents) = extended_machine(&m, text, &extended, &description)
            .map_err(|e| CliError::failure(format!("--model-out: {e}")))?;
        files.push(Output::new("--model-out", path.clone(), contents));
        model_out = Some((name, path.display().to_string()));
    }
    let run = Run {
        machine: &args.machine,
        label: &label,
        data: &data_name,
        samples: record.samples.len(),
        held: held
            .iter()
            .map(|(n, r)| (n.clone(), r.samples.len()))
            .collect(),
        opts: &opts,
        model_out: model_out.clone(),
    };
    if let Some(path) = &args.json {
        let json = diagnosis_json(&m, &run, &d, &extended);
        files.push(Output::new("--json", path.clone(), json.render()));
    }
    if let Some(dir) = &args.plot {
        let mut records = vec![(data_name.clone(), &record, true)];
        records.extend(held.iter().map(|(n, r)| (n.clone(), r, false)));
        for (name, svg) in
            plots(&m, &run, &d, &records).map_err(|e| CliError::failure(format!("--plot: {e}")))?
        {
            files.push(Output::new("--plot", dir.join(name), svg));
        }
    }
    let mut text = report(&m, &run, &d);
    if data::looks_zeroed(&record) && !args.zeroed {
        text.push_str(
            "Note: the first reading is exactly 0: if the readings were zeroed at the first sample, give --zeroed.\n",
        );
    }
    let created = match &args.plot {
        Some(dir) if !dir.exists() => {
            std::fs::create_dir_all(dir).map_err(|e| {
                CliError::failure(format!(
                    "--plot: cannot create directory `{}`: {e}",
                    dir.display()
                ))
            })?;
            Some(dir.clone())
        }
        _ => None,
    };
    if let Err(e) = write_all(&files) {
        if let Some(dir) = created {
            let _ = std::fs::remove_dir(dir);
        }
        return Err(e);
    }
    if !files.is_empty() {
        text.push_str("\nWrote:\n");
        for f in &files {
            text.push_str(&format!("  {}\n", f.path.display()));
        }
    }
    print!("{text}");
    Ok(())
}

// ------------------------------------------------------------------ the diagnosis for people

/// What a report needs besides the diagnosis.
pub struct Run<'a> {
    /// `--machine` as given (a built-in name or a file).
    pub machine: &'a str,
    /// The base model's label (`reduced`).
    pub label: &'a str,
    /// The fitted file's name.
    pub data: &'a str,
    /// Its samples.
    pub samples: usize,
    /// The held-out files' names and samples.
    pub held: Vec<(String, usize)>,
    /// The options of the diagnosis.
    pub opts: &'a DiagnoseOptions,
    /// The model written by --model-out: its name and the file.
    pub model_out: Option<(String, String)>,
}

/// The base model's terms (as given, without the offsets --zeroed adds) and the findings: the
/// extended model as a sub-model lists it.
pub fn extended_terms(base: &Model, d: &Diagnosis) -> Model {
    let mut out = base.clone();
    for f in &d.findings {
        if !out.terms.contains(&f.term) {
            out.terms.push(f.term);
        }
    }
    out
}

/// `reduced + ECC@harmonic:2`.
pub fn extended_label(m: &Machine, label: &str, d: &Diagnosis) -> String {
    std::iter::once(label.to_string())
        .chain(d.findings.iter().map(|f| f.term.spelling(m)))
        .collect::<Vec<_>>()
        .join(" + ")
}

/// `ECC harmonic:2` → the term's two words.
fn term_words(m: &Machine, t: &Term) -> String {
    format!("{} {}", t.effect.name(m), t.basis)
}

/// A p-value for people.
fn p_text(p: f64) -> String {
    if p == 0.0 {
        "< 1e-300".into()
    } else if p < 1e-3 {
        format!("{p:.1e}")
    } else {
        format!("{p:.3}")
    }
}

/// How the p-value of a finding was corrected, for people.
fn correction_text(f: &Finding, draws: usize) -> String {
    match f.correction {
        Correction::Bonferroni => format!(
            "Bonferroni-corrected: raw p × {} candidates tried",
            f.candidates_tried
        ),
        Correction::MonteCarlo => format!(
            "corrected by a Monte-Carlo null of the selection over the {} candidates tried ({draws} draws)",
            f.candidates_tried
        ),
    }
}

/// The harmonic amplitude √(c² + s²) and phase atan2(s, c) of a finding (display units, degrees),
/// with standard uncertainties from the covariance of the extended fit when it has them.
pub struct Harmonic {
    /// √(c² + s²), µm or µrad.
    pub amplitude: f64,
    /// Its standard uncertainty.
    pub amplitude_std: Option<f64>,
    /// atan2(s, c), degrees.
    pub phase_deg: f64,
    /// Its standard uncertainty, degrees.
    pub phase_std_deg: Option<f64>,
}

/// The columns of `term` in the extended fit.
fn columns_of(d: &Diagnosis, term: &Term) -> Vec<usize> {
    let model = &d.extended_fit.model;
    model
        .columns()
        .iter()
        .enumerate()
        .filter(|(_, (t, _))| model.terms[*t] == *term)
        .map(|(j, _)| j)
        .collect()
}

/// Amplitude and phase of a harmonic finding, `None` for other bases or undetermined values.
pub fn harmonic(m: &Machine, d: &Diagnosis, f: &Finding) -> Option<Harmonic> {
    if !matches!(f.term.basis, Basis::Harmonic(_)) || f.values.len() != 2 {
        return None;
    }
    let k = display_factor(m, f.term.effect);
    let (c, s) = (f.values[0] * k, f.values[1] * k);
    if !c.is_finite() || !s.is_finite() {
        return None;
    }
    let a = c.hypot(s);
    let phase = s.atan2(c);
    let cols = columns_of(d, &f.term);
    let cov = &d.extended_fit.fit.covariance;
    let (amplitude_std, phase_std_deg) = if cols.len() == 2 && a > 0.0 {
        let (i, j) = (cols[0], cols[1]);
        let (vcc, vss, vcs) = (
            cov[(i, i)] * k * k,
            cov[(j, j)] * k * k,
            cov[(i, j)] * k * k,
        );
        let var_a = (c * c * vcc + s * s * vss + 2.0 * c * s * vcs) / (a * a);
        let var_p = (s * s * vcc + c * c * vss - 2.0 * c * s * vcs) / (a * a * a * a);
        let ok = |v: f64| (v.is_finite() && v >= 0.0).then(|| v.sqrt());
        (ok(var_a), ok(var_p).map(f64::to_degrees))
    } else {
        (None, None)
    };
    Some(Harmonic {
        amplitude: a,
        amplitude_std,
        phase_deg: phase.to_degrees(),
        phase_std_deg,
    })
}

/// `7.7512 ± 0.3012 (cos), 6.1003 ± 0.2710 (sin) µrad`.
pub fn values_text(m: &Machine, f: &Finding) -> String {
    let k = display_factor(m, f.term.effect);
    let unit = data::unit(f.term.effect.unit(m));
    let names = f.term.basis.column_names();
    let parts: Vec<String> = f
        .values
        .iter()
        .zip(&f.stds)
        .enumerate()
        .map(|(i, (v, s))| {
            let v = if v.is_finite() {
                data::people(v * k)
            } else {
                "not determined".into()
            };
            let s = s.map_or(String::new(), |s| format!(" ± {}", data::people(s * k)));
            let suffix = if names.len() > 1 {
                let n = &names[i];
                format!(" ({})", n.rsplit(':').next().unwrap_or(n))
            } else {
                String::new()
            };
            format!("{v}{s}{suffix}")
        })
        .collect();
    format!("{} {unit}", parts.join(", "))
}

/// The findings, one block each: name, values, amplitude and phase, share, F and p, alternatives.
pub fn findings_text(m: &Machine, d: &Diagnosis, draws: usize) -> String {
    let mut out = String::new();
    for (i, f) in d.findings.iter().enumerate() {
        let unit = data::unit(f.term.effect.unit(m));
        out.push_str(&format!(
            "  {}. {}: {}\n",
            i + 1,
            f.description,
            values_text(m, f)
        ));
        if let (Some(h), Basis::Harmonic(k)) = (harmonic(m, d, f), f.term.basis) {
            let pm = |s: Option<f64>, digits: usize| {
                s.map_or(String::new(), |s| format!(" ± {s:.digits$}"))
            };
            let axis = match f.term.effect.carrier(m) {
                model_spec::basis::Carrier::Axis(a) => m.axes[a].name.clone(),
                model_spec::basis::Carrier::None => "θ".into(),
            };
            out.push_str(&format!(
                "     amplitude {}{} {unit}, phase {:.1}{}° (amplitude·cos({k}·{axis} − phase))\n",
                data::people(h.amplitude),
                pm(h.amplitude_std, 4),
                h.phase_deg,
                pm(h.phase_std_deg, 1),
            ));
        }
        out.push_str(&format!(
            "     explains {:.1} % of the base model's residual (sum of squares); F = {:.1}, p = {} ({})\n",
            100.0 * f.explained_fraction,
            f.f,
            p_text(f.p_value),
            correction_text(f, draws)
        ));
        if !f.alternatives.is_empty() {
            let alts: Vec<String> = f.alternatives.iter().map(|t| term_words(m, t)).collect();
            out.push_str(&format!(
                "     the data cannot tell it from: {}\n",
                alts.join(", ")
            ));
        }
    }
    out
}

/// The residual RMS before and after, fitted and held out, as rows of a table.
pub fn gain_text(run: &Run, d: &Diagnosis) -> String {
    let mut rows = vec![(format!("{} (fitted)", run.data), d.fit_rms.0, d.fit_rms.1)];
    for (name, before, after) in &d.validation {
        rows.push((format!("{name} (held out)"), *before, *after));
    }
    let header = ["data", "before µm", "after µm", "change"].map(String::from);
    let table: Vec<Vec<String>> = rows
        .iter()
        .map(|(n, b, a)| {
            vec![
                n.clone(),
                data::um(*b),
                data::um(*a),
                if *b > 0.0 {
                    format!("{:+.1} %", 100.0 * (a - b) / b)
                } else {
                    "-".into()
                },
            ]
        })
        .collect();
    indent(&super::gains::text_table(&header, &table), "  ")
}

fn indent(text: &str, pad: &str) -> String {
    text.lines().map(|l| format!("{pad}{l}\n")).collect()
}

/// A path or argument for a shell command line, quoted when needed.
fn shell(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./:@,+=".contains(c))
    {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// The commands that use the extended model.
pub fn use_text(m: &Machine, run: &Run, d: &Diagnosis) -> String {
    let zeroed = if run.opts.zeroed { " --zeroed" } else { "" };
    let mut out = String::new();
    if d.findings.is_empty() {
        out.push_str(&format!(
            "Nothing to add: model {} explains {} down to the noise.\n",
            run.label, run.data
        ));
    } else {
        let terms: Vec<String> = d.findings.iter().map(|f| f.term.spelling(m)).collect();
        out.push_str(&format!(
            "Use the extended model: rtest identify --machine {} --model {} --terms {} --data {}{zeroed}\n",
            shell(run.machine),
            shell(run.label),
            terms.join(","),
            shell(run.data)
        ));
    }
    if let Some((name, file)) = &run.model_out {
        out.push_str(&format!(
            "The extended model is `{name}` of {file}: rtest identify --machine {} --model {name} --data {}{zeroed}; rtest generate --machine {} --model {name}\n",
            shell(file),
            shell(run.data),
            shell(file)
        ));
    }
    out
}

/// `C harmonic:2 y`.
fn component_label(c: &Component) -> String {
    format!("{} {} {}", c.source, c.shape, ["x", "y", "z"][c.direction])
}

/// The largest components of `before`, each with its amplitude in `after` (0 if gone).
fn component_rows(before: &[Component], after: &[Component], n: usize) -> Vec<(String, f64, f64)> {
    before
        .iter()
        .take(n)
        .map(|c| {
            let a = after
                .iter()
                .find(|x| x.source == c.source && x.shape == c.shape && x.direction == c.direction)
                .map_or(0.0, |x| x.explained_rms_um);
            (component_label(c), c.explained_rms_um, a)
        })
        .collect()
}

/// Why the selection stopped, one line.
pub fn stop_text(m: &Machine, d: &Diagnosis) -> String {
    let best = d.stop.best.map_or(String::new(), |t| {
        format!("; best remaining candidate: {}", term_words(m, &t))
    });
    format!("Stopped: {}{best}.\n", d.stop.reason)
}

/// The whole report.
pub fn report(m: &Machine, run: &Run, d: &Diagnosis) -> String {
    let o = run.opts;
    let mut out = format!(
        "Diagnosis on {} ({} samples, readings {}): machine {}, model {} ({} terms)\n",
        run.data,
        run.samples,
        if o.zeroed {
            "zeroed at the first sample"
        } else {
            "not zeroed"
        },
        m.name,
        run.label,
        d.base.terms.len()
    );
    if run.held.is_empty() {
        out.push_str("Held out: none (--validate gives files to measure the gain on)\n");
    } else {
        let h: Vec<String> = run
            .held
            .iter()
            .map(|(n, s)| format!("{n} ({s} samples)"))
            .collect();
        out.push_str(&format!("Held out (not fitted): {}\n", h.join(", ")));
    }
    let fit = &d.base_fit.fit;
    out.push_str(&format!(
        "\nBase fit: model {} on {}, refined against the exact machine: residual RMS {} µm, σ̂ {} ({} degrees of freedom)\n",
        run.label,
        run.data,
        data::um(d.fit_rms.0),
        fit.sigma
            .map_or("undefined".into(), |s| format!("{} µm", data::um(s))),
        fit.dof
    ));

    out.push_str(
        "\nResidual structure of the base fit: the largest shapes, each fitted alone per direction (RMS of what it explains, µm; shapes of axes that move together overlap, so these are indications: the selection decides):\n",
    );
    let rows = component_rows(&d.structure_before, &d.structure_after, 8);
    if rows.is_empty() {
        out.push_str("  none (nothing moves on this path)\n");
    } else {
        let header = ["axis", "shape", "dir", "base µm", "extended µm"].map(String::from);
        let table: Vec<Vec<String>> = d
            .structure_before
            .iter()
            .zip(&rows)
            .map(|(c, (_, b, a))| {
                vec![
                    c.source.clone(),
                    c.shape.clone(),
                    ["x", "y", "z"][c.direction].to_string(),
                    format!("{b:.4}"),
                    format!("{a:.4}"),
                ]
            })
            .collect();
        out.push_str(&indent(&super::gains::text_table(&header, &table), "  "));
    }

    let k = &o.dictionary;
    out.push_str(&format!(
        "\nCandidates: {} terms the model lacks (harmonic:1..{} of rotary-axis errors, poly:1..{} of linear-axis errors, reversal of positioning errors, const location, squareness and set-up errors, dx0 dy0 dz0 const and time:1..{}); {} do not vary on {} (unexcited).\n",
        d.dictionary_size,
        k.harmonics,
        k.poly,
        k.time,
        d.unexcited.len(),
        run.data
    ));
    out.push_str(&format!(
        "Forward selection, significance α = {} per step after the correction for the candidates tried:\n",
        o.alpha
    ));
    if d.findings.is_empty() {
        out.push_str("  no finding\n");
    } else {
        out.push_str(&findings_text(m, d, o.draws));
    }
    out.push_str(&stop_text(m, d));

    if d.confounded.is_empty() {
        out.push_str("\nConfounded: none (the model spans no candidate)\n");
    } else {
        out.push_str(&format!(
            "\nConfounded ({}: the extended model spans them, the data cannot see them apart from what it has; candidate [model terms it is a combination of]):\n",
            d.confounded.len()
        ));
        let items: Vec<String> = d
            .confounded
            .iter()
            .map(|c| {
                let with: Vec<String> = c.with.iter().map(|t| t.spelling(m)).collect();
                format!("{} [{}]", term_words(m, &c.term), with.join(" "))
            })
            .collect();
        out.push_str(&wrap(&items, "; ", "  ", 100));
    }

    out.push_str(&format!(
        "\nGain: residual RMS, base model {} → extended model {}:\n",
        run.label,
        extended_label(m, run.label, d)
    ));
    out.push_str(&gain_text(run, d));
    out.push_str(&worse_text(d));
    out.push('\n');
    out.push_str(&use_text(m, run, d));
    out
}

/// A warning for every held-out file the extended model predicts worse than the base model.
pub fn worse_text(d: &Diagnosis) -> String {
    let worse: Vec<String> = d
        .validation
        .iter()
        .filter(|(_, b, a)| a > b)
        .map(|(n, b, a)| format!("{n} ({:+.1} %)", 100.0 * (a - b) / b))
        .collect();
    if worse.is_empty() || d.findings.is_empty() {
        return String::new();
    }
    format!(
        "Warning: the extended model predicts {} worse than the base model: a finding may stand for one of the candidates the data cannot tell it from, or the fitted path does not separate the cause; try those alternatives (identify --terms) on the held-out data.\n",
        worse.join(", ")
    )
}

/// `items` joined by `sep` in lines of at most `width` characters, each starting with `pad`.
fn wrap(items: &[String], sep: &str, pad: &str, width: usize) -> String {
    let mut out = String::new();
    let mut line = String::new();
    for (i, item) in items.iter().enumerate() {
        let piece = if i + 1 < items.len() {
            format!("{item}{}", sep.trim_end())
        } else {
            item.clone()
        };
        if !line.is_empty() && pad.len() + line.chars().count() + 1 + piece.chars().count() > width
        {
            out.push_str(&format!("{pad}{line}\n"));
            line.clear();
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(&piece);
    }
    if !line.is_empty() {
        out.push_str(&format!("{pad}{line}\n"));
    }
    out
}

// ------------------------------------------------------------------ JSON

fn term_json(m: &Machine, t: &Term) -> Vec<(String, Json)> {
    vec![
        ("error".into(), Json::str(t.effect.name(m))),
        ("basis".into(), Json::str(t.basis.to_string())),
    ]
}

fn opt(x: Option<f64>) -> Json {
    x.map_or(Json::Null, Json::Num)
}

fn components_json(c: &[Component], n: usize) -> Json {
    Json::Arr(
        c.iter()
            .take(n)
            .map(|c| {
                Json::Obj(vec![
                    ("source".into(), Json::str(&c.source)),
                    ("shape".into(), Json::str(&c.shape)),
                    ("direction".into(), Json::str(["x", "y", "z"][c.direction])),
                    ("explained_rms_um".into(), Json::Num(c.explained_rms_um)),
                ])
            })
            .collect(),
    )
}

/// The diagnosis as JSON (values in µm and µrad).
pub fn diagnosis_json(m: &Machine, run: &Run, d: &Diagnosis, extended: &Model) -> Json {
    let spell = |ts: &[Term]| Json::Arr(ts.iter().map(|t| Json::str(t.spelling(m))).collect());
    let findings = d
        .findings
        .iter()
        .map(|f| {
            let k = display_factor(m, f.term.effect);
            let mut o = term_json(m, &f.term);
            let h = harmonic(m, d, f);
            o.extend([
                ("description".into(), Json::str(&f.description)),
                (
                    "values".into(),
                    Json::Arr(
                        f.values
                            .iter()
                            .map(|v| opt(v.is_finite().then_some(v * k)))
                            .collect(),
                    ),
                ),
                (
                    "stds".into(),
                    Json::Arr(f.stds.iter().map(|s| opt(s.map(|s| s * k))).collect()),
                ),
                ("unit".into(), Json::str(f.term.effect.unit(m))),
                (
                    "columns".into(),
                    Json::Arr(
                        f.term
                            .basis
                            .column_names()
                            .into_iter()
                            .map(Json::Str)
                            .collect(),
                    ),
                ),
                ("amplitude".into(), opt(h.as_ref().map(|h| h.amplitude))),
                (
                    "amplitude_std".into(),
                    opt(h.as_ref().and_then(|h| h.amplitude_std)),
                ),
                ("phase_deg".into(), opt(h.as_ref().map(|h| h.phase_deg))),
                (
                    "phase_std_deg".into(),
                    opt(h.as_ref().and_then(|h| h.phase_std_deg)),
                ),
                ("explained_fraction".into(), Json::Num(f.explained_fraction)),
                ("f".into(), Json::Num(f.f)),
                ("p_value".into(), Json::Num(f.p_value)),
                (
                    "correction".into(),
                    Json::str(match f.correction {
                        Correction::Bonferroni => "bonferroni",
                        Correction::MonteCarlo => "monte-carlo",
                    }),
                ),
                (
                    "candidates_tried".into(),
                    Json::Int(f.candidates_tried as i64),
                ),
                ("alternatives".into(), spell(&f.alternatives)),
            ]);
            Json::Obj(o)
        })
        .collect();
    let confounded = d
        .confounded
        .iter()
        .map(|c| {
            let mut o = term_json(m, &c.term);
            o.push(("with".into(), spell(&c.with)));
            Json::Obj(o)
        })
        .collect();
    let added: Vec<Term> = d.findings.iter().map(|f| f.term).collect();
    let (name, file) = match &run.model_out {
        Some((n, f)) => (Json::str(n), Json::str(f)),
        None => (Json::Null, Json::Null),
    };
    let validation = d
        .validation
        .iter()
        .map(|(n, b, a)| {
            Json::Obj(vec![
                ("data".into(), Json::str(n)),
                ("residual_rms_um_before".into(), Json::Num(b * 1e3)),
                ("residual_rms_um_after".into(), Json::Num(a * 1e3)),
            ])
        })
        .collect();
    Json::Obj(vec![
        ("machine".into(), Json::str(&m.name)),
        ("data".into(), Json::str(run.data)),
        ("samples".into(), Json::Int(run.samples as i64)),
        ("base_model".into(), Json::str(run.label)),
        ("zeroed".into(), Json::Bool(run.opts.zeroed)),
        ("alpha".into(), Json::Num(run.opts.alpha)),
        (
            "base_fit".into(),
            Json::Obj(vec![
                ("terms".into(), spell(&d.base.terms)),
                ("residual_rms_um".into(), Json::Num(d.fit_rms.0 * 1e3)),
                (
                    "sigma_um".into(),
                    opt(d.base_fit.fit.sigma.map(|s| s * 1e3)),
                ),
            ]),
        ),
        (
            "structure".into(),
            Json::Obj(vec![
                ("before".into(), components_json(&d.structure_before, 12)),
                ("after".into(), components_json(&d.structure_after, 12)),
            ]),
        ),
        (
            "dictionary_size".into(),
            Json::Int(d.dictionary_size as i64),
        ),
        ("unexcited".into(), spell(&d.unexcited)),
        ("findings".into(), Json::Arr(findings)),
        (
            "stop".into(),
            Json::Obj(vec![
                ("reason".into(), Json::str(&d.stop.reason)),
                (
                    "best_remaining".into(),
                    d.stop.best.map_or(Json::Null, |t| Json::str(t.spelling(m))),
                ),
                ("p_value".into(), Json::Num(d.stop.p_value)),
            ]),
        ),
        ("confounded".into(), Json::Arr(confounded)),
        (
            "extended_model".into(),
            Json::Obj(vec![
                ("label".into(), Json::str(extended_label(m, run.label, d))),
                ("terms".into(), spell(&extended.terms)),
                ("added".into(), spell(&added)),
                ("name".into(), name),
                ("file".into(), file),
            ]),
        ),
        (
            "gain".into(),
            Json::Obj(vec![
                (
                    "fit".into(),
                    Json::Obj(vec![
                        ("data".into(), Json::str(run.data)),
                        (
                            "residual_rms_um_before".into(),
                            Json::Num(d.fit_rms.0 * 1e3),
                        ),
                        ("residual_rms_um_after".into(), Json::Num(d.fit_rms.1 * 1e3)),
                    ]),
                ),
                ("validation".into(), Json::Arr(validation)),
            ]),
        ),
    ])
}

// ------------------------------------------------------------------ the extended machine

/// The TOML text of `--machine`: a built-in machine's, or the file's.
pub fn machine_text(name_or_path: &str) -> CliResult<String> {
    if let Some((_, text)) = model_spec::BUILTIN.iter().find(|(n, _)| *n == name_or_path) {
        return Ok(text.to_string());
    }
    std::fs::read_to_string(name_or_path)
        .map_err(|e| CliError::failure(format!("--machine: cannot read `{name_or_path}`: {e}")))
}

/// The machine description `text` of `m` with `extended` appended as `[models.extended]` (or
/// `extended2`, … if the name is taken), checked by parsing it back. Returns the model's name
/// and the text.
pub fn extended_machine(
    m: &Machine,
    text: &str,
    extended: &Model,
    description: &str,
) -> Result<(String, String), String> {
    let name = std::iter::once("extended".to_string())
        .chain((2..).map(|i| format!("extended{i}")))
        .find(|n| !m.models.contains_key(n))
        .expect("an unused name");
    let quote = |s: &str| serde_json::to_string(s).expect("a string");
    let terms: Vec<String> = extended
        .terms
        .iter()
        .map(|t| quote(&t.spelling(m)))
        .collect();
    let mut list = String::new();
    let mut line = String::new();
    for (i, t) in terms.iter().enumerate() {
        let piece = if i + 1 < terms.len() {
            format!("{t},")
        } else {
            t.clone()
        };
        if !line.is_empty() && line.len() + 1 + piece.len() > 88 {
            list.push_str(&format!("    {line}\n"));
            line.clear();
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(&piece);
    }
    list.push_str(&format!("    {line}\n"));
    let mut out = text.to_string();
    if !out.ends_with('\n') {
        out.push('\n');
    }
    out.push_str(&format!(
        "\n# Written by rtest diagnose: the model {name} is the base model and what the diagnosis found.\n[models.{name}]\ndescription = {}\nerrors = [\n{list}]\n",
        quote(description)
    ));
    let back = model_spec::parse_machine("<extended machine description>", &out)
        .map_err(|e| format!("the extended machine description does not parse back: {e}"))?;
    let model = Model::of(&back, &name).ok_or("the extended model is missing after parsing")?;
    if model.terms != extended.terms || back.errors != m.errors || back.name != m.name {
        return Err(
            "the extended machine description does not read back as the same machine and model"
                .into(),
        );
    }
    Ok((name, out))
}

// ------------------------------------------------------------------ plots

/// A safe file stem for a record's figures: the file's stem, unique among `taken`.
fn stem(name: &str, taken: &mut Vec<String>) -> String {
    let raw = Path::new(name)
        .file_stem()
        .map_or("data".to_string(), |s| s.to_string_lossy().into_owned());
    let mut s: String = raw
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() {
        s = "data".into();
    }
    let mut out = s.clone();
    let mut i = 2;
    while taken.contains(&out) {
        out = format!("{s}-{i}");
        i += 1;
    }
    taken.push(out.clone());
    out
}

/// The abscissa of a path figure: the rotary axis that moves most when it moves one way
/// (degrees), else the sample index.
fn abscissa(m: &Machine, record: &Record) -> (String, Vec<f64>) {
    let mut best: Option<(usize, f64)> = None;
    for a in m.rotary_axes() {
        let q: Vec<f64> = record.samples.iter().map(|s| s.commands[a]).collect();
        let range = q.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
            - q.iter().cloned().fold(f64::INFINITY, f64::min);
        let monotonic = q.windows(2).all(|w| w[1] >= w[0]) || q.windows(2).all(|w| w[1] <= w[0]);
        if range > 1e-9 && monotonic && best.is_none_or(|(_, r)| range > r) {
            best = Some((a, range));
        }
    }
    match best {
        Some((a, _)) => (
            format!("{} (deg)", m.axes[a].name),
            record
                .samples
                .iter()
                .map(|s| s.commands[a].to_degrees())
                .collect(),
        ),
        None => (
            "sample index".into(),
            (0..record.samples.len()).map(|i| i as f64).collect(),
        ),
    }
}

/// The SVG figures of the diagnosis: for every record (name, record, fitted?) the measured error
/// against the base and extended predictions along the path (`<stem>-path.svg`), and the
/// residual spectrum before and after (`<stem>-spectrum.svg`). File names and SVG texts.
pub fn plots(
    m: &Machine,
    run: &Run,
    d: &Diagnosis,
    records: &[(String, &Record, bool)],
) -> Result<Vec<(String, String)>, String> {
    let o = run.opts;
    let mut out = Vec::new();
    let mut taken = Vec::new();
    let ext_label = extended_label(m, run.label, d);
    for (name, record, fitted) in records {
        // The fitted record: the fits' own prediction (the minimum-norm solution, so that
        // confounded groups keep their combined effect), not zeroed: the offsets of --zeroed are
        // in the models. Held out: the values, zeroed like the readings (as the gain).
        let predict = |fit: &solver::fitting::Identification| {
            let values: Vec<Option<f64>> = if *fitted {
                fit.fit.solution.iter().map(|&v| Some(v)).collect()
            } else {
                fit.fit.values.clone()
            };
            let opts = ValidateOptions {
                zeroed: o.zeroed && !fitted,
                exact: true,
                params: o.params.clone(),
                ..Default::default()
            };
            validate(m, &fit.model, &values, record, &opts)
                .map_err(|e| format!("cannot predict {name}: {e}"))
        };
        let before = predict(&d.base_fit)?;
        let after = predict(&d.extended_fit)?;
        let (x_label, x) = abscissa(m, record);
        let um = |v: &[[f64; 3]], k: usize| v.iter().map(|r| r[k] * 1e3).collect::<Vec<f64>>();
        let measured: Vec<[f64; 3]> = before
            .prediction
            .iter()
            .zip(&before.residual)
            .map(|(p, r)| [p[0] + r[0], p[1] + r[1], p[2] + r[2]])
            .collect();
        let panels: Vec<plots::Panel> = (0..3)
            .map(|k| plots::Panel {
                name: format!("{} error", ["x", "y", "z"][k]),
                measured: plots::Series::new("measured", um(&measured, k)),
                predictions: vec![
                    plots::Series::new(
                        format!("base model ({})", run.label),
                        um(&before.prediction, k),
                    ),
                    plots::Series::new(
                        format!("extended model ({ext_label})"),
                        um(&after.prediction, k),
                    ),
                ],
            })
            .collect();
        let role = if *fitted { "fitted" } else { "held out" };
        let s = stem(name, &mut taken);
        let svg = plots::path_comparison(
            &format!("{name} ({role}): measured and predicted error, µm"),
            &x_label,
            &x,
            &panels,
        )
        .map_err(|e| e.to_string())?;
        out.push((format!("{s}-path.svg"), svg));

        let k = &o.dictionary;
        let (sb, sa) = if *fitted {
            (d.structure_before.clone(), d.structure_after.clone())
        } else {
            (
                structure::analyse(m, record, &before.residual, k.harmonics, k.poly, k.time),
                structure::analyse(m, record, &after.residual, k.harmonics, k.poly, k.time),
            )
        };
        let rows = component_rows(&sb, &sa, 12);
        if !rows.is_empty() {
            let svg = plots::spectrum(
                &format!("{name} ({role}): residual components, µm"),
                &format!("base model ({})", run.label),
                &format!("extended model ({ext_label})"),
                &rows,
            )
            .map_err(|e| e.to_string())?;
            out.push((format!("{s}-spectrum.svg"), svg));
        }
    }
    Ok(out)
}

// ------------------------------------------------------------------ writing

/// One output file, computed.
pub struct Output {
    /// The flag it belongs to, for messages.
    pub flag: &'static str,
    /// Where it goes.
    pub path: PathBuf,
    /// Its contents.
    pub contents: String,
}

impl Output {
    /// An output file.
    pub fn new(flag: &'static str, path: PathBuf, contents: String) -> Output {
        Output {
            flag,
            path,
            contents,
        }
    }
}

/// Writes every file through a temporary file in its directory, then renames them all: a
/// failure leaves none of them (and no temporary file) behind.
pub fn write_all(files: &[Output]) -> CliResult {
    for (i, f) in files.iter().enumerate() {
        if let Some(g) = files[..i].iter().find(|g| g.path == f.path) {
            return Err(CliError::usage(format!(
                "{}: `{}` is also the file of {}",
                f.flag,
                f.path.display(),
                g.flag
            )));
        }
    }
    let mut staged: Vec<(PathBuf, &Output)> = Vec::new();
    let clean = |staged: &[(PathBuf, &Output)]| {
        for (tmp, _) in staged {
            let _ = std::fs::remove_file(tmp);
        }
    };
    for (i, f) in files.iter().enumerate() {
        let path = &f.path;
        let Some(file_name) = path.file_name() else {
            clean(&staged);
            return Err(CliError::usage(format!(
                "{}: `{}` is not a file name",
                f.flag,
                path.display()
            )));
        };
        if path.is_dir() {
            clean(&staged);
            return Err(CliError::failure(format!(
                "{}: cannot write `{}`: it is a directory",
                f.flag,
                path.display()
            )));
        }
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        let tmp = dir.join(format!(
            ".{}.rtest-tmp-{}-{i}",
            file_name.to_string_lossy(),
            std::process::id()
        ));
        if let Err(e) = std::fs::write(&tmp, &f.contents) {
            let _ = std::fs::remove_file(&tmp);
            clean(&staged);
            return Err(CliError::failure(format!(
                "{}: cannot write `{}`: {e}",
                f.flag,
                path.display()
            )));
        }
        staged.push((tmp, f));
    }
    for (k, (tmp, f)) in staged.iter().enumerate() {
        if let Err(e) = std::fs::rename(tmp, &f.path) {
            clean(&staged[k..]);
            return Err(CliError::failure(format!(
                "{}: cannot write `{}`: {e}",
                f.flag,
                f.path.display()
            )));
        }
    }
    Ok(())
}
