//! `rtest compensate`: what `identify` found, put back onto the machine: corrected commands
//! (a CSV of poses or an NC program), a corrected kinematic description, axis compensation
//! tables.

use super::args::ValueBounds;
use super::{EXIT_CODES, Error, ReadFile, VerbResult, check_outputs};
use crate::Done;
use compensation::confounded::tool_length;
use compensation::kinematics::{CorrectedDescription, corrected_description};
use compensation::limits::{
    ChangeLimits, MAX_CHANGE_UM, MAX_CHANGE_URAD, check_changes, coarse_words,
};
use compensation::run::{PoseSource, RunError, Stopped, Summary, compensate_each};
use compensation::tables::{Pitch, axis_tables};
use compensation::values::{CompensationError, MachineErrors};
use formats::nc::{Dialect, WriteOptions, Written, parse_program};
use formats::poses::{
    AxisWord, PoseList, axis_words, from_file_units, from_file_units_into, read_keeping_bom,
    read_pose_csv, to_file_units_into,
};
use model_spec::units::{compact, readable};
use output::{Outputs, Target};
use report::json::compensate::{
    CompensationReport, CompensationSource, KinematicsReport, LengthReport,
};
use report::json::read::parse_identification;
use report::json::to_json;
use report::text::compensate::{compensation, kinematics_and_tables, length_warning};
use std::path::PathBuf;

const LONG_ABOUT: &str = "\
Puts identified errors back onto the machine. The values come from `rtest identify --json` \
(--params: one record or a campaign). Only the machine's geometric errors are compensated; \
set-up errors, the R-test's offsets and instrument terms, each record's own parameters, and \
time, velocity and reversal terms are left out and listed. An undetermined value is refused.

--path IN -o OUT: corrected commands, a CSV of poses (one column per axis letter; mm, degrees) \
or, with --nc iso|linuxcnc|heidenhain, an NC program in machine coordinates: the predicted tool \
point and tool axis become the commanded ones (to 1 nm); the rotation about the tool axis is \
reported. A command past a limit by at most 0.01 mm or 0.01° is clamped and listed, further \
out refused. Words whose decimals lose more than 0.1 µm or 1 µrad are refused unless \
--decimals N says how many to write.

