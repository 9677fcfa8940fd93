//! `rtest plan --probe`: a touch-probe kinematics calibration planned before measuring: the
//! probing poses per rotary axis, what they determine, the valuation numbers, and, with
//! `--per-axis auto`, the least number of positions that meets the targets
//! (docs/probe-plan.md).

use super::args;
use super::generator_args::GeneratorArgs;
use super::{Error, VerbResult, check_outputs, pose_args};
use crate::Done;
use fitting::plan::Targets;
use fitting::plan::probe::{
    Choice, MAX_PER_AXIS, MIN_PER_AXIS, ProbePlan, ProbePlanError, ProbePlanInputs, ProbeSetup,
    choose_per_axis, pattern_covariance,
};
use fitting::{Constraint, EstimateError, Tolerances};
use formats::csv::{ReadOptions, format_record};
use formats::paths::parse_path;
use formats::probe::read_probe_instrument;
use model_spec::Machine;
use model_spec::units::{UM_PER_MM, short};
use output::{Outputs, Target};
use report::json::plan_probe::{AutoSource, PlanProbeReport, PlanProbeSource, ProbeSource};
use report::json::to_json;
use std::path::{Path, PathBuf};

/// How many positions per rotary axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PerAxis {
    /// This many.
    Given(usize),
    /// The least that meets the targets.
    Auto,
}

/// `--per-axis`: a whole number from 3 to 12, or `auto`.
fn per_axis(s: &str) -> Result<PerAxis, String> {
    let t = s.trim();
    if t.eq_ignore_ascii_case("auto") {
        return Ok(PerAxis::Auto);
    }
    match t.parse::<usize>() {
        Ok(n) if (MIN_PER_AXIS..=MAX_PER_AXIS).contains(&n) => Ok(PerAxis::Given(n)),
        _ => Err(format!(
            "`{}` is neither a whole number from {MIN_PER_AXIS} to {MAX_PER_AXIS} nor `auto`",
            model_spec::text::quoted_start(s)
        )),
    }
}

/// The flags of `rtest plan` that only a probe plan takes.
#[derive(Debug, clap::Args)]
pub struct ProbeFlags {
    /// Plan a touch-probe calibration instead of R-test tests: the probe instrument file
    /// (TOML: tip_radius_mm, sphere_radius_mm, noise_um; docs/probe.md).
    #[arg(long, value_name = "FILE",
          conflicts_with_all = ["paths", "ball", "zeroed", "shared_setup", "noise_um",
                                "noise_phi", "target_ms", "ball_step_mm", "top", "step_deg",
                                "min_ball_height_mm"])]
    pub probe: Option<PathBuf>,
    /// With --probe: positions per rotary axis, 3 to 12, or `auto` (the least that gives every
    /// determined parameter of interest the valuation --min-valuation); default auto.
    #[arg(long, value_name = "N|auto", requires = "probe", value_parser = per_axis)]
    pub per_axis: Option<PerAxis>,
    /// With --probe: the least valuation number (target ÷ predicted std) `auto` asks of every
    /// determined parameter of interest; the controllers need 2, call 4 desirable.
    #[arg(long, value_name = "V", requires = "probe", value_parser = args::between(0.01, 1000.0))]
    pub min_valuation: Option<f64>,
    /// With --probe: parameters held at 0, `zero:NAME,...` (e.g. zero:XOC,ZOW): what one sphere
    /// position cannot separate.
    #[arg(long, value_name = "zero:NAME,...", requires = "probe")]
    pub constraint: Option<String>,
    /// With --probe: also write the planned poses as a path CSV (docs/paths.md), which
    /// `rtest simulate --path FILE [--probe PROBE]` takes; `-`: standard output.
    #[arg(long, value_name = "FILE", requires = "probe")]
    pub poses_out: Option<Target>,
}

impl ProbeFlags {
    /// Refuses the flags of a probe plan in a plan without --probe (clap's `requires` does not
    /// hold them once --paths, which conflicts with --probe, is given).
    ///
    /// # Errors
    /// A usage error naming the first such flag.
    pub fn refuse_without_probe(&self) -> VerbResult {
        let given = [
            ("--per-axis", self.per_axis.is_some()),
            ("--min-valuation", self.min_valuation.is_some()),
            ("--constraint", self.constraint.is_some()),
            ("--poses-out", self.poses_out.is_some()),
        ];
        match given.iter().find(|(_, g)| *g) {
            Some((flag, _)) if self.probe.is_none() => Err(Error::usage(format!(
                "{flag}: only with --probe (a touch-probe plan); an R-test plan (--paths) does not take it"
            ))),
            _ => Ok(()),
        }
    }
}

