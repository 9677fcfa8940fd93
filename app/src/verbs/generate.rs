//! `rtest generate`: standalone `no_std` Rust code for a machine's gains, as one file or as a
//! ready crate (`--crate DIR`).

use codegen::build::crate_files;

use super::{EXIT_CODES, Error, VerbResult, args, check_outputs};
use crate::Done;
use model_spec::Machine;
use output::{Outputs, Target};
use std::path::{Path, PathBuf};

const LONG_ABOUT: &str = "\
Generates a standalone Rust source file with the error-gain functions of a machine: \
straight-line, allocation-free, no_std-compatible code (only + - *; the sines and cosines of the \
rotary commands are inputs). It holds `Pose` (sin/cos of rotary commands, linear commands in mm), \
`Params` (kinematic parameters in mm, defaulting to the machine description) and one module per \
model whose `pub fn gains(pose, params, out)` writes [gx, gy, gz, gi, gj, gk] per error: tool \
point minus workpiece point in the tool frame, mm per mm of a translational error and mm per rad \
of an angular error, valid where the nominal tool point is on the workpiece point (every R-test \
pose). Errors themselves are in mm and rad inside the code (µm and µrad for people). The file \
has no crate attributes, so it can be `include!`d or used as a module (docs/codegen.md). \
With --crate DIR, writes a ready no_std crate instead: Cargo.toml (its own workspace, no \
dependencies), src/lib.rs (the code, with crate documentation on the machine, its models, the \
units and how to call it), README.md and machine.toml (the description it was generated from). \
DIR must not exist or be empty; the files are written all or none.";

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
    /// Write a ready no_std crate into DIR (created if missing; refused if not empty):
    /// Cargo.toml, src/lib.rs, README.md and the machine description as machine.toml.
    #[arg(long = "crate", value_name = "DIR", conflicts_with = "output")]
    crate_dir: Option<PathBuf>,
}

/// Runs `rtest generate`.
pub fn run(args: &GenerateArgs) -> VerbResult<Done> {
    let (m, text) = super::load_machine_and_text(&args.machine)?;
    for (i, name) in args.model.iter().enumerate() {
        args::model_errors(&m, name)?;
        if args.model[..i].contains(name) {
            return Err(Error::usage(format!("--model: `{name}` is given twice")));
        }
    }
    let inputs: Vec<_> = super::machine_file(&args.machine)
        .map(|p| ("--machine", p))
        .into_iter()
        .collect();
    let models: Vec<&str> = args.model.iter().map(String::as_str).collect();
    match &args.crate_dir {
        Some(dir) => {
            // An input among the files the crate would hold is named as such (a usage error)
            // before the directory is refused as not empty.
            let files: Vec<Target> = crate_files::NAMES
                .iter()
                .map(|name| Target::Path(dir.join(name)))
                .collect();
            let named: Vec<(&str, &Target)> = files.iter().map(|t| ("--crate", t)).collect();
            output::refuse_overwriting_inputs(&inputs, &named).map_err(super::write_error)?;
            refuse_non_empty(dir)?;
            check_outputs(&inputs, &[], &[("--crate", dir)])?;
            let code = generate(&m, &models)?;
            let files = crate_files::files(&m, &text, &models, &code);
            let mut outputs = Outputs::new();
            for (relative, contents) in files {
                let (place, name) = match relative.rsplit_once('/') {
                    Some((sub, name)) => (dir.join(sub), name),
                    None => (dir.clone(), relative),
                };
                outputs.add_in_dir("--crate", place, name, contents);
            }
            let built = crate_files::package_name(&m.name);
            Ok(Done::new("", outputs, false).then(format!(
                "Crate `{built}` of machine `{}` in `{}`: `cargo build --release` there, or a \
                 path dependency of your crate.\n",
                m.name,
                dir.display()
            )))
        }
        None => {
            let target = args.output.clone().unwrap_or(Target::Stdout);
            check_outputs(&inputs, &[("-o", &target)], &[])?;
            let code = generate(&m, &models)?;
            let mut files = Outputs::new();
            files.add("-o", target.clone(), code);
            // The code may be on standard output: what was written is said on standard error.
            Ok(Done::new("", files, true))
        }
    }
}

/// The code of the models `models` of `m` (every model when empty).
fn generate(m: &Machine, models: &[&str]) -> VerbResult<String> {
    codegen::emit::generate_machine(m, models)
        .map_err(|e| Error::computation(format!("generate: machine {}: {e}", m.name)))
}

/// Refuses a crate directory that exists and is not an empty directory: a crate is written
/// whole into a place of its own, never over or among other files.
fn refuse_non_empty(dir: &Path) -> VerbResult {
    let shown = dir.display();
    match std::fs::metadata(dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotADirectory => Err(Error::input(format!(
            "--crate: `{shown}`: a directory above it is a file"
        ))),
        Err(e) => Err(Error::input(format!("--crate: cannot read `{shown}`: {e}"))),
        Ok(meta) if !meta.is_dir() => Err(Error::input(format!(
            "--crate: `{shown}` exists and is not a directory"
        ))),
        Ok(_) => {
            let mut entries = std::fs::read_dir(dir)
                .map_err(|e| Error::input(format!("--crate: cannot read `{shown}`: {e}")))?;
            match entries.next() {
                None => Ok(()),
                Some(entry) => {
                    let first = entry
                        .map(|e| format!(" (it holds `{}`)", e.file_name().to_string_lossy()))
                        .unwrap_or_default();
                    Err(Error::input(format!(
                        "--crate: `{shown}` exists and is not empty{first}: give a new or empty \
                         directory"
                    )))
                }
            }
        }
    }
}
