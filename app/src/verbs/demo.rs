//! `rtest demo`: the seed's experiment on the virtual seed machine (`app::demo`), written to
//! `./rtest-demo/`.

use super::{EXIT_CODES, Error, VerbResult, check_outputs};
use crate::Done;
use crate::demo;
use output::Outputs;
use std::path::Path;
use std::time::Instant;

/// Directory the demo writes to, relative to the working directory.
const OUT_DIR: &str = "rtest-demo";

/// The history database the demo records its identification in, inside [`OUT_DIR`].
const HISTORY: &str = "rtest-history.sqlite";

/// The HTML report of the check, inside [`OUT_DIR`].
const REPORT: &str = "report.html";
/// The HTML report of the compensation: the recommended model's identification on K4, the
/// diagnosis that recommends it, K1 compensated with it.
const REPORT_COMPENSATION: &str = "report-compensation.html";

/// The machine id of the demo's virtual machine in that history.
const MACHINE_ID: &str = "demo";

/// Flags of `rtest demo`.
#[derive(Debug, clap::Args)]
#[command(
    about = "The seed's experiment on the virtual seed machine; writes ./rtest-demo/",
    long_about = "\
The main job of rtest on the seed's five-axis machine (seed-ac), with the documented demo truth \
seed-ac-demo (docs/truth.md): location errors of A and C and ball set-up errors of 10-30 µm and \
µrad, an angular positioning error of C twice per revolution (ECC@harmonic:2, 10 µrad) that the \
reduced model lacks, and 0.5 µm of R-test noise.

1. Simulates K4, K1 and K2 on the exact virtual machine.
2. Identifies the reduced model (the seed's Table 2) on K4: values ± std against the truth.
3. Validates on K1 and K2: residual RMS and max per direction (µm), before and after, against \
the seed's ±12 µm (K4) and ±15 µm (K1, K2).
4. Says what the reduced model leaves unexplained, and why.
5. Diagnoses it on K4 with K1 and K2 held out: the missing term, named as an ISO 230 error with \
its value ± std (µm, µrad), then checked against the truth.
6. Compensates K1 and K2 with the recommended model; measures what is left on the exact machine.

Writes, in ./rtest-demo/ (all or none), and lists: the measurements k4.csv, k1.csv, k2.csv (axes \
in mm and degrees, readings in µm), the JSON reports of identify, validate, diagnose and \
compensate, the generated code, the gain table (mm/mm, mm/rad), the extended machine, SVG \
figures and two HTML reports (report.html, report-compensation.html). Records the \
identification on K4 in rtest-demo/rtest-history.sqlite (machine id demo). The same steps one \
by one: rtest simulate / identify / validate / diagnose / compensate / history.

Details: README.md (the demo and its files), docs/truth.md, docs/report.md.",
    after_help = EXIT_CODES
)]
pub struct DemoArgs {}

/// Runs `rtest demo`.
pub fn run(_args: &DemoArgs) -> VerbResult<Done> {
    let start = Instant::now();
    let dir = Path::new(OUT_DIR);
    check_outputs(&[], &[], &[("demo", dir)])?;
    // A history left by an earlier run is checked before any work.
    let db = dir.join(HISTORY);
    let mut recorder =
        super::record::Recorder::open("demo:", &db, MACHINE_ID, &["K4"])?.saying(recorded);
    let result = demo::run(OUT_DIR).map_err(|e| Error::computation(e.to_string()))?;
    let mut files = Outputs::new();
    let mut listed = Vec::new();
    for f in &result.files {
        files.add_in_dir("demo", dir, &f.name, f.contents.clone());
        listed.push((f.name.clone(), f.what.clone()));
    }
    for (name, what, svg) in super::figures::svgs(&result.figures)? {
        files.add_in_dir("demo", dir, &name, svg);
        listed.push((name, what));
    }
    files.add_in_dir("demo", dir, REPORT, html_report(&result, Check::Reduced)?);
    listed.push((
        REPORT.to_string(),
        "the HTML report of the check: identification on K4, validations on K1 and K2, diagnosis with its figures (rtest report, docs/report.md)".to_string(),
    ));
    files.add_in_dir(
        "demo",
        dir,
        REPORT_COMPENSATION,
        html_report(&result, Check::Compensation)?,
    );
    listed.push((
        REPORT_COMPENSATION.to_string(),
        "the HTML report of the compensation: the recommended model identified on K4, the diagnosis, K1 compensated".to_string(),
    ));
    let check = check_of(&mut recorder, &result.files)?;
    let seconds = start.elapsed().as_secs_f64();
    let text = result.text + &demo::written(OUT_DIR, &listed, seconds);
    Ok(Done::new(text, files, false)
        .unlisted()
        .recording_last(recorder, check))
}

