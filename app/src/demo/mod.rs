//! The seed's experiment replayed on the virtual seed machine (`seed-ac`) with its documented
//! demo truth: simulate K4, K1 and K2; identify the reduced model on K4 (refined against the
//! exact machine); validate it on every path; say what the truth has that the model lacks;
//! diagnose the reduced model on K4 with K1 and K2 held out; compensate K1 and K2 with the
//! recommended model and measure what is left on the exact machine; and produce the files
//! people take away (measurements, reports, generated code, gain table, extended machine
//! description, compensated poses, figure data). Nothing is written here: the caller writes [`Demo::files`] and draws
//! [`Demo::figures`].

mod compensation;
mod text;

use codegen::table::{Format, render};
use diagnosis::figures::{Figures, figures};
use diagnosis::hidden::hidden_terms;
use diagnosis::{DiagnoseOptions, diagnose, one_record};
use fitting::campaign::{CampaignIdentification, CampaignValues};
use fitting::sanity::{ValueLimits, check_values};
use fitting::{
    Identification, IdentifyOptions, RefineOptions, Refinement, ValidateOptions, identify, validate,
};
use formats::csv::format_record;
use formats::progress::Unwatched;
use formats::truth::builtin_truth;
use model_spec::{FULL_MODEL, Machine};
use report::inputs::Document;
use report::json::{
    CampaignSource, DiagnosisReport, DiagnosisSource, IdentificationReport, ValidationReport,
    ValidationSource, to_json,
};
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::model::Model;
use simulation::record::Record;
use simulation::truth::Truth;
use simulation::{builtin_path, provenance, simulate};

/// The machine of the demo.
pub const MACHINE: &str = "seed-ac";
/// Its reduced model (the seed's Table 2).
pub const REDUCED: &str = "reduced";
/// The truth of the demo.
pub const TRUTH: &str = "seed-ac-demo";
/// The paths simulated, and the offset of each one's noise seed from the truth's.
pub const PATHS: [(&str, u64); 3] = [("K4", 0), ("K1", 1), ("K2", 2)];
/// The extended machine description the demo writes.
pub const EXTENDED_FILE: &str = "seed-ac-extended.toml";
/// The seed's deviations (measured minus predicted) on K4, and on K1 and K2, µm.
pub const SEED_DEVIATION_UM: (f64, f64) = (12.0, 15.0);

/// One file of the demo.
#[derive(Clone, Debug, PartialEq)]
pub struct DemoFile {
    /// Its name in the output directory.
    pub name: String,
    /// Its contents.
    pub contents: String,
    /// What it is, for people.
    pub what: String,
    /// The result it holds, for a JSON report (what the HTML reports and the history take,
    /// never read back from the JSON).
    pub document: Option<Document>,
}

/// The demo's results.
#[derive(Clone, Debug)]
pub struct Demo {
    /// The files to write, in order.
    pub files: Vec<DemoFile>,
    /// The figures to draw (their file names are [`diagnosis::figures::PathFigure::file_name`]
    /// and [`diagnosis::figures::SpectrumFigure::file_name`]).
    pub figures: Figures,
    /// The summary for people.
    pub text: String,
}

/// The list of the files written to `dir` (name, what it is), and the time taken, for people.
pub fn written(dir: &str, files: &[(String, String)], seconds: f64) -> String {
    let mut text = format!("\nWrote {dir}/:\n");
    for (name, what) in files {
        text.push_str(&format!("  {dir}/{name}  ({what})\n"));
    }
    text.push_str(&format!(
        "\nDone in {seconds:.2} s. The same steps one by one: rtest simulate, rtest identify, rtest validate, rtest diagnose (see --help).\n"
    ));
    text
}

/// A step of the demo that failed.
#[derive(Debug, thiserror::Error)]
#[error("demo: {step}: {message}")]
pub struct DemoError {
    /// What it was doing.
    pub step: &'static str,
    /// Why it failed.
    pub message: String,
}

fn failed<E: std::fmt::Display>(step: &'static str) -> impl Fn(E) -> DemoError {
    move |e| DemoError {
        step,
        message: e.to_string(),
    }
}

/// `model` identified on `record` (the file `data`: its record labelled by the file's stem,
/// on a set-up of that label, at the machine's default parameters) as a campaign of one,
/// refined against the exact machine; with what the refinement did and the fit in the
/// model's own terms.
pub(crate) fn identify_refined(
    m: &Machine,
    model: &Model,
    record: &Record,
    data: &str,
    step: &'static str,
) -> Result<Identified, DemoError> {
    let label = formats::campaign::stem_label(std::path::Path::new(data));
    let one = CampaignRecord::new(
        label.clone(),
        record.clone(),
        m.default_parameters(),
        label,
        false,
    );
    let campaign = Campaign::new(vec![one]).map_err(failed(step))?;
    let opts = IdentifyOptions::default().refined(RefineOptions::default());
    let fit = identify(m, model, &campaign, &opts).map_err(failed(step))?;
    match (fit.single_record(m), fit.refinement.clone()) {
        (Some(own), Some(refinement)) => Ok(Identified {
            campaign: fit,
            own,
            refinement,
        }),
        _ => Err(DemoError {
            step,
            message: "the campaign of one record gave no refined fit of it".into(),
        }),
    }
}

