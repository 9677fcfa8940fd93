//! `rtest plan`: what a planned campaign of R-test tests will determine, before measuring, and
//! the single added test or ball position that would help most.

use super::args::{self, items, positive};
use super::{EXIT_CODES, Error, VerbResult, check_outputs, pose_args};
use crate::Done;
use fitting::EstimateError;
use fitting::Tolerances;
use fitting::noise::{MAX_PHI, NoiseModel, NoiseSource};
use fitting::plan::{
    self, BASE_BALL, BallPosition, Plan, PlanError, PlannedTest, Targets, candidates,
    suggest_with_progress,
};
use model_spec::Machine;
use model_spec::text::quoted_start;
use model_spec::units::{UM_PER_MM, compact};
use output::{Outputs, Target};
use report::json::plan::{PlanReport, PlanSource};
use report::json::to_json;
use simulation::generator::{GeneratorError, SampleProblem};

const LONG_ABOUT: &str = "\
Predicts, before measuring, what a campaign of R-test tests will determine: the rank and the \
condition number of its design matrix, the groups of parameters it cannot separate, and the \
predicted standard uncertainty (µm, µrad; ms for servo lags) of every parameter it determines, for \
a reading noise of --noise-um per direction (white, or AR(1) with --noise-phi); none for what it \
cannot determine. Then it suggests the single added test or ball position that helps most, and \
ranks the candidates. Details: docs/plan.md.

The plan: --paths lists tests of the machine's generator (`rtest path --list`), each generated \
with the linear axes following the ball at the kinematic parameters of --param (mm; the ball \
position `base`) and checked against the strokes, the ranges and the clearance rule. `TEST:NAME` \
puts a test at the ball position NAME of --ball NAME:SYMBOL=VALUE,... (mm), e.g. --ball \
high:Zw=260 --paths K4,K4:high. Each record has its own ball set-up (XOW YOW ZOW) unless \
--shared-setup; with --zeroed its own R-test zero (dx0 dy0 dz0).

The suggestion: every test at every planned ball position and at each moved by --ball-step-mm (mm) \
along each of the ball's symbols, added on its own, ranked by the parameters of interest (the \
machine's) newly determined, then the largest std/target (--target-um, --target-urad, \
--target-ms), then the sum of (std/target)^2; --top sets how many are shown. Where a position term \
and a time term correlate by 0.9 or more, it names the reversed (T-rev) or there-and-back (T-back) \
test that separates them.

--json FILE writes the report (`-`: standard output; `null` where the plan determines no value).

--probe FILE plans a touch-probe calibration: each rotary axis at --per-axis N|auto positions, \
valuation numbers (target / std), --poses-out FILE for `path --probe`. Details: docs/probe-plan.md.";

