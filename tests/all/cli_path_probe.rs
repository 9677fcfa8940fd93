//! End-to-end tests of `rtest path --probe` and `rtest probe-log`: the probing program of a
//! test in every dialect with its probe plan (and Heidenhain's FN 16 format file), read back by
//! `programs::reader` in the order of a probing program; a log made of the plan's contacts (the
//! sphere moved by a known offset) turned into the probe hits CSV, whose sphere fits give that
//! offset; bad flags, files and logs refused with one line naming the flag, file and line, and
//! nothing written.

use crate::common::{entries, fails, ok, temp_dir_tagged};
use fitting::sphere::{Latch, RadiusMode, SphereFitOptions, fit_sphere};
use formats::nc::Dialect;
use formats::poses::axis_words;
use formats::probe::read_probe_hits;
use model_spec::Machine;
use nalgebra::Vector3;
use programs::probe::{ProbePlan, check_order, read_probe_plan};
use programs::reader::{Step, read_program};
use simulation::exact::tool_centre_point_ik;
use std::path::Path;

const PROBE: &str = "name = \"TS 460\"\ntip_radius_mm = 1.5\nsphere_radius_mm = 12.5\n";

fn seed() -> Machine {
    model_spec::builtin("seed-ac").unwrap().unwrap()
}

/// `rtest path` of turn-C at 120° steps (4 poses) with the probe in `dialect`, to `file`.
fn program(dir: &Path, dialect: &str, file: &str) -> String {
    std::fs::write(dir.join("probe.toml"), PROBE).unwrap();
    ok(
        dir,
        &[
            "path",
            "--machine",
            "seed-ac",
            "--test",
            "turn-C",
            "--step-deg",
            "120",
            "--probe",
            "probe.toml",
            "--nc",
            dialect,
            "-o",
            file,
        ],
    )
}

/// A log of `dialect` of the plan's contacts moved by `shift` (mm on X, Y, Z), every number in
/// full.
fn log_of(m: &Machine, plan: &ProbePlan, dialect: Dialect, shift: [f64; 3]) -> String {
    let at = |r: &[f64], n: &str| r[m.axis_by_name(n).unwrap()];
    plan.rows
        .iter()
        .map(|r| {
            let (x, y, z) = (
                at(&r.axes, "X") + shift[0],
                at(&r.axes, "Y") + shift[1],
                at(&r.axes, "Z") + shift[2],
            );
            match dialect {
                Dialect::LinuxCnc => format!(
                    "{x} {y} {z} {} 0 {} 0 0 0\n",
                    at(&r.axes, "A"),
                    at(&r.axes, "C")
                ),
                _ => format!("X {x} Y {y} Z {z}\n"),
            }
        })
        .collect()
}

