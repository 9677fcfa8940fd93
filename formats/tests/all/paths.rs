//! Test paths: K1, K2, K4 of seed-ac, path files with inverse-kinematics fill, and errors.

#![allow(clippy::needless_range_loop)] // x, y, z components read best by index

use crate::common;

use common::{Scratch, builtin};
use formats::csv::ReadOptions;
use formats::paths::{PathFileError, load_path, parse_path};
use model_spec::Machine;
use simulation::VirtualMachine;
use simulation::paths::{BUILTIN_PATHS, PathError, SAMPLE_PERIOD_S, builtin_path, fill_linear_ik};
use simulation::record::Record;

fn seed_ac() -> Machine {
    builtin("seed-ac")
}

fn deg(m: &Machine, r: &Record, i: usize, axis: &str) -> f64 {
    r.samples[i].commands[m.axis_by_name(axis).unwrap()].to_degrees()
}

fn assert_closed(m: &Machine, r: &Record) {
    let vm = VirtualMachine::new(m);
    let p = m.default_parameters();
    for s in &r.samples {
        let gap = vm.nominal_error_vector(&s.commands, &p).position;
        assert!(gap.amax() < 1e-9, "nominal gap {gap:?}");
    }
}

#[test]
fn k1_k2_k4_are_as_designed() {
    let m = seed_ac();
    let k1 = builtin_path(&m, "K1").unwrap().unwrap();
    let k2 = builtin_path(&m, "K2").unwrap().unwrap();
    let k4 = builtin_path(&m, "K4").unwrap().unwrap();
    assert_eq!(
        (k1.samples.len(), k2.samples.len(), k4.samples.len()),
        (361, 121, 241)
    );
    let (a, c) = (m.axis_by_name("A").unwrap(), m.axis_by_name("C").unwrap());
    for (i, s) in k1.samples.iter().enumerate() {
        assert_eq!(s.commands[a], 0.0);
        assert_eq!(s.commands[c], (i as f64).to_radians());
    }
    for (i, s) in k2.samples.iter().enumerate() {
        assert_eq!(s.commands[a], (-90.0 + i as f64).to_radians());
        assert_eq!(s.commands[c], 0.0);
    }
    for (i, s) in k4.samples.iter().enumerate() {
        let cd = 1.5 * i as f64;
        assert_eq!(s.commands[c], cd.to_radians());
        let ad = -45.0 * (1.0 - cd.to_radians().cos());
        assert_eq!(s.commands[a], ad.to_radians());
    }
    assert!(
        (deg(&m, &k4, 60, "A") + 45.0).abs() < 1e-12,
        "C = 90°: A = -45°"
    );
    assert!(
        (deg(&m, &k4, 120, "A") + 90.0).abs() < 1e-12,
        "C = 180°: A = -90°"
    );
    for r in [&k1, &k2, &k4] {
        assert!(r.measured.is_empty());
        for (i, s) in r.samples.iter().enumerate() {
            assert_eq!(s.t, i as f64 * SAMPLE_PERIOD_S);
        }
        assert_closed(&m, r);
    }
    // Every axis moves on K4; directions of motion follow the moves.
    let first = &k4.samples[0].commands;
    let last = &k4.samples[240].commands;
    for ax in 0..m.axes.len() {
        assert!(
            k4.samples.iter().any(|s| s.commands[ax] != first[ax]),
            "axis {} moves",
            m.axes[ax].name
        );
    }
    assert!((last[c] - 2.0 * std::f64::consts::PI).abs() < 1e-12);
    assert_eq!(k4.samples[10].motion[a], -1, "A goes down first");
    assert_eq!(k4.samples[130].motion[a], 1, "and comes back up");
    assert!(k1.samples.iter().all(|s| s.motion[c] == 1));
    assert!(k2.samples.iter().all(|s| s.motion[a] == 1));
}

#[test]
fn builtin_names_ignore_case_and_others_are_not_builtin() {
    let m = seed_ac();
    assert_eq!(BUILTIN_PATHS, ["K1", "K2", "K4"]);
    let a = builtin_path(&m, "k4").unwrap().unwrap();
    let b = builtin_path(&m, "K4").unwrap().unwrap();
    assert_eq!(a, b);
    assert!(builtin_path(&m, "K3").is_none());
    let e = load_path(&m, "K3", &ReadOptions::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "`K3` is neither a test of machine seed-ac (K1, K2, K4, turn-A, turn-C, pair-A-C) nor an existing file"
    );
}

#[test]
fn builtin_paths_need_rotary_axes_a_and_c() {
    let e = load_path(&builtin("head-table-bc"), "K4", &ReadOptions::default()).unwrap_err();
    assert!(matches!(e, PathFileError::Builtin(PathError::NotAC { .. })));
    assert_eq!(
        e.to_string(),
        "path K4 is defined only for machines whose rotary axes are A and C (like seed-ac); machine head-table-bc has rotary axes B, C: its tests are turn-B, turn-C, pair-B-C, or give the path as a CSV file"
    );
    let e = load_path(&builtin("seed-3axis"), "k1", &ReadOptions::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "path K1 is defined only for machines whose rotary axes are A and C (like seed-ac); machine seed-3axis has no rotary axes: give the path as a CSV file"
    );
}