/// Flags of `rtest plan`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Predict what a planned campaign of tests will determine, and what to add",
    long_about = LONG_ABOUT,
    after_help = EXIT_CODES
)]
pub struct PlanArgs {
    /// Built-in machine (see `rtest machines`) or path of a machine TOML file.
    #[arg(long, value_name = "NAME|FILE")]
    machine: String,
    /// Model of the machine (`reduced`, `full`, …); required unless --terms is given.
    #[arg(long, value_name = "NAME")]
    model: Option<String>,
    /// Terms added to --model or alone: comma list of NAME or NAME@BASIS.
    #[arg(long, value_name = "LIST")]
    terms: Option<String>,
    /// The planned tests, in order: comma list of TEST (at the `base` ball position) or
    /// TEST:NAME (at the ball position NAME of --ball), e.g. `K4,K1,K4:high`.
    #[arg(long, value_name = "LIST", required_unless_present = "probe")]
    paths: Option<String>,
    /// Kinematic parameters (mm) of the `base` ball position, overriding the machine's
    /// defaults (`Xw=-200,Zw=180`).
    #[arg(long, value_name = "SYMBOL=VALUE,...")]
    param: Option<String>,
    /// A named ball position: NAME:SYMBOL=VALUE,... (mm; other symbols as `base`). Repeat for
    /// several.
    #[arg(long, value_name = "NAME:SYMBOL=VALUE,...")]
    ball: Vec<String>,
    /// The readings will be zeroed at each record's first sample: every record's dx0 dy0 dz0
    /// join the fit.
    #[arg(long)]
    zeroed: bool,
    /// Records at one ball position share one ball set-up (one XOW YOW ZOW).
    #[arg(long)]
    shared_setup: bool,
    /// Standard deviation of one reading, per direction, µm.
    #[arg(long, value_name = "UM", default_value = "0.5", value_parser = positive)]
    noise_um: f64,
    /// Lag-1 autocorrelation of the reading noise (AR(1); 0: white), 0 ≤ F < 0.99.
    #[arg(long, value_name = "F", default_value = "0", value_parser = phi)]
    noise_phi: f64,
    /// Target uncertainty of translational parameters, µm (1e-6 to 1e6).
    #[arg(long, value_name = "UM", default_value = "1", value_parser = args::between(1e-6, 1e6))]
    target_um: f64,
    /// Target uncertainty of angular parameters, µrad (1e-6 to 1e6).
    #[arg(long, value_name = "URAD", default_value = "5", value_parser = args::between(1e-6, 1e6))]
    target_urad: f64,
    /// Target uncertainty of servo lags (velocity terms), ms (1e-6 to 1e6).
    #[arg(long, value_name = "MS", default_value = "0.1", value_parser = args::between(1e-6, 1e6))]
    target_ms: f64,
    /// The step by which the candidate ball positions are moved from the planned ones, mm.
    #[arg(long, value_name = "MM", default_value = "100", value_parser = positive)]
    ball_step_mm: f64,
    /// Candidates shown in the ranking.
    #[arg(long, value_name = "N", default_value_t = 5,
          value_parser = clap::value_parser!(u64).range(1..=10_000))]
    top: u64,
    #[command(flatten)]
    generator: super::generator_args::GeneratorArgs,
    /// Also write the report as JSON to FILE (`-`: standard output).
    #[arg(long, value_name = "FILE")]
    json: Option<Target>,
    #[command(flatten)]
    probe: super::plan_probe::ProbeFlags,
}

/// A lag-1 autocorrelation: a number from 0 up to, not including, 0.99.
fn phi(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if (0.0..MAX_PHI).contains(&x) => Ok(x),
        _ => Err(format!(
            "`{s}` is not a lag-1 autocorrelation from 0 up to (not including) {MAX_PHI}"
        )),
    }
}

/// One `--ball NAME:SYMBOL=VALUE,...`: its name and parameters (`base` overridden).
fn ball(m: &Machine, text: &str, base: &[f64]) -> VerbResult<BallPosition> {
    let example = "expected NAME:SYMBOL=VALUE,..., e.g. high:Zw=260";
    let Some((name, list)) = text.split_once(':') else {
        return Err(Error::usage(format!(
            "--ball: `{}` has no `:` ({example})",
            quoted_start(text)
        )));
    };
    let name = name.trim();
    if name == BASE_BALL || !plan::valid_ball_name(name) {
        return Err(Error::usage(format!(
            "--ball: `{}` is not a ball position name: a letter, then letters, digits, `_`, `-`, `.` or `+`, at most {} characters, and not `{BASE_BALL}` (the position of --param)",
            quoted_start(name),
            plan::MAX_BALL_NAME_CHARS
        )));
    }
    let flag = format!("--ball {name}");
    let mut params = base.to_vec();
    pose_args::override_params(m, &flag, list, &mut params)?;
    Ok(BallPosition {
        name: name.to_string(),
        params,
    })
}

