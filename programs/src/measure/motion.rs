//! How long a move of the machine takes, by the assumptions the timing plan states, and how far
//! the sensor nest leaves the ball while the axes move.
//!
//! A move from pose `p` to pose `q` is a straight line in the space of the axis commands: every
//! axis moves by `Δ_a = q_a − p_a` (mm or degrees) along `p + s·Δ`, `s` from 0 to 1, as a
//! control interpolates a block with tool centre point control off. With an axis's speed limit
//! `v_a` (mm/min or degrees/min) and acceleration `α_a` (mm/s² or degrees/s²), the path
//! parameter may move at most at `ṡ = min_a v_a / (60·|Δ_a|)` (1/s) and accelerate at most at
//! `s̈ = min_a α_a / |Δ_a|` (1/s²). From rest to rest at a commanded `ṡ` the move takes
//! (a trapezoid of `ṡ`):
//!
//! - `1/ṡ` with the acceleration neglected (`α = 0` for every moving axis);
//! - `1/ṡ + ṡ/s̈` when the cruise is reached (`ṡ² ≤ s̈`);
//! - `2/√s̈` (a triangle) when it is not.

use simulation::exact::VirtualMachine;

/// Sub-steps of a move at which the gap between the nest and the ball is evaluated (the gap of
/// a rotary step is largest at its middle, which is one of them).
const GAP_STEPS: usize = 8;

/// The rate limit of the path parameter `s` of the move `delta` (one per axis, mm or degrees)
/// when each axis may move at `per_min[a]` (mm/min or degrees/min): 1/s, `f64::INFINITY` for a
/// move of no axis.
pub(crate) fn rate_limit(delta: &[f64], per_min: &[f64]) -> f64 {
    delta
        .iter()
        .zip(per_min)
        .filter(|(d, _)| **d != 0.0)
        .map(|(d, v)| v / 60.0 / d.abs())
        .fold(f64::INFINITY, f64::min)
}

/// The acceleration limit of the path parameter (1/s²) of the move `delta` when each axis may
/// accelerate at `per_s2[a]` (mm/s² or degrees/s²; 0: neglected): `f64::INFINITY` when every
/// moving axis's acceleration is neglected.
pub(crate) fn acceleration_limit(delta: &[f64], per_s2: &[f64]) -> f64 {
    delta
        .iter()
        .zip(per_s2)
        .filter(|(d, a)| **d != 0.0 && **a > 0.0)
        .map(|(d, a)| a / d.abs())
        .fold(f64::INFINITY, f64::min)
}

/// The duration (s) of a move from rest to rest at the commanded path rate `rate` (1/s) with
/// the path acceleration limit `accel` (1/s², infinite when neglected): see the module
/// documentation. 0 for a move of no axis (`rate` infinite).
pub(crate) fn rest_to_rest_s(rate: f64, accel: f64) -> f64 {
    if rate.is_infinite() {
        return 0.0;
    }
    if accel.is_infinite() {
        1.0 / rate
    } else if rate * rate <= accel {
        1.0 / rate + rate / accel
    } else {
        2.0 / accel.sqrt()
    }
}

/// The time (s) a start from rest loses against an instantaneous start at the path rate `rate`
/// (1/s) with acceleration limit `accel` (1/s²): `ṡ/(2·s̈)`, 0 when neglected. A stop loses the
/// same.
pub(crate) fn ramp_loss_s(rate: f64, accel: f64) -> f64 {
    if rate.is_infinite() || accel.is_infinite() {
        0.0
    } else {
        rate / (2.0 * accel)
    }
}

/// The length (mm, degrees counted as mm) of the move `delta` in the space of the axis words:
/// what a control that takes `F` along all the axes of a block divides by `F`.
pub(crate) fn combined_length(delta: &[f64]) -> f64 {
    delta.iter().map(|d| d * d).sum::<f64>().sqrt()
}

/// The largest distance (mm) between the nominal tool point and the nominal workpiece point
/// (the nest and the ball) along the straight move from `from` to `to` (commands in mm and
/// rad), evaluated at the ends and at [`GAP_STEPS`] − 1 points between, at the machine's
/// default kinematic parameters.
pub(crate) fn largest_gap_mm(vm: &VirtualMachine, params: &[f64], from: &[f64], to: &[f64]) -> f64 {
    let mut q = from.to_vec();
    (0..=GAP_STEPS)
        .map(|k| {
            let s = k as f64 / GAP_STEPS as f64;
            for (a, x) in q.iter_mut().enumerate() {
                *x = from[a] + s * (to[a] - from[a]);
            }
            vm.nominal_error_vector(&q, params).position.norm()
        })
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trapezoid_and_triangle() {
        // 10 mm at 600 mm/min: 1 s at cruise; 100 mm/s² on 10 mm: s̈ = 10, ṡ = 1.
        let d = [10.0, 0.0];
        let rate = rate_limit(&d, &[600.0, 600.0]);
        let accel = acceleration_limit(&d, &[100.0, 0.0]);
        assert!((rate - 1.0).abs() < 1e-15 && (accel - 10.0).abs() < 1e-15);
        assert!((rest_to_rest_s(rate, accel) - 1.1).abs() < 1e-12);
        assert!((rest_to_rest_s(rate, f64::INFINITY) - 1.0).abs() < 1e-15);
        // A short move never reaches the cruise: 2/√s̈.
        assert!((rest_to_rest_s(100.0, 4.0) - 1.0).abs() < 1e-15);
        assert_eq!(rest_to_rest_s(f64::INFINITY, 1.0), 0.0);
        assert!((ramp_loss_s(1.0, 10.0) - 0.05).abs() < 1e-15);
        assert!((combined_length(&[3.0, 4.0]) - 5.0).abs() < 1e-15);
    }
}