Also: --kinematics-out FILE (the description with the location errors folded in), --tables DIR \
(per-axis errors and corrections every --pitch mm or --pitch-deg degrees), --linuxcnc DIR \
(LinuxCNC's trt-kins pins and joint compensation files), --isg FILE (ISG's volumetric \
compensation file), --siemens DIR (a SINUMERIK's swivel data record --carrier N, TRAORI \
machine data, $AA_ENC_COMP and $AN_CEC tables), --json and --report (with --path). What an \
output cannot hold is listed. --param sets kinematic symbols (mm; the tool length, say).

Limits: a value or a folded change beyond --max-change-um (default 50) or --max-change-urad \
(250) is refused. A tool-side length that cannot be told from a compensated error (Zp from \
ZOA on seed-ac) is warned of: give the length measured on a tool setter with --param.

Details: docs/compensation.md, docs/compensation-tables.md, docs/controllers.md, \
docs/nc-programs.md, docs/report.md.";

/// Flags of `rtest compensate`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Compensate: corrected commands (CSV or NC), corrected kinematics, axis tables",
    long_about = LONG_ABOUT,
    after_help = EXIT_CODES
)]
pub struct CompensateArgs {
    /// Built-in machine (see `rtest machines`) or path of a machine TOML file.
    #[arg(long, value_name = "NAME|FILE")]
    machine: String,
    /// The JSON written by `rtest identify --json`, of one record or a campaign (values in µm
    /// and µrad).
    #[arg(long, value_name = "FILE")]
    params: PathBuf,
    /// The commanded poses: a CSV (columns named by the axis letters) or, with --nc, a program.
    #[arg(long, value_name = "FILE", requires = "output")]
    path: Option<PathBuf>,
    /// Where the corrected poses go, in the format of --path.
    #[arg(short = 'o', long = "output", value_name = "FILE", requires = "path")]
    output: Option<Target>,
    /// --path is an NC program of this dialect (iso: Fanuc-type G-code; linuxcnc; heidenhain).
    #[arg(long, value_name = "iso|linuxcnc|heidenhain", value_parser = ["iso", "linuxcnc", "heidenhain"])]
    nc: Option<String>,
    /// The fewest decimals of a corrected NC word (at most 9). Default: the program's own, and a
    /// program whose words lose more than 0.1 µm or 1 µrad of a correction is refused.
    #[arg(long, value_name = "N")]
    decimals: Option<usize>,
    /// Kinematic symbols (mm), `NAME=VALUE,...`, overriding the machine's defaults.
    #[arg(long, value_name = "LIST")]
    param: Option<String>,
    /// Also write the machine description with the location errors folded into its offsets.
    #[arg(long, value_name = "FILE")]
    kinematics_out: Option<Target>,
    /// Also write one axis compensation table per axis into this directory.
    #[arg(long, value_name = "DIR")]
    tables: Option<PathBuf>,
    /// Also write LinuxCNC's files into this directory: the pins of its xyzac-trt-kins or
    /// xyzbc-trt-kins module (kinematics.hal, mm) and joint compensation files (joint_N.comp,
    /// mm or degrees).
    #[arg(long, value_name = "DIR")]
    linuxcnc: Option<PathBuf>,
    /// Also write the errors as ISG-kernel's volumetric compensation file (Beckhoff TwinCAT
    /// CNC, ISG_CSV; values in mm and rad, positions in mm and degrees) to FILE.
    #[arg(long, value_name = "FILE")]
    isg: Option<Target>,
    /// Also write a SINUMERIK's files into this directory: swivel data record --carrier
    /// (TC_CARR_N.MPF; vectors in mm), the five-axis transformation's machine data
    /// (TRAFO_1.INI) and compensation tables (AX_EEC.INI, NC_CEC.INI; mm or degrees).
    #[arg(long, value_name = "DIR")]
    siemens: Option<PathBuf>,
    /// The number of the swivel data record --siemens sets (from 1).
    #[arg(long, value_name = "N", default_value_t = 1, requires = "siemens")]
    carrier: u32,
    /// Pitch of the tables of linear axes, mm.
    #[arg(long, value_name = "MM", default_value_t = 10.0, value_parser = super::args::positive)]
    pitch: f64,
    /// Pitch of the tables of rotary axes, degrees.
    #[arg(long, value_name = "DEG", default_value_t = 5.0, value_parser = super::args::positive)]
    pitch_deg: f64,
    /// The largest linear error or change compensated, µm (over the axis's range for an error
    /// that varies with its axis; each change folded by --kinematics-out): a larger one is
    /// refused.
    #[arg(long, value_name = "UM", default_value_t = MAX_CHANGE_UM, value_parser = super::args::positive)]
    max_change_um: f64,
    /// The largest angular error compensated, µrad: a larger one is refused.
    #[arg(long, value_name = "URAD", default_value_t = MAX_CHANGE_URAD, value_parser = super::args::positive)]
    max_change_urad: f64,
    /// Also write the summary as JSON to FILE (`-`: standard output).
    #[arg(long, value_name = "FILE")]
    json: Option<Target>,
    /// Also write the HTML report (docs/report.md) of the identification of --params and this
    /// compensation to FILE (`-`: standard output).
    #[arg(long, value_name = "FILE")]
    report: Option<Target>,
    #[command(flatten)]
    bounds: ValueBounds,
}

