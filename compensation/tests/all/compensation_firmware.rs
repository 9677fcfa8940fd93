//! The generated compensation functions against the host: `compensate` (f64) equals the host's
//! fixed steps bit for bit on every compiled model of every built-in machine, and the
//! single-precision first-order correction stays within its stated bound of the host's
//! corrected pose.

use compensation::correct::Compensator;
use model_spec::{AxisKind, Machine, Side, builtin};
use simulation::exact::chain_transform;
use simulation::rng::Rng;

/// The host's sine and cosine, as the generated code's caller passes it.
fn sin_cos(x: f64) -> (f64, f64) {
    x.sin_cos()
}

/// A random pose within the strokes and ranges, with |tilt| ≥ 15° away from a singular pose:
/// every rotary command at least 15° from 0°, and the tool axis at least 15° from the plane of
/// two rotary axes ([`orientation_conditioning`]; the nutating head and table are singular at
/// B = 180° too).
fn random_pose(m: &Machine, rng: &mut Rng) -> Vec<f64> {
    loop {
        let q = draw_pose(m, rng);
        if orientation_conditioning(m, &q) >= 15f64.to_radians().sin() {
            return q;
        }
    }
}

/// For a machine with two rotary axes, `|∂t/∂q₁ × ∂t/∂q₂|` at `q`, `t` the tool axis in the
/// workpiece frame (nominal machine): the sine of the angle between the tool axis and the plane
/// of the two rotary axes. Where it vanishes both axes turn the tool axis the same way, a
/// singular pose (A = 0° on seed-ac: `|sin A|`). 1 for other machines.
fn orientation_conditioning(m: &Machine, q: &[f64]) -> f64 {
    let rotary: Vec<usize> = m.rotary_axes().collect();
    let [a, b] = rotary[..] else {
        return 1.0;
    };
    let (params, zeros) = (m.default_parameters(), vec![0.0; m.catalogue.len()]);
    let tool_axis = |q: &[f64]| {
        let tool = chain_transform(m, Side::Tool, q, &params, &zeros);
        let work = chain_transform(m, Side::Work, q, &params, &zeros);
        let z = tool.rotation.matrix().column(2).into_owned();
        work.rotation.inverse_transform_vector(&z)
    };
    let derivative = |i: usize| {
        let h = 1e-6;
        let (mut up, mut down) = (q.to_vec(), q.to_vec());
        up[i] += h;
        down[i] -= h;
        (tool_axis(&up) - tool_axis(&down)) / (2.0 * h)
    };
    derivative(a).cross(&derivative(b)).norm()
}

/// Rotary commands uniform over their ranges (±180° when unlimited), at least 15° from 0°;
/// linear commands uniform over their strokes.
fn draw_pose(m: &Machine, rng: &mut Rng) -> Vec<f64> {
    m.axes
        .iter()
        .map(|a| {
            let [lo, hi] = a.limits;
            match a.kind {
                AxisKind::Linear => rng.uniform_in(lo, hi),
                AxisKind::Rotary => {
                    let (lo, hi) = if lo.is_finite() {
                        (lo, hi)
                    } else {
                        (-180.0, 180.0)
                    };
                    let mut v = rng.uniform_in(lo, hi);
                    if v.abs() < 15.0 {
                        v = 15.0_f64.copysign(v);
                    }
                    v.to_radians()
                }
            }
        })
        .collect()
}

/// Random values of the model's errors: each within ±`mm` (translations) and ±`rad`.
fn random_values(m: &Machine, errors: &[usize], (mm, rad): (f64, f64), rng: &mut Rng) -> Vec<f64> {
    errors
        .iter()
        .map(|&e| {
            let size = if m.catalogue[e].is_angular() { rad } else { mm };
            size * rng.uniform_in(-1.0, 1.0)
        })
        .collect()
}

