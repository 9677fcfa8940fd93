//! End-to-end tests of `rtest path`: the list of a machine's tests, a test written as a path
//! CSV that reads back to the generator's poses bit for bit, `simulate --path NAME` on any
//! machine, and bad input refused with one stderr line, the right exit code and no file.

use formats::csv::ReadOptions;
use formats::paths::parse_path;
use model_spec::Machine;
use simulation::generator::{GeneratorOptions, generate};
use simulation::paths::builtin_path;

use crate::common;
use common::{entries, fails, ok, read_json, temp_dir_tagged};

fn machine(name: &str) -> Machine {
    model_spec::builtin(name).unwrap().unwrap()
}

#[test]
fn the_list_names_every_test_with_one_line_each() {
    let dir = temp_dir_tagged("cli-path", "list");
    let out = ok(&dir, &["path", "--machine", "head-table-bc", "--list"]);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 10, "{out}");
    assert!(
        lines[0].starts_with("Tests of machine head-table-bc"),
        "{out}"
    );
    // Every test, then its reversed and there-and-back versions.
    assert!(lines[1].trim_start().starts_with("turn-B  "), "{out}");
    assert!(lines[2].trim_start().starts_with("turn-B-rev  "), "{out}");
    assert!(lines[3].trim_start().starts_with("turn-B-back  "), "{out}");
    assert!(lines[4].trim_start().starts_with("turn-C  "), "{out}");
    assert!(
        lines[7].contains("pair-B-C       C turns 0° .. 360° in 1.5° steps, B = -45·(1 − cos C)°"),
        "{out}"
    );
    assert!(
        lines[9].contains("pair-B-C-back  there and back (the poses forward, then reversed, the turning point once): C turns 0° .. 360° in 1.5° steps, B = -45·(1 − cos C)° (481 samples)"),
        "{out}"
    );
    // A machine without rotary axes says so.
    let out = ok(&dir, &["path", "--machine", "seed-3axis", "--list"]);
    assert_eq!(
        out,
        "Machine seed-3axis has no rotary axis, so it has no R-test test (the tests turn rotary axes): give a path as a CSV file.\n"
    );
    // With a ball position, the tests it puts out of stroke say where.
    let out = ok(
        &dir,
        &[
            "path",
            "--machine",
            "seed-ac",
            "--list",
            "--param",
            "Xw=-450",
        ],
    );
    assert!(
        out.contains("not generated here: test turn-C, sample 64 of 361 (t = 63 s; A = 0°, C = 63°): Y = -401.079599 mm outside its stroke -400 .. 400 mm"),
        "{out}"
    );
    // The list as JSON.
    ok(
        &dir,
        &[
            "path",
            "--machine",
            "seed-ac",
            "--list",
            "--json",
            "list.json",
        ],
    );
    let json = read_json(&dir.join("list.json"));
    let tests = json["tests"].as_array().unwrap();
    let names: Vec<&str> = tests.iter().map(|t| t["name"].as_str().unwrap()).collect();
    let forward: Vec<&str> = names.iter().copied().step_by(3).collect();
    assert_eq!(forward, ["K1", "K2", "K4", "turn-A", "turn-C", "pair-A-C"]);
    assert_eq!(&names[15..], ["pair-A-C", "pair-A-C-rev", "pair-A-C-back"]);
    assert_eq!(tests[15]["follower"]["amplitude_deg"], -45.0);
    assert_eq!(tests[15]["samples"], 241);
    assert_eq!(tests[16]["samples"], 241);
    assert_eq!(tests[17]["samples"], 481);
    assert_eq!(
        [
            &tests[15]["order"],
            &tests[16]["order"],
            &tests[17]["order"]
        ],
        ["forward", "reversed", "there and back"]
    );
    assert_eq!(tests[9]["from_deg"], -90.0);
    assert!(tests.iter().all(|t| t["within_limits"] == true));
}

