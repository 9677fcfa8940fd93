//! Inclined axes with exact and numeric directions: the symbolic gains equal central finite
//! differences of the exact chain at on-ball poses, the compiled program equals the symbolic
//! gains, and the gain tables are exact (`√2`, `√3`) where the direction allows and numeric
//! (named constants) where it does not.

use codegen::{GainModel, compile};
use model_spec::parse_machine;

use crate::common;
use common::gains::{close, pose};

/// A head-table machine: C table on the work side; X Y Z and a rotary head about `direction`
/// on the tool side, with the tool 120 mm below the head's pivot.
fn machine(direction: &str) -> model_spec::Machine {
    let text = format!(
        r#"
name = "inclined-test"
[symbols]
Xw = 100.0
Yw = 20.0
Zw = 80.0
Zb = 150.0
Lt = 120.0
[[work]]
axis = "C"
type = "rotary"
direction = "+z"
[[work]]
end = "ball"
offset = ["Xw", "Yw", "Zw"]
[[tool]]
axis = "X"
type = "linear"
direction = "+x"
stroke = [-900.0, 900.0]
[[tool]]
axis = "Y"
type = "linear"
direction = "+y"
stroke = [-900.0, 900.0]
[[tool]]
axis = "Z"
type = "linear"
direction = "+z"
stroke = [-900.0, 900.0]
[[tool]]
axis = "B"
type = "rotary"
direction = {direction}
offset = [0, 0, "Zb"]
range = [-180.0, 180.0]
[[tool]]
end = "probe"
offset = [0, 0, "Lt"]
"#
    );
    parse_machine("inclined-test.toml", &text).unwrap()
}

const DIRECTIONS: [&str; 5] = [
    "[0, 1, 1]",
    "[0, -0.5, 0.8660254037844386]",
    "[1, 2, 3]",
    "[0, 0.766044443118978, 0.6427876096865394]",
    "[0.7071067811865476, 0, 0.7071067811865476]",
];

#[test]
fn gains_equal_finite_differences_for_exact_and_numeric_directions() {
    for direction in DIRECTIONS {
        let m = machine(direction);
        let all: Vec<usize> = (0..m.catalogue.len()).collect();
        let model = GainModel::derive(&m, &all);
        let program = compile(&m, &model);
        for case in 0..12 {
            let unit: Vec<f64> = (0..16)
                .map(|i| ((i * 7919 + case * 104_729) % 1000) as f64 / 1000.0)
                .collect();
            let (commands, params) = pose(&m, &unit);
            let symbolic = model.evaluate(&commands, &params);
            let numeric = simulation::fd::fd_gains(&m, &commands, &params, &model.errors);
            let inputs = model.atoms.values(&commands, &params);
            let (mut scratch, mut ir) = (Vec::new(), vec![0.0; program.outputs.len()]);
            program.eval(&inputs, &mut scratch, &mut ir);
            for (i, (s, n)) in symbolic.iter().zip(&numeric).enumerate() {
                for k in 0..6 {
                    assert!(
                        close(s[k], n[k], 1e-8),
                        "{direction} {} row {k}: symbolic {} vs finite difference {}",
                        model.error_names[i],
                        s[k],
                        n[k]
                    );
                    assert!(close(s[k], ir[6 * i + k], 1e-12));
                }
            }
        }
    }
}

#[test]
fn tables_are_exact_where_the_direction_allows() {
    let names = |direction: &str| {
        let m = machine(direction);
        GainModel::derive(&m, &(0..m.catalogue.len()).collect::<Vec<_>>())
            .atoms
            .names
    };
    let constants = |n: Vec<String>| -> Vec<String> {
        n.into_iter()
            .filter(|a| a.starts_with('√') || a.starts_with('k'))
            .collect()
    };
    assert_eq!(constants(names(DIRECTIONS[0])), ["√2"]);
    assert_eq!(constants(names(DIRECTIONS[1])), ["√3"]);
    // |(1, 2, 3)| = √14 and the projected x' has length √(13/14).
    assert_eq!(constants(names(DIRECTIONS[2])), ["√2", "√7", "√13"]);
    assert_eq!(constants(names(DIRECTIONS[4])), ["√2"]);
    let numeric = constants(names(DIRECTIONS[3]));
    assert!(
        !numeric.is_empty() && numeric.iter().all(|a| a.starts_with('k')),
        "{numeric:?}"
    );
}

#[test]
fn an_exact_frame_keeps_exact_zeros() {
    // The axial error of the inclined B moves the tool along z', which turns with nothing
    // downstream but the tool: its orientation rows are exactly zero, and the 45° frame's
    // entries cancel exactly in the tool frame (no 1e-17 terms).
    let m = machine(DIRECTIONS[0]);
    let ezb = m.error_by_name("EZB").unwrap();
    let model = GainModel::derive(&m, &[ezb]);
    for k in 3..6 {
        assert!(
            model.gains[0][k].is_zero(),
            "row {k}: {:?}",
            model.gains[0][k]
        );
    }
    // In the tool frame, the head's own z' is fixed: EZB is (0, √2/2, √2/2) at every pose.
    let want = ["0", "0.5*√2", "0.5*√2"];
    for (k, want) in want.iter().enumerate() {
        let text = codegen::table::format_poly(&model.gains[0][k], &model.atoms.names, false);
        assert_eq!(text, *want, "row {k}");
    }
}