/// What a probe plan takes from the other flags of `rtest plan`.
#[derive(Clone, Copy, Debug)]
pub struct Common<'a> {
    /// `--machine`.
    pub machine: &'a str,
    /// `--model`.
    pub model: Option<&'a str>,
    /// `--terms`.
    pub terms: Option<&'a str>,
    /// `--param`.
    pub param: Option<&'a str>,
    /// `--target-um`, `--target-urad` (and the servo lags' default).
    pub targets: Targets,
    /// `--json`.
    pub json: Option<&'a Target>,
    /// `--max-tilt-deg`, `--period-s`.
    pub generator: &'a GeneratorArgs,
}

/// Runs `rtest plan --probe FILE`.
pub fn run(common: &Common<'_>, probe_file: &Path, flags: &ProbeFlags) -> VerbResult<Done> {
    let m = super::load_machine(common.machine)?;
    let (label, model) = args::model(&m, common.model, common.terms)?;
    fitting::plan::check_model(&m, &model).map_err(|e| {
        let flag = if common.terms.is_some() {
            "--terms"
        } else {
            "--model"
        };
        Error::usage(format!("{flag}: {e}"))
    })?;
    let constraint = match flags.constraint.as_deref() {
        None => Constraint::None,
        Some(text) => match args::constraint(Some(text)) {
            Ok(c @ (Constraint::Zero(_) | Constraint::None)) => c,
            Ok(Constraint::MinimumNorm) => {
                return Err(Error::usage(
                    "--constraint: min-norm gives values to what the poses do not determine, not uncertainties a plan can promise; hold parameters at 0 with zero:NAME,...",
                ));
            }
            Err(e) => return Err(e),
        },
    };
    let params = pose_args::params(&m, common.param)?;
    let options = common.generator.options()?;
    let instrument =
        read_probe_instrument(probe_file).map_err(|e| Error::input(format!("--probe: {e}")))?;
    let Some(noise_um) = instrument.noise_um else {
        return Err(Error::input(format!(
            "--probe: {}: the probe instrument declares no noise_um: the plan needs the probe's σ along the approach (its repeatability, µm) for the uncertainty of each pose's sphere fit",
            probe_file.display()
        )));
    };
    let mut inputs: Vec<(&str, &Path)> = vec![("--probe", probe_file)];
    inputs.extend(super::machine_file(common.machine).map(|p| ("--machine", p)));
    let mut outputs: Vec<(&str, &Target)> = Vec::new();
    outputs.extend(common.json.map(|t| ("--json", t)));
    outputs.extend(flags.poses_out.as_ref().map(|t| ("--poses-out", t)));
    check_outputs(&inputs, &outputs, &[])?;

    let probe = ProbeSetup {
        tip_radius_mm: instrument.tip_radius_mm,
        sphere_radius_mm: instrument.sphere_radius_mm,
        noise_mm: noise_um / UM_PER_MM,
    };
    let tol = Tolerances::default();
    let plan_inputs = ProbePlanInputs {
        machine: &m,
        model: &model,
        params: &params,
        clearance: &options.clearance,
        probe: &probe,
        constraint: &constraint,
        tol: &tol,
    };
    let fail = |e: ProbePlanError| plan_error(e, common, flags);
    let min_valuation = flags
        .min_valuation
        .unwrap_or(fitting::plan::probe::NEEDED_VALUATION);
    let (plan, choice): (ProbePlan, Option<Choice>) = match flags.per_axis.unwrap_or(PerAxis::Auto)
    {
        PerAxis::Given(n) => (plan_inputs.plan(n).map_err(fail)?, None),
        PerAxis::Auto => {
            let c = choose_per_axis(&plan_inputs, &common.targets, min_valuation).map_err(fail)?;
            (c.plan.clone(), Some(c))
        }
    };
    // The pattern's centre covariance in the probe's frame (the pattern turns with the probe).
    let pattern = pattern_covariance(&probe).map_err(fail)?;
    let source = PlanProbeSource {
        label: &label,
        base_model: common.model,
        model: &model,
        probe: ProbeSource {
            name: instrument.name.as_deref(),
            tip_radius_mm: probe.tip_radius_mm,
            sphere_radius_mm: probe.sphere_radius_mm,
            noise_mm: probe.noise_mm,
            centre_covariance_mm2: std::array::from_fn(|i| {
                std::array::from_fn(|j| pattern[(i, j)])
            }),
        },
        params: &params,
        plan: &plan,
        targets: &common.targets,
        min_valuation,
        auto: choice.as_ref().map(|c| AutoSource {
            met: c.met,
            tried: &c.tried,
            below: &c.below,
        }),
    };
    let report = PlanProbeReport::new(&m, source)
        .map_err(|e| Error::computation(format!("plan --probe: {e}")))?;
    let text = report::text::plan_probe::plan_probe(&report);
    let mut files = Outputs::new();
    if let Some(target) = common.json {
        let json = to_json(&report).map_err(|e| Error::computation(format!("--json: {e}")))?;
        files.add("--json", target.clone(), json);
    }
    if let Some(target) = &flags.poses_out {
        let csv = poses_csv(&m, &plan, &params, options.period_s, &target.to_string())?;
        files.add("--poses-out", target.clone(), csv);
    }
    let stdout_taken = matches!(common.json, Some(Target::Stdout))
        || matches!(flags.poses_out, Some(Target::Stdout));
    Ok(Done::new(text, files, stdout_taken))
}

