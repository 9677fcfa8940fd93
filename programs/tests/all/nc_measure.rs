//! Measurement programs: the written program reads back as the path's poses at its resolution,
//! in every dialect and mode, over several machines and paths; the timing plan follows its
//! stated model; the plan's CSV reads back exactly and refuses what is malformed. The sequence
//! of the programs (clearance, approach, stop, retract) is tested in `sequence.rs`.

use crate::common;

use common::builtin;
use formats::csv::ReadOptions;
use formats::nc::Dialect;
use formats::paths::load_path;
use formats::poses::{axis_words, to_file_units};
use model_spec::{AxisKind, Machine, parse_machine};
use programs::measure::{
    ContinuousTiming, MeasureError, MeasureMode, MeasureOptions, PlanKind, StaticMotion,
    StaticTiming, TimingPlan, format_plan, measurement_program, parse_plan, plan_comments,
};
use programs::reader::read_program;
use simulation::builtin_path;
use simulation::paths::{fill_linear_ik, record_from_commands};
use simulation::record::Record;

const PATH_AC: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../formats/tests/data/path-ac.csv"
);

fn static_mode() -> MeasureMode {
    MeasureMode::Static(StaticTiming::default())
}

fn continuous_mode() -> MeasureMode {
    MeasureMode::Continuous(ContinuousTiming::default())
}

/// A path of `m` whose rotary axes sweep a grid (degrees per step `step`) and whose linear axes
/// follow the ball.
fn sweep(m: &Machine, steps: usize, step: f64) -> Record {
    let rotary: Vec<usize> = m.rotary_axes().collect();
    let mut commands: Vec<Vec<f64>> = (0..steps)
        .map(|i| {
            let mut q = vec![0.0; m.axes.len()];
            for (k, &a) in rotary.iter().enumerate() {
                let deg = if k == 0 {
                    step * i as f64
                } else {
                    -20.0 * (i as f64 * step).to_radians().sin()
                };
                q[a] = deg.to_radians();
            }
            q
        })
        .collect();
    fill_linear_ik(m, &m.default_parameters(), &mut commands).unwrap();
    let times = (0..steps).map(|i| i as f64).collect();
    record_from_commands(commands, times)
}

/// Every test path: machine and record.
fn paths() -> Vec<(String, Machine, Record)> {
    let ac = builtin("seed-ac");
    let mut out = Vec::new();
    for name in ["K1", "K2", "K4"] {
        out.push((
            name.to_string(),
            ac.clone(),
            builtin_path(&ac, name).unwrap().unwrap(),
        ));
    }
    let file = load_path(&ac, PATH_AC, &ReadOptions::default()).unwrap();
    out.push(("path-ac.csv".into(), ac, file));
    let bc = builtin("head-table-bc");
    let r = sweep(&bc, 40, 2.0);
    out.push(("head-table-bc sweep".into(), bc, r));
    let ca = parse_machine(
        "head-head-ca.toml",
        include_str!("../../../tests/machines/head-head-ca.toml"),
    )
    .unwrap();
    let r = sweep(&ca, 40, 2.0);
    out.push(("head-head-ca sweep".into(), ca, r));
    out
}

/// `x` rounded to `d` decimals, as a decimal text read back.
fn rounded(x: f64, d: usize) -> f64 {
    let v: f64 = format!("{x:.d$}").parse().unwrap();
    v + 0.0
}

