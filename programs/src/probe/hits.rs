//! A control's log and the program's plan turned into probe hits: each trip matched, in
//! order, with its planned hit, checked, and given the plan's pose label, rotary angles,
//! approach direction and nominal time.

use super::log::LoggedTrip;
use super::plan::ProbePlan;
use formats::csv::{CsvError, Ctx};
use formats::probe::{ProbeHit, ProbeHits, ProbePose};
use model_spec::units::{short, significant};
use model_spec::{AxisKind, Machine};

/// How a log is checked against its plan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LogOptions {
    /// The farthest a latched position may lie from its planned contact, mm (the distance over
    /// the linear axes' commands): beyond it the sphere is not where the plan puts it, the
    /// probe tripped on something else, or the log is not of this plan. Above 0. Default
    /// [`LogOptions::DEFAULT_MAX_DEVIATION_MM`]; keep it below the program's overtravel, so that
    /// the end of a probing move that did not trip is refused too.
    pub max_deviation_mm: f64,
    /// How far a rotary axis the log holds (LinuxCNC) may be from the plan's, degrees. Default
    /// 1e-4° (the log's six decimals and the program's).
    pub rotary_tolerance_deg: f64,
}

impl LogOptions {
    /// The default of [`LogOptions::max_deviation_mm`], mm.
    pub const DEFAULT_MAX_DEVIATION_MM: f64 = 0.5;
}

impl Default for LogOptions {
    fn default() -> Self {
        LogOptions {
            max_deviation_mm: LogOptions::DEFAULT_MAX_DEVIATION_MM,
            rotary_tolerance_deg: 1e-4,
        }
    }
}

/// The probe hits of the trips `trips` of the log named `log` (in messages), of a program of
/// machine `m` whose plan is `plan`: trip `k` is the plan's hit `k`. Each hit has the log's
/// linear axes, the plan's rotary axes, approach direction and time; its `line` is 0 (not read
/// from a hits file).
///
/// # Errors
/// [`CsvError::Format`] at the log's line: fewer trips than hits (at the end of the log, naming
/// the first hit without a trip), more trips than hits (at the first trip too many), a latched
/// position farther than `o.max_deviation_mm` from its planned contact, a rotary axis of the
/// log not the plan's, a linear axis the log does not hold; [`CsvError::Record`] for options
/// out of range.
pub fn hits_from_log(
    m: &Machine,
    plan: &ProbePlan,
    trips: &[LoggedTrip],
    log: &str,
    o: &LogOptions,
) -> Result<ProbeHits, CsvError> {
    let valid = o.max_deviation_mm.is_finite()
        && o.max_deviation_mm > 0.0
        && o.rotary_tolerance_deg.is_finite()
        && o.rotary_tolerance_deg >= 0.0;
    if !valid {
        return Err(CsvError::Record(format!(
            "largest deviation {} mm and rotary tolerance {} deg: above 0 and at least 0",
            significant(o.max_deviation_mm),
            significant(o.rotary_tolerance_deg)
        )));
    }
    let cx = Ctx { file: log };
    let rows = &plan.rows;
    let describe = |k: usize| {
        let p = &rows[k];
        format!("pose {}, hit {} (program line {})", p.pose, p.hit, p.line)
    };
    if trips.len() < rows.len() {
        let line = trips.last().map_or(1, |t| t.line + 1);
        return Err(cx.err(
            line,
            None,
            format!(
                "the log ends after {} trip(s), the plan has {} hits: the first without a trip is {}: the probe did not trip there, or the program stopped",
                trips.len(),
                rows.len(),
                describe(trips.len())
            ),
        ));
    }
    if trips.len() > rows.len() {
        return Err(cx.err(
            trips[rows.len()].line,
            None,
            format!(
                "trip {}: the plan has only {} hits (a log an earlier run appended to? delete the log before the run)",
                rows.len() + 1,
                rows.len()
            ),
        ));
    }
    let mut poses: Vec<ProbePose> = Vec::new();
    for (k, (trip, p)) in trips.iter().zip(rows).enumerate() {
        let mut axes = p.axes.clone();
        let mut squared = 0.0;
        for (a, ax) in m.axes.iter().enumerate() {
            match (ax.kind, trip.axes.get(a).copied().flatten()) {
                (AxisKind::Linear, Some(v)) => {
                    squared += (v - p.axes[a]).powi(2);
                    axes[a] = v;
                }
                (AxisKind::Linear, None) => {
                    return Err(cx.err(
                        trip.line,
                        None,
                        format!("the log does not hold axis {}", ax.name),
                    ));
                }
                (AxisKind::Rotary, Some(v)) if (v - p.axes[a]).abs() > o.rotary_tolerance_deg => {
                    return Err(cx.err(
                        trip.line,
                        None,
                        format!(
                            "trip {} ({}): axis {} at {} deg, the plan's pose is at {} deg: the log is not of this plan",
                            k + 1,
                            describe(k),
                            ax.name,
                            short(v),
                            short(p.axes[a])
                        ),
                    ));
                }
                (AxisKind::Rotary, _) => {}
            }
        }
        let deviation = squared.sqrt();
        if deviation > o.max_deviation_mm {
            let linear: Vec<String> = m
                .axes
                .iter()
                .enumerate()
                .filter(|(_, x)| x.kind == AxisKind::Linear)
                .map(|(a, x)| format!("{}{}", x.name, short(p.axes[a])))
                .collect();
            return Err(cx.err(
                trip.line,
                None,
                format!(
                    "trip {} ({}) latched {} mm from its planned contact {}, beyond the {} mm allowed: the sphere is not where the plan puts it, the probe tripped on something else, or the log is not of this plan",
                    k + 1,
                    describe(k),
                    short(deviation),
                    linear.join(" "),
                    short(o.max_deviation_mm)
                ),
            ));
        }
        let hit = ProbeHit {
            line: 0,
            axes,
            direction: p.direction,
            t_s: p.t_s,
        };
        match poses.last_mut() {
            Some(last) if last.label == p.pose => last.hits.push(hit),
            _ => poses.push(ProbePose {
                label: p.pose.clone(),
                hits: vec![hit],
            }),
        }
    }
    Ok(ProbeHits { poses })
}
