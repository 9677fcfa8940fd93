//! rtest's LinuxCNC outputs against the real LinuxCNC (`support::linuxcnc`), in three steps,
//! on seed-ac (`xyzac-trt-kins`) and table-table-bc (`xyzbc-trt-kins`):
//!
//! 1. at zero errors, LinuxCNC's joints for the world positions of 50 poses are rtest's own
//!    commands (within 1e-6 mm and 1e-6°);
//! 2. on a machine whose errors are only what the pins hold (the location translations of the
//!    two rotary axes), the pins rtest computes make LinuxCNC put the tool on the ball
//!    (within 1e-6 mm) at 50 orientations;
//! 3. on a machine with errors the pins cannot hold (angular location, squareness, component
//!    errors varying with the position), the corrected program in joint coordinates, run
//!    through LinuxCNC's identity kinematics, leaves under 0.02 µm.
//!
//! Steps 1 and 2 of a machine share one LinuxCNC run (the pins set between them); step 3 runs
//! other kinematics, in a run of its own.

use crate::common::temp_dir_tagged;
use crate::identified::errors_of;
use crate::support::linuxcnc::{Config, for_test, number};
use compensation::controllers::linuxcnc::{TrtKinematics, check_poses, trt_kinematics};
use compensation::kinematics::corrected_description;
use compensation::run::{CommandedPose, compensate_poses};
use compensation::values::MachineErrors;
use formats::controllers::linuxcnc::hal_file;
use model_spec::{Machine, Side, parse_machine};
use nalgebra::Vector3;
use simulation::exact::{VirtualMachine, tool_centre_point_ik};

fn machine(name: &str) -> Machine {
    model_spec::builtin::builtin(name).unwrap().unwrap()
}

/// The true error values at a pose (catalogue order, mm and rad).
fn catalogue_values(m: &Machine, errors: &MachineErrors, q: &[f64]) -> Vec<f64> {
    let mut at = vec![0.0; errors.errors().len()];
    errors.values_at(m, q, &mut at);
    let mut v = vec![0.0; m.catalogue.len()];
    for (e, x) in errors.errors().iter().zip(at) {
        v[*e] = x;
    }
    v
}

/// The distance between the tool point and the ball (mm) on `m` with `errors` at `q`.
fn gap(m: &Machine, errors: &MachineErrors, q: &[f64]) -> f64 {
    let v = catalogue_values(m, errors, q);
    let vm = VirtualMachine::new(m);
    let p = m.default_parameters();
    let tool = vm.chain_transform(Side::Tool, q, &p, &v);
    let work = vm.chain_transform(Side::Work, q, &p, &v);
    (tool.translation.vector - work.translation.vector).norm()
}

/// The world position of the description's tool point at `q` (mm): in the workpiece frame,
/// minus the world origin.
fn world(m: &Machine, k: &TrtKinematics, q: &[f64]) -> Vector3<f64> {
    let vm = VirtualMachine::new(m);
    let p = m.default_parameters();
    let tool = vm.nominal_chain_transform(Side::Tool, q, &p);
    let work = vm.nominal_chain_transform(Side::Work, q, &p);
    work.inverse_transform_point(&tool.translation.vector.into())
        .coords
        - Vector3::from(k.world_origin)
}

/// The MDI blocks: the modes, then one straight move per pose (world position and angles).
fn blocks(k: &TrtKinematics, poses: &[(Vector3<f64>, [f64; 2])]) -> Vec<String> {
    let (t, c) = (k.joints[3].letter, k.joints[4].letter);
    let mut b = vec!["G90 G21 G17 G40 G49 G61 G94".to_string()];
    for (p, [tilt, turn]) in poses {
        b.push(format!(
            "G1 X{} Y{} Z{} {t}{} {c}{} F1000000",
            number(p[0]),
            number(p[1]),
            number(p[2]),
            number(*tilt),
            number(*turn)
        ));
    }
    b
}

/// The module's angles (degrees) of `q`.
fn angles(k: &TrtKinematics, q: &[f64]) -> [f64; 2] {
    let j = k.joints_of(q);
    [j[3], j[4]]
}