#[test]
fn programs_read_back_as_the_poses_at_their_resolution() {
    for (name, m, path) in paths() {
        for dialect in [Dialect::Iso, Dialect::LinuxCnc, Dialect::Heidenhain] {
            for (mode, decimals) in [
                (static_mode(), 4),
                (continuous_mode(), 4),
                (static_mode(), 3),
                (static_mode(), 6),
            ] {
                let mut o = MeasureOptions::new(&m, dialect, mode);
                o.decimals = decimals;
                o.test_name = name.clone();
                if name == "path-ac.csv" {
                    // Its 15° steps take the nest 2.4 mm off the ball between poses (refused by
                    // default: `a_coarse_path_is_refused`).
                    o.max_gap_mm = 3.0;
                }
                let what = format!("{name}, {dialect:?}, {mode:?}, {decimals} decimals");
                let p =
                    measurement_program(&m, &path, &o).unwrap_or_else(|e| panic!("{what}: {e}"));
                let read = read_program("p", &p.text, dialect, &axis_words(&m)).unwrap();
                let poses = read.measuring_poses();
                assert_eq!(poses.len(), path.samples.len(), "{what}");
                assert_eq!(p.plan.rows.len(), path.samples.len(), "{what}");
                let half = 0.5 * 10f64.powi(-(decimals as i32));
                for (i, ((pose, s), row)) in poses
                    .iter()
                    .zip(&path.samples)
                    .zip(&p.plan.rows)
                    .enumerate()
                {
                    let given = to_file_units(&m, &s.commands);
                    for (a, &g) in given.iter().enumerate() {
                        // The word is the pose rounded to nearest at the program's resolution.
                        assert_eq!(pose[a], rounded(g, decimals), "{what}: pose {}", i + 1);
                        assert!((pose[a] - g).abs() <= half * (1.0 + 1e-9), "{what}");
                        // The plan holds the pose as commanded.
                        let planned = match m.axes[a].kind {
                            AxisKind::Linear => row.commands[a],
                            AxisKind::Rotary => row.commands[a].to_degrees(),
                        };
                        assert!((planned - pose[a]).abs() < 1e-9, "{what}");
                    }
                }
                for (a, r) in p.rounding.iter().enumerate() {
                    assert!(*r <= half * (1.0 + 1e-9), "{what}: axis {a} rounding {r}");
                }
                p.plan.check().unwrap();
                assert_eq!(
                    p.plan.kind,
                    if matches!(mode, MeasureMode::Static(_)) {
                        PlanKind::Static
                    } else {
                        PlanKind::Continuous
                    }
                );
            }
        }
    }
}

/// Three poses of `seed-ac` that move C only (the nest leaves the ball: the gap check is
/// relaxed for this timing test).
fn c_moves(m: &Machine, degrees: &[f64]) -> Record {
    let c = m.axis_by_name("C").unwrap();
    let commands = degrees
        .iter()
        .map(|d| {
            let mut q = vec![0.0; m.axes.len()];
            q[c] = d.to_radians();
            q
        })
        .collect();
    record_from_commands(commands, vec![0.0; degrees.len()])
}

#[test]
fn the_static_plan_follows_its_timing_model() {
    let m = builtin("seed-ac");
    // C: 0 → 18° → 18° → 9°, feed 1800°/min = 30°/s, acceleration 1800°/s².
    let r = c_moves(&m, &[0.0, 18.0, 18.0, 9.0]);
    let mut o = MeasureOptions::new(
        &m,
        Dialect::Iso,
        MeasureMode::Static(StaticTiming {
            settle_s: 0.5,
            window_s: 1.25,
            ..StaticTiming::default()
        }),
    );
    o.max_gap_mm = 1e6;
    let p = measurement_program(&m, &r, &o).unwrap();
    // 18° at 30°/s: ṡ = 1/0.6 s, F = 100 (1/min); s̈ = 1800/18 = 100/s², cruise reached:
    // 0.6 + (1/0.6)/100 s. 9°: ṡ = 1/0.3 s (F200), s̈ = 200: 0.3 + (1/0.3)/200 s.
    let m1 = 0.6 + (100.0 / 60.0) / 100.0;
    let m3 = 0.3 + (200.0 / 60.0) / 200.0;
    let expected = [
        (0.0, 0.5, 1.75, 1.75),
        (1.75 + m1, 2.25 + m1, 3.5 + m1, 3.5 + m1),
        (3.5 + m1, 4.0 + m1, 5.25 + m1, 5.25 + m1),
        (5.25 + m1 + m3, 5.75 + m1 + m3, 7.0 + m1 + m3, 7.0 + m1 + m3),
    ];
    for (row, e) in p.plan.rows.iter().zip(expected) {
        let t = row.times();
        for (a, b) in t.iter().zip([e.0, e.1, e.2, e.3]) {
            assert!((a - b).abs() < 1e-12, "{t:?} {e:?}");
        }
    }
    assert!(
        p.text
            .contains("\nG93 G1 X0.0000 Y0.0000 Z0.0000 A0.0000 C18.0000 F100.000\nG4 P1750\n"),
        "{}",
        p.text
    );
    assert!(
        p.text
            .contains("\nG1 X0.0000 Y0.0000 Z0.0000 A0.0000 C9.0000 F200.000\n")
    );
    // The repeated pose is a block that moves nothing; in inverse time it still needs its F.
    assert!(
        p.text
            .contains("\nG1 X0.0000 Y0.0000 Z0.0000 A0.0000 C18.0000 F99999.999\n")
    );
    // After the last dwell: 30 mm off the ball along the tool axis (Z), then the clearance.
    assert!(
        p.text.ends_with(
            "G4 P1750\nG94 G1 X0.0000 Y0.0000 Z30.0000 F500.000\nG53 G0 Z500.0000\nM30\n%\n"
        ),
        "{}",
        p.text
    );

    // Heidenhain: F in mm/min along the combined move (degrees as mm): 18° in 0.6 s = 1800.
    o.dialect = Dialect::Heidenhain;
    let h = measurement_program(&m, &r, &o).unwrap();
    assert!(
        h.text
            .contains(" L X+0.0000 Y+0.0000 Z+0.0000 A+0.0000 C+18.0000 R0 F1800.000 M91\n"),
        "{}",
        h.text
    );
    assert!(
        h.text.contains(" CYCL DEF 9.0 DWELL TIME\n")
            && h.text.contains(" CYCL DEF 9.1 DWELL 1.75\n")
    );
    for (a, b) in h.plan.rows.iter().zip(&p.plan.rows) {
        for (x, y) in a.times().iter().zip(b.times()) {
            assert!((x - y).abs() < 1e-12);
        }
    }

    // Acceleration neglected, rapid moves: 18° at 7200°/min = 120°/s.
    o.dialect = Dialect::Iso;
    o.rates.iter_mut().for_each(|r| r.acceleration_per_s2 = 0.0);
    o.mode = MeasureMode::Static(StaticTiming {
        settle_s: 0.5,
        window_s: 1.25,
        motion: StaticMotion::Rapid,
        ..StaticTiming::default()
    });
    let g0 = measurement_program(&m, &r, &o).unwrap();
    assert!((g0.plan.rows[1].arrive_s - (1.75 + 0.15)).abs() < 1e-12);
    assert!(
        g0.text
            .contains("\nG0 X0.0000 Y0.0000 Z0.0000 A0.0000 C18.0000\n")
    );
    assert!(!g0.text.contains("G93"));
}

