//! `rtest compensate --siemens DIR [--carrier N]`: the files a SINUMERIK loads for a five-axis
//! machine a swivel data record covers: the record with the identified location errors folded
//! in (`TC_CARR_<N>.MPF`), the channel machine data that make it the five-axis transformation
//! (`TRAFO_1.INI`), and the measuring-system and sag compensation tables of the identified
//! positioning and straightness errors (`AX_EEC.INI`, `NC_CEC.INI`). What none of them holds is
//! listed in the record's comments and in the summary, per error, with its value and why.
//! See docs/controllers.md, section "Siemens".

use super::{Error, VerbResult};
use compensation::controllers::siemens::tables::{SiemensTable, TableError, siemens_tables};
use compensation::controllers::siemens::{SwivelKinematics, swivel_kinematics};
use compensation::kinematics::{CorrectedDescription, corrected_description};
use compensation::tables::Pitch;
use compensation::values::{LeftOut, MachineErrors};
use formats::controllers::siemens::{
    CarrierRecord, CecTable, EncoderTable, carrier_program, cec_file, encoder_file, number,
    trafo_machine_data,
};
use model_spec::units::readable;
use model_spec::{Machine, parse_machine};

/// The files for a SINUMERIK, and what the summary says of them.
pub struct SiemensFiles {
    /// `(file name, text)`, written into the directory.
    pub files: Vec<(String, String)>,
    /// The corrected description the record comes from (the change limits check its folds).
    pub corrected: CorrectedDescription,
    /// Lines for the summary.
    pub summary: String,
}

/// The name of the part program of record `carrier`.
pub fn carrier_file_name(carrier: u32) -> String {
    format!("TC_CARR_{carrier}.MPF")
}

/// Whether `name` is a file `--siemens` writes (for the check that no input is overwritten).
pub fn is_ours(name: &str) -> bool {
    matches!(name, "TRAFO_1.INI" | "AX_EEC.INI" | "NC_CEC.INI")
        || (name.starts_with("TC_CARR_") && name.ends_with(".MPF"))
}

