//! The touch-probe programs (`programs::probe`), read back by `programs::reader` in every
//! dialect: every block classified, the order (setup, log, clearance, orientation, stop, per
//! pose the rotary axes, per hit positioning, pre-touch, probing move, latch and log, retract),
//! the points checked on the nominal machine independently of the writer (the pre-touch point
//! `R_eff + pre-touch` from the sphere's centre, the probing move's end `R_eff − overtravel`
//! and its direction, the plan's contact on the sphere, no other move nearer the sphere than
//! the pre-touch point), exact blocks, the words' decimals, both directions, the refusals.

use crate::common::{builtin, commands};
use formats::nc::Dialect;
use formats::poses::{axis_words, from_file_units};
use model_spec::{AxisKind, Machine, Side};
use programs::probe::{
    PatternAzimuth, PatternHit, ProbeError, ProbeOptions, ProbeProgram, check_order,
    default_pattern, hit_steps, probe_program,
};
use programs::reader::{ProbeKind, ReadProgram, Step, read_program};
use simulation::exact::VirtualMachine;
use simulation::paths::record_from_commands;
use simulation::record::Record;

pub(crate) const DIALECTS: [Dialect; 3] = [Dialect::Iso, Dialect::LinuxCnc, Dialect::Heidenhain];

/// The sphere's radius and the tip's, mm.
pub(crate) const SPHERE_MM: f64 = 12.5;
pub(crate) const TIP_MM: f64 = 1.5;

/// The default pattern (probe frame), checked bit for bit against `fitting::sphere`'s.
pub(crate) fn pattern() -> Vec<PatternHit> {
    let p = default_pattern();
    let fit: Vec<PatternHit> = fitting::sphere::default_pattern(1.0)
        .iter()
        .map(|h| PatternHit {
            point: [h.point_mm.x, h.point_mm.y, h.point_mm.z],
            approach: [h.approach.x, h.approach.y, h.approach.z],
        })
        .collect();
    assert_eq!(p, fit);
    p
}

/// Poses of `m` at the rotary angles `angles` (degrees, by axis name); linear axes 0.
pub(crate) fn poses(m: &Machine, angles: &[&[(&str, f64)]]) -> Record {
    let c: Vec<Vec<f64>> = angles
        .iter()
        .map(|a| {
            let rad: Vec<(&str, f64)> = a.iter().map(|(n, d)| (*n, d.to_radians())).collect();
            commands(m, &rad)
        })
        .collect();
    let n = c.len();
    record_from_commands(c, (0..n).map(|i| i as f64).collect())
}

/// Three poses of `seed-ac`.
pub(crate) fn seed_poses(m: &Machine) -> Record {
    poses(
        m,
        &[
            &[],
            &[("A", 30.0), ("C", 90.0)],
            &[("A", -45.0), ("C", 200.0)],
        ],
    )
}

/// Five poses of `head-table-bc`, the head tilted both ways by up to 60°.
pub(crate) fn head_poses(m: &Machine) -> Record {
    poses(
        m,
        &[
            &[],
            &[("B", -60.0)],
            &[("B", 30.0), ("C", 90.0)],
            &[("B", 60.0), ("C", 200.0)],
            &[("B", -45.0), ("C", 300.0)],
        ],
    )
}

pub(crate) fn options(m: &Machine, d: Dialect) -> ProbeOptions {
    ProbeOptions::new(m, d, pattern(), SPHERE_MM, TIP_MM)
}

/// The tip's position relative to the sphere's centre, bed frame (mm), at `pose` (file units)
/// on the nominal machine at its default parameters.
pub(crate) fn gap(m: &Machine, pose: &[f64]) -> [f64; 3] {
    let vm = VirtualMachine::new(m);
    let q = from_file_units(m, pose);
    let p = m.default_parameters();
    let t = vm
        .nominal_chain_transform(Side::Tool, &q, &p)
        .translation
        .vector;
    let w = vm
        .nominal_chain_transform(Side::Work, &q, &p)
        .translation
        .vector;
    [t.x - w.x, t.y - w.y, t.z - w.z]
}