/// A record identified by [`identify_refined`].
pub(crate) struct Identified {
    /// The identification of its campaign of one: what reports, validation and compensation
    /// take.
    pub(crate) campaign: CampaignIdentification,
    /// The same fit in the model's own terms (`XOW`, not `XOW[k4]`): what the text compares
    /// with the truth.
    pub(crate) own: Identification,
    /// What the refinement did.
    pub(crate) refinement: Refinement,
}

/// One simulated path.
pub(crate) struct Run {
    pub(crate) name: &'static str,
    pub(crate) file: String,
    pub(crate) truth: Truth,
    pub(crate) record: Record,
}

/// Runs the demo; `dir` is the output directory's name as the files will be named in the
/// reports (`rtest-demo`).
///
/// # Errors
/// [`DemoError`] naming the step that failed (none does on a correct build).
pub fn run(dir: &str) -> Result<Demo, DemoError> {
    let m = model_spec::builtin(MACHINE)
        .ok_or_else(|| failed("machine")(format!("no built-in machine {MACHINE}")))?
        .map_err(failed("machine"))?;
    let truth = builtin_truth(TRUTH, &m)
        .ok_or_else(|| failed("truth")(format!("no built-in truth {TRUTH}")))?
        .map_err(failed("truth"))?;
    let model = Model::of(&m, REDUCED)
        .ok_or_else(|| failed("model")(format!("machine {MACHINE} has no model {REDUCED}")))?;
    let path_of = |f: &str| format!("{dir}/{f}");

    // 1. Simulations.
    let mut runs = Vec::new();
    let mut files = Vec::new();
    for (name, offset) in PATHS {
        let path = builtin_path(&m, name)
            .ok_or_else(|| failed("path")(format!("no built-in path {name}")))?
            .map_err(failed("path"))?;
        let mut t = truth.clone();
        t.seed = truth.seed.wrapping_add(offset);
        let record = simulate(&m, &t, &path).map_err(failed("simulation"))?;
        let comments = provenance(&m, name, &t, record.samples.len());
        let csv = format_record(&m, &record, &comments).map_err(failed("simulation"))?;
        let file = format!("{}.csv", name.to_ascii_lowercase());
        files.push(DemoFile {
            name: file.clone(),
            contents: csv,
            what: format!(
                "{name} measurement: {} samples; axes mm and degrees, readings µm",
                record.samples.len()
            ),
            document: None,
        });
        runs.push(Run {
            name,
            file,
            truth: t,
            record,
        });
    }
    let k4 = &runs[0];

    // 2. Identification on K4, refined against the exact machine.
    let k4_file = path_of(&k4.file);
    let fitted = identify_refined(&m, &model, &k4.record, &k4_file, "identification")?;
    let (ident, refinement) = (&fitted.own, &fitted.refinement);
    check_values(&m, ident, &ValueLimits::default()).map_err(failed("identification"))?;
    let identification = IdentificationReport::of_campaign(
        &m,
        CampaignSource {
            label: REDUCED,
            base_model: Some(REDUCED),
            data: std::slice::from_ref(&k4_file),
        },
        &fitted.campaign,
        Some(refinement),
    )
    .map_err(failed("identification"))?;
    files.push(DemoFile {
        name: "identify.json".into(),
        contents: to_json(&identification).map_err(failed("identification"))?,
        what: "the reduced model identified on K4, as rtest identify --json writes it".into(),
        document: Some(Document::Identification(Box::new(identification.clone()))),
    });

    // 3. Validation on every path (K4: the fit itself), exact prediction.
    // Every path was measured on K4's ball set-up: each record on the fitted set-up.
    let exact = ValidateOptions::new().exact(true);
    let fitted_label = formats::campaign::stem_label(std::path::Path::new(&k4_file));
    let values = CampaignValues::of(&fitted.campaign);
    let mut validations = Vec::new();
    for r in &runs {
        let data = path_of(&r.file);
        let label = formats::campaign::stem_label(std::path::Path::new(&data));
        let record = CampaignRecord::new(
            label,
            r.record.clone(),
            m.default_parameters(),
            fitted_label.clone(),
            false,
        );
        let campaign = Campaign::new(vec![record]).map_err(failed("validation"))?;
        let v =
            validate(&m, &values, &campaign, &exact, &Unwatched).map_err(failed("validation"))?;
        let report = ValidationReport::new(
            &m,
            ValidationSource {
                model: REDUCED,
                params: &path_of("identify.json"),
                data: &[data],
                kinematics: &[m.default_parameters()],
                exact: true,
            },
            &v,
        )
        .map_err(failed("validation"))?;
        if r.name != "K4" {
            files.push(DemoFile {
                name: format!("validate-{}.json", r.name.to_ascii_lowercase()),
                contents: to_json(&report).map_err(failed("validation"))?,
                document: Some(Document::Validation(Box::new(report.clone()))),
                what: format!(
                    "validation on {}, as rtest validate --json writes it",
                    r.name
                ),
            });
        }
        validations.push(report);
    }

    // 4. What the reduced model lacks according to the truth.
    let records: Vec<&Record> = runs.iter().map(|r| &r.record).collect();
    let hidden =
        hidden_terms(&m, &truth, &model, &k4.record, &records).map_err(failed("hidden terms"))?;

    // 5. The diagnosis of the reduced model on K4, K1 and K2 held out (on K4's set-up), from
    // the data alone.
    let opts = DiagnoseOptions::default();
    let label = |r: &Run| r.name.to_ascii_lowercase();
    let held: Vec<(String, Record)> = runs[1..]
        .iter()
        .map(|r| (label(r), r.record.clone()))
        .collect();
    let (fitted, held_out) = one_record(
        &label(k4),
        k4.record.clone(),
        held,
        m.default_parameters(),
        false,
    )
    .map_err(failed("diagnosis"))?;
    let diagnosis =
        diagnose(&m, &model, &fitted, &held_out, &opts, &Unwatched).map_err(failed("diagnosis"))?;
    let machine_text = model_spec::write::source_text(MACHINE).map_err(failed("extended model"))?;
    let (ext_name, ext_text) = diagnosis
        .extended_machine(
            &m,
            &machine_text,
            REDUCED,
            "rtest demo: the diagnosis of the reduced model on K4",
        )
        .map_err(failed("extended model"))?;
    let held_files: Vec<String> = runs[1..].iter().map(|r| path_of(&r.file)).collect();
    let source = DiagnosisSource {
        machine_source: MACHINE,
        label: REDUCED,
        data: vec![k4_file.clone()],
        held_out: held_files.clone(),
        data_arguments: vec!["--data".into(), k4_file.clone()],
        opts: &opts,
        model_out: Some((ext_name, path_of(EXTENDED_FILE))),
    };
    let diagnosis_report =
        DiagnosisReport::new(&m, &source, &diagnosis).map_err(failed("diagnosis"))?;
    let mut names = vec![k4_file.clone()];
    names.extend(held_files);
    let figures = figures(&m, &diagnosis, REDUCED, &opts, &fitted, &held_out, &names)
        .map_err(failed("figures"))?;

    // 6. The recommended model put back onto the machine: K1 and K2 compensated.
    let compensation = compensation::compensate_held_out(
        &m, &truth, &model, &diagnosis, &runs, &k4_file, &mut files,
    )?;

    // Files people take away.
    let code = codegen::emit::generate_machine(&m, &[]).map_err(failed("code generation"))?;
    let full = codegen::GainModel::derive(&m, &m.errors);
    let reduced = codegen::GainModel::derive(&m, &model.errors());
    let markdown = render(
        &m,
        &reduced,
        &report::text::gains::title(&m, Some(REDUCED), reduced.errors.len()),
        Format::Markdown,
    );
    files.push(DemoFile {
        name: "seed_ac.rs".into(),
        contents: code,
        what: "generated no_std Rust gains of the full and reduced models".into(),
        document: None,
    });
    files.push(DemoFile {
        name: "gains-reduced.md".into(),
        contents: markdown,
        what: "gain table of the reduced model, the seed's Table 2, Markdown".into(),
        document: None,
    });
    files.push(DemoFile {
        name: "diagnose.json".into(),
        contents: to_json(&diagnosis_report).map_err(failed("diagnosis"))?,
        what: "the diagnosis of the reduced model on K4, as rtest diagnose --json writes it".into(),
        document: Some(Document::Diagnosis(Box::new(diagnosis_report.clone()))),
    });
    files.push(DemoFile {
        name: EXTENDED_FILE.into(),
        contents: ext_text,
        what: "seed-ac with the extended model appended ([models.extended]), as rtest diagnose --model-out writes it".into(),
        document: None,
    });

    let ops: Vec<(&str, usize, String)> = [(FULL_MODEL, &full), (REDUCED, &reduced)]
        .into_iter()
        .map(|(name, g)| {
            (
                name,
                g.errors.len(),
                codegen::compile(&m, g).op_counts().to_string(),
            )
        })
        .collect();
    let text = text::summary(&text::Summary {
        m: &m,
        truth: &truth,
        runs: &runs,
        ident,
        refinement,
        identification: &identification,
        validations: &validations,
        hidden: &hidden,
        diagnosis: &diagnosis,
        diagnosis_report: &diagnosis_report,
        operations: &ops,
        compensation: &compensation,
    });
    Ok(Demo {
        files,
        figures,
        text,
    })
}
