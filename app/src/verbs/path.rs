//! `rtest path`: the R-test tests of a machine, listed or generated as a path CSV.
//!
//! The record of poses is computed in one function ([`poses`]), written in another
//! ([`csv_text`]), so that other formats of the same poses are one more writer.

use super::generator_args::option_flag;
use super::{EXIT_CODES, Error, VerbResult, check_outputs, pose_args};
use crate::Done;
use formats::csv::{ReadOptions, format_record};
use formats::paths::parse_path;
use model_spec::units::short;
use model_spec::{AxisKind, Machine};
use output::{Outputs, Target};
use simulation::generator::{
    self, GeneratorError, GeneratorOptions, Order, SampleProblem, TestKind, TestSpec,
};
use simulation::record::Record;

const LONG_ABOUT: &str = "\
The R-test tests of a machine, in the spirit of ISO 10791-6: `turn-R` for every rotary axis R (a \
full turn where its range allows, the other rotary axes at 0°), `pair-R-S` for every two rotary \
axes (the primary turns, the secondary follows base + a·(1 − cos φ)), and on machines whose rotary \
axes are A and C the seed's K1, K2, K4. Every test T also comes reversed, T-rev, and there and \
back in one record, T-back. Details: docs/paths.md.

--list: the machine's tests, one line each (with --param: whether each stays within the strokes at \
that ball position). --test NAME -o FILE: the test's path as a CSV in the measurement format \
without readings (axis columns in mm and degrees, t_s in s). The linear axes follow the ball by \
the nominal inverse kinematics at the kinematic parameters (the description's defaults, overridden \
by --param, mm: the ball position is Xw=…,Yw=…,Zw=… on most machines).

Every sample is checked: within the strokes and ranges, the nest on the ball, the tool axis within \
--max-tilt-deg (90°) of the table normal, the ball centre at least --min-ball-height-mm (30 mm) \
above the table face. A test that breaks a check is an error naming the first sample, the axis and \
the limit; nothing is clipped.

--nc iso|linuxcnc|heidenhain -o prog.nc: an NC measurement program of the test instead of the CSV, \
static or --continuous, and its sample-timing plan (CSV, --plan) that `rtest segment` cuts a streamed \
log with (docs/measurement-programs.md). In machine coordinates (iso: G53 and a zeroed G54; \
linuxcnc: G53; heidenhain: M91) it goes to --clearance-mm, turns the rotary axes there, M19, \
approaches the first pose along the tool axis (--approach-mm), stops (M0) for the nest check, \
measures, retracts; its header lists the checks in that order. `rtest simulate --path NAME` takes \
the same test names. `-o -` writes to standard output. --probe PROBE.toml: a touch-probe program \
and its probe plan instead (docs/probe-programs.md).";

/// Flags of `rtest path`.
#[derive(Debug, clap::Args)]
#[command(
    about = "R-test tests of any machine: list them, or write one as a path CSV",
    long_about = LONG_ABOUT,
    after_help = EXIT_CODES
)]
pub struct PathArgs {
    /// Built-in machine (see `rtest machines`) or path of a machine TOML file.
    #[arg(long, value_name = "NAME|FILE")]
    machine: String,
    /// List the machine's tests instead of writing one.
    #[arg(long, conflicts_with_all = ["test", "output", "step_deg", "period_s"])]
    list: bool,
    /// The test to write (`turn-C`, `pair-A-C`, `K4`; see --list), any case; with --probe also
    /// a path CSV of poses (as `rtest plan --probe --poses-out` writes them).
    #[arg(
        long,
        value_name = "NAME|FILE",
        required_unless_present = "list",
        requires = "output"
    )]
    pub(super) test: Option<String>,
    /// Kinematic parameters (mm) overriding the machine's defaults, the ball position among
    /// them (`Xw=-200,Zw=180`).
    #[arg(long, value_name = "SYMBOL=VALUE,...")]
    param: Option<String>,
    #[command(flatten)]
    generator: super::generator_args::GeneratorArgs,
    /// With --list: the list as JSON to FILE (`-`: standard output).
    #[arg(long, value_name = "FILE", requires = "list")]
    json: Option<Target>,
    /// The path CSV to write, or with --nc the NC program (`-`: standard output).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Option<Target>,
    #[command(flatten)]
    nc: super::path_nc::NcArgs,
    #[command(flatten)]
    probe: super::path_probe::ProbeArgs,
}

