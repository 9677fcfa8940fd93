//! `rtest generate`: standalone `no_std` Rust code for a machine's gains.

use super::{CliError, CliResult, EXIT_CODES, args, check_outputs, write};
use output::{Outputs, Target};

const LONG_ABOUT: &str = "\
Generates a standalone Rust source file with the error-gain functions of a machine: \
straight-line, allocation-free, no_std-compatible code (only + - *; the sines and cosines of the \
rotary commands are inputs). It holds `Pose` (sin/cos of rotary commands, linear commands in mm), \
`Params` (kinematic parameters in mm, defaulting to the machine description) and one module per \
model whose `pub fn gains(pose, params, out)` writes [gx, gy, gz, gi, gj, gk] per error: tool \
point minus workpiece point in the tool frame, mm per mm of a translational error and mm per rad \
of an angular error, valid where the nominal tool point is on the workpiece point (every R-test \
pose). Errors themselves are in mm and rad inside the code (µm and µrad for people). The file \
has no crate attributes, so it can be `include!`d or used as a module (docs/codegen.md).";

/// Flags of `rtest generate`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Generate no_std Rust code for a machine's error gains",
    long_about = LONG_ABOUT,
    after_help = EXIT_CODES
)]
pub struct GenerateArgs {
    /// Built-in machine (see `rtest machines`) or path of a machine TOML file.
    #[arg(long, value_name = "NAME|FILE")]
    machine: String,
    /// Model to generate (`full`, `reduced`, …); repeat for several. Default: every model of
    /// the machine.
    #[arg(long, value_name = "NAME")]
    model: Vec<String>,
    /// Write the code to FILE instead of standard output.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Option<Target>,
}

/// Runs `rtest generate`.
pub fn run(args: &GenerateArgs) -> CliResult {
    let m = super::load_machine(&args.machine)?;
    for (i, name) in args.model.iter().enumerate() {
        args::model_errors(&m, name)?;
        if args.model[..i].contains(name) {
            return Err(CliError::usage(format!("--model: `{name}` is given twice")));
        }
    }
    let target = args.output.clone().unwrap_or(Target::Stdout);
    let inputs: Vec<_> = super::machine_file(&args.machine)
        .map(|p| ("--machine", p))
        .into_iter()
        .collect();
    check_outputs(&inputs, &[("-o", &target)], &[])?;
    let models: Vec<&str> = args.model.iter().map(String::as_str).collect();
    let code = codegen::emit::generate_machine(&m, &models)
        .map_err(|e| CliError::computation(format!("generate: machine {}: {e}", m.name)))?;
    let mut files = Outputs::new();
    files.add("-o", target.clone(), code);
    // The code may be on standard output: what was written is said on standard error.
    super::print_text(&super::wrote(&write(files)?), true)
}
