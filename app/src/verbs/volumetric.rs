//! `rtest volumetric`: the three-axis volumetric compensation from 6D laser-interferometer
//! measurements taken at the tool end (docs/volumetric.md).

use super::{EXIT_CODES, Error, VerbResult, check_outputs};
use crate::Done;
use compensation::volumetric::path::correct_poses;
use compensation::volumetric::summary::{SetSummary, VolumetricReport};
use compensation::volumetric::{
    AxisMeasurement, GridSpec, VolumetricError, VolumetricModel, format_grid, read_laser,
    read_squareness,
};
use formats::poses::{axis_words, read_pose_file};
use model_spec::{AxisKind, Machine};
use output::{Outputs, Target};
use std::path::{Path, PathBuf};

const LONG_ABOUT: &str = "\
The three-axis volumetric compensation of the seed's three-axis paper: the kinematic-parameter \
independent model of a machine whose three linear axes carry the tool (seed-3axis), built from \
one 6D laser-interferometer measurement per axis taken with the reflector at the tool end, and \
the squareness errors from their own measurement. It predicts the tool-end error du (µm) at any \
X, Y, Z of the measured ranges and compensates with -du: the corrected command u_c solves \
u_c = u - du(u_c).

--laser names one CSV per linear axis (AXIS=FILE, comma-separated or the flag repeated): the \
commands of every axis in mm (X_mm,Y_mm,Z_mm: the measured axis strictly increasing, the others \
standing still) and the six errors of the measured axis at the tool end (EXX_um,EYX_um,EZX_um \
in µm and EAX_urad,EBX_urad,ECX_urad in µrad for X). --squareness is a TOML file with every \
squareness error of the machine in µrad (COX, AOZ, BOZ on seed-3axis) and optionally \
[reference], the axis positions in mm where du = 0 (default 0). A position outside a measured \
range is an error.

--path corrects the commanded poses of a CSV (columns X,Y,Z in mm; other columns kept byte for \
byte) into -o; a corrected command outside a stroke is refused. --grid writes du on a grid over \
the measured ranges at --pitch mm (X_mm,Y_mm,Z_mm,dx_um,dy_um,dz_um: the predicted error; a \
controller moves by -du). Prints the largest and RMS predicted error and correction per axis \
over the grid, the path, or (neither given) an 11 x 11 x 11 lattice; --json prints it as JSON.

Details: docs/volumetric.md.";

/// Flags of `rtest volumetric`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Volumetric compensation of a three-axis machine from 6D laser measurements at the tool end (µm, µrad)",
    long_about = LONG_ABOUT,
    after_help = EXIT_CODES
)]
pub struct VolumetricArgs {
    /// Built-in machine (see `rtest machines`) or path of a machine TOML file: three linear
    /// axes carrying the tool (seed-3axis).
    #[arg(long, value_name = "NAME|FILE")]
    machine: String,
    /// The laser measurement of each linear axis: `X=x.csv,Y=y.csv,Z=z.csv` (or the flag
    /// once per axis).
    #[arg(long, value_name = "AXIS=FILE,...", required = true)]
    laser: Vec<String>,
    /// The squareness errors (µrad) and the reference point (mm): a TOML file.
    #[arg(long, value_name = "FILE")]
    squareness: PathBuf,
    /// A CSV of commanded poses (columns X,Y,Z in mm) to correct; needs -o.
    #[arg(long, value_name = "FILE", requires = "output")]
    path: Option<PathBuf>,
    /// Where to write the corrected path (`-`: standard output).
    #[arg(short = 'o', long = "output", value_name = "FILE", requires = "path")]
    output: Option<Target>,
    /// Where to write the volumetric grid CSV (predicted error, µm); needs --pitch.
    #[arg(long, value_name = "FILE", requires = "pitch")]
    grid: Option<Target>,
    /// The grid's pitch, mm: it must divide every measured range.
    #[arg(
        long,
        value_name = "MM",
        requires = "grid",
        allow_negative_numbers = true
    )]
    pitch: Option<String>,
    /// Print the summary as JSON.
    #[arg(long)]
    json: bool,
}

/// The points per axis of the lattice summarised when neither --grid nor --path is given.
const LATTICE_POINTS: usize = 11;

/// `--laser` as (axis, file) pairs, each linear axis of `m` once.
fn laser_files(m: &Machine, values: &[String]) -> VerbResult<Vec<(usize, PathBuf)>> {
    let mut out: Vec<(usize, PathBuf)> = Vec::new();
    for item in values.iter().flat_map(|v| v.split(',')) {
        let Some((axis, file)) = item.split_once('=') else {
            return Err(Error::usage(format!(
                "--laser: `{item}` is not AXIS=FILE (e.g. X=x.csv)"
            )));
        };
        let axis = axis.trim();
        let a = m
            .axis_by_name(&axis.to_ascii_uppercase())
            .filter(|&a| m.axes[a].kind == AxisKind::Linear)
            .ok_or_else(|| {
                let linear: Vec<&str> = m.linear_axes().map(|a| m.axes[a].name.as_str()).collect();
                Error::usage(format!(
                    "--laser: `{axis}` is not a linear axis of {} ({})",
                    m.name,
                    linear.join(", ")
                ))
            })?;
        if file.is_empty() {
            return Err(Error::usage(format!("--laser: `{item}` names no file")));
        }
        if out.iter().any(|(b, _)| *b == a) {
            return Err(Error::usage(format!(
                "--laser: axis {} is given twice",
                m.axes[a].name
            )));
        }
        out.push((a, PathBuf::from(file)));
    }
    Ok(out)
}

