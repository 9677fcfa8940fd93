//! `rtest simulate`: R-test readings of the exact virtual machine along a test path, written as
//! a measurement CSV that `identify` reads back.

use super::args::RecordLimits;
use super::{EXIT_CODES, Error, VerbResult, check_outputs};
use crate::Done;
use formats::csv::{format_record, parse_measurement};
use formats::paths::{PathFileError, load_path};
use formats::truth::TruthError;
use model_spec::units::parse_scaled;
use output::{Outputs, Target};
use report::text::simulation;
use simulation::paths::PathError;
use simulation::readings::SimulateError;
use simulation::truth::{MAX_NOISE_PHI, MAX_NOISE_UM, MAX_SEED, Truth};
use simulation::{provenance, simulate};
use std::path::Path;

const LONG_ABOUT: &str = "\
Simulates an R-test measurement: the exact virtual machine (exact homogeneous transforms, no \
linearisation) runs a test path with the errors of a truth, and the readings are written as a \
measurement CSV.

The path is a test of the machine (`rtest path --machine M --list`: turn-C, pair-A-C, …; on \
machines whose rotary axes are A and C also the seed's K1, K2, K4) or a path CSV file (rotary \
columns in degrees, linear columns in mm optional: filled by the nominal inverse kinematics), \
planned at the description's kinematic parameters or at --param Xw=…,Zw=… (mm, the ball \
position; the truth's ball moves with it and the record reads back there).

The truth (--truth) says the real machine: error values (translational in µm, angular in \
µrad), R-test zero offsets dx0 dy0 dz0 (µm), Gaussian noise (µm; white, or AR(1)) and its seed, \
zeroing at the first sample; --noise-um, --noise-phi, --seed and --zeroed override it. Default: \
the machine's demo truth if it has one (seed-ac-demo for seed-ac), else the nominal machine.

The CSV has the machine's axes (linear mm, rotary degrees), dx_um,dy_um,dz_um (tool minus \
workpiece, tool frame, µm) and t_s (s). It is read back first: readings `identify` would refuse \
(beyond --max-reading-um) are an error (exit code 3) and nothing is written. `-o -` writes it to \
standard output. Prints the samples and the RMS of the readings (µm).

With --probe FILE (docs/probe.md) it simulates a touch probe instead: 9 hits on the sphere at \
each pose of the path, with the probe's pre-travel and noise, as a probe hits CSV.

Details: docs/truth.md (paths, truths, the CSV, --commanded, --instrument), \
docs/probe-simulation.md (--probe).";

/// Flags of `rtest simulate`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Simulate R-test readings on the exact virtual machine (writes a measurement CSV, µm)",
    long_about = LONG_ABOUT,
    after_help = EXIT_CODES
)]
pub struct SimulateArgs {
    /// Built-in machine (see `rtest machines`) or path of a machine TOML file.
    #[arg(long, value_name = "NAME|FILE")]
    machine: String,
    /// Kinematic parameters (mm) overriding the description's defaults, the ball position among
    /// them (`Xw=-200,Zw=180`): the path is planned there and the truth's parameters move by as
    /// much.
    #[arg(long, value_name = "SYMBOL=VALUE,...")]
    param: Option<String>,
    /// Test path: a test of the machine (`turn-C`, `pair-A-C`, K1, K2, K4 …; see `rtest path
    /// --list`) or a path CSV file (rotary axes in degrees, linear axes in mm optional).
    #[arg(long, value_name = "TEST|FILE")]
    path: String,
    /// Truth: a built-in name (seed-ac-demo, seed-ac-reduced, …) or a truth TOML file
    /// (docs/truth.md). Default: the machine's demo truth, else the nominal machine.
    #[arg(long, value_name = "NAME|FILE")]
    truth: Option<String>,
    /// Standard deviation of the Gaussian reading noise per direction, µm, from 0 to 1000
    /// (overrides the truth's).
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    noise_um: Option<String>,
    /// Lag-1 autocorrelation φ of the reading noise, 0 ≤ F < 0.99: AR(1) noise per direction,
    /// e_t = φ·e_{t−1} + σ·√(1−φ²)·n_t (0: white; overrides the truth's `noise_phi`).
    #[arg(long, value_name = "F")]
    noise_phi: Option<String>,
    /// Seed of the noise generator, 0 to 9223372036854775807 (overrides the truth's).
    #[arg(long, value_name = "N",
          value_parser = clap::value_parser!(u64).range(0..=MAX_SEED))]
    seed: Option<u64>,
    /// Zero the readings at the first sample, as R-test software does (overrides the truth).
    #[arg(long)]
    zeroed: bool,
    /// The poses the program commanded before compensation (a pose CSV, or the measurement
    /// the compensated --path came from), written as the record's axes: a controller that
    /// compensates reports the program's positions, not the corrected ones.
    #[arg(long, value_name = "FILE")]
    commanded: Option<std::path::PathBuf>,
    /// A probe instrument file (TOML, docs/probe.md): simulate touch-probe hits on the
    /// calibration sphere at every pose of --path instead of R-test readings, and write a probe
    /// hits CSV (docs/probe-simulation.md); --noise-um is then the probe's noise.
    #[arg(long, value_name = "FILE",
          conflicts_with_all = ["zeroed", "noise_phi", "commanded", "instrument"])]
    probe: Option<std::path::PathBuf>,
    /// The measurement CSV to write (`-`: standard output).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Target,
    #[command(flatten)]
    records: RecordLimits,
    #[command(flatten)]
    instrument: super::args::InstrumentArgs,
}

