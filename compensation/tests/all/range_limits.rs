//! A corrected command that passes a range limit by a hair is put on the limit and listed,
//! not refused with the whole program; further out, the pose is refused. On the nutating
//! table (B's range 0…180°), a positioning error of B moves the corrected B of a pose at
//! B = 0° below 0° by a few thousandths of a degree in one sign.

use crate::common::builtin;

use compensation::run::{CLAMP_MARGIN, CommandedPose, Compensated, RunError, compensate_poses};
use model_spec::Machine;
use simulation::exact::tool_centre_point_ik;

/// The pose B = 0°, C = 30° with the tool on the ball (linear axes by the inverse kinematics).
fn b_zero(m: &Machine) -> Vec<f64> {
    let mut q = vec![0.0; m.axes.len()];
    q[m.axis_by_name("C").unwrap()] = 30f64.to_radians();
    tool_centre_point_ik(m, &mut q, &m.default_parameters()).unwrap();
    q
}

/// Compensates the pose at B = 0° (line 7) with B's positioning error `ecb` (rad) alone.
fn compensate(m: &Machine, ecb: f64) -> Result<Compensated, RunError> {
    let e = m.error_by_name("ECB").unwrap();
    let values_at = move |_: &[f64], out: &mut [f64]| out[0] = ecb;
    let pose = [CommandedPose {
        line: 7,
        commands: b_zero(m),
    }];
    compensate_poses(
        m,
        &[e],
        m.default_parameters(),
        "b-zero.csv",
        &pose,
        &values_at,
    )
}

#[test]
fn b_at_zero_corrected_a_hair_below_its_range_is_kept_on_zero_and_listed() {
    let m = builtin("nutating-table-bc");
    let b = m.axis_by_name("B").unwrap();
    assert_eq!(m.axes[b].limits, [0.0, 180.0]);
    // 50 µrad of positioning error: a correction of 0.0029° of B, inside the range in one sign
    // and below 0° in the other.
    let plus = compensate(&m, 50e-6).unwrap();
    let minus = compensate(&m, -50e-6).unwrap();
    let (inside, clamped) = if plus.summary.clamped.is_empty() {
        (plus, minus)
    } else {
        (minus, plus)
    };
    assert!(inside.summary.clamped.is_empty());
    let kept = inside.poses[0][b].to_degrees();
    assert!(kept > 0.002 && kept < 0.004, "B corrected to {kept}°");
    let listed = &clamped.summary.clamped;
    assert_eq!(listed.len(), 1, "{listed:?}");
    let c = &listed[0];
    assert_eq!(
        (c.line, c.axis.as_str(), c.rotary, c.limit),
        (7, "B", true, 0.0)
    );
    assert!(
        (c.corrected + kept).abs() < 1e-6,
        "{} against {kept}",
        c.corrected
    );
    assert_eq!(clamped.poses[0][b], 0.0, "B put on its limit exactly");
}

#[test]
fn a_correction_further_past_the_range_is_refused() {
    let m = builtin("nutating-table-bc");
    // 500 µrad: 0.029° past 0°, beyond the margin of 0.01°, in the sign that leaves the range.
    let results = [compensate(&m, 500e-6), compensate(&m, -500e-6)];
    let refused: Vec<&RunError> = results.iter().filter_map(|r| r.as_ref().err()).collect();
    assert_eq!(refused.len(), 1, "{results:?}");
    let RunError::OutOfLimits { file, lines, count } = refused[0] else {
        panic!("{:?}", refused[0]);
    };
    assert_eq!((file.as_str(), *count), ("b-zero.csv", 1));
    assert_eq!(lines[0].0, 7);
    assert!(lines[0].1.contains("B = -0.0286"), "{}", lines[0].1);
    const { assert!(CLAMP_MARGIN < 0.0286) };
}