/// A probe plan's error as a verb's error, naming the flag at fault.
fn plan_error(e: ProbePlanError, common: &Common<'_>, flags: &ProbeFlags) -> Error {
    let per_axis = match flags.per_axis {
        Some(PerAxis::Given(n)) => format!("--per-axis {n}"),
        _ => "--per-axis auto".to_string(),
    };
    match e {
        ProbePlanError::Probe(s) => Error::input(format!("--probe: {s}")),
        ProbePlanError::PerAxis(_) => Error::usage(format!("--per-axis: {e}")),
        ProbePlanError::NoRotaryAxis(_) => Error::usage(format!("--machine: {e}")),
        ProbePlanError::Generator(g) => Error::usage(format!("--param: {g}")),
        ProbePlanError::NoPose { .. } => {
            let flag = if common.param.is_some() {
                "--param"
            } else {
                "--probe"
            };
            Error::usage(format!(
                "{flag}: {e}: move the sphere (--param) nearer the rotary axes"
            ))
        }
        ProbePlanError::Estimate(e @ EstimateError::TooFewReadings { .. }) => Error::usage(
            format!("{per_axis}: the poses give too few readings for the model's parameters: {e}"),
        ),
        ProbePlanError::Estimate(e @ EstimateError::UnknownParameter(..)) => {
            let e = e.to_string();
            Error::usage(format!(
                "--constraint: {}",
                e.strip_prefix("constraint: ").unwrap_or(&e)
            ))
        }
        ProbePlanError::Estimate(e) => {
            Error::computation(format!("--probe: cannot predict the plan: {e}"))
        }
    }
}

/// The planned poses as a path CSV (the measurement format without readings: axis columns in
/// mm and degrees, `t_s` one `period_s` per pose), read back before it is written: the same
/// commands and times, bit for bit, within the strokes.
fn poses_csv(
    m: &Machine,
    plan: &ProbePlan,
    params: &[f64],
    period_s: f64,
    output: &str,
) -> VerbResult<String> {
    let mut record = plan.campaign.records[0].record.clone();
    record.covariance.clear();
    for (i, s) in record.samples.iter_mut().enumerate() {
        s.t = i as f64 * period_s;
    }
    let changed: Vec<String> = m
        .symbols
        .iter()
        .zip(params)
        .filter(|(s, x)| s.default != **x)
        .map(|(s, x)| format!("{} = {}", s.name, short(*x)))
        .collect();
    let labels: Vec<&str> = plan.poses.poses.iter().map(|p| p.label.as_str()).collect();
    let comments = vec![
        format!(
            "rtest plan --probe: {} probing poses of machine {}, {} positions per rotary axis",
            labels.len(),
            m.name,
            plan.poses.per_axis
        ),
        format!("poses, in order: {}", labels.join(", ")),
        format!(
            "kinematic parameters (mm): {}; the linear axes put the probe tip on the sphere's centre",
            if changed.is_empty() {
                "the description's defaults".to_string()
            } else {
                format!("the description's defaults but {}", changed.join(", "))
            }
        ),
        format!("{} s between poses; no readings", short(period_s)),
    ];
    let csv = format_record(m, &record, &comments)
        .map_err(|e| Error::computation(format!("--poses-out: {e}")))?;
    let mut read = ReadOptions::default();
    read.on_ball_tolerance_mm = f64::INFINITY;
    let back = parse_path(output, &csv, m, &read).map_err(|e| {
        Error::computation(format!(
            "--poses-out: the poses do not read back, so they are not written: {e}"
        ))
    })?;
    let same = back.samples.len() == record.samples.len()
        && back
            .samples
            .iter()
            .zip(&record.samples)
            .all(|(a, b)| a.commands == b.commands && a.t == b.t);
    if !same {
        return Err(Error::computation(
            "--poses-out: the poses do not read back to the same commands, so they are not written",
        ));
    }
    Ok(csv)
}
