//! Gain tables for people, laid out like the seed's Table 1: one row per error, grouped by axis,
//! columns ΔX ΔY ΔZ (position) and ΔI ΔJ ΔK (orientation), as plain text, Markdown or LaTeX.
//!
//! A table writes the expanded canonical polynomials ([`crate::derive::Gains::expanded`]),
//! whose size doubles with every rotary axis a gain spans: a few kilobytes for a five-axis
//! machine, half a megabyte for a chain of six rotary axes, 39 MB and 0.4 s for ten, 157 MB and
//! 2 s for twelve (`docs/codegen.md`, long chains). The generated code never expands.

use crate::GainModel;
use crate::poly::Poly;
use crate::rational::Rational;
use model_spec::{ErrorKind, Machine};

/// Output format of a table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Aligned plain text.
    Text,
    /// A Markdown table.
    Markdown,
    /// A LaTeX `longtable`.
    Latex,
}

/// Writes a polynomial in the seed's style (`Za + Ca*Zc + Sa*Sc*Xw`), or LaTeX
/// (`Z_{a} + C_a Z_{c}`) with `latex`. `names` are the names of the atoms; an atom past them is
/// a named intermediate of the shared form, written `u0`, `u1`, … (`u_{0}` in LaTeX).
pub fn format_poly(p: &Poly, names: &[String], latex: bool) -> String {
    if p.is_zero() {
        return "0".into();
    }
    let mut out = String::new();
    for (i, (m, c)) in p.terms().enumerate() {
        let negative = c.is_negative();
        let c = c.abs();
        match (i, negative) {
            (0, true) => out.push('-'),
            (0, false) => {}
            (_, true) => out.push_str(" - "),
            (_, false) => out.push_str(" + "),
        }
        let mut factors: Vec<String> = Vec::new();
        if !c.is_one() || m.is_one() {
            factors.push(if latex {
                latex_rational(c)
            } else {
                c.to_string()
            });
        }
        for &(a, e) in m.factors() {
            let n = match names.get(usize::from(a)) {
                Some(n) => n.clone(),
                None if latex => format!("u_{{{}}}", usize::from(a) - names.len()),
                None => format!("u{}", usize::from(a) - names.len()),
            };
            factors.push(match (e, latex) {
                (1, _) => n,
                (_, false) => format!("{n}^{e}"),
                (_, true) => format!("{n}^{{{e}}}"),
            });
        }
        out.push_str(&factors.join(if latex { " " } else { "*" }));
    }
    out
}

fn latex_rational(c: Rational) -> String {
    let s = c.to_string();
    match s.split_once('/') {
        Some((n, d)) => format!("\\frac{{{n}}}{{{d}}}"),
        None => s,
    }
}

/// The group label of an error, the seed's way: the axis letter for component and location
/// errors, `squareness` and `set-up` for the others.
pub fn group(m: &Machine, error: usize) -> String {
    match m.catalogue[error].kind {
        ErrorKind::Component { axis, .. } | ErrorKind::Location { axis, .. } => {
            m.axes[axis].name.clone()
        }
        ErrorKind::Squareness { .. } => "squareness".into(),
        ErrorKind::Setup { .. } => "set-up".into(),
    }
}

const HEADERS: [&str; 6] = ["ΔX", "ΔY", "ΔZ", "ΔI", "ΔJ", "ΔK"];
const LATEX_HEADERS: [&str; 6] = [
    "\\Delta X",
    "\\Delta Y",
    "\\Delta Z",
    "\\Delta I",
    "\\Delta J",
    "\\Delta K",
];

/// Renders the gain table of `model` (derived from `m`) under the title `title`, expanding the
/// model's gains first if it has intermediates (see the module documentation for the cost).
pub fn render(m: &Machine, model: &GainModel, title: &str, format: Format) -> String {
    let latex = format == Format::Latex;
    let names = if latex {
        &model.atoms.latex
    } else {
        &model.atoms.names
    };
    let rows: Vec<(String, String, Vec<String>)> = model
        .errors
        .iter()
        .zip(&model.gains)
        .map(|(&e, g)| {
            (
                group(m, e),
                m.catalogue[e].name.clone(),
                g.iter().map(|p| format_poly(p, names, latex)).collect(),
            )
        })
        .collect();
    let legend = legend(m);
    match format {
        Format::Text => text(title, &rows, &legend),
        Format::Markdown => markdown(title, &rows, &legend),
        Format::Latex => latex_table(title, &rows),
    }
}

