//! `rtest instrument`: the R-test instruments (sensor heads): the presets, one described, and
//! the calibration of an instrument's own errors from known displacements.

use super::{EXIT_CODES, Error, VerbResult, check_outputs};
use crate::Done;
use fitting::calibrate::{Calibration, CalibrationError, PARAMETERS, SensorCalibration, calibrate};
use formats::csv::ReadOptions;
use formats::sensors::read_calibration_file;
use model_spec::instrument::{
    Instrument, PRESETS, ReadingsFrame, Tip, parse_instrument, preset, smallest_singular_value,
    write::to_toml,
};
use model_spec::units::{fixed, format_scaled};
use output::{Outputs, Target};
use simulation::instrument::head::SensorHead;
use std::path::PathBuf;

const LONG_ABOUT: &str = "\
The R-test instruments: a precision ball and three or more displacement sensors in the nest \
(docs/instrument.md). `list` lists the presets, `show` describes one (or a TOML file): its \
sensors, the first-order map from the error vector to the readings, and the noise of the error \
vector the readings give. `calibrate` fits each sensor's gain error, zero and direction error \
from a calibration record (known displacements dx_um,dy_um,dz_um beside the sensors' readings \
s1_um, …) with uncertainties, and writes the calibrated description; a quantity the record does \
not determine gets no number and keeps its described value.

Give --instrument NAME|FILE to identify, validate, diagnose and simulate to read or write the \
sensors' readings instead of dx_um,dy_um,dz_um.";

/// Flags of `rtest instrument`.
#[derive(Debug, clap::Args)]
#[command(
    about = "R-test instruments: list the presets, describe one, calibrate one from known displacements",
    long_about = LONG_ABOUT,
    after_help = EXIT_CODES
)]
pub struct InstrumentVerb {
    #[command(subcommand)]
    action: Action,
}

#[derive(Debug, clap::Subcommand)]
enum Action {
    /// List the preset instruments.
    List,
    /// Describe an instrument: a preset or a TOML file.
    Show {
        /// The instrument: a preset name or the path of a TOML file.
        #[arg(value_name = "NAME|FILE")]
        instrument: String,
    },
    /// Calibrate an instrument's gains, zeros and directions from known displacements, and
    /// write the calibrated description.
    Calibrate(CalibrateArgs),
}

/// Flags of `rtest instrument calibrate`.
#[derive(Debug, clap::Args)]
struct CalibrateArgs {
    /// The instrument as described: a preset name or the path of a TOML file.
    #[arg(long, value_name = "NAME|FILE")]
    instrument: String,
    /// The calibration record: a CSV with the known error vector dx_um,dy_um,dz_um (nest minus
    /// ball, nest frame, µm), every sensor's reading (s1_um, …, µm) and optionally t_s.
    #[arg(long, value_name = "FILE")]
    data: PathBuf,
    /// The calibrated description to write (TOML; `-`: standard output).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Target,
}

/// Runs `rtest instrument`.
pub fn run(args: &InstrumentVerb) -> VerbResult<Done> {
    match &args.action {
        Action::List => Ok(Done::text(list())),
        Action::Show { instrument } => {
            let i = super::args::instrument(instrument, "instrument")?;
            Ok(Done::text(show(&i)))
        }
        Action::Calibrate(c) => run_calibrate(c),
    }
}

fn list() -> String {
    let mut out = String::from("Preset instruments (rtest instrument show NAME):\n");
    for (name, _) in PRESETS {
        if let Some(Ok(i)) = preset(name) {
            out += &format!("  {name:<12} {}\n", i.description);
        }
    }
    out
}

/// A vector for people, mm or unitless, four decimals.
fn vector(v: [f64; 3]) -> String {
    format!(
        "{:>8} {:>8} {:>8}",
        fixed(v[0], 4),
        fixed(v[1], 4),
        fixed(v[2], 4)
    )
}

