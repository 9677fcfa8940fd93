//! The engine on long chains: synthetic machines with 6 and 12 rotary axes
//! (`codegen/tests/all/support/chains.rs`: a serial arm on the tool side after X, Y and Z slides, a
//! table stack on the work side, directions x, z, y and an inclined one in turn, every offset
//! a kinematic symbol), whose gains are written over named intermediates.
//!
//! At random on-ball poses (rotary commands across ±180°, linear commands by the nominal
//! tool-centre-point inverse kinematics) and random kinematic offsets:
//! - the gains of every error equal central finite differences of the exact, untruncated chain
//!   (`simulation::fd::fd_gains`), position and orientation rows;
//! - the compiled program (in-process evaluator) equals the symbolic gains;
//! - a gain the engine made an exact zero is zero in the compiled program (a literal `0`, not
//!   a computed value), and zero in the exact chain.

use codegen::ir::Output;
use codegen::{GainModel, compile};
use proptest::test_runner::{Config, TestRunner};

#[path = "../../codegen/tests/all/support/chains.rs"]
mod chains;
use crate::common;
use common::gains::{close, pose};

fn check(rotary: usize, cases: u32) {
    let m = chains::synthetic(rotary, true);
    let errors: Vec<usize> = (0..m.catalogue.len()).collect();
    let model = GainModel::derive(&m, &errors);
    assert!(
        !model.intermediates().is_empty(),
        "{}: a chain this long names intermediates",
        m.name
    );
    let program = compile(&m, &model);
    let shared = model.gains.shared();
    for (i, row) in shared.iter().enumerate() {
        for (k, g) in row.iter().enumerate() {
            if g.is_zero() {
                assert_eq!(
                    program.outputs[6 * i + k],
                    Output::Const(0.0),
                    "{} {} row {k}: an exact zero is a literal zero",
                    m.name,
                    model.error_names[i]
                );
            }
        }
    }
    let mut runner = TestRunner::new(Config {
        cases,
        ..Config::default()
    });
    runner
        .run(&proptest::collection::vec(0.0f64..1.0, 64), |unit| {
            let (commands, params) = pose(&m, &unit);
            let symbolic = model.evaluate(&commands, &params);
            let numeric = simulation::fd::fd_gains(&m, &commands, &params, &errors);
            let inputs = model.atoms.values(&commands, &params);
            let mut ir = vec![0.0; program.outputs.len()];
            program.eval(&inputs, &mut Vec::new(), &mut ir);
            for (i, (s, n)) in symbolic.iter().zip(&numeric).enumerate() {
                for k in 0..6 {
                    proptest::prop_assert!(
                        close(s[k], n[k], 1e-8),
                        "{} {} row {k}: symbolic {} vs finite difference {} at {commands:?}",
                        m.name,
                        model.error_names[i],
                        s[k],
                        n[k]
                    );
                    proptest::prop_assert!(
                        close(s[k], ir[6 * i + k], 1e-11),
                        "{} {} row {k}: symbolic {} vs compiled {}",
                        m.name,
                        model.error_names[i],
                        s[k],
                        ir[6 * i + k]
                    );
                    if shared[i][k].is_zero() {
                        proptest::prop_assert!(
                            n[k].abs() < 1e-9,
                            "{} {} row {k}: an exact zero, but the exact chain gives {}",
                            m.name,
                            model.error_names[i],
                            n[k]
                        );
                    }
                }
            }
            Ok(())
        })
        .unwrap();
}

#[test]
fn six_rotary_axes_equal_finite_differences_and_the_compiled_program() {
    check(6, 16);
}

#[test]
fn twelve_rotary_axes_equal_finite_differences_and_the_compiled_program() {
    check(12, 8);
}
