//! `rtest machines`: the built-in machines (or one given by name or file) described for people:
//! first one line per machine (its family, its axes and its description), then each machine in
//! full.

use super::{EXIT_CODES, VerbResult};
use crate::Done;
use model_spec::{AxisKind, Machine, Side};

/// Flags of `rtest machines`.
#[derive(Debug, clap::Args)]
#[command(
    about = "List the built-in machines: family, axes, kinematic symbols, errors and models",
    long_about = "\
Lists the built-in machines, or the one given with --machine: first one line per machine (its \
name, its family: three-axis, rotary table, swivel head, table-table, head-head or head-table, \
with its rotary axes from the bed outwards and any inclined axis; its axes; its description), \
then each machine in full: its axes (linear or rotary, direction, stroke in mm or range in \
degrees, the chain they are on), the kinematic chains from the bed to the workpiece (ball) and \
to the tool point (probe), the kinematic symbols with their default values in mm, the ISO 230 \
errors of their full model (translational errors in µm and angular errors in µrad wherever \
rtest shows values) and their sub-models. An inclined axis shows its direction vector; its \
errors are named in its own frame (docs/conventions.md).",
    after_help = EXIT_CODES
)]
pub struct MachinesArgs {
    /// Describe only this machine: a built-in name or the path of a machine TOML file.
    #[arg(long, value_name = "NAME|FILE")]
    machine: Option<String>,
}

/// Runs `rtest machines`.
pub fn run(args: &MachinesArgs) -> VerbResult<Done> {
    let machines = match &args.machine {
        Some(name) => vec![super::load_machine(name)?],
        None => model_spec::all_builtin(),
    };
    let mut text = overview(&machines);
    text.push('\n');
    let details: Vec<String> = machines
        .iter()
        .map(model_spec::describe::describe)
        .collect();
    text.push_str(&details.join("\n"));
    Ok(Done::text(text))
}

/// One line per machine, aligned: name, family, axes, description.
pub fn overview(machines: &[Machine]) -> String {
    let rows: Vec<[String; 4]> = machines
        .iter()
        .map(|m| {
            let letters: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
            [
                m.name.clone(),
                family(m),
                format!("{} axes: {}", letters.len(), letters.join(" ")),
                m.description.clone(),
            ]
        })
        .collect();
    let width = |k: usize| rows.iter().map(|r| r[k].chars().count()).max().unwrap_or(0);
    let (w0, w1, w2) = (width(0), width(1), width(2));
    let mut out = String::new();
    for r in &rows {
        out.push_str(&format!(
            "{:<w0$}  {:<w1$}  {:<w2$}  {}\n",
            r[0], r[1], r[2], r[3]
        ));
    }
    out
}

/// The machine's family from its topology: where its rotary axes are (the work side carries
/// tables, the tool side heads) and their letters from the bed outwards, head first: `three-axis`
/// (no rotary axis), `rotary table B`, `swivel head B`, `table-table B/C`, `head-head C/A`,
/// `head-table B/C`; inclined rotary axes are named after it (`nutating head-table B/C: B
/// inclined [0, 1, 1]`).
pub fn family(m: &Machine) -> String {
    let rotary = |side: Side| -> Vec<usize> {
        let chain = match side {
            Side::Work => &m.work,
            Side::Tool => &m.tool,
        };
        chain
            .axes()
            .filter(|&a| m.axes[a].kind == AxisKind::Rotary)
            .collect()
    };
    let (tables, heads) = (rotary(Side::Work), rotary(Side::Tool));
    let kind = match (heads.len(), tables.len()) {
        (0, 0) => {
            let n = m.axes.len();
            return if n == 3 {
                "three-axis".to_string()
            } else {
                format!("{n} linear axes")
            };
        }
        (0, 1) => "rotary table",
        (1, 0) => "swivel head",
        (0, _) => "table-table",
        (_, 0) => "head-head",
        _ => "head-table",
    };
    let all: Vec<usize> = heads.iter().chain(&tables).copied().collect();
    let letters: Vec<&str> = all.iter().map(|&a| m.axes[a].name.as_str()).collect();
    let inclined: Vec<String> = all
        .iter()
        .filter(|&&a| m.axes[a].direction.inclined.is_some())
        .map(|&a| format!("{} inclined {}", m.axes[a].name, m.axes[a].direction))
        .collect();
    if inclined.is_empty() {
        format!("{kind} {}", letters.join("/"))
    } else {
        format!(
            "nutating {kind} {}: {}",
            letters.join("/"),
            inclined.join(", ")
        )
    }
}
