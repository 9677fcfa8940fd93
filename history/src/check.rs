//! One check: an identification as the history keeps it. Built from the identification
//! report ([`IdentificationReport`], of one record or of a campaign of several) and what only
//! the caller knows: the machine id, the test paths, the time of the measurement and the input
//! files.

use formats::time::Timestamp;
use report::json::identify::ParameterReport;
use report::json::{IdentificationReport, ValidationReport};
use serde::Serialize;

/// The longest machine id, test-path label, or text field of a check, in characters.
pub const MAX_LABEL_CHARS: usize = 200;

/// An input file of a check: which flag named it, its path as given, its size and digest.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct InputFile {
    /// The flag that named it (`--data`, `--machine`, `--campaign`, `--noise-record`,
    /// `--instrument`).
    pub role: String,
    /// The path as given on the command line (relative paths stay relative).
    pub path: String,
    /// Its size, bytes.
    pub bytes: u64,
    /// Its SHA-256, 64 lower-case hex digits (as `sha256sum` prints it).
    pub sha256: String,
}

/// One identified parameter of a check, in its unit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Parameter {
    /// The parameter's name as the report writes it (`XOC`, `ECC@harmonic:2:cos`, `XOW[k4]`).
    pub name: String,
    /// Its effect (`XOC`, `ECC`, `dx0`).
    pub error: String,
    /// Its basis column (`const`, `harmonic:2:cos`, …).
    pub basis: String,
    /// In a campaign: `shared`, `setup` or `record`; `None` in a single identification.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub owner: Option<String>,
    /// In a campaign: the set-up's or record's label of a `setup` or `record` parameter.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub of: Option<String>,
    /// The estimate, in `unit`; `None` when the data did not determine it.
    pub value: Option<f64>,
    /// Its standard uncertainty, in `unit`; `None` when undetermined, fixed, or without a
    /// degree of freedom.
    pub std: Option<f64>,
    /// `um`, `urad`, `ms` or `1`.
    pub unit: String,
    /// Whether the data determined it.
    pub determined: bool,
    /// Fixed to 0 by the constraint.
    pub fixed: bool,
}

impl Parameter {
    /// The parameter as an identification report writes it; `owner` and `of` as a campaign
    /// report gives them (`None` in a single identification).
    fn from_report(q: &ParameterReport, owner: Option<String>, of: Option<String>) -> Parameter {
        Parameter {
            name: q.name.clone(),
            error: q.error.clone(),
            basis: q.basis.clone(),
            owner,
            of,
            value: q.value,
            std: q.std,
            unit: q.unit.clone(),
            determined: q.determined,
            fixed: q.fixed,
        }
    }
}

/// Whether a check fitted one record or a campaign.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum CheckKind {
    /// One record (`rtest identify --data FILE`).
    Record,
    /// Several records fitted together (`--data a.csv,b.csv`, `--campaign FILE`).
    Campaign,
}

impl CheckKind {
    /// `record` or `campaign`, as stored.
    pub fn as_str(self) -> &'static str {
        match self {
            CheckKind::Record => "record",
            CheckKind::Campaign => "campaign",
        }
    }
}

/// One identification as recorded: who, what, when, from which files, and every value.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Check {
    /// The user's id of the physical machine (a serial number): two machines of the same
    /// description are two histories.
    pub machine_id: String,
    /// The description's fingerprint (`Machine::fingerprint`).
    pub fingerprint: String,
    /// The description's name (`seed-ac`).
    pub machine: String,
    /// The model's label (`reduced`, `reduced + ECC@harmonic:2`).
    pub model: String,
    /// The machine's model it started from (`--model`), if any.
    pub base_model: Option<String>,
    /// The terms fitted, in model order (the R-test offsets of zeroed readings included).
    pub terms: Vec<String>,
    /// The test paths measured (labels: `K4`, or a campaign's record labels), each once.
    pub paths: Vec<String>,
    /// When the measurement was taken (UTC).
    pub measured_at: Timestamp,
    /// When the check was recorded (UTC).
    pub recorded_at: Timestamp,
    /// The version of rtest that identified it.
    pub rtest_version: String,
    /// One record or a campaign.
    pub kind: CheckKind,
    /// A re-check (`rtest validate --refit NAMES --record`): a few poses measured again
    /// refitted the named machine parameters (the pivot) and the records' new set-ups (the
    /// preset), every other value held at a calibration's. Re-checks make their own series.
    pub recheck: bool,
    /// Every input file, with its digest.
    pub inputs: Vec<InputFile>,
    /// Every parameter, in report order.
    pub parameters: Vec<Parameter>,
    /// Numerical rank of the fit.
    pub rank: usize,
    /// Parameters not fixed by the constraint.
    pub free_parameters: usize,
    /// Condition number of the scaled design matrix; `None` when the rank is 0.
    pub condition: Option<f64>,
    /// The groups of parameters the data could not separate (the unidentifiable names).
    pub unidentifiable: Vec<Vec<String>>,
    /// Residual RMS, `√(RSS / 3N)`, µm.
    pub residual_rms_um: f64,
    /// σ̂ of the fit, µm; `None` without a degree of freedom.
    pub sigma_um: Option<f64>,
    /// Samples fitted.
    pub samples: usize,
    /// Degrees of freedom.
    pub dof: usize,
    /// Whether the readings were zeroed (then `dx0 dy0 dz0` were fitted).
    pub zeroed: bool,
    /// The constraint (`none`, `minimum-norm`, `zero: XOC, YOA`).
    pub constraint: String,
    /// `exact` (refined against the exact machine) or `first-order`.
    pub refinement: String,
    /// The noise model the uncertainties assume, for people; `None` if the report had none.
    pub noise_model: Option<String>,
}

