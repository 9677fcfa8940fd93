//! Axes that move or turn in negative directions: the symbolic gains are right, and the sign
//! convention the documentation states holds on the exact machine.
//!
//! Two test machines (`tests/machines/`) have negative directions in both chains:
//! `neg-table` (work: X along −x, A about −x, C about −z) and `neg-head` (work: C about −z;
//! tool: X along −x, Z along −z, A head about −x). For random poses (rotary commands across
//! their range, linear commands by the nominal tool-centre-point inverse kinematics) and random
//! kinematic offsets, for every error of the catalogue:
//! - the symbolic first-order gains (`codegen::GainModel`) equal central finite differences of
//!   the exact chain, position and orientation rows, as `tests/all/gains_property.rs` checks for
//!   the built-in machines;
//! - the compiled straight-line program (`codegen::Program`) equals the symbolic gains.
//!
//! And the convention of docs/conventions.md §2: every error is counted along or about the
//! positive coordinate direction, so on an axis of direction `-d` a command `+Δ` moves the
//! chain exactly as the positioning error `−Δ` does, and the correction of a positioning error
//! `e` in the axis's own command units is `+e` (on a `+d` axis it is `−e`).

use codegen::{GainModel, compile};
use model_spec::{AxisKind, Machine, Side, parse_machine};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use simulation::exact::chain_transform;
use simulation::fd::fd_gains;

/// The two test machines with negative directions.
fn machines() -> Vec<Machine> {
    [
        (
            "tests/machines/neg-table.toml",
            include_str!("../machines/neg-table.toml"),
        ),
        (
            "tests/machines/neg-head.toml",
            include_str!("../machines/neg-head.toml"),
        ),
    ]
    .iter()
    .map(|(file, text)| parse_machine(file, text).expect("the test machines are valid"))
    .collect()
}

use crate::common;
use common::gains::{close, pose};

#[test]
fn the_test_machines_have_negative_directions_in_both_chains() {
    let ms = machines();
    let negative = |m: &Machine, side: Side, kind: AxisKind| {
        m.axes
            .iter()
            .filter(|a| a.side == side && a.kind == kind && a.direction.own.negative)
            .map(|a| format!("{}{}", a.name, a.direction))
            .collect::<Vec<_>>()
    };
    assert_eq!(negative(&ms[0], Side::Work, AxisKind::Linear), ["X-x"]);
    assert_eq!(
        negative(&ms[0], Side::Work, AxisKind::Rotary),
        ["A-x", "C-z"]
    );
    assert_eq!(
        negative(&ms[1], Side::Tool, AxisKind::Linear),
        ["X-x", "Z-z"]
    );
    assert_eq!(negative(&ms[1], Side::Tool, AxisKind::Rotary), ["A-x"]);
    assert_eq!(negative(&ms[1], Side::Work, AxisKind::Rotary), ["C-z"]);
}

#[test]
fn symbolic_gains_equal_finite_differences_and_the_compiled_program() {
    let ms = machines();
    let models: Vec<GainModel> = ms
        .iter()
        .map(|m| GainModel::derive(m, &(0..m.catalogue.len()).collect::<Vec<_>>()))
        .collect();
    let programs: Vec<_> = ms.iter().zip(&models).map(|(m, g)| compile(m, g)).collect();
    let mut runner = TestRunner::new(Config {
        cases: 48,
        ..Config::default()
    });
    runner
        .run(&proptest::collection::vec(0.0f64..1.0, 32), |unit| {
            for ((m, model), program) in ms.iter().zip(&models).zip(&programs) {
                let (commands, params) = pose(m, &unit);
                let symbolic = model.evaluate(&commands, &params);
                let numeric = fd_gains(m, &commands, &params, &model.errors);
                let inputs = model.atoms.values(&commands, &params);
                let (mut scratch, mut ir) = (Vec::new(), vec![0.0; program.outputs.len()]);
                program.eval(&inputs, &mut scratch, &mut ir);
                for (i, (s, n)) in symbolic.iter().zip(&numeric).enumerate() {
                    for k in 0..6 {
                        prop_assert!(
                            close(s[k], n[k], 1e-8),
                            "{} {} row {k}: symbolic {} vs finite difference {} at commands {commands:?}",
                            m.name,
                            model.error_names[i],
                            s[k],
                            n[k]
                        );
                        prop_assert!(
                            close(s[k], ir[6 * i + k], 1e-12),
                            "{} {} row {k}: symbolic {} vs compiled {}",
                            m.name,
                            model.error_names[i],
                            s[k],
                            ir[6 * i + k]
                        );
                    }
                }
            }
            Ok(())
        })
        .unwrap();
}