#[test]
fn every_dialect_writes_a_program_that_reads_back_and_its_log_becomes_hits() {
    let m = seed();
    let shift = [0.04, -0.025, 0.015];
    for (name, dialect, file) in [
        ("linuxcnc", Dialect::LinuxCnc, "k.ngc"),
        ("iso", Dialect::Iso, "k.nc"),
        ("heidenhain", Dialect::Heidenhain, "k.h"),
    ] {
        let dir = temp_dir_tagged("cli-path-probe", name);
        let out = program(&dir, name, file);
        assert!(
            out.starts_with(&format!(
                "Probing program ({name}) of test turn-C of machine seed-ac: 4 poses probed, 36 hits, nominal duration "
            )),
            "{out}"
        );
        assert!(out.contains(&format!("rtest probe-log --machine seed-ac --plan k.plan.csv --log LOG --nc {name} -o hits.csv")), "{out}");
        let mut expected = vec![file.to_string(), "k.plan.csv".into(), "probe.toml".into()];
        if dialect == Dialect::Heidenhain {
            expected.push("k.A".into());
            assert_eq!(
                std::fs::read_to_string(dir.join("k.A")).unwrap(),
                "\"X %+.4LF Y %+.4LF Z %+.4LF\", Q115, Q116, Q117;\n"
            );
        }
        expected.sort();
        assert_eq!(entries(&dir), expected, "{name}");
        let text = std::fs::read_to_string(dir.join(file)).unwrap();
        let read = read_program(file, &text, dialect, &axis_words(&m)).unwrap();
        check_order(&read, dialect).unwrap();
        let plan = read_probe_plan(&dir.join("k.plan.csv"), &m).unwrap();
        assert_eq!(plan.rows.len(), 36);
        // The plan's lines are the program's probing blocks.
        let probes: Vec<usize> = read
            .blocks
            .iter()
            .filter(|b| b.step == Step::Probe && b.motion.is_some())
            .map(|b| b.line)
            .collect();
        assert_eq!(
            plan.rows.iter().map(|r| r.line).collect::<Vec<_>>(),
            probes,
            "{name}"
        );
        match dialect {
            Dialect::LinuxCnc => assert!(text.contains("(PROBEOPEN k.txt)\n"), "{name}"),
            Dialect::Heidenhain => assert!(text.contains(" FN 16: F-PRINT k.A / k.TXT\n")),
            _ => assert!(text.contains("\nPOPEN\n") && text.contains("\nPCLOS\n")),
        }
        // The control's log: the sphere is `shift` off its nominal place.
        std::fs::write(dir.join("k.log"), log_of(&m, &plan, dialect, shift)).unwrap();
        let out = ok(
            &dir,
            &[
                "probe-log",
                "--machine",
                "seed-ac",
                "--plan",
                "k.plan.csv",
                "--log",
                "k.log",
                "--nc",
                name,
                "-o",
                "hits.csv",
            ],
        );
        assert!(
            out.starts_with("Matched the 36 trips of k.log with the plan's hits: 4 poses. Largest distance of a latch from its planned contact: 0.049497 mm ("),
            "{name}: {out}"
        );
        let hits = read_probe_hits(&dir.join("hits.csv"), &m).unwrap();
        let labels: Vec<&str> = hits.poses.iter().map(|p| p.label.as_str()).collect();
        assert_eq!(labels, ["p1", "p2", "p3", "p4"]);
        for pose in &hits.poses {
            let mut q = formats::poses::from_file_units(&m, &pose.hits[0].axes);
            tool_centre_point_ik(&m, &mut q, &m.default_parameters()).unwrap();
            let idx = |n: &str| m.axis_by_name(n).unwrap();
            let centre = Vector3::new(q[idx("X")], q[idx("Y")], q[idx("Z")]);
            let latches: Vec<Latch> = pose
                .hits
                .iter()
                .map(|h| {
                    let p = Vector3::new(h.axes[idx("X")], h.axes[idx("Y")], h.axes[idx("Z")]);
                    Latch {
                        tip_mm: p,
                        approach: (centre - p).normalize(),
                    }
                })
                .collect();
            let fit = fit_sphere(
                &latches,
                &SphereFitOptions {
                    radius: RadiusMode::Calibrated {
                        sphere_radius_mm: 12.5,
                    },
                    tip_radius_mm: 1.5,
                    noise_mm: 0.0005,
                },
            )
            .unwrap();
            let e = fit.centre_mm - centre - Vector3::from(shift);
            assert!(e.norm() < 1e-9, "{name} {}: {e:?}", pose.label);
        }
    }
}

