//! Fills the position rows of the full seed-ac H matrix for N poses (the first argument) with the
//! generated code, sines and cosines included; `method` (second argument) picks the code:
//! `position` (the generated `position_gains`), `gains` (the generated `gains`, six rows),
//! `evaluator` (the IR evaluator), `first-order` (the runtime first-order product).
//! For instruction counts: run under `valgrind --tool=callgrind` with two N and divide the
//! difference (BENCHMARKS.md).

use generated::seed_ac::{Params, full};
use std::hint::black_box;

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(1000);
    let method = std::env::args().nth(2).unwrap_or_else(|| "position".into());
    let m = model_spec::builtin("seed-ac").unwrap().unwrap();
    let errors = m.model_errors("full").unwrap().to_vec();
    let model = codegen::GainModel::derive(&m, &errors);
    let program = codegen::compile(&m, &model);
    let chain = perf::first_order::FirstOrderChain::new(&m, &errors);
    let params = Params::default();
    let defaults = m.default_parameters();
    let mut rows = [[0.0; full::N]; 3];
    let mut six = [[0.0; 6]; full::N];
    let (mut scratch, mut flat) = (Vec::new(), vec![0.0; 6 * full::N]);
    let mut d = vec![[0.0; 6]; full::N];
    for i in 0..n {
        let (pose, commands) = perf::sweep_pose(i as f64 * 1e-3);
        match method.as_str() {
            "position" => full::position_gains(black_box(&pose), &params, &mut rows),
            "gains" => full::gains(black_box(&pose), &params, &mut six),
            "evaluator" => {
                let inputs = model.atoms.values(&commands, &defaults);
                program.eval(&inputs, &mut scratch, &mut flat);
            }
            "first-order" => chain.gains(&commands, &defaults, &mut d),
            other => panic!("unknown method {other}"),
        }
        black_box((&rows, &six, &flat, &d));
    }
}