#[test]
fn the_continuous_plan_has_lead_dwells_and_timed_blocks() {
    let m = builtin("seed-ac");
    let r = c_moves(&m, &[0.0, 3.0, 6.0, 12.0]);
    let mut o = MeasureOptions::new(
        &m,
        Dialect::Iso,
        MeasureMode::Continuous(ContinuousTiming {
            sample_rate_hz: 50.0,
            lead_s: 1.5,
        }),
    );
    o.max_gap_mm = 1e6;
    let p = measurement_program(&m, &r, &o).unwrap();
    // Blocks of 3°, 3°, 6° at 30°/s: 0.1, 0.1, 0.2 s; the start and the stop each lose
    // ṡ/(2s̈): block 1 ṡ = 10/s, s̈ = 600/s²; last ṡ = 5/s, s̈ = 300/s².
    let (ramp_in, ramp_out) = (10.0 / 1200.0, 5.0 / 600.0);
    let instants = [1.5, 1.6 + ramp_in, 1.7 + ramp_in, 1.9 + ramp_in + ramp_out];
    for (row, t) in p.plan.rows.iter().zip(instants) {
        assert!(
            (row.start_s - t).abs() < 1e-12 && row.start_s == row.end_s,
            "{row:?} {t}"
        );
    }
    assert_eq!(p.plan.rows[0].arrive_s, 0.0);
    assert!((p.plan.rows[3].depart_s - (instants[3] + 1.5)).abs() < 1e-12);
    assert!(p.text.contains("G90 G21 G94 G17 G40 G49 G80 G69 G15 G64\n"));
    assert!(
        p.text.contains(
            "G4 P1500 (LEAD-IN)\nG93 G1 X0.0000 Y0.0000 Z0.0000 A0.0000 C3.0000 F600.000\n"
        ),
        "{}",
        p.text
    );
    assert!(p.text.contains(
        "C12.0000 F300.000\nG4 P1500 (LEAD-OUT)\nG94 G1 X0.0000 Y0.0000 Z30.0000 F500.000\n"
    ));

    // A block shorter than one sampling period is refused.
    o.mode = MeasureMode::Continuous(ContinuousTiming {
        sample_rate_hz: 5.0,
        lead_s: 1.5,
    });
    let e = measurement_program(&m, &r, &o).unwrap_err();
    assert!(
        e.to_string().contains("less than one sampling period"),
        "{e}"
    );
}

