//! `rtest gains`: the error-gain functions of a machine's model, as a symbolic table or as
//! numbers at one pose.

use super::{EXIT_CODES, Error, VerbResult, args, pose_args};
use crate::Done;
use codegen::GainModel;
use codegen::atoms::AtomKind;
use codegen::poly::Poly;
use codegen::table::{self, render};
use model_spec::{AxisKind, Machine};
use report::json::gains::COLUMNS;
use report::json::{GainTableReport, PoseGains, PoseGainsReport, to_json};
use report::text::gains::{pose_gains, title};
use simulation::pose::{Pose, PoseError, complete};

const LONG_ABOUT: &str = "\
Error-gain functions of a machine (the seed's Tables 1 and 2): how each error of the model moves \
the tool point relative to the workpiece point, to first order, in the tool frame.

Without --at: the symbolic table, one row per error, columns ΔX ΔY ΔZ (position: mm per mm of a \
translational error, mm per rad of an angular error) and ΔI ΔJ ΔK (orientation of the tool z axis, \
per mm or per rad), written in Sa/Ca (sine/cosine of rotary axis A's command), Xm (linear \
command of X, mm) and the kinematic symbols (mm).

With --at: the six gains of every error at that pose: position [gx, gy, gz] in mm/mm or mm/rad \
(an error of e µm moves the tool point by g·e µm, of e µrad by g·e nm) and orientation [gi, gj, \
gk] (1/mm, 1/rad). Axis positions in mm and degrees, kinematic parameters in mm (--param). \
Every rotary axis must be given; linear axes left out are filled by the nominal \
tool-centre-point inverse kinematics. The pose must be within the strokes and ranges unless \
--allow-off-stroke. A gain within the rounding bound of its evaluation is written 0 and listed.

Details (the pose, the zeros, the JSON of --format json): docs/codegen.md §10.";

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
pub fn run(args: &GainsArgs) -> VerbResult<Done> {
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
                .map_err(|e| Error::computation(format!("--format: {e}")))?,
        };
        return Ok(Done::text(out));
    };
    let params = pose_args::params(&m, args.param.as_deref())?;
    let pose = complete(&m, &pose_args::at(&m, at)?, params, args.allow_off_stroke).map_err(
        |e| match e {
            PoseError::Ik(_) => Error::input(format!("--at: {e}")),
            PoseError::OffStroke(_) => {
                Error::usage(format!("--at: {e} (--allow-off-stroke accepts it)"))
            }
            PoseError::MissingRotary(_) => Error::usage(format!("--at: {e}")),
        },
    )?;
    let model = GainModel::derive(&m, &errors);
    // The shared form (fast on long chains): each named intermediate is evaluated in turn
    // with its bound, which becomes the error bound of its atom.
    let mut atoms = model.atoms.all_values(&pose.commands, &pose.params);
    let mut atom_errors = atom_error_bounds(&m, &model, &pose, &atoms);
    for d in model.intermediates().definitions() {
        let (value, bound) = evaluate_with_bound(d, &atoms, &atom_errors);
        atoms.push(value);
        atom_errors.push(bound);
    }
    let mut gains = vec![[0.0; 6]; errors.len()];
    let mut vanishing = Vec::new();
    for (i, polys) in model.gains.shared().iter().enumerate() {
        for (k, p) in polys.iter().enumerate() {
            let (value, bound) = evaluate_with_bound(p, &atoms, &atom_errors);
            if !value.is_finite() {
                return Err(Error::computation(format!(
                    "--at: gain {} of {} is not finite at this pose ({value})",
                    COLUMNS[k], model.error_names[i]
                )));
            }
            gains[i][k] = if p.is_zero() {
                0.0
            } else if value.abs() <= bound {
                vanishing.push(format!("{} {}", model.error_names[i], COLUMNS[k]));
                0.0
            } else {
                value
            };
        }
    }
    let mut notes = String::new();
    if let (None, Some(note)) = (table_format, pose.off_ball_note()) {
        // The JSON stays what tools read; the note goes to standard error.
        notes = format!("{note}\n");
    }
    // The distance from the tool point to the workpiece point is 0 to rounding after the
    // inverse kinematics: within the bound of its own rounding it is written 0.
    let mut pose = pose;
    if pose.gap_mm <= 16.0 * f64::EPSILON * lengths(&m, &pose) {
        pose.gap_mm = 0.0;
    }
    let report = PoseGains {
        names: &model.error_names,
        angular: &model.angular,
        gains: &gains,
        vanishing,
        zeros: ZERO_RULE.into(),
    };
    let out = match table_format {
        Some(f) => pose_gains(&m, &title, &pose, &report, f),
        None => to_json(
            &PoseGainsReport::new(&m, model_name.as_deref(), &pose, &report)
                .map_err(|e| Error::computation(format!("--at: {e}")))?,
        )
        .map_err(|e| Error::computation(format!("--format: {e}")))?,
    };
    Ok(Done::text(out).noting(notes))
}

