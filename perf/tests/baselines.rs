//! The four ways to compute the gains agree: (a) the generated code,
//! (b) the in-process IR evaluator, (c) the exact HTM chain with central finite differences,
//! (d) the runtime first-order product of the chain without code generation.

use codegen::{GainModel, compile};
use model_spec::AxisKind;
use perf::first_order::FirstOrderChain;
use simulation::exact::tool_centre_point_ik;
use simulation::fd::fd_gains;
use simulation::rng::Rng;

#[test]
fn generated_evaluator_finite_differences_and_first_order_product_agree() {
    let mut rng = Rng::new(5);
    for m in model_spec::all_builtin() {
        let errors = m.model_errors("full").unwrap().to_vec();
        let model = GainModel::derive(&m, &errors);
        let program = compile(&m, &model);
        let compiled = generated::lookup(&m.name, "full").unwrap();
        let chain = FirstOrderChain::new(&m, &errors);
        for _ in 0..20 {
            let params: Vec<f64> = m
                .symbols
                .iter()
                .map(|s| s.default + rng.uniform_in(-50.0, 50.0))
                .collect();
            let mut commands: Vec<f64> = m
                .axes
                .iter()
                .map(|a| match a.kind {
                    AxisKind::Rotary => rng.uniform_in(-3.0, 3.0),
                    AxisKind::Linear => 0.0,
                })
                .collect();
            tool_centre_point_ik(&m, &mut commands, &params).unwrap();
            let inputs = model.atoms.values(&commands, &params);
            let n_pose = compiled.pose_inputs.len();
            let mut a = vec![0.0; 6 * errors.len()];
            (compiled.gains)(&inputs[..n_pose], &inputs[n_pose..], &mut a);
            let mut b = vec![0.0; 6 * errors.len()];
            program.eval(&inputs, &mut Vec::new(), &mut b);
            let c = fd_gains(&m, &commands, &params, &errors);
            let mut d = vec![[0.0; 6]; errors.len()];
            chain.gains(&commands, &params, &mut d);
            for i in 0..errors.len() {
                for k in 0..6 {
                    let x = a[6 * i + k];
                    let scale = 1.0 + x.abs();
                    let name = &m.catalogue[errors[i]].name;
                    assert_eq!(
                        x.to_bits(),
                        b[6 * i + k].to_bits(),
                        "{} {name}: generated vs evaluator",
                        m.name
                    );
                    assert!(
                        (x - d[i][k]).abs() < 1e-12 * scale,
                        "{} {name} row {k}: generated {x} vs first-order product {}",
                        m.name,
                        d[i][k]
                    );
                    assert!(
                        (x - c[i][k]).abs() < 1e-8 * scale,
                        "{} {name} row {k}: generated {x} vs finite differences {}",
                        m.name,
                        c[i][k]
                    );
                }
            }
        }
    }
}