#[test]
fn generated_compensate_equals_the_host_bit_for_bit() {
    let mut rng = Rng::new(7);
    let mut checked = 0;
    for compiled in generated::MODELS {
        let m = builtin(compiled.machine).unwrap().unwrap();
        let errors = m.model_errors(compiled.model).unwrap().to_vec();
        for _ in 0..50 {
            let mut params = m.default_parameters();
            for p in params.iter_mut() {
                *p += rng.uniform_in(-200.0, 200.0);
            }
            let q = random_pose(&m, &mut rng);
            let values = random_values(&m, &errors, (20e-3, 50e-6), &mut rng);
            let mut host = Compensator::new(&m, &errors, params.clone()).unwrap();
            let expected = host.fixed_steps(&q, &values);
            let mut out = vec![0.0; q.len()];
            (compiled.compensate)(&q, &params, &values, sin_cos, &mut out);
            for (a, (e, o)) in q.iter().zip(expected.iter().zip(&out)) {
                assert_eq!(
                    e.to_bits(),
                    o.to_bits(),
                    "{} {}: host {e} generated {o} (commanded {a})",
                    compiled.machine,
                    compiled.model
                );
            }
            assert!(expected.iter().zip(&q).any(|(e, a)| e != a));
            checked += 1;
        }
    }
    assert!(checked >= 50 * 5, "every compiled model checked");
}

/// The single-precision first-order correction, against the host's corrected pose: one step
/// leaves the second order of the correction (the rotary change squared times the lever arm,
/// and the change of the predicted error over the correction) and the rounding of `f32`. With
/// every error of the model within ±10 µm and ±20 µrad and lever arms up to about 1.5 m
/// (kinematic parameters within ±500 mm on top of the strokes), the tool point differs by less
/// than 0.02 µm wherever the correction is below 50 µm and 100 µrad.
#[test]
fn first_order_f32_is_within_its_bound() {
    let mut rng = Rng::new(8);
    let (mut worst, mut worst_any, mut counted) = (0.0f64, 0.0f64, 0);
    for compiled in generated::MODELS {
        let m = builtin(compiled.machine).unwrap().unwrap();
        let errors = m.model_errors(compiled.model).unwrap().to_vec();
        let rotary: Vec<usize> = m.rotary_axes().collect();
        let linear: Vec<usize> = m.linear_axes().collect();
        for _ in 0..200 {
            let mut params = m.default_parameters();
            for p in params.iter_mut() {
                *p += rng.uniform_in(-500.0, 500.0);
            }
            let q = random_pose(&m, &mut rng);
            let values = random_values(&m, &errors, (10e-3, 20e-6), &mut rng);
            let mut host = Compensator::new(&m, &errors, params.clone()).unwrap();
            let corrected = host.fixed_steps(&q, &values);
            let mut pose: Vec<f32> = Vec::new();
            for &a in &rotary {
                let (s, c) = q[a].sin_cos();
                pose.extend([s as f32, c as f32]);
            }
            pose.extend(linear.iter().map(|&a| q[a] as f32));
            let params32: Vec<f32> = params.iter().map(|&p| p as f32).collect();
            let values32: Vec<f32> = values.iter().map(|&v| v as f32).collect();
            let mut out = vec![0.0f32; q.len() + 6];
            (compiled.first_order_f32)(&pose, &params32, &values32, &mut out);
            // The tool-point difference: linear changes directly, rotary ones times 1 m.
            let miss = (0..q.len())
                .map(|a| {
                    let d = (q[a] + f64::from(out[a])) - corrected[a];
                    match m.axes[a].kind {
                        AxisKind::Linear => d.abs(),
                        AxisKind::Rotary => d.abs() * 1000.0,
                    }
                })
                .fold(0.0, f64::max);
            let lin = linear
                .iter()
                .map(|&a| (corrected[a] - q[a]).abs())
                .fold(0.0, f64::max);
            let turn: f64 = rotary.iter().map(|&a| (corrected[a] - q[a]).abs()).sum();
            worst_any = worst_any.max(miss);
            if lin > 0.05 || turn > 1e-4 {
                continue;
            }
            counted += 1;
            worst = worst.max(miss);
        }
    }
    eprintln!(
        "first_order_f32: worst difference {:.2e} µm over {counted} poses with corrections up to \
         50 µm and 100 µrad; {:.2e} µm over all",
        worst * 1e3,
        worst_any * 1e3
    );
    assert!(
        counted >= 200,
        "{counted} poses with corrections in the range"
    );
    assert!(worst < 2e-5, "worst difference {:e} mm", worst);
}