#[test]
fn the_header_states_the_assumptions_and_the_checks_in_order() {
    let m = builtin("seed-ac");
    let k4 = builtin_path(&m, "K4").unwrap().unwrap();
    let mut o = MeasureOptions::new(&m, Dialect::Iso, static_mode());
    o.test_name = "K4".into();
    let in_order = |text: &str, needles: &[&str], what: &str| {
        let mut at = 0;
        for needle in needles {
            match text[at..].find(needle) {
                Some(i) => at += i + needle.len(),
                None => panic!("`{needle}` not in the {what} header after byte {at}"),
            }
        }
    };
    let iso = measurement_program(&m, &k4, &o).unwrap().text;
    in_order(
        &iso,
        &[
            "%\nO1000 (RTEST R-TEST MEASUREMENT PROGRAM)\n",
            "(TEST K4, 241 POSES, STATIC: MEASURED AT REST)",
            "G4 P IN MS [NOT LINUXCNC]",
            "MACHINE COORDINATES",
            "(1 COORDINATES: G53",
            "THIS PROGRAM SETS TO ZERO [G10 L2 P1]: NOTE YOUR G54",
            "(2 TOOL: G49",
            "(3 TCP OFF",
            "(4 ROTARY AXES A C",
            "360 IS 360",
            "NOT 0: NO ROLL-OVER [MODULO] AXIS",
            "PARAMETER 1008 ROA = 0",
            "(5 CLEARANCE: Z RAPIDS FIRST TO Z500 MM [MACHINE],)",
            "(6 SPINDLE: M5, THEN M19",
            "(7 APPROACH: RAPID TO 30 MM ABOVE POSE 1",
            "FEED ONTO THE BALL AT 500 MM/MIN",
            "(8 STOP [M0]: CHECK THE NEST SITS ON THE BALL",
            "(9 END: FEED 30 MM OFF THE BALL",
            "  ZC = 29.794",
            "  XW = -217.504",
            "WHEN THE PROGRAM RESUMES AFTER",
            "(EACH POSE: MOVE, DWELL 3 S = SETTLE 1 S + WINDOW 2 S)",
            "INVERSE TIME [G93",
            "LARGEST NEST-BALL GAP ALONG A MOVE",
            "G90 G21 G94 G17 G40 G49 G80 G69 G15 G61\nG10 L2 P1 X0 Y0 Z0 A0 C0\nG54\nM5\n",
        ],
        "ISO",
    );
    o.dialect = Dialect::LinuxCnc;
    let l = measurement_program(&m, &k4, &o).unwrap().text;
    assert!(
        l.starts_with("%\n(rtest R-test measurement program)\n"),
        "{}",
        &l[..200]
    );
    in_order(
        &l,
        &[
            "G4 P in s",
            "(1 coordinates: G53 on every move",
            "(2 tool: G49",
            "(3 kinematics: trivial",
            "no WRAPPED_ROTARY",
            "G90 G21 G94 G17 G40 G49 G80 G61\nM5\n",
            "(MSG,check the nest sits on the ball",
            "\nM2\n%\n",
        ],
        "LinuxCNC",
    );
    // No O word (a subroutine in LinuxCNC), no G69/G15 (not LinuxCNC codes).
    assert!(!l.contains("\nO") && !l.contains("G69") && !l.contains("G15"));
    o.dialect = Dialect::Heidenhain;
    let h = measurement_program(&m, &k4, &o).unwrap().text;
    in_order(
        &h,
        &[
            "0 BEGIN PGM RTEST1000 MM\n1 ; rtest R-test measurement program\n",
            "; 1 coordinates: M91 on every positioning block",
            "; 2 tool: no TOOL CALL here",
            "the active tool must have L 0 and R 0",
            "; 3 TCP off: FUNCTION RESET TCPM here",
            "M127 here",
            "degrees counted as mm (no M116)",
            " FUNCTION RESET TCPM\n",
            " L M127\n",
            " L M5\n",
            " STOP ; check the nest sits on the ball",
            "END PGM RTEST1000 MM\n",
        ],
        "Heidenhain",
    );
    // No tool call block (a comment may name it).
    assert!(h.lines().all(|l| {
        !l.split_once(' ')
            .is_some_and(|(_, b)| b.starts_with("TOOL CALL"))
    }));
    // Block numbers count every line from 0.
    for (i, line) in h.lines().enumerate() {
        assert!(line.starts_with(&format!("{i} ")), "{line}");
    }
}

