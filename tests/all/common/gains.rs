//! What the gain tests share: random on-ball poses and a relative comparison.

use model_spec::{AxisKind, Machine};

/// A pose and kinematic parameters drawn from `unit` (numbers in [0, 1)): parameters within
/// ±100 mm of their defaults, rotary commands across their range (±180° when unlimited),
/// linear commands by the nominal tool-centre-point inverse kinematics (the tool point on the
/// ball, as in every R-test sample).
pub fn pose(m: &Machine, unit: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let mut u = unit.iter().copied().cycle();
    let params: Vec<f64> = m
        .symbols
        .iter()
        .map(|s| s.default + 200.0 * (u.next().unwrap() - 0.5))
        .collect();
    let mut commands: Vec<f64> = m
        .axes
        .iter()
        .map(|a| match a.kind {
            AxisKind::Linear => 0.0,
            AxisKind::Rotary => {
                let [lo, hi] = a.limits;
                let (lo, hi) = if lo.is_finite() {
                    (lo, hi)
                } else {
                    (-180.0, 180.0)
                };
                (lo + (hi - lo) * u.next().unwrap()).to_radians()
            }
        })
        .collect();
    simulation::exact::tool_centre_point_ik(m, &mut commands, &params)
        .expect("three independent linear axes");
    (commands, params)
}

/// `a` and `b` agree to `tol`, relative to the larger of 1 and their magnitudes.
pub fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}