/// The plan of the flags.
fn plan_of(m: &Machine, args: &PlanArgs) -> VerbResult<Plan> {
    let base = pose_args::params(m, args.param.as_deref())?;
    let mut balls = vec![BallPosition {
        name: BASE_BALL.to_string(),
        params: base.clone(),
    }];
    for text in &args.ball {
        let b = ball(m, text, &base)?;
        if balls.iter().any(|o| o.name == b.name) {
            return Err(Error::usage(format!(
                "--ball: `{}` is given twice",
                quoted_start(&b.name)
            )));
        }
        balls.push(b);
    }
    let mut tests = Vec::new();
    let example = "expected a comma list of TEST or TEST:BALL, e.g. K4,K1,K4:high";
    // The number of tests is checked with the plan's shape (`Plan::check`), before any work.
    let paths = args.paths.as_deref().unwrap_or_default();
    for item in items("--paths", paths, example)? {
        let (test, name) = item.split_once(':').unwrap_or((item, BASE_BALL));
        let (test, name) = (test.trim(), name.trim());
        let Some(b) = balls.iter().position(|b| b.name == name) else {
            let named: Vec<&str> = balls[1..].iter().map(|b| b.name.as_str()).collect();
            return Err(Error::usage(format!(
                "--paths: `{}`: no ball position `{}` (define it with --ball {}:SYMBOL=VALUE,...; defined: {})",
                quoted_start(item),
                quoted_start(name),
                quoted_start(name),
                if named.is_empty() {
                    "none".to_string()
                } else {
                    named.join(", ")
                }
            )));
        };
        tests.push(PlannedTest {
            test: test.to_string(),
            ball: b,
        });
    }
    if let Some(unused) = (1..balls.len()).find(|&b| !tests.iter().any(|t| t.ball == b)) {
        return Err(Error::usage(format!(
            "--ball {}: no test of --paths is at this position (write TEST:{} in --paths)",
            balls[unused].name, balls[unused].name
        )));
    }
    Ok(Plan {
        balls,
        tests,
        zeroed: args.zeroed,
        shared_setup: args.shared_setup,
        generator: args.generator.options()?,
    })
}

/// A plan error as a verb's error, naming the flag at fault: usage errors for what the command
/// line asks (an unknown test, a ball position that puts a test out of a stroke or beyond the
/// clearance rule), a bad input where the machine cannot follow the ball, a failed computation
/// otherwise.
fn plan_error(e: PlanError, args: &PlanArgs) -> Error {
    match e {
        PlanError::Plan(s) => Error::usage(format!("--paths: {s}")),
        PlanError::Generator { test, ball, error } => {
            let ball_flag = if ball != BASE_BALL {
                format!("--ball {ball}")
            } else if args.param.is_some() {
                "--param".to_string()
            } else {
                "--paths".to_string()
            };
            let at = format!("{test} at ball position `{ball}`");
            match &error {
                GeneratorError::UnknownTest { .. } | GeneratorError::NoRotaryAxis { .. } => {
                    Error::usage(format!("--paths: {error}"))
                }
                GeneratorError::NoRoom { .. } | GeneratorError::TooManySamples { .. } => {
                    Error::usage(format!("--paths: {at}: {error}"))
                }
                GeneratorError::Option { .. } => Error::usage(format!("--paths: {error}")),
                GeneratorError::ParamCount { .. } | GeneratorError::Param { .. } => {
                    Error::usage(format!("{ball_flag}: {at}: {error}"))
                }
                GeneratorError::BallTooLow { .. } => Error::usage(format!(
                    "{ball_flag}: {at}: {error} (or set --min-ball-height-mm to your nest's reach)"
                )),
                GeneratorError::Sample(s) => match s.problem {
                    SampleProblem::Limits(_) => Error::usage(format!(
                        "{ball_flag}: {at}: {error}: the linear axes follow the ball; a ball nearer the rotary axes keeps them within their strokes"
                    )),
                    SampleProblem::Tilt { .. } => Error::usage(format!("--paths: {at}: {error}")),
                    SampleProblem::Ik(_) => Error::input(format!("--machine: {at}: {error}")),
                    SampleProblem::OffBall { .. } | SampleProblem::NotFinite(_) => {
                        Error::computation(format!("--paths: {at}: {error}"))
                    }
                },
            }
        }
        PlanError::Estimate(e @ EstimateError::TooFewReadings { .. }) => Error::usage(format!(
            "--paths: the plan has too few samples for its parameters: {e}"
        )),
        PlanError::Estimate(e) => {
            Error::computation(format!("--paths: cannot predict the plan: {e}"))
        }
    }
}

