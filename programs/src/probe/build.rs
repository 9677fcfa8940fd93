//! The probing program, its plan and its nominal times, from the poses of a record.

use super::geometry::{Frame, HitPoints, hit_points, turned};
use super::text::Writer;
use super::{MAX_DISTANCE_MM, MAX_OVERSHOOT_DEG, ProbeError, ProbeOptions, ProbeProgram};
use formats::csv::column_order;
use formats::nc::MAX_DECIMALS;
use formats::poses::axis_words;
use model_spec::units::{short, significant};
use model_spec::{AxisKind, Machine};
use nalgebra::Vector3;
use simulation::exact::VirtualMachine;
use simulation::probe::PatternTurn;
use simulation::record::Record;

/// The operator's message at the stop.
pub(crate) const STOP_MESSAGE: &str =
    "check the probe is on and the sphere clean at its place, then cycle start";

/// The longest log name.
const MAX_LOG_NAME: usize = 32;

/// The poses of a program: each probed once, or twice (arriving from below, then above).
pub(crate) struct Pass {
    /// The pose's label in the plan and the hits CSV (`p3`, `p3+`, `p3-`).
    pub(crate) label: String,
    /// Its index among the record's samples.
    pub(crate) sample: usize,
    /// The rotary angles the axes come from before the pose's (file units), when they arrive
    /// from one side.
    pub(crate) from: Option<Vec<f64>>,
}

fn check_options(m: &Machine, o: &ProbeOptions) -> Result<(), ProbeError> {
    let bad = |s: String| Err(ProbeError::Options(s));
    let positive = |x: f64| x.is_finite() && x > 0.0;
    let r = o.effective_radius_mm();
    if o.pattern.is_empty() {
        return bad("a probing pattern without a hit".into());
    }
    for (i, h) in o.pattern.iter().enumerate() {
        let (point, approach) = (Vector3::from(h.point), Vector3::from(h.approach));
        let unit =
            |v: &Vector3<f64>| v.iter().all(|x| x.is_finite()) && (v.norm() - 1.0).abs() <= 1e-9;
        if !unit(&point) || !unit(&approach) || point.dot(&approach) > -0.5 {
            return bad(format!(
                "hit {} of the pattern: its point and approach must be unit vectors, the approach into the sphere (within 60° of the inward normal)",
                i + 1
            ));
        }
    }
    if !positive(o.sphere_radius_mm) || !positive(o.tip_radius_mm) {
        return bad(format!(
            "sphere radius {} mm and tip radius {} mm: both above 0",
            significant(o.sphere_radius_mm),
            significant(o.tip_radius_mm)
        ));
    }
    let distance = |what: &str, x: f64, max: f64| {
        if positive(x) && x <= max {
            Ok(())
        } else {
            Err(ProbeError::Options(format!(
                "{what} {} mm: above 0 and at most {} mm",
                significant(x),
                short(max)
            )))
        }
    };
    distance("pre-touch distance", o.pretouch_mm, MAX_DISTANCE_MM)?;
    distance(
        "overtravel",
        o.overtravel_mm,
        MAX_DISTANCE_MM.min(r * (1.0 - 1e-9)),
    )?;
    distance("safe height", o.safe_mm, MAX_DISTANCE_MM)?;
    if o.safe_mm <= o.pretouch_mm {
        return bad(format!(
            "safe height {} mm above the sphere: above the pre-touch distance {} mm, so that every hit is approached from above",
            short(o.safe_mm),
            short(o.pretouch_mm)
        ));
    }
    for (what, f) in [
        ("probing feed", o.probe_feed_mm_min),
        ("positioning feed", o.position_feed_mm_min),
    ] {
        if !(1.0..=99_999.0).contains(&f) {
            return bad(format!("{what} {} mm/min: from 1 to 99999", significant(f)));
        }
    }
    let max_decimals = if o.dialect == formats::nc::Dialect::Iso {
        7
    } else {
        MAX_DECIMALS
    };
    if o.decimals > max_decimals {
        return bad(format!(
            "{} decimals asked for, at most {max_decimals}{}",
            o.decimals,
            if max_decimals == 7 {
                " (DPRNT prints at most 8 digits)"
            } else {
                ""
            }
        ));
    }
    if !(1..=9999).contains(&o.program_number) {
        return bad(format!(
            "program number {}: from 1 to 9999",
            o.program_number
        ));
    }
    if o.params.len() != m.symbols.len() || o.params.iter().any(|v| !v.is_finite()) {
        return bad(format!(
            "{} kinematic parameters for the {} symbols of machine {}, all finite",
            o.params.len(),
            m.symbols.len(),
            m.name
        ));
    }
    if o.rates.len() != m.axes.len()
        || o.rates
            .iter()
            .any(|r| !positive(r.rapid_per_min) || !positive(r.feed_per_min))
    {
        return bad(format!(
            "{} axis rates for the {} axes of machine {}, every rate above 0",
            o.rates.len(),
            m.axes.len(),
            m.name
        ));
    }
    if let Some(d) = o.backlash_overshoot_deg
        && !(positive(d) && d <= MAX_OVERSHOOT_DEG)
    {
        return bad(format!(
            "rotary overshoot {}°: above 0 and at most {MAX_OVERSHOOT_DEG}°",
            significant(d)
        ));
    }
    if !(o.stem_clearance_deg.is_finite() && (0.0..=90.0).contains(&o.stem_clearance_deg)) {
        return bad(format!(
            "stem clearance {}°: from 0 to 90°",
            significant(o.stem_clearance_deg)
        ));
    }
    let name_ok = !o.log_name.is_empty()
        && o.log_name.len() <= MAX_LOG_NAME
        && o.log_name
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'-' || b == b'_');
    if !name_ok {
        return bad(format!(
            "log name `{}`: 1 to {MAX_LOG_NAME} letters, digits, `-` or `_`",
            o.log_name
        ));
    }
    if o.clearance_mm.is_some_and(|z| !z.is_finite()) {
        return bad("the clearance must be a finite position, mm".into());
    }
    Ok(())
}