#[test]
fn a_path_file_without_linear_columns_is_filled_by_inverse_kinematics() {
    let m = seed_ac();
    let k4 = builtin_path(&m, "K4").unwrap().unwrap();
    // The K4 rotary commands in degrees, columns C before A, no time, comments.
    let mut text = String::from("# K4, rotary axes only\nC,A\n");
    for s in &k4.samples {
        let a = s.commands[m.axis_by_name("A").unwrap()];
        let c = s.commands[m.axis_by_name("C").unwrap()];
        text += &format!(
            "{},{}\n",
            model_spec::units::degrees_for(c),
            model_spec::units::degrees_for(a)
        );
    }
    let dir = Scratch::new("paths");
    let f = dir.0.join("k4-rotary.csv");
    std::fs::write(&f, &text).unwrap();
    let mut r = load_path(&m, f.to_str().unwrap(), &ReadOptions::default()).unwrap();
    // Without a `t_s` column the samples are only numbered.
    assert!(!r.has_times() && r.samples.iter().all(|s| !s.timed));
    r.samples.iter_mut().for_each(|s| s.timed = true);
    assert!(r == k4, "same commands bit for bit, t = i s, same motion");
    assert_closed(&m, &r);
}

#[test]
fn path_fixture_on_disk() {
    let m = seed_ac();
    let f = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/path-ac.csv");
    let r = load_path(&m, f, &ReadOptions::default()).unwrap();
    assert_eq!(r.samples.len(), 5);
    assert_eq!(
        r.samples.iter().map(|s| s.t).collect::<Vec<_>>(),
        vec![0.0, 0.5, 1.0, 1.5, 2.0]
    );
    assert!(r.measured.is_empty());
    assert_closed(&m, &r);
}

#[test]
fn a_path_file_with_every_axis_is_taken_as_written() {
    let m = seed_ac();
    // At A = 0°, C = 90° the nest is on the ball at X, Y, Z = -0.279, -217.504, 56.661 mm;
    // the second sample is 0.239 mm above it, within the tolerance.
    let r = parse_path(
        "p.csv",
        "X,Y,Z,A,C\n-0.279,-217.504,56.661,0,90\n-0.279,-217.504,56.9,0,90\n",
        &m,
        &ReadOptions::default(),
    )
    .unwrap();
    let z = m.axis_by_name("Z").unwrap();
    assert_eq!(r.samples[1].commands[z], 56.9);
    assert_eq!(r.samples[0].commands[m.axis_by_name("X").unwrap()], -0.279);
    assert_eq!(r.samples[1].t, 1.0, "no t_s: t = sample index");
    // A three-axis machine: linear axes only; its ball is fixed at the origin, the nest within
    // 0.37 mm of it.
    let m3 = builtin("seed-3axis");
    let names: Vec<&str> = m3.axes.iter().map(|a| a.name.as_str()).collect();
    let r = parse_path(
        "p.csv",
        &format!("{}\n0.1,0.2,0.3\n", names.join(",")),
        &m3,
        &ReadOptions::default(),
    )
    .unwrap();
    assert_eq!(r.samples[0].commands, vec![0.1, 0.2, 0.3]);
}

#[test]
fn path_file_errors() {
    let m = seed_ac();
    let e = parse_path("p.csv", "X,A,C\n0,0,0\n", &m, &ReadOptions::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "p.csv:1: missing column(s) Y, Z (linear axes, mm): give every linear axis or none (then they are filled by the nominal inverse kinematics)"
    );
    let e = parse_path("p.csv", "A\n0\n", &m, &ReadOptions::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "p.csv:1: missing column(s) C (rotary axes, degrees): every rotary axis needs a column"
    );
    let e = parse_path("p.csv", "A,C,dx_um\n0,0,1\n", &m, &ReadOptions::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "p.csv:1: missing column(s) dy_um, dz_um (measured error vector, µm): a measurement file needs dx_um, dy_um and dz_um"
    );
    // Measured columns are allowed in a path file and ignored.
    let r = parse_path(
        "p.csv",
        "A,C,dx_um,dy_um,dz_um\n0,0,1,2,3\n",
        &m,
        &ReadOptions::default(),
    )
    .unwrap();
    assert!(r.measured.is_empty());
}

#[test]
fn fill_linear_ik_reports_the_failing_sample() {
    let m = builtin("seed-3axis");
    let mut q = vec![vec![0.0; m.axes.len()]; 3];
    // seed-3axis has three linear axes: the inverse kinematics works at every pose.
    fill_linear_ik(&m, &m.default_parameters(), &mut q).unwrap();
    // A machine with two linear axes cannot place the tool point.
    let text = r#"
name = "two-linear"
[[work]]
axis = "X"
type = "linear"
direction = "+x"
stroke = [-100, 100]
[[work]]
axis = "C"
type = "rotary"
direction = "+z"
[[work]]
end = "ball"
[[tool]]
axis = "Z"
type = "linear"
direction = "+z"
stroke = [-100, 100]
[[tool]]
end = "probe"
"#;
    let m2 = model_spec::parse_machine("two.toml", text).unwrap();
    let mut q = vec![vec![0.0; m2.axes.len()]; 2];
    let (i, e) = fill_linear_ik(&m2, &m2.default_parameters(), &mut q).unwrap_err();
    assert_eq!(i, 0);
    assert!(
        e.to_string().contains("needs exactly three linear axes"),
        "{e}"
    );
    let err = parse_path("p.csv", "# c\nC\n0\n10\n", &m2, &ReadOptions::default()).unwrap_err();
    assert!(
        err.to_string().starts_with(
            "p.csv:3: the linear axes are not given and the nominal inverse kinematics cannot fill them: machine `two-linear`: the tool-centre-point inverse kinematics needs exactly three linear axes"
        ),
        "{err}"
    );
}