fn show(i: &Instrument) -> String {
    let r = i.ball_radius_mm;
    let mut out = format!("instrument {}: {}\n", i.name, i.description);
    out += &format!(
        "ball radius {} mm; displacements in the {} frame{}\n",
        format_scaled(r, 0),
        i.frame.keyword(),
        if i.frame == ReadingsFrame::Machine {
            " (rotated into the tool frame at each pose)"
        } else {
            ""
        }
    );
    out += &format!(
        "{:<8} {:^26}  {:<16} {:^26}  {:>9} {:>9} {:>9}\n",
        "sensor", "direction x y z", "tip", "tip at zero x y z (mm)", "gain", "noise µm", "zero µm"
    );
    for s in &i.sensors {
        let tip = match s.tip {
            Tip::Flat { face_radius_mm } => {
                format!("flat, face r {}", format_scaled(face_radius_mm, 0))
            }
            Tip::Sphere { radius_mm } => format!("ball, r {}", format_scaled(radius_mm, 0)),
        };
        out += &format!(
            "{:<8} {}  {:<16} {}  {:>9} {:>9} {:>9}\n",
            s.name,
            vector(s.direction),
            tip,
            vector(s.tip_at_zero(r)),
            fixed(s.gain, 6),
            fixed(s.noise_mm * 1e3, 3),
            fixed(s.zero_mm * 1e3, 3)
        );
    }
    let rows = model_spec::instrument::first_order_matrix(i);
    out += "first-order map at zero (reading per error vector, µm/µm):\n";
    for (s, row) in i.sensors.iter().zip(&rows) {
        out += &format!("  {:<8} {}\n", s.name, vector(*row));
    }
    out += &format!(
        "smallest singular value {} (1 for three orthogonal sensors): the least the readings move per µm of displacement\n",
        fixed(smallest_singular_value(&rows), 3)
    );
    let head = SensorHead::new(i);
    let zeros: Vec<f64> = i.sensors.iter().map(|s| s.zero_mm).collect();
    if let Ok(inv) = head.displacement(&zeros, false) {
        let c = inv.covariance;
        let sd = [c[0][0].sqrt(), c[1][1].sqrt(), c[2][2].sqrt()];
        let corr = |a: usize, b: usize| c[a][b] / (sd[a] * sd[b]);
        out += &format!(
            "noise of the error vector read at zero, from the sensors' σ: σx {} µm, σy {} µm, σz {} µm; correlations xy {}, xz {}, yz {}\n",
            fixed(sd[0] * 1e3, 3),
            fixed(sd[1] * 1e3, 3),
            fixed(sd[2] * 1e3, 3),
            fixed(corr(0, 1), 2),
            fixed(corr(0, 2), 2),
            fixed(corr(1, 2), 2)
        );
    }
    let lateral: Vec<String> = i
        .sensors
        .iter()
        .filter_map(|s| match s.tip {
            Tip::Sphere { radius_mm } => Some(format!(
                "{} {}",
                s.name,
                fixed(0.05f64.powi(2) / (2.0 * (r + radius_mm)) * 1e3, 3)
            )),
            Tip::Flat { .. } => None,
        })
        .collect();
    if !lateral.is_empty() {
        out += &format!(
            "ball tips read a displacement d⊥ across their axis as −|d⊥|²/(2(R + r)), at 50 µm: {} µm (the exact inverse accounts for it)\n",
            lateral.join(", ")
        );
    }
    out
}

/// A calibrated value for people: `value ± std unit`, or why there is none.
fn value(cal: &SensorCalibration, j: usize, scale: f64, decimals: usize, unit: &str) -> String {
    match cal.value(j) {
        Some((v, Some(s))) => format!(
            "{} ± {} {unit}",
            fixed(v * scale, decimals),
            fixed(s * scale, decimals)
        ),
        Some((v, None)) => format!(
            "{} (no uncertainty: no degree of freedom) {unit}",
            fixed(v * scale, decimals)
        ),
        None => "not determined by the record".into(),
    }
}