/// The axes a dialect's log holds, by letter: LinuxCNC logs X Y Z A B C U V W; ISO reads the
/// skip position of the first three axes (`#5061`–`#5063`) and Heidenhain `Q115`–`Q117`,
/// which must be X, Y, Z.
fn check_log_axes(m: &Machine, o: &ProbeOptions, linear: &[usize]) -> Result<(), ProbeError> {
    let letters: Vec<char> = axis_words(m).iter().map(|w| w.letter).collect();
    let ok = match o.dialect {
        formats::nc::Dialect::LinuxCnc => letters.iter().all(|c| "XYZABCUVW".contains(*c)),
        _ => linear.iter().map(|&a| letters[a]).collect::<String>() == "XYZ",
    };
    if ok && o.dialect == formats::nc::Dialect::Iso {
        // DPRNT[X#31[ab]]: a + b ≤ 8 digits, b the decimals.
        let digits = 8 - o.decimals.min(8) as i32;
        let reach = linear
            .iter()
            .map(|&a| m.axes[a].limits[0].abs().max(m.axes[a].limits[1].abs()))
            .fold(0.0, f64::max);
        if reach >= 10f64.powi(digits) {
            return Err(ProbeError::Options(format!(
                "machine {}: DPRNT prints at most 8 digits, {} after the point with {} decimals, and a stroke reaches {} mm: fewer decimals (rtest path --decimals)",
                m.name,
                o.decimals,
                o.decimals,
                short(reach)
            )));
        }
    }
    if ok {
        Ok(())
    } else {
        Err(ProbeError::Options(format!(
            "machine {}: the {} dialect logs {}, not the axes {}",
            m.name,
            o.dialect.name(),
            match o.dialect {
                formats::nc::Dialect::LinuxCnc => "X Y Z A B C U V W",
                formats::nc::Dialect::Iso => "the linear axes X Y Z (#5061-#5063)",
                formats::nc::Dialect::Heidenhain => "the linear axes X Y Z (Q115-Q117)",
            },
            letters
                .iter()
                .map(char::to_string)
                .collect::<Vec<_>>()
                .join(" ")
        )))
    }
}

