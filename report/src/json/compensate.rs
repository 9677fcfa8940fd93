//! The compensation report (`rtest compensate --json`): what was compensated, what was left
//! out and why, and what the corrections came to per axis.
//!
//! Units: corrections of linear axes in µm, of rotary axes in µrad; remainders in µm and µrad;
//! line numbers 1-based in the input file.

use super::{NonFinite, finite};
use compensation::run::Summary;
use model_spec::units::{UM_PER_MM, URAD_PER_RAD};
use serde::{Deserialize, Serialize};

/// A corrected command put back on the stroke or range limit it passed by at most
/// `compensation::run::CLAMP_MARGIN` (0.01 mm or 0.01°).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClampedReport {
    /// The 1-based line of the pose.
    pub line: usize,
    /// The axis.
    pub axis: String,
    /// `mm` for a linear axis, `deg` for a rotary one.
    pub unit: String,
    /// The corrected command before it was clamped (mm or degrees).
    pub corrected: f64,
    /// The limit it was put on (mm or degrees).
    pub limit: f64,
}

impl ClampedReport {
    /// For people: `line 7: B = -0.002865° put on 0°`.
    pub fn for_people(&self) -> String {
        let unit = if self.unit == "deg" { "°" } else { " mm" };
        format!(
            "line {}: {} = {}{unit} put on {}{unit}",
            self.line,
            self.axis,
            model_spec::units::readable(self.corrected, 6),
            model_spec::units::format_scaled(self.limit + 0.0, 0)
        )
    }
}

/// The corrections of one axis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AxisReport {
    /// The axis.
    pub axis: String,
    /// `um` for a linear axis, `urad` for a rotary one.
    pub unit: String,
    /// The largest correction, signed.
    pub largest: f64,
    /// The line of the pose with the largest correction.
    pub largest_line: usize,
    /// The RMS of the corrections.
    pub rms: f64,
    /// The largest difference between the written and the computed corrected value (the
    /// resolution of the output format); `null` for a CSV, which holds the exact value.
    pub rounding: Option<f64>,
}

/// A term of the identification that was not compensated.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LeftOutReport {
    /// The term (`XOW`, `dx0@time:1`).
    pub term: String,
    /// Why.
    pub reason: String,
}

impl From<&compensation::values::LeftOut> for LeftOutReport {
    fn from(l: &compensation::values::LeftOut) -> LeftOutReport {
        LeftOutReport {
            term: l.term.clone(),
            reason: l.reason.clone(),
        }
    }
}

/// An error folded into the corrected kinematic description, or one that could not be.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct KinematicsReport {
    /// The file written.
    pub file: String,
    /// `ERROR → where` for each folded error.
    pub folded: Vec<String>,
    /// `ERROR: why` for each error not folded.
    pub not_folded: Vec<String>,
}

/// The tool-side length (the R-test holder's or the tool's: the offset of the tool chain's end
/// along the tool axis, `Zp`) that cannot be told from what is compensated
/// (`compensation::confounded::tool_length`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LengthReport {
    /// The length's kinematic symbol (`Zp`).
    pub symbol: String,
    /// `true` when the length is itself a term of the identification (its change is what
    /// cannot be told from the location errors in `with`, which the model does not hold).
    pub identified: bool,
    /// What it cannot be told from: the compensated errors or folded symbols (`ZOA`), or for
    /// an identified length the location errors the model lacks.
    pub with: Vec<String>,
    /// The warning for people, with the fix (the text prints it after `Warning: `).
    pub warning: String,
}

impl LengthReport {
    /// The report of `c`, with its warning.
    pub fn of(c: &compensation::confounded::LengthConfounded) -> LengthReport {
        let with = c.with.join(", ");
        let (s, end) = (&c.symbol, &c.end);
        let warning = if c.identified {
            format!(
                "The identified change of the {end}'s length {s} cannot be told from {with}, which the model does not hold: a location error of the pivot along the tool axis is taken for a change of the length, folded into {s}'s default, and lost when the length is set from a tool setter. Measure the length on a tool setter, give it with --param {s}=LENGTH (mm), and identify {with} instead of {s}."
            )
        } else {
            format!(
                "The {end}'s length {s} (the offset of the tool chain's end along the tool axis) cannot be told from {with}: {s} added to the identification's model does not raise the rank of its design. A holder or tool longer or shorter than the description says is identified as {with} and compensated as the machine's error, for every tool. Measure the length on a tool setter and give it with --param {s}=LENGTH (mm) when identifying and compensating."
            )
        };
        LengthReport {
            symbol: s.clone(),
            identified: c.identified,
            with: c.with.clone(),
            warning,
        }
    }
}

