//! The sequence of a measurement program, read back by `programs::reader` in every dialect,
//! static and continuous, on every built-in machine with a rotary axis: machine coordinates on
//! every move, the clearance, the rotary axes there, the orientation, the approach along the
//! tool axis, the stop, the measuring poses (those of the plan), the retract along the tool
//! axis to the clearance, the end; C = 360° written as 360.

use crate::common;

use common::builtin;
use formats::nc::Dialect;
use formats::poses::{axis_words, from_file_units};
use model_spec::{AxisKind, Machine};
use programs::measure::{
    ContinuousTiming, MeasureMode, MeasureOptions, StaticTiming, measurement_program,
};
use programs::reader::{Motion, ReadProgram, Step, read_program};
use simulation::exact::VirtualMachine;
use simulation::generator::{self, GeneratorOptions};
use simulation::record::Record;

const DIALECTS: [Dialect; 3] = [Dialect::Iso, Dialect::LinuxCnc, Dialect::Heidenhain];

/// The built-in machines with a rotary axis and the first test of each (K1 on `seed-ac`).
fn machines() -> Vec<(Machine, String, Record)> {
    let mut out = Vec::new();
    for (name, _) in model_spec::builtin::BUILTIN {
        let m = builtin(name);
        let opts = GeneratorOptions::default();
        let tests = generator::tests_with(&m, &opts.clearance);
        let Some(spec) = tests.first() else {
            continue;
        };
        let params = m.default_parameters();
        let r = generator::generate_test(&m, spec, &params, &opts).unwrap();
        out.push((m, spec.name.clone(), r));
    }
    assert!(out.len() >= 6, "{} machines", out.len());
    out
}

fn modes() -> [MeasureMode; 2] {
    [
        MeasureMode::Static(StaticTiming::default()),
        MeasureMode::Continuous(ContinuousTiming::default()),
    ]
}

/// The nominal position of the nest relative to the ball in the tool frame (mm) at the pose
/// `p` (mm, degrees): (0, 0, d) when the nest is `d` mm above the ball along the tool axis.
fn nest_from_ball(m: &Machine, p: &[f64]) -> [f64; 3] {
    let v = VirtualMachine::new(m)
        .nominal_error_vector(&from_file_units(m, p), &m.default_parameters())
        .position;
    [v.x, v.y, v.z]
}

/// Two poses equal to 1e-9 (the plan's degrees are converted from radians).
fn same(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9)
}

fn names(m: &Machine, mv: &Motion) -> Vec<String> {
    mv.named.iter().map(|&a| m.axes[a].name.clone()).collect()
}