/// Step 1 on `name`: the rows of LinuxCNC's joints after each of `blocks` (the modes, then one
/// move per check pose at the world positions of rtest's commands at zero errors, with `k` the
/// kinematics of the nominal description) give rtest's own commands.
fn zero_errors_give_rtests_joints(name: &str, k: &TrtKinematics, rows: &[[f64; 5]]) {
    let m = machine(name);
    let poses = check_poses(&m);
    assert_eq!(rows.len(), poses.len(), "{name}: one row per pose");
    let (mut mm, mut deg) = (0.0f64, 0.0f64);
    for (q, got) in poses.iter().zip(rows) {
        let want = k.joints_of(q);
        for j in 0..5 {
            let d = (got[j] - want[j]).abs();
            if j < 3 {
                mm = mm.max(d)
            } else {
                deg = deg.max(d)
            }
        }
    }
    eprintln!("{name}: LinuxCNC's joints against rtest's: {mm:.2e} mm, {deg:.2e}°");
    assert!(mm < 1e-6 && deg < 1e-6, "{name}: {mm} mm, {deg}°");
}

/// Step 2 on `name` with `truth` (location translations, mm): `k` the kinematics of the
/// corrected description, `rows` LinuxCNC's joints after each move to the ball at the check
/// poses' angles with `k`'s pins.
fn the_pins_put_the_tool_on_the_ball(
    name: &str,
    truth: &[(&str, f64)],
    k: &TrtKinematics,
    rows: &[[f64; 5]],
) {
    let m = machine(name);
    let errors = errors_of(&m, truth);
    assert_eq!(
        rows.len(),
        check_poses(&m).len(),
        "{name}: one row per pose"
    );
    let miss = rows
        .iter()
        .map(|j| gap(&m, &errors, &k.commands_of(j)))
        .fold(0.0, f64::max);
    // The same joints on the machine without its errors miss by their size: the check sees
    // the errors.
    let nominal = errors_of(
        &m,
        &truth.iter().map(|(n, _)| (*n, 0.0)).collect::<Vec<_>>(),
    );
    let without = rows
        .iter()
        .map(|j| gap(&m, &nominal, &k.commands_of(j)))
        .fold(0.0, f64::max);
    eprintln!(
        "{name}: the tool misses the ball by {miss:.2e} mm (on the machine without its errors: {without:.2e} mm)"
    );
    assert!(miss < 1e-6, "{name}: {miss} mm");
    assert!(without > 1e-3, "{name}: {without} mm");
}

/// Steps 1 and 2 on `name` (step 2 with `truth`) in one LinuxCNC run of the trt module: it
/// starts with the pins of the nominal description and runs step 1's moves; the lines of the
/// HAL file rtest writes for the corrected description then set every pin of the module
/// (`setp`, between two blocks: the module reads its pins at every call), and step 2's moves
/// follow. One boot of LinuxCNC instead of two.
fn steps_1_and_2(name: &str, truth: &[(&str, f64)]) {
    let Some(lc) = for_test(name) else { return };
    let m = machine(name);
    // Step 1: the nominal description, the world positions of rtest's commands.
    let nominal = trt_kinematics(&m, &m.default_parameters()).unwrap();
    let poses = check_poses(&m);
    let targets: Vec<_> = poses
        .iter()
        .map(|q| (world(&m, &nominal, q), angles(&nominal, q)))
        .collect();
    let step_1 = blocks(&nominal, &targets);
    // Step 2: the corrected description; the ball sits at the workpiece frame's origin, so its
    // world position is the same at every pose and only the angles change.
    let errors = errors_of(&m, truth);
    let source = model_spec::write::source_text(name).unwrap();
    let corrected = corrected_description(&m, &source, &errors).unwrap();
    assert!(corrected.not_folded.is_empty());
    let folded = parse_machine("corrected.toml", &corrected.toml).unwrap();
    let k = trt_kinematics(&folded, &folded.default_parameters()).unwrap();
    assert_eq!(k.module.name(), nominal.module.name(), "{name}: one module");
    let ball = -Vector3::from(k.world_origin);
    let targets: Vec<_> = poses.iter().map(|q| (ball, angles(&k, q))).collect();
    let pins: Vec<String> = hal_file(k.module.name(), &[], &k.hal_pins())
        .lines()
        .map(str::to_string)
        .collect();
    assert_eq!(
        pins.len(),
        k.hal_pins().len(),
        "{name}: one `setp` line per pin"
    );
    assert!(pins.iter().all(|l| l.starts_with("setp ")), "{pins:?}");
    let step_2 = blocks(&k, &targets);
    let all: Vec<String> = step_1.iter().chain(&pins).chain(&step_2).cloned().collect();
    let dir = temp_dir_tagged("linuxcnc", &format!("{name}-trt"));
    let hal = hal_file(nominal.module.name(), &[], &nominal.hal_pins());
    let config = Config {
        kinematics: nominal.module.name(),
        coordinates: nominal.module.coordinates(),
        hal: &hal,
    };
    let rows = lc
        .run(&dir, &config, &all)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    // Each step's first block sets the modes: its row is left out.
    let second = step_1.len() + pins.len();
    zero_errors_give_rtests_joints(name, &nominal, &rows[1..step_1.len()]);
    the_pins_put_the_tool_on_the_ball(name, truth, &k, &rows[second + 1..]);
}

