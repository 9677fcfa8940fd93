//! The test generator: the catalogue of every built-in and fixture machine, every test within
//! strokes, ranges and the clearance rule with the nest on the ball; the seed's K1, K2, K4
//! unchanged; the errors of bad input.

use crate::common;

use common::{builtin, fixture};
use formats::csv::{ReadOptions, format_record};
use formats::paths::parse_path;
use model_spec::{Machine, parse_machine};
use simulation::VirtualMachine;
use simulation::generator::clearance::{TILT_TOLERANCE_DEG, TiltGauge};
use simulation::generator::{
    Clearance, GeneratorError, GeneratorOptions, SampleProblem, TestKind, ball_height_mm, generate,
    generate_test, tests, tests_with,
};
use simulation::paths::{builtin_path, fill_linear_ik, record_from_commands};
use simulation::record::Record;

/// Every built-in machine and every fixture machine with rotary axes.
fn machines() -> Vec<Machine> {
    let mut all = model_spec::all_builtin();
    for f in [
        "tests/machines/head-head-ca.toml",
        "tests/machines/neg-head.toml",
        "tests/machines/neg-table.toml",
        "codegen/tests/machines/one-rotary.toml",
    ] {
        all.push(fixture(f));
    }
    all
}

fn names(m: &Machine) -> Vec<String> {
    tests(m).into_iter().map(|t| t.name).collect()
}

fn deg(m: &Machine, r: &Record, i: usize, axis: &str) -> f64 {
    r.samples[i].commands[m.axis_by_name(axis).unwrap()].to_degrees()
}

/// The rotary commands (A, C) in degrees of a sample index.
type RotaryDegrees = fn(usize) -> (f64, f64);

/// The seed's paths as they were defined before the generator: rotary commands from degrees,
/// linear axes by the inverse kinematics at the default parameters, t = i s.
fn seed_path(m: &Machine, name: &str) -> Record {
    let (n, f): (usize, RotaryDegrees) = match name {
        "K1" => (361, |i| (0.0, i as f64)),
        "K2" => (121, |i| (-90.0 + i as f64, 0.0)),
        "K4" => (241, |i| {
            let c = 1.5 * i as f64;
            (-45.0 * (1.0 - c.to_radians().cos()) + 0.0, c)
        }),
        _ => unreachable!(),
    };
    let (a, c) = (m.axis_by_name("A").unwrap(), m.axis_by_name("C").unwrap());
    let mut commands: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            let (da, dc) = f(i);
            let mut q = vec![0.0; m.axes.len()];
            q[a] = da.to_radians();
            q[c] = dc.to_radians();
            q
        })
        .collect();
    fill_linear_ik(m, &m.default_parameters(), &mut commands).unwrap();
    record_from_commands(commands, (0..n).map(|i| i as f64).collect())
}

#[test]
fn k1_k2_k4_of_seed_ac_are_unchanged_sample_for_sample() {
    let m = builtin("seed-ac");
    let p = m.default_parameters();
    let o = GeneratorOptions::default();
    for name in ["K1", "K2", "K4"] {
        let old = seed_path(&m, name);
        let new = generate(&m, name, &p, &o).unwrap();
        assert_eq!(new.samples.len(), old.samples.len(), "{name}");
        for (a, b) in new.samples.iter().zip(&old.samples) {
            let bits = |s: &simulation::record::Sample| {
                s.commands.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
            };
            assert_eq!(bits(a), bits(b), "{name}: commands bit for bit");
            assert_eq!(a.t.to_bits(), b.t.to_bits());
            assert_eq!(a.motion, b.motion);
        }
        assert_eq!(builtin_path(&m, name).unwrap().unwrap(), old, "{name}");
    }
    // K1 is turn-C and K4 is pair-A-C on seed-ac; K2 is the seed's part of turn-A.
    let turn_c = generate(&m, "turn-C", &p, &o).unwrap();
    assert_eq!(turn_c, seed_path(&m, "K1"));
    let pair = generate(&m, "pair-a-c", &p, &o).unwrap();
    assert_eq!(pair, seed_path(&m, "K4"));
    let turn_a = generate(&m, "turn-A", &p, &o).unwrap();
    assert_eq!(turn_a.samples.len(), 181);
    assert_eq!(
        (deg(&m, &turn_a, 0, "A"), deg(&m, &turn_a, 180, "A")),
        (-90.0, 90.0)
    );
}