/// What a re-check's check takes from the calibration it re-checked: its machine description's
/// fingerprint, its model's label, base model and terms.
#[derive(Clone, Debug, PartialEq)]
pub struct RecheckedCalibration {
    /// The machine description's fingerprint.
    pub fingerprint: String,
    /// The model's label.
    pub model: String,
    /// The base model, when the model extends one.
    pub base_model: Option<String>,
    /// The model's terms.
    pub terms: Vec<String>,
}

/// `(effect, basis)` of a parameter's name (`ECC@harmonic:2:cos` → `ECC`, `harmonic:2:cos`;
/// `XOB` → `XOB`, `const`).
fn split_name(name: &str) -> (String, String) {
    match name.split_once('@') {
        Some((e, b)) => (e.to_string(), b.to_string()),
        None => (name.to_string(), "const".to_string()),
    }
}

/// What a check says besides its identification report.
#[derive(Clone, Debug, PartialEq)]
pub struct Provenance {
    /// The user's machine id.
    pub machine_id: String,
    /// The test paths measured; empty: the report's records (a campaign's labels) or, for a
    /// single record, the stem of its data file (`k4.csv` → `k4`).
    pub paths: Vec<String>,
    /// When the measurement was taken.
    pub measured_at: Timestamp,
    /// When it is recorded.
    pub recorded_at: Timestamp,
    /// The rtest version.
    pub rtest_version: String,
    /// The input files.
    pub inputs: Vec<InputFile>,
}

/// The stem of a file name (`runs/k4.csv` → `k4`).
fn stem(path: &str) -> String {
    std::path::Path::new(path)
        .file_stem()
        .map_or_else(|| path.to_string(), |s| s.to_string_lossy().into_owned())
}

impl Check {
    /// The check of an identification, of one record ([`CheckKind::Record`], stored as a
    /// single identification always was: parameters without owners, the terms with the zero
    /// offsets of zeroed readings, the data file's stem as its path) or of several
    /// ([`CheckKind::Campaign`]: every parameter with its owner, `shared`, `setup` or `record`,
    /// and the records' labels as paths). The paths of `p`, when given, replace the default.
    pub fn from_identification(report: &IdentificationReport, p: Provenance) -> Check {
        let campaign = report.is_campaign();
        let paths = if !p.paths.is_empty() {
            p.paths
        } else if campaign {
            report.records.iter().map(|r| r.label.clone()).collect()
        } else {
            let data = report
                .data
                .as_deref()
                .or_else(|| report.records.first().map(|r| r.data.as_str()))
                .unwrap_or("");
            vec![stem(data)]
        };
        let mut terms = report.terms.clone();
        if campaign {
            // The records' zero offsets are not among a campaign's terms; a zeroed record adds
            // them, and they change what the other values mean.
            for q in &report.parameters {
                if q.owner.as_deref() == Some("record") && q.basis == "const" {
                    let t = q.error.clone();
                    if !terms.contains(&t) {
                        terms.push(t);
                    }
                }
            }
        }
        Check {
            machine_id: p.machine_id,
            fingerprint: report.fingerprint.clone(),
            machine: report.machine.clone(),
            model: report.model.clone(),
            base_model: report.base_model.clone(),
            terms,
            paths,
            measured_at: p.measured_at,
            recorded_at: p.recorded_at,
            rtest_version: p.rtest_version,
            kind: if campaign {
                CheckKind::Campaign
            } else {
                CheckKind::Record
            },
            recheck: false,
            inputs: p.inputs,
            parameters: report
                .parameters
                .iter()
                .map(|q| {
                    if campaign {
                        Parameter::from_report(q, q.owner.clone(), q.of.clone())
                    } else {
                        Parameter::from_report(q, None, None)
                    }
                })
                .collect(),
            rank: report.rank,
            free_parameters: report.free_parameters,
            condition: report.condition,
            unidentifiable: report.confounded.clone(),
            residual_rms_um: report.residual_rms_um,
            sigma_um: report.sigma_um,
            samples: report.samples,
            dof: report.dof,
            zeroed: report.any_zeroed(),
            constraint: report.constraint.clone(),
            refinement: report.refinement.method.clone(),
            noise_model: report.noise_model.as_ref().map(|n| n.text.clone()),
        }
    }