#[test]
fn both_directions_label_each_pose_twice() {
    let dir = temp_dir_tagged("cli-path-probe", "both");
    std::fs::write(dir.join("probe.toml"), PROBE).unwrap();
    let out = ok(
        &dir,
        &[
            "path",
            "--machine",
            "seed-ac",
            "--test",
            "turn-C",
            "--step-deg",
            "180",
            "--probe",
            "probe.toml",
            "--nc",
            "linuxcnc",
            "--both-directions",
            "--overshoot-deg",
            "3",
            "-o",
            "b.ngc",
            "--plan",
            "b-plan.csv",
        ],
    );
    assert!(out.contains("6 poses probed, 54 hits"), "{out}");
    let plan = read_probe_plan(&dir.join("b-plan.csv"), &seed()).unwrap();
    let labels: Vec<&str> = plan
        .rows
        .iter()
        .step_by(9)
        .map(|r| r.pose.as_str())
        .collect();
    assert_eq!(labels, ["p1+", "p1-", "p2+", "p2-", "p3+", "p3-"]);
    let text = std::fs::read_to_string(dir.join("b.ngc")).unwrap();
    assert!(
        text.contains("(pose p2+: A0 C180)\nG53 G0 A-3.0000 C177.0000\nG53 G0 A0.0000 C180.0000\n"),
        "{text}"
    );
}

#[test]
fn bad_flags_files_and_logs_are_refused_and_nothing_is_written() {
    let dir = temp_dir_tagged("cli-path-probe", "errors");
    std::fs::write(dir.join("probe.toml"), PROBE).unwrap();
    let base = [
        "path",
        "--machine",
        "seed-ac",
        "--test",
        "turn-C",
        "--step-deg",
        "120",
        "--probe",
        "probe.toml",
    ];
    let with = |extra: &[&'static str]| -> Vec<&str> {
        base.iter().copied().chain(extra.iter().copied()).collect()
    };
    fails(&dir, &with(&["-o", "p.ngc"]), 2, &["--nc"]);
    fails(
        &dir,
        &with(&["--nc", "iso", "-o", "p.nc", "--continuous"]),
        2,
        &["'--probe <FILE>' cannot be used with '--continuous'"],
    );
    fails(
        &dir,
        &with(&["--nc", "iso", "-o", "p.nc", "--overshoot-deg", "2"]),
        2,
        &["--both-directions"],
    );
    fails(
        &dir,
        &with(&["--nc", "linuxcnc", "-o", "p.ngc", "--safe-mm", "1"]),
        2,
        &["--probe: safe height 1 mm above the sphere: above the pre-touch distance 2 mm"],
    );
    fails(
        &dir,
        &with(&["--nc", "heidenhain", "-o", "-", "--plan", "p.csv"]),
        2,
        &["--probe --nc heidenhain: the program's FN 16 reads a format file written beside it"],
    );
    fails(
        &dir,
        &with(&["--nc", "iso", "-o", "probe.toml"]),
        2,
        &["probe.toml"],
    );
    std::fs::write(
        dir.join("bad.toml"),
        "tip_radius_mm = -1\nsphere_radius_mm = 12.5\n",
    )
    .unwrap();
    let mut args = with(&["--nc", "iso", "-o", "p.nc"]);
    args[8] = "bad.toml";
    fails(
        &dir,
        &args,
        1,
        &["--probe: bad.toml:1:17: `tip_radius_mm` is -1 mm"],
    );
    // A pose whose hits meet the sphere's stem (A at -120° tilts the table beyond 90°).
    fails(
        &dir,
        &[
            "path",
            "--machine",
            "seed-ac",
            "--test",
            "turn-A",
            "--step-deg",
            "30",
            "--probe",
            "probe.toml",
            "--nc",
            "iso",
            "-o",
            "p.nc",
        ],
        2,
        &[
            "--test: pose at sample 1: the hit at (0, -1, 0) from the centre (bed frame) is 0° from the sphere's stem",
        ],
    );
    assert_eq!(entries(&dir), ["bad.toml", "probe.toml"]);

    // probe-log: a log one trip short, a trip far off, a line that is not a log's.
    program(&dir, "linuxcnc", "k.ngc");
    let m = seed();
    let plan = read_probe_plan(&dir.join("k.plan.csv"), &m).unwrap();
    let log = log_of(&m, &plan, Dialect::LinuxCnc, [0.0; 3]);
    let lines: Vec<&str> = log.lines().collect();
    let cmd = |log: &'static str, nc: &'static str| {
        vec![
            "probe-log",
            "--machine",
            "seed-ac",
            "--plan",
            "k.plan.csv",
            "--log",
            log,
            "--nc",
            nc,
            "-o",
            "hits.csv",
        ]
    };
    std::fs::write(dir.join("short.log"), lines[..35].join("\n") + "\n").unwrap();
    fails(
        &dir,
        &cmd("short.log", "linuxcnc"),
        1,
        &[
            "--log: short.log:36: the log ends after 35 trip(s), the plan has 36 hits: the first without a trip is pose p4, hit 9 (program line ",
        ],
    );
    let mut far: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
    // X 1000 mm off.
    far[6] = format!("1{}", far[6]);
    std::fs::write(dir.join("far.log"), far.join("\n") + "\n").unwrap();
    fails(
        &dir,
        &cmd("far.log", "linuxcnc"),
        1,
        &[
            "--log: far.log:7: trip 7 (pose p1, hit 7 (program line ",
            "beyond the 0.5 mm allowed",
        ],
    );
    fails(
        &dir,
        &cmd("far.log", "iso"),
        1,
        &[
            "--log: far.log:1: `",
            "where X belongs: a DPRNT line of the probe log is `X<number> Y<number> Z<number>`",
        ],
    );
    fails(
        &dir,
        &cmd("far.log", "fanuc"),
        2,
        &["--nc: `fanuc` is not a dialect"],
    );
    fails(
        &dir,
        &cmd("none.log", "linuxcnc"),
        1,
        &["--log: cannot read `none.log`"],
    );
    std::fs::write(dir.join("good.log"), &log).unwrap();
    let mut args = cmd("good.log", "linuxcnc");
    args.extend(["--max-deviation-mm", "0"]);
    fails(&dir, &args, 2, &["--max-deviation-mm"]);
    let mut args = cmd("good.log", "linuxcnc");
    args[4] = "good.log";
    fails(&dir, &args, 1, &["--plan: good.log:1: "]);
    let mut args = cmd("good.log", "linuxcnc");
    args[10] = "good.log";
    fails(&dir, &args, 2, &["good.log"]);
    assert!(!dir.join("hits.csv").exists());
}