/// Parses `--noise-um` (µm, finite, 0 to [`MAX_NOISE_UM`]) into mm, without double rounding.
fn noise_mm(text: &str) -> VerbResult<f64> {
    let bad = |why: &str| Error::usage(format!("--noise-um: `{text}` {why}"));
    let x: f64 = text
        .trim()
        .parse()
        .map_err(|_| bad("is not a number (µm)"))?;
    if !x.is_finite() || !(0.0..=MAX_NOISE_UM).contains(&x) {
        return Err(bad(&format!(
            "must be a finite number from 0 to {MAX_NOISE_UM} µm"
        )));
    }
    parse_scaled(text, -3).ok_or_else(|| bad("is not a plain decimal number (µm)"))
}

/// Parses `--noise-phi` (finite, 0 ≤ φ < [`MAX_NOISE_PHI`]).
fn noise_phi(text: &str) -> VerbResult<f64> {
    let x: f64 = text.trim().parse().map_err(|_| {
        Error::usage(format!(
            "--noise-phi: `{text}` is not a number (the lag-1 autocorrelation)"
        ))
    })?;
    if !(x.is_finite() && (0.0..MAX_NOISE_PHI).contains(&x)) {
        return Err(Error::usage(format!(
            "--noise-phi: `{text}` must be at least 0 and below {MAX_NOISE_PHI}"
        )));
    }
    Ok(x)
}

/// The truth of `--truth`, else the machine's demo truth, else the nominal machine.
fn truth(m: &model_spec::Machine, name: Option<&str>) -> VerbResult<Truth> {
    let found = match name {
        Some(n) => formats::truth::load_truth(n, m),
        None => formats::truth::default_truth(m),
    };
    found.map_err(|e| match e {
        TruthError::NotFound(_) => Error::usage(format!("--truth: {e}")),
        _ => Error::input(format!("--truth: {e}")),
    })
}

/// Writes the poses of the pose file `file` (one per sample of `record`, mm and degrees) as
/// the record's commands.
fn relabel(
    m: &model_spec::Machine,
    record: &mut simulation::record::Record,
    file: &Path,
) -> VerbResult {
    let table = formats::poses::read_pose_file(file, &formats::poses::axis_words(m))
        .map_err(|e| Error::input(format!("--commanded: {e}")))?;
    let poses = table.poses();
    if poses.len() != record.samples.len() {
        return Err(Error::input(format!(
            "--commanded: {} holds {} poses, the path {} samples: they must be the same poses, before and after compensation",
            file.display(),
            poses.len(),
            record.samples.len()
        )));
    }
    for (sample, pose) in record.samples.iter_mut().zip(poses) {
        sample.commands = formats::poses::from_file_units(m, &pose.commands);
    }
    Ok(())
}

