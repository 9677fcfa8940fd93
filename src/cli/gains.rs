//! `rtest gains`: the error-gain functions of a machine's model, as a symbolic table or as
//! numbers at one pose.

use super::{CliError, CliResult, EXIT_CODES, args, pose_args};
use codegen::GainModel;
use codegen::table::{self, render};
use solver::fitting::GainSource;
use solver::io::report::{GainTableReport, PoseGainsReport, to_json};
use solver::io::text::gains::{pose_gains, title};
use solver::simulation::pose::{PoseError, complete};

const LONG_ABOUT: &str = "\
Error-gain functions of a machine (the seed's Tables 1 and 2): how each error of the model moves \
the tool point relative to the workpiece point, to first order, in the tool frame.

Without --at: the symbolic table, one row per error, columns ΔX ΔY ΔZ (position: mm per mm of a \
translational error, mm per rad of an angular error) and ΔI ΔJ ΔK (orientation of the tool z axis, \
per mm or per rad), written in Sa/Ca (sine/cosine of rotary axis A's command), Xm (linear \
command of X, mm) and the kinematic symbols (mm).

With --at: the numbers at that pose, computed by the same code the identification uses: for \
every error [gx, gy, gz], tool frame, mm/mm for translational errors and mm/rad for angular \
errors (1 mm/rad = 1 µm of error vector per mrad; an error of e µm moves the tool point by g·e \
µm, an error of e µrad by g·e nm). Axis positions in mm and degrees, kinematic parameters in mm \
(defaults from the machine description, overridden by --param). Every rotary axis must be given; \
linear axes left out of --at are filled by the machine's nominal tool-centre-point inverse \
kinematics (the linear positions that put the tool point on the workpiece point at the given \
rotary positions). The pose must be within the machine's strokes and ranges unless \
--allow-off-stroke is given.

JSON without --at: {\"machine\", \"model\" (null with --errors), \"units\", \"columns\", \
\"atoms\": {name: meaning}, \"gains\": {error: [6 formulas]}}. JSON with --at: {error: [gx, gy, gz]}, \
errors in model order.";

/// `--format` of the gain tables.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// Aligned plain text.
    Text,
    /// A Markdown table.
    Markdown,
    /// A LaTeX longtable.
    Latex,
    /// JSON.
    Json,
}

/// Flags of `rtest gains`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Error-gain functions of a machine (the seed's Tables 1 and 2)",
    long_about = LONG_ABOUT,
    after_help = EXIT_CODES
)]
pub struct GainsArgs {
    /// Built-in machine (see `rtest machines`) or path of a machine TOML file.
    #[arg(long, value_name = "NAME|FILE")]
    machine: String,
    /// Model of the machine: `full` (every error of its model, the default) or a sub-model
    /// (`reduced`, …).
    #[arg(long, value_name = "NAME", conflicts_with = "errors")]
    model: Option<String>,
    /// Explicit errors instead of a model: comma list of ISO 230 names in the order wanted
    /// (`XOC,YOC,BOA`; the digit-zero spelling `X0C` is accepted).
    #[arg(long, value_name = "LIST")]
    errors: Option<String>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    format: Format,
    /// Evaluate at this pose: axis positions, linear in mm, rotary in degrees
    /// (`X=0,Y=0,Z=0,A=30,C=45`). Every rotary axis is required; missing linear axes come
    /// from the nominal tool-centre-point inverse kinematics.
    #[arg(long, value_name = "AXIS=VALUE,...")]
    at: Option<String>,
    /// Kinematic parameters (mm) overriding the machine's defaults (`Xw=-217.504,Zc=29.794`);
    /// only with --at.
    #[arg(long, value_name = "SYMBOL=VALUE,...", requires = "at")]
    param: Option<String>,
    /// Accept a pose outside the machine's strokes and ranges.
    #[arg(long, requires = "at")]
    allow_off_stroke: bool,
}

/// Runs `rtest gains`.
pub fn run(args: &GainsArgs) -> CliResult {
    let m = super::load_machine(&args.machine)?;
    let (model_name, errors) =
        args::select_errors(&m, args.model.as_deref(), args.errors.as_deref())?;
    let title = title(&m, model_name.as_deref(), errors.len());
    let table_format = match args.format {
        Format::Text => Some(table::Format::Text),
        Format::Markdown => Some(table::Format::Markdown),
        Format::Latex => Some(table::Format::Latex),
        Format::Json => None,
    };
    let Some(at) = &args.at else {
        let model = GainModel::derive(&m, &errors);
        let out = match table_format {
            Some(f) => render(&m, &model, &title, f),
            None => to_json(&GainTableReport::new(&m, model_name.as_deref(), &model))
                .map_err(|e| CliError::computation(format!("--format: {e}")))?,
        };
        return super::print(&out);
    };
    let params = pose_args::params(&m, args.param.as_deref())?;
    let pose = complete(&m, &pose_args::at(&m, at)?, params, args.allow_off_stroke).map_err(
        |e| match e {
            PoseError::Ik(_) => CliError::input(format!("--at: {e}")),
            PoseError::OffStroke(_) => {
                CliError::usage(format!("--at: {e} (--allow-off-stroke accepts it)"))
            }
            PoseError::MissingRotary(_) => CliError::usage(format!("--at: {e}")),
        },
    )?;
    let mut source = GainSource::new(&m, &errors, &pose.params)
        .map_err(|e| CliError::usage(format!("--param: {e}")))?;
    let mut gains = vec![[0.0; 3]; source.errors().len()];
    source
        .position_gains(&pose.commands, &mut gains)
        .map_err(|e| CliError::computation(format!("--at: {e}")))?;
    let names: Vec<String> = errors
        .iter()
        .map(|&e| m.catalogue[e].name.clone())
        .collect();
    let angular: Vec<bool> = errors
        .iter()
        .map(|&e| m.catalogue[e].is_angular())
        .collect();
    if let (None, Some(note)) = (table_format, pose.off_ball_note()) {
        // The JSON stays what tools read; the note goes to standard error.
        super::print_text(&format!("{note}\n"), true)?;
    }
    let out = match table_format {
        Some(f) => pose_gains(&m, &title, &pose, &names, &angular, &gains, f),
        None => to_json(
            &PoseGainsReport::new(&names, &gains)
                .map_err(|e| CliError::computation(format!("--at: {e}")))?,
        )
        .map_err(|e| CliError::computation(format!("--format: {e}")))?,
    };
    super::print(&out)
}