#[test]
fn the_catalogues_of_the_machines() {
    let all = machines();
    let by_name = |n: &str| all.iter().find(|m| m.name == n).unwrap();
    assert_eq!(
        names(by_name("seed-ac")),
        ["K1", "K2", "K4", "turn-A", "turn-C", "pair-A-C"]
    );
    assert_eq!(names(by_name("seed-3axis")), Vec::<String>::new());
    assert_eq!(
        names(by_name("head-table-bc")),
        ["turn-B", "turn-C", "pair-B-C"]
    );
    // The seed's tests exist on every machine whose rotary axes are A and C.
    for n in ["head-head-ca", "neg-head", "neg-table"] {
        assert_eq!(
            names(by_name(n)),
            ["K1", "K2", "K4", "turn-A", "turn-C", "pair-A-C"]
        );
    }
    assert_eq!(names(by_name("one-rotary")), ["turn-B"]);
    let descriptions: Vec<String> = tests(by_name("seed-ac"))
        .into_iter()
        .map(|t| format!("{}: {}", t.name, t.description))
        .collect();
    assert_eq!(
        descriptions,
        [
            "K1: the seed's K1: C turns 0° .. 360° in 1° steps, A at 0° (361 samples)",
            "K2: the seed's K2: A turns -90° .. 30° in 1° steps, C at 0° (121 samples)",
            "K4: the seed's K4: C turns 0° .. 360° in 1.5° steps, A = -45·(1 − cos C)° (241 samples)",
            "turn-A: A turns -90° .. 90° (where the tool axis stays within 90° of the table normal) in 1° steps, C at 0° (181 samples)",
            "turn-C: C turns 0° .. 360° (a full turn) in 1° steps, A at 0° (361 samples)",
            "pair-A-C: C turns 0° .. 360° in 1.5° steps, A = -45·(1 − cos C)° (241 samples)",
        ]
    );
    // A tilting table without a turntable: the B trunnion of one-rotary turns where the tool
    // axis stays above the table, not over its whole ±180° range.
    let t = &tests(by_name("one-rotary"))[0];
    assert_eq!((t.sweep.from_deg, t.sweep.to_deg), (-90.0, 90.0));
    assert_eq!(
        t.description,
        "B turns -90° .. 90° (where the tool axis stays within 90° of the table normal) in 1° steps (181 samples)"
    );
    // A head about -x (neg-head) tilts the tool axis; the C table turns a full turn.
    let t = tests(by_name("neg-head"));
    assert_eq!((t[3].sweep.from_deg, t[3].sweep.to_deg), (-90.0, 90.0));
    assert_eq!((t[4].sweep.from_deg, t[4].sweep.to_deg), (0.0, 360.0));
    assert_eq!(t[5].kind, TestKind::Pair);
    // head-head-ca: its C head's range (±360°) holds a full turn from 0°.
    let t = tests(by_name("head-head-ca"));
    assert_eq!((t[4].sweep.from_deg, t[4].sweep.to_deg), (0.0, 360.0));
}

/// Every check a generated record must pass, sample by sample.
fn check_record(m: &Machine, name: &str, r: &Record, params: &[f64], o: &GeneratorOptions) {
    let vm = VirtualMachine::new(m);
    let gauge = TiltGauge::new(m);
    assert!(r.measured.is_empty());
    assert!(ball_height_mm(m, params) >= o.clearance.min_ball_height_mm);
    for (i, s) in r.samples.iter().enumerate() {
        let what = format!("{} {name} sample {i}", m.name);
        assert_eq!(s.t, i as f64 * o.period_s, "{what}");
        m.check_pose(&s.commands)
            .unwrap_or_else(|e| panic!("{what}: {e}"));
        let tilt = gauge.tilt_deg(&s.commands);
        assert!(
            tilt <= o.clearance.max_tilt_deg + TILT_TOLERANCE_DEG,
            "{what}: tilt {tilt}"
        );
        let gap = vm.nominal_error_vector(&s.commands, params).position;
        assert!(gap.amax() < 1e-9, "{what}: nest off the ball by {gap:?} mm");
    }
}

