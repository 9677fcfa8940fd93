//! A compensation for people: what was compensated and left out, the corrections per axis, the
//! remainders, and the lines that need a look.

use super::{header, table};
use crate::json::compensate::{CompensationReport, KinematicsReport, LengthReport};
use model_spec::units::{fixed, readable};

/// At most this many line numbers are listed in a sentence.
const LINES_SHOWN: usize = 12;

fn lines(v: &[usize]) -> String {
    let shown: Vec<String> = v.iter().take(LINES_SHOWN).map(|l| l.to_string()).collect();
    if v.len() > LINES_SHOWN {
        format!("{} and {} more", shown.join(", "), v.len() - LINES_SHOWN)
    } else {
        shown.join(", ")
    }
}

/// The whole compensation text.
pub fn compensation(r: &CompensationReport) -> String {
    let mut text = format!(
        "Compensation of {} ({} poses, {}) -> {}: machine {}, model {} with the values of {}\n",
        r.input, r.poses, r.format, r.output, r.machine, r.model, r.params_file
    );
    text.push_str(&format!(
        "Compensated: {} machine error(s): {}\n",
        r.compensated.len(),
        r.compensated.join(" ")
    ));
    if !r.left_out.is_empty() {
        text.push_str("Left out (not machine errors, or not pose by pose):\n");
        for l in &r.left_out {
            text.push_str(&format!("  {}: {}\n", l.term, l.reason));
        }
    }
    text.push('\n');
    let rounding = r.axes.iter().any(|a| a.rounding.is_some());
    let mut head = vec!["axis", "unit", "largest", "at line", "RMS"];
    if rounding {
        head.push("rounding");
    }
    let rows: Vec<Vec<String>> = r
        .axes
        .iter()
        .map(|a| {
            let unit = if a.unit == "urad" { "µrad" } else { "µm" };
            let mut row = vec![
                a.axis.clone(),
                unit.to_string(),
                fixed(a.largest, 3),
                a.largest_line.to_string(),
                fixed(a.rms, 3),
            ];
            if let Some(x) = a.rounding {
                row.push(readable(x, 3));
            }
            row
        })
        .collect();
    text.push_str("Corrections (corrected minus commanded):\n");
    text.push_str(&table(&header(&head), &rows));
    let coarse: Vec<&str> = r
        .axes
        .iter()
        .filter(|a| {
            a.rounding
                .is_some_and(|x| x > 0.1 * a.largest.abs() && x > 0.0)
        })
        .map(|a| a.axis.as_str())
        .collect();
    if !coarse.is_empty() {
        text.push_str(&format!(
            "The program's decimals lose more than a tenth of the largest correction on {}: give --decimals N for more.\n",
            coarse.join(", ")
        ));
    }
    text.push_str(&format!(
        "\nPredicted remainder at the corrected poses: position {} µm (at most)",
        readable(r.position_remainder_um, 2)
    ));
    if r.orientation_corrected {
        text.push_str(&format!(
            ", tilt of the tool axis {} µrad",
            readable(r.tilt_remainder_urad, 3)
        ));
    }
    text.push_str(".\n");
    text.push_str(&format!(
        "Rotation about the tool axis (no axis removes it): largest {} µrad, RMS {} µrad.\n",
        readable(r.roll_largest_urad, 3),
        readable(r.roll_rms_urad, 3)
    ));
    if !r.orientation_corrected {
        text.push_str("The machine has no rotary axis: the tool's orientation is not corrected.\n");
    } else if !r.tilt_uncorrected_lines.is_empty() {
        text.push_str(&format!(
            "Near a singular pose the rotary axes cannot correct the tilt of the tool axis (more than 1 µrad remains) at {} pose(s), lines {}.\n",
            r.tilt_uncorrected_lines.len(),
            lines(&r.tilt_uncorrected_lines)
        ));
    }
    if !r.clamped.is_empty() {
        let shown: Vec<String> = r.clamped.iter().take(10).map(|c| c.for_people()).collect();
        let more = r.clamped.len() - shown.len();
        text.push_str(&format!(
            "Clamped to a stroke or range limit they passed by at most 0.01 mm or 0.01° ({} command(s); the pose keeps that much of its error): {}{}.\n",
            r.clamped.len(),
            shown.join("; "),
            if more > 0 { format!("; and {more} more") } else { String::new() }
        ));
    }
    text.push_str(&kinematics_and_tables(r.kinematics.as_ref(), &r.tables));
    text.push_str(&length_warning(r.length_confounded.as_ref()));
    text
}

/// The warning that the tool-side length cannot be told from what is compensated, after a
/// blank line; empty when there is none.
pub fn length_warning(length: Option<&LengthReport>) -> String {
    length.map_or(String::new(), |l| format!("\nWarning: {}\n", l.warning))
}

/// The corrected kinematic description (what was folded, what was not) and the tables
/// written, for people; empty when neither was asked for.
pub fn kinematics_and_tables(kinematics: Option<&KinematicsReport>, tables: &[String]) -> String {
    let mut text = String::new();
    if let Some(k) = kinematics {
        text.push_str(&format!("\nCorrected kinematic description: {}\n", k.file));
        for f in &k.folded {
            text.push_str(&format!("  folded: {f}\n"));
        }
        for f in &k.not_folded {
            text.push_str(&format!("  not folded: {f}\n"));
        }
    }
    if !tables.is_empty() {
        text.push_str(&format!(
            "\nAxis compensation tables: {}\n",
            tables.join(", ")
        ));
    }
    text
}
