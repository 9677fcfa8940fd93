//! The exact virtual machine: transforms, error vectors and the nominal inverse kinematics.

use crate::common;

use common::{Rng, builtin, commands, id, random_rotary, sym};
use model_spec::{Machine, Side, all_builtin, parse_machine};
use nalgebra::{Vector3, Vector4};
use simulation::exact::{ExactError, VirtualMachine};
use simulation::fd::fd_gains;
use simulation::{chain_transform, error_vector, nominal_error_vector, tool_centre_point_ik};

fn close(a: &Vector3<f64>, b: &Vector3<f64>, tol: f64) -> bool {
    (a - b).amax() <= tol
}

#[test]
fn ik_closes_the_nominal_gap_on_every_builtin() {
    let mut rng = Rng::new(42);
    for m in all_builtin() {
        let p = m.default_parameters();
        for _ in 0..200 {
            let mut q = random_rotary(&m, &mut rng);
            let rotary = q.clone();
            tool_centre_point_ik(&m, &mut q, &p).unwrap();
            let v = nominal_error_vector(&m, &q, &p);
            assert!(
                v.position.amax() < 1e-9,
                "{}: gap {:?} at {q:?}",
                m.name,
                v.position
            );
            assert_eq!(v.orientation, Vector3::zeros());
            for i in m.rotary_axes() {
                assert_eq!(q[i], rotary[i], "rotary commands are kept");
            }
        }
    }
}

#[test]
fn ik_with_random_parameters_too() {
    let mut rng = Rng::new(3);
    for m in all_builtin() {
        for _ in 0..50 {
            let p: Vec<f64> = m.symbols.iter().map(|_| rng.range(-300.0, 300.0)).collect();
            let mut q = random_rotary(&m, &mut rng);
            tool_centre_point_ik(&m, &mut q, &p).unwrap();
            let v = nominal_error_vector(&m, &q, &p);
            assert!(v.position.amax() < 1e-9, "{}: {:?}", m.name, v.position);
        }
    }
}

#[test]
fn seed_ac_chain_transforms_at_known_poses() {
    let m = builtin("seed-ac");
    let p = m.default_parameters();
    let zero = vec![0.0; m.catalogue.len()];
    let (xw, yw, zw, zc, zp) = (
        sym(&m, &p, "Xw"),
        sym(&m, &p, "Yw"),
        sym(&m, &p, "Zw"),
        sym(&m, &p, "Zc"),
        sym(&m, &p, "Zp"),
    );
    let q = commands(&m, &[]);
    let w = chain_transform(&m, Side::Work, &q, &p, &zero);
    assert!(close(
        &w.translation.vector,
        &Vector3::new(xw, yw, zc + zw),
        1e-12
    ));
    let t = chain_transform(&m, Side::Tool, &q, &p, &zero);
    assert!(close(
        &t.translation.vector,
        &Vector3::new(0.0, 0.0, zp),
        1e-12
    ));
    // X = 10 mm, A = +90° (right-hand about +x): (x, y, z) → (x, −z, y) below the A frame.
    let q = commands(&m, &[("X", 10.0), ("A", 90f64.to_radians()), ("Y", 5.0)]);
    let w = chain_transform(&m, Side::Work, &q, &p, &zero);
    assert!(close(
        &w.translation.vector,
        &Vector3::new(10.0 + xw, -(zc + zw), yw),
        1e-12
    ));
    // The 4×4 homogeneous matrix maps the end frame's origin to the end point.
    let h = w.to_homogeneous() * Vector4::new(0.0, 0.0, 0.0, 1.0);
    assert!(close(&h.xyz(), &w.translation.vector, 0.0));
    let t = chain_transform(&m, Side::Tool, &q, &p, &zero);
    assert!(close(
        &t.translation.vector,
        &Vector3::new(0.0, 5.0, zp),
        1e-12
    ));
}

#[test]
fn setup_error_xow_on_seed_ac_at_home() {
    let m = builtin("seed-ac");
    let p = m.default_parameters();
    let mut q = commands(&m, &[]);
    tool_centre_point_ik(&m, &mut q, &p).unwrap();
    let mut e = vec![0.0; m.catalogue.len()];
    e[id(&m, "XOW")] = 0.01;
    let v = error_vector(&m, &q, &p, &e);
    // The ball sits 0.01 mm further along +x: tool minus workpiece is −0.01 mm along x.
    assert!(close(&v.position, &Vector3::new(-0.01, 0.0, 0.0), 1e-12));
    assert_eq!(v.orientation, Vector3::zeros());
}

#[test]
fn no_errors_gives_the_nominal_error_vector() {
    let mut rng = Rng::new(9);
    for m in all_builtin() {
        let p = m.default_parameters();
        let q = random_rotary(&m, &mut rng);
        let zero = vec![0.0; m.catalogue.len()];
        assert_eq!(
            error_vector(&m, &q, &p, &zero),
            nominal_error_vector(&m, &q, &p)
        );
    }
}

