//! The header of a probing program: what the program is, what the operator checks in the
//! order the program runs, and what its plan assumes.

use super::ProbeOptions;
use super::sequence::Clearance;
use formats::nc::Dialect;
use model_spec::units::short;
use model_spec::{AxisKind, Machine};

/// The lines (without comment marks) of the header of a program of `passes` poses probed and
/// `hits` hits, which retracts to `clearance`; `duration_s` its nominal duration (s), when
/// known.
pub(crate) fn lines(
    m: &Machine,
    o: &ProbeOptions,
    clearance: &Clearance,
    passes: usize,
    hits: usize,
    duration_s: Option<f64>,
) -> Vec<String> {
    let d = o.dialect;
    let r = o.effective_radius_mm();
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
    h.push(format!(
        "{test}{passes} poses probed, {} hits each, {hits} hits",
        o.pattern.len()
    ));
    if let Some(deg) = o.backlash_overshoot_deg {
        h.push(format!(
            "each pose twice: rotary axes arriving from {} deg below (+), then above (-)",
            short(deg)
        ));
    }
    h.push(match d {
        Dialect::Iso => {
            "dialect iso: Fanuc-type G-code with custom macro B (G31, #5061, DPRNT)".into()
        }
        Dialect::LinuxCnc => "dialect linuxcnc: LinuxCNC G-code (G38.2, PROBEOPEN)".into(),
        Dialect::Heidenhain => "dialect heidenhain: conversational (TCH PROBE 0, FN 16)".into(),
    });
    h.push("positions: machine coordinates, absolute, mm, degrees".into());
    h.push("CHECK BEFORE AND DURING THE RUN, IN THIS ORDER:".into());
    match d {
        Dialect::Iso => {
            h.push("1 coordinates: G53 rapids; the feed moves and G31 run in".into());
            h.push("  G54, WHICH THIS PROGRAM SETS TO ZERO (G10 L2 P1): note".into());
            h.push("  your G54 and restore it after; G52, G92, the external".into());
            h.push("  offset (EXT), G68, G51: all zero/off. #5061-#5063 are".into());
            h.push("  then machine coordinates: axes 1-3 must be X Y Z".into());
        }
        Dialect::LinuxCnc => {
            h.push("1 coordinates: G53 on every move but G38.2, which runs in".into());
            h.push("  G54, WHICH THIS PROGRAM SETS TO ZERO (G10 L2 P1 ... R0):".into());
            h.push("  note your G54 and restore it after; G92.1 here clears".into());
            h.push("  G92 offsets; G52 must be zero".into());
        }
        Dialect::Heidenhain => {
            h.push("1 coordinates: M91 on every positioning block; cycle 0".into());
            h.push("  and Q115-Q117 use the active preset: ACTIVATE A PRESET".into());
            h.push("  OF 0 IN EVERY AXIS (the machine datum); no datum shift,".into());
            h.push("  no tilted working plane".into());
        }
    }
    match d {
        Dialect::Iso | Dialect::LinuxCnc => {
            h.push("2 probe: in the spindle, switched on, calibrated; G49 here:".into());
            h.push("  no tool length acts; the probe's length (tip centre) is".into());
            h.push("  in the kinematic parameters below".into());
        }
        Dialect::Heidenhain => {
            h.push("2 probe: in the spindle, the active tool (TOOL CALL before".into());
            h.push("  this program) with L 0 in the tool table: its length (tip".into());
            h.push("  centre) is in the kinematic parameters below; calibrated".into());
        }
    }
    h.push(format!(
        "  tip radius {} mm, sphere radius {} mm: R_eff {} mm",
        short(o.tip_radius_mm),
        short(o.sphere_radius_mm),
        short(r)
    ));
    h.push(match d {
        Dialect::Iso => "3 TCP off: no G43.4/G43.5 (G49 here cancels them)".into(),
        Dialect::LinuxCnc => "3 kinematics: trivial (no 5-axis TCP kinematics on)".into(),
        Dialect::Heidenhain => "3 TCP off: FUNCTION RESET TCPM here".into(),
    });
    let rotary: Vec<&str> = m
        .axes
        .iter()
        .filter(|a| a.kind == AxisKind::Rotary)
        .map(|a| a.name.as_str())
        .collect();
    if rotary.is_empty() {
        h.push("4 no rotary axis".into());
    } else {
        h.push(format!(
            "4 rotary axes {}: absolute angles, no roll-over axis,",
            rotary.join(" ")
        ));
        h.push(match d {
            Dialect::Iso => "  no shortest path (Fanuc: parameter 1008 ROA = 0)".into(),
            Dialect::LinuxCnc => "  no shortest path (no WRAPPED_ROTARY)".into(),
            Dialect::Heidenhain => "  no shortest path (M127 here; not modulo)".into(),
        });
    }
    h.push("5 sphere: its centre at the ball position of the kinematic".into());
    h.push(format!(
        "  parameters, within {} mm; clean; its stem along the table",
        short(
            super::LogOptions::DEFAULT_MAX_DEVIATION_MM
                .min(0.5 * o.pretouch_mm.min(o.overtravel_mm))
        )
    ));
    h.push(format!(
        "  normal (no hit within {} deg of it)",
        short(o.stem_clearance_deg)
    ));
    let z = &m.axes[clearance.axis].name;
    h.push(format!(
        "6 clearance: {z} rapids to {z}{} mm (machine) first, the",
        short(clearance.position_mm)
    ));
    h.push("  rotary axes turn there at every pose: that space must be free".into());
    h.push("7 spindle: M5, then M19 orients the probe (its calibrated angle)".into());
    h.push(match d {
        Dialect::Iso => "8 STOP (M0): probe on, the DPRNT device (I/O channel) ready".into(),
        Dialect::LinuxCnc => format!(
            "8 STOP (M0): probe on; the log is {}.txt (PROBEOPEN)",
            o.log_name
        ),
        Dialect::Heidenhain => format!(
            "8 STOP: probe on; {}.A beside this program, no old {}.TXT",
            o.log_name, o.log_name
        ),
    });
    h.push(format!(
        "9 each pose: rotary axes at the clearance, rapid to {} mm",
        short(o.safe_mm)
    ));
    h.push(format!(
        "  above the sphere; each hit at F{}: over it, down to {} mm",
        short(o.position_feed_mm_min),
        short(o.pretouch_mm)
    ));
    match d {
        Dialect::Iso => {
            h.push(format!(
                "  off it, G31 at F{} to {} mm beyond the contact",
                short(o.probe_feed_mm_min),
                short(o.overtravel_mm)
            ));
            h.push("  (no trip: macro alarm #3000=101), DPRNT of #5061-#5063,".into());
            h.push("  back, up".into());
        }
        Dialect::LinuxCnc => {
            h.push(format!(
                "  off it, G38.2 at F{} to {} mm beyond the contact",
                short(o.probe_feed_mm_min),
                short(o.overtravel_mm)
            ));
            h.push("  (no trip: an error stops the program), back, up".into());
        }
        Dialect::Heidenhain => {
            h.push("  off it, cycle 0 along the axis nearest the normal, then".into());
            h.push("  FN 16 of Q115-Q117, back, up. Probe table: F".into());
            h.push(format!(
                "  {} mm/min, DIST {} mm (pre-touch + overtravel)",
                short(o.probe_feed_mm_min),
                short(o.pretouch_mm + o.overtravel_mm)
            ));
        }
    }
    h.push(format!(
        "10 end: {z} to the clearance, the log closed, end of program"
    ));
    if m.symbols.is_empty() {
        h.push("kinematic parameters: none".into());
    } else {
        h.push("kinematic parameters (sphere centre, probe length), mm:".into());
        for (s, v) in m.symbols.iter().zip(&o.params) {
            h.push(format!("  {} = {}", s.name, short(*v)));
        }
    }
    h.push("program clock: t = 0 s when the program resumes after the stop".into());
    if let Some(t) = duration_s {
        h.push(format!(
            "nominal duration {} s (rapid rates of the plan, no acceleration)",
            short(t)
        ));
    }
    h.push("the probe plan (CSV) gives every hit's pose, contact and direction".into());
    h
}