/// Runs `rtest simulate`.
pub fn run(args: &SimulateArgs) -> VerbResult<Done> {
    let m = super::load_machine(&args.machine)?;
    let noise = args.noise_um.as_deref().map(noise_mm).transpose()?;
    let phi = args.noise_phi.as_deref().map(noise_phi).transpose()?;
    let mut inputs: Vec<(&str, &Path)> = Vec::new();
    inputs.extend(super::machine_file(&args.machine).map(|p| ("--machine", p)));
    let path_file = Path::new(&args.path);
    if path_file.exists() {
        inputs.push(("--path", path_file));
    }
    if let Some(t) = args.truth.as_deref().map(Path::new).filter(|p| p.exists()) {
        inputs.push(("--truth", t));
    }
    if let Some(c) = &args.commanded {
        inputs.push(("--commanded", c.as_path()));
    }
    inputs.extend(args.instrument.input());
    if let Some(p) = &args.probe {
        inputs.push(("--probe", p.as_path()));
    }
    check_outputs(&inputs, &[("-o", &args.output)], &[])?;
    let mut truth = truth(&m, args.truth.as_deref())?;
    // A ball position on the command line: the machine as planned there, the truth's real
    // parameters moved by as much as the plan's.
    let params = super::pose_args::params(&m, args.param.as_deref())?;
    let defaults = m.default_parameters();
    for ((real, p), d) in truth.params.iter_mut().zip(&params).zip(&defaults) {
        *real += p - d;
    }
    let m = formats::campaign::machine_at(&m, &params);
    let read = args.records.read_options();
    let path = load_path(&m, &args.path, &read).map_err(|e| match e {
        PathFileError::NotFound { .. } | PathFileError::Builtin(PathError::NotAC { .. }) => {
            Error::usage(format!("--path: {e}"))
        }
        other => Error::input(format!("--path: {other}")),
    })?;
    if let Some(probe_file) = &args.probe {
        return super::simulate_probe::run(&super::simulate_probe::ProbeRequest {
            machine: &m,
            path_name: &args.path,
            path: &path,
            truth: &truth,
            probe_file,
            noise_mm: noise,
            seed: args.seed,
            output: &args.output,
        });
    }
    if let Some(n) = noise {
        truth.noise_mm = n;
    }
    if let Some(p) = phi {
        truth.noise_phi = p;
    }
    if let Some(s) = args.seed {
        truth.seed = s;
    }
    truth.zeroed |= args.zeroed;
    if let Some((instrument, frame)) = args.instrument.load()? {
        return run_instrument(args, &m, &truth, &path, &instrument, frame);
    }
    let mut record = simulate(&m, &truth, &path).map_err(|e| match e {
        e @ SimulateError::Times { .. } => Error::input(format!("--path {}: {e}", args.path)),
        e => Error::computation(format!("--truth: {e}")),
    })?;
    if let Some(file) = &args.commanded {
        relabel(&m, &mut record, file)?;
    }
    let comments = provenance(&m, &args.path, &truth, record.samples.len());
    let csv = format_record(&m, &record, &comments)
        .map_err(|e| Error::computation(format!("-o: {e}")))?;
    // What is written is what identify reads: read it back with the same rules.
    parse_measurement(&args.output.to_string(), &csv, &m, &read).map_err(|e| {
        Error::computation(format!(
            "-o: the simulated record would not be accepted by identify, so it is not written: {e}"
        ))
    })?;
    let mut files = Outputs::new();
    files.add("-o", args.output.clone(), csv);
    let written = args.output.path().map(|p| p.display().to_string());
    let text = simulation(&m, &args.path, &truth, &record, written.as_deref());
    Ok(Done::new(text, files, matches!(args.output, Target::Stdout)).unlisted())
}

/// `rtest simulate --instrument`: the sensors' readings instead of the error vectors.
fn run_instrument(
    args: &SimulateArgs,
    m: &model_spec::Machine,
    truth: &Truth,
    path: &simulation::record::Record,
    instrument: &model_spec::instrument::Instrument,
    frame: model_spec::instrument::ReadingsFrame,
) -> VerbResult<Done> {
    use formats::sensors::{format_sensor_record, parse_sensor_measurement};
    use simulation::instrument::simulate::{SensorSimulationError, simulate_sensors};
    let mut sensors = simulate_sensors(m, truth, path, instrument, frame).map_err(|e| match e {
        SensorSimulationError::Simulate(e @ SimulateError::Times { .. }) => {
            Error::input(format!("--path {}: {e}", args.path))
        }
        SensorSimulationError::Contact { .. } => Error::computation(format!(
            "--instrument {}: {e}: the error vector takes the ball off a sensor",
            instrument.name
        )),
        e => Error::computation(format!("--truth: {e}")),
    })?;
    if let Some(file) = &args.commanded {
        relabel(m, &mut sensors.record, file)?;
    }
    let mut comments = provenance(m, &args.path, truth, sensors.record.samples.len());
    comments.pop();
    comments.push(format!(
        "instrument: {} ({} sensors, displacements in the {} frame); sensor noise σ {} µm from seed {} (the truth's noise is that of the displacement)",
        instrument.name,
        instrument.sensors.len(),
        frame.keyword(),
        instrument
            .sensors
            .iter()
            .map(|s| format!("{} {}", s.name, model_spec::units::format_scaled(s.noise_mm, 3)))
            .collect::<Vec<_>>()
            .join(", "),
        truth.seed
    ));
    comments.push(format!(
        "units: linear axes mm, rotary axes degrees, {} µm (sensor readings, positive: plunger pushed in), t_s s",
        instrument.columns().join(" ")
    ));
    let csv = format_sensor_record(m, instrument, &sensors, &comments)
        .map_err(|e| Error::computation(format!("-o: {e}")))?;
    let read = args.records.read_options();
    let record =
        parse_sensor_measurement(&args.output.to_string(), &csv, m, instrument, frame, &read)
            .map_err(|e| {
                Error::computation(format!(
                    "-o: the simulated record would not be accepted by identify --instrument, so it is not written: {e}"
                ))
            })?;
    let mut files = Outputs::new();
    files.add("-o", args.output.clone(), csv);
    let written = args.output.path().map(|p| p.display().to_string());
    let mut text = simulation(m, &args.path, truth, &record, written.as_deref());
    if let Some(at) = text.find("): ") {
        text.insert_str(at + 1, &format!(" with instrument {}", instrument.name));
    }
    let text = text.replace(
        "RMS of the readings",
        "RMS of the error vectors the sensors read",
    );
    Ok(Done::new(text, files, matches!(args.output, Target::Stdout)).unlisted())
}