/// Checks the sequence of program `read` of `m`, whose measuring poses must be `poses` (mm,
/// degrees), written with 4 decimals, the approach 30 mm long at 500 mm/min.
fn check_sequence(m: &Machine, read: &ReadProgram, poses: &[Vec<f64>], what: &str) {
    use Step::*;
    assert_eq!(
        read.steps(),
        [
            Setup, Spindle, Clearance, Orient, Approach, Stop, Measure, Retract, End
        ],
        "{what}"
    );
    // Machine coordinates on every move.
    for b in &read.blocks {
        if let Some(mv) = &b.motion {
            assert!(
                mv.machine,
                "{what}: line {} not in machine coordinates",
                b.line
            );
        }
    }
    let linear = |a: usize| m.axes[a].kind == AxisKind::Linear;
    // The clearance: one linear axis rapids to an end of its stroke, then the rotary axes turn
    // to the first pose's angles.
    let clearance = read.moves(Clearance);
    let first = clearance[0];
    assert!(first.rapid && first.named.len() == 1, "{what}: {first:?}");
    let z = first.named[0];
    assert!(linear(z), "{what}");
    let zc = first.pose[z];
    assert!(m.axes[z].limits.contains(&zc), "{what}: clearance {zc}");
    let rotary: Vec<usize> = (0..m.axes.len()).filter(|&a| !linear(a)).collect();
    assert_eq!(clearance.len(), 2, "{what}");
    let mut turned = clearance[1].named.clone();
    turned.sort_unstable();
    assert!(clearance[1].rapid && turned == rotary, "{what}");
    for &a in &rotary {
        assert_eq!(
            clearance[1].pose[a], poses[0][a],
            "{what}: axis {}",
            m.axes[a].name
        );
    }
    // The approach: rapids, the last 30 mm above the first pose along the tool axis, the
    // clearance axis still at the clearance before it; then one feed onto the ball.
    let approach = read.moves(Approach);
    let (feed, rapids) = approach.split_last().unwrap();
    assert!(rapids.iter().all(|mv| mv.rapid), "{what}");
    assert!(
        !rapids.is_empty() && rapids.last().unwrap().named == [z],
        "{what}"
    );
    if rapids.len() > 1 {
        assert_eq!(rapids[rapids.len() - 2].pose[z], zc, "{what}");
        assert!(!rapids[rapids.len() - 2].named.contains(&z), "{what}");
    }
    let above = &rapids.last().unwrap().pose;
    let g = nest_from_ball(m, above);
    assert!(
        g[0].abs() < 1e-3 && g[1].abs() < 1e-3 && (g[2] - 30.0).abs() < 1e-3,
        "{what}: the approach starts at {g:?} from the ball (tool frame), not 30 mm along the tool axis"
    );
    for &a in &rotary {
        assert!(same(&[above[a]], &[poses[0][a]]), "{what}");
    }
    assert!(
        !feed.rapid && feed.feed == Some(500.0) && !feed.inverse_time,
        "{what}"
    );
    assert!(same(&feed.pose, &poses[0]), "{what}");
    // Between the clearance and the approach the spindle is oriented; before, stopped; the
    // program stops for the operator after the approach.
    assert!(read.blocks_of(Orient)[0].m_codes.contains(&19), "{what}");
    assert!(read.blocks_of(Spindle)[0].m_codes.contains(&5), "{what}");
    let stop = read.blocks_of(Stop);
    assert_eq!(stop.len(), 1, "{what}");
    assert!(
        stop[0]
            .comment
            .as_deref()
            .is_some_and(|c| c.to_lowercase().contains("nest sits on the ball")),
        "{what}: {:?}",
        stop[0]
    );
    // The measuring poses are the plan's, as written.
    let read_poses = read.measuring_poses();
    assert_eq!(read_poses.len(), poses.len(), "{what}");
    for (i, (a, b)) in read_poses.iter().zip(poses).enumerate() {
        assert!(
            same(a, b),
            "{what}: pose {}: {a:?} against the plan's {b:?}",
            i + 1
        );
    }
    // The retract: a feed 30 mm off the last pose along the tool axis, then the clearance.
    let retract = read.moves(Retract);
    assert_eq!(retract.len(), 2, "{what}");
    assert!(
        !retract[0].rapid && retract[0].feed == Some(500.0),
        "{what}"
    );
    assert!(retract[0].named.iter().all(|&a| linear(a)), "{what}");
    let g = nest_from_ball(m, &retract[0].pose);
    assert!(
        g[0].abs() < 1e-3 && g[1].abs() < 1e-3 && (g[2] - 30.0).abs() < 1e-3,
        "{what}: the retract ends at {g:?}"
    );
    assert!(retract[1].rapid && retract[1].named == [z], "{what}");
    assert_eq!(
        retract[1].pose[z],
        zc,
        "{what}: {}",
        names(m, retract[1]).join(" ")
    );
    assert_eq!(read.blocks.last().unwrap().step, End, "{what}");
}

#[test]
fn every_program_runs_clearance_approach_stop_poses_retract_in_machine_coordinates() {
    for (m, test, path) in machines() {
        for dialect in DIALECTS {
            for mode in modes() {
                let mut o = MeasureOptions::new(&m, dialect, mode);
                o.test_name = test.clone();
                let what = format!("{} {test} {dialect:?} {mode:?}", m.name);
                let p =
                    measurement_program(&m, &path, &o).unwrap_or_else(|e| panic!("{what}: {e}"));
                let read = read_program("p", &p.text, dialect, &axis_words(&m)).unwrap();
                let poses: Vec<Vec<f64>> = p
                    .plan
                    .rows
                    .iter()
                    .map(|r| formats::poses::to_file_units(&m, &r.commands))
                    .collect();
                check_sequence(&m, &read, &poses, &what);
                // The dwells in the dialect's unit: ms (ISO P), s (LinuxCNC P, Heidenhain).
                let dwell = read
                    .blocks_of(Step::Dwell)
                    .iter()
                    .find_map(|b| b.dwell_s)
                    .unwrap();
                let s = match mode {
                    MeasureMode::Static(t) => t.settle_s + t.window_s,
                    MeasureMode::Continuous(t) => t.lead_s,
                };
                let expected = if dialect == Dialect::Iso {
                    1000.0 * s
                } else {
                    s
                };
                assert_eq!(dwell, expected, "{what}");
            }
        }
    }
}

#[test]
fn c_at_360_is_written_as_360() {
    let m = builtin("seed-ac");
    let k1 = simulation::builtin_path(&m, "K1").unwrap().unwrap();
    let c = m.axis_by_name("C").unwrap();
    for dialect in DIALECTS {
        let o = MeasureOptions::new(&m, dialect, MeasureMode::Static(StaticTiming::default()));
        let p = measurement_program(&m, &k1, &o).unwrap();
        let read = read_program("k1", &p.text, dialect, &axis_words(&m)).unwrap();
        let poses = read.measuring_poses();
        assert_eq!(poses[0][c], 0.0);
        assert_eq!(poses.last().unwrap()[c], 360.0, "{dialect:?}");
        let word = if dialect == Dialect::Heidenhain {
            " C+360.0000 "
        } else {
            " C360.0000 "
        };
        assert!(p.text.contains(word), "{dialect:?}");
        // C only ever rises by 1° from pose to pose: no move relies on a shortest path.
        for w in poses.windows(2) {
            assert!((w[1][c] - w[0][c] - 1.0).abs() < 1e-9, "{dialect:?}");
        }
    }
}

