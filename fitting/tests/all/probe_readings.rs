//! Probe hits turned into readings (`fitting::probe`): a pose's reading is the error vector an
//! R-test would read there, with its sign; the refusals name the file and the line.

use crate::common::{Rng, builtin, random_rotary};
use fitting::probe::{PreTravel, ProbeSettings, probe_record};
use fitting::sphere::default_pattern;
use formats::probe::{ProbeHit, ProbeHits, ProbePose};
use model_spec::{AxisKind, Machine, Side};
use nalgebra::{Matrix3, Vector3};
use simulation::exact::VirtualMachine;

const SPHERE_MM: f64 = 12.5;
const TIP_MM: f64 = 1.5;

fn settings() -> ProbeSettings {
    ProbeSettings {
        tip_radius_mm: TIP_MM,
        sphere_radius_mm: SPHERE_MM,
        noise_mm: Some(0.5e-3),
        declared: PreTravel::default(),
        max_reading_mm: 1.0,
        off_sphere_mm: 0.5,
    }
}

/// Random errors of every location error of `m` (up to 30 µm, 60 µrad): constant, so a pose's
/// error vector is the same at every hit.
fn location_errors(m: &Machine, rng: &mut Rng) -> Vec<f64> {
    m.catalogue
        .iter()
        .map(|e| {
            if matches!(e.kind, model_spec::ErrorKind::Component { .. }) {
                0.0
            } else if e.is_angular() {
                rng.range(-60e-6, 60e-6)
            } else {
                rng.range(-0.03, 0.03)
            }
        })
        .collect()
}

/// `P_tool − P_work` at `commands` with `errors` (bed frame, mm).
fn gap(vm: &VirtualMachine, q: &[f64], params: &[f64], errors: &[f64]) -> Vector3<f64> {
    let t = vm.transform_with(Side::Tool, q, params, &|id| errors[id]);
    let w = vm.transform_with(Side::Work, q, params, &|id| errors[id]);
    t.translation.vector - w.translation.vector
}

/// The default pattern's hits at the pose `rotary` (rad) of a machine whose error in the bed
/// frame is `g` (mm): the nominal tip targets `−g + R_eff·u_i` reached through the nominal
/// linear map, with `pre(n)` added along each approach `n`.
fn pose_hits(
    vm: &VirtualMachine,
    label: &str,
    rotary: &[f64],
    params: &[f64],
    g: Vector3<f64>,
    pre: &dyn Fn(&Vector3<f64>) -> f64,
    line: &mut usize,
) -> ProbePose {
    let m = vm.machine();
    let mut q0 = rotary.to_vec();
    vm.tool_centre_point_ik(&mut q0, params).unwrap();
    let zero = vec![0.0; m.catalogue.len()];
    let linear: Vec<usize> = m.linear_axes().collect();
    let b = gap(vm, &q0, params, &zero);
    let mut a = Matrix3::zeros();
    for (k, &i) in linear.iter().enumerate() {
        let mut q = q0.clone();
        q[i] += 1.0;
        a.set_column(k, &(gap(vm, &q, params, &zero) - b));
    }
    let ainv = a.try_inverse().unwrap();
    let hits = default_pattern(SPHERE_MM + TIP_MM)
        .iter()
        .map(|h| {
            let n = h.approach;
            let target = -g + h.point_mm + pre(&n) * n;
            let dq = ainv * (target - b);
            let mut q = q0.clone();
            for (k, &i) in linear.iter().enumerate() {
                q[i] += dq[k];
            }
            *line += 1;
            ProbeHit {
                line: *line,
                axes: m
                    .axes
                    .iter()
                    .zip(&q)
                    .map(|(ax, &x)| match ax.kind {
                        AxisKind::Linear => x,
                        AxisKind::Rotary => x.to_degrees(),
                    })
                    .collect(),
                direction: [n.x, n.y, n.z],
                t_s: *line as f64,
            }
        })
        .collect();
    ProbePose {
        label: label.into(),
        hits,
    }
}

#[test]
fn a_probe_reading_is_the_error_vector_an_r_test_reads() {
    for name in ["seed-ac", "table-table-bc", "head-table-bc"] {
        let m = builtin(name);
        let vm = VirtualMachine::new(&m);
        let params = m.default_parameters();
        let mut rng = Rng::new(7);
        let errors = location_errors(&m, &mut rng);
        let mut line = 1;
        let mut poses = Vec::new();
        let mut expected = Vec::new();
        for k in 0..6 {
            let mut q = random_rotary(&m, &mut rng);
            vm.tool_centre_point_ik(&mut q, &params).unwrap();
            let g = gap(&vm, &q, &params, &errors);
            poses.push(pose_hits(
                &vm,
                &format!("p{k}"),
                &q,
                &params,
                g,
                &|_| 0.0,
                &mut line,
            ));
            expected.push(vm.error_vector(&q, &params, &errors).position);
        }
        let read = probe_record("h.csv", &m, &params, &ProbeHits { poses }, &settings()).unwrap();
        for (k, e) in expected.iter().enumerate() {
            let got = Vector3::from(read.record.measured[k]);
            // Second order apart: the reading turns by the nominal tool rotation, the error
            // vector by the actual one (60 µrad × 50 µm = 3 nm).
            assert!(
                (got - e).norm() < 1e-5,
                "{name} pose {k}: reading {got:?}, the exact error vector {e:?}"
            );
            assert!(e.norm() > 5e-3, "{name}: the errors must show: {e:?}");
        }
        // The record carries one sample per pose, the covariances and the first hits' lines.
        assert_eq!(read.record.samples.len(), 6);
        assert_eq!(read.record.covariance.len(), 6);
        assert_eq!(read.record.lines[1], 11);
        assert!(
            read.pre_travel_mm.0.abs() < 1e-9,
            "{name}: {:?}",
            read.pre_travel_mm
        );
    }
}

