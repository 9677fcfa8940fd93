//! A machine described for people: its chains, axes, kinematic symbols, errors and models, as
//! `rtest machines` prints them.
//!
//! ```text
//! seed-ac: Five-axis machine of the seed paper: …
//!   work chain: bed -> X -> A -> C -> ball
//!   tool chain: bed -> Y -> Z -> holder -> probe
//!   axes:
//!     X   linear  direction +x  stroke -500 .. 500 mm       work chain, offset [0, 0, 0] mm
//!     A   rotary  direction +x  range -120 .. 120 deg       work chain, offset [Xa, Ya, Za] mm
//!     C   rotary  direction +z  range unlimited             work chain, offset [0, 0, Zc] mm
//!   …
//! ```
//!
//! Numbers are written with [`crate::units::short`]: lengths in mm, rotary ranges in degrees.

use crate::machine::{AxisKind, Chain, FULL_MODEL, Link, Machine, Side, Value};
use crate::units::short;

/// An offset coordinate: its number (mm) or its symbol's name.
fn value(m: &Machine, v: &Value) -> String {
    match v {
        Value::Number(x) => short(*x),
        Value::Symbol(s) => m.symbols[*s].name.clone(),
    }
}

/// `bed -> X -> A -> C -> ball`.
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

/// The machine `m` for people, several lines, each ending with a newline: name and
/// description, the two chains, one line per axis (type, direction, stroke in mm or range in
/// degrees, chain, offset in mm), the kinematic symbols with their defaults (mm), the errors
/// of the full model and the models with their errors.
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
                format!("stroke {} .. {} mm", short(lo), short(hi)),
            ),
            AxisKind::Rotary if lo.is_finite() || hi.is_finite() => (
                "rotary",
                format!("range {} .. {} deg", short(lo), short(hi)),
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
            .map(|s| format!("{} = {}", s.name, short(s.default)))
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
        "    {FULL_MODEL} ({} errors): every error of the machine's model\n",
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