#[test]
fn at_zero_errors_linuxcnc_gives_rtests_joints_and_the_pins_put_the_tool_on_the_ball_on_seed_ac() {
    steps_1_and_2(
        "seed-ac",
        &[
            ("XOC", 0.021),
            ("YOC", -0.014),
            ("YOA", 0.035),
            ("ZOA", -0.027),
        ],
    );
}

#[test]
fn at_zero_errors_linuxcnc_gives_rtests_joints_and_the_pins_put_the_tool_on_the_ball_on_table_table_bc()
 {
    steps_1_and_2(
        "table-table-bc",
        &[
            ("XOC", -0.018),
            ("YOC", 0.025),
            ("XOB", 0.031),
            ("ZOB", -0.022),
        ],
    );
}

/// Step 3 on `name` with `truth`: the corrected poses in joint coordinates through LinuxCNC's
/// identity kinematics.
fn the_joint_program_leaves_under_20_nm(name: &str, truth: &[(&str, f64)]) {
    let Some(lc) = for_test(name) else { return };
    let m = machine(name);
    let errors = errors_of(&m, truth);
    let k = trt_kinematics(&m, &m.default_parameters()).unwrap();
    let params = m.default_parameters();
    // The nominal R-test poses: the ball reached at the angles of the check poses.
    let commanded: Vec<CommandedPose> = check_poses(&m)
        .into_iter()
        .enumerate()
        .map(|(i, mut q)| {
            tool_centre_point_ik(&m, &mut q, &params).unwrap();
            CommandedPose {
                line: i + 1,
                commands: q,
            }
        })
        .collect();
    let values_at = |q: &[f64], out: &mut [f64]| errors.values_at(&m, q, out);
    let corrected = compensate_poses(&m, errors.errors(), params, "poses", &commanded, &values_at)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    let before = commanded
        .iter()
        .map(|p| gap(&m, &errors, &p.commands))
        .fold(0.0, f64::max);
    let mut b = vec!["G90 G21 G17 G40 G49 G61 G94".to_string()];
    for q in &corrected.poses {
        let j = k.joints_of(q);
        b.push(format!(
            "G1 X{} Y{} Z{} {}{} C{} F1000000",
            number(j[0]),
            number(j[1]),
            number(j[2]),
            k.joints[3].letter,
            number(j[3]),
            number(j[4])
        ));
    }
    let dir = temp_dir_tagged("linuxcnc", &format!("{name}-joints"));
    let kinematics = format!("trivkins coordinates={}", k.module.coordinates());
    let config = Config {
        kinematics: &kinematics,
        coordinates: k.module.coordinates(),
        hal: "",
    };
    let rows = lc
        .run(&dir, &config, &b)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    let after = rows[1..]
        .iter()
        .map(|j| gap(&m, &errors, &k.commands_of(j)))
        .fold(0.0, f64::max);
    eprintln!(
        "{name}: tool to ball {before:.3e} mm as commanded, {after:.2e} mm after the joint-coordinate program"
    );
    assert!(before > 0.01, "{name}: the errors must matter: {before} mm");
    assert!(after < 2e-5, "{name}: {after} mm");
}

#[test]
fn the_joint_program_leaves_under_20_nm_on_seed_ac() {
    the_joint_program_leaves_under_20_nm(
        "seed-ac",
        &[
            ("XOC", 0.021),
            ("YOC", -0.014),
            ("YOA", 0.035),
            ("ZOA", -0.027),
            ("AOC", 40e-6),
            ("BOC", -25e-6),
            ("BOA", 30e-6),
            ("COA", -20e-6),
            ("COX", 15e-6),
            ("EXX@poly:1", 0.008),
            ("EZZ@poly:2", -0.004),
        ],
    );
}

#[test]
fn the_joint_program_leaves_under_20_nm_on_table_table_bc() {
    the_joint_program_leaves_under_20_nm(
        "table-table-bc",
        &[
            ("XOC", -0.018),
            ("YOC", 0.025),
            ("XOB", 0.031),
            ("ZOB", -0.022),
            ("AOB", 35e-6),
            ("COB", -20e-6),
            ("AOC", 25e-6),
            ("EYX@poly:1", 0.006),
        ],
    );
}