/// Runs `rtest plan` (`--probe`: a touch-probe plan, [`super::plan_probe`]).
pub fn run(args: &PlanArgs) -> VerbResult<Done> {
    if let Some(file) = &args.probe.probe {
        let common = super::plan_probe::Common {
            machine: &args.machine,
            model: args.model.as_deref(),
            terms: args.terms.as_deref(),
            param: args.param.as_deref(),
            targets: Targets {
                um: args.target_um,
                urad: args.target_urad,
                ms: args.target_ms,
            },
            json: args.json.as_ref(),
            generator: &args.generator,
        };
        return super::plan_probe::run(&common, file, &args.probe);
    }
    args.probe.refuse_without_probe()?;
    let m = super::load_machine(&args.machine)?;
    let (label, model) = args::model(&m, args.model.as_deref(), args.terms.as_deref())?;
    plan::check_model(&m, &model).map_err(|e| {
        let flag = if args.terms.is_some() {
            "--terms"
        } else {
            "--model"
        };
        Error::usage(format!("{flag}: {e}"))
    })?;
    if args.noise_um > simulation::truth::MAX_NOISE_UM {
        return Err(Error::usage(format!(
            "--noise-um: {} µm is beyond {} µm, the largest reading noise rtest takes",
            compact(args.noise_um),
            simulation::truth::MAX_NOISE_UM
        )));
    }
    let plan = plan_of(&m, args)?;
    let inputs: Vec<_> = super::machine_file(&args.machine)
        .map(|p| ("--machine", p))
        .into_iter()
        .collect();
    let outputs: Vec<(&str, &Target)> = args.json.iter().map(|t| ("--json", t)).collect();
    check_outputs(&inputs, &outputs, &[])?;
    let fail = |e: PlanError| plan_error(e, args);
    let sigma_mm = args.noise_um / UM_PER_MM;
    let noise = if args.noise_phi == 0.0 {
        NoiseModel::white(sigma_mm, NoiseSource::Declared)
    } else {
        NoiseModel::ar1(args.noise_phi, sigma_mm, NoiseSource::Declared)
    };
    let tol = Tolerances::default();
    // The candidates first: their number is bounded (`MAX_CANDIDATES`) before any prediction.
    let set = candidates::candidates(&m, &plan, args.ball_step_mm).map_err(fail)?;
    let predicted = plan.predict(&m, &model, &noise, &tol).map_err(fail)?;
    let targets = Targets {
        um: args.target_um,
        urad: args.target_urad,
        ms: args.target_ms,
    };
    // A progress bar on a terminal's standard error, unless the JSON report takes standard
    // output.
    let bar = super::progress::Bar::new(
        super::progress::wanted(matches!(args.json, Some(Target::Stdout))),
        false,
    );
    let suggestion =
        suggest_with_progress(&m, &model, &plan, &predicted, &set, &targets, &tol, &bar);
    drop(bar);
    let suggestion = suggestion.map_err(fail)?;
    let separation =
        plan::separate::separation(&m, &model, &plan, &predicted.prediction, &set, &noise, &tol)
            .map_err(fail)?;
    let source = PlanSource {
        label: &label,
        base_model: args.model.as_deref(),
        model: &model,
        plan: &plan,
        planned: &predicted.planned,
        prediction: &predicted.prediction,
        candidates: &set,
        suggestion: &suggestion,
        targets: &targets,
        separation: separation.as_ref(),
    };
    let report =
        PlanReport::new(&m, source).map_err(|e| Error::computation(format!("plan: {e}")))?;
    let text = report::text::plan::plan(&report, args.top as usize);
    let mut files = Outputs::new();
    if let Some(target) = &args.json {
        let json = to_json(&report).map_err(|e| Error::computation(format!("--json: {e}")))?;
        files.add("--json", target.clone(), json);
    }
    let stdout_taken = matches!(args.json, Some(Target::Stdout));
    Ok(Done::new(text, files, stdout_taken))
}

#[cfg(test)]
#[path = "plan_fuzz.rs"]
mod fuzz;