/// A generator error as a verb's error, naming the flag at fault: a usage error for what the
/// command line asks (an unknown test, an option out of its domain, a ball position that puts
/// a test out of its limits), a bad input where the machine cannot follow the ball, a failed
/// computation otherwise.
fn generator_error(e: &GeneratorError, args: &PathArgs) -> Error {
    let ball_flag = if args.param.is_some() {
        "--param"
    } else {
        "--test"
    };
    match e {
        GeneratorError::Option { option, .. } => {
            Error::usage(format!("{}: {e}", option_flag(option)))
        }
        GeneratorError::NoRotaryAxis { .. }
        | GeneratorError::UnknownTest { .. }
        | GeneratorError::NoRoom { .. }
        | GeneratorError::TooManySamples { .. } => Error::usage(format!("--test: {e}")),
        GeneratorError::ParamCount { .. } | GeneratorError::Param { .. } => {
            Error::usage(format!("--param: {e}"))
        }
        GeneratorError::BallTooLow { .. } => {
            let flag = if args.param.is_some() {
                "--param"
            } else {
                "--min-ball-height-mm"
            };
            Error::usage(format!(
                "{flag}: {e} (or set --min-ball-height-mm to your nest's reach)"
            ))
        }
        GeneratorError::Sample(s) => match s.problem {
            SampleProblem::Limits(_) => Error::usage(format!(
                "{ball_flag}: {e}: the linear axes follow the ball; a ball nearer the rotary axes keeps them within their strokes"
            )),
            SampleProblem::Tilt { .. } => Error::usage(format!("--test: {e}")),
            SampleProblem::Ik(_) => Error::input(format!("--machine: {e}")),
            SampleProblem::OffBall { .. } | SampleProblem::NotFinite(_) => {
                Error::computation(format!("--test: {e}"))
            }
        },
    }
}

/// The test asked for and its record of poses: commands in mm and rad, times in s, every
/// sample checked by the generator.
pub fn poses(
    args: &PathArgs,
    m: &Machine,
    params: &[f64],
    opts: &GeneratorOptions,
) -> VerbResult<(TestSpec, Record)> {
    let name = args.test.as_deref().unwrap_or_default();
    let all = generator::tests_with(m, &opts.clearance);
    let unknown = || GeneratorError::UnknownTest {
        machine: m.name.clone(),
        name: name.trim().to_string(),
        tests: all.iter().map(|t| t.name.clone()).collect(),
    };
    let spec = match generator::lookup_test(&all, name) {
        Some(s) => s,
        None if all.is_empty() => {
            return Err(generator_error(
                &GeneratorError::NoRotaryAxis {
                    machine: m.name.clone(),
                },
                args,
            ));
        }
        None => return Err(generator_error(&unknown(), args)),
    };
    let record =
        generator::generate_test(m, &spec, params, opts).map_err(|e| generator_error(&e, args))?;
    Ok((spec, record))
}

/// The kinematic parameters that differ from the description's defaults (`Xw=-200, Zw=180`),
/// or `None`.
fn changed_params(m: &Machine, params: &[f64]) -> Option<String> {
    let changed: Vec<String> = m
        .symbols
        .iter()
        .zip(params)
        .filter(|(s, x)| s.default.to_bits() != x.to_bits())
        .map(|(s, &x)| format!("{}={}", s.name, model_spec::units::format_scaled(x, 0)))
        .collect();
    (!changed.is_empty()).then(|| changed.join(", "))
}

/// The CSV of `record` (test `spec` of `m` at `params`, generated with `opts`), read back
/// before it is written: the same poses and times, bit for bit, within the strokes.
pub fn csv_text(
    m: &Machine,
    spec: &TestSpec,
    record: &Record,
    params: &[f64],
    opts: &GeneratorOptions,
    output: &str,
) -> VerbResult<String> {
    let mut comments = vec![
        format!("rtest path: test {} of machine {}", spec.name, m.name),
        spec.description.clone(),
        format!(
            "kinematic parameters (mm): {}",
            changed_params(m, params).map_or("the description's defaults".into(), |c| format!(
                "the description's defaults but {c}"
            ))
        ),
        format!(
            "clearance: tool axis within {}° of the table normal, ball at least {} mm above the table",
            short(opts.clearance.max_tilt_deg),
            short(opts.clearance.min_ball_height_mm)
        ),
    ];
    comments.push(format!(
        "{} samples, {} s apart; no readings",
        record.samples.len(),
        short(opts.period_s)
    ));
    let csv =
        format_record(m, record, &comments).map_err(|e| Error::computation(format!("-o: {e}")))?;
    // The nest is on the ball at `params` (checked by the generator); the reader checks it at
    // the defaults, so that check is left to the generator here.
    let mut read = ReadOptions::default();
    read.on_ball_tolerance_mm = f64::INFINITY;
    let back = parse_path(output, &csv, m, &read).map_err(|e| {
        Error::computation(format!(
            "-o: the path does not read back, so it is not written: {e}"
        ))
    })?;
    if back != *record {
        return Err(Error::computation(
            "-o: the path does not read back to the same poses, so it is not written",
        ));
    }
    Ok(csv)
}