fn legend(m: &Machine) -> String {
    let rotary: Vec<String> = m
        .rotary_axes()
        .map(|a| {
            let l = m.axes[a].name.to_ascii_lowercase();
            format!("S{l}, C{l} = sin, cos of the {} command", m.axes[a].name)
        })
        .collect();
    let linear: Vec<String> = m
        .linear_axes()
        .map(|a| format!("{}m", m.axes[a].name))
        .collect();
    let mut s = String::from(
        "Error vector = tool point minus workpiece point, in the tool frame (first order).\n\
         ΔX ΔY ΔZ: mm per mm of a translational error, mm per rad of an angular error.\n\
         ΔI ΔJ ΔK: change of the tool z axis minus change of the workpiece z axis (seed eqs. 14-16), per mm or per rad.\n",
    );
    if !rotary.is_empty() {
        s.push_str(&rotary.join("; "));
        s.push_str(".\n");
    }
    if !linear.is_empty() {
        s.push_str(&format!("{}: linear commands, mm. ", linear.join(", ")));
    }
    let symbols: Vec<&str> = m.symbols.iter().map(|s| s.name.as_str()).collect();
    if !symbols.is_empty() {
        s.push_str(&format!(
            "Kinematic parameters (mm): {}.",
            symbols.join(" ")
        ));
    }
    s.push('\n');
    s
}

/// `c` padded with spaces to `width` characters. By hand: the width of `format!` is limited to
/// 65 535, and a cell of a long chain's expanded table is longer.
fn pad(c: &str, width: usize) -> String {
    let mut s = String::with_capacity(width.max(c.len()));
    s.push_str(c);
    s.extend(std::iter::repeat_n(
        ' ',
        width.saturating_sub(c.chars().count()),
    ));
    s
}

fn text(title: &str, rows: &[(String, String, Vec<String>)], legend: &str) -> String {
    let mut widths = [0usize; 8];
    let header: Vec<String> = ["group", "error"]
        .iter()
        .map(|s| s.to_string())
        .chain(HEADERS.iter().map(|s| s.to_string()))
        .collect();
    let all: Vec<Vec<String>> = std::iter::once(header)
        .chain(rows.iter().map(|(g, e, cells)| {
            [g.clone(), e.clone()]
                .into_iter()
                .chain(cells.iter().cloned())
                .collect()
        }))
        .collect();
    for r in &all {
        for (w, c) in widths.iter_mut().zip(r) {
            *w = (*w).max(c.chars().count());
        }
    }
    let mut out = format!("{title}\n{legend}\n");
    for (i, r) in all.iter().enumerate() {
        let line: Vec<String> = r.iter().zip(&widths).map(|(c, w)| pad(c, *w)).collect();
        out.push_str(line.join("  ").trim_end());
        out.push('\n');
        if i == 0 {
            out.push_str(
                &widths
                    .iter()
                    .map(|w| "-".repeat(*w))
                    .collect::<Vec<_>>()
                    .join("  "),
            );
            out.push('\n');
        }
    }
    out
}

fn markdown(title: &str, rows: &[(String, String, Vec<String>)], legend: &str) -> String {
    let mut out = format!(
        "### {title}\n\n{}\n",
        legend
            .lines()
            .map(|l| format!("{l}  \n"))
            .collect::<String>()
    );
    out.push_str(&format!("| group | error | {} |\n", HEADERS.join(" | ")));
    out.push_str(&format!("|{}\n", "---|".repeat(8)));
    let mut last_group = String::new();
    for (g, e, cells) in rows {
        let shown = if *g == last_group {
            String::new()
        } else {
            g.clone()
        };
        last_group = g.clone();
        let cells: Vec<String> = cells
            .iter()
            .map(|c| {
                if c == "0" {
                    "0".into()
                } else {
                    format!("`{c}`")
                }
            })
            .collect();
        out.push_str(&format!("| {shown} | {e} | {} |\n", cells.join(" | ")));
    }
    out
}

fn latex_table(title: &str, rows: &[(String, String, Vec<String>)]) -> String {
    let mut out =
        String::from("% requires \\usepackage{longtable}\n\\begin{longtable}{llllllll}\n");
    out.push_str(&format!(
        "\\caption{{{}}}\\\\\n\\hline\n",
        title.replace('_', "\\_")
    ));
    out.push_str(&format!(
        "group & error & {} \\\\\n\\hline\n\\endhead\n",
        LATEX_HEADERS
            .iter()
            .map(|h| format!("${h}$"))
            .collect::<Vec<_>>()
            .join(" & ")
    ));
    let mut last_group = String::new();
    for (g, e, cells) in rows {
        let shown = if *g == last_group {
            String::new()
        } else {
            g.clone()
        };
        if !last_group.is_empty() && *g != last_group {
            out.push_str("\\hline\n");
        }
        last_group = g.clone();
        let cells: Vec<String> = cells.iter().map(|c| format!("${c}$")).collect();
        out.push_str(&format!(
            "{shown} & $\\mathrm{{{e}}}$ & {} \\\\\n",
            cells.join(" & ")
        ));
    }
    out.push_str("\\hline\n\\end{longtable}\n");
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn cells_pad_beyond_the_width_limit_of_format() {
        assert_eq!(super::pad("ΔX", 4), "ΔX  ");
        assert_eq!(super::pad("long", 2), "long");
        assert_eq!(super::pad("a", 70_000).len(), 70_000);
    }
}