#[test]
fn markers_split_the_dwell() {
    let m = builtin("seed-ac");
    let k4 = builtin_path(&m, "K4").unwrap().unwrap();
    let mode = MeasureMode::Static(StaticTiming {
        marker_m: Some(100),
        marker_comment: true,
        ..StaticTiming::default()
    });
    let iso = measurement_program(&m, &k4, &MeasureOptions::new(&m, Dialect::Iso, mode)).unwrap();
    assert!(
        iso.text.contains("\nG4 P1000\nM100\nG4 P2000 (SAMPLE 1)\n"),
        "{}",
        &iso.text[..3000]
    );
    assert!(
        iso.text
            .contains("\nG4 P1000\nM100\nG4 P2000 (SAMPLE 241)\nG94 G1 ")
    );
    let h =
        measurement_program(&m, &k4, &MeasureOptions::new(&m, Dialect::Heidenhain, mode)).unwrap();
    assert!(h.text.contains(" L M100\n") && h.text.contains(" CYCL DEF 9.1 DWELL 2 ; sample 17\n"));
    // The markers change nothing in the plan.
    let plain = measurement_program(
        &m,
        &k4,
        &MeasureOptions::new(&m, Dialect::Iso, static_mode()),
    )
    .unwrap();
    assert_eq!(plain.plan, iso.plan);
    assert!(!plain.text.contains("M100") && !plain.text.contains("SAMPLE"));
    // A marker that would stop the program, move the spindle the nest sits in or change tools
    // is refused.
    for (code, why) in [
        (0, "stops"),
        (19, "spindle"),
        (3, "spindle"),
        (6, "changes tools"),
        (91, "positions"),
    ] {
        let mode = MeasureMode::Static(StaticTiming {
            marker_m: Some(code),
            ..StaticTiming::default()
        });
        let e =
            measurement_program(&m, &k4, &MeasureOptions::new(&m, Dialect::Iso, mode)).unwrap_err();
        assert!(
            matches!(e, MeasureError::Options(_)) && e.to_string().contains(why),
            "M{code}: {e}"
        );
    }
}

#[test]
fn what_cannot_be_written_is_refused() {
    let m = builtin("seed-ac");
    let k4 = builtin_path(&m, "K4").unwrap().unwrap();
    let base = MeasureOptions::new(&m, Dialect::Iso, static_mode());
    let fails = |o: &MeasureOptions, r: &Record, needle: &str| {
        let e = measurement_program(&m, r, o).unwrap_err();
        assert!(e.to_string().contains(needle), "`{needle}` not in: {e}");
        e
    };
    let mut o = base.clone();
    o.decimals = 10;
    fails(&o, &k4, "10 decimals asked for, at most 9");
    let mut o = base.clone();
    o.rates.pop();
    fails(&o, &k4, "4 axis rates for the 5 axes");
    let mut o = base.clone();
    o.rates[2].feed_per_min = 0.0;
    fails(&o, &k4, "axis C: the feed and rapid rates");
    let mut o = base.clone();
    o.mode = MeasureMode::Static(StaticTiming {
        window_s: 0.0,
        ..StaticTiming::default()
    });
    fails(&o, &k4, "measuring window 0 s");
    fails(&base, &Record::default(), "no pose");
    let mut o = base.clone();
    o.max_gap_mm = 0.01;
    let e = fails(&o, &k4, "the nest leaves the ball by");
    assert!(
        matches!(e, MeasureError::Move { ref from, .. } if from == "sample 1"),
        "{e}"
    );
    // A pose off its range once rounded: A at -120.00004° rounds to -120.0000 (within), but
    // -120.0001 is outside.
    let mut r = c_moves(&m, &[0.0]);
    let a = m.axis_by_name("A").unwrap();
    r.samples[0].commands[a] = (-120.0001f64).to_radians();
    let mut o = base.clone();
    o.max_gap_mm = 1e6;
    fails(
        &o,
        &r,
        "sample 1: as written with 4 decimals: A = -120.0001° outside its range",
    );
}

#[test]
fn a_coarse_path_is_refused() {
    let m = builtin("seed-ac");
    let coarse = load_path(&m, PATH_AC, &ReadOptions::default()).unwrap();
    let e = measurement_program(
        &m,
        &coarse,
        &MeasureOptions::new(&m, Dialect::Iso, static_mode()),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("move from the pose at line 4 to the next: the nest leaves the ball by 2.4"),
        "{e}"
    );
}

