//! `rtest probe-log`: the control's log of a touch-probe program (`rtest path --probe`) turned
//! into the probe hits CSV with the program's probe plan (docs/probe-programs.md).

use super::{EXIT_CODES, Error, VerbResult, check_outputs};
use crate::Done;
use formats::csv::CsvError;
use formats::probe::{format_probe_hits, parse_probe_hits};
use model_spec::AxisKind;
use model_spec::units::short;
use output::{Outputs, Target};
use programs::probe::{LogOptions, hits_from_log, read_probe_log, read_probe_plan};
use std::path::{Path, PathBuf};

const LONG_ABOUT: &str = "\
Turns the log a touch-probe calibration program wrote on the control into the probe hits CSV \
(docs/probe.md) with the program's probe plan. Details: docs/probe-programs.md.

--plan is the probe plan `rtest path --probe` wrote beside the program (every hit's pose, planned \
contact, probing direction, nominal time). --log is what the control wrote: LinuxCNC's PROBEOPEN \
file (nine numbers per trip, X Y Z A B C U V W), the ISO program's DPRNT lines (X… Y… Z…) or the \
Heidenhain program's FN 16 lines (X… Y… Z…); --nc says which. The trips are matched with the plan's \
hits in order: the counts must be equal, every latched position within --max-deviation-mm of its \
planned contact, and LinuxCNC's rotary axes the plan's. The hits take the latched linear axes and \
the plan's pose labels, rotary axes, directions and times (the logs have none). Any mismatch is an \
error naming the log's line, and nothing is written.";

/// Flags of `rtest probe-log`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Turn a touch-probe program's log into the probe hits CSV with its probe plan",
    long_about = LONG_ABOUT,
    after_help = EXIT_CODES
)]
pub struct ProbeLogArgs {
    /// Built-in machine (see `rtest machines`) or path of a machine TOML file: the program's.
    #[arg(long, value_name = "NAME|FILE")]
    machine: String,
    /// The probe plan written with the program (`rtest path --probe … --plan`).
    #[arg(long, value_name = "FILE")]
    plan: PathBuf,
    /// The control's log of the latched positions.
    #[arg(long, value_name = "FILE")]
    log: PathBuf,
    /// The program's dialect, which sets the log's format: iso (DPRNT), linuxcnc (PROBEOPEN)
    /// or heidenhain (FN 16).
    #[arg(long, value_name = "iso|linuxcnc|heidenhain")]
    nc: String,
    /// The probe hits CSV to write (`-`: standard output).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Target,
    /// The farthest a latched position may lie from its planned contact, mm (default 0.5;
    /// keep it below the program's overtravel).
    #[arg(long, value_name = "MM", value_parser = super::args::positive)]
    max_deviation_mm: Option<f64>,
}

/// Runs `rtest probe-log`.
pub fn run(args: &ProbeLogArgs) -> VerbResult<Done> {
    let dialect = formats::nc::Dialect::from_name(&args.nc).ok_or_else(|| {
        Error::usage(format!(
            "--nc: `{}` is not a dialect (iso, linuxcnc or heidenhain; Fanuc-type controls read iso)",
            args.nc
        ))
    })?;
    let m = super::load_machine(&args.machine)?;
    let mut inputs: Vec<(&str, &Path)> = vec![("--plan", &args.plan), ("--log", &args.log)];
    inputs.extend(super::machine_file(&args.machine).map(|p| ("--machine", p)));
    check_outputs(&inputs, &[("-o", &args.output)], &[])?;
    let plan = read_probe_plan(&args.plan, &m).map_err(|e| Error::input(format!("--plan: {e}")))?;
    let trips =
        read_probe_log(&args.log, dialect, &m).map_err(|e| Error::input(format!("--log: {e}")))?;
    let mut o = LogOptions::default();
    if let Some(d) = args.max_deviation_mm {
        o.max_deviation_mm = d;
    }
    let log_name = args.log.display().to_string();
    let hits = hits_from_log(&m, &plan, &trips, &log_name, &o).map_err(|e| match e {
        CsvError::Record(why) => Error::usage(format!("--max-deviation-mm: {why}")),
        e => Error::input(format!("--log: {e}")),
    })?;
    // The largest distance of a latch from its planned contact, mm, and its hit.
    let mut largest = (0.0f64, String::new());
    for (hit, p) in hits.poses.iter().flat_map(|x| &x.hits).zip(&plan.rows) {
        let d = m
            .axes
            .iter()
            .enumerate()
            .filter(|(_, a)| a.kind == AxisKind::Linear)
            .map(|(a, _)| (hit.axes[a] - p.axes[a]).powi(2))
            .sum::<f64>()
            .sqrt();
        if d >= largest.0 {
            largest = (d, format!("pose {}, hit {}", p.pose, p.hit));
        }
    }
    let comments = vec![
        format!(
            "probe hits written by rtest {} for machine {} from the log {} ({}) with the plan {}",
            env!("CARGO_PKG_VERSION"),
            m.name,
            args.log.display(),
            dialect.name(),
            args.plan.display()
        ),
        "axes: the latched linear axes, the plan's rotary axes; nx,ny,nz, t_s: the plan's (the nominal times of the contacts)".into(),
    ];
    let csv = format_probe_hits(&m, &hits, &comments)
        .map_err(|e| Error::computation(format!("-o: {e}")))?;
    let back = parse_probe_hits(&args.output.to_string(), &csv, &m).map_err(|e| {
        Error::computation(format!(
            "-o: the hits do not read back, so they are not written: {e}"
        ))
    })?;
    if back.hit_count() != plan.rows.len() {
        return Err(Error::computation(
            "-o: the hits do not read back as written, so they are not written",
        ));
    }
    let text = format!(
        "Matched the {} trips of {} with the plan's hits: {} poses. Largest distance of a latch from its planned contact: {} mm ({}; at most {} mm allowed).\n",
        trips.len(),
        args.log.display(),
        hits.poses.len(),
        short(largest.0),
        largest.1,
        short(o.max_deviation_mm)
    );
    let mut files = Outputs::new();
    files.add("-o", args.output.clone(), csv);
    Ok(Done::new(
        text,
        files,
        matches!(args.output, Target::Stdout),
    ))
}
