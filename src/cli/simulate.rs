//! `rtest simulate`: R-test readings of the exact virtual machine along a test path, written as
//! a measurement CSV.

use super::data;
use super::{CliError, CliResult, EXIT_CODES};
use solver::fitting::validate::statistics;
use solver::io::csv::{format_record, format_scaled, parse_scaled};
use solver::simulation::readings::{provenance, simulate};
use std::path::PathBuf;

const LONG_ABOUT: &str = "\
Simulates an R-test measurement: the exact virtual machine (exact homogeneous transforms, no \
linearisation; solver::simulation::readings) runs a test path with the errors of a truth, and the readings \
are written as a measurement CSV.

The path is K1 (C 0..360 deg in 1 deg steps, A = 0; 361 samples), K2 (A -90..30 deg, C = 0; 121 \
samples), K4 (C = 1.5·i deg, A = -45·(1 - cos C) deg, i = 0..240; 241 samples) of a machine \
whose rotary axes are A and C, or a path CSV file (rotary columns in degrees, linear columns in \
mm optional: they are filled by the nominal tool-centre-point inverse kinematics). The truth \
(docs/truth.md) says the real machine: error values (translational in µm, angular in µrad, \
constants or position-dependent), R-test zero offsets dx0 dy0 dz0 (µm), noise (µm) and its \
seed, zeroing at the first sample. Default truth: the machine's built-in demo truth if it has \
one (seed-ac-demo for seed-ac), else the nominal machine. --noise-um, --seed and --zeroed \
override the truth's.

The CSV (DESIGN.md) has a comment header saying what produced it, then the columns of the \
machine's axes (linear mm, rotary degrees), dx_um,dy_um,dz_um (tool minus workpiece, tool \
frame, µm) and t_s (s). It is written atomically. Prints one line: the samples and the RMS of \
the readings (µm).";

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
    /// Test path: K1, K2, K4 (machines with rotary axes A and C) or a path CSV file (rotary
    /// axes in degrees, linear axes in mm optional).
    #[arg(long, value_name = "K1|K2|K4|FILE")]
    path: String,
    /// Truth: a built-in name (seed-ac-demo, seed-ac-reduced, …) or a truth TOML file
    /// (docs/truth.md). Default: the machine's demo truth, else the nominal machine.
    #[arg(long, value_name = "NAME|FILE")]
    truth: Option<String>,
    /// Standard deviation of the Gaussian reading noise per direction, µm (overrides the
    /// truth's).
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    noise_um: Option<String>,
    /// Seed of the noise generator (overrides the truth's).
    #[arg(long, value_name = "N")]
    seed: Option<u64>,
    /// Zero the readings at the first sample, as R-test software does (overrides the truth).
    #[arg(long)]
    zeroed: bool,
    /// The measurement CSV to write (atomically).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: PathBuf,
}

/// Parses `--noise-um` (µm, finite, not negative) into mm, without double rounding.
fn noise_mm(text: &str) -> CliResult<f64> {
    let bad = |why: &str| CliError::usage(format!("--noise-um: `{text}` {why}"));
    let x: f64 = text
        .trim()
        .parse()
        .map_err(|_| bad("is not a number (µm)"))?;
    if !x.is_finite() || x < 0.0 {
        return Err(bad("must be a finite number ≥ 0 (µm)"));
    }
    parse_scaled(text, -3).ok_or_else(|| bad("is not a plain decimal number (µm)"))
}

/// Runs `rtest simulate`.
pub fn run(args: &SimulateArgs) -> CliResult {
    let m = super::load_machine(&args.machine)?;
    let noise = args.noise_um.as_deref().map(noise_mm).transpose()?;
    let mut truth = data::truth(&m, args.truth.as_deref())?;
    let path = data::path(&m, &args.path)?;
    if let Some(n) = noise {
        truth.noise_mm = n;
    }
    if let Some(s) = args.seed {
        truth.seed = s;
    }
    if args.zeroed {
        truth.zeroed = true;
    }
    let record =
        simulate(&m, &truth, &path).map_err(|e| CliError::failure(format!("--truth: {e}")))?;
    let n = record.samples.len();
    let comments = provenance(&m, &args.path, &truth, n);
    let text =
        format_record(&m, &record, &comments).map_err(|e| CliError::failure(format!("-o: {e}")))?;
    super::write_atomic("-o", &args.output, &text)?;
    let zeros = vec![[0.0; 3]; n];
    let (per, all) = statistics(&record.measured, &zeros);
    println!(
        "simulated {} on {} (truth {}, noise {} µm, seed {}, {}): {n} samples, RMS of the readings {} µm (x {}, y {}, z {}); wrote {}",
        args.path,
        m.name,
        truth.source,
        format_scaled(truth.noise_mm, 3),
        truth.seed,
        if truth.zeroed {
            "zeroed at the first sample"
        } else {
            "not zeroed"
        },
        short_um(all.measured_rms),
        short_um(per[0].measured_rms),
        short_um(per[1].measured_rms),
        short_um(per[2].measured_rms),
        args.output.display()
    );
    Ok(())
}

/// mm (not negative) as µm with three decimals.
fn short_um(mm: f64) -> String {
    format!("{:.3}", mm * 1e3)
}
