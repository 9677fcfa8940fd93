//! `rtest`: geometric error models of machine tools from R-test measurements.
//!
//! A thin command line: every verb parses its flags, calls the libraries (`model-spec`,
//! `codegen`, the numeric crates, `plots`, `output`, `perf`) and prints. Verbs live in [`cli`], one
//! module each.

mod cli;

use clap::{Parser, Subcommand};
use cli::{CliError, EXIT_CODES, EXIT_USAGE};
use std::io::Write as _;
use std::process::ExitCode;

/// Geometric error models of five-axis (and three-axis) machine tools from R-test measurements.
#[derive(Debug, Parser)]
#[command(
    name = "rtest",
    version,
    about = "Geometric error models of machine tools from R-test measurements",
    long_about = "\
Geometric error models of machine tools from R-test measurements: the ISO 230 error catalogue of \
a machine topology, its error-gain functions, no_std Rust code for controllers, simulated R-test \
measurements on the exact virtual machine, identification of the errors with uncertainties and \
what the data cannot separate, and validation on other test paths. Units at \
every boundary: positions in mm, rotary positions in degrees, translational errors in µm, angular \
errors in µrad; gains in mm/mm (translational errors) and mm/rad (angular errors). A machine is a \
built-in name (see `rtest machines`) or the path of a TOML description (docs/model-spec.md).",
    after_help = EXIT_CODES
)]
struct Cli {
    #[command(subcommand)]
    verb: Verb,
}

#[derive(Debug, Subcommand)]
enum Verb {
    Machines(cli::machines::MachinesArgs),
    Gains(cli::gains::GainsArgs),
    Generate(cli::generate::GenerateArgs),
    Simulate(cli::simulate::SimulateArgs),
    Identify(cli::identify::IdentifyArgs),
    Validate(cli::validate::ValidateArgs),
    Demo(cli::demo::DemoArgs),
    Bench(cli::bench::BenchArgs),
    Diagnose(cli::diagnose::DiagnoseArgs),
    Compensate(cli::compensate::CompensateArgs),
    Volumetric(cli::volumetric::VolumetricArgs),
    Path(cli::path::PathArgs),
    Instrument(cli::instrument::InstrumentVerb),
    Segment(cli::segment::SegmentArgs),
    Plan(cli::plan::PlanArgs),
    History(cli::history::HistoryArgs),
    Report(cli::report::ReportArgs),
}

/// The verbs, for the hint of a usage error.
const VERBS: [&str; 17] = [
    "machines",
    "gains",
    "generate",
    "simulate",
    "identify",
    "validate",
    "diagnose",
    "demo",
    "bench",
    "compensate",
    "volumetric",
    "path",
    "instrument",
    "segment",
    "plan",
    "history",
    "report",
];

/// A clap error as one line: its message and its hints, without the usage block.
fn one_line(e: &clap::Error) -> String {
    let rendered = e.render().to_string();
    let parts: Vec<&str> = rendered
        .lines()
        .map(str::trim)
        .filter(|l| {
            !l.is_empty() && !l.starts_with("Usage:") && !l.starts_with("For more information")
        })
        .collect();
    let text = parts.join(" ");
    text.strip_prefix("error: ").unwrap_or(&text).to_string()
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            // --help, --version
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) if e.kind() == clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            // `rtest` alone: the help, on stderr, as a usage error.
            let _ = e.print();
            return ExitCode::from(EXIT_USAGE);
        }
        Err(e) => {
            let verb = std::env::args().nth(1).filter(|a| !a.starts_with('-'));
            let help = match verb {
                Some(v) if VERBS.contains(&v.as_str()) => {
                    format!("rtest {v} --help")
                }
                _ => "rtest --help".into(),
            };
            report(&CliError {
                code: EXIT_USAGE,
                message: format!("{} (see `{help}`)", one_line(&e)),
            });
            return ExitCode::from(EXIT_USAGE);
        }
    };
    let result = match &cli.verb {
        Verb::Machines(a) => cli::machines::run(a),
        Verb::Gains(a) => cli::gains::run(a),
        Verb::Generate(a) => cli::generate::run(a),
        Verb::Simulate(a) => cli::simulate::run(a),
        Verb::Identify(a) => cli::identify::run(a),
        Verb::Validate(a) => cli::validate::run(a),
        Verb::Demo(a) => cli::demo::run(a),
        Verb::Bench(a) => cli::bench::run(a),
        Verb::Diagnose(a) => cli::diagnose::run(a),
        Verb::Compensate(a) => cli::compensate::run(a),
        Verb::Volumetric(a) => cli::volumetric::run(a),
        Verb::Path(a) => cli::path::run(a),
        Verb::Instrument(a) => cli::instrument::run(a),
        Verb::Segment(a) => cli::segment::run(a),
        Verb::Plan(a) => cli::plan::run(a),
        Verb::History(a) => cli::history::run(a),
        Verb::Report(a) => cli::report::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            report(&e);
            ExitCode::from(e.code)
        }
    }
}

fn report(e: &CliError) {
    let message = e.message.lines().collect::<Vec<_>>().join(" ");
    let _ = writeln!(std::io::stderr(), "rtest: error: {message}");
}
