//! The header of a measurement program: comment lines stating everything the program and its
//! timing plan assume, so that the person at the control can check it before the run.

use crate::measure::approach::Retreat;
use crate::measure::plan::TimingPlan;
use crate::measure::{MeasureMode, MeasureOptions, MeasurementProgram, StaticMotion};
use formats::nc::Dialect;
use model_spec::units::short;
use model_spec::{AxisKind, Machine};

/// The lines (without comment marks) of the header of the program of `plan`, whose moves leave
/// the ball by at most `gap_mm` (mm) and which comes and goes by `r`: what the program is,
/// what the operator checks, in the order the program runs, then the assumptions of the plan.
pub(crate) fn lines(
    m: &Machine,
    o: &MeasureOptions,
    plan: &TimingPlan,
    gap_mm: f64,
    r: &Retreat,
) -> Vec<String> {
    let d = o.dialect;
    let g_code = d.is_g_code();
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
    h.push(match d {
        Dialect::Iso => "dialect iso: Fanuc-type G-code, G4 P in ms (not LinuxCNC)".into(),
        Dialect::LinuxCnc => "dialect linuxcnc: LinuxCNC G-code, G4 P in s".into(),
        Dialect::Heidenhain => "dialect heidenhain: conversational (Klartext)".into(),
    });
    h.push("positions: machine coordinates, absolute, mm, degrees".into());
    let z = &m.axes[r.axis].name;
    let rotary: Vec<&str> = m
        .axes
        .iter()
        .filter(|a| a.kind == AxisKind::Rotary)
        .map(|a| a.name.as_str())
        .collect();
    let rotary = rotary.join(" ");
    h.push("CHECK BEFORE AND DURING THE RUN, IN THIS ORDER:".into());
    match d {
        Dialect::Iso => {
            h.push("1 coordinates: G53 for the clearance, approach and".into());
            h.push("  retract rapids; the feed moves run in G54, WHICH".into());
            h.push("  THIS PROGRAM SETS TO ZERO (G10 L2 P1): note your G54".into());
            h.push("  and restore it after; G52, G92 shifts, the external".into());
            h.push("  offset (EXT), G68 rotation, G51 scaling: all zero/off".into());
            h.push("2 tool: G49 here cancels tool length compensation;".into());
            h.push("  the nest length is in the machine description".into());
            h.push("3 TCP off: no G43.4/G43.5 (G49 here cancels them)".into());
        }
        Dialect::LinuxCnc => {
            h.push("1 coordinates: G53 on every move (machine coordinates,".into());
            h.push("  no G5x, G52, G92 offset acts on them)".into());
            h.push("2 tool: G49 here cancels tool length offset; the".into());
            h.push("  nest length is in the machine description".into());
            h.push("3 kinematics: trivial (no 5-axis TCP kinematics on):".into());
            h.push("  the axis words must be the positions of the axes themselves".into());
        }
        Dialect::Heidenhain => {
            h.push("1 coordinates: M91 on every positioning block (machine".into());
            h.push("  datum); no tilted working plane (M91 refused there)".into());
            h.push("2 tool: no TOOL CALL here (a call may change tools and".into());
            h.push("  unload the nest); M91 blocks apply no tool length;".into());
            h.push("  still: the active tool must have L 0 and R 0".into());
            h.push("3 TCP off: FUNCTION RESET TCPM here (M129 on controls".into());
            h.push("  without FUNCTION TCPM)".into());
        }
    }
    if !rotary.is_empty() {
        h.push(format!(
            "4 rotary axes {rotary}: absolute angles, 360 is 360"
        ));
        h.push("  not 0: no roll-over (modulo) axis, no shortest path".into());
        h.push(match d {
            Dialect::Iso => "  (Fanuc: parameter 1008 ROA = 0 for these axes)".into(),
            Dialect::LinuxCnc => "  (LinuxCNC: no WRAPPED_ROTARY for these axes)".into(),
            Dialect::Heidenhain => "  (M127 here: shortest path M126 off; not modulo)".into(),
        });
    } else {
        h.push("4 no rotary axis".into());
    }
    h.push(format!(
        "5 clearance: {z} rapids first to {z}{} mm (machine),",
        short(r.clearance_mm)
    ));
    h.push(if rotary.is_empty() {
        "  the other axes stay: the space there must be free".into()
    } else {
        format!("  then {rotary} turn to pose 1 there: the space must be free")
    });
    h.push("6 spindle: M5, then M19 orients the nest before the".into());
    h.push("  approach (at the M19 angle the machine builder set)".into());
    h.push(format!(
        "7 approach: rapid to {} mm above pose 1 along the tool",
        short(o.approach_mm)
    ));
    h.push(format!(
        "  axis, then feed onto the ball at {} mm/min",
        short(o.approach_feed_mm_min)
    ));
    h.push(format!(
        "8 {}: check the nest sits on the ball, start the",
        if g_code { "STOP (M0)" } else { "STOP block" }
    ));
    h.push("  R-test log, cycle start: t = 0 of the timing plan".into());
    h.push(format!(
        "9 end: feed {} mm off the ball along the tool axis,",
        short(o.approach_mm)
    ));
    h.push(format!("  rapid {z} to the clearance, end of program"));
    if m.symbols.is_empty() {
        h.push("kinematic parameters: none".into());
    } else {
        h.push("kinematic parameters (ball and nest), mm:".into());
        for (s, v) in m.symbols.iter().zip(&o.params) {
            h.push(format!("  {} = {}", s.name, short(*v)));
        }
    }
    h.push("program clock: t = 0 s when the program resumes after".into());
    h.push("the stop, the nest at rest on the ball at pose 1".into());
    match o.mode {
        MeasureMode::Static(t) => {
            h.push(format!(
                "each pose: move, dwell {} s = settle {} s + window {} s",
                short(t.settle_s + t.window_s),
                short(t.settle_s),
                short(t.window_s)
            ));
            match t.motion {
                StaticMotion::Feed if g_code => {
                    h.push("moves: G1 in inverse time (G93: F = 1/min), all axes".into());
                    h.push(if d == Dialect::Iso {
                        "interpolated; G61 exact stop".into()
                    } else {
                        "interpolated; G61 exact path".into()
                    });
                }
                StaticMotion::Feed => heidenhain_feed(&mut h),
                StaticMotion::Rapid if g_code => {
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
            match d {
                Dialect::Iso => {
                    h.push("moves: G1 in inverse time (G93: F = 1/min), G64".into());
                    h.push("continuous path, the time of each block commanded".into());
                }
                Dialect::LinuxCnc => {
                    h.push("moves: G1 in inverse time (G93: F = 1/min), G64".into());
                    h.push("P0.01 blending within 0.01 mm, block times commanded".into());
                }
                Dialect::Heidenhain => heidenhain_feed(&mut h),
            }
        }
    }
    h.push("assumed rates (feed, rapid, acceleration; 0 neglected):".into());
    for i in formats::csv::column_order(m) {
        let (a, rt) = (&m.axes[i], &o.rates[i]);
        let (u, acc) = match a.kind {
            AxisKind::Linear => ("mm/min", "mm/s2"),
            AxisKind::Rotary => ("deg/min", "deg/s2"),
        };
        h.push(format!(
            "  {} {} {u}, {} {u}, {} {acc}",
            a.name,
            short(rt.feed_per_min),
            short(rt.rapid_per_min),
            short(rt.acceleration_per_s2)
        ));
    }
    h.push(format!(
        "largest nest-ball gap along a move: {} mm (nominal)",
        short(gap_mm)
    ));
    h.push(format!(
        "planned duration {} s from t = 0 (the retract after)",
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
        "program clock: t = 0 s when the program resumes after its stop (M0, STOP), at rest at pose 1".into(),
        "axes in mm and degrees as the program commands them; times in s: arrive_s at rest (or passing),"
            .into(),
        "start_s .. end_s the measuring window (an instant when equal), depart_s the next move".into(),
        "the timing assumptions are in the program's header (docs/measurement-programs.md)".into(),
    ]
}
