//! `rtest`: geometric error models of machine tools from R-test measurements.
//!
//! A thin command line: clap parses the flags into a verb's options, the verb's function in
//! the `app` crate does the work, and this file prints its text or its one-line error and
//! exits with the code of the error's class.

use app::error::{EXIT_CODES, EXIT_USAGE};
use app::verbs as cli;
use clap::{Parser, Subcommand};
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
    ProbeLog(cli::probe_log::ProbeLogArgs),
    Plan(cli::plan::PlanArgs),
    History(cli::history::HistoryArgs),
    Report(cli::report::ReportArgs),
}

/// The verbs, for the hint of a usage error.
const VERBS: [&str; 18] = [
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
    "probe-log",
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
            report(&app::Error::usage(format!(
                "{} (see `{help}`)",
                one_line(&e)
            )));
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
        Verb::ProbeLog(a) => cli::probe_log::run(a),
        Verb::Plan(a) => cli::plan::run(a),
        Verb::History(a) => cli::history::run(a),
        Verb::Report(a) => cli::report::run(a),
    };
    match result
        .and_then(app::Done::finish)
        .and_then(|shown| print(&shown))
    {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            report(&e);
            ExitCode::from(e.exit_code())
        }
    }
}

fn report(e: &app::Error) {
    let message = e.message.lines().collect::<Vec<_>>().join(" ");
    let _ = writeln!(std::io::stderr(), "rtest: error: {message}");
}

/// Prints what a verb has done: its notes on standard error, its text on standard output. A
/// stream that cannot be written (a closed pipe) is an output that cannot be written: exit
/// code 1, never a panic.
fn print(shown: &app::Shown) -> Result<(), app::Error> {
    let failed =
        |name: &str, e: std::io::Error| app::Error::input(format!("cannot write to {name}: {e}"));
    if !shown.stderr.is_empty() {
        std::io::stderr()
            .lock()
            .write_all(shown.stderr.as_bytes())
            .map_err(|e| failed("standard error", e))?;
    }
    let mut out = std::io::stdout().lock();
    out.write_all(shown.stdout.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|e| failed("standard output", e))
}
