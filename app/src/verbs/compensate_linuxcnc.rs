//! `rtest compensate --linuxcnc DIR`: the files LinuxCNC loads for a table-table machine its
//! `xyzac-trt-kins` or `xyzbc-trt-kins` module covers: the module's pins with the identified
//! location translations folded in (`kinematics.hal`), and a joint compensation file per joint
//! whose positioning error was identified (`joint_N.comp`, `COMP_FILE_TYPE = 1`). What neither
//! holds is listed in the HAL file's comments and in the summary, per error, with its value.
//! See docs/controllers.md.

use super::{Error, VerbResult};
use compensation::controllers::linuxcnc::{TrtKinematics, TrtModule, trt_kinematics};
use compensation::kinematics::{CorrectedDescription, Directions, corrected_description_with};
use compensation::tables::{AxisTable, Pitch, axis_tables};
use compensation::values::{CompensationError, LeftOut, MachineErrors};
use formats::controllers::linuxcnc::{CompPoint, comp_file, hal_file};
use model_spec::units::compact;
use model_spec::{AxisKind, Machine, parse_machine};

/// The files for LinuxCNC, and what the summary says of them.
pub struct LinuxcncFiles {
    /// `(file name, text)`, written into the directory.
    pub files: Vec<(String, String)>,
    /// The corrected description the pins come from (the change limits check its folds).
    pub corrected: CorrectedDescription,
    /// Lines for the summary.
    pub summary: String,
}

/// The files of `--linuxcnc` for machine `m` (its description's text `source`) with the
/// identified `errors` (and the terms compensation left out, for the reversal of a joint's
/// positioning), kinematic symbols overridden by `param` (`--param`), tables at `pitch`.
///
/// # Errors
/// A usage error when the machine is not covered by a `trt` module or a table has more points
/// than LinuxCNC reads (a coarser `--pitch`); an input error when the values cannot be folded.
pub fn linuxcnc_files(
    m: &Machine,
    source: &str,
    errors: &MachineErrors,
    left_out: &[LeftOut],
    param: Option<&str>,
    pitch: Pitch,
    params_file: &str,
) -> VerbResult<LinuxcncFiles> {
    // The modules' axes are exactly x or y and z: the angular location errors stay out of the
    // directions and are listed as not held.
    let corrected = corrected_description_with(m, source, errors, Directions::Keep)
        .map_err(|e| Error::input(format!("--linuxcnc: {e}")))?;
    let folded = parse_machine(&format!("<corrected {}>", m.name), &corrected.toml)
        .map_err(|e| Error::computation(format!("--linuxcnc: the corrected description: {e}")))?;
    let params = super::pose_args::params(&folded, param)?;
    let kins =
        trt_kinematics(&folded, &params).map_err(|e| Error::usage(format!("--linuxcnc: {e}")))?;
    let tables = axis_tables(m, errors, pitch).map_err(|e| match e {
        CompensationError::Pitch { .. } => Error::usage(format!("--linuxcnc: {e}")),
        other => Error::computation(format!("--linuxcnc: {other}")),
    })?;
    let mut files = Vec::new();
    let mut comp_lines = Vec::new();
    let mut held_by_comp = Vec::new();
    for t in tables.iter().filter(|t| t.positioning.is_some()) {
        let joint = kins
            .joints
            .iter()
            .find(|j| j.axis_name == t.axis)
            .expect("every axis has a joint");
        let reversal = reversal_of(t, left_out);
        let points = comp_points(t, joint.sign, reversal);
        let name = format!("joint_{}.comp", joint.joint);
        let text = comp_file(joint.joint, &points).map_err(|e| {
            Error::usage(format!(
                "--linuxcnc: axis {}: {e}: choose a coarser --pitch or --pitch-deg",
                t.axis
            ))
        })?;
        let positioning = &t.error_names[t.positioning.expect("filtered")];
        held_by_comp.push((positioning.clone(), name.clone()));
        comp_lines.push(format!(
            "[JOINT_{}] COMP_FILE = {name}, COMP_FILE_TYPE = 1: axis {}'s positioning ({positioning}{}), {} points, joint = {}{}",
            joint.joint,
            t.axis,
            if reversal.is_some() {
                " and its reversal in the forward/reverse columns"
            } else {
                ""
            },
            points.len(),
            if joint.sign < 0.0 { "-" } else { "" },
            t.axis
        ));
        files.push((name, text));
    }
    let not_held = not_held_lines(m, &corrected, &held_by_comp, left_out);
    let comments = hal_comments(m, &kins, params_file, &corrected, &comp_lines, &not_held);
    let hal = hal_file(kins.module.name(), &comments, &kins.hal_pins());
    files.insert(0, ("kinematics.hal".to_string(), hal));
    let mut summary = format!(
        "LinuxCNC ({}, joints {}): kinematics.hal{}\n",
        kins.module.name(),
        joint_map(&kins),
        files[1..]
            .iter()
            .map(|(n, _)| format!(", {n}"))
            .collect::<String>()
    );
    if !not_held.is_empty() {
        summary += "  not held by LinuxCNC's kinematics or joint compensation (the corrected program holds them):\n";
        for l in &not_held {
            summary += &format!("    {l}\n");
        }
    }
    Ok(LinuxcncFiles {
        files,
        corrected,
        summary,
    })
}