/// Refuses flags that ask for nothing or for what the others do not give.
fn check_flags(args: &CompensateArgs) -> VerbResult {
    if args.path.is_none()
        && args.kinematics_out.is_none()
        && args.tables.is_none()
        && args.linuxcnc.is_none()
        && args.isg.is_none()
        && args.siemens.is_none()
    {
        return Err(Error::usage(
            "nothing to write: give --path IN -o OUT, --kinematics-out FILE, --tables DIR, --linuxcnc DIR, --isg FILE or --siemens DIR",
        ));
    }
    if args.json.is_some() && args.path.is_none() {
        return Err(Error::usage(
            "--json summarises corrected poses: give --path",
        ));
    }
    if args.report.is_some() && args.path.is_none() {
        return Err(Error::usage(
            "--report summarises corrected poses: give --path",
        ));
    }
    if args.nc.is_none() && args.decimals.is_some() {
        return Err(Error::usage("--decimals applies to NC programs (--nc)"));
    }
    super::args::nc_decimals(args.decimals)?;
    Ok(())
}

/// Runs `rtest compensate`.
pub fn run(args: &CompensateArgs) -> VerbResult<Done> {
    check_flags(args)?;
    let machine = super::load_machine_read(&args.machine)?;
    let (m, machine_text) = (machine.machine, machine.text);
    let mut inputs = vec![("--params", args.params.as_path())];
    inputs.extend(args.path.as_deref().map(|p| ("--path", p)));
    inputs.extend(super::machine_file(&args.machine).map(|p| ("--machine", p)));
    let outputs: Vec<(&str, &Target)> = [
        ("-o", args.output.as_ref()),
        ("--kinematics-out", args.kinematics_out.as_ref()),
        ("--json", args.json.as_ref()),
        ("--report", args.report.as_ref()),
        ("--isg", args.isg.as_ref()),
    ]
    .into_iter()
    .filter_map(|(f, t)| t.map(|t| (f, t)))
    .collect();
    let dirs: Vec<(&str, &std::path::Path)> = args
        .tables
        .iter()
        .map(|d| ("--tables", d.as_path()))
        .chain(args.linuxcnc.iter().map(|d| ("--linuxcnc", d.as_path())))
        .chain(args.siemens.iter().map(|d| ("--siemens", d.as_path())))
        .collect();
    check_outputs(&inputs, &outputs, &dirs)?;
    let pitch = Pitch {
        linear_mm: args.pitch,
        rotary_deg: args.pitch_deg,
    };
    if let Some(dir) = &args.tables {
        let table = |n: &str| n.starts_with("axis_") && n.ends_with(".csv");
        super::check_dir_inputs(&inputs, "--tables", dir, &table)?;
    }
    if let Some(dir) = &args.linuxcnc {
        let ours =
            |n: &str| n == "kinematics.hal" || (n.starts_with("joint_") && n.ends_with(".comp"));
        super::check_dir_inputs(&inputs, "--linuxcnc", dir, &ours)?;
    }
    if let Some(dir) = &args.siemens {
        let ours = super::compensate_siemens::is_ours;
        super::check_dir_inputs(&inputs, "--siemens", dir, &ours)?;
    }
    let params = super::pose_args::params(&m, args.param.as_deref())?;
    // --params is read once: its values, and the identification the report shows.
    let params_file = args.params.display().to_string();
    let (params_text, params_digest) =
        model_spec::text::read_text_hashed(&args.params, report::json::read::MAX_REPORT_BYTES)
            .map_err(|e| Error::input(format!("--params: {e}")))?;
    let id = parse_identification(&params_file, &params_text, &m)
        .map_err(|e| Error::input(format!("--params: {e}")))?;
    let mut read_files = vec![ReadFile::new("--params", &args.params, params_digest)];
    let v = &id.values;
    super::campaign::check_campaign_values(&m, &v.layout, &v.values, &args.bounds.values())
        .map_err(|e| {
            Error::input(format!(
                "--params: {}: {e}: these cannot be the errors of a machine tool (--max-error-um, --max-error-urad change the bounds)",
                args.params.display()
            ))
        })?;
    let (errors, left_out) = MachineErrors::from_values(&m, v, &id.file)
        .map_err(|e| Error::input(format!("--params: {e}")))?;
    let symbols_note = symbols_note(&m, &params, errors.record_params(), args.param.is_some());
    check_change_limits(args, &m, &errors, None)?;
    let mut files = Outputs::new();
    files.protect(&inputs);
    let mut source = CompensationSource::of(&m, &id.model_name, &params_file, &errors, &left_out);
    source.length_confounded = length_confounded(&m, v, &errors)?;
    let mut summary = None;
    if let (Some(path), Some(out)) = (&args.path, &args.output) {
        let words = axis_words(&m);
        let file = path.display().to_string();
        let values_at = |q: &[f64], out: &mut [f64]| errors.values_at(&m, q, out);
        let correct = Correction {
            m: &m,
            errors: errors.errors(),
            params: &params,
            file: &file,
            values_at: &values_at,
        };
        let (path_text, digest) =
            read_keeping_bom(path).map_err(|e| Error::input(format!("--path: {e}")))?;
        read_files.push(ReadFile::new("--path", path, digest));
        let (text, rounding, format, s) =
            correct.rewrite(args.nc.as_deref(), args.decimals, &path_text, &words)?;
        files.add("-o", out.clone(), text);
        source.input = file;
        source.output = out.to_string();
        source.format = format;
        source.rounding = rounding;
        summary = Some(s);
    }
    if let Some(target) = &args.kinematics_out {
        let corrected = corrected_description(&m, &machine_text, &errors)
            .map_err(|e| Error::input(format!("--kinematics-out: {e}")))?;
        check_change_limits(args, &m, &errors, Some(&corrected))?;
        source.kinematics = Some(kinematics_report(target, &corrected));
        files.add("--kinematics-out", target.clone(), corrected.toml);
    }
    if let Some(dir) = &args.tables {
        let tables = axis_tables(&m, &errors, pitch).map_err(|e| match e {
            CompensationError::Pitch { .. } => Error::usage(format!("--tables: {e}")),
            other => Error::computation(format!("--tables: {other}")),
        })?;
        for t in &tables {
            let name = t.file_name();
            source.tables.push(dir.join(&name).display().to_string());
            files.add_in_dir("--tables", dir, &name, t.to_csv());
        }
    }
    // What the controller outputs say of themselves.
    let mut controller_summary = String::new();
    if let Some(dir) = &args.linuxcnc {
        let written = super::compensate_linuxcnc::linuxcnc_files(
            &m,
            &machine_text,
            &errors,
            &left_out,
            args.param.as_deref(),
            pitch,
            &params_file,
        )?;
        check_change_limits(args, &m, &errors, Some(&written.corrected))?;
        for (name, text) in written.files {
            files.add_in_dir("--linuxcnc", dir, &name, text);
        }
        controller_summary = written.summary;
    }
    if let Some(target) = &args.isg {
        let (text, lines) = super::compensate_isg::isg_file(&m, &errors, pitch, &params_file)?;
        files.add("--isg", target.clone(), text);
        controller_summary.push_str(&lines);
    }
    if let Some(dir) = &args.siemens {
        let written = super::compensate_siemens::siemens_files(
            &m,
            &machine_text,
            &errors,
            &left_out,
            args.param.as_deref(),
            pitch,
            &params_file,
            args.carrier,
        )?;
        check_change_limits(args, &m, &errors, Some(&written.corrected))?;
        for (name, text) in written.files {
            files.add_in_dir("--siemens", dir, &name, text);
        }
        controller_summary.push_str(&written.summary);
    }
    let mut text = match &summary {
        Some(s) => {
            let report = CompensationReport::new(source, s)
                .map_err(|e| Error::computation(format!("--path: {e}")))?;
            if let Some(target) = &args.json {
                let json =
                    to_json(&report).map_err(|e| Error::computation(format!("--json: {e}")))?;
                files.add("--json", target.clone(), json);
            }
            if let Some(target) = &args.report {
                read_files.extend(ReadFile::machine(&args.machine, machine.digest));
                let html = html_report(&params_file, &params_text, &m, &read_files, &report)?;
                files.add("--report", target.clone(), html);
            }
            compensation(&report)
        }
        None => {
            format!(
                "Machine {}, model {} with the values of {}\n{}",
                source.machine,
                source.model,
                source.params_file,
                kinematics_and_tables(source.kinematics.as_ref(), &source.tables)
            ) + &length_warning(source.length_confounded.as_ref())
        }
    };
    text.push_str(&controller_summary);
    text.push_str(&symbols_note);
    let stdout_taken = [
        &args.output,
        &args.kinematics_out,
        &args.json,
        &args.report,
        &args.isg,
    ]
    .iter()
    .any(|t| matches!(t, Some(Target::Stdout)));
    Ok(Done::new(text, files, stdout_taken))
}

