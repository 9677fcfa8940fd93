//! `rtest machines`: the built-in machines (or one given by name or file) described for people.

use super::{CliResult, EXIT_CODES};

/// Flags of `rtest machines`.
#[derive(Debug, clap::Args)]
#[command(
    about = "List the built-in machines: axes, kinematic symbols, errors and models",
    long_about = "\
Lists the built-in machines, or the one given with --machine: their axes (linear or rotary, \
direction, stroke in mm or range in degrees, the chain they are on), the kinematic chains from \
the bed to the workpiece (ball) and to the tool point (probe), the kinematic symbols with their \
default values in mm, the ISO 230 errors of their full model (translational errors in µm and \
angular errors in µrad wherever rtest shows values) and their sub-models.",
    after_help = EXIT_CODES
)]
pub struct MachinesArgs {
    /// Describe only this machine: a built-in name or the path of a machine TOML file.
    #[arg(long, value_name = "NAME|FILE")]
    machine: Option<String>,
}

/// Runs `rtest machines`.
pub fn run(args: &MachinesArgs) -> CliResult {
    let machines = match &args.machine {
        Some(name) => vec![super::load_machine(name)?],
        None => model_spec::all_builtin(),
    };
    let text: Vec<String> = machines
        .iter()
        .map(model_spec::describe::describe)
        .collect();
    super::print(&text.join("\n"))
}