#[test]
fn every_test_of_every_machine_is_within_limits_and_clearance_with_the_nest_on_the_ball() {
    let o = GeneratorOptions::default();
    let mut count = 0;
    for m in machines() {
        let p = m.default_parameters();
        for t in tests(&m) {
            let r = generate_test(&m, &t, &p, &o)
                .unwrap_or_else(|e| panic!("{} {}: {e}", m.name, t.name));
            check_record(&m, &t.name, &r, &p, &o);
            // The primary covers its interval, ends included; the axes it does not move stand
            // at their rest values.
            let first = r.samples[0].commands[t.sweep.primary].to_degrees();
            let last = r.samples.last().unwrap().commands[t.sweep.primary].to_degrees();
            assert!(
                (first - t.sweep.from_deg).abs() < 1e-9,
                "{} {}",
                m.name,
                t.name
            );
            assert!(
                (last - t.sweep.to_deg).abs() < 1e-9,
                "{} {}",
                m.name,
                t.name
            );
            for a in m.rotary_axes().filter(|a| !t.moves.contains(a)) {
                assert!(r.samples.iter().all(|s| s.commands[a] == 0.0));
            }
            if let Some(f) = t.sweep.follower {
                let reach = r
                    .samples
                    .iter()
                    .map(|s| (s.commands[f.axis].to_degrees() - f.base_deg).abs())
                    .fold(0.0, f64::max);
                assert!(
                    (reach - 2.0 * f.amplitude_deg.abs()).abs() < 1e-9,
                    "{} {}: the secondary reaches its excursion",
                    m.name,
                    t.name
                );
            }
            count += 1;
        }
    }
    // Built in: seed-ac 6, head-table-bc 3, table-table-bc 3, head-head-ca 6, the nutating
    // head and table 3 each, horizontal-4axis-b 1; fixtures: head-head-ca, neg-head, neg-table
    // 6 each, one-rotary 1.
    assert_eq!(count, 6 + 3 + 3 + 6 + 3 + 3 + 1 + 6 + 6 + 6 + 1);
}

#[test]
fn a_machine_without_rotary_axes_has_no_test() {
    let m = builtin("seed-3axis");
    let e = generate(
        &m,
        "turn-C",
        &m.default_parameters(),
        &GeneratorOptions::default(),
    )
    .unwrap_err();
    assert!(matches!(e, GeneratorError::NoRotaryAxis { .. }));
    assert_eq!(
        e.to_string(),
        "machine seed-3axis has no rotary axis, so it has no R-test test (the tests turn rotary axes): give a path as a CSV file"
    );
}

#[test]
fn an_unknown_test_lists_the_machines_tests() {
    let m = builtin("head-table-bc");
    let e = generate(
        &m,
        "K4",
        &m.default_parameters(),
        &GeneratorOptions::default(),
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "machine head-table-bc has no test `K4` (its tests: turn-B, turn-C, pair-B-C)"
    );
}

