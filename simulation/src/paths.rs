//! Test paths: the tests of a machine ([`crate::generator`]: `turn-C`, `pair-A-C`,
//! …, and the seed's `K1`, `K2`, `K4` on machines whose rotary axes are A and C), paths for any
//! machine from a CSV file, and the nominal tool-centre-point inverse kinematics that fills the
//! linear commands.
//!
//! The seed's paths (docs/conventions.md; the seed's sample counts, ISO 10791-6 style), sample
//! `i`:
//! - `K1`: `C = i°`, `A = 0°`, `i = 0…360` (361 samples);
//! - `K2`: `A = (−90 + i)°`, `C = 0°`, `i = 0…120` (121 samples);
//! - `K4`: `C = 1.5·i°`, `A = −45·(1 − cos C)°`, `i = 0…240` (241 samples; all five axes move).
//!
//! A built-in path is its test generated with the default options at the machine's default
//! kinematic parameters (what the controller believes): the rotary commands are computed in
//! degrees and converted with `to_radians()`; the linear axes follow the ball by the nominal
//! tool-centre-point inverse kinematics
//! ([`crate::exact::VirtualMachine::tool_centre_point_ik`]); every sample is checked
//! against the strokes, the ranges and the clearance rule. Sample `i` is taken at
//! `t = i·`[`SAMPLE_PERIOD_S`] (1 s): the R-test samples at rest after each step, so only the
//! order of the samples matters for `time:K` effects, which are normalised over the record.
//! Directions of motion come from [`crate::record::motion_directions`].
//!
//! Path files (a CSV in the measurement format) are read by `formats::paths`.

use crate::exact::{ExactError, VirtualMachine};
use crate::generator::{self, GeneratorError, GeneratorOptions};
use crate::record::{Record, motion_directions, samples_from};
use model_spec::Machine;

/// Time between two samples of the built-in paths, s.
pub const SAMPLE_PERIOD_S: f64 = 1.0;

/// Names of the seed's paths (matched without regard to case), on machines whose rotary axes
/// are A and C.
pub const BUILTIN_PATHS: [&str; 3] = generator::SEED_TESTS;

/// Why a built-in path could not be made.
#[derive(Debug, thiserror::Error)]
pub enum PathError {
    /// One of the seed's paths asked of a machine whose rotary axes are not A and C.
    #[error(
        "path {path} is defined only for machines whose rotary axes are A and C (like seed-ac); machine {machine} has {has}: {instead}"
    )]
    NotAC {
        /// The path.
        path: String,
        /// The machine.
        machine: String,
        /// What rotary axes it has (`rotary axes B, C`, `no rotary axes`).
        has: String,
        /// What to use instead (`its tests are turn-B, turn-C, pair-B-C`).
        instead: String,
    },
    /// A test of the machine that cannot be generated.
    #[error("path {path}: {source}")]
    Generator {
        /// The path.
        path: String,
        /// Why.
        source: GeneratorError,
    },
}

/// The built-in path `name` (a test of `m`: `K1`, `K2`, `K4`, `turn-C`, `pair-A-C`, …, any
/// case) generated with the default options at the machine's default kinematic parameters;
/// `None` when `name` is none of them.
///
/// # Errors
/// [`PathError::NotAC`] for a seed path on a machine whose rotary axes are not A and C;
/// [`PathError::Generator`] when a sample cannot be generated within the machine's limits.
pub fn builtin_path(m: &Machine, name: &str) -> Option<Result<Record, PathError>> {
    let upper = name.trim().to_ascii_uppercase();
    let tests = generator::tests(m);
    let Some(spec) = generator::lookup_test(&tests, name) else {
        return BUILTIN_PATHS
            .contains(&upper.as_str())
            .then(|| Err(not_ac(m, &upper, &tests)));
    };
    Some(
        generator::generate_test(
            m,
            &spec,
            &m.default_parameters(),
            &GeneratorOptions::default(),
        )
        .map_err(|source| PathError::Generator {
            path: spec.name.clone(),
            source,
        }),
    )
}

/// The names of `tests`, comma-separated, or why there are none.
pub fn test_names(tests: &[generator::TestSpec]) -> String {
    if tests.is_empty() {
        "no tests: it has no rotary axis".to_string()
    } else {
        tests
            .iter()
            .map(|t| t.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    }
}

fn not_ac(m: &Machine, name: &str, tests: &[generator::TestSpec]) -> PathError {
    let mut has: Vec<&str> = m.rotary_axes().map(|i| m.axes[i].name.as_str()).collect();
    has.sort_by_key(|n| model_spec::catalogue::iso_rank(n));
    PathError::NotAC {
        path: name.to_string(),
        machine: m.name.clone(),
        has: if has.is_empty() {
            "no rotary axes".into()
        } else {
            format!("rotary axes {}", has.join(", "))
        },
        instead: if tests.is_empty() {
            "give the path as a CSV file".into()
        } else {
            format!(
                "its tests are {}, or give the path as a CSV file",
                test_names(tests)
            )
        },
    }
}

/// Fills the linear entries (mm) of every command vector by the nominal tool-centre-point
/// inverse kinematics of `m` with kinematic parameters `params` (mm), keeping the rotary
/// entries (rad). The chains are lowered once.
///
/// # Errors
/// The index of the first sample where the inverse kinematics fails, and why; the commands
/// before it are filled, the others unchanged.
///
/// # Panics
/// When a command vector is not one per axis, or `params` not one per symbol.
pub fn fill_linear_ik(
    m: &Machine,
    params: &[f64],
    commands: &mut [Vec<f64>],
) -> Result<(), (usize, ExactError)> {
    let vm = VirtualMachine::new(m);
    for (i, q) in commands.iter_mut().enumerate() {
        vm.tool_centre_point_ik(q, params).map_err(|e| (i, e))?;
    }
    Ok(())
}

/// A record without measurements from commands (mm, rad; one vector per sample) and times (s):
/// directions of motion by [`motion_directions`].
///
/// # Panics
/// When `times` is not one per sample.
pub fn record_from_commands(commands: Vec<Vec<f64>>, times: Vec<f64>) -> Record {
    assert_eq!(commands.len(), times.len(), "one time per sample");
    let motion = motion_directions(&commands);
    Record {
        samples: samples_from(commands, times, motion),
        ..Default::default()
    }
}