/// head-table-bc: the tool frame turns with the B head, and the error vector is expressed in it.
///
/// Work chain: `Rz(C) · (Xw, Yw, Zw) · (XOW, YOW, ZOW)`, so XOW = e moves the ball by
/// `Rz(C)·(e, 0, 0) = e·(cos C, sin C, 0)` in the bed frame, and tool minus workpiece is
/// `g = −e·(cos C, sin C, 0)`.
/// Tool chain: `X · Y · Z · (Xb, Yb, Zb) · Ry(B) · (0, 0, Zt)`, so `R_tool = Ry(B)`; at
/// B = +90°, `Ry = [[0, 0, 1], [0, 1, 0], [−1, 0, 0]]`: the tool's z axis (third column) points
/// along bed +x and its x axis along bed −z. In the tool frame
/// `R_toolᵀ·g = (−g_z, g_y, g_x) = −e·(0, sin C, cos C)`:
/// at C = 0 the set-up error along x shows up entirely on the tool's z, with gain −1.
#[test]
fn head_table_bc_setup_error_in_the_turned_tool_frame() {
    let m = builtin("head-table-bc");
    let p = m.default_parameters();
    let e = 0.01;
    let mut err = vec![0.0; m.catalogue.len()];
    err[id(&m, "XOW")] = e;
    for c_deg in [0.0f64, 30.0, -125.0] {
        let c = c_deg.to_radians();
        let mut q = commands(&m, &[("B", 90f64.to_radians()), ("C", c)]);
        tool_centre_point_ik(&m, &mut q, &p).unwrap();
        let expected = -e * Vector3::new(0.0, c.sin(), c.cos());
        let v = error_vector(&m, &q, &p, &err);
        assert!(
            close(&v.position, &expected, 1e-12),
            "C = {c_deg}°: {:?} vs {expected:?}",
            v.position
        );
        let g = fd_gains(&m, &q, &p, &[id(&m, "XOW")]);
        assert!(close(
            &Vector3::new(g[0][0], g[0][1], g[0][2]),
            &(expected / e),
            1e-10
        ));
    }
    // The tilt COB of the B head about z turns the tool's z axis (bed +x at B = 90°) by
    // COB·ẑ × x̂ = COB·(0, 1, 0) in the bed frame, which is (0, 1, 0) in the tool frame too:
    // orientation gain (0, 1, 0).
    let mut q = commands(&m, &[("B", 90f64.to_radians())]);
    tool_centre_point_ik(&m, &mut q, &p).unwrap();
    let g = fd_gains(&m, &q, &p, &[id(&m, "COB")]);
    assert!(close(
        &Vector3::new(g[0][3], g[0][4], g[0][5]),
        &Vector3::new(0.0, 1.0, 0.0),
        1e-9
    ));
    // Its position gain: the tool point (Zt below the pivot, i.e. at Zt·(1, 0, 0) from the pivot
    // in the bed frame) moves by COB·ẑ × (Zt, 0, 0) = (0, COB·Zt, 0): tool frame (0, Zt, 0).
    let zt = sym(&m, &p, "Zt");
    assert!(close(
        &Vector3::new(g[0][0], g[0][1], g[0][2]),
        &Vector3::new(0.0, zt, 0.0),
        1e-9
    ));
}

/// The exact chain is not linearised: the difference between the exact error vector and its
/// first-order prediction `ε·gain` is of second order in `ε`.
#[test]
fn rotation_errors_are_exact_beyond_first_order() {
    type Case = (&'static str, &'static str, &'static [(&'static str, f64)]);
    let cases: [Case; 3] = [
        ("seed-ac", "BOA", &[("A", -0.6), ("C", 2.1)]),
        ("seed-ac", "EAX", &[("A", 0.4), ("C", -1.0)]),
        ("head-table-bc", "AOB", &[("B", 1.1), ("C", 0.3)]),
    ];
    for (name, error, pose) in cases {
        let m = builtin(name);
        let p = m.default_parameters();
        let mut q = commands(&m, pose);
        tool_centre_point_ik(&m, &mut q, &p).unwrap();
        let k = id(&m, error);
        let gain = fd_gains(&m, &q, &p, &[k])[0];
        let residual = |eps: f64| {
            let mut e = vec![0.0; m.catalogue.len()];
            e[k] = eps;
            let v = error_vector(&m, &q, &p, &e).to_array();
            (0..6)
                .map(|i| (v[i] - eps * gain[i]).abs())
                .fold(0.0, f64::max)
        };
        let (r1, r2) = (residual(1e-3), residual(5e-4));
        assert!(
            r1 > 1e-6,
            "{name} {error}: second-order term {r1:e} missing"
        );
        let ratio = r1 / r2;
        assert!(
            (ratio - 4.0).abs() < 0.05,
            "{name} {error}: residual ratio {ratio} (r = {r1:e}, {r2:e}), expected 4"
        );
    }
}

