//! ISG's volumetric compensation (`compensation::controllers::isg`): the position errors under
//! ISG's names with their values, one block per axis of its component errors, the chain, and
//! the machines its model does not cover.

use crate::common::builtin;
use crate::identified::errors_of;
use compensation::controllers::isg::{IsgError, isg_name, isg_volumetric};
use compensation::tables::Pitch;

const PITCH: Pitch = Pitch {
    linear_mm: 250.0,
    rotary_deg: 90.0,
};

#[test]
fn the_names_are_rtests_with_the_letter_o_as_a_zero() {
    assert_eq!(isg_name("XOC"), "X0C");
    assert_eq!(isg_name("COX"), "C0X");
    assert_eq!(isg_name("EXX"), "EXX");
}

#[test]
fn seed_ac_position_errors_and_the_component_errors_of_x_and_c() {
    let m = builtin("seed-ac");
    let e = errors_of(
        &m,
        &[
            ("XOC", 0.012),
            ("AOC", 3e-5),
            ("COX", -2e-5),
            ("EXX@poly:1", 0.01),
            ("EYX", 0.002),
            ("ECC", 4e-6),
        ],
    );
    let v = isg_volumetric(&m, &e, PITCH).unwrap();
    assert_eq!(v.chain, "CAXYZ");
    assert_eq!(v.workpiece_axes, 3);
    assert!(v.not_held.is_empty());
    let position = &v.blocks[0];
    assert_eq!(position.columns, ["C0X", "X0C", "A0C"]);
    assert_eq!(position.rows, [vec![-2e-5, 0.012, 3e-5]]);
    let x = &v.blocks[1];
    assert_eq!(x.columns, ["X", "EXX", "EYX"]);
    // Over X's stroke, -500..500 mm every 250 mm: EXX = 0.01·P1(x/500) mm, EYX constant.
    assert_eq!(x.rows.len(), 5);
    assert_eq!(x.rows[0][0], -500.0);
    assert!((x.rows[0][1] + 0.01).abs() < 1e-15 && (x.rows[4][1] - 0.01).abs() < 1e-15);
    assert!(x.rows.iter().all(|r| r[2] == 0.002));
    let c = &v.blocks[2];
    assert_eq!(c.columns, ["C", "ECC"]);
    assert_eq!(c.rows.len(), 5);
    assert!(c.rows.iter().all(|r| r[1] == 4e-6));
}

#[test]
fn an_identified_length_is_listed_as_not_held() {
    let m = builtin("seed-ac");
    let e = errors_of(&m, &[("XOC", 0.01), ("Zc", 0.02)]);
    let v = isg_volumetric(&m, &e, PITCH).unwrap();
    assert_eq!(v.not_held.len(), 1);
    assert_eq!(v.not_held[0].0, "Zc");
}

#[test]
fn an_inclined_axis_is_not_covered() {
    let m = builtin("nutating-table-bc");
    let e = errors_of(&m, &[("XOC", 0.01)]);
    match isg_volumetric(&m, &e, PITCH) {
        Err(IsgError::NotCovered { why, .. }) => {
            assert!(why.contains("axis B is inclined"), "{why}")
        }
        other => panic!("{other:?}"),
    }
}
