//! The symbolic gains are right, and every way of evaluating them agrees.
//!
//! For random poses (rotary commands across their range, linear commands by the nominal
//! tool-centre-point inverse kinematics, so the tool point is on the ball as in every R-test
//! sample) and random kinematic offsets, for every error of every built-in machine:
//! - the symbolic first-order gains equal central finite differences of the exact, untruncated
//!   HTM chain (exact small rotations), position and orientation rows alike;
//! - the straight-line IR evaluated in-process equals the symbolic gains;
//! - the compiled code of the `generated` crate equals the IR evaluator, for every model.

use codegen::{GainModel, compile};
use model_spec::all_builtin;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

use crate::common;
use common::gains::{close, pose};

#[test]
fn symbolic_gains_equal_finite_differences_of_the_exact_chain() {
    let machines = all_builtin();
    let models: Vec<GainModel> = machines
        .iter()
        .map(|m| GainModel::derive(m, &(0..m.catalogue.len()).collect::<Vec<_>>()))
        .collect();
    let mut runner = TestRunner::new(Config {
        cases: 48,
        ..Config::default()
    });
    runner
        .run(&proptest::collection::vec(0.0f64..1.0, 32), |unit| {
            for (m, model) in machines.iter().zip(&models) {
                let (commands, params) = pose(m, &unit);
                let symbolic = model.evaluate(&commands, &params);
                let numeric = simulation::fd::fd_gains(m, &commands, &params, &model.errors);
                for (i, (s, n)) in symbolic.iter().zip(&numeric).enumerate() {
                    for k in 0..6 {
                        prop_assert!(
                            close(s[k], n[k], 1e-8),
                            "{} {} row {k}: symbolic {} vs finite difference {} at commands {commands:?}",
                            m.name, model.error_names[i], s[k], n[k]
                        );
                    }
                }
            }
            Ok(())
        })
        .unwrap();
}

#[test]
fn evaluator_and_compiled_code_equal_the_symbolic_gains_for_every_model() {
    let mut runner = TestRunner::new(Config {
        cases: 64,
        ..Config::default()
    });
    let machines = all_builtin();
    let mut checked = 0;
    for m in &machines {
        for name in m.model_names() {
            let model = GainModel::derive(m, m.model_errors(name).unwrap());
            let program = compile(m, &model);
            let compiled = generated::lookup(&m.name, name)
                .unwrap_or_else(|| panic!("{} {name} is compiled in", m.name));
            assert_eq!(compiled.errors, model.error_names.as_slice());
            assert_eq!(compiled.operations, program.op_counts().total());
            runner
                .run(&proptest::collection::vec(0.0f64..1.0, 32), |unit| {
                    let (commands, params) = pose(m, &unit);
                    let symbolic = model.evaluate(&commands, &params);
                    let inputs = model.atoms.values(&commands, &params);
                    let (mut scratch, mut ir) = (Vec::new(), vec![0.0; program.outputs.len()]);
                    program.eval(&inputs, &mut scratch, &mut ir);
                    let n_pose = compiled.pose_inputs.len();
                    let mut native = vec![0.0; program.outputs.len()];
                    (compiled.gains)(&inputs[..n_pose], &inputs[n_pose..], &mut native);
                    let n = model.errors.len();
                    let mut position = vec![0.0; 3 * n];
                    (compiled.position_gains)(&inputs[..n_pose], &inputs[n_pose..], &mut position);
                    for i in 0..n {
                        for d in 0..3 {
                            prop_assert!(
                                close(position[d * n + i], native[6 * i + d], 1e-13),
                                "{} {}: position gains {} vs gains {}",
                                m.name,
                                model.error_names[i],
                                position[d * n + i],
                                native[6 * i + d]
                            );
                        }
                    }
                    for (i, row) in symbolic.iter().enumerate() {
                        for (k, &s) in row.iter().enumerate() {
                            let j = 6 * i + k;
                            prop_assert!(
                                close(s, ir[j], 1e-12),
                                "{} {name} {} row {k}: symbolic {} vs IR {}",
                                m.name,
                                model.error_names[i],
                                s,
                                ir[j]
                            );
                            prop_assert_eq!(
                                ir[j].to_bits(),
                                native[j].to_bits(),
                                "{} {}: IR and compiled code differ",
                                m.name,
                                name
                            );
                        }
                    }
                    Ok(())
                })
                .unwrap();
            checked += 1;
        }
    }
    assert_eq!(
        checked,
        generated::MODELS.len(),
        "every compiled model was checked"
    );
}