/// What `--kinematics-out` wrote into `target`: each error folded into the description (µm,
/// the value before and after, mm) and each one that could not be, with why.
fn kinematics_report(target: &Target, corrected: &CorrectedDescription) -> KinematicsReport {
    KinematicsReport {
        file: target.to_string(),
        folded: corrected
            .folded
            .iter()
            .map(|f| {
                format!(
                    "{} = {} µm into {}: {} -> {} mm",
                    f.name,
                    readable(f.value_mm * 1e3, 4),
                    f.place,
                    compact(f.before_mm),
                    compact(f.after_mm)
                )
            })
            .chain(corrected.symbols.iter().map(|f| {
                format!(
                    "{} = {} µm into its default: {} -> {} mm",
                    f.name,
                    readable(f.change_mm * 1e3, 4),
                    compact(f.before_mm),
                    compact(f.after_mm)
                )
            }))
            .chain(corrected.directions.iter().map(direction_line))
            .chain(corrected.turned.iter().map(|t| {
                format!(
                    "{} turned by the axes {}: {} -> {} mm",
                    t.place,
                    t.by.join(", "),
                    compact(t.before_mm),
                    compact(t.after_mm)
                )
            }))
            .chain(corrected.set_up_turn.map(|_| {
                let [x, y, z] = corrected.set_up_change_mm.map(|v| readable(v * 1e3, 4));
                format!(
                    "the ball's frame turns with them: identified with this description, XOW YOW ZOW come out larger by {x}, {y}, {z} µm"
                )
            }))
            .collect(),
        not_folded: corrected
            .not_folded
            .iter()
            .map(|n| format!("{}: {}", n.spelling, n.reason))
            .collect(),
    }
}