/// How `rtest gains --at` decides that a gain is zero (said in its outputs).
pub const ZERO_RULE: &str = "A gain is written 0 when its polynomial is identically zero, or when its value at this pose is within the bound on the rounding error of its evaluation (it vanishes here to the precision of the numbers; such gains are listed).";

/// Bound on the absolute error of each atom's value at `pose` (`atoms`: the values, in atom
/// order): a sine or cosine carries the rounding of degrees to radians and of the function,
/// `ε·(2·|θ| + 1)` for θ in rad; a linear command the inverse kinematics filled carries the
/// distance it left between the tool point and the workpiece point plus `ε` times the lengths
/// it was computed from; every other number (a command or parameter as given, a constant of an
/// inclined frame) is exact to `ε` relative. `ε` is the machine epsilon of `f64`.
fn atom_error_bounds(m: &Machine, model: &GainModel, pose: &Pose, atoms: &[f64]) -> Vec<f64> {
    let eps = f64::EPSILON;
    let lengths = lengths(m, pose);
    model
        .atoms
        .kinds
        .iter()
        .zip(atoms)
        .map(|(kind, &v)| match *kind {
            AtomKind::Sin(a) | AtomKind::Cos(a) => eps * (2.0 * pose.commands[a].abs() + 1.0),
            AtomKind::Command(a) if pose.from_ik[a] => pose.gap_mm + eps * lengths,
            _ => eps * v.abs(),
        })
        .collect()
}

/// The sum of the magnitudes of the lengths a pose is computed from (kinematic parameters and
/// linear commands), mm: the scale of the rounding of positions at the pose.
fn lengths(m: &Machine, pose: &Pose) -> f64 {
    pose.params.iter().map(|p| p.abs()).sum::<f64>()
        + m.axes
            .iter()
            .zip(&pose.commands)
            .filter(|(a, _)| a.kind == AxisKind::Linear)
            .map(|(_, c)| c.abs())
            .sum::<f64>()
}

/// The value of `p` at the atom values `x` and a bound on its absolute error, given a bound
/// `dx` on the error of every atom value (a named intermediate is an atom whose bound is that
/// of its own evaluation).
///
/// With `P` the polynomial of the absolute values of `p`'s coefficients, evaluated term by
/// term: the input errors move the value by at most `P(|x| + dx) − P(|x|)` (to first order,
/// all terms positive), and evaluating `n` operations of products and a sum in floating point
/// adds at most `γₙ·P(|x| + dx)` with `γₙ = n·u / (1 − n·u)` (Higham, *Accuracy and Stability
/// of Numerical Algorithms*, §3.1), `n` = highest degree + coefficient rounding + number of
/// terms; the bound is doubled to cover its own rounding.
fn evaluate_with_bound(p: &Poly, x: &[f64], dx: &[f64]) -> (f64, f64) {
    let (mut plain, mut moved, mut degree) = (0.0f64, 0.0f64, 0u32);
    for (mono, c) in p.terms() {
        let c = c.to_f64().abs();
        let (mut a, mut b) = (c, c);
        for &(atom, e) in mono.factors() {
            let i = atom as usize;
            a *= x[i].abs().powi(e as i32);
            b *= (x[i].abs() + dx[i]).powi(e as i32);
        }
        plain += a;
        moved += b;
        degree = degree.max(mono.degree());
    }
    let n = (degree as usize + 3 + p.len()) as f64;
    let u = f64::EPSILON / 2.0;
    let gamma = n * u / (1.0 - n * u);
    (p.eval(x), 2.0 * (gamma * moved + (moved - plain)))
}
