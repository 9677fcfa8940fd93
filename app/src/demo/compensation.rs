//! The demo's last step: the model the diagnosis recommends (the reduced model when it
//! recommends nothing), identified on K4, put back onto the machine: K1 and K2 compensated as
//! `rtest compensate` does, and run on the exact virtual machine to see what is left.

use super::{DemoError, DemoFile, REDUCED, Run, failed};
use compensation::run::{CommandedPose, compensate_poses};
use compensation::values::MachineErrors;
use compensation::verify::machine_error_rms;
use diagnosis::Diagnosis;
use fitting::campaign::CampaignValues;
use formats::poses::to_file_units;
use model_spec::Machine;
use model_spec::units::format_scaled;
use report::inputs::Document;
use report::json::compensate::{CompensationReport, CompensationSource};
use report::json::{CampaignSource, IdentificationReport, to_json};
use simulation::model::Model;
use simulation::truth::Truth;

/// What compensation did on one held-out path.
pub(crate) struct Compensated {
    /// The path.
    pub(crate) name: &'static str,
    /// The machine's own error RMS (set-up of the ball aside) before and after, mm.
    pub(crate) before: f64,
    /// After.
    pub(crate) after: f64,
}

/// The step's results: the model used, the paths, and its files.
pub(crate) struct CompensationStep {
    /// The label of the model compensated with.
    pub(crate) label: String,
    /// The errors compensated.
    pub(crate) compensated: Vec<String>,
    /// One per held-out path.
    pub(crate) paths: Vec<Compensated>,
}

/// A pose CSV of `poses` (commands in mm and rad) with the machine's axis letters as columns
/// (mm and degrees, the shortest decimals that read back), as `rtest compensate -o` writes a
/// pose CSV with those columns.
fn pose_csv(m: &Machine, poses: &[Vec<f64>]) -> String {
    let mut text = m
        .axes
        .iter()
        .map(|a| a.name.as_str())
        .collect::<Vec<_>>()
        .join(",");
    text.push('\n');
    for q in poses {
        let row: Vec<String> = to_file_units(m, q)
            .iter()
            .map(|&x| format_scaled(x, 0))
            .collect();
        text.push_str(&row.join(","));
        text.push('\n');
    }
    text
}

/// Identifies the recommended model on K4 (`runs[0]`), compensates the other paths and
/// measures them on the exact machine with `truth`; adds the identification (of the record
/// named `data`), the compensated K1 and its summary to `files`.
pub(crate) fn compensate_held_out(
    m: &Machine,
    truth: &Truth,
    base: &Model,
    diagnosis: &Diagnosis,
    runs: &[Run],
    data: &str,
    files: &mut Vec<DemoFile>,
) -> Result<CompensationStep, DemoError> {
    let (model, label) = if diagnosis.recommendation.recommended {
        (
            diagnosis.extended_terms(),
            diagnosis.extended_label(m, REDUCED),
        )
    } else {
        (base.clone(), REDUCED.to_string())
    };
    let k4 = &runs[0];
    let fitted = super::identify_refined(m, &model, &k4.record, data, "compensation")?;
    let data = [data.to_string()];
    let source = CampaignSource {
        label: &label,
        base_model: Some(REDUCED),
        data: &data,
    };
    let report =
        IdentificationReport::of_campaign(m, source, &fitted.campaign, Some(&fitted.refinement))
            .map_err(failed("compensation"))?;
    let json = to_json(&report).map_err(failed("compensation"))?;
    // The values as identified, in process (the JSON above is the file the demo writes).
    let values = CampaignValues::of(&fitted.campaign);
    let (errors, left_out) = MachineErrors::from_values(m, &values, "identify-recommended.json")
        .map_err(failed("compensation"))?;
    files.push(DemoFile {
        name: "identify-recommended.json".into(),
        contents: json,
        what: format!("the model the diagnosis recommends ({label}) identified on K4, as rtest identify --json writes it"),
        document: Some(Document::Identification(Box::new(report.clone()))),
    });
    let params = m.default_parameters();
    let values_at = |q: &[f64], out: &mut [f64]| errors.values_at(m, q, out);
    let mut paths = Vec::new();
    for r in &runs[1..] {
        let commanded: Vec<Vec<f64>> = r
            .record
            .samples
            .iter()
            .map(|s| s.commands.clone())
            .collect();
        // Line numbers of the pose CSV: the header is line 1.
        let poses: Vec<CommandedPose> = commanded
            .iter()
            .enumerate()
            .map(|(i, q)| CommandedPose {
                line: i + 2,
                commands: q.clone(),
            })
            .collect();
        let file = format!("{}-commanded.csv", r.name.to_ascii_lowercase());
        let done = compensate_poses(
            m,
            errors.errors(),
            params.clone(),
            &file,
            &poses,
            &values_at,
        )
        .map_err(failed("compensation"))?;
        let pairs = |qs: &[Vec<f64>]| -> f64 {
            let at: Vec<(&[f64], &[f64])> = qs
                .iter()
                .map(|q| (q.as_slice(), params.as_slice()))
                .collect();
            machine_error_rms(m, truth, &at)
        };
        paths.push(Compensated {
            name: r.name,
            before: pairs(&commanded),
            after: pairs(&done.poses),
        });
        if r.name == "K1" {
            let csv = pose_csv(m, &done.poses);
            let mut source =
                CompensationSource::of(m, &label, "identify-recommended.json", &errors, &left_out);
            source.input = "K1".into();
            source.output = "k1-compensated.csv".into();
            source.format = "csv".into();
            let summary =
                CompensationReport::new(source, &done.summary).map_err(failed("compensation"))?;
            files.push(DemoFile {
                name: "k1-compensated.csv".into(),
                contents: csv,
                what: "K1's poses compensated with the recommended model, as rtest compensate -o writes them (mm, degrees)".into(),
                document: None,
            });
            files.push(DemoFile {
                name: "compensate-k1.json".into(),
                contents: to_json(&summary).map_err(failed("compensation"))?,
                document: Some(Document::Compensation(Box::new(summary.clone()))),
                what: "the summary of K1's compensation, as rtest compensate --json writes it"
                    .into(),
            });
        }
    }
    Ok(CompensationStep {
        compensated: errors
            .errors()
            .iter()
            .map(|&e| m.catalogue[e].name.clone())
            .collect(),
        label,
        paths,
    })
}