/// The range of every axis over `record`, for people: `X -0.3 .. 12 mm`, `C 0 .. 360°`.
fn extents(m: &Machine, record: &Record) -> String {
    let mut order: Vec<usize> = (0..m.axes.len()).collect();
    order.sort_by_key(|&a| {
        let kind = m.axes[a].kind == AxisKind::Rotary;
        (kind, model_spec::catalogue::iso_rank(&m.axes[a].name))
    });
    order
        .iter()
        .map(|&a| {
            let ax = &m.axes[a];
            let rotary = ax.kind == AxisKind::Rotary;
            let shown = |q: f64| if rotary { q.to_degrees() } else { q };
            let (lo, hi) = record
                .samples
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), s| {
                    (l.min(shown(s.commands[a])), h.max(shown(s.commands[a])))
                });
            let (unit, what) = if rotary {
                ("°", "range")
            } else {
                (" mm", "stroke")
            };
            let [l, h] = ax.limits;
            let limits = if l.is_finite() {
                format!(" ({what} {} .. {}{unit})", short(l), short(h))
            } else {
                String::new()
            };
            format!(
                "  {} {} .. {}{unit}{limits}\n",
                ax.name,
                short(lo),
                short(hi)
            )
        })
        .collect()
}

/// Runs `rtest path`.
pub fn run(args: &PathArgs) -> VerbResult<Done> {
    let m = super::load_machine(&args.machine)?;
    if args.probe.probe.is_some() {
        let parts = super::path_probe::PathParts {
            machine_arg: &args.machine,
            param: args.param.as_deref(),
            generator: &args.generator,
            output: args.output.as_ref(),
        };
        return super::path_probe::run(args, &m, parts, &args.probe, &args.nc);
    }
    let mut inputs = Vec::new();
    inputs.extend(super::machine_file(&args.machine).map(|p| ("--machine", p)));
    let dialect = args.nc.dialect()?;
    let plan_target = match (&dialect, &args.output) {
        (Some(_), Some(program)) => Some(args.nc.plan_target(program)?),
        _ => None,
    };
    let outputs: Vec<(&str, &Target)> = [
        ("-o", args.output.as_ref()),
        ("--json", args.json.as_ref()),
        ("--plan", plan_target.as_ref()),
    ]
    .into_iter()
    .filter_map(|(f, t)| t.map(|t| (f, t)))
    .collect();
    check_outputs(&inputs, &outputs, &[])?;
    let params = pose_args::params(&m, args.param.as_deref())?;
    let opts = args.generator.options()?;
    if args.list {
        return list(args.json.as_ref(), &m, &params, &opts);
    }
    let (spec, record) = poses(args, &m, &params, &opts)?;
    let target = args.output.as_ref().expect("clap requires -o with --test");
    let mut files = Outputs::new();
    let mut program_note = String::new();
    match (dialect, plan_target) {
        (Some(d), Some(plan_target)) => {
            let (program, plan, note) =
                super::path_nc::program(&args.nc, d, &m, &spec.name, &record, &params)?;
            files.add("-o", target.clone(), program);
            files.add("--plan", plan_target, plan);
            program_note = note;
        }
        _ => {
            let csv = csv_text(&m, &spec, &record, &params, &opts, &target.to_string())?;
            files.add("-o", target.clone(), csv);
        }
    }
    let mut text = format!(
        "Test {} of machine {}: {} samples.\n  {}\n",
        spec.name,
        m.name,
        record.samples.len(),
        spec.description
    );
    text += &extents(&m, &record);
    text += &program_note;
    if let Some(c) = changed_params(&m, &params) {
        text +=
            &format!("Kinematic parameters changed from the description's defaults: {c} (mm).\n");
        text += &off_default_note(&m, &record);
    }
    if spec.kind == TestKind::Seed {
        text += "The seed's angles are fixed: --max-tilt-deg does not shape them, it only checks them.\n";
    }
    Ok(Done::new(text, files, matches!(target, Target::Stdout)))
}