#[test]
fn the_clearance_and_the_approach_are_options_and_are_checked() {
    let m = builtin("seed-ac");
    let k4 = simulation::builtin_path(&m, "K4").unwrap().unwrap();
    let mut o = MeasureOptions::new(
        &m,
        Dialect::LinuxCnc,
        MeasureMode::Static(StaticTiming::default()),
    );
    o.clearance_mm = Some(250.0);
    o.approach_mm = 12.5;
    o.approach_feed_mm_min = 200.0;
    let p = measurement_program(&m, &k4, &o).unwrap();
    // The clearance, the approach and the retract are outside the plan: its times are the
    // same whatever they are.
    let default = MeasureOptions::new(
        &m,
        Dialect::LinuxCnc,
        MeasureMode::Static(StaticTiming::default()),
    );
    assert_eq!(measurement_program(&m, &k4, &default).unwrap().plan, p.plan);
    assert!(p.text.contains("\nG53 G0 Z250.0000\n"), "{}", p.text);
    assert!(p.text.contains("\nG53 G0 Z69.1610\n"), "56.661 + 12.5");
    assert!(p.text.contains(" F200.000\n(MSG,"));
    assert!(p.text.ends_with("G53 G0 Z250.0000\nM2\n%\n"));
    // A clearance outside the stroke, or below the approach's start, is refused.
    for (z, why) in [(600.0, "outside the stroke of axis Z"), (60.0, "beyond it")] {
        o.clearance_mm = Some(z);
        let e = measurement_program(&m, &k4, &o).unwrap_err().to_string();
        assert!(e.contains(why), "{z}: {e}");
    }
    o.clearance_mm = None;
    o.approach_mm = 0.0;
    let e = measurement_program(&m, &k4, &o).unwrap_err().to_string();
    assert!(e.contains("approach 0 mm"), "{e}");
    // An approach so long that it starts beyond the Z stroke.
    o.approach_mm = 450.0;
    let e = measurement_program(&m, &k4, &o).unwrap_err().to_string();
    assert!(
        e.contains("beyond it") || e.contains("outside the strokes"),
        "{e}"
    );
}

#[test]
fn the_reader_tells_a_program_out_of_order() {
    let m = builtin("seed-ac");
    let k4 = simulation::builtin_path(&m, "K4").unwrap().unwrap();
    let o = MeasureOptions::new(
        &m,
        Dialect::Iso,
        MeasureMode::Static(StaticTiming::default()),
    );
    let text = measurement_program(&m, &k4, &o).unwrap().text;
    let words = axis_words(&m);
    // Without its stop, the approach and the measuring moves are not told apart.
    let no_stop: String = text
        .lines()
        .filter(|l| !l.starts_with("M0 "))
        .map(|l| format!("{l}\n"))
        .collect();
    let read = read_program("p", &no_stop, Dialect::Iso, &words).unwrap();
    assert!(!read.steps().contains(&Step::Stop));
    // Without the zeroed G54, the feed moves are not in machine coordinates.
    let no_zero = text.replace("G10 L2 P1 X0 Y0 Z0 A0 C0\n", "");
    let read = read_program("p", &no_zero, Dialect::Iso, &words).unwrap();
    assert!(read.moves(Step::Measure).iter().all(|mv| !mv.machine));
    assert!(read.moves(Step::Clearance).iter().all(|mv| mv.machine));
    // A G54 zeroed on some axes only does not count.
    let part = text.replace("G10 L2 P1 X0 Y0 Z0 A0 C0\n", "G10 L2 P1 X0 Y0 Z0\n");
    let read = read_program("p", &part, Dialect::Iso, &words).unwrap();
    assert!(
        read.moves(Step::Approach)
            .last()
            .is_some_and(|mv| !mv.machine)
    );
    // A word the reader does not know names its line.
    let e = read_program("p", "%\nG90\nG43 H1\n", Dialect::Iso, &words).unwrap_err();
    assert!(e.to_string().starts_with("p:3:1: `G43`"), "{e}");
}

#[test]
fn a_measurement_program_is_not_a_program_compensate_corrects() {
    use formats::nc::parse_program;
    let m = builtin("seed-ac");
    let k4 = simulation::builtin_path(&m, "K4").unwrap().unwrap();
    for (dialect, needle) in [
        (
            Dialect::Iso,
            "`G10`: setting offsets from the program is refused",
        ),
        (
            Dialect::LinuxCnc,
            "`G53`: a one-shot move in machine coordinates is refused",
        ),
        (
            Dialect::Heidenhain,
            "a move with axis X, A, C, Y not yet known",
        ),
    ] {
        let o = MeasureOptions::new(&m, dialect, MeasureMode::Static(StaticTiming::default()));
        let text = measurement_program(&m, &k4, &o).unwrap().text;
        let e = parse_program("k4", &text, dialect, &axis_words(&m))
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle), "{dialect:?}: {e}");
    }
}