/// The passes over the poses of `poses`: one per pose, or two with an overshoot (from below,
/// then from above), labelled `p<sample>`, `p<sample>+`, `p<sample>-`.
fn passes(
    m: &Machine,
    written: &[Vec<f64>],
    o: &ProbeOptions,
    poses: &Record,
) -> Result<Vec<Pass>, ProbeError> {
    let mut out = Vec::new();
    for (i, w) in written.iter().enumerate() {
        let Some(d) = o.backlash_overshoot_deg else {
            out.push(Pass {
                label: format!("p{}", i + 1),
                sample: i,
                from: None,
            });
            continue;
        };
        for (sign, suffix) in [(-1.0, '+'), (1.0, '-')] {
            let mut from = w.clone();
            for a in m.rotary_axes() {
                from[a] += sign * d;
                let [lo, hi] = m.axes[a].limits;
                if from[a] < lo || from[a] > hi {
                    return Err(ProbeError::Pose {
                        place: poses.place(i),
                        message: format!(
                            "axis {} at {}° cannot arrive from {}° ({}° {} the pose): outside its range [{}, {}]°; probe this pose from one side only",
                            m.axes[a].name,
                            short(w[a]),
                            short(from[a]),
                            short(d),
                            if sign < 0.0 { "below" } else { "above" },
                            short(lo),
                            short(hi)
                        ),
                    });
                }
            }
            out.push(Pass {
                label: format!("p{}{suffix}", i + 1),
                sample: i,
                from: Some(from),
            });
        }
    }
    Ok(out)
}

/// The probing program of the poses of `poses` (commands in mm and rad; only their rotary
/// axes are used, the linear ones follow from the nominal inverse kinematics) on machine `m`,
/// and its plan (see the module documentation of [`crate::probe`]).
///
/// # Errors
/// [`ProbeError::Options`] for an option out of range, no pose, a machine without three linear
/// axes or whose axes the dialect's log cannot name, a clearance nearer the sphere than the
/// safe height; [`ProbeError::Pose`] for a pose without inverse kinematics, a hit that cannot
/// be probed there (below the equator along the tool axis, near the stem, outside the
/// strokes); [`ProbeError::ReadBack`] when the written program does not read back as written.
pub fn probe_program(
    m: &Machine,
    poses: &Record,
    o: &ProbeOptions,
) -> Result<ProbeProgram, ProbeError> {
    check_options(m, o)?;
    if poses.samples.is_empty() {
        return Err(ProbeError::Options(
            "no pose: a probing program needs at least one".into(),
        ));
    }
    let vm = VirtualMachine::new(m);
    let letters: Vec<char> = axis_words(m).iter().map(|w| w.letter).collect();
    let w = Writer::new(o.dialect, letters, column_order(m), o.decimals);
    // The written rotary angles of every pose, then its frame and hits.
    let mut written: Vec<Vec<f64>> = Vec::new();
    let mut frames: Vec<(Frame, Vec<HitPoints>)> = Vec::new();
    for (i, s) in poses.samples.iter().enumerate() {
        let err = |message: String| ProbeError::Pose {
            place: poses.place(i),
            message,
        };
        if s.commands.len() != m.axes.len() {
            return Err(err(format!(
                "{} commands for the {} axes of machine {}",
                s.commands.len(),
                m.axes.len(),
                m.name
            )));
        }
        let given = formats::poses::to_file_units(m, &s.commands);
        let (_, rotary) = w
            .words(&given, |a| m.axes[a].kind == AxisKind::Rotary)
            .map_err(err)?;
        let mut pose = given.clone();
        for (a, v) in rotary {
            pose[a] = v;
        }
        let frame = Frame::new(m, &vm, &o.params, &pose).map_err(|e| {
            if e.starts_with("machine ") {
                ProbeError::Options(e)
            } else {
                err(e)
            }
        })?;
        // The pattern turns with the probe and, pose after pose, about the stylus.
        let turn = PatternTurn::new(frame.pose.tool_rotation.matrix(), o.azimuth.offset_rad(i));
        let hits = o
            .pattern
            .iter()
            .map(|h| hit_points(&frame, &turned(&turn, h), o))
            .collect::<Result<Vec<_>, _>>()
            .map_err(err)?;
        written.push(frame.centre.clone());
        frames.push((frame, hits));
    }
    check_log_axes(m, o, &frames[0].0.linear())?;
    let passes = passes(m, &written, o, poses)?;
    let clearance = super::sequence::clearance(m, &vm, o, &frames)?;
    let sequence = super::sequence::Sequence {
        m,
        o,
        frames: &frames,
        passes: &passes,
        clearance,
        poses,
    };
    let (text, expected, plan, duration_s) = sequence.write(w)?;
    super::check::read_back(m, o, &text, &expected)?;
    let format_file = (o.dialect == formats::nc::Dialect::Heidenhain).then(|| {
        let d = o.decimals;
        format!("\"X %+.{d}LF Y %+.{d}LF Z %+.{d}LF\", Q115, Q116, Q117;\n")
    });
    Ok(ProbeProgram {
        text,
        plan,
        format_file,
        passes: passes.len(),
        duration_s,
    })
}
