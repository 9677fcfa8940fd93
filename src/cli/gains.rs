//! `rtest gains`: the error-gain functions of a machine's model, as a symbolic table or as
//! numbers at one pose.

use super::json::Json;
use super::pose::{self, Pose};
use super::{CliResult, Compiled, EXIT_CODES, Format};
use codegen::GainModel;
use codegen::atoms::AtomKind;
use codegen::table::{format_poly, render};
use model_spec::Machine;

const ABOUT: &str = "Error-gain functions of a machine (the seed's Tables 1 and 2)";

const LONG_ABOUT: &str = "\
Error-gain functions of a machine (the seed's Tables 1 and 2): how each error of the model moves \
the tool point relative to the workpiece point, to first order, in the tool frame.

Without --at: the symbolic table, one row per error, columns ΔX ΔY ΔZ (position: mm per mm of a \
translational error, mm per rad of an angular error) and ΔI ΔJ ΔK (orientation of the tool z axis, \
per mm or per rad), written in Sa/Ca (sine/cosine of rotary axis A's command), Xm (linear \
command of X, mm) and the kinematic symbols (mm).

With --at: the numbers at that pose: for every error [gx, gy, gz], tool frame, mm/mm for \
translational errors and mm/rad for angular errors (1 mm/rad = 1 µm of error vector per mrad; an \
error of e µm moves the tool point by g·e µm, an error of e µrad by g·e nm). Axis positions in mm \
and degrees, kinematic parameters in mm (defaults from the machine description, overridden by \
--param). Every rotary axis must be given; linear axes left out of --at are filled by the \
machine's nominal tool-centre-point inverse kinematics (solver::simulation::tool_centre_point_ik: the linear \
positions that put the tool point on the workpiece point at the given rotary positions).

JSON without --at: {\"machine\", \"model\" (null with --errors), \"units\", \"columns\", \
\"atoms\": {name: meaning}, \"gains\": {error: [6 formulas]}}. JSON with --at: {error: [gx, gy, gz]}, \
errors in model order.";

/// Flags of `rtest gains`.
#[derive(Debug, clap::Args)]
#[command(about = ABOUT, long_about = LONG_ABOUT, after_help = EXIT_CODES)]
pub struct GainsArgs {
    /// Built-in machine (see `rtest machines`) or path of a machine TOML file.
    #[arg(long, value_name = "NAME|FILE")]
    machine: String,
    /// Model of the machine: `full` (every error of its model, the default) or a sub-model
    /// (`reduced`, …).
    #[arg(long, value_name = "NAME", conflicts_with = "errors")]
    model: Option<String>,
    /// Explicit errors instead of a model: comma list of ISO 230 names in the order wanted
    /// (`XOC,YOC,BOA`; the digit-zero spelling `X0C` is accepted).
    #[arg(long, value_name = "LIST")]
    errors: Option<String>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    format: Format,
    /// Evaluate at this pose: axis positions, linear in mm, rotary in degrees
    /// (`X=0,Y=0,Z=0,A=30,C=45`). Every rotary axis is required; missing linear axes come
    /// from the nominal tool-centre-point inverse kinematics.
    #[arg(long, value_name = "AXIS=VALUE,...")]
    at: Option<String>,
    /// Kinematic parameters (mm) overriding the machine's defaults (`Xw=-217.504,Zc=29.794`);
    /// only with --at.
    #[arg(long, value_name = "SYMBOL=VALUE,...", requires = "at")]
    param: Option<String>,
}

/// Runs `rtest gains`.
pub fn run(args: &GainsArgs) -> CliResult {
    let m = super::load_machine(&args.machine)?;
    let (model_name, errors) =
        super::select_errors(&m, args.model.as_deref(), args.errors.as_deref())?;
    let pose = match &args.at {
        Some(at) => {
            let params = pose::parse_params(&m, args.param.as_deref())?;
            Some(pose::parse_at(&m, at, params)?)
        }
        None => None,
    };
    let title = title(&m, model_name.as_deref(), errors.len());
    let out = match pose {
        None => {
            let model = GainModel::derive(&m, &errors);
            match args.format.table() {
                Some(f) => render(&m, &model, &title, f),
                None => symbolic_json(&m, model_name.as_deref(), &model).render(),
            }
        }
        Some(pose) => {
            let compiled = Compiled::new(&m, &errors);
            let gains = compiled.position_gains(&pose.commands, &pose.params);
            match args.format {
                Format::Json => numeric_json(&compiled.model, &gains).render(),
                f => numeric_table(&m, &title, &pose, &compiled.model, &gains, f),
            }
        }
    };
    print!("{out}");
    Ok(())
}

/// `Error gains of seed-ac, model full (44 errors)`.
pub fn title(m: &Machine, model: Option<&str>, n: usize) -> String {
    match model {
        Some(name) => format!("Error gains of {}, model {name} ({n} errors)", m.name),
        None => format!("Error gains of {}, chosen errors ({n})", m.name),
    }
}

/// What each atom of the formulas stands for.
pub fn atom_legend(m: &Machine, model: &GainModel) -> Vec<(String, String)> {
    model
        .atoms
        .kinds
        .iter()
        .zip(&model.atoms.names)
        .map(|(k, name)| {
            let meaning = match *k {
                AtomKind::Sin(a) => format!("sine of the {} command", m.axes[a].name),
                AtomKind::Cos(a) => format!("cosine of the {} command", m.axes[a].name),
                AtomKind::Command(a) => format!("{} command, mm", m.axes[a].name),
                AtomKind::Symbol(s) => format!(
                    "kinematic parameter, mm (default {})",
                    super::short(m.symbols[s].default)
                ),
            };
            (name.clone(), meaning)
        })
        .collect()
}

/// The symbolic table as JSON.
fn symbolic_json(m: &Machine, model_name: Option<&str>, model: &GainModel) -> Json {
    let columns = ["dX", "dY", "dZ", "dI", "dJ", "dK"].map(Json::str).to_vec();
    let atoms = atom_legend(m, model)
        .into_iter()
        .map(|(n, s)| (n, Json::Str(s)))
        .collect();
    let gains = model
        .error_names
        .iter()
        .zip(&model.gains)
        .map(|(name, g)| {
            let cells = g
                .iter()
                .map(|p| Json::Str(format_poly(p, &model.atoms.names, false)))
                .collect();
            (name.clone(), Json::Arr(cells))
        })
        .collect();
    Json::Obj(vec![
        ("machine".into(), Json::str(&m.name)),
        ("model".into(), model_name.map_or(Json::Null, Json::str)),
        (
            "units".into(),
            Json::str(
                "error vector = tool point minus workpiece point, tool frame, first order; dX dY dZ in mm per mm of a translational error or mm per rad of an angular error; dI dJ dK per mm or per rad",
            ),
        ),
        ("columns".into(), Json::Arr(columns)),
        ("atoms".into(), Json::Obj(atoms)),
        ("gains".into(), Json::Obj(gains)),
    ])
}

/// Numeric gains as JSON: `{error: [gx, gy, gz]}`.
pub fn numeric_json(model: &GainModel, gains: &[[f64; 3]]) -> Json {
    Json::Obj(
        model
            .error_names
            .iter()
            .zip(gains)
            .map(|(n, g)| (n.clone(), Json::nums(g)))
            .collect(),
    )
}

/// The unit of a gain: `mm/rad` for an angular error, `mm/mm` otherwise.
fn unit(angular: bool) -> &'static str {
    if angular { "mm/rad" } else { "mm/mm" }
}

/// Numeric gains as a table for people (text, Markdown or LaTeX).
pub fn numeric_table(
    m: &Machine,
    title: &str,
    pose: &Pose,
    model: &GainModel,
    gains: &[[f64; 3]],
    format: Format,
) -> String {
    let params = m
        .symbols
        .iter()
        .zip(&pose.params)
        .map(|(s, v)| format!("{} = {}", s.name, super::short(*v)))
        .collect::<Vec<_>>()
        .join(", ");
    let notes = [
        format!("At {}.", pose::describe(m, pose)),
        format!(
            "Kinematic parameters (mm): {}.",
            if params.is_empty() { "none" } else { &params }
        ),
        "Error vector = tool point minus workpiece point, in the tool frame (first order).".into(),
        "gx gy gz: mm/mm for translational errors, mm/rad for angular errors (1 mm/rad = 1 µm per mrad).".into(),
    ];
    let header = ["error", "unit", "gx", "gy", "gz"].map(String::from);
    let rows: Vec<[String; 5]> = model
        .error_names
        .iter()
        .zip(&model.angular)
        .zip(gains)
        .map(|((n, &ang), g)| {
            [
                n.clone(),
                unit(ang).to_string(),
                super::fixed(g[0]),
                super::fixed(g[1]),
                super::fixed(g[2]),
            ]
        })
        .collect();
    match format {
        Format::Markdown => {
            let mut out = format!("### {title}\n\n");
            for n in &notes {
                out.push_str(&format!("{n}  \n"));
            }
            out.push_str(&format!("\n| {} |\n", header.join(" | ")));
            out.push_str("|---|---|---:|---:|---:|\n");
            for r in &rows {
                out.push_str(&format!("| {} |\n", r.join(" | ")));
            }
            out
        }
        Format::Latex => {
            let mut out = String::from("% requires \\usepackage{longtable}\n");
            for n in &notes {
                out.push_str(&format!("% {n}\n"));
            }
            out.push_str("\\begin{longtable}{llrrr}\n");
            out.push_str(&format!("\\caption{{{title}}}\\\\\n\\hline\n"));
            out.push_str("error & unit & $g_x$ & $g_y$ & $g_z$ \\\\\n\\hline\n\\endhead\n");
            for r in &rows {
                out.push_str(&format!(
                    "${}$ & {} & {} & {} & {} \\\\\n",
                    r[0], r[1], r[2], r[3], r[4]
                ));
            }
            out.push_str("\\hline\n\\end{longtable}\n");
            out
        }
        Format::Text | Format::Json => {
            let mut out = format!("{title}\n");
            for n in &notes {
                out.push_str(&format!("{n}\n"));
            }
            out.push('\n');
            out.push_str(&text_table(&header, &rows));
            out
        }
    }
}

/// An aligned text table: first two columns left-aligned, the rest right-aligned. Every row
/// has the header's number of cells.
pub fn text_table<R: AsRef<[String]>>(header: &[String], rows: &[R]) -> String {
    let mut widths = vec![0usize; header.len()];
    for r in std::iter::once(header).chain(rows.iter().map(AsRef::as_ref)) {
        for (w, c) in widths.iter_mut().zip(r) {
            *w = (*w).max(c.chars().count());
        }
    }
    let line = |r: &[String]| {
        let cells: Vec<String> = r
            .iter()
            .zip(&widths)
            .enumerate()
            .map(|(i, (c, &w))| {
                if i < 2 {
                    format!("{c:<w$}")
                } else {
                    format!("{c:>w$}")
                }
            })
            .collect();
        format!("{}\n", cells.join("  ").trim_end())
    };
    let mut out = line(header);
    out.push_str(&format!(
        "{}\n",
        widths
            .iter()
            .map(|&w| "-".repeat(w))
            .collect::<Vec<_>>()
            .join("  ")
    ));
    for r in rows {
        out.push_str(&line(r.as_ref()));
    }
    out
}