/// The largest difference (mm, or rad for the entries of the rotation) between two chain
/// transforms.
fn distance(a: &simulation::exact::Transform, b: &simulation::exact::Transform) -> f64 {
    (a.to_homogeneous() - b.to_homogeneous()).abs().max()
}

/// The chain transform of the axis `axis` of `m` at `commands` with the error `error` at
/// `value` (every other error zero), default parameters.
fn chain_with(
    m: &Machine,
    commands: &[f64],
    error: &str,
    value: f64,
) -> simulation::exact::Transform {
    let mut errors = vec![0.0; m.catalogue.len()];
    errors[m.error_by_name(error).expect("the error exists")] = value;
    let side = m.catalogue[m.error_by_name(error).unwrap()]
        .axis()
        .map_or(Side::Work, |a| m.axes[a].side);
    chain_transform(m, side, commands, &m.default_parameters(), &errors)
}

/// On every axis: a command `+Δ` moves its chain as its positioning error `s·Δ` does, `s` −1
/// on a negative direction and +1 on a positive one; and commanding `q + c` with the
/// correction `c = −s·e` cancels the positioning error `e` at `q`.
#[test]
fn a_command_and_the_positioning_error_act_along_the_same_coordinate_with_the_sign_of_the_direction()
 {
    let mut checked = Vec::new();
    for m in machines()
        .iter()
        .chain([&model_spec::builtin("seed-ac").unwrap().unwrap()])
    {
        let mut rng = 0x9e37_79b9_7f4a_7c15u64;
        let mut unit = || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 11) as f64 / (1u64 << 53) as f64
        };
        for (i, axis) in m.axes.iter().enumerate() {
            let positioning = match axis.kind {
                AxisKind::Linear => {
                    format!(
                        "E{}{}",
                        axis.direction.own.dir.translation_letter(),
                        axis.name
                    )
                }
                AxisKind::Rotary => {
                    format!("E{}{}", axis.direction.own.dir.rotation_letter(), axis.name)
                }
            };
            let s = if axis.direction.own.negative {
                -1.0
            } else {
                1.0
            };
            let (delta, e) = match axis.kind {
                AxisKind::Linear => (0.05, 0.03),   // mm
                AxisKind::Rotary => (2e-4, 1.5e-4), // rad
            };
            for _ in 0..5 {
                let units: Vec<f64> = (0..32).map(|_| unit()).collect();
                let (q, _) = pose(m, &units);
                let mut moved = q.clone();
                moved[i] += delta;
                // +Δ commanded ≡ the positioning error s·Δ.
                let by_command = chain_with(m, &moved, &positioning, 0.0);
                let by_error = chain_with(m, &q, &positioning, s * delta);
                assert!(
                    distance(&by_command, &by_error) < 1e-12,
                    "{} {}: command +Δ and {positioning} = {}·Δ differ by {:e}",
                    m.name,
                    axis.name,
                    s,
                    distance(&by_command, &by_error)
                );
                // The opposite sign is off by 2Δ: the check can fail.
                let wrong = chain_with(m, &q, &positioning, -s * delta);
                assert!(distance(&by_command, &wrong) > delta);
                // The correction c = −s·e in command units cancels the error e.
                let mut corrected = q.clone();
                corrected[i] += -s * e;
                let compensated = chain_with(m, &corrected, &positioning, e);
                let nominal = chain_with(m, &q, &positioning, 0.0);
                assert!(
                    distance(&compensated, &nominal) < 1e-12,
                    "{} {}: the correction {} of {positioning} = {e} leaves {:e}",
                    m.name,
                    axis.name,
                    -s * e,
                    distance(&compensated, &nominal)
                );
                checked.push(format!("{}{}", axis.name, axis.direction));
            }
        }
    }
    // Every direction sign and kind was exercised.
    for d in ["X-x", "A-x", "C-z", "Z-z", "X+x", "Y+y"] {
        assert!(checked.iter().any(|c| c == d), "{d} not checked");
    }
}
