//! The touch-probe calibration program of `rtest path --probe FILE --nc D -o PROGRAM`: the
//! flags, and the program with its probe plan (and, Heidenhain, the format file of its
//! `FN 16`), from the poses of the test `rtest path` computes (docs/probe-programs.md).

use super::generator_args::GeneratorArgs;
use super::path_nc::NcArgs;
use super::{Error, VerbResult, check_outputs, pose_args};
use crate::Done;
use formats::nc::Dialect;
use formats::probe::read_probe_instrument;
use model_spec::Machine;
use model_spec::units::short;
use output::{Outputs, Target};
use programs::probe::{
    ProbeError, ProbeOptions, default_pattern, format_probe_plan, probe_program,
};
use std::path::{Path, PathBuf};

/// Flags of the probing program (with `--probe`).
#[derive(Debug, clap::Args)]
pub struct ProbeArgs {
    /// With --nc: write a touch-probe calibration program instead of an R-test program; FILE
    /// is the probe instrument (TOML: tip_radius_mm, sphere_radius_mm; docs/probe.md). The
    /// sphere's centre is the ball of the machine description and the probe's tip centre its
    /// tool point (--param); every pose of the test is probed with the default 9-hit pattern,
    /// which turns with the probe and, pose after pose, 22.5° about the stylus.
    #[arg(
        long,
        value_name = "FILE",
        requires = "nc",
        conflicts_with_all = ["continuous", "settle_s", "window_s", "rapid", "sample_rate_hz", "max_gap_mm", "approach_mm", "approach_feed"]
    )]
    pub probe: Option<PathBuf>,
    /// --probe: how far outside the sphere each probing move starts, mm (default 2).
    #[arg(long, value_name = "MM", requires = "probe", value_parser = super::args::between(1e-3, 50.0))]
    pub pretouch_mm: Option<f64>,
    /// --probe: how far beyond the nominal contact a probing move goes before it fails, mm
    /// (default 2; below the sphere's radius plus the tip's).
    #[arg(long, value_name = "MM", requires = "probe", value_parser = super::args::between(1e-3, 50.0))]
    pub overtravel_mm: Option<f64>,
    /// --probe: the height of the moves between the hits above the sphere, mm (default 10;
    /// above --pretouch-mm).
    #[arg(long, value_name = "MM", requires = "probe", value_parser = super::args::between(1e-3, 50.0))]
    pub safe_mm: Option<f64>,
    /// --probe: the probing feed, mm/min (default 100).
    #[arg(long, value_name = "MM_PER_MIN", requires = "probe", value_parser = super::args::between(1.0, 99_999.0))]
    pub probe_feed: Option<f64>,
    /// --probe: the feed of the moves near the sphere, mm/min (default 1000).
    #[arg(long, value_name = "MM_PER_MIN", requires = "probe", value_parser = super::args::between(1.0, 99_999.0))]
    pub position_feed: Option<f64>,
    /// --probe: probe every pose twice, its rotary axes arriving from below, then from above
    /// (poses `p1+`, `p1-`): the difference of the two centres is their backlash.
    #[arg(long, requires = "probe")]
    pub both_directions: bool,
    /// --both-directions: how far past the pose the rotary axes turn before they arrive,
    /// degrees (default 2; at most 30).
    #[arg(long, value_name = "DEG", requires = "both_directions", value_parser = super::args::between(1e-3, 30.0))]
    pub overshoot_deg: Option<f64>,
    /// --probe: the least angle between a hit and the sphere's stem (along the table normal),
    /// degrees (default 30).
    #[arg(long, value_name = "DEG", requires = "probe", value_parser = super::args::between(0.0, 90.0))]
    pub stem_clearance_deg: Option<f64>,
}

/// The log's name on the control from the program's file: its stem, letters, digits, `-` and
/// `_` kept, at most 32 characters; `rtest-probe` for standard output or a stem with none.
fn log_name(program: &Target) -> String {
    let stem = match program {
        Target::Path(p) => p
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        Target::Stdout => String::new(),
    };
    let kept: String = stem
        .chars()
        .filter(|c| c.is_ascii_alphanumeric() || *c == '-' || *c == '_')
        .take(32)
        .collect();
    if kept.is_empty() {
        "rtest-probe".into()
    } else {
        kept
    }
}

/// What `rtest path` hands over to write a probing program.
pub struct PathParts<'a> {
    /// `--machine` as given.
    pub machine_arg: &'a str,
    /// `--param`.
    pub param: Option<&'a str>,
    /// The generator's flags.
    pub generator: &'a GeneratorArgs,
    /// `-o`.
    pub output: Option<&'a Target>,
}