/// The compensation report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CompensationReport {
    /// Machine name.
    pub machine: String,
    /// The identification's model label.
    pub model: String,
    /// The identification report the values came from.
    pub params_file: String,
    /// The input file.
    pub input: String,
    /// The output file.
    pub output: String,
    /// `csv`, `iso` or `heidenhain`.
    pub format: String,
    /// The number of poses corrected.
    pub poses: usize,
    /// The machine errors compensated.
    pub compensated: Vec<String>,
    /// The terms left out.
    pub left_out: Vec<LeftOutReport>,
    /// Per axis, machine order.
    pub axes: Vec<AxisReport>,
    /// The largest predicted position remainder at a corrected pose, µm (below 0.001).
    pub position_remainder_um: f64,
    /// `true` when rotary axes corrected the orientation of the tool axis.
    pub orientation_corrected: bool,
    /// The largest predicted tilt of the tool axis that remains, µrad.
    pub tilt_remainder_urad: f64,
    /// The lines where the tilt could not be fully corrected (near a singular pose).
    pub tilt_uncorrected_lines: Vec<usize>,
    /// The largest predicted rotation about the tool axis, µrad: no axis removes it.
    pub roll_largest_urad: f64,
    /// Its RMS, µrad.
    pub roll_rms_urad: f64,
    /// Poses that needed host refinement steps after the generated code's fixed steps.
    pub refined_poses: usize,
    /// Corrected commands put back on a limit they passed by at most 0.01 mm or 0.01° (absent
    /// when there are none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub clamped: Vec<ClampedReport>,
    /// The corrected kinematic description, when one was written.
    pub kinematics: Option<KinematicsReport>,
    /// The axis compensation tables written.
    pub tables: Vec<String>,
    /// The tool-side length that cannot be told from what is compensated (absent when it can,
    /// or when the description has none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length_confounded: Option<LengthReport>,
}

/// Where a compensation report comes from, besides the summary.
#[derive(Clone, Debug, PartialEq)]
pub struct CompensationSource {
    /// Machine name.
    pub machine: String,
    /// The model label.
    pub model: String,
    /// The identification report.
    pub params_file: String,
    /// The input file.
    pub input: String,
    /// The output file.
    pub output: String,
    /// `csv`, `iso` or `heidenhain`.
    pub format: String,
    /// The errors compensated.
    pub compensated: Vec<String>,
    /// The terms left out.
    pub left_out: Vec<LeftOutReport>,
    /// Per axis, the largest rounding of the written values (mm or rad), for NC programs.
    pub rounding: Option<Vec<f64>>,
    /// The corrected kinematic description.
    pub kinematics: Option<KinematicsReport>,
    /// The tables written.
    pub tables: Vec<String>,
    /// The tool-side length that cannot be told from what is compensated.
    pub length_confounded: Option<LengthReport>,
}

impl CompensationSource {
    /// The source of a compensation of machine `m` with the errors `errors` of the model
    /// `model` read from `params_file`, `left_out` the terms it leaves out; the caller sets
    /// the input, output and format (and the rounding, description and tables it writes).
    pub fn of(
        m: &model_spec::Machine,
        model: &str,
        params_file: &str,
        errors: &compensation::values::MachineErrors,
        left_out: &[compensation::values::LeftOut],
    ) -> CompensationSource {
        CompensationSource {
            machine: m.name.clone(),
            model: model.to_string(),
            params_file: params_file.to_string(),
            input: String::new(),
            output: String::new(),
            format: String::new(),
            compensated: errors
                .errors()
                .iter()
                .map(|&e| m.catalogue[e].name.clone())
                .collect(),
            left_out: left_out.iter().map(LeftOutReport::from).collect(),
            rounding: None,
            kinematics: None,
            tables: Vec::new(),
            length_confounded: None,
        }
    }
}

impl CompensationReport {
    /// The report of a compensated file.
    ///
    /// # Errors
    /// [`NonFinite`] when a figure is not finite (a failed computation).
    pub fn new(source: CompensationSource, s: &Summary) -> Result<CompensationReport, NonFinite> {
        let axes = s
            .axes
            .iter()
            .enumerate()
            .map(|(i, a)| {
                let (unit, k) = if a.rotary {
                    ("urad", URAD_PER_RAD)
                } else {
                    ("um", UM_PER_MM)
                };
                Ok(AxisReport {
                    axis: a.axis.clone(),
                    unit: unit.to_string(),
                    largest: finite(|| format!("axes[{i}].largest"), a.largest * k)?,
                    largest_line: a.largest_line,
                    rms: finite(|| format!("axes[{i}].rms"), a.rms * k)?,
                    rounding: match &source.rounding {
                        Some(r) => Some(finite(|| format!("axes[{i}].rounding"), r[i] * k)?),
                        None => None,
                    },
                })
            })
            .collect::<Result<Vec<_>, NonFinite>>()?;
        Ok(CompensationReport {
            machine: source.machine,
            model: source.model,
            params_file: source.params_file,
            input: source.input,
            output: source.output,
            format: source.format,
            poses: s.poses,
            compensated: source.compensated,
            left_out: source.left_out,
            axes,
            position_remainder_um: finite(
                || "position_remainder_um".into(),
                s.position_remainder * UM_PER_MM,
            )?,
            orientation_corrected: s.orientation_corrected,
            tilt_remainder_urad: finite(
                || "tilt_remainder_urad".into(),
                s.tilt_remainder * URAD_PER_RAD,
            )?,
            tilt_uncorrected_lines: s.tilt_uncorrected.clone(),
            roll_largest_urad: finite(
                || "roll_largest_urad".into(),
                s.roll_largest * URAD_PER_RAD,
            )?,
            roll_rms_urad: finite(|| "roll_rms_urad".into(), s.roll_rms * URAD_PER_RAD)?,
            refined_poses: s.refined,
            clamped: s
                .clamped
                .iter()
                .map(|c| ClampedReport {
                    line: c.line,
                    axis: c.axis.clone(),
                    unit: if c.rotary { "deg" } else { "mm" }.to_string(),
                    corrected: c.corrected,
                    limit: c.limit,
                })
                .collect(),
            kinematics: source.kinematics,
            tables: source.tables,
            length_confounded: source.length_confounded,
        })
    }
}
