//! What well-formed samples must still satisfy, with the messages that name file, line, field
//! and value: plausible readings, poses within the strokes and ranges, the sensor nest on the
//! ball when the file gives the linear axes; the same in the block reader and for path files;
//! the built-in paths within the strokes of seed-ac.

use crate::common;
use crate::csvfiles;

use common::builtin;
use csvfiles::{drop_columns, k4_record, k4_text, set_field};
use formats::csv::{
    CsvError, LISTED, MeasurementBlocks, ReadOptions, format_record, parse_measurement,
};
use formats::paths::parse_path;
use model_spec::Machine;
use simulation::paths::{BUILTIN_PATHS, builtin_path};
use std::io::Cursor;

fn opts() -> ReadOptions {
    ReadOptions::default()
}

fn whole(text: &str, m: &Machine, o: &ReadOptions) -> String {
    parse_measurement("k4.csv", text, m, o)
        .unwrap_err()
        .to_string()
}

/// The first error of the block reader (blocks of `block` samples).
fn blocks(text: &str, m: &Machine, block: usize, o: &ReadOptions) -> String {
    MeasurementBlocks::new("k4.csv".into(), Cursor::new(text.as_bytes()), m, block, o)
        .unwrap()
        .find_map(|b| b.err())
        .unwrap()
        .to_string()
}

#[test]
fn implausible_readings_are_refused_with_count_bound_and_first_lines() {
    let m = builtin("seed-ac");
    let text = k4_text(&m);
    let bad = set_field(&text, 14, "dx_um", "1e308");
    let bad = set_field(&bad, 15, "dz_um", "-2.4e3");
    let bad = set_field(&bad, 90, "dy_um", "1500");
    assert_eq!(
        whole(&bad, &m, &opts()),
        "k4.csv: 3 readings beyond the plausibility bound of 1000 µm: line 14 dx_um = 1e308, line 15 dz_um = -2400, line 90 dy_um = 1500"
    );
    match parse_measurement("k4.csv", &bad, &m, &opts()).unwrap_err() {
        CsvError::Refused {
            file, count, lines, ..
        } => assert_eq!(
            (file.as_str(), count, lines),
            ("k4.csv", 3, vec![14, 15, 90])
        ),
        other => panic!("{other:?}"),
    }
    // The block reader cannot look ahead: the offending lines of the first block with any.
    assert_eq!(
        blocks(&bad, &m, 30, &opts()),
        "k4.csv: 2 readings beyond the plausibility bound of 1000 µm: line 14 dx_um = 1e308, line 15 dz_um = -2400"
    );
    assert_eq!(
        blocks(&set_field(&text, 90, "dy_um", "1500"), &m, 30, &opts()),
        "k4.csv: 1 reading beyond the plausibility bound of 1000 µm: line 90 dy_um = 1500"
    );
    // The bound itself is accepted, in every direction; a bound of one's own.
    let edge = set_field(&text, 5, "dx_um", "1000");
    let edge = set_field(&edge, 6, "dy_um", "-1000");
    parse_measurement("k4.csv", &edge, &m, &opts()).unwrap();
    let mut tight = opts();
    tight.max_reading_mm = 0.2125;
    assert_eq!(
        whole(&set_field(&text, 7, "dz_um", "-212.6"), &m, &tight),
        "k4.csv: 1 reading beyond the plausibility bound of 212.5 µm: line 7 dz_um = -212.6"
    );
    // More than are listed: the count, the first few, and `…`.
    let mut many = text.clone();
    for line in 20..20 + LISTED + 3 {
        many = set_field(&many, line, "dy_um", "-5000");
    }
    let e = whole(&many, &m, &opts());
    let listed: Vec<String> = (20..20 + LISTED)
        .map(|l| format!("line {l} dy_um = -5000"))
        .collect();
    assert_eq!(
        e,
        format!(
            "k4.csv: {} readings beyond the plausibility bound of 1000 µm: {}, …",
            LISTED + 3,
            listed.join(", ")
        )
    );
}

/// seed-3axis with its workpiece point at x = 612.3 mm (nominal), from the built-in description.
fn three_axis_far_workpiece() -> Machine {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../model-spec/machines/seed-3axis.toml"
    ))
    .unwrap()
    .replace("Xw = 0.0", "Xw = 612.3");
    model_spec::parse_machine("far.toml", &text).unwrap()
}