/// Runs `rtest path --probe`: the probing program of the test's poses (`args` the whole of
/// `rtest path`'s flags, for the test's poses).
pub fn run(
    args: &super::path::PathArgs,
    m: &Machine,
    parts: PathParts,
    probe: &ProbeArgs,
    nc: &NcArgs,
) -> VerbResult<Done> {
    let Some(file) = &probe.probe else {
        return Err(Error::usage("--probe: no probe instrument file given"));
    };
    let dialect = nc
        .dialect()?
        .ok_or_else(|| Error::usage("--probe needs --nc iso|linuxcnc|heidenhain"))?;
    let target = parts
        .output
        .ok_or_else(|| Error::usage("--probe: give the program's file with -o"))?;
    let plan_target = nc.plan_target(target)?;
    let name = log_name(target);
    let format_target = match (dialect, target) {
        (Dialect::Heidenhain, Target::Path(p)) => Some(Target::Path(
            p.parent()
                .unwrap_or(Path::new(""))
                .join(format!("{name}.A")),
        )),
        (Dialect::Heidenhain, Target::Stdout) => {
            return Err(Error::usage(
                "--probe --nc heidenhain: the program's FN 16 reads a format file written beside it: give the program's file with -o FILE",
            ));
        }
        _ => None,
    };
    let mut inputs: Vec<(&str, &Path)> = vec![("--probe", file.as_path())];
    inputs.extend(super::machine_file(parts.machine_arg).map(|p| ("--machine", p)));
    let mut outputs: Vec<(&str, &Target)> = vec![("-o", target), ("--plan", &plan_target)];
    if let Some(f) = &format_target {
        outputs.push(("-o (its FN 16 format file)", f));
    }
    check_outputs(&inputs, &outputs, &[])?;
    let instrument =
        read_probe_instrument(file).map_err(|e| Error::input(format!("--probe: {e}")))?;
    let params = pose_args::params(m, parts.param)?;
    let gen_opts = parts.generator.options()?;
    let (test_name, record) = match args.test.as_deref() {
        // A path CSV of poses (`rtest plan --probe --poses-out`): a file that is no test name.
        Some(f) if Path::new(f).is_file() && simulation::paths::builtin_path(m, f).is_none() => {
            let record = formats::paths::load_path(m, f, &formats::csv::ReadOptions::default())
                .map_err(|e| Error::input(format!("--test: {e}")))?;
            (f.to_string(), record)
        }
        _ => {
            let (spec, record) = super::path::poses(args, m, &params, &gen_opts)?;
            (spec.name, record)
        }
    };
    let mut o = ProbeOptions::new(
        m,
        dialect,
        default_pattern(),
        instrument.sphere_radius_mm,
        instrument.tip_radius_mm,
    );
    o.params = params.clone();
    o.test_name = test_name;
    o.log_name = name.clone();
    o.clearance_mm = nc.clearance_mm;
    if let Some(d) = super::args::nc_decimals(nc.decimals)? {
        o.decimals = d;
    }
    if let Some(v) = probe.pretouch_mm {
        o.pretouch_mm = v;
    }
    if let Some(v) = probe.overtravel_mm {
        o.overtravel_mm = v;
    }
    if let Some(v) = probe.safe_mm {
        o.safe_mm = v;
    }
    if let Some(v) = probe.probe_feed {
        o.probe_feed_mm_min = v;
    }
    if let Some(v) = probe.position_feed {
        o.position_feed_mm_min = v;
    }
    if probe.both_directions {
        o.backlash_overshoot_deg = Some(probe.overshoot_deg.unwrap_or(2.0));
    }
    if let Some(v) = probe.stem_clearance_deg {
        o.stem_clearance_deg = v;
    }
    let p = probe_program(m, &record, &o).map_err(|e| match e {
        ProbeError::Options(why) => Error::usage(format!("--probe: {why}")),
        ProbeError::Pose { .. } => Error::usage(format!("--test: {e}")),
        ProbeError::ReadBack(_) => Error::computation(format!("--probe: {e}")),
    })?;
    let comments = vec![
        format!(
            "probe plan written by rtest {} for machine {}, test {}: {} poses probed, {} hits, {} program",
            env!("CARGO_PKG_VERSION"),
            m.name,
            o.test_name,
            p.passes,
            p.plan.rows.len(),
            dialect.name()
        ),
        format!(
            "sphere radius {} mm, tip radius {} mm ({}): the contacts are R_eff = {} mm from the nominal centre",
            short(o.sphere_radius_mm),
            short(o.tip_radius_mm),
            file.display(),
            short(o.effective_radius_mm())
        ),
        "axes: the planned contact in mm and degrees (machine coordinates); nx,ny,nz: the probing move's direction, bed frame".into(),
        "pattern: 9 hits defined in the probe's frame, turned by each pose's nominal tool rotation and by 0, 22.5, 45, 67.5° about the stylus, pose after pose".into(),
        "t_s: the nominal time of the contact from the resume after the stop, s; line: the program's probing block".into(),
        "rtest probe-log turns the control's log into the probe hits CSV with this plan (docs/probe-programs.md)".into(),
    ];
    let plan = format_probe_plan(m, &p.plan, &comments)
        .map_err(|e| Error::computation(format!("--plan: {e}")))?;
    let mut files = Outputs::new();
    files.add("-o", target.clone(), p.text);
    files.add("--plan", plan_target.clone(), plan);
    if let (Some(f), Some(text)) = (format_target, p.format_file) {
        files.add("-o (its FN 16 format file)", f, text);
    }
    let log = match dialect {
        Dialect::LinuxCnc => {
            format!("{name}.txt (PROBEOPEN, in LinuxCNC's configuration directory)")
        }
        Dialect::Iso => "the DPRNT output of the POPEN device".into(),
        Dialect::Heidenhain => format!("{name}.TXT (FN 16, beside the program)"),
    };
    let text = format!(
        "Probing program ({}) of test {} of machine {}: {} poses probed, {} hits, nominal duration {} s.\n  Sphere {} mm, tip {} mm; the control logs to {log}.\n  Then: rtest probe-log --machine {} --plan {} --log LOG --nc {} -o hits.csv\n",
        dialect.name(),
        o.test_name,
        m.name,
        p.passes,
        p.plan.rows.len(),
        short(p.duration_s),
        short(o.sphere_radius_mm),
        short(o.tip_radius_mm),
        parts.machine_arg,
        plan_target,
        dialect.name()
    );
    Ok(Done::new(text, files, matches!(target, Target::Stdout)))
}