/// The check of the demo's identification on K4 (its `identify.json`, from `k4.csv`), for the
/// history, with `k4.csv` among the recorder's inputs.
fn check_of(
    recorder: &mut super::record::Recorder,
    files: &[demo::DemoFile],
) -> VerbResult<history::Check> {
    let file = |name: &str| {
        files
            .iter()
            .find(|f| f.name == name)
            .ok_or_else(|| Error::computation(format!("demo: no {name} to record")))
    };
    let k4 = file("k4.csv")?;
    recorder.add_input(
        "--data",
        &format!("{OUT_DIR}/k4.csv"),
        k4.contents.as_bytes(),
    );
    match &file("identify.json")?.document {
        Some(::report::Document::Identification(report)) => Ok(
            history::Check::from_identification(report, recorder.provenance()),
        ),
        _ => Err(Error::computation(
            "demo: identify.json holds no identification to record",
        )),
    }
}

/// The line that says where the demo's check `id` went.
fn recorded(id: i64) -> String {
    format!(
        "Recorded the identification on K4 as check {id} of machine `{MACHINE_ID}` in {OUT_DIR}/{HISTORY}; its trend: rtest history --db {OUT_DIR}/{HISTORY} --machine-id {MACHINE_ID} --error XOC\n"
    )
}

/// The two checks the demo's HTML reports show.
#[derive(Clone, Copy, PartialEq)]
enum Check {
    /// The reduced model identified on K4, validated on K1 and K2, diagnosed.
    Reduced,
    /// The model the diagnosis recommends identified on K4, the diagnosis, K1 compensated.
    Compensation,
}

/// The HTML report of one of the demo's checks, with the diagnosis's path figures and the
/// measurement files hashed as written.
fn html_report(result: &demo::Demo, check: Check) -> VerbResult<String> {
    let m = super::load_machine("seed-ac")?;
    let mut i = super::report::inputs_for(&m, &[]);
    let fail = |e: ::report::InputError| Error::computation(format!("demo: {e}"));
    for f in &result.files {
        let path = format!("{OUT_DIR}/{}", f.name);
        if ["k4.csv", "k1.csv", "k2.csv"].contains(&f.name.as_str()) {
            i.files.push(::report::InputFile {
                role: "measurement".into(),
                path: path.clone(),
                digest: Ok(history::sha256::Digest::of(f.contents.as_bytes())),
                modified: None,
            });
        }
        let json = |prefix: &str| f.name.starts_with(prefix) && f.name.ends_with(".json");
        let wanted = f.name == "diagnose.json"
            || match check {
                Check::Reduced => f.name == "identify.json" || json("validate-"),
                Check::Compensation => f.name == "identify-recommended.json" || json("compensate-"),
            };
        if let (true, Some(doc)) = (wanted, &f.document) {
            i.add(&path, doc.clone()).map_err(fail)?;
        }
    }
    if check == Check::Reduced {
        i.no_compensation = Some(format!(
            "The demo compensated K1 with the model the diagnosis recommends, identified again on K4 (identify-recommended.json), not with this report's: {OUT_DIR}/{REPORT_COMPENSATION} is the report of that compensation."
        ));
    }
    i.path_figures = ::report::figures::path_figures(&result.figures)
        .map_err(|e| Error::computation(format!("demo: {e}")))?;
    super::report::render("demo", &i)
}