#[test]
fn a_tilting_heads_planned_poses_are_programmed_in_every_dialect_simulated_and_identified() {
    // head-table-bc's B tilts the probe: the pattern turns with it (and 22.5° about the stylus
    // pose after pose), so every pose the plan chooses, B from −60° to 60°, is written in
    // every dialect and read back; the same poses simulated and identified give the truth.
    let dir = temp_dir_tagged("cli-path-probe", "head");
    std::fs::write(dir.join("probe.toml"), format!("{PROBE}noise_um = 0.5\n")).unwrap();
    let terms = "XOW,YOW,ZOW,XOB,ZOB,AOB,COB,XOC,YOC,AOC,BOC";
    ok(
        &dir,
        &[
            "plan",
            "--machine",
            "head-table-bc",
            "--probe",
            "probe.toml",
            "--terms",
            terms,
            "--constraint",
            "zero:XOC,ZOW",
            "--poses-out",
            "poses.csv",
        ],
    );
    let m = model_spec::builtin("head-table-bc").unwrap().unwrap();
    let poses = formats::paths::load_path(
        &m,
        &dir.join("poses.csv").to_string_lossy(),
        &formats::csv::ReadOptions::default(),
    )
    .unwrap();
    let b = m.axis_by_name("B").unwrap();
    let n = poses.samples.len();
    assert!(
        poses
            .samples
            .iter()
            .any(|s| s.commands[b].to_degrees().abs() > 45.0),
        "the plan tilts the head"
    );
    let vm = simulation::VirtualMachine::new(&m);
    let params = m.default_parameters();
    let pattern = simulation::probe::approach_directions();
    for (name, dialect, file) in [
        ("linuxcnc", Dialect::LinuxCnc, "h.ngc"),
        ("iso", Dialect::Iso, "h.nc"),
        ("heidenhain", Dialect::Heidenhain, "h.h"),
    ] {
        let out = ok(
            &dir,
            &[
                "path",
                "--machine",
                "head-table-bc",
                "--test",
                "poses.csv",
                "--probe",
                "probe.toml",
                "--nc",
                name,
                "-o",
                file,
            ],
        );
        assert!(
            out.contains(&format!("{n} poses probed, {} hits", 9 * n)),
            "{out}"
        );
        let text = std::fs::read_to_string(dir.join(file)).unwrap();
        let read = read_program(file, &text, dialect, &axis_words(&m)).unwrap();
        check_order(&read, dialect).unwrap();
        let plan = read_probe_plan(&dir.join("h.plan.csv"), &m).unwrap();
        assert_eq!(plan.rows.len(), 9 * n, "{name}");
        if dialect == Dialect::Heidenhain {
            continue;
        }
        // Every direction is the pattern's turned by the pose's nominal tool rotation and
        // 0°, 22.5°, 45°, 67.5° about the stylus.
        for (i, s) in poses.samples.iter().enumerate() {
            let r = *vm
                .nominal_chain_transform(model_spec::Side::Tool, &s.commands, &params)
                .rotation
                .matrix();
            let phi = [0.0f64, 22.5, 45.0, 67.5][i % 4].to_radians();
            for (k, d) in pattern.iter().enumerate() {
                let turned = Vector3::new(
                    d.x * phi.cos() - d.y * phi.sin(),
                    d.x * phi.sin() + d.y * phi.cos(),
                    d.z,
                );
                let got = Vector3::from(plan.rows[9 * i + k].direction);
                assert!(
                    (got - r * turned).norm() < 1e-9,
                    "{name}: pose {i}, hit {k}"
                );
            }
        }
    }
    std::fs::write(
        dir.join("t.toml"),
        "machine = \"head-table-bc\"\n[errors]\nYOW = 5\nXOW = 10\nXOB = -14\nZOB = 9\nAOB = 16\nCOB = -21\nYOC = 8\nAOC = -15\nBOC = 19\n",
    )
    .unwrap();
    ok(
        &dir,
        &[
            "simulate",
            "--machine",
            "head-table-bc",
            "--path",
            "poses.csv",
            "--probe",
            "probe.toml",
            "--truth",
            "t.toml",
            "-o",
            "hits.csv",
        ],
    );
    ok(
        &dir,
        &[
            "identify",
            "--machine",
            "head-table-bc",
            "--terms",
            terms,
            "--constraint",
            "zero:XOC,ZOW",
            "--data",
            "hits.csv",
            "--probe",
            "probe.toml",
            "--json",
            "id.json",
        ],
    );
    let id = crate::common::read_json(&dir.join("id.json"));
    let truth = [
        ("XOW", 10.0),
        ("YOW", 5.0),
        ("XOB", -14.0),
        ("ZOB", 9.0),
        ("AOB", 16.0),
        ("COB", -21.0),
        ("YOC", 8.0),
        ("AOC", -15.0),
        ("BOC", 19.0),
    ];
    let mut seen = 0;
    for p in id["parameters"].as_array().unwrap() {
        let Some((_, t)) = truth.iter().find(|(n, _)| p["name"] == *n) else {
            continue;
        };
        let (v, s) = (p["value"].as_f64().unwrap(), p["std"].as_f64().unwrap());
        assert!(
            ((v - t) / s).abs() < 4.0,
            "{}: {v} ± {s}, truth {t}",
            p["name"]
        );
        seen += 1;
    }
    assert_eq!(seen, truth.len());
}
