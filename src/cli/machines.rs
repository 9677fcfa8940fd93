//! `rtest machines`: the built-in machines (or one given by name or file) described for people.

use super::{CliResult, EXIT_CODES};
use model_spec::{AxisKind, Chain, Link, Machine, Side, Value};

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
    let text: Vec<String> = machines.iter().map(describe).collect();
    print!("{}", text.join("\n"));
    Ok(())
}

fn value(m: &Machine, v: &Value) -> String {
    match v {
        Value::Number(x) => super::short(*x),
        Value::Symbol(s) => m.symbols[*s].name.clone(),
    }
}

fn chain(m: &Machine, c: &Chain) -> String {
    let mut parts = vec!["bed".to_string()];
    for link in &c.links {
        parts.push(match link {
            Link::Axis(a) => m.axes[*a].name.clone(),
            Link::Fixed { name, .. } => name.clone(),
        });
    }
    parts.push(c.end_name.clone());
    parts.join(" -> ")
}

/// A machine for people, several lines.
pub fn describe(m: &Machine) -> String {
    let mut out = format!("{}: {}\n", m.name, m.description);
    out.push_str(&format!("  work chain: {}\n", chain(m, &m.work)));
    out.push_str(&format!("  tool chain: {}\n", chain(m, &m.tool)));
    out.push_str("  axes:\n");
    for a in &m.axes {
        let [lo, hi] = a.limits;
        let (kind, travel) = match a.kind {
            AxisKind::Linear => (
                "linear",
                format!("stroke {} .. {} mm", super::short(lo), super::short(hi)),
            ),
            AxisKind::Rotary if lo.is_finite() || hi.is_finite() => (
                "rotary",
                format!("range {} .. {} deg", super::short(lo), super::short(hi)),
            ),
            AxisKind::Rotary => ("rotary", "range unlimited".to_string()),
        };
        let side = match a.side {
            Side::Work => "work",
            Side::Tool => "tool",
        };
        let offset: Vec<String> = a.offset.iter().map(|v| value(m, v)).collect();
        out.push_str(&format!(
            "    {:<3} {kind:<6}  direction {}  {travel:<26}  {side} chain, offset [{}] mm\n",
            a.name,
            a.direction,
            offset.join(", ")
        ));
    }
    if m.symbols.is_empty() {
        out.push_str("  kinematic symbols: none\n");
    } else {
        let symbols: Vec<String> = m
            .symbols
            .iter()
            .map(|s| format!("{} = {}", s.name, super::short(s.default)))
            .collect();
        out.push_str(&format!(
            "  kinematic symbols (defaults, mm): {}\n",
            symbols.join(", ")
        ));
    }
    let names = |ids: &[usize]| {
        ids.iter()
            .map(|&e| m.catalogue[e].name.as_str())
            .collect::<Vec<_>>()
            .join(" ")
    };
    out.push_str(&format!(
        "  errors ({} of the {} of its topology; translational in µm, angular in µrad): {}\n",
        m.errors.len(),
        m.catalogue.len(),
        names(&m.errors)
    ));
    out.push_str("  models:\n");
    out.push_str(&format!(
        "    {} ({} errors): every error of the machine's model\n",
        model_spec::FULL_MODEL,
        m.errors.len()
    ));
    for (name, sub) in &m.models {
        out.push_str(&format!(
            "    {name} ({} errors): {}\n      {}\n",
            sub.errors.len(),
            sub.description,
            names(&sub.errors)
        ));
    }
    out
}
