//! SINUMERIK swivel data records (`compensation::controllers::siemens`): which descriptions they
//! cover and with which type, the vectors of the built-in machines, the self-check, and the
//! compensation tables' signs. (The written part program against an independent forward
//! model: the root package's `siemens_forward` tests.)

use crate::common::builtin;
use crate::identified::errors_of;
use compensation::controllers::siemens::tables::{TableKind, siemens_tables};
use compensation::controllers::siemens::{KinematicType, swivel_kinematics};
use compensation::tables::Pitch;
use nalgebra::Vector3;

#[test]
fn the_built_in_five_axis_machines_map_onto_their_kinematic_types() {
    for (name, kind, map) in [
        (
            "seed-ac",
            KinematicType::P,
            "X1 = -X, Y1 = Y, Z1 = Z, A1 = A, C1 = C",
        ),
        (
            "table-table-bc",
            KinematicType::P,
            "X1 = X, Y1 = Y, Z1 = Z, B1 = B, C1 = C",
        ),
        (
            "nutating-table-bc",
            KinematicType::P,
            "X1 = X, Y1 = Y, Z1 = Z, B1 = B, C1 = C",
        ),
        (
            "head-table-bc",
            KinematicType::M,
            "X1 = X, Y1 = Y, Z1 = Z, B1 = B, C1 = C",
        ),
        (
            "head-head-ca",
            KinematicType::T,
            "X1 = X, Y1 = Y, Z1 = Z, C1 = C, A1 = A",
        ),
        (
            "nutating-head-bc",
            KinematicType::M,
            "X1 = X, Y1 = Y, Z1 = Z, B1 = B, C1 = C",
        ),
    ] {
        let m = builtin(name);
        let k = swivel_kinematics(&m, &m.default_parameters()).unwrap();
        assert_eq!(k.data.kind, kind, "{name}");
        assert_eq!(k.axis_map(), map, "{name}");
        assert!(k.check_mm < 1e-9, "{name}: {}", k.check_mm);
        for v in [k.data.v1, k.data.v2] {
            assert!((v.norm() - 1.0).abs() < 1e-14, "{name}: {v}");
        }
        // The closures of W1 and IM9.
        let d = &k.data;
        let closure = match kind {
            KinematicType::P => d.l4 + d.l2 + d.l3,
            KinematicType::T => d.l1 + d.l2 + d.l3,
            KinematicType::M => (d.l1 + d.l2) + (d.l4 + d.l3),
        };
        assert!(closure.norm() < 1e-11, "{name}: {closure}");
    }
}

#[test]
fn the_nutating_table_has_its_inclined_axis_as_v1() {
    let m = builtin("nutating-table-bc");
    let k = swivel_kinematics(&m, &m.default_parameters()).unwrap();
    let s = std::f64::consts::FRAC_1_SQRT_2;
    assert!(
        (k.data.v1 - Vector3::new(0.0, -s, s)).norm() < 1e-15,
        "{}",
        k.data.v1
    );
    assert_eq!(k.data.v2, Vector3::new(0.0, 0.0, 1.0));
    // The axes intersect at the bed origin (Xb = Yb = Zb = 0, Xc = Yc = 0): l3 = 0, l2 from
    // the tool point at zero (z = Zp = 220) to it.
    assert!(k.data.l3.norm() < 1e-12, "{}", k.data.l3);
    assert!(
        (k.data.l2 - Vector3::new(0.0, 0.0, -220.0)).norm() < 1e-12,
        "{}",
        k.data.l2
    );
}

#[test]
fn machines_without_two_rotary_axes_over_three_linear_ones_are_not_covered() {
    for name in ["seed-3axis", "horizontal-4axis-b"] {
        let m = builtin(name);
        let e = swivel_kinematics(&m, &m.default_parameters()).unwrap_err();
        assert!(
            e.to_string().contains(&format!(
                "machine `{name}` is not covered by a SINUMERIK swivel data record"
            )),
            "{e}"
        );
        assert!(
            e.to_string()
                .contains("two rotary axes over three linear ones"),
            "{e}"
        );
    }
}

#[test]
fn a_table_side_axis_drifting_plus_y_moves_the_tool_minus_y_in_its_cec_table() {
    // seed-ac's X carries the table: EYX of +2 µm/100 mm moves the table +y, the tool −y
    // relative to it; machine axis X1 = −X, so the table over X1 runs from −500 to 500 with the
    // deviation −EYX(X = −X1).
    let m = builtin("seed-ac");
    let errors = errors_of(
        &m,
        &[("EYX@poly:1", 0.002), ("EXX@poly:1", -0.003), ("ECC", 1e-5)],
    );
    let k = swivel_kinematics(&m, &m.default_parameters()).unwrap();
    let pitch = Pitch {
        linear_mm: 10.0,
        rotary_deg: 10.0,
    };
    let tables = siemens_tables(&m, &m.default_parameters(), &errors, &k, pitch).unwrap();
    let by = |e: &str| tables.iter().find(|t| t.error == e).unwrap();
    let eyx = by("EYX");
    assert_eq!(
        (eyx.kind, eyx.input.as_str(), eyx.output.as_str()),
        (TableKind::CrossAxis, "X1", "Y1")
    );
    assert_eq!((eyx.min, eyx.step, eyx.values.len()), (-500.0, 10.0, 101));
    let exx = by("EXX");
    assert_eq!(
        (exx.kind, exx.input.as_str(), exx.output.as_str()),
        (TableKind::Encoder, "X1", "X1")
    );
    let ecc = by("ECC");
    assert!(ecc.rotary && ecc.modulo && ecc.min == 0.0 && ecc.values.len() == 37);
    // C is `+z`: its deviation is +ECC, in degrees.
    assert!(
        ecc.values
            .iter()
            .all(|v| (v - 1e-5f64.to_degrees()).abs() < 1e-18)
    );
    // The values: the errors at X = −X1, with the signs above.
    let mut slot = vec![0.0; errors.errors().len()];
    let mut q = vec![0.0; m.axes.len()];
    let x = m.axis_by_name("X").unwrap();
    for (i, (ey, ex)) in eyx.values.iter().zip(&exx.values).enumerate() {
        let x1 = eyx.min + 10.0 * i as f64;
        q[x] = -x1;
        errors.values_at(&m, &q, &mut slot);
        let name = |n: &str| {
            errors
                .errors()
                .iter()
                .position(|&e| m.catalogue[e].name == n)
                .unwrap()
        };
        assert!((ey + slot[name("EYX")]).abs() < 1e-15);
        // EXX moves the table +x, the tool −x relative to it: along X1 the deviation is −EXX.
        assert!((ex + slot[name("EXX")]).abs() < 1e-15);
    }
    // The pitch limit.
    let fine = Pitch {
        linear_mm: 1.0,
        rotary_deg: 10.0,
    };
    let e = siemens_tables(&m, &m.default_parameters(), &errors, &k, fine).unwrap_err();
    assert!(
        e.to_string()
            .contains("1001 points at a pitch of 1 mm, more than the 200"),
        "{e}"
    );
}