/// `X=-X Y=Y Z=Z A=A C=-C`: each joint letter and the description's axis it is.
fn joint_map(k: &TrtKinematics) -> String {
    k.joints
        .iter()
        .map(|j| {
            format!(
                "{}={}{}",
                j.letter,
                if j.sign < 0.0 { "-" } else { "" },
                j.axis_name
            )
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// The identified reversal of the table's positioning error (`EXX@reversal`; mm or rad, the
/// error's value while the axis's command increases), if compensation left one out.
fn reversal_of(t: &AxisTable, left_out: &[LeftOut]) -> Option<f64> {
    let name = &t.error_names[t.positioning?];
    let spelling = format!("{name}@reversal");
    left_out
        .iter()
        .find(|l| l.term == spelling)
        .and_then(|l| l.values.first().copied().flatten())
}

/// The points of a joint's compensation file: the table's rows in joint units (`sign ×`
/// position; mm or degrees), ascending, the correction in the joint's sense, with the
/// reversal (the positioning error is `+reversal` while the command increases) in the
/// forward and reverse columns.
fn comp_points(t: &AxisTable, sign: f64, reversal: Option<f64>) -> Vec<CompPoint> {
    let rotary = t.kind == AxisKind::Rotary;
    let unit = |v: f64| if rotary { v.to_degrees() } else { v };
    // The deviation in the axis's own sense moves with the axis's signed direction.
    let r = t.direction.sign() * reversal.unwrap_or(0.0);
    let mut points: Vec<CompPoint> = t
        .rows
        .iter()
        .map(|row| {
            let deviation = row.deviation.expect("a positioning table");
            // Corrections while the command increases and decreases, in the axis's units.
            let (up, down) = (-(deviation + r), -(deviation - r));
            let (forward, reverse) = if sign > 0.0 { (up, down) } else { (down, up) };
            CompPoint {
                position: sign * row.position + 0.0,
                forward: sign * unit(forward),
                reverse: sign * unit(reverse),
            }
        })
        .collect();
    points.sort_by(|a, b| a.position.total_cmp(&b.position));
    points
}

/// What neither the pins nor a joint file holds, one line per compensated term.
fn not_held_lines(
    m: &Machine,
    corrected: &CorrectedDescription,
    held_by_comp: &[(String, String)],
    left_out: &[LeftOut],
) -> Vec<String> {
    let held: Vec<&str> = held_by_comp.iter().map(|(e, _)| e.as_str()).collect();
    let mut out = super::compensate_held::not_folded_lines(m, corrected, &held);
    for l in left_out {
        let Some(error) = l.term.strip_suffix("@reversal") else {
            continue;
        };
        if held_by_comp.iter().any(|(e, _)| e == error) {
            continue;
        }
        out.push(format!(
            "{}: backlash of an axis without a joint file here; LinuxCNC's [JOINT_n] BACKLASH takes it",
            l.term
        ));
    }
    out
}

/// The comment block of the HAL file: where it comes from, how to load it, the joint map,
/// what each pin holds and what is not held.
fn hal_comments(
    m: &Machine,
    k: &TrtKinematics,
    params_file: &str,
    corrected: &CorrectedDescription,
    comp_lines: &[String],
    not_held: &[String],
) -> Vec<String> {
    let tilt = k.module.tilt_letter();
    let mut c = vec![
        format!(
            "LinuxCNC {} pins of machine {} with the values of {}, written by rtest.",
            k.module.name(),
            m.name,
            params_file.replace(['\n', '\r'], " ")
        ),
        format!(
            "INI: [KINS] KINEMATICS = {} and JOINTS = 5, [TRAJ] COORDINATES = {}, and this file as a [HAL] HALFILE after the one that loads the module.",
            k.module.name(),
            k.module.coordinates()
        ),
        format!(
            "Joints: {} (a joint is the axis's command times the sign shown; the table-side axes of the description move the tool the other way relative to the table).",
            joint_map(k)
        ),
        format!(
            "World zero: the table point under the controlled point at every joint 0, {} mm from the description's workpiece origin; the controlled point is the description's tool point, so tool-offset is 0 and no tool length compensation is active.",
            k.world_origin
                .iter()
                .map(|v| compact(*v))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        format!(
            "x-rot-point, y-rot-point: the C axis line; z-rot-point and {}: the {tilt} axis line; z-offset = 0 (only z-rot-point + z-offset + tool-offset matters).",
            match k.module {
                TrtModule::Xyzac => "y-offset",
                TrtModule::Xyzbc => "x-offset",
            }
        ),
        format!(
            "Checked: the module's inverse kinematics with these pins gives the description's joints to {:.1e} mm at 50 poses.",
            k.check_mm.max(1e-15)
        ),
    ];
    c.extend(super::compensate_held::held_lines(corrected));
    for l in comp_lines {
        c.push(format!("Joint compensation: {l}."));
    }
    c.extend(super::compensate_held::not_held_block(not_held));
    c
}