#[test]
fn a_ball_out_of_stroke_names_the_first_sample_axis_and_limit() {
    let m = builtin("seed-ac");
    let mut p = m.default_parameters();
    p[m.symbol_by_name("Xw").unwrap()] = -450.0;
    let e = generate(&m, "turn-C", &p, &GeneratorOptions::default()).unwrap_err();
    let GeneratorError::Sample(s) = &e else {
        panic!("{e}")
    };
    let SampleProblem::Limits(l) = &s.problem else {
        panic!("{e}")
    };
    // The ball 450 mm from the C axis: Y leaves its ±400 mm stroke at the first sample where
    // the ball swings beyond it.
    assert_eq!(l.name, "Y");
    assert_eq!(s.at.test, "turn-C");
    assert_eq!(
        e.to_string(),
        format!(
            "test turn-C, sample {} of 361 (t = {} s; A = 0°, C = {}°): {}",
            s.at.sample + 1,
            s.at.sample,
            s.at.sample,
            l
        )
    );
    assert!(
        e.to_string().contains("outside its stroke -400 .. 400 mm"),
        "{e}"
    );
}

#[test]
fn bad_parameters_and_options_are_refused() {
    let m = builtin("seed-ac");
    let o = GeneratorOptions::default();
    let mut p = m.default_parameters();
    p[m.symbol_by_name("Zw").unwrap()] = f64::NAN;
    let e = generate(&m, "K1", &p, &o).unwrap_err();
    assert_eq!(
        e.to_string(),
        "kinematic parameter Zw = NaN mm: not a finite number"
    );
    p[m.symbol_by_name("Zw").unwrap()] = 1e6;
    let e = generate(&m, "K1", &p, &o).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("kinematic parameter Zw = 1000000 mm: beyond"),
        "{e}"
    );
    let e = generate(&m, "K1", &p[..3], &o).unwrap_err();
    assert!(matches!(
        e,
        GeneratorError::ParamCount {
            expected: 13,
            found: 3,
            ..
        }
    ));
    let p = m.default_parameters();
    for (step, period, tilt, height) in [
        (Some(0.0), 1.0, 90.0, 30.0),
        (Some(f64::NAN), 1.0, 90.0, 30.0),
        (Some(-1.0), 1.0, 90.0, 30.0),
        (None, 0.0, 90.0, 30.0),
        (None, f64::INFINITY, 90.0, 30.0),
        (None, 1.0, 181.0, 30.0),
        (None, 1.0, f64::NAN, 30.0),
        (None, 1.0, 90.0, -1.0),
    ] {
        let o = GeneratorOptions {
            step_deg: step,
            period_s: period,
            clearance: Clearance {
                max_tilt_deg: tilt,
                min_ball_height_mm: height,
            },
        };
        let e = generate(&m, "K1", &p, &o).unwrap_err();
        assert!(matches!(e, GeneratorError::Option { .. }), "{e}");
    }
    let o = GeneratorOptions {
        step_deg: Some(1e-3),
        ..GeneratorOptions::default()
    };
    let e = generate(&m, "K1", &p, &o).unwrap_err();
    assert_eq!(
        e.to_string(),
        "test K1: a step of 0.001° over 360° gives more than 100000 samples, the most a test may have"
    );
}

#[test]
fn the_step_and_the_period_are_options() {
    let m = builtin("seed-ac");
    let p = m.default_parameters();
    let o = GeneratorOptions {
        step_deg: Some(2.0),
        period_s: 0.5,
        ..GeneratorOptions::default()
    };
    let r = generate(&m, "turn-C", &p, &o).unwrap();
    assert_eq!(r.samples.len(), 181);
    assert_eq!(deg(&m, &r, 1, "C"), 2.0);
    assert_eq!(r.samples[10].t, 5.0);
    check_record(&m, "turn-C", &r, &p, &o);
    // A step that does not divide the span: the next whole number of equal steps.
    let o = GeneratorOptions {
        step_deg: Some(7.0),
        ..GeneratorOptions::default()
    };
    let r = generate(&m, "turn-C", &p, &o).unwrap();
    assert_eq!(r.samples.len(), 53);
    assert!((deg(&m, &r, 1, "C") - 360.0 / 52.0).abs() < 1e-12);
    assert_eq!(deg(&m, &r, 52, "C"), 360.0);
}