/// A folded direction for people: `AOC = 29.75 µrad, BOC = -12.5 µrad into the direction of
/// C: (0, 0, 1) -> (…)`.
fn direction_line(d: &compensation::kinematics::FoldedDirection) -> String {
    let vector = |v: &[f64; 3]| {
        let parts: Vec<String> = v.iter().map(|x| compact(*x)).collect();
        format!("({})", parts.join(", "))
    };
    let mut what: Vec<String> = d
        .errors
        .iter()
        .map(|a| format!("{} = {} µrad", a.name, readable(a.value_rad * 1e6, 4)))
        .collect();
    if !d.carried_by.is_empty() {
        what.push(format!("the turn of {}", d.carried_by.join(", ")));
    }
    format!(
        "{} into the direction of {}: {} -> {}",
        what.join(", "),
        d.axis,
        vector(&d.before),
        vector(&d.after)
    )
}

/// Refuses the values of `--params` (`errors`) when an error's largest value over the
/// machine's ranges, or a change folded into `corrected` (the description `--kinematics-out`
/// writes), is beyond `--max-change-um` or `--max-change-urad`.
fn check_change_limits(
    args: &CompensateArgs,
    m: &model_spec::Machine,
    errors: &MachineErrors,
    corrected: Option<&CorrectedDescription>,
) -> VerbResult {
    let limits = ChangeLimits::from_display(args.max_change_um, args.max_change_urad);
    let flag = if corrected.is_some() {
        "--kinematics-out"
    } else {
        "--params"
    };
    check_changes(m, errors, corrected, limits).map_err(|e| Error::input(format!("{flag}: {e}")))
}