#[test]
fn poses_outside_the_strokes_and_ranges_are_refused_naming_axis_value_and_limits() {
    // Linear axes given: X on the ball but beyond its stroke.
    let m = three_axis_far_workpiece();
    let text = "X,Y,Z,dx_um,dy_um,dz_um\n399,0,0,1,2,3\n400,0,0,1,2,3\n612.3,0,0,1,2,3\n";
    let mut loose = opts();
    loose.on_ball_tolerance_mm = f64::INFINITY;
    assert_eq!(
        whole(text, &m, &loose),
        "k4.csv: 1 pose outside the strokes and ranges of machine seed-3axis: line 4: X = 612.3 mm outside its stroke -400 .. 400 mm"
    );
    // Rotary axes in degrees; linear axes filled by the inverse kinematics are checked too.
    let m = builtin("seed-ac");
    let rotary = drop_columns(&k4_text(&m), &["X", "Y", "Z"]);
    let bad = set_field(&rotary, 7, "A", "-130");
    let bad = set_field(&bad, 9, "A", "120.000001");
    assert_eq!(
        whole(&bad, &m, &opts()),
        "k4.csv: 2 poses outside the strokes and ranges of machine seed-ac (the linear axes filled by the nominal inverse kinematics): line 7: A = -130° outside its range -120 .. 120°; line 9: A = 120.000001° outside its range -120 .. 120°"
    );
    // The limits are inclusive (to within 1e-9 of the unit).
    parse_measurement("k4.csv", &set_field(&rotary, 7, "A", "-120"), &m, &opts()).unwrap();
    parse_measurement(
        "k4.csv",
        &set_field(&rotary, 7, "A", "120.0000000001"),
        &m,
        &opts(),
    )
    .unwrap();
    // Narrower limits of X and A: several axes on one line.
    let mut narrow = builtin("seed-ac");
    let x = narrow.axis_by_name("X").unwrap();
    narrow.axes[x].limits = [-200.0, 200.0];
    let a = narrow.axis_by_name("A").unwrap();
    narrow.axes[a].limits = [-1.0, 1.0];
    assert_eq!(
        whole("A,C,dx_um,dy_um,dz_um\n-90,180,0,0,0\n", &narrow, &opts()),
        "k4.csv: 1 pose outside the strokes and ranges of machine seed-ac (the linear axes filled by the nominal inverse kinematics): line 2: X = -217.504 mm outside its stroke -200 .. 200 mm, A = -90° outside its range -1 .. 1°"
    );
    // K4 (X up to ±217.504 mm) on that machine: many poses, the first few listed, and `…`; the
    // block reader lists those of its first block.
    let e = whole(&rotary, &narrow, &opts());
    assert!(
        e.starts_with("k4.csv: ") && e.contains(" poses outside the strokes and ranges of machine seed-ac (the linear axes filled by the nominal inverse kinematics): line 2: X = 217.504 mm outside its stroke -200 .. 200 mm; line 3: X = 217.4"),
        "{e}"
    );
    assert!(e.ends_with("; …"), "{e}");
    let e = blocks(&k4_text(&m), &narrow, 4, &opts());
    assert!(
        e.starts_with("k4.csv: 4 poses outside the strokes and ranges of machine seed-ac: line 2: X = 217.504 mm outside its stroke -200 .. 200 mm; line 3: X = 217.4")
            && e.contains("; line 5: X = ")
            && !e.contains('…'),
        "{e}"
    );
    // Allowed on request.
    let mut allow = opts();
    allow.allow_off_stroke = true;
    let r = parse_measurement("k4.csv", &bad, &m, &allow).unwrap();
    assert_eq!(r.samples.len(), 241);
    parse_measurement("k4.csv", &rotary, &narrow, &allow).unwrap();
}