#[test]
fn pretravel_gains_predict_the_centre_shift_and_a_declared_pretravel_is_removed() {
    let m = builtin("head-table-bc");
    let vm = VirtualMachine::new(&m);
    let params = m.default_parameters();
    let mut rng = Rng::new(3);
    let mut q = random_rotary(&m, &mut rng);
    vm.tool_centre_point_ik(&mut q, &params).unwrap();
    let tool = vm
        .transform_with(Side::Tool, &q, &params, &|_| 0.0)
        .rotation;
    let lobing = PreTravel {
        constant_mm: 0.0,
        lobing_mm: [2e-3, -1e-3],
    };
    let pre = |n: &Vector3<f64>| lobing.along(tool.matrix(), n);
    let mut line = 1;
    let clean = pose_hits(&vm, "p", &q, &params, Vector3::zeros(), &|_| 0.0, &mut line);
    let lobed = pose_hits(&vm, "p", &q, &params, Vector3::zeros(), &pre, &mut line);
    let s = settings();
    let at = |p: &ProbePose, s: &ProbeSettings| {
        probe_record(
            "h.csv",
            &m,
            &params,
            &ProbeHits {
                poses: vec![p.clone()],
            },
            s,
        )
        .unwrap()
    };
    let base = at(&clean, &s);
    let shifted = at(&lobed, &s);
    let shift = Vector3::from(shifted.record.measured[0]) - Vector3::from(base.record.measured[0]);
    let predicted: Vector3<f64> = base.poses[0]
        .pretravel_gain
        .iter()
        .zip(&base.poses[0].approach_tool)
        .map(|(gain, n)| gain * lobing.along(&nalgebra::Matrix3::identity(), n))
        .sum();
    assert!(
        shift.norm() > 0.3e-3,
        "the lobing moves the centre: {shift:?}"
    );
    assert!(
        (shift - predicted).norm() < 1e-3 * shift.norm(),
        "measured {shift:?}, predicted {predicted:?}"
    );
    // Declared, it is removed before the fit.
    let declared = ProbeSettings {
        declared: lobing,
        ..s
    };
    let removed = at(&lobed, &declared);
    assert!(Vector3::from(removed.record.measured[0]).norm() < 1e-9);
    // A constant pre-travel moves no centre; the radii show it.
    let constant = pose_hits(
        &vm,
        "p",
        &q,
        &params,
        Vector3::zeros(),
        &|_| 2e-3,
        &mut line,
    );
    let c = at(&constant, &s);
    assert!(Vector3::from(c.record.measured[0]).norm() < 1e-9);
    assert!(
        (c.pre_travel_mm.0 - 2e-3).abs() < 1e-9,
        "{:?}",
        c.pre_travel_mm
    );
}

#[test]
fn refusals_name_the_file_the_line_and_the_rule() {
    let m = builtin("seed-ac");
    let vm = VirtualMachine::new(&m);
    let params = m.default_parameters();
    let q = vec![0.0; m.axes.len()];
    let mut line = 3;
    let mut pose = pose_hits(
        &vm,
        "p1",
        &q,
        &params,
        Vector3::zeros(),
        &|_| 0.0,
        &mut line,
    );
    let read = |pose: &ProbePose, s: &ProbeSettings| {
        probe_record(
            "h.csv",
            &m,
            &params,
            &ProbeHits {
                poses: vec![pose.clone()],
            },
            s,
        )
        .unwrap_err()
        .to_string()
    };
    // A dirty hit (20 µm on the third hit, the one approached along +X: X moves the table,
    // so X + 0.02 puts the tip 20 µm outwards) is refused by the residual rule, named by its
    // line.
    let clean = pose.clone();
    assert!((Vector3::from(pose.hits[2].direction) - Vector3::x()).norm() < 1e-12);
    let x = m.axes.iter().position(|a| a.name == "X").unwrap();
    pose.hits[2].axes[x] += 0.02;
    let e = read(&pose, &settings());
    assert!(
        e.starts_with("h.csv:6: pose `p1`: sphere fit refused (residual)"),
        "{e}"
    );
    assert!(e.contains("hit 3 of the pose (line 6) is "), "{e}");
    // No declared σ.
    let e = read(
        &clean,
        &ProbeSettings {
            noise_mm: None,
            ..settings()
        },
    );
    assert!(e.starts_with("h.csv:4: ") && e.contains("noise_um"), "{e}");
    // A wrong sphere radius: every hit is 1 mm off the nominal sphere.
    let e = read(
        &clean,
        &ProbeSettings {
            sphere_radius_mm: SPHERE_MM + 1.0,
            ..settings()
        },
    );
    assert!(
        e.starts_with("h.csv:4: pose `p1`: the hit's tip centre"),
        "{e}"
    );
    // A radius 8 µm off: the radius rule.
    let e = read(
        &clean,
        &ProbeSettings {
            sphere_radius_mm: SPHERE_MM + 0.008,
            ..settings()
        },
    );
    assert!(e.contains("sphere fit refused (radius)"), "{e}");
}