#[test]
fn a_test_written_reads_back_to_the_generators_poses() {
    let dir = temp_dir_tagged("cli-path", "write");
    let cases: [(&str, &str, &[&str]); 4] = [
        ("seed-ac", "K4", &[]),
        ("seed-ac", "turn-A", &["--param", "Xw=-200,Zw=180"]),
        ("head-table-bc", "pair-b-c", &["--step-deg", "2.5"]),
        ("head-table-bc", "turn-B", &["--period-s", "0.25"]),
    ];
    for (m_name, test, extra) in cases {
        let m = machine(m_name);
        let mut args = vec!["path", "--machine", m_name, "--test", test, "-o", "p.csv"];
        args.extend_from_slice(extra);
        let out = ok(&dir, &args);
        assert!(out.ends_with("Wrote p.csv\n"), "{out}");
        let text = std::fs::read_to_string(dir.join("p.csv")).unwrap();
        assert!(text.starts_with("# rtest path: test "), "{text}");
        let mut read = ReadOptions::default();
        read.on_ball_tolerance_mm = f64::INFINITY;
        let back = parse_path("p.csv", &text, &m, &read).unwrap();
        let mut params = m.default_parameters();
        let mut opts = GeneratorOptions::default();
        match extra {
            ["--param", _] => {
                params[m.symbol_by_name("Xw").unwrap()] = -200.0;
                params[m.symbol_by_name("Zw").unwrap()] = 180.0;
            }
            ["--step-deg", s] => opts.step_deg = Some(s.parse().unwrap()),
            ["--period-s", s] => opts.period_s = s.parse().unwrap(),
            _ => {}
        }
        let expected = generate(&m, test, &params, &opts).unwrap();
        assert_eq!(back, expected, "{m_name} {test} {extra:?}");
        if extra.is_empty() {
            assert_eq!(back, builtin_path(&m, test).unwrap().unwrap());
        }
    }
    // A ball away from the description's defaults: the reader of measurements would refuse
    // the path, and the summary says so.
    let out = ok(
        &dir,
        &[
            "path",
            "--machine",
            "seed-ac",
            "--test",
            "turn-C",
            "--param",
            "Yw=20",
            "-o",
            "q.csv",
        ],
    );
    assert!(out.contains("Note: at the description's default parameters this path leaves the nest up to 20.279 mm off the ball"), "{out}");
    // `-o -`: the CSV on standard output, the summary on standard error.
    let o = common::run(
        Some(&dir),
        &["path", "--machine", "seed-ac", "--test", "K2", "-o", "-"],
    );
    assert!(o.status.success());
    let text = common::stdout(&o);
    assert_eq!(text.lines().filter(|l| !l.starts_with('#')).count(), 122);
    assert!(common::stderr(&o).starts_with("Test K2 of machine seed-ac: 121 samples."));
}

#[test]
fn simulate_takes_the_tests_of_any_machine() {
    let dir = temp_dir_tagged("cli-path", "simulate");
    let out = ok(
        &dir,
        &[
            "simulate",
            "--machine",
            "head-table-bc",
            "--path",
            "pair-B-C",
            "-o",
            "s.csv",
        ],
    );
    assert!(
        out.starts_with("simulated pair-B-C on head-table-bc"),
        "{out}"
    );
    let text = std::fs::read_to_string(dir.join("s.csv")).unwrap();
    assert_eq!(text.lines().filter(|l| !l.starts_with('#')).count(), 242);
    fails(
        &dir,
        &[
            "simulate",
            "--machine",
            "head-table-bc",
            "--path",
            "K4",
            "-o",
            "s2.csv",
        ],
        2,
        &[
            "--path: path K4 is defined only for machines whose rotary axes are A and C",
            "its tests are turn-B, turn-C, pair-B-C",
        ],
    );
    fails(
        &dir,
        &[
            "simulate",
            "--machine",
            "seed-ac",
            "--path",
            "turn-X",
            "-o",
            "s2.csv",
        ],
        2,
        &[
            "`turn-X` is neither a test of machine seed-ac (K1, K2, K4, turn-A, turn-C, pair-A-C) nor an existing file",
        ],
    );
    assert_eq!(entries(&dir), ["s.csv"]);
}