    /// The check of a re-check ([`Check::recheck`] set): the validation report `v` with its
    /// `recheck` part, of the calibration `calibration` (its model's label and terms). Its
    /// parameters are the pivot (owner `shared`) and every record's refits (the preset: owner
    /// `setup`; a zero: owner `record`); the held values are not the re-check's and are not
    /// stored. Its constraint says what was refitted (`recheck: XOB, ZOB`), so that only
    /// re-checks of the same parameters make a series. `None` when `v` is no re-check.
    pub fn from_recheck(
        v: &ValidationReport,
        calibration: &RecheckedCalibration,
        p: Provenance,
    ) -> Option<Check> {
        let c = v.recheck.as_ref()?;
        let paths = if p.paths.is_empty() {
            v.records.iter().map(|r| r.label.clone()).collect()
        } else {
            p.paths
        };
        let mut parameters: Vec<Parameter> = c
            .pivot
            .iter()
            .map(|q| {
                let (error, basis) = split_name(&q.name);
                Parameter {
                    name: q.name.clone(),
                    error,
                    basis,
                    owner: Some("shared".into()),
                    of: None,
                    value: q.value,
                    std: q.std,
                    unit: q.unit.clone(),
                    determined: q.value.is_some(),
                    fixed: false,
                }
            })
            .collect();
        for r in &v.records {
            for q in &r.refitted {
                let base = q.name.split('[').next().unwrap_or(&q.name);
                let (error, basis) = split_name(base);
                let setup = matches!(error.as_str(), "XOW" | "YOW" | "ZOW" | "Xw" | "Yw" | "Zw");
                parameters.push(Parameter {
                    name: q.name.clone(),
                    error,
                    basis,
                    owner: Some(if setup { "setup" } else { "record" }.into()),
                    of: Some(if setup {
                        r.setup.clone()
                    } else {
                        r.label.clone()
                    }),
                    value: q.value,
                    std: q.std,
                    unit: q.unit.clone(),
                    determined: q.value.is_some(),
                    fixed: false,
                });
            }
        }
        let free = parameters.len();
        let rank = parameters.iter().filter(|q| q.determined).count();
        let unidentifiable: Vec<Vec<String>> = parameters
            .iter()
            .filter(|q| !q.determined)
            .map(|q| vec![q.name.clone()])
            .collect();
        Some(Check {
            machine_id: p.machine_id,
            fingerprint: calibration.fingerprint.clone(),
            machine: v.machine.clone(),
            model: calibration.model.clone(),
            base_model: calibration.base_model.clone(),
            terms: calibration.terms.clone(),
            paths,
            measured_at: p.measured_at,
            recorded_at: p.recorded_at,
            rtest_version: p.rtest_version,
            kind: if v.records.len() == 1 {
                CheckKind::Record
            } else {
                CheckKind::Campaign
            },
            recheck: true,
            inputs: p.inputs,
            parameters,
            rank,
            free_parameters: free,
            condition: None,
            unidentifiable,
            residual_rms_um: v.overall.residual_rms_um,
            sigma_um: c.sigma_um,
            samples: v.samples,
            dof: c.dof,
            zeroed: v.records.iter().any(|r| r.zeroed),
            constraint: format!(
                "recheck: {}",
                c.pivot
                    .iter()
                    .map(|q| q.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            refinement: v.prediction.clone(),
            noise_model: Some(c.scale_text()),
        })
    }

    /// The parameter called `name` ([`same_name`]), if the check has it.
    pub fn parameter(&self, name: &str) -> Option<&Parameter> {
        self.parameters.iter().find(|p| same_name(&p.name, name))
    }

    /// Checks what the database requires of a check: a machine id and test-path labels that
    /// people can type (no control characters, no commas in labels, no blanks around them, at
    /// most [`MAX_LABEL_CHARS`] characters), at least one path, finite numbers.
    ///
    /// # Errors
    /// What is wrong, naming the field.
    pub fn validate(&self) -> Result<(), String> {
        label("machine id", &self.machine_id, false)?;
        if self.paths.is_empty() {
            return Err("a check needs at least one test path".into());
        }
        for p in &self.paths {
            label("test path", p, true)?;
        }
        let mut seen: Vec<String> = Vec::new();
        for p in &self.paths {
            let key = p.to_lowercase();
            if seen.contains(&key) {
                return Err(format!("test path `{p}` is given twice"));
            }
            seen.push(key);
        }
        let finite = |what: &str, x: f64| {
            if x.is_finite() {
                Ok(())
            } else {
                Err(format!("{what} is not finite ({x})"))
            }
        };
        finite("the residual RMS", self.residual_rms_um)?;
        for x in self.condition.iter().chain(&self.sigma_um) {
            finite("a fit statistic", *x)?;
        }
        for q in &self.parameters {
            for x in q.value.iter().chain(&q.std) {
                finite(&format!("parameter {}", q.name), *x)?;
            }
        }
        Ok(())
    }
}

/// Checks a machine id or a test-path label.
///
/// # Errors
/// What is wrong with it, naming `what`.
pub fn label(what: &str, text: &str, path: bool) -> Result<(), String> {
    if text.is_empty() {
        return Err(format!("the {what} is empty"));
    }
    if text.trim() != text {
        return Err(format!("the {what} `{text}` has blanks around it"));
    }
    if text.chars().any(char::is_control) {
        return Err(format!("the {what} {text:?} has a control character"));
    }
    if path && text.contains(',') {
        return Err(format!("the {what} `{text}` has a comma"));
    }
    if text.chars().count() > MAX_LABEL_CHARS {
        return Err(format!(
            "the {what} is longer than {MAX_LABEL_CHARS} characters"
        ));
    }
    Ok(())
}

/// Whether two parameter names are the same, as rtest reads names: without regard to case,
/// and with the digit-zero spelling of a three-character error name as an alias (`X0C` is
/// `XOC`), in the effect before any `@` or `[`.
pub fn same_name(a: &str, b: &str) -> bool {
    canonical_key(a) == canonical_key(b)
}

/// The form of a name that [`same_name`] compares.
pub fn canonical_key(name: &str) -> String {
    let split = name.find(['@', '[']).unwrap_or(name.len());
    let (effect, rest) = name.split_at(split);
    let mut effect: Vec<char> = effect.chars().flat_map(char::to_uppercase).collect();
    if effect.len() == 3 && effect[1] == '0' {
        effect[1] = 'O';
    }
    let mut key: String = effect.into_iter().collect();
    key.push_str(&rest.to_lowercase());
    key
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_compare_as_rtest_reads_them() {
        assert!(same_name("XOC", "x0c"));
        assert!(same_name("XOC", "xoc"));
        assert!(same_name("dx0", "DX0"));
        assert!(same_name("ECC@harmonic:2:cos", "ecc@HARMONIC:2:COS"));
        assert!(same_name("XOW[k4]", "x0w[K4]"));
        assert!(!same_name("XOC", "YOC"));
        assert!(!same_name("XOC", "XOC@time:1"));
        // dx0 is not a three-character ISO name with a middle zero: D X 0.
        assert!(!same_name("dx0", "dxo"));
    }

    #[test]
    fn labels() {
        assert!(label("machine id", "M123", false).is_ok());
        assert!(label("machine id", "M 123/B", false).is_ok());
        assert!(
            label("machine id", "", false)
                .unwrap_err()
                .contains("empty")
        );
        assert!(
            label("machine id", " M1", false)
                .unwrap_err()
                .contains("blanks")
        );
        assert!(
            label("machine id", "M\n1", false)
                .unwrap_err()
                .contains("control")
        );
        assert!(
            label("test path", "K1,K2", true)
                .unwrap_err()
                .contains("comma")
        );
        assert!(
            label("machine id", &"x".repeat(201), false)
                .unwrap_err()
                .contains("200")
        );
    }
}