#[test]
fn the_clearance_rule_shapes_the_turns_and_refuses_what_breaks_it() {
    let m = builtin("seed-ac");
    let p = m.default_parameters();
    let o = GeneratorOptions {
        clearance: Clearance {
            max_tilt_deg: 60.0,
            ..Clearance::default()
        },
        ..GeneratorOptions::default()
    };
    let t = tests_with(&m, &o.clearance);
    let turn_a = t.iter().find(|t| t.name == "turn-A").unwrap();
    assert_eq!((turn_a.sweep.from_deg, turn_a.sweep.to_deg), (-60.0, 60.0));
    let pair = t.iter().find(|t| t.name == "pair-A-C").unwrap();
    assert_eq!(pair.sweep.follower.unwrap().amplitude_deg, -30.0);
    for name in ["turn-A", "pair-A-C", "turn-C"] {
        let r = generate(&m, name, &p, &o).unwrap();
        check_record(&m, name, &r, &p, &o);
    }
    // The seed's K2 keeps its angles and goes beyond 60°: refused at its first sample.
    let e = generate(&m, "K2", &p, &o).unwrap_err();
    assert_eq!(
        e.to_string(),
        "test K2, sample 1 of 121 (t = 0 s; A = -90°, C = 0°): the tool axis tilts 90° from the table normal, more than the 60° of the clearance rule"
    );
    // The ball must stand above the table by the nest's reach.
    let one = fixture("codegen/tests/machines/one-rotary.toml");
    let o = GeneratorOptions {
        clearance: Clearance {
            min_ball_height_mm: 50.0,
            ..Clearance::default()
        },
        ..GeneratorOptions::default()
    };
    let e = generate(&one, "turn-B", &one.default_parameters(), &o).unwrap_err();
    assert_eq!(
        e.to_string(),
        "the ball centre stands 40 mm above the face of the B table, less than the 50 mm the nest needs (the minimum ball height of the clearance rule): raise the ball"
    );
    let mut p = m.default_parameters();
    p[m.symbol_by_name("Zw").unwrap()] = 12.0;
    let e = generate(&m, "K1", &p, &GeneratorOptions::default()).unwrap_err();
    assert!(matches!(e, GeneratorError::BallTooLow { .. }), "{e}");
    // Nothing tilts the tool axis of a table turning about it: a tilt of 0° allows turn-C
    // only, and turn-A has no room.
    let o = GeneratorOptions {
        clearance: Clearance {
            max_tilt_deg: 0.0,
            ..Clearance::default()
        },
        ..GeneratorOptions::default()
    };
    let p = m.default_parameters();
    let r = generate(&m, "turn-C", &p, &o).unwrap();
    check_record(&m, "turn-C", &r, &p, &o);
    let e = generate(&m, "turn-A", &p, &o).unwrap_err();
    assert_eq!(
        e.to_string(),
        "test turn-A: axis A cannot turn: its range and the clearance rule leave it only 0°"
    );
}

/// A machine whose A head and D table both turn about x: the tilt is the difference of the two
/// angles, so the pair moves both ways and the secondary's swing must be reduced.
const TWO_TILTS: &str = r#"
name = "two-tilts"
[symbols]
Zw = 60.0
Zt = -150.0
[[work]]
axis = "D"
type = "rotary"
direction = "+x"
range = [-100, 100]
[[work]]
end = "ball"
offset = [0, 0, "Zw"]
[[tool]]
axis = "X"
type = "linear"
direction = "+x"
stroke = [-800, 800]
[[tool]]
axis = "Y"
type = "linear"
direction = "+y"
stroke = [-800, 800]
[[tool]]
axis = "Z"
type = "linear"
direction = "+z"
stroke = [-800, 800]
[[tool]]
axis = "A"
type = "rotary"
direction = "+x"
range = [-100, 100]
[[tool]]
end = "probe"
offset = [0, 0, "Zt"]
"#;