#[test]
fn the_plan_csv_reads_back_exactly() {
    let m = builtin("seed-ac");
    let k4 = builtin_path(&m, "K4").unwrap().unwrap();
    for mode in [static_mode(), continuous_mode()] {
        let mut o = MeasureOptions::new(&m, Dialect::Iso, mode);
        o.test_name = "K4".into();
        let p = measurement_program(&m, &k4, &o).unwrap();
        let comments = plan_comments(&m, &o, &p);
        let text = format_plan(&m, &p.plan, &comments).unwrap();
        assert!(
            text.starts_with("# sample-timing plan written by rtest "),
            "{text}"
        );
        assert!(text.contains(" for machine seed-ac, test K4: 241 poses, "));
        assert!(text.contains("\nsample,X,Y,Z,A,C,arrive_s,start_s,end_s,depart_s\n1,"));
        let back = parse_plan("plan.csv", &text, &m).unwrap();
        assert_eq!(back, p.plan);
        assert_eq!(format_plan(&m, &back, &comments).unwrap(), text);
    }
}

#[test]
fn a_malformed_plan_is_refused_at_its_line_and_column() {
    let m = builtin("seed-ac");
    let header = "sample,X,Y,Z,A,C,arrive_s,start_s,end_s,depart_s\n";
    let row1 = "1,-217.504,-0.279,211.537,0,0,0,1,3,3\n";
    let cases: Vec<(String, &str)> = vec![
        (String::new(), "plan.csv:1: an empty plan"),
        (header.into(), "plan.csv:2: a plan with a header and no row"),
        (
            "sample,X,Y,Z,A,C,arrive_s,start_s,end_s\n".into(),
            "plan.csv:1: missing column(s) depart_s",
        ),
        (
            "sample,X,Y,Z,A,B,arrive_s,start_s,end_s,depart_s\n".into(),
            "plan.csv:1: column 6 `B`: unknown column `B`",
        ),
        (
            "sample,X,x,Y,Z,A,C,arrive_s,start_s,end_s,depart_s\n".into(),
            "plan.csv:1: column 3 `x`: column `x` appears twice",
        ),
        (
            format!("{header}2,-217.504,-0.279,211.537,0,0,0,1,3,3\n"),
            "plan.csv:2: column 1 `sample`: sample 2 where sample 1 belongs",
        ),
        (
            format!("{header}1,-217.504,-0.279,211.537,0,0,0,1,3\n"),
            "plan.csv:2: 9 fields, the header has 10",
        ),
        (
            format!("{header}1,-217.504,-0.279,x,0,0,0,1,3,3\n"),
            "plan.csv:2: column 4 `Z`: `x` is not a finite decimal",
        ),
        (
            format!("{header}1,-217.504,-0.279,211.537,0,0,0,1,0.5,3\n"),
            "plan.csv:2: end_s = 0.5 s is before start_s = 1 s",
        ),
        (
            format!("{header}{row1}2,-217.504,-0.279,211.537,0,0,2,3,4,4\n"),
            "plan.csv:3: arrive_s = 2 s is before the previous pose's depart_s = 3 s",
        ),
        (
            format!("{header}{row1}2,-217.504,-0.279,211.537,0,0,3,4,4,5\n"),
            "plan.csv:3: a measuring window without a length",
        ),
        (
            format!(
                "{header}1,-217.504,-0.279,211.537,0,0,0,1,1,3\n2,-217.504,-0.279,211.537,0,0,3,4,5,6\n"
            ),
            "plan.csv:3: a measuring window of 1 s in a continuous plan",
        ),
        (
            format!("{header}1,-217.504,-0.279,211.537,130,0,0,1,3,3\n"),
            "plan.csv:2: the pose is refused: A = 130° outside its range",
        ),
    ];
    for (text, needle) in cases {
        let e = parse_plan("plan.csv", &text, &m).unwrap_err().to_string();
        assert!(e.starts_with(needle), "`{needle}` is not the start of: {e}");
    }
    // A plan of another kind than its rows, given in memory, is refused by its check.
    let plan = TimingPlan {
        kind: PlanKind::Continuous,
        rows: parse_plan("p", &format!("{header}{row1}"), &m)
            .unwrap()
            .rows,
    };
    assert!(
        format_plan(&m, &plan, &[])
            .unwrap_err()
            .to_string()
            .contains("continuous plan")
    );
}