/// The warning that the tool-side length of `m` cannot be told from what the identification
/// of `values` (`errors`) puts onto the machine, when it cannot (`compensation::confounded`).
fn length_confounded(
    m: &model_spec::Machine,
    values: &fitting::campaign::CampaignValues,
    errors: &MachineErrors,
) -> VerbResult<Option<LengthReport>> {
    let found =
        tool_length(m, values, errors).map_err(|e| Error::computation(format!("--params: {e}")))?;
    Ok(found.as_ref().map(LengthReport::of))
}

/// Refuses a program `written` back from `--path` (`file`) whose words lose more of a
/// correction than `compensation::limits` allows, unless `--decimals` (`decimals`) says how
/// many decimals to write.
fn refuse_coarse_words(
    m: &model_spec::Machine,
    file: &str,
    decimals: Option<usize>,
    written: &Written,
) -> VerbResult {
    if decimals.is_some() {
        return Ok(());
    }
    let coarse = coarse_words(m, &written.rounding, &written.largest_rounding);
    let Some(needed) = coarse.iter().map(|c| c.needed).max() else {
        return Ok(());
    };
    Err(Error::input(format!(
        "--path: {file}: the program's words cannot carry the correction: {}; give --decimals {needed} to write every corrected word with at least {needed} decimals (or write the program with more decimals)",
        coarse
            .iter()
            .map(|c| c.for_people())
            .collect::<Vec<_>>()
            .join("; ")
    )))
}

/// The correction of the poses of `--path`: what [`compensate_each`] takes besides the poses.
struct Correction<'a> {
    m: &'a model_spec::Machine,
    errors: &'a [model_spec::ErrorId],
    params: &'a [f64],
    file: &'a str,
    values_at: &'a (dyn Fn(&[f64], &mut [f64]) + Sync),
}

impl Correction<'_> {
    /// Corrects `poses` (mm and degrees, as the file holds them), handing each corrected pose
    /// (mm and degrees) to `write`, the writer of `-o`; the summary.
    /// The corrected `--path` file, whose `text` is an NC program of dialect `nc` (written with
    /// at least `decimals` decimals) or a pose CSV, its axes named by `words`: the corrected
    /// text, the rounding of the written words (mm and rad; NC only), the format's name and the
    /// summary of the correction.
    fn rewrite(
        &self,
        nc: Option<&str>,
        decimals: Option<usize>,
        text: &str,
        words: &[AxisWord],
    ) -> VerbResult<(String, Option<Vec<f64>>, String, Summary)> {
        let (m, file) = (self.m, self.file);
        Ok(match nc {
            Some(name) => {
                let dialect = Dialect::from_name(name).expect("clap checks the dialect");
                let program = parse_program(file, text, dialect, words)
                    .map_err(|e| Error::input(format!("--path: {e}")))?;
                let options = WriteOptions::with_min_decimals(decimals.unwrap_or(0));
                let mut writer = program
                    .writer(&options)
                    .map_err(|e| Error::input(format!("-o: {e}")))?;
                let s = self.run(program.pose_list(), |q| writer.pose(q))?;
                let written = writer
                    .finish()
                    .map_err(|e| Error::input(format!("-o: {e}")))?;
                refuse_coarse_words(m, file, decimals, &written)?;
                let rounding = from_file_units(m, &written.rounding);
                (written.text, Some(rounding), name.to_string(), s)
            }
            None => {
                let table = read_pose_csv(file, text, words)
                    .map_err(|e| Error::input(format!("--path: {e}")))?;
                let mut writer = table.writer();
                let s = self.run(table.pose_list(), |q| writer.pose(q))?;
                let text = writer
                    .finish()
                    .map_err(|e| Error::input(format!("-o: {e}")))?;
                (text, None, "csv".to_string(), s)
            }
        })
    }

    fn run<E: std::fmt::Display>(
        &self,
        poses: &PoseList,
        mut write: impl FnMut(&[f64]) -> Result<(), E>,
    ) -> VerbResult<Summary> {
        let m = self.m;
        let mut in_file_units = vec![0.0; m.axes.len()];
        let sink = |_: usize, q: &[f64]| {
            to_file_units_into(m, q, &mut in_file_units);
            write(&in_file_units)
        };
        let source = InRadians { m, poses };
        compensate_each(
            m,
            self.errors,
            self.params.to_vec(),
            self.file,
            &source,
            self.values_at,
            sink,
        )
        .map_err(|e| match e {
            Stopped::Run(e @ RunError::NotConverged { .. }) => {
                Error::computation(format!("--path: {e}"))
            }
            Stopped::Run(other) => Error::input(format!("--path: {other}")),
            Stopped::Sink(e) => Error::input(format!("-o: {e}")),
        })
    }
}