#[test]
fn a_pair_that_would_tilt_too_far_swings_less() {
    let m = parse_machine("two-tilts.toml", TWO_TILTS).unwrap();
    let p = m.default_parameters();
    let o = GeneratorOptions::default();
    let t = tests(&m);
    assert_eq!(
        t.iter().map(|t| t.name.as_str()).collect::<Vec<_>>(),
        ["turn-A", "turn-D", "pair-A-D"]
    );
    let pair = &t[2];
    let f = pair.sweep.follower.unwrap();
    assert_eq!(
        m.axes[pair.sweep.primary].name, "D",
        "the later letter on a tie"
    );
    assert_eq!(f.amplitude_deg, -45.0, "planned: A to -90°");
    let r = generate_test(&m, pair, &p, &o).unwrap();
    check_record(&m, "pair-A-D", &r, &p, &o);
    let reach = r
        .samples
        .iter()
        .map(|s| -s.commands[f.axis].to_degrees())
        .fold(0.0, f64::max);
    assert!(reach > 30.0 && reach < 90.0, "reduced swing {reach}°");
    // The largest swing: some sample is at the tilt limit, to within the 1e-6° grid.
    let gauge = TiltGauge::new(&m);
    let worst = r
        .samples
        .iter()
        .map(|s| gauge.tilt_deg(&s.commands))
        .fold(0.0, f64::max);
    assert!(worst > 90.0 - 1e-4, "worst tilt {worst}°");
}

#[test]
fn a_range_narrower_than_the_test_is_used_as_it_is() {
    let text = std::fs::read_to_string(format!(
        "{}/../tests/machines/neg-table.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
    .replace("range = [-110.0, 110.0]", "range = [-30.0, 20.0]")
    .replace(
        "direction = \"-z\"\noffset = [0, 0, \"Zc\"]",
        "direction = \"-z\"\noffset = [0, 0, \"Zc\"]\nrange = [-200, 100]",
    );
    let m = parse_machine("narrow.toml", &text).unwrap();
    let t = tests(&m);
    let turn_a = t.iter().find(|t| t.name == "turn-A").unwrap();
    assert_eq!((turn_a.sweep.from_deg, turn_a.sweep.to_deg), (-30.0, 20.0));
    assert!(
        turn_a.description.contains("(its range)"),
        "{}",
        turn_a.description
    );
    let turn_c = t.iter().find(|t| t.name == "turn-C").unwrap();
    assert_eq!(
        (turn_c.sweep.from_deg, turn_c.sweep.to_deg),
        (-200.0, 100.0)
    );
    let pair = t.iter().find(|t| t.name == "pair-A-C").unwrap();
    assert_eq!(pair.sweep.follower.unwrap().amplitude_deg, -15.0);
    assert!(
        pair.description
            .contains("A = -15·(1 − cos(360°·(C + 200)/300))°"),
        "{}",
        pair.description
    );
    let (p, o) = (m.default_parameters(), GeneratorOptions::default());
    for t in &t {
        match generate_test(&m, t, &p, &o) {
            Ok(r) => check_record(&m, &t.name, &r, &p, &o),
            // The seed's tests keep their angles: K1 and K4 turn C to 360°, K2 tilts A to -90°.
            Err(e) => {
                assert_eq!(t.kind, TestKind::Seed, "{e}");
                assert!(e.to_string().contains("outside its range"), "{e}");
            }
        }
    }
}

#[test]
fn generated_paths_round_trip_through_the_csv_bit_for_bit() {
    let o = GeneratorOptions::default();
    for m in machines() {
        let mut p = m.default_parameters();
        // A ball moved by 5 mm where the description has a symbol for it.
        if let Some(s) = m.symbol_by_name("Yw") {
            p[s] += 5.0;
        }
        let mut read = ReadOptions::default();
        read.on_ball_tolerance_mm = f64::INFINITY;
        for t in tests(&m) {
            let r = generate_test(&m, &t, &p, &o).unwrap();
            let text = format_record(&m, &r, &[format!("{} {}", m.name, t.name)]).unwrap();
            let back = parse_path("p.csv", &text, &m, &read).unwrap();
            assert_eq!(back, r, "{} {}", m.name, t.name);
        }
    }
}