fn custom(text: &str) -> Machine {
    parse_machine("<test>", text).expect("valid test machine")
}

/// Y on the work side under a C table; X, an A head and a Z ram after it on the tool side, so Z
/// moves along `Rx(A)·ẑ = (0, −sin A, cos A)`.
const TILTED_RAM: &str = r#"
name = "tilted-ram"
[symbols]
L = 150.0
[[work]]
axis = "Y"
type = "linear"
direction = "-y"
stroke = [-400.0, 400.0]
[[work]]
axis = "C"
type = "rotary"
direction = "+z"
offset = [10.0, 20.0, 30.0]
[[work]]
end = "ball"
offset = [100.0, -50.0, 40.0]
[[tool]]
axis = "X"
type = "linear"
direction = "+x"
stroke = [-400.0, 400.0]
[[tool]]
axis = "A"
type = "rotary"
direction = "+x"
offset = [0.0, 0.0, 500.0]
[[tool]]
axis = "Z"
type = "linear"
direction = "+z"
stroke = [-400.0, 400.0]
[[tool]]
end = "probe"
offset = [0, 0, "L"]
"#;

#[test]
fn ik_with_linear_axes_on_both_chains_and_a_turned_ram() {
    let m = custom(TILTED_RAM);
    let p = m.default_parameters();
    let mut rng = Rng::new(5);
    for _ in 0..100 {
        let mut q = commands(
            &m,
            &[("A", rng.range(-1.4, 1.4)), ("C", rng.range(-3.0, 3.0))],
        );
        tool_centre_point_ik(&m, &mut q, &p).unwrap();
        assert!(nominal_error_vector(&m, &q, &p).position.amax() < 1e-9);
    }
    // At A = 90° the ram moves along −y, like the (work-side, −y) Y axis: singular.
    let mut q = commands(&m, &[("A", std::f64::consts::FRAC_PI_2), ("C", 0.2)]);
    let before = q.clone();
    match tool_centre_point_ik(&m, &mut q, &p) {
        Err(ExactError::Singular { pose, names, .. }) => {
            assert!(pose.contains("A = 90°"), "{pose}");
            assert_eq!(names, "Y, X, Z");
        }
        other => panic!("expected a singular pose, got {other:?}"),
    }
    assert_eq!(q, before, "commands unchanged on error");
}

#[test]
fn ik_needs_three_linear_axes() {
    let m = custom(
        r#"
name = "two-linear"
[[work]]
axis = "C"
type = "rotary"
direction = "+z"
[[work]]
end = "ball"
offset = [0, 0, 0]
[[tool]]
axis = "X"
type = "linear"
direction = "+x"
stroke = [-1.0, 1.0]
[[tool]]
axis = "Y"
type = "linear"
direction = "+y"
stroke = [-1.0, 1.0]
[[tool]]
end = "probe"
offset = [0, 0, 0]
"#,
    );
    let mut q = vec![0.0; m.axes.len()];
    let err = tool_centre_point_ik(&m, &mut q, &[]).unwrap_err();
    assert!(matches!(err, ExactError::LinearAxisCount { count: 2, .. }));
    assert!(
        err.to_string().contains("exactly three linear axes"),
        "{err}"
    );
}

/// A rotary axis turning about −z at +θ is the same as one about +z at −θ, and its angular
/// positioning error still turns about +z.
#[test]
fn negative_rotary_direction_and_its_positioning_error() {
    let plus = builtin("head-table-bc");
    let text = model_spec::BUILTIN
        .iter()
        .find(|(n, _)| *n == "head-table-bc")
        .unwrap()
        .1
        .replacen("direction = \"+z\"", "direction = \"-z\"", 1);
    let minus = custom(&text);
    assert!(
        minus.axes[minus.axis_by_name("C").unwrap()]
            .direction
            .own
            .negative
    );
    assert!(
        !minus.axes[minus.axis_by_name("Z").unwrap()]
            .direction
            .own
            .negative
    );
    let p = plus.default_parameters();
    let (vp, vm) = (VirtualMachine::new(&plus), VirtualMachine::new(&minus));
    let mut e = vec![0.0; plus.catalogue.len()];
    e[id(&plus, "ECC")] = 2e-3;
    e[id(&plus, "XOW")] = 5e-3;
    let theta = 0.7;
    let qp = commands(&plus, &[("C", -theta), ("B", 0.5), ("X", 3.0)]);
    let qm = commands(&minus, &[("C", theta), ("B", 0.5), ("X", 3.0)]);
    let (a, b) = (vp.error_vector(&qp, &p, &e), vm.error_vector(&qm, &p, &e));
    assert!(close(&a.position, &b.position, 1e-12));
    assert!(close(&a.orientation, &b.orientation, 1e-15));
}