/// A library error as the verb's error: the files and the poses are bad input, a failed
/// computation is exit code 3.
fn failure(flag: &str, e: VolumetricError) -> Error {
    match e {
        VolumetricError::Computation(_) => Error::computation(format!("{flag}: {e}")),
        _ => Error::input(format!("{flag}: {e}")),
    }
}

/// Parses `--pitch` (mm, finite, positive).
fn pitch_mm(text: &str) -> VerbResult<f64> {
    match text.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        _ => Err(Error::usage(format!(
            "--pitch: `{text}` is not a positive number of mm"
        ))),
    }
}

/// Runs `rtest volumetric`.
pub fn run(args: &VolumetricArgs) -> VerbResult<Done> {
    let m = super::load_machine(&args.machine)?;
    let lasers = laser_files(&m, &args.laser)?;
    let pitch = args.pitch.as_deref().map(pitch_mm).transpose()?;
    let mut inputs: Vec<(&str, &Path)> = Vec::new();
    inputs.extend(super::machine_file(&args.machine).map(|p| ("--machine", p)));
    inputs.extend(lasers.iter().map(|(_, p)| ("--laser", p.as_path())));
    inputs.push(("--squareness", args.squareness.as_path()));
    if let Some(p) = &args.path {
        inputs.push(("--path", p.as_path()));
    }
    let mut outputs: Vec<(&str, &Target)> = Vec::new();
    if let Some(o) = &args.output {
        outputs.push(("-o", o));
    }
    if let Some(g) = &args.grid {
        outputs.push(("--grid", g));
    }
    check_outputs(&inputs, &outputs, &[])?;
    let measurements: Vec<AxisMeasurement> = lasers
        .iter()
        .map(|(a, p)| read_laser(p, &m, *a).map_err(|e| failure("--laser", e)))
        .collect::<VerbResult<_>>()?;
    let squareness =
        read_squareness(&args.squareness, &m).map_err(|e| failure("--squareness", e))?;
    let model =
        VolumetricModel::new(&m, &measurements, &squareness).map_err(|e| failure("--laser", e))?;

    let mut files = Outputs::new();
    let mut sets = Vec::new();
    if let (Some(target), Some(p)) = (&args.grid, pitch) {
        let grid =
            GridSpec::new(&m, &model, p).map_err(|e| Error::usage(format!("--pitch: {e}")))?;
        let poses = grid.poses(m.axes.len());
        let (summary, du) = SetSummary::over_poses(&m, &model, "grid", Some(p), &poses)
            .map_err(|e| failure("--grid", e))?;
        let comments = vec![
            format!(
                "rtest volumetric grid of {}: predicted tool-end error du (actual minus nominal tool point, µm) at each grid point (mm); a controller moves by -du",
                m.name
            ),
            format!(
                "pitch {} mm; du = 0 at the reference point; laser files: {}; squareness: {}",
                model_spec::units::short(p),
                lasers
                    .iter()
                    .map(|(a, f)| format!("{}={}", m.axes[*a].name, f.display()))
                    .collect::<Vec<_>>()
                    .join(", "),
                args.squareness.display()
            ),
        ];
        files.add(
            "--grid",
            target.clone(),
            format_grid(&m, &grid, &du, &comments),
        );
        sets.push(summary);
    }
    if let (Some(path), Some(target)) = (&args.path, &args.output) {
        let table = read_pose_file(path, &axis_words(&m))
            .map_err(|e| Error::input(format!("--path: {e}")))?;
        let poses: Vec<(usize, Vec<f64>)> = table
            .poses()
            .iter()
            .map(|p| (p.line, p.commands.clone()))
            .collect();
        let corrected =
            correct_poses(table.file(), &m, &model, &poses).map_err(|e| failure("--path", e))?;
        let commands: Vec<Vec<f64>> = corrected.iter().map(|c| c.commands.clone()).collect();
        let text = table
            .write(&commands)
            .map_err(|e| Error::input(format!("-o: {e}")))?;
        let du = corrected
            .iter()
            .map(|c| model.du(&c.commanded).map_err(|e| failure("--path", e)))
            .collect::<VerbResult<Vec<_>>>()?;
        sets.push(SetSummary::new(&m, "path", None, &du, &corrected));
        files.add("-o", target.clone(), text);
    }
    if sets.is_empty() {
        let lattice = GridSpec::lattice(&m, &model, LATTICE_POINTS);
        let poses = lattice.poses(m.axes.len());
        let (summary, _) = SetSummary::over_poses(&m, &model, "lattice", None, &poses)
            .map_err(|e| failure("--laser", e))?;
        sets.push(summary);
    }
    let report = VolumetricReport::new(&m, &model, &measurements, &squareness, sets);
    let stdout_taken = args
        .output
        .as_ref()
        .is_some_and(|t| matches!(t, Target::Stdout))
        || args
            .grid
            .as_ref()
            .is_some_and(|t| matches!(t, Target::Stdout));
    if args.json {
        let mut j = serde_json::to_string_pretty(&report)
            .map_err(|e| Error::computation(format!("--json: {e}")))?;
        j.push('\n');
        Ok(Done::new(j, files, stdout_taken).unlisted())
    } else {
        Ok(Done::new(report.text(), files, stdout_taken))
    }
}