#[test]
fn bad_input_is_refused_and_writes_nothing() {
    let dir = temp_dir_tagged("cli-path", "bad");
    let base = ["path", "--machine", "seed-ac", "-o", "x.csv"];
    let with = |more: &[&'static str]| -> Vec<&'static str> {
        let mut v = base.to_vec();
        v.extend_from_slice(more);
        v
    };
    let cases: [(&[&str], i32, &str); 10] = [
        (
            &["--test", "K3"],
            2,
            "--test: machine seed-ac has no test `K3` (its tests: K1, K2, K4, turn-A, turn-C, pair-A-C)",
        ),
        (
            &["--test", "K1", "--param", "Q=1"],
            2,
            "--param: machine seed-ac has no kinematic symbol `Q`",
        ),
        (
            &["--test", "K1", "--param", "Xw=inf"],
            2,
            "--param: `Xw=inf`: the value must be a finite number",
        ),
        (
            &["--test", "K1", "--step-deg", "nan"],
            2,
            "--step-deg: step = NaN: the step must be a finite number of degrees above 0",
        ),
        (
            &["--test", "K1", "--period-s", "-1"],
            2,
            "--period-s: period = -1",
        ),
        (
            &["--test", "turn-A", "--max-tilt-deg", "200"],
            2,
            "--max-tilt-deg: max tilt = 200",
        ),
        (
            &["--test", "turn-A", "--min-ball-height-mm", "300"],
            2,
            "--min-ball-height-mm: the ball centre stands 211.537 mm above the face of the C table, less than the 300 mm",
        ),
        (
            &["--test", "turn-C", "--param", "Xw=-450"],
            2,
            "--param: test turn-C, sample 64 of 361 (t = 63 s; A = 0°, C = 63°): Y = -401.079599 mm outside its stroke -400 .. 400 mm",
        ),
        (
            &["--test", "K2", "--max-tilt-deg", "80"],
            2,
            "--test: test K2, sample 1 of 121 (t = 0 s; A = -90°, C = 0°): the tool axis tilts 90° from the table normal, more than the 80° of the clearance rule",
        ),
        (
            &["--test", "turn-C", "--step-deg", "0.001"],
            2,
            "more than 100000 samples",
        ),
    ];
    for (more, code, needle) in cases {
        fails(&dir, &with(more), code, &[needle]);
    }
    fails(
        &dir,
        &[
            "path",
            "--machine",
            "seed-3axis",
            "--test",
            "turn-C",
            "-o",
            "x.csv",
        ],
        2,
        &["--test: machine seed-3axis has no rotary axis, so it has no R-test test"],
    );
    fails(
        &dir,
        &[
            "path",
            "--machine",
            "head-table-bc",
            "--test",
            "K4",
            "-o",
            "x.csv",
        ],
        2,
        &["--test: machine head-table-bc has no test `K4` (its tests: turn-B, turn-C, pair-B-C)"],
    );
    // An output that names the machine's file.
    std::fs::write(
        dir.join("m.toml"),
        model_spec::BUILTIN
            .iter()
            .find(|(n, _)| *n == "head-table-bc")
            .unwrap()
            .1,
    )
    .unwrap();
    fails(
        &dir,
        &[
            "path",
            "--machine",
            "m.toml",
            "--test",
            "turn-C",
            "-o",
            "m.toml",
        ],
        2,
        &["-o: `m.toml` is also the input of --machine"],
    );
    assert_eq!(entries(&dir), ["m.toml"]);
}

#[test]
fn the_nc_program_of_a_test_reads_back_to_its_poses_in_every_dialect() {
    use formats::nc::Dialect;
    use formats::poses::axis_words;
    use programs::reader::{Step, read_program};
    let dir = temp_dir_tagged("cli-path", "nc");
    for (machine_name, test, param) in [
        ("seed-ac", "K4", None),
        ("head-table-bc", "pair-B-C", Some("Zw=120")),
    ] {
        let m = machine(machine_name);
        let mut params = m.default_parameters();
        if param.is_some() {
            let z = m.symbols.iter().position(|s| s.name == "Zw").unwrap();
            params[z] = 120.0;
        }
        let path = generate(&m, test, &params, &GeneratorOptions::default()).unwrap();
        for (dialect, file) in [
            (Dialect::Iso, "p.nc"),
            (Dialect::LinuxCnc, "p.ngc"),
            (Dialect::Heidenhain, "p.h"),
        ] {
            let mut args = vec![
                "path",
                "--machine",
                machine_name,
                "--test",
                test,
                "--nc",
                dialect.name(),
                "-o",
                file,
            ];
            if let Some(p) = param {
                args.extend(["--param", p]);
            }
            let out = ok(&dir, &args);
            assert!(out.contains("Measurement program"), "{out}");
            let text = std::fs::read_to_string(dir.join(file)).unwrap();
            let program = read_program(file, &text, dialect, &axis_words(&m)).unwrap();
            // Machine coordinates, the approach, the stop, the poses, the retract, in order.
            assert_eq!(
                program.steps(),
                [
                    Step::Setup,
                    Step::Spindle,
                    Step::Clearance,
                    Step::Orient,
                    Step::Approach,
                    Step::Stop,
                    Step::Measure,
                    Step::Retract,
                    Step::End
                ],
                "{machine_name} {dialect:?}"
            );
            assert!(
                program
                    .blocks
                    .iter()
                    .filter_map(|b| b.motion.as_ref())
                    .all(|mv| mv.machine)
            );
            let poses = program.measuring_poses();
            assert_eq!(poses.len(), path.samples.len(), "{machine_name} {test}");
            for (p, s) in poses.iter().zip(&path.samples) {
                for (k, a) in m.axes.iter().enumerate() {
                    let want = match a.kind {
                        model_spec::AxisKind::Linear => s.commands[k],
                        model_spec::AxisKind::Rotary => s.commands[k].to_degrees(),
                    };
                    // The program's resolution: 0.0001 mm and 0.0001°.
                    let rounded = (want * 1e4).round() / 1e4;
                    assert!(
                        (p[k] - rounded).abs() < 1e-9,
                        "{machine_name} {test} {:?}: axis {} {} against {rounded}",
                        dialect,
                        a.name,
                        p[k]
                    );
                }
            }
            // The timing plan is written beside the program, one row per pose.
            let plan_file = dir.join(std::path::Path::new(file).with_extension("plan.csv"));
            let plan = programs::measure::read_plan(&plan_file, &m).unwrap();
            assert_eq!(plan.rows.len(), path.samples.len());
        }
    }
    // A dialect that is not one, and a program to standard output without --plan.
    fails(
        &dir,
        &[
            "path",
            "--machine",
            "seed-ac",
            "--test",
            "K4",
            "--nc",
            "fanuc",
            "-o",
            "x.nc",
        ],
        2,
        &[
            "--nc: `fanuc` is not a dialect (iso, linuxcnc or heidenhain; Fanuc-type controls read iso)",
        ],
    );
    fails(
        &dir,
        &[
            "path",
            "--machine",
            "seed-ac",
            "--test",
            "K4",
            "--nc",
            "iso",
            "-o",
            "-",
        ],
        2,
        &["--plan FILE"],
    );
}

#[test]
fn simulate_and_identify_take_the_ball_position_the_path_was_planned_at() {
    let dir = temp_dir_tagged("cli-path", "param");
    let out = ok(
        &dir,
        &[
            "simulate",
            "--machine",
            "seed-ac",
            "--path",
            "K4",
            "--param",
            "Zw=261.537",
            "-o",
            "k4h.csv",
        ],
    );
    assert!(out.contains("wrote k4h.csv"), "{out}");
    // Read at the ball position it was planned at, it identifies the demo truth's errors.
    let out = ok(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "k4h.csv",
            "--param",
            "Zw=261.537",
        ],
    );
    assert!(out.contains("rank 11 of 11"), "{out}");
    // At the description's defaults the nest is 50 mm off the ball: refused, saying so.
    fails(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "k4h.csv",
        ],
        1,
        &["off the nominal workpiece point by more than 0.5 mm"],
    );
    // A ball position that puts the test out of stroke is the generator's error.
    fails(
        &dir,
        &[
            "simulate",
            "--machine",
            "seed-ac",
            "--path",
            "K4",
            "--param",
            "Zw=311.537",
            "-o",
            "x.csv",
        ],
        1,
        &["sample 170 of 241", "outside its stroke"],
    );
    assert!(!dir.join("x.csv").exists());
}

