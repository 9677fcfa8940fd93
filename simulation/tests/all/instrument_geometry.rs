//! The exact contact geometry of the instrument heads: forward and inverse agree to 1e-12 mm,
//! the first-order map is exact for flat tips and misses the lateral term of ball tips (by the
//! amount the formula says), the covariance of the inverse is that of a Monte-Carlo, and
//! geometry without a solution is an error.

use model_spec::instrument::{Instrument, Tip, parse_instrument, preset};
use nalgebra::Vector3;
use simulation::instrument::head::{InverseError, SensorHead};
use simulation::rng::Rng;

fn instrument(name: &str) -> Instrument {
    preset(name).unwrap().unwrap()
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn diff(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[test]
fn forward_then_inverse_gives_the_displacement_back_to_1e_12_mm() {
    let mut rng = Rng::new(11);
    for name in ["orthogonal", "inclined-45", "four-45"] {
        let head = SensorHead::new(&instrument(name));
        let mut worst: f64 = 0.0;
        let mut steps = 0;
        for _ in 0..500 {
            // Up to ±300 µm in every direction: far beyond an R-test's readings.
            let e = [0.0; 3].map(|_: f64| rng.uniform_in(-0.3, 0.3));
            let s = head.readings(e).unwrap();
            let inv = head.displacement(&s, false).unwrap();
            worst = worst.max(
                diff(inv.displacement, e)
                    .iter()
                    .fold(0.0, |a, v| a.max(v.abs())),
            );
            steps = steps.max(inv.iterations);
        }
        assert!(worst < 1e-12, "{name}: {worst:e} mm");
        assert!(steps <= 6, "{name}: {steps} Gauss–Newton steps");
    }
}

#[test]
fn zero_displacement_reads_exactly_zero_and_back() {
    for name in ["orthogonal", "inclined-45", "four-45"] {
        let head = SensorHead::new(&instrument(name));
        let s = head.readings([0.0; 3]).unwrap();
        assert!(s.iter().all(|&v| v == 0.0), "{name}: {s:?}");
        let inv = head.displacement(&s, false).unwrap();
        assert_eq!(inv.displacement, [0.0; 3], "{name}");
    }
}

/// The first-order inverse against the exact one at 50 µm.
#[test]
fn first_order_against_exact_at_50_um() {
    // Flat tips: the readings are linear in the displacement, the first-order inverse is the
    // exact one (to rounding) in every direction.
    let flat = SensorHead::new(&instrument("orthogonal"));
    let mut rng = Rng::new(5);
    for _ in 0..200 {
        let mut e = [0.0; 3].map(|_: f64| rng.normal());
        let n = norm(e);
        e = e.map(|v| 0.05 * v / n);
        let s = flat.readings(e).unwrap();
        let linear = flat.first_order_displacement(&s).unwrap();
        assert!(norm(diff(linear, e)) < 1e-15, "{e:?} {linear:?}");
    }

    // Ball tips (inclined-45: R = 12.7 mm, r = 2 mm): each sensor reads m·e − |e⊥|²/(2(R + r))
    // to second order, e⊥ the part of e across its axis.
    let i = instrument("inclined-45");
    let head = SensorHead::new(&i);
    let rho = 12.7 + 2.0;
    let e = [0.05, 0.0, 0.0];
    let s = head.readings(e).unwrap();
    for (k, sensor) in i.sensors.iter().enumerate() {
        let m = Vector3::from(sensor.direction);
        let ev = Vector3::from(e);
        let along = m.dot(&ev);
        let across2 = ev.norm_squared() - along * along;
        let predicted = along - across2 / (2.0 * rho);
        // The next term is of the fourth order: |e⊥|⁴/(8ρ³), below 1e-9 mm here.
        assert!(
            (s[k] - predicted).abs() < 1e-9,
            "{}: {} vs {predicted}",
            sensor.name,
            s[k]
        );
    }
    let exact = head.displacement(&s, false).unwrap().displacement;
    let linear = head.first_order_displacement(&s).unwrap();
    assert!(norm(diff(exact, e)) < 1e-12);
    let error_um = norm(diff(linear, e)) * 1e3;
    eprintln!(
        "inclined-45, 50 µm along x: first-order error {error_um:.4} µm ({:.4}, {:.4}, {:.4})",
        (linear[0] - e[0]) * 1e3,
        (linear[1] - e[1]) * 1e3,
        (linear[2] - e[2]) * 1e3
    );
    // Along x the three lateral terms are 0.0425, 0.0744 and 0.0744 µm; the first-order
    // inverse reads them as a displacement of about 0.09 µm, mostly along z.
    assert!(
        (0.08..0.1).contains(&error_um),
        "first-order error {error_um} µm"
    );
    let z_share = (linear[2] - e[2]).abs() * 1e3 / error_um;
    assert!(z_share > 0.9, "{z_share}");

    // The largest first-order error over directions of 50 µm, and its size against the
    // bound |e|²/(2(R + r))·‖A⁻¹‖ (A the first-order matrix, smallest singular value √0.75).
    let mut worst: f64 = 0.0;
    for _ in 0..2000 {
        let mut d = [0.0; 3].map(|_: f64| rng.normal());
        let n = norm(d);
        d = d.map(|v| 0.05 * v / n);
        let s = head.readings(d).unwrap();
        let linear = head.first_order_displacement(&s).unwrap();
        worst = worst.max(norm(diff(linear, d)));
    }
    let bound = 0.05f64.powi(2) / (2.0 * rho) * 3f64.sqrt() / 0.75f64.sqrt();
    eprintln!(
        "inclined-45, 50 µm in any direction: largest first-order error {:.4} µm (bound {:.4} µm)",
        worst * 1e3,
        bound * 1e3
    );
    assert!(worst < bound, "{worst} ≥ {bound}");
    assert!(
        worst * 1e3 > 0.1,
        "worst first-order error {} µm",
        worst * 1e3
    );
}

#[test]
fn four_sensors_weigh_their_readings_and_refuse_disagreement() {
    let i = instrument("four-45");
    let head = SensorHead::new(&i);
    let e = [0.02, -0.03, 0.01];
    let mut s = head.readings(e).unwrap();
    let inv = head.displacement(&s, false).unwrap();
    assert!(norm(diff(inv.displacement, e)) < 1e-12);
    assert!(inv.residual_mm.iter().all(|r| r.abs() < 1e-12));
    // A reading 0.05 µm off (half a σ) moves the least-squares solution, not refused.
    s[0] += 0.05e-3;
    let inv = head.displacement(&s, false).unwrap();
    assert!(inv.residual_mm.iter().any(|r| r.abs() > 1e-6));
    // One sensor 1 mm off: not noise.
    s[0] += 1.0;
    match head.displacement(&s, false) {
        Err(e @ InverseError::Disagree { .. }) => {
            assert!(
                e.to_string()
                    .contains("the readings of the 4 sensors disagree"),
                "{e}"
            )
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_covariance_of_the_inverse_is_that_of_a_monte_carlo() {
    // Unequal noise on the three inclined sensors gives correlated x, y, z noise.
    let mut i = instrument("inclined-45");
    i.sensors[0].noise_mm = 0.3e-3;
    let head = SensorHead::new(&i);
    let e = [0.04, -0.02, 0.03];
    let clean = head.readings(e).unwrap();
    let predicted = head.displacement(&clean, false).unwrap().covariance;
    let mut rng = Rng::new(3);
    let n = 20_000;
    let mut sum = [[0.0; 3]; 3];
    for _ in 0..n {
        let s: Vec<f64> = clean
            .iter()
            .zip(&head.noise_mm)
            .map(|(v, sd)| v + sd * rng.normal())
            .collect();
        let d = diff(head.displacement(&s, false).unwrap().displacement, e);
        for a in 0..3 {
            for b in 0..3 {
                sum[a][b] += d[a] * d[b];
            }
        }
    }
    for a in 0..3 {
        for b in 0..3 {
            let mc = sum[a][b] / n as f64;
            let scale = (predicted[a][a] * predicted[b][b]).sqrt();
            assert!(
                (mc - predicted[a][b]).abs() < 0.04 * scale,
                "[{a}][{b}]: Monte-Carlo {mc:e}, predicted {:e}",
                predicted[a][b]
            );
        }
    }
    // The x–z correlation is not small: the noisy sensor s1 lies in the x–z plane.
    let r = predicted[0][2] / (predicted[0][0] * predicted[2][2]).sqrt();
    eprintln!("inclined-45, s1 at 0.3 µm: x–z correlation {r:.3}");
    assert!(r.abs() > 0.3, "{r}");
    // With equal σ the symmetric layout is uncorrelated in the nest frame, σx = σy = σ/√0.75,
    // σz = σ/√1.5.
    let sym = SensorHead::new(&instrument("inclined-45"));
    let c = sym.displacement(&[0.0; 3], false).unwrap().covariance;
    let sigma2: f64 = 1e-8;
    assert!((c[0][0] - sigma2 / 0.75).abs() < 1e-12 * sigma2);
    assert!((c[2][2] - sigma2 / 1.5).abs() < 1e-12 * sigma2);
    assert!(c[0][1].abs() < 1e-12 * sigma2 && c[0][2].abs() < 1e-12 * sigma2);
}

#[test]
fn geometry_without_a_solution_is_an_error() {
    // A flat face of radius 4 mm: 5 mm across it the ball is off the face.
    let flat = SensorHead::new(&instrument("orthogonal"));
    let e = flat.readings([0.0, 5.0, 0.0]).unwrap_err();
    assert!(e.to_string().contains("off the face"), "{e}");
    // Ball tips: 30 mm across (21 mm across the axis of s1) they no longer touch with their
    // faces.
    let ball = SensorHead::new(&instrument("inclined-45"));
    let e = ball.readings([30.0, 0.0, 0.0]).unwrap_err();
    assert!(e.to_string().contains("cannot touch"), "{e}");
    // Readings no displacement explains: an error, never a panic or a NaN.
    for s in [[30.0, -30.0, 0.0], [1e9, 0.0, 0.0], [f64::NAN, 0.0, 0.0]] {
        assert!(ball.displacement(&s, false).is_err(), "{s:?}");
        assert!(flat.displacement(&s, false).is_err(), "{s:?}");
    }
    assert!(ball.displacement(&[0.0, 0.0], false).is_err());
}

#[test]
fn a_ball_tip_off_the_centre_line_reads_along_its_contact_normal() {
    // The plunger axis passes 1 mm beside the nest centre: the first-order direction is the
    // contact normal scaled by 1/cos, and the exact inverse still recovers the displacement.
    let text = r#"
name = "offset"
ball_radius_mm = 12.7
[[sensor]]
name = "s1"
direction = [1, 0, 0]
tip = "sphere"
tip_radius_mm = 2
position_mm = [-14.665938, 1, 0]
[[sensor]]
name = "s2"
direction = [0, 1, 0]
tip = "flat"
face_radius_mm = 4
[[sensor]]
name = "s3"
direction = [0, 0, -1]
tip = "flat"
face_radius_mm = 4
"#;
    let i = parse_instrument("offset.toml", text).unwrap();
    assert!(matches!(i.sensors[0].tip, Tip::Sphere { .. }));
    let rows = model_spec::instrument::first_order_matrix(&i);
    let q = i.sensors[0].tip_at_zero(12.7);
    assert!(((q[0] * q[0] + q[1] * q[1]).sqrt() - 14.7).abs() < 1e-12);
    assert!((rows[0][1] - q[1] / q[0]).abs() < 1e-12, "{:?}", rows[0]);
    let head = SensorHead::new(&i);
    let e = [0.03, -0.04, 0.02];
    let inv = head
        .displacement(&head.readings(e).unwrap(), false)
        .unwrap();
    assert!(norm(diff(inv.displacement, e)) < 1e-12);
}