#[test]
fn linear_axes_given_must_keep_the_nest_on_the_ball() {
    // A three-axis grid whose readings are the commanded motion in mm: not an R-test record.
    let m = builtin("seed-3axis");
    let mut text = String::from("# a grid\nX,Y,Z,dx_um,dy_um,dz_um\n");
    for x in [0, 100, 200] {
        for y in [0, 50] {
            for z in [0, -20] {
                text += &format!("{x},{y},{z},{x},{y},{z}\n");
            }
        }
    }
    let e = parse_measurement("grid.csv", &text, &m, &opts()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "grid.csv: 11 poses put the nominal tool point off the nominal workpiece point by more than 0.5 mm (machine seed-3axis, default kinematic parameters): line 4: 20 mm, line 5: 50 mm, line 6: 53.851648 mm, line 7: 100 mm, line 8: 101.98039 mm, …; in an R-test record the linear axes follow the ball (the sensor nest stays on the ball) and the readings are the small error vector in µm; leave the linear columns out to have them filled by the nominal inverse kinematics"
    );
    match e {
        CsvError::Refused { count, lines, .. } => {
            assert_eq!((count, lines), (11, vec![4, 5, 6, 7, 8]))
        }
        other => panic!("{other:?}"),
    }
    // In blocks of 3: the first block waits until X moves too (line 7).
    let e = MeasurementBlocks::new(
        "grid.csv".into(),
        Cursor::new(text.as_bytes()),
        &m,
        3,
        &opts(),
    )
    .unwrap()
    .find_map(|b| b.err())
    .unwrap()
    .to_string();
    assert!(
        e.starts_with("grid.csv: 4 poses put the nominal tool point off the nominal workpiece point by more than 0.5 mm (machine seed-3axis, default kinematic parameters): line 4: 20 mm, line 5: 50 mm, line 6: 53.851648 mm, line 7: 100 mm; in an R-test record"),
        "{e}"
    );
    // seed-ac with the linear axes written for the wrong side of the ball; within the
    // tolerance; the tolerance of one's own.
    let m = builtin("seed-ac");
    let text = k4_text(&m);
    let wrong = set_field(&text, 2, "X", "-217.504");
    assert!(
        whole(&wrong, &m, &opts()).starts_with(
            "k4.csv: 1 pose put the nominal tool point off the nominal workpiece point by more than 0.5 mm (machine seed-ac, default kinematic parameters): line 2: 435.008 mm; in an R-test record"
        )
    );
    let near = set_field(&text, 2, "X", "217.9");
    parse_measurement("k4.csv", &near, &m, &opts()).unwrap();
    let mut tight = opts();
    tight.on_ball_tolerance_mm = 0.25;
    let e = whole(&near, &m, &tight);
    assert!(
        e.contains("by more than 0.25 mm") && e.contains("line 2: 0.396 mm"),
        "{e}"
    );
    // Without the linear columns the inverse kinematics puts the nest on the ball.
    let rotary = drop_columns(&text, &["X", "Y", "Z"]);
    parse_measurement("k4.csv", &rotary, &m, &opts()).unwrap();
}

#[test]
fn path_files_are_checked_as_measurements_are() {
    let m = builtin("seed-ac");
    let k4 = builtin_path(&m, "K4").unwrap().unwrap();
    let path = format_record(&m, &k4, &[]).unwrap();
    let rotary = drop_columns(&path, &["X", "Y", "Z"]);
    assert_eq!(
        parse_path("p.csv", &set_field(&rotary, 7, "A", "-130"), &m, &opts())
            .unwrap_err()
            .to_string(),
        "p.csv: 1 pose outside the strokes and ranges of machine seed-ac (the linear axes filled by the nominal inverse kinematics): line 7: A = -130° outside its range -120 .. 120°"
    );
    let e = parse_path("p.csv", &set_field(&path, 3, "Z", "60"), &m, &opts()).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("p.csv: 1 pose put the nominal tool point off the nominal workpiece point by more than 0.5 mm (machine seed-ac, default kinematic parameters): line 3: 3.3"),
        "{e}"
    );
    // Readings are optional in a path file; when present, the bound applies.
    let measured = k4_text(&m);
    parse_path("p.csv", &measured, &m, &opts()).unwrap();
    assert_eq!(
        parse_path(
            "p.csv",
            &set_field(&measured, 4, "dz_um", "-1e6"),
            &m,
            &opts()
        )
        .unwrap_err()
        .to_string(),
        "p.csv: 1 reading beyond the plausibility bound of 1000 µm: line 4 dz_um = -1e6"
    );
}

#[test]
fn the_builtin_paths_lie_within_the_strokes_and_ranges_of_seed_ac() {
    let m = builtin("seed-ac");
    for name in BUILTIN_PATHS {
        let p = builtin_path(&m, name).unwrap().unwrap();
        // Read back as a path file and as a measurement: every check passes.
        let text = format_record(&m, &p, &[]).unwrap();
        assert_eq!(
            parse_path("p.csv", &text, &m, &opts()).unwrap(),
            p,
            "{name}"
        );
        let rec = if name == "K4" {
            k4_record(&m)
        } else {
            simulation::readings::simulate(&m, &formats::truth::seed_ac_demo_truth(), &p).unwrap()
        };
        let text = format_record(&m, &rec, &[]).unwrap();
        parse_measurement("m.csv", &text, &m, &opts()).unwrap();
        // With room to spare: 5 % of every finite stroke and range.
        for s in &p.samples {
            for (a, &q) in m.axes.iter().zip(&s.commands) {
                let v = match a.kind {
                    model_spec::AxisKind::Linear => q,
                    model_spec::AxisKind::Rotary => q.to_degrees(),
                };
                let [lo, hi] = a.limits;
                let room = 0.05 * (hi - lo);
                assert!(
                    !room.is_finite() || (v >= lo + room && v <= hi - room),
                    "{name}: {} = {v} near its limits {lo} .. {hi}",
                    a.name
                );
            }
        }
    }
}