fn calibration_text(c: &Calibration, data: &str) -> String {
    let mut out = format!(
        "calibration of instrument {} from {data} ({} known displacements)\n",
        c.instrument.name, c.rows
    );
    for (cal, s) in c.sensors.iter().zip(&c.instrument.sensors) {
        let [p1, p2] = cal.tilt_axes;
        out += &format!(
            "sensor {}: gain error {}; zero {}; tilt about [{}] {}; tilt about [{}] {}; residual σ̂ {} µm; calibrated gain {}\n",
            cal.sensor,
            value(cal, 0, 1e6, 1, "ppm"),
            value(cal, 1, 1e3, 4, "µm"),
            vector(p1).split_whitespace().collect::<Vec<_>>().join(", "),
            value(cal, 2, 1e6, 1, "µrad"),
            vector(p2).split_whitespace().collect::<Vec<_>>().join(", "),
            value(cal, 3, 1e6, 1, "µrad"),
            cal.fit.sigma.map_or("–".into(), |s| fixed(s * 1e3, 4)),
            fixed(s.gain, 7),
        );
    }
    out
}

/// The comment lines at the head of the calibrated description.
fn provenance(c: &Calibration, data: &str, described: &Instrument) -> Vec<String> {
    let mut lines = vec![
        format!(
            "calibrated by rtest {} from {data} ({} known displacements), described as {}",
            env!("CARGO_PKG_VERSION"),
            c.rows,
            described.name
        ),
        "(gain error relative, zero µm, tilts µrad about the axes given; standard uncertainties from the residual)".into(),
    ];
    for cal in &c.sensors {
        let parts: Vec<String> = PARAMETERS
            .iter()
            .enumerate()
            .map(|(j, name)| {
                let (scale, decimals, unit) = match j {
                    0 => (1.0, 9, ""),
                    1 => (1e3, 4, " µm"),
                    _ => (1e6, 1, " µrad"),
                };
                match cal.value(j) {
                    Some((v, s)) => format!(
                        "{name} {}{}{unit}",
                        fixed(v * scale, decimals),
                        s.map_or(String::new(), |s| format!(
                            " ± {}",
                            fixed(s * scale, decimals)
                        ))
                    ),
                    None => format!("{name} not determined (kept as described)"),
                }
            })
            .collect();
        lines.push(format!("{}: {}", cal.sensor, parts.join(", ")));
    }
    lines
}

fn run_calibrate(args: &CalibrateArgs) -> VerbResult<Done> {
    let described = super::args::instrument(&args.instrument, "--instrument")?;
    let mut inputs = vec![("--data", args.data.as_path())];
    let instrument_file = std::path::Path::new(&args.instrument);
    if preset(&args.instrument).is_none() {
        inputs.push(("--instrument", instrument_file));
    }
    check_outputs(&inputs, &[("-o", &args.output)], &[])?;
    let record = read_calibration_file(&args.data, &described, &ReadOptions::default())
        .map_err(|e| Error::input(format!("--data: {e}")))?;
    let data = args.data.display().to_string();
    let c = calibrate(&described, &record).map_err(|e| match e {
        e @ (CalibrationError::Record(_) | CalibrationError::Contact { .. }) => {
            Error::input(format!("--data: {e}"))
        }
        e => Error::computation(format!("--data {data}: {e}")),
    })?;
    let text = to_toml(&c.instrument, &provenance(&c, &data, &described));
    // What is written is what a later run reads: read it back with the same rules.
    let back = parse_instrument(&args.output.to_string(), &text).map_err(|e| {
        Error::computation(format!(
            "-o: the calibrated description does not read back, so it is not written: {e}"
        ))
    })?;
    if back != c.instrument {
        return Err(Error::computation(
            "-o: the calibrated description does not read back to the same values, so it is not written",
        ));
    }
    let mut files = Outputs::new();
    files.add("-o", args.output.clone(), text);
    let out = calibration_text(&c, &data);
    Ok(Done::new(out, files, matches!(args.output, Target::Stdout)))
}