fn norm(v: &[f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn read(m: &Machine, p: &ProbeProgram, d: Dialect) -> ReadProgram {
    read_program("probe.nc", &p.text, d, &axis_words(m)).expect("reads")
}

/// Checks program `p` of `m` in dialect `d` under `o` against the nominal machine.
fn check_program(m: &Machine, p: &ProbeProgram, d: Dialect, o: &ProbeOptions, what: &str) {
    let read = read(m, p, d);
    check_order(&read, d).unwrap_or_else(|e| panic!("{what}: {e}"));
    let r = o.effective_radius_mm();
    let b = &read.blocks;
    // The hits, each from its pre-touch block.
    let starts: Vec<usize> = (0..b.len())
        .filter(|&i| b[i].step == Step::PreTouch)
        .collect();
    assert_eq!(starts.len(), p.plan.rows.len(), "{what}");
    let steps = hit_steps(d);
    for (k, (&i, planned)) in starts.iter().zip(&p.plan.rows).enumerate() {
        let what = format!("{what}, hit {}", k + 1);
        let got: Vec<Step> = b[i..i + steps.len()].iter().map(|x| x.step).collect();
        assert_eq!(got, steps, "{what}");
        let pre = &b[i].motion.as_ref().unwrap().pose;
        let probe = b[i + 1..].iter().find(|x| x.motion.is_some()).unwrap();
        let back = &b[i + steps.len() - 1].motion.as_ref().unwrap().pose;
        assert_eq!(
            pre, back,
            "{what}: the retract returns to the pre-touch point"
        );
        // 4 decimals: each word within 5e-5 of the exact point.
        let tol = 2e-4;
        assert!(
            (norm(&gap(m, pre)) - (r + o.pretouch_mm)).abs() < tol,
            "{what}"
        );
        assert!(
            (norm(&gap(m, &planned.axes)) - r).abs() < 1e-9,
            "{what}: the contact"
        );
        assert_eq!(planned.line, probe.line, "{what}: the plan's line");
        let mv = probe.motion.as_ref().unwrap();
        let kind = probe.probe.unwrap().kind;
        let dir = match (d, kind) {
            (Dialect::Iso, ProbeKind::Skip) | (Dialect::LinuxCnc, ProbeKind::StraightProbe) => {
                assert!(
                    (norm(&gap(m, &mv.pose)) - (r - o.overtravel_mm)).abs() < tol,
                    "{what}"
                );
                assert_eq!(
                    probe.probe.unwrap().feed,
                    Some(o.probe_feed_mm_min),
                    "{what}"
                );
                let (a, e) = (gap(m, pre), gap(m, &mv.pose));
                let v = [e[0] - a[0], e[1] - a[1], e[2] - a[2]];
                let n = norm(&v);
                [v[0] / n, v[1] / n, v[2] / n]
            }
            (Dialect::Heidenhain, ProbeKind::ReferencePlane { axis, positive, .. }) => {
                assert_eq!(
                    &mv.pose, pre,
                    "{what}: cycle 0 starts at the pre-touch point"
                );
                let mut moved = pre.clone();
                moved[axis] += if positive { 1.0 } else { -1.0 };
                let (a, e) = (gap(m, pre), gap(m, &moved));
                let v = [e[0] - a[0], e[1] - a[1], e[2] - a[2]];
                let n = norm(&v);
                [v[0] / n, v[1] / n, v[2] / n]
            }
            other => panic!("{what}: {other:?}"),
        };
        let cos: f64 = (0..3).map(|j| dir[j] * planned.direction[j]).sum();
        assert!(
            cos > 1.0 - 1e-6,
            "{what}: direction {dir:?} vs {:?}",
            planned.direction
        );
        // The contact lies on the probing line, ahead of the pre-touch point.
        let (a, c) = (gap(m, pre), gap(m, &planned.axes));
        let along: f64 = (0..3).map(|j| (c[j] - a[j]) * dir[j]).sum();
        let off = (0..3)
            .map(|j| (c[j] - a[j] - along * dir[j]).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!(along > 0.0 && off < tol, "{what}: along {along}, off {off}");
    }
    // No move but the probing moves comes nearer the sphere than the pre-touch point, and every
    // position lies within the strokes.
    let mut last: Option<Vec<f64>> = None;
    for x in b {
        let Some(mv) = &x.motion else { continue };
        if mv.pose.iter().all(|v| !v.is_nan()) {
            m.check_pose(&from_file_units(m, &mv.pose)).unwrap();
        }
        if x.step != Step::Probe
            && let Some(from) = &last
            && from.iter().chain(&mv.pose).all(|v| !v.is_nan())
        {
            for s in 0..=16 {
                let u = s as f64 / 16.0;
                let q: Vec<f64> = from
                    .iter()
                    .zip(&mv.pose)
                    .map(|(a, b)| a + u * (b - a))
                    .collect();
                let dist = norm(&gap(m, &q));
                // Heidenhain's cycle 0 probes along a machine axis: on a tilted head its
                // pre-touch point may be below the equator seen along the tool axis, reached
                // at least half the pre-touch distance outside the sphere.
                let least = if d == Dialect::Heidenhain {
                    r + 0.5 * o.pretouch_mm
                } else {
                    r + o.pretouch_mm
                };
                assert!(
                    dist > least - 2e-4,
                    "{what}: line {} comes {dist} mm from the centre",
                    x.line
                );
            }
        }
        if x.step != Step::Probe {
            last = Some(mv.pose.clone());
        }
    }
}

#[test]
fn every_dialect_reads_back_in_order_with_its_points_on_the_nominal_machine() {
    let seed = builtin("seed-ac");
    let nutating = builtin("nutating-table-bc");
    let head = builtin("head-table-bc");
    let cases = [
        (&seed, seed_poses(&seed)),
        (
            &nutating,
            poses(&nutating, &[&[], &[("B", 40.0), ("C", 135.0)]]),
        ),
        (&head, head_poses(&head)),
    ];
    for (m, poses) in &cases {
        for d in DIALECTS {
            let o = options(m, d);
            let p = probe_program(m, poses, &o).unwrap_or_else(|e| panic!("{} {d:?}: {e}", m.name));
            assert_eq!(p.plan.rows.len(), 9 * poses.samples.len());
            assert_eq!(p.passes, poses.samples.len());
            assert_eq!(p.format_file.is_some(), d == Dialect::Heidenhain);
            check_program(m, &p, d, &o, &format!("{} {d:?}", m.name));
            // The plan's times increase, from the stop's resume.
            assert!(p.plan.rows.windows(2).all(|w| w[1].t_s > w[0].t_s));
            assert!(p.plan.rows[0].t_s > 0.0 && p.duration_s > p.plan.rows.last().unwrap().t_s);
        }
    }
}

/// The lines of `text` that start with `prefix` (a Heidenhain block number taken off).
fn lines_starting<'a>(text: &'a str, prefix: &str) -> Vec<&'a str> {
    text.lines()
        .map(|l| {
            l.trim_start_matches(|c: char| c.is_ascii_digit())
                .trim_start()
        })
        .filter(|l| l.starts_with(prefix))
        .collect()
}

#[test]
fn the_probing_blocks_are_written_exactly() {
    let m = builtin("seed-ac");
    let one = poses(&m, &[&[]]);
    // At A0 C0 the centre is at X217.504 Y-0.279 Z56.661 (X moves the table: the +x side of
    // the sphere is at a smaller X); R_eff 14, pre-touch 2, overtravel 2.
    let p = probe_program(&m, &one, &options(&m, Dialect::LinuxCnc)).unwrap();
    let t = &p.text;
    assert_eq!(lines_starting(t, "G10")[0], "G10 L2 P1 X0 Y0 Z0 A0 C0 R0");
    assert_eq!(lines_starting(t, "G92.1").len(), 1);
    assert_eq!(
        lines_starting(t, "(PROBEOPEN"),
        ["(PROBEOPEN rtest-probe.txt)"]
    );
    assert_eq!(lines_starting(t, "(PROBECLOSE"), ["(PROBECLOSE)"]);
    let g38 = lines_starting(t, "G38.2");
    assert_eq!(g38.len(), 9);
    assert_eq!(g38[0], "G38.2 X205.5040 Y-0.2790 Z56.6610 F100.000");
    assert_eq!(g38[1], "G38.2 X217.5040 Y11.7210 Z56.6610 F100.000");
    assert_eq!(g38[8], "G38.2 X217.5040 Y-0.2790 Z68.6610 F100.000");
    assert!(t.contains(
        "G53 G1 X201.5040 Y-0.2790 Z56.6610 F1000.000\nG38.2 X205.5040 Y-0.2790 Z56.6610 F100.000\nG53 G1 X201.5040 Y-0.2790 Z56.6610 F1000.000\n"
    ));

    let p = probe_program(&m, &one, &options(&m, Dialect::Iso)).unwrap();
    assert!(p.text.contains(
        "G1 X201.5040 Y-0.2790 Z56.6610 F1000.000\nG31 X205.5040 Y-0.2790 Z56.6610 F100.000\n#31=#5061\n#32=#5062\n#33=#5063\nIF[[ABS[#31-205.5040]+ABS[#32+0.2790]+ABS[#33-56.6610]]LT0.0100]THEN#3000=101(PROBE DID NOT TRIGGER)\nDPRNT[X#31[44]*Y#32[44]*Z#33[44]]\nG1 X201.5040 Y-0.2790 Z56.6610 F1000.000\n"
    ));
    assert_eq!(lines_starting(&p.text, "POPEN").len(), 1);
    assert_eq!(lines_starting(&p.text, "PCLOS").len(), 1);
    assert_eq!(
        lines_starting(&p.text, "G10")[0],
        "G10 L2 P1 X0 Y0 Z0 A0 C0"
    );

    let p = probe_program(&m, &one, &options(&m, Dialect::Heidenhain)).unwrap();
    let cycles = lines_starting(&p.text, "TCH PROBE");
    assert_eq!(cycles.len(), 18);
    assert_eq!(cycles[0], "TCH PROBE 0.0 REFERENCE PLANE Q1 X+");
    assert_eq!(cycles[1], "TCH PROBE 0.1 X+201.5040 Y-0.2790 Z+56.6610");
    assert_eq!(cycles[2], "TCH PROBE 0.0 REFERENCE PLANE Q1 Y-");
    // Hit 5 (45°, R/2 up) is probed along X, from where its probing line along X meets the
    // sphere of R_eff + 2 mm; the pole along −Z.
    assert_eq!(cycles[8], "TCH PROBE 0.0 REFERENCE PLANE Q1 X+");
    assert_eq!(cycles[16], "TCH PROBE 0.0 REFERENCE PLANE Q1 Z-");
    assert_eq!(cycles[17], "TCH PROBE 0.1 X+217.5040 Y-0.2790 Z+72.6610");
    assert_eq!(
        lines_starting(&p.text, "FN 16")[0],
        "FN 16: F-PRINT rtest-probe.A / rtest-probe.TXT"
    );
    assert_eq!(
        p.format_file.as_deref(),
        Some("\"X %+.4LF Y %+.4LF Z %+.4LF\", Q115, Q116, Q117;\n")
    );
}

/// The axis words of the moving lines of `text` (G-code or Heidenhain): their numbers.
fn numbers(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for l in text.lines() {
        let l = l
            .trim_start_matches(|c: char| c.is_ascii_digit())
            .trim_start();
        if l.starts_with('(') || l.starts_with(';') || l.starts_with('#') || l.starts_with("IF") {
            continue;
        }
        for w in l.split_whitespace() {
            let mut c = w.chars();
            if c.next().is_some_and(|c| "XYZAC".contains(c)) && w.len() > 1 {
                let rest: String = c.collect();
                let digits = rest.trim_start_matches(['+', '-']);
                if digits.starts_with(|c: char| c.is_ascii_digit()) {
                    out.push(rest);
                }
            }
        }
    }
    out
}

#[test]
fn words_keep_the_decimals_asked_for() {
    let m = builtin("seed-ac");
    let poses = seed_poses(&m);
    for (d, decimals) in [
        (Dialect::LinuxCnc, 9),
        (Dialect::Heidenhain, 6),
        (Dialect::Iso, 3),
        (Dialect::Iso, 5),
    ] {
        let mut o = options(&m, d);
        o.decimals = decimals;
        let p = probe_program(&m, &poses, &o).unwrap();
        let words = numbers(&p.text);
        assert!(words.len() > 100);
        for w in &words {
            let frac = w.split_once('.').map_or(0, |(_, f)| f.len());
            // `G10 L2 P1 X0 …` zeroes are the only words without decimals.
            assert!(frac == decimals || w == "0", "{d:?} {decimals}: `{w}`");
        }
        // The pre-touch points lie R_eff + 2 mm from the centre to the words' resolution.
        let read = read(&m, &p, d);
        let tol = 0.5 * 10f64.powi(-(decimals as i32)) * 3f64.sqrt() + 1e-12;
        for b in read.blocks_of(Step::PreTouch) {
            let pose = &b.motion.as_ref().unwrap().pose;
            let e = norm(&gap(&m, pose)) - 16.0;
            assert!(e.abs() <= tol, "{d:?} {decimals}: {e}");
        }
        if d == Dialect::Iso {
            let f = format!("[{}{decimals}]", 8 - decimals);
            assert!(p.text.contains(&format!("DPRNT[X#31{f}*Y#32{f}*Z#33{f}]")));
        }
    }
    // DPRNT prints at most 8 digits: 8 decimals leave none for the integer part.
    let mut o = options(&m, Dialect::Iso);
    o.decimals = 8;
    let e = probe_program(&m, &poses, &o).unwrap_err().to_string();
    assert_eq!(
        e,
        "8 decimals asked for, at most 7 (DPRNT prints at most 8 digits)"
    );
    // With 6 decimals two integer digits remain, and the strokes reach 500 mm.
    o.decimals = 6;
    let e = probe_program(&m, &poses, &o).unwrap_err().to_string();
    assert!(
        e.contains("DPRNT prints at most 8 digits, 6 after the point"),
        "{e}"
    );
}

#[test]
fn both_directions_probe_each_pose_arriving_from_below_then_above() {
    let m = builtin("seed-ac");
    let two = poses(&m, &[&[("A", 10.0)], &[("A", 30.0), ("C", 90.0)]]);
    let (a, c) = (m.axis_by_name("A").unwrap(), m.axis_by_name("C").unwrap());
    for d in DIALECTS {
        let mut o = options(&m, d);
        o.backlash_overshoot_deg = Some(2.0);
        let p = probe_program(&m, &two, &o).unwrap();
        assert_eq!(p.passes, 4);
        let labels: Vec<&str> = p
            .plan
            .rows
            .iter()
            .step_by(9)
            .map(|r| r.pose.as_str())
            .collect();
        assert_eq!(labels, ["p1+", "p1-", "p2+", "p2-"]);
        check_program(&m, &p, d, &o, &format!("{d:?} both directions"));
        // Each pass turns the rotary axes twice: past the pose, then to it.
        let read = read(&m, &p, d);
        let turns: Vec<(f64, f64)> = read
            .moves(Step::Pose)
            .iter()
            .map(|mv| (mv.pose[a], mv.pose[c]))
            .collect();
        assert_eq!(
            turns,
            [
                (8.0, -2.0),
                (10.0, 0.0),
                (12.0, 2.0),
                (10.0, 0.0),
                (28.0, 88.0),
                (30.0, 90.0),
                (32.0, 92.0),
                (30.0, 90.0)
            ],
            "{d:?}"
        );
    }
    // A at the end of its range cannot arrive from beyond it (the sphere's stem, then
    // horizontal, is not in the way of this check).
    let mut o = options(&m, Dialect::LinuxCnc);
    o.backlash_overshoot_deg = Some(2.0);
    o.stem_clearance_deg = 0.0;
    let end = poses(
        &m,
        &[&[("A", 0.0)], &[("A", 30.0), ("C", 90.0)], &[("A", 120.0)]],
    );
    match probe_program(&m, &end, &o) {
        Err(ProbeError::Pose { place, message }) => {
            assert_eq!(place, "sample 3");
            assert!(
                message.starts_with("axis A at 120° cannot arrive from 122°"),
                "{message}"
            );
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn poses_and_options_that_cannot_be_probed_are_refused() {
    let m = builtin("seed-ac");
    let o = options(&m, Dialect::LinuxCnc);
    // At A = 90° the table stands vertical: its stem points along +y, at the +Y hit (the
    // second pose's pattern turned 22.5° about the stylus: 22.5° from the stem).
    let tilted = poses(&m, &[&[], &[("A", 90.0)]]);
    let e = probe_program(&m, &tilted, &o).unwrap_err().to_string();
    assert!(
        e.starts_with("pose at sample 2: the hit at (-0.382683, 0.92388, 0) from the centre (bed frame) is 22.5° from the sphere's stem"),
        "{e}"
    );
    // head-table-bc at B = −90°: the spindle horizontal, the pattern turned with it; the
    // equator hit below the sphere meets the stem (the table normal reversed).
    let head = builtin("head-table-bc");
    let e = probe_program(
        &head,
        &poses(&head, &[&[("B", -90.0)]]),
        &options(&head, Dialect::LinuxCnc),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("pose at sample 1: the hit at (0, 0, -1) from the centre (bed frame) is 0° from the sphere's stem"),
        "{e}"
    );
    let one = poses(&m, &[&[]]);
    let refused = |f: &dyn Fn(&mut ProbeOptions)| {
        let mut o = options(&m, Dialect::Iso);
        f(&mut o);
        probe_program(&m, &one, &o).unwrap_err().to_string()
    };
    assert_eq!(
        refused(&|o| o.safe_mm = 2.0),
        "safe height 2 mm above the sphere: above the pre-touch distance 2 mm, so that every hit is approached from above"
    );
    assert_eq!(
        refused(&|o| o.overtravel_mm = 14.0),
        "overtravel 14 mm: above 0 and at most 14 mm"
    );
    assert_eq!(
        refused(&|o| o.log_name = "probe log".into()),
        "log name `probe log`: 1 to 32 letters, digits, `-` or `_`"
    );
    assert_eq!(
        refused(&|o| o.probe_feed_mm_min = 0.5),
        "probing feed 0.5 mm/min: from 1 to 99999"
    );
    assert_eq!(
        refused(&|o| o.clearance_mm = Some(70.0)),
        "clearance Z 70 mm: a hit's safe height is at Z 80.661 mm, beyond it: give a clearance farther from the sphere (rtest path --clearance-mm) or a lower safe height"
    );
    assert_eq!(
        refused(&|o| o.backlash_overshoot_deg = Some(45.0)),
        "rotary overshoot 45°: above 0 and at most 30°"
    );
    assert_eq!(
        probe_program(&m, &record_from_commands(vec![], vec![]), &o)
            .unwrap_err()
            .to_string(),
        "no pose: a probing program needs at least one"
    );
    // A machine whose rotary axes are all the table's: the probe's axes must be X, Y, Z for ISO.
    assert!(m.axes.iter().filter(|a| a.kind == AxisKind::Linear).count() == 3);
}

#[test]
fn the_reader_refuses_what_it_does_not_know_in_a_probing_program() {
    let m = builtin("seed-ac");
    let axes = axis_words(&m);
    let e = read_program("p.nc", "G90\n#1=5\n", Dialect::Iso, &axes)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("p.nc:2:"), "{e}");
    assert!(
        e.contains("a macro statement the reader does not know"),
        "{e}"
    );
    let e = read_program("p.nc", "G31 F100\n", Dialect::Iso, &axes).unwrap_err();
    assert!(
        e.to_string()
            .contains("a probing block without an axis word"),
        "{e}"
    );
    // G31 is not LinuxCNC's, G38.2 not ISO's.
    assert!(read_program("p.ngc", "G31 X1\n", Dialect::LinuxCnc, &axes).is_err());
    assert!(read_program("p.nc", "G38.2 X1\n", Dialect::Iso, &axes).is_err());
    let e = read_program(
        "p.h",
        "0 BEGIN PGM P MM\n1 TCH PROBE 0.1 X+1\n",
        Dialect::Heidenhain,
        &axes,
    )
    .unwrap_err();
    assert!(e.to_string().contains("without its TCH PROBE 0.0"), "{e}");
    let e = read_program(
        "p.h",
        "0 TCH PROBE 0.0 REFERENCE PLANE Q1 X+\n1 L X+1 R0 FMAX M91\n",
        Dialect::Heidenhain,
        &axes,
    )
    .unwrap_err();
    assert!(e.to_string().starts_with("p.h:2:"), "{e}");
    // LinuxCNC's probe log comments are blocks; in ISO they are comments.
    let r = read_program(
        "p.ngc",
        "(PROBEOPEN log.txt)\n(PROBECLOSE)\n",
        Dialect::LinuxCnc,
        &axes,
    )
    .unwrap();
    let steps: Vec<Step> = r.blocks.iter().map(|b| b.step).collect();
    assert_eq!(steps, [Step::LogOpen, Step::LogClose]);
    assert_eq!(r.blocks[0].statement.as_deref(), Some("log.txt"));
    let r = read_program("p.nc", "(PROBEOPEN log.txt)\n", Dialect::Iso, &axes).unwrap();
    assert!(r.blocks.is_empty());
}

#[test]
fn the_pattern_turns_with_the_tilted_head_and_about_the_stylus_pose_after_pose() {
    // head-table-bc's B tilts the probe: every hit's direction in the plan is the pattern's
    // (probe frame) turned by the pose's nominal tool rotation, from the nominal tool chain
    // here, and by 0°, 22.5°, 45°, 67.5°, 0° about the stylus; no hit is below the sphere's
    // equator seen along the tool axis.
    let m = builtin("head-table-bc");
    let poses = head_poses(&m);
    let vm = VirtualMachine::new(&m);
    let params = m.default_parameters();
    let pattern = pattern();
    for d in DIALECTS {
        let o = options(&m, d);
        let p = probe_program(&m, &poses, &o).unwrap_or_else(|e| panic!("{d:?}: {e}"));
        assert_eq!(p.plan.rows.len(), 9 * poses.samples.len());
        for (i, sample) in poses.samples.iter().enumerate() {
            let tool = vm.nominal_chain_transform(Side::Tool, &sample.commands, &params);
            let r = tool.rotation.matrix();
            let phi = [0.0f64, 22.5, 45.0, 67.5][i % 4].to_radians();
            let axis = r.column(2);
            for (k, h) in pattern.iter().enumerate() {
                let row = &p.plan.rows[9 * i + k];
                let a = h.approach;
                let turned = nalgebra::Vector3::new(
                    a[0] * phi.cos() - a[1] * phi.sin(),
                    a[0] * phi.sin() + a[1] * phi.cos(),
                    a[2],
                );
                let want = r * turned;
                let got = nalgebra::Vector3::from(row.direction);
                if d == Dialect::Heidenhain {
                    // Cycle 0 probes along the machine axis nearest the hit's normal.
                    assert!(got.dot(&want) > 60f64.to_radians().cos() - 1e-12, "{i} {k}");
                } else {
                    assert!((got - want).norm() < 1e-12, "{d:?} pose {i} hit {k}");
                }
                // The hit's point (−approach in the pattern) on the spindle's half.
                assert!((-want).dot(&axis) > -1e-12, "pose {i} hit {k}");
            }
        }
    }
    // With the azimuth fixed, every pose is probed at azimuth 0.
    let mut o = options(&m, Dialect::LinuxCnc);
    o.azimuth = PatternAzimuth::Fixed;
    let fixed = probe_program(&m, &poses, &o).unwrap();
    let cycled = probe_program(&m, &poses, &options(&m, Dialect::LinuxCnc)).unwrap();
    for (i, (f, c)) in fixed.plan.rows.iter().zip(&cycled.plan.rows).enumerate() {
        // The pole lies on the stylus: no azimuth turns it.
        let (pose, hit) = (i / 9, i % 9);
        assert_eq!(
            f.direction == c.direction,
            pose % 4 == 0 || hit == 8,
            "row {i}"
        );
    }
}

#[test]
fn on_a_table_table_machine_the_fixed_pattern_writes_the_bed_frame_program() {
    // seed-ac's tool does not turn: at azimuth 0 the pattern is the bed-frame one, so the
    // first pose of a cycled program and every pose of a fixed one probe along ±X, ±Y, −Z.
    let m = builtin("seed-ac");
    let mut o = options(&m, Dialect::LinuxCnc);
    o.azimuth = PatternAzimuth::Fixed;
    let p = probe_program(&m, &seed_poses(&m), &o).unwrap();
    for (i, row) in p.plan.rows.iter().enumerate() {
        assert_eq!(row.direction, pattern()[i % 9].approach, "row {i}");
    }
}