/// The gap check of a measurement program names the flag that relaxes it, and the flag does:
/// 15° steps of K4 take the nest 1.9 mm off the ball, refused at the default 0.5 mm and
/// written with `--max-gap-mm 5`; beyond 5 mm the flag itself is refused.
#[test]
fn the_gap_check_names_and_takes_its_flag() {
    let dir = temp_dir_tagged("path", "gap");
    let base = "path --machine seed-ac --test K4 --nc iso -o k4.nc --step-deg 15";
    fails(
        &dir,
        &common::words(base),
        3,
        &[
            "the nest leaves the ball by 1.89",
            "rtest path --max-gap-mm",
        ],
    );
    assert!(entries(&dir).is_empty());
    ok(&dir, &common::words(&format!("{base} --max-gap-mm 5")));
    assert!(dir.join("k4.nc").exists());
    fails(
        &dir,
        &common::words(&format!("{base} --max-gap-mm 9")),
        2,
        &["--max-gap-mm", "`9` is not a number from 0.001 to 5"],
    );
}

/// The clearance, the approach and its feed are flags; a clearance outside the stroke of the
/// tool-axis slide, or nearer the ball than the approach's start, is refused naming the flag,
/// and nothing is written.
#[test]
fn the_clearance_and_the_approach_are_flags() {
    let dir = temp_dir_tagged("path", "clearance");
    let base = "path --machine seed-ac --test K4 --nc linuxcnc -o k4.ngc";
    ok(
        &dir,
        &common::words(&format!(
            "{base} --clearance-mm 300 --approach-mm 20 --approach-feed 250"
        )),
    );
    let text = std::fs::read_to_string(dir.join("k4.ngc")).unwrap();
    assert!(
        text.contains("\nG53 G0 Z300.0000\nG53 G0 A0.0000 C0.0000\nM19 R0\n"),
        "{text}"
    );
    assert!(text.contains(
        "\nG53 G0 Z76.6610\nG53 G94 G1 X217.5040 Y-0.2790 Z56.6610 A0.0000 C0.0000 F250.000\n(MSG,"
    ));
    assert!(text.ends_with("G53 G0 Z300.0000\nM2\n%\n"));
    assert!(
        text.contains("(5 clearance: Z rapids first to Z300 mm [machine],)"),
        "{text}"
    );
    for (flags, needle) in [
        (
            "--clearance-mm 900",
            "--nc: clearance Z 900 mm: outside the stroke of axis Z",
        ),
        (
            "--clearance-mm 60",
            "--nc: clearance Z 60 mm: the approach starts at Z 86.661 mm, beyond it",
        ),
        ("--clearance-mm -600", "outside the stroke of axis Z"),
    ] {
        let d = temp_dir_tagged("path", "clearance-bad");
        fails(&d, &common::words(&format!("{base} {flags}")), 2, &[needle]);
        assert!(entries(&d).is_empty());
    }
    fails(
        &dir,
        &common::words(&format!("{base} --approach-mm 0")),
        2,
        &["--approach-mm", "is not a number from 0.001 to 500"],
    );
    fails(
        &dir,
        &common::words("path --machine seed-ac --test K4 --approach-mm 10 -o x.csv"),
        2,
        &["--nc"],
    );
}
