//! `Machine::check_pose`: commands in mm and rad against strokes in mm and ranges in degrees.

use model_spec::pose::{LIMIT_TOLERANCE, OutsideLimits, PoseError};
use model_spec::{AxisKind, Machine, builtin};

/// seed-ac: X [-500, 500] mm, A [-120, 120] degrees, C unlimited, Y [-400, 400] mm,
/// Z [-500, 500] mm.
fn seed_ac() -> Machine {
    builtin("seed-ac").unwrap().unwrap()
}

/// The message for `commands` (X mm, A degrees, C degrees, Y mm, Z mm).
fn message(commands: [f64; 5]) -> Option<String> {
    let [x, a, c, y, z] = commands;
    seed_ac()
        .check_pose(&[x, a.to_radians(), c.to_radians(), y, z])
        .err()
        .map(|e| e.to_string())
}

#[test]
fn within_and_at_the_limits() {
    let m = seed_ac();
    assert_eq!(m.check_pose(&[0.0; 5]), Ok(()));
    assert_eq!(message([500.0, 120.0, 0.0, -400.0, 500.0]), None);
    assert_eq!(message([-500.0, -120.0, 0.0, 400.0, -500.0]), None);
    // Within the margin of rounding.
    assert_eq!(message([500.0 + 0.5e-9, 0.0, 0.0, 0.0, 0.0]), None);
    assert_eq!(message([0.0, -120.0 - 0.5e-9, 0.0, 0.0, 0.0]), None);
    assert_eq!(LIMIT_TOLERANCE, 1e-9);
    // Every whole degree of A, as radians, read back within its range.
    for deg in -120..=120 {
        assert_eq!(message([0.0, deg as f64, 0.0, 0.0, 0.0]), None, "{deg}");
    }
    // C has no range: any finite angle.
    assert_eq!(m.check_pose(&[0.0, 0.0, 1e6, 0.0, 0.0]), Ok(()));
    assert_eq!(m.check_pose(&[0.0, 0.0, -1e300, 0.0, 0.0]), Ok(()));
}

#[test]
fn outside() {
    assert_eq!(
        message([500.001, 0.0, 0.0, 0.0, 0.0]).unwrap(),
        "X = 500.001 mm outside its stroke -500 .. 500 mm"
    );
    assert_eq!(
        message([0.0, 121.0, 0.0, 0.0, 0.0]).unwrap(),
        "A = 121° outside its range -120 .. 120°"
    );
    assert_eq!(
        message([0.0, 0.0, 0.0, 0.0, -612.25]).unwrap(),
        "Z = -612.25 mm outside its stroke -500 .. 500 mm"
    );
    // Just beyond the margin: every digit, so that the value is not shown as the limit.
    assert_eq!(
        message([0.0, 0.0, 0.0, 400.000_000_1, 0.0]).unwrap(),
        "Y = 400.0000001 mm outside its stroke -400 .. 400 mm"
    );
    // The first axis outside, in axis order (X, A, C, Y, Z).
    assert_eq!(
        message([0.0, 130.0, 0.0, 401.0, 0.0]).unwrap(),
        "A = 130° outside its range -120 .. 120°"
    );
}

#[test]
fn a_huge_value_is_written_compactly() {
    // Not the three hundred digits of 1e300: the shortest decimal that reads back.
    assert_eq!(
        message([1e300, 0.0, 0.0, 0.0, 0.0]).unwrap(),
        "X = 1e300 mm outside its stroke -500 .. 500 mm"
    );
    // More than twelve digits near a limit: every digit, not the limit's six decimals.
    assert_eq!(
        message([500.000_000_002_1, 0.0, 0.0, 0.0, 0.0]).unwrap(),
        "X = 500.0000000021 mm outside its stroke -500 .. 500 mm"
    );
    assert_eq!(
        message([0.0, 0.0, 0.0, 0.0, -2.5e12]).unwrap(),
        "Z = -2.5e12 mm outside its stroke -500 .. 500 mm"
    );
}

#[test]
fn typed() {
    let m = seed_ac();
    let e = m
        .check_pose(&[0.0, 130f64.to_radians(), 0.0, 0.0, 0.0])
        .unwrap_err();
    match e {
        PoseError::OutsideLimits(OutsideLimits {
            axis,
            ref name,
            kind,
            value,
            limits,
        }) => {
            assert_eq!((axis, name.as_str(), kind), (1, "A", AxisKind::Rotary));
            assert!((value - 130.0).abs() < 1e-12);
            assert_eq!(limits, [-120.0, 120.0]);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn not_a_pose() {
    let m = seed_ac();
    assert_eq!(
        m.check_pose(&[0.0; 4]).unwrap_err().to_string(),
        "a pose of machine seed-ac has one command per axis (5), found 4"
    );
    assert_eq!(
        m.check_pose(&[0.0, 0.0, f64::NAN, 0.0, 0.0])
            .unwrap_err()
            .to_string(),
        "axis C: the command NaN is not a finite number"
    );
    assert!(matches!(
        m.check_pose(&[f64::INFINITY, 0.0, 0.0, 0.0, 0.0]),
        Err(PoseError::NotFinite { axis: 0, .. })
    ));
}
