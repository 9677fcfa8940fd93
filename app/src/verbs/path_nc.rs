//! The NC measurement program of `rtest path --nc`: the flags and the program with its timing
//! plan, from the record of poses `rtest path` computed (docs/measurement-programs.md).

use super::{Error, VerbResult};
use formats::nc::Dialect;
use model_spec::Machine;
use output::Target;
use programs::measure::{
    ContinuousTiming, MeasureMode, MeasureOptions, StaticMotion, StaticTiming, format_plan,
    measurement_program, plan_comments,
};
use simulation::record::Record;
use std::path::PathBuf;

/// Flags of the measurement program (with `--nc`).
#[derive(Debug, clap::Args)]
pub struct NcArgs {
    /// Write an NC measurement program of the test instead of a path CSV: `iso` (Fanuc-type
    /// G-code), `linuxcnc` (LinuxCNC G-code) or `heidenhain` (conversational). -o is then the
    /// program; --plan its sample-timing plan.
    #[arg(long, value_name = "iso|linuxcnc|heidenhain")]
    pub nc: Option<String>,
    /// With --nc: the sample-timing plan (CSV) to write beside the program (default: the
    /// program's file name with `.plan.csv` in place of its extension).
    #[arg(long, value_name = "FILE", requires = "nc")]
    pub plan: Option<Target>,
    /// With --nc: measure on the fly (feed moves through the poses, the R-test sampling at
    /// --sample-rate-hz) instead of at rest after each move.
    #[arg(long, requires = "nc")]
    pub continuous: bool,
    /// Static program: settle time at each pose before its measuring window, s.
    #[arg(long, value_name = "S", requires = "nc", conflicts_with = "continuous")]
    pub settle_s: Option<f64>,
    /// Static program: the measuring window at each pose, s.
    #[arg(long, value_name = "S", requires = "nc", conflicts_with = "continuous")]
    pub window_s: Option<f64>,
    /// Static program: rapid moves between the poses (interpolated) instead of feed moves.
    #[arg(long, requires = "nc", conflicts_with = "continuous")]
    pub rapid: bool,
    /// Continuous program: the R-test's sampling rate, Hz.
    #[arg(long, value_name = "HZ", requires = "continuous")]
    pub sample_rate_hz: Option<f64>,
    /// The farthest the nest may leave the ball between two poses on the nominal machine, mm
    /// (default 0.5; at most 5): a move that leaves it farther is refused.
    #[arg(long, value_name = "MM", requires = "nc", value_parser = super::args::between(1e-3, 5.0))]
    pub max_gap_mm: Option<f64>,
    /// Decimals of the axis words (default 4: 0.0001 mm, 0.0001°; at most 9).
    #[arg(long, value_name = "N", requires = "nc")]
    pub decimals: Option<usize>,
    /// The clearance position of the tool-axis slide (Z on most machines), mm in machine
    /// coordinates: the program rapids there first, turns the rotary axes there, and returns
    /// there at the end (default: the end of its stroke away from the ball, from the machine
    /// description).
    #[arg(
        long,
        value_name = "MM",
        requires = "nc",
        allow_negative_numbers = true
    )]
    pub clearance_mm: Option<f64>,
    /// How far above the first pose, along the tool axis, the approach's rapid ends and its
    /// slow feed onto the ball starts; the retract feeds as far off the last pose. mm (default
    /// 30; at most 500).
    #[arg(long, value_name = "MM", requires = "nc", value_parser = super::args::between(1e-3, 500.0))]
    pub approach_mm: Option<f64>,
    /// The feed of the approach onto the ball and of the retract off it, mm/min (default 500).
    #[arg(long, value_name = "MM_PER_MIN", requires = "nc", value_parser = super::args::between(1.0, 99_999.0))]
    pub approach_feed: Option<f64>,
}

impl NcArgs {
    /// The dialect of `--nc`, if given.
    pub fn dialect(&self) -> VerbResult<Option<Dialect>> {
        self.nc
            .as_deref()
            .map(|n| {
                Dialect::from_name(n).ok_or_else(|| {
                    Error::usage(format!(
                        "--nc: `{n}` is not a dialect (iso, linuxcnc or heidenhain; Fanuc-type controls read iso)"
                    ))
                })
            })
            .transpose()
    }

    /// The plan's target: --plan, else the program's file with `.plan.csv`.
    pub fn plan_target(&self, program: &Target) -> VerbResult<Target> {
        if let Some(p) = &self.plan {
            return Ok(p.clone());
        }
        match program {
            Target::Path(p) => {
                let mut plan = PathBuf::from(p);
                plan.set_extension("plan.csv");
                Ok(Target::Path(plan))
            }
            Target::Stdout => Err(Error::usage(
                "--nc with -o -: give the timing plan's file with --plan FILE",
            )),
        }
    }

    /// The options of the program for `m` at kinematic parameters `params` (mm).
    fn options(
        &self,
        m: &Machine,
        dialect: Dialect,
        test: &str,
        params: &[f64],
    ) -> VerbResult<MeasureOptions> {
        let mode = if self.continuous {
            let mut t = ContinuousTiming::default();
            if let Some(r) = self.sample_rate_hz {
                t.sample_rate_hz = r;
            }
            MeasureMode::Continuous(t)
        } else {
            let mut t = StaticTiming::default();
            if let Some(s) = self.settle_s {
                t.settle_s = s;
            }
            if let Some(w) = self.window_s {
                t.window_s = w;
            }
            if self.rapid {
                t.motion = StaticMotion::Rapid;
            }
            MeasureMode::Static(t)
        };
        let mut o = MeasureOptions::new(m, dialect, mode);
        o.test_name = test.to_string();
        o.params = params.to_vec();
        if let Some(g) = self.max_gap_mm {
            o.max_gap_mm = g;
        }
        if let Some(d) = super::args::nc_decimals(self.decimals)? {
            o.decimals = d;
        }
        o.clearance_mm = self.clearance_mm;
        if let Some(a) = self.approach_mm {
            o.approach_mm = a;
        }
        if let Some(f) = self.approach_feed {
            o.approach_feed_mm_min = f;
        }
        Ok(o)
    }
}

/// The measurement program of the poses of `record` (test `test` of `m`, planned at `params`)
/// and its timing plan's CSV, with a line for people.
pub fn program(
    args: &NcArgs,
    dialect: Dialect,
    m: &Machine,
    test: &str,
    record: &Record,
    params: &[f64],
) -> VerbResult<(String, String, String)> {
    let o = args.options(m, dialect, test, params)?;
    let p = measurement_program(m, record, &o).map_err(|e| match e {
        programs::measure::MeasureError::Options(why) => Error::usage(format!("--nc: {why}")),
        other => Error::computation(format!("--nc: {other}")),
    })?;
    let plan = format_plan(m, &p.plan, &plan_comments(m, &o, &p))
        .map_err(|e| Error::computation(format!("--plan: {e}")))?;
    let note = format!(
        "Measurement program ({}, {}): {} poses, planned duration {} s; largest nest-ball gap along a move {} mm (nominal).\n",
        dialect.name(),
        if args.continuous {
            "continuous"
        } else {
            "static"
        },
        p.plan.rows.len(),
        model_spec::units::short(p.plan.duration_s()),
        model_spec::units::short(p.largest_gap_mm)
    );
    Ok((p.text, plan, note))
}
