//! The header of a measurement program: comment lines stating everything the program and its
//! timing plan assume, so that the person at the control can check it before the run.

use crate::measure::plan::TimingPlan;
use crate::measure::{MeasureMode, MeasureOptions, MeasurementProgram, StaticMotion};
use formats::nc::Dialect;
use model_spec::units::short;
use model_spec::{AxisKind, Machine};

/// The header's lines (without comment marks), each short enough for a control's display.
/// The lines (without comment marks) of the header of the program of `plan`, whose moves leave
/// the ball by at most `gap_mm` (mm).
pub(crate) fn lines(
    m: &Machine,
    o: &MeasureOptions,
    plan: &TimingPlan,
    gap_mm: f64,
) -> Vec<String> {
    let iso = o.dialect == Dialect::Iso;
    let n = plan.rows.len();
    let mut h = vec![format!(
        "written by rtest {} for machine {}",
        env!("CARGO_PKG_VERSION"),
        m.name
    )];
    let test = if o.test_name.is_empty() {
        String::new()
    } else {
        format!("test {}, ", o.test_name)
    };
    let mode = match o.mode {
        MeasureMode::Static(_) => "static: measured at rest",
        MeasureMode::Continuous(_) => "continuous: measured on the fly",
    };
    h.push(format!("{test}{n} poses, {mode}"));
    h.push("positions: machine coordinates, absolute, mm and degrees".into());
    if iso {
        h.push("no work offset, shift, rotation or scaling active".into());
        h.push("(G54-G59, G52, G92, G68, G51 cancelled or zero)".into());
        h.push("tool length compensation off (G49)".into());
        h.push("tool centre point control off (no G43.4, G43.5)".into());
    } else {
        h.push("the preset must be the machine datum: no datum shift,".into());
        h.push("no tilted working plane, no rotation or scaling".into());
        h.push("tool centre point control off (FUNCTION RESET TCPM;".into());
        h.push("M129 on controls without FUNCTION TCPM)".into());
        h.push("the active tool must have length 0 and radius 0".into());
    }
    h.push("the position of the nest is in the machine description,".into());
    h.push("so no tool length may act on the positions".into());
    h.push("rotary axes: absolute angles, no shortest-path rollover".into());
    if m.symbols.is_empty() {
        h.push("kinematic parameters: none".into());
    } else {
        h.push("kinematic parameters (ball and nest), mm:".into());
        for (s, v) in m.symbols.iter().zip(&o.params) {
            h.push(format!("  {} = {}", s.name, short(*v)));
        }
    }
    h.push("start with the nest on the ball at pose 1: the first".into());
    h.push(format!(
        "move goes there at {} mm/min",
        short(o.approach_feed_mm_min)
    ));
    h.push("program clock: t = 0 s at rest at pose 1 after that move".into());
    match o.mode {
        MeasureMode::Static(t) => {
            h.push(format!(
                "each pose: move, dwell {} s = settle {} s + window {} s",
                short(t.settle_s + t.window_s),
                short(t.settle_s),
                short(t.window_s)
            ));
            match t.motion {
                StaticMotion::Feed if iso => {
                    h.push("moves: G1 in inverse time (G93: F = 1/min), all axes".into());
                    h.push("interpolated; G61 exact stop".into());
                }
                StaticMotion::Feed => heidenhain_feed(&mut h),
                StaticMotion::Rapid if iso => {
                    h.push("moves: G0; rapid moves must be interpolated (all".into());
                    h.push("axes in a straight line), else the nest hits the ball".into());
                }
                StaticMotion::Rapid => h.push("moves: L ... FMAX, all axes interpolated".into()),
            }
            if let Some(code) = t.marker_m {
                h.push(format!(
                    "M{code} marks each window (PLC time not in the plan)"
                ));
            }
        }
        MeasureMode::Continuous(t) => {
            h.push(format!(
                "lead-in and lead-out dwells {} s, R-test sampling {} Hz",
                short(t.lead_s),
                short(t.sample_rate_hz)
            ));
            if iso {
                h.push("moves: G1 in inverse time (G93: F = 1/min), G64".into());
                h.push("continuous path, the time of each block commanded".into());
            } else {
                heidenhain_feed(&mut h);
            }
        }
    }
    h.push("assumed rates (feed, rapid, acceleration; 0 neglected):".into());
    for i in formats::csv::column_order(m) {
        let (a, r) = (&m.axes[i], &o.rates[i]);
        let (u, acc) = match a.kind {
            AxisKind::Linear => ("mm/min", "mm/s2"),
            AxisKind::Rotary => ("deg/min", "deg/s2"),
        };
        h.push(format!(
            "  {} {} {u}, {} {u}, {} {acc}",
            a.name,
            short(r.feed_per_min),
            short(r.rapid_per_min),
            short(r.acceleration_per_s2)
        ));
    }
    h.push(format!(
        "largest nest-ball gap along a move: {} mm (nominal)",
        short(gap_mm)
    ));
    h.push(format!(
        "planned duration {} s from t = 0",
        short(plan.duration_s())
    ));
    h.push("the timing plan (CSV) gives the window of each pose".into());
    h
}

/// The Heidenhain feed assumption.
fn heidenhain_feed(h: &mut Vec<String>) {
    h.push("moves: L, F in mm/min along the combined move of all".into());
    h.push("axes, degrees counted as mm (no M116): check the run".into());
    h.push("time against the plan in a dry run".into());
}

/// The comment lines of a plan's CSV (for [`crate::measure::format_plan`]): what wrote
/// it, for which machine, test, dialect and mode, the program clock, the columns' units, and
/// where the timing assumptions are stated.
pub fn plan_comments(m: &Machine, o: &MeasureOptions, program: &MeasurementProgram) -> Vec<String> {
    let test = if o.test_name.is_empty() {
        String::new()
    } else {
        format!(", test {}", o.test_name)
    };
    vec![
        format!(
            "sample-timing plan written by rtest {} for machine {}{test}: {} poses, {} program in {}",
            env!("CARGO_PKG_VERSION"),
            m.name,
            program.plan.rows.len(),
            program.plan.kind.name(),
            o.dialect.name()
        ),
        "program clock: t = 0 s at rest at pose 1 after the program's first move".into(),
        "axes in mm and degrees as the program commands them; times in s: arrive_s at rest (or passing),"
            .into(),
        "start_s .. end_s the measuring window (an instant when equal), depart_s the next move".into(),
        "the timing assumptions are in the program's header (docs/measurement-programs.md)".into(),
    ]
}
