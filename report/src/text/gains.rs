//! Numeric gains at one pose for people (text, Markdown or LaTeX): per error the position gains
//! `[gx, gy, gz]` in the tool frame (mm/mm for translational errors, mm/rad for angular errors)
//! and the orientation gains `[gi, gj, gk]` of the tool axis (1/mm or 1/rad).

use super::{header, table};
use crate::json::PoseGains;
use codegen::table::Format;
use model_spec::units::{fixed, short};
use model_spec::{AxisKind, Machine};
use simulation::pose::Pose;

/// `Error gains of seed-ac, model full (44 errors)`, or `chosen errors (3)` for a list.
pub fn title(m: &Machine, model: Option<&str>, n: usize) -> String {
    match model {
        Some(name) => format!("Error gains of {}, model {name} ({n} errors)", m.name),
        None => format!("Error gains of {}, chosen errors ({n})", m.name),
    }
}

/// The pose for people: `X = 12.5 mm (IK), A = 30°, …`.
pub fn describe_pose(m: &Machine, pose: &Pose) -> String {
    m.axes
        .iter()
        .enumerate()
        .map(|(i, a)| match a.kind {
            AxisKind::Linear => format!(
                "{} = {} mm{}",
                a.name,
                short(pose.shown[i]),
                if pose.from_ik[i] { " (IK)" } else { "" }
            ),
            AxisKind::Rotary => format!("{} = {}°", a.name, short(pose.shown[i])),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The table of the gains `g` (`[gx, gy, gz, gi, gj, gk]` per error) at `pose`, titled
/// `title`, with the rule that decided the zeros and the gains that vanish at this pose.
pub fn pose_gains(
    m: &Machine,
    title: &str,
    pose: &Pose,
    g: &PoseGains<'_>,
    format: Format,
) -> String {
    let zero_note = if g.vanishing.is_empty() {
        g.zeros.clone()
    } else {
        format!(
            "{} Vanishing at this pose: {}.",
            g.zeros,
            g.vanishing.join(", ")
        )
    };
    let params = m
        .symbols
        .iter()
        .zip(&pose.params)
        .map(|(s, v)| format!("{} = {}", s.name, short(*v)))
        .collect::<Vec<_>>()
        .join(", ");
    let mut notes = vec![
        format!("At {}.", describe_pose(m, pose)),
        format!(
            "Kinematic parameters (mm): {}.",
            if params.is_empty() { "none" } else { &params }
        ),
        "Error vector = tool point minus workpiece point, in the tool frame (first order).".into(),
        "gx gy gz: position, mm/mm for translational errors, mm/rad for angular errors (1 mm/rad = 1 µm per mrad).".into(),
        "gi gj gk: orientation of the tool axis (unit vector), 1/mm for translational errors, 1/rad for angular errors.".into(),
        zero_note,
    ];
    notes.extend(pose.off_ball_note());
    let head = header(&["error", "unit", "gx", "gy", "gz", "gi", "gj", "gk"]);
    let rows: Vec<Vec<String>> = g
        .names
        .iter()
        .zip(g.angular)
        .zip(g.gains)
        .map(|((n, &ang), g)| {
            let mut row = vec![n.clone(), if ang { "mm/rad" } else { "mm/mm" }.to_string()];
            row.extend(g.iter().map(|&v| fixed(v, 6)));
            row
        })
        .collect();
    match format {
        Format::Markdown => {
            let mut out = format!("### {title}\n\n");
            for n in &notes {
                out.push_str(&format!("{n}  \n"));
            }
            out.push_str(&format!("\n| {} |\n", head.join(" | ")));
            out.push_str("|---|---|---:|---:|---:|---:|---:|---:|\n");
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
            out.push_str("\\begin{longtable}{llrrrrrr}\n");
            out.push_str(&format!("\\caption{{{title}}}\\\\\n\\hline\n"));
            out.push_str(
                "error & unit & $g_x$ & $g_y$ & $g_z$ & $g_i$ & $g_j$ & $g_k$ \\\\\n\\hline\n\\endhead\n",
            );
            for r in &rows {
                out.push_str(&format!("${}$ & {} \\\\\n", r[0], r[1..].join(" & ")));
            }
            out.push_str("\\hline\n\\end{longtable}\n");
            out
        }
        Format::Text => {
            let mut out = format!("{title}\n");
            for n in &notes {
                out.push_str(&format!("{n}\n"));
            }
            out.push('\n');
            out.push_str(&table(&head, &rows));
            out
        }
    }
}