/// The poses of a file (mm and degrees) as the compensation reads them (mm and rad).
struct InRadians<'a> {
    m: &'a model_spec::Machine,
    poses: &'a PoseList,
}

impl PoseSource for InRadians<'_> {
    fn count(&self) -> usize {
        self.poses.len()
    }

    fn line(&self, i: usize) -> usize {
        self.poses.line(i)
    }

    fn commands_into(&self, i: usize, out: &mut [f64]) {
        from_file_units_into(self.m, self.poses.commands(i), out);
    }
}

/// The HTML report (`--report`) of the identification of `--params` (`params_text`, read from
/// `params_file`) and of `report`, the compensation just computed; `inputs` as read.
fn html_report(
    params_file: &str,
    params_text: &str,
    m: &model_spec::Machine,
    inputs: &[ReadFile],
    report: &CompensationReport,
) -> VerbResult<String> {
    let mut i = super::report::inputs_for(m, inputs);
    let fail = |e: ::report::InputError| Error::input(format!("--params: {e}"));
    let params = ::report::inputs::classify(params_file, params_text).map_err(fail)?;
    i.add(params_file, params).map_err(fail)?;
    i.add(
        "this run of rtest compensate",
        ::report::Document::Compensation(Box::new(report.clone())),
    )
    .map_err(|e| Error::computation(format!("--report: {e}")))?;
    super::report::render("--report", &i)
}

/// The note on the machine's kinematic symbols: where the records of the identification were
/// modelled with other values of the machine's side (not the ball's position) than the
/// correction uses (`params`, mm: the defaults and `--param`), which; empty otherwise.
fn symbols_note(m: &model_spec::Machine, params: &[f64], records: &[f64], given: bool) -> String {
    let workpiece = m.workpiece_symbols();
    let differ: Vec<String> = m
        .symbols
        .iter()
        .enumerate()
        .filter(|(s, _)| !workpiece.contains(s))
        .filter(|(s, _)| records.get(*s).is_some_and(|r| *r != params[*s]))
        .map(|(s, sym)| {
            format!(
                "{} = {} mm (the correction uses {} mm)",
                sym.name,
                model_spec::units::short(records[s]),
                model_spec::units::short(params[s])
            )
        })
        .collect();
    if differ.is_empty() {
        return String::new();
    }
    format!(
        "Note: the identification's records were modelled with {}; the correction takes the machine's kinematic symbols from {}.\n",
        differ.join(", "),
        if given {
            "--param and the description's defaults"
        } else {
            "the description's defaults (--param sets them)"
        }
    )
}