/// The files of `--siemens` for machine `m` (its description's text `source`) with the
/// identified `errors` (and the terms compensation left out), kinematic symbols overridden by
/// `param`, tables at `pitch`, the record's number `carrier`.
///
/// # Errors
/// A usage error for `--carrier 0`, a machine no record covers, or a table with more points
/// than written (a coarser `--pitch`); an input error when the values cannot be folded.
#[allow(clippy::too_many_arguments)]
pub fn siemens_files(
    m: &Machine,
    source: &str,
    errors: &MachineErrors,
    left_out: &[LeftOut],
    param: Option<&str>,
    pitch: Pitch,
    params_file: &str,
    carrier: u32,
) -> VerbResult<SiemensFiles> {
    if carrier == 0 {
        return Err(Error::usage(
            "--carrier 0: swivel data records are numbered from 1 (record 0 is not a record: $TC_CARR1[0]=0 clears every record)",
        ));
    }
    let corrected = corrected_description(m, source, errors)
        .map_err(|e| Error::input(format!("--siemens: {e}")))?;
    let folded = parse_machine(&format!("<corrected {}>", m.name), &corrected.toml)
        .map_err(|e| Error::computation(format!("--siemens: the corrected description: {e}")))?;
    let params = super::pose_args::params(&folded, param)?;
    let kins =
        swivel_kinematics(&folded, &params).map_err(|e| Error::usage(format!("--siemens: {e}")))?;
    let own_params = super::pose_args::params(m, param)?;
    let tables = siemens_tables(m, &own_params, errors, &kins, pitch).map_err(|e| match e {
        TableError::TooManyPoints { unit, .. } => Error::usage(format!(
            "--siemens: {e}: choose a coarser {}",
            if unit == "mm" {
                "--pitch"
            } else {
                "--pitch-deg"
            }
        )),
        TableError::BadPitch { .. } => Error::usage(format!("--siemens: {e}")),
        TableError::Values(e) => Error::computation(format!("--siemens: {e}")),
    })?;
    let held_by_tables: Vec<&str> = tables.iter().map(|t| t.error.as_str()).collect();
    let not_held = not_held_lines(m, &corrected, &held_by_tables, left_out);
    let origin = format!(
        "{}, {}, {}",
        number(kins.origin.x),
        number(kins.origin.y),
        number(kins.origin.z)
    );
    let head = vec![
        format!(
            "Machine {} with the values of {}, written by rtest compensate --siemens.",
            m.name,
            params_file.replace(['\n', '\r'], " ")
        ),
        format!("Machine axes: {}.", kins.axis_map()),
        format!(
            "Machine coordinates: the description's bed axes, zero at its tool point with every axis at 0 ({origin} mm from the bed origin); a linear machine axis moves the tool relative to the table along +x, +y or +z."
        ),
    ];
    let (enc, cec): (Vec<&SiemensTable>, Vec<&SiemensTable>) = tables
        .iter()
        .partition(|t| t.kind == compensation::controllers::siemens::tables::TableKind::Encoder);
    let mut files = Vec::new();
    let mut table_lines = Vec::new();
    if !enc.is_empty() {
        let text = encoder_file(&encoder_comments(&head), &encoder_tables(&enc));
        files.push(("AX_EEC.INI".to_string(), text));
        for t in &enc {
            table_lines.push(format!(
                "AX_EEC.INI: {} of axis {} as $AA_ENC_COMP of {} ({} points)",
                t.error,
                t.axis,
                t.input,
                t.values.len()
            ));
        }
    }
    if !cec.is_empty() {
        let text = cec_file(&cec_comments(&head), &cec_tables(&cec));
        files.push(("NC_CEC.INI".to_string(), text));
        for (i, t) in cec.iter().enumerate() {
            table_lines.push(format!(
                "NC_CEC.INI: {} as $AN_CEC table {i}, input {}, output {} ({} points)",
                t.error,
                t.input,
                t.output,
                t.values.len()
            ));
        }
    }
    let record = record_of(&kins, carrier);
    let comments = record_comments(&head, &kins, carrier, &corrected, &table_lines, &not_held);
    files.insert(
        0,
        (
            carrier_file_name(carrier),
            carrier_program(&comments, &record),
        ),
    );
    files.insert(
        1,
        (
            "TRAFO_1.INI".to_string(),
            trafo_machine_data(&trafo_comments(&head, carrier), carrier),
        ),
    );
    let mut summary = format!(
        "Siemens (swivel data record {carrier}, type {}, {}): {}\n",
        kins.data.kind.letter(),
        kins.axis_map(),
        files
            .iter()
            .map(|(n, _)| n.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    );
    if !not_held.is_empty() {
        summary += "  not held by the swivel data record or the compensation tables (the corrected program holds them):\n";
        for l in &not_held {
            summary += &format!("    {l}\n");
        }
    }
    Ok(SiemensFiles {
        files,
        corrected,
        summary,
    })
}

/// The record's values.
fn record_of(k: &SwivelKinematics, carrier: u32) -> CarrierRecord {
    let d = &k.data;
    let a = |v: &compensation::controllers::siemens::Vector| [v.x, v.y, v.z];
    CarrierRecord {
        number: carrier,
        kind: d.kind.letter(),
        l1: a(&d.l1),
        l2: a(&d.l2),
        v1: a(&d.v1),
        v2: a(&d.v2),
        l3: a(&d.l3),
        l4: a(&d.l4),
    }
}

fn encoder_tables(tables: &[&SiemensTable]) -> Vec<EncoderTable> {
    tables
        .iter()
        .map(|t| EncoderTable {
            axis: t.input.clone(),
            min: t.min,
            step: t.step,
            values: t.values.clone(),
            modulo: t.modulo,
            note: format!(
                "{}: {} of axis {} ({}), {} points; MD38000 $MA_MM_ENC_COMP_MAX_POINTS[0,{}] must be at least {}",
                t.input,
                t.error,
                t.axis,
                if t.rotary { "degrees" } else { "mm" },
                t.values.len(),
                t.input,
                t.values.len()
            ),
        })
        .collect()
}

fn cec_tables(tables: &[&SiemensTable]) -> Vec<CecTable> {
    tables
        .iter()
        .enumerate()
        .map(|(i, t)| CecTable {
            input: t.input.clone(),
            output: t.output.clone(),
            min: t.min,
            step: t.step,
            values: t.values.clone(),
            modulo: t.modulo,
            note: format!(
                "{} of axis {}: {} as a function of {}, mm, {} points; MD18342 $MN_MM_CEC_MAX_POINTS[{i}] must be at least {}",
                t.error,
                t.axis,
                t.output,
                t.input,
                t.values.len(),
                t.values.len()
            ),
        })
        .collect()
}

fn encoder_comments(head: &[String]) -> Vec<String> {
    let mut c = vec![
        "SINUMERIK measuring-system error compensation (K3), 1st measuring system.".to_string(),
    ];
    c.extend(head.iter().cloned());
    c.push("Values: the deviation, actual minus commanded position, in the machine axis's own sense (mm; degrees on a rotary axis); K3: the NC adds it to the actual value, so a positive value makes the axis move negative. Absolute values, not zero at the reference point.".into());
    c.push("Load with MD32700 $MA_ENC_COMP_ENABLE[0] = 0, then set it to 1, POWER ON and reference the axis. Outside MIN..MAX the end values hold; MAX may lie past the stroke by less than a step.".into());
    c
}

fn cec_comments(head: &[String]) -> Vec<String> {
    let mut c = vec![
        "SINUMERIK sag / angularity compensation (K3): straightness errors of the linear axes."
            .to_string(),
    ];
    c.extend(head.iter().cloned());
    c.push("Values: the deviation of the tool relative to the table along the output axis (mm), as the input axis moves, rotary axes at 0.".into());
    c.push("SIGN NOT DOCUMENTED: K3 does not say whether the NC adds a $AN_CEC value to the output axis's actual value (as $AA_ENC_COMP, which these values assume) or to its set-point (then each correction doubles its error). Check one table on the machine before use.".into());
    c.push("Load with MD32710 $MA_CEC_ENABLE = 0 on the output axes, then set it to 1 and SD41300 $SN_CEC_TABLE_ENABLE[t] = 1 per table.".into());
    c
}

fn trafo_comments(head: &[String], carrier: u32) -> Vec<String> {
    let mut c = vec![format!(
        "SINUMERIK five-axis transformation 1 as transformer type 72: its kinematics from swivel data record {carrier} (IM9 2017 §21.7)."
    )];
    c.extend(head.iter().cloned());
    c.push("Not set here: MD24110 $MC_TRAFO_AXES_IN_1 and MD24120 $MC_TRAFO_GEOAX_ASSIGN_TAB_1 (the channel's axis numbers, the machine's own; NEW CONF).".into());
    c.push("Activation: the public manuals read do not give the activation class of MD24100 or MD24582; check the list manual or the commissioning manual (NEW CONF or POWER ON) before relying on a reset.".into());
    c
}

/// The comment block of the record's part program.
fn record_comments(
    head: &[String],
    k: &SwivelKinematics,
    carrier: u32,
    corrected: &CorrectedDescription,
    table_lines: &[String],
    not_held: &[String],
) -> Vec<String> {
    let kind = match k.data.kind {
        compensation::controllers::siemens::KinematicType::T => "T, only the tool turns",
        compensation::controllers::siemens::KinematicType::P => "P, only the part turns",
        compensation::controllers::siemens::KinematicType::M => {
            "M, the tool turns about rotary axis 1, the part about rotary axis 2"
        }
    };
    let mut c = vec![format!(
        "SINUMERIK swivel data record {carrier} (orientable toolholder, W1), absolute values."
    )];
    c.extend(head.iter().cloned());
    c.push(format!(
        "Kinematic type {kind}; rotary axis 1 = {}, rotary axis 2 = {}.",
        k.rotary[0].axis_name, k.rotary[1].axis_name
    ));
    c.push("Lengths in mm; v1, v2 unit vectors about which a positive axis position turns the head or the table (right-handed), angles in degrees; the controlled point is the description's tool point (tool length 0 in these vectors).".into());
    c.push(format!(
        "Run once; if record {carrier} is active, select it again (TCARR={carrier}). $TC_CARR21/22 (the channel's rotary axes) and 26..40 (Hirth, limits, names, CYCLE800's mode) are left as set."
    ));
    c.push(format!(
        "Checked: the chain of W1 2.5 and IM9 with these values gives the description's tool point relative to its table to {:.1e} mm at 50 poses.",
        k.check_mm.max(1e-15)
    ));
    c.extend(super::compensate_held::held_lines(corrected));
    for l in table_lines {
        c.push(format!("Held in a table: {l}."));
    }
    c.extend(super::compensate_held::not_held_block(not_held));
    c
}

/// What neither the record nor a table holds, one line per compensated term.
fn not_held_lines(
    m: &Machine,
    corrected: &CorrectedDescription,
    held_by_tables: &[&str],
    left_out: &[LeftOut],
) -> Vec<String> {
    let mut out = super::compensate_held::not_folded_lines(m, corrected, held_by_tables);
    for l in left_out {
        if let Some(error) = l.term.strip_suffix("@reversal") {
            let angular = m
                .error_by_name(error)
                .is_some_and(|e| m.catalogue[e].is_angular());
            let value = match l.values.first().copied().flatten() {
                Some(v) if angular => format!(" = {} µrad", readable(v * 1e6, 4)),
                Some(v) => format!(" = {} µm", readable(v * 1e3, 4)),
                None => String::new(),
            };
            out.push(format!(
                "{}{value}: backlash, which depends on the direction of approach; the SINUMERIK's backlash compensation takes it (not written here)",
                l.term
            ));
        }
    }
    out
}