/// A note when the path's nest is off the ball at the description's default parameters by more
/// than the readers accept: `simulate`, `identify` and the other readers check the nest on the
/// ball at the defaults.
fn off_default_note(m: &Machine, record: &Record) -> String {
    let vm = simulation::VirtualMachine::new(m);
    let defaults = m.default_parameters();
    let worst = record
        .samples
        .iter()
        .map(|s| {
            vm.nominal_error_vector(&s.commands, &defaults)
                .position
                .norm()
        })
        .fold(0.0, f64::max);
    let tol = simulation::pose::ON_BALL_TOLERANCE_MM;
    if worst > tol {
        format!(
            "Note: at the description's default parameters this path leaves the nest up to {} mm off the ball, beyond the {} mm the measurement readers accept: give the same --param to `simulate` and `identify` (or `params` to the record in a campaign file), which then read it at that ball position.\n",
            short(worst),
            short(tol)
        )
    } else {
        String::new()
    }
}

/// `--list`: the tests of `m` under `opts`, each with whether it is generated within the limits
/// at `params`; as text on standard output, or as JSON to `json`.
fn list(
    json: Option<&Target>,
    m: &Machine,
    params: &[f64],
    opts: &GeneratorOptions,
) -> VerbResult<Done> {
    let tests = generator::tests_with_orders(m, &opts.clearance);
    let status: Vec<Option<String>> = tests
        .iter()
        .map(|t| {
            generator::generate_test(m, t, params, opts)
                .err()
                .map(|e| e.to_string())
        })
        .collect();
    if let Some(target) = json {
        let entries: Vec<serde_json::Value> = tests
            .iter()
            .zip(&status)
            .map(|(t, error)| {
                let sw = &t.sweep;
                let n = generator::sweep::steps(sw.span_deg(), sw.default_step_deg);
                serde_json::json!({
                    "name": t.name,
                    "description": t.description,
                    "kind": match t.kind {
                        TestKind::Turn => "turn",
                        TestKind::Pair => "pair",
                        TestKind::Seed => "seed",
                    },
                    "moves": t.moves.iter().map(|&a| m.axes[a].name.clone()).collect::<Vec<_>>(),
                    "from_deg": sw.from_deg,
                    "to_deg": sw.to_deg,
                    "step_deg": sw.span_deg() / n as f64,
                    "samples": t.order.samples(n),
                    "order": match t.order {
                        Order::Forward => "forward",
                        Order::Reversed => "reversed",
                        Order::ThereAndBack => "there and back",
                    },
                    "follower": sw.follower.map(|f| serde_json::json!({
                        "axis": m.axes[f.axis].name,
                        "base_deg": f.base_deg,
                        "amplitude_deg": f.amplitude_deg,
                    })),
                    "within_limits": error.is_none(),
                    "error": error,
                })
            })
            .collect();
        let doc = serde_json::json!({
            "machine": m.name,
            "max_tilt_deg": opts.clearance.max_tilt_deg,
            "min_ball_height_mm": opts.clearance.min_ball_height_mm,
            "parameters_mm": m.symbols.iter().zip(params)
                .map(|(s, &x)| (s.name.clone(), serde_json::json!(x)))
                .collect::<serde_json::Map<_, _>>(),
            "tests": entries,
        });
        let text = serde_json::to_string_pretty(&doc)
            .map_err(|e| Error::computation(format!("--json: {e}")))?
            + "\n";
        let mut files = Outputs::new();
        files.add("--json", target.clone(), text);
        return Ok(Done::new("", files, matches!(target, Target::Stdout)));
    }
    if tests.is_empty() {
        return Ok(Done::text(format!(
            "Machine {} has no rotary axis, so it has no R-test test (the tests turn rotary axes): give a path as a CSV file.\n",
            m.name
        )));
    }
    let width = tests.iter().map(|t| t.name.len()).max().unwrap_or(0);
    let mut text = format!(
        "Tests of machine {} (clearance: tool axis within {}° of the table normal, ball at least {} mm above the table; kinematic parameters: {}):\n",
        m.name,
        short(opts.clearance.max_tilt_deg),
        short(opts.clearance.min_ball_height_mm),
        changed_params(m, params).map_or("the description's defaults".into(), |c| format!(
            "the description's defaults but {c} mm"
        ))
    );
    for (t, error) in tests.iter().zip(&status) {
        text += &format!("  {:width$}  {}\n", t.name, t.description);
        if let Some(e) = error {
            text += &format!("  {:width$}  not generated here: {e}\n", "");
        }
    }
    Ok(Done::text(text))
}
