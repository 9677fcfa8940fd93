//! The slice helpers check their lengths and say which one is wrong.

use generated::seed_ac::{PARAMETERS, POSE_INPUTS, Params, Pose, reduced};

fn inputs() -> (Vec<f64>, Vec<f64>) {
    (vec![0.5; POSE_INPUTS.len()], vec![1.0; PARAMETERS.len()])
}

#[test]
fn right_lengths_equal_the_struct_functions() {
    let (pose, params) = inputs();
    let mut flat = vec![0.0; 6 * reduced::N];
    reduced::gains_slice(&pose, &params, &mut flat);
    let mut rows = [[0.0; 6]; reduced::N];
    reduced::gains(
        &Pose::from_slice(&pose),
        &Params::from_slice(&params),
        &mut rows,
    );
    assert_eq!(flat, rows.concat());
    let mut position = vec![0.0; 3 * reduced::N];
    reduced::position_gains_slice(&pose, &params, &mut position);
    for d in 0..3 {
        for i in 0..reduced::N {
            assert_eq!(position[d * reduced::N + i], rows[i][d]);
        }
    }
}

#[test]
#[should_panic(expected = "Pose::from_slice: one value per pose input")]
fn a_short_pose_panics() {
    let _ = Pose::from_slice(&[0.0; 3]);
}

#[test]
#[should_panic(expected = "Params::from_slice: one value per parameter")]
fn a_long_parameter_slice_panics() {
    let _ = Params::from_slice(&vec![0.0; PARAMETERS.len() + 1]);
}

#[test]
#[should_panic(expected = "gains_slice: `out` holds 6 * N gains")]
fn a_wrong_output_length_panics() {
    let (pose, params) = inputs();
    reduced::gains_slice(&pose, &params, &mut vec![0.0; 6 * reduced::N - 1]);
}

#[test]
#[should_panic(expected = "position_gains_slice: `out` holds 3 * N gains")]
fn a_wrong_position_output_length_panics() {
    let (pose, params) = inputs();
    reduced::position_gains_slice(&pose, &params, &mut vec![0.0; 6 * reduced::N]);
}
