//! The whole loop on the exact virtual machine: identify on K4, compensate paths, run the
//! compensated commands through the exact machine with the true errors.
//!
//! - Demo truth (its extended model explains the data): with the model the diagnosis
//!   recommends, the error RMS of K1, K2, K4 and a random five-axis path falls by at least
//!   90 %.
//! - Full-budget truth (the reduced model cannot explain the data): the compensated error RMS
//!   on the paths not fitted is no larger than the validated residual RMS of the model used
//!   (those paths without noise and reading drift), plus 10 %.
//!
//! The machine's error is measured without the ball's set-up error: where the ball sits on
//! the table is not the machine's doing, and compensation leaves it alone.

use crate::one_record::{identify_refined_one, validate_one};
use crate::one_report::{IdentificationSource, report_of_one};
use compensation::run::{CommandedPose, compensate_poses};
use compensation::values::MachineErrors;
use compensation::verify::machine_error_rms;
use diagnosis::{DiagnoseOptions, diagnose, one_record};
use fitting::{IdentifyOptions, RefineOptions, ValidateOptions};
use formats::progress::Unwatched;
use formats::truth::builtin_truth;
use model_spec::basis::BasisContext;
use model_spec::{Machine, builtin};
use report::json::read::parse_identification;
use report::json::to_json;
use simulation::exact::VirtualMachine;
use simulation::model::{Effect, Model};
use simulation::record::Record;
use simulation::rng::Rng;
use simulation::{Truth, builtin_path, simulate};

/// Poses with the kinematic parameters of each (the workpiece point varies on a random path).
type Poses = Vec<(Vec<f64>, Vec<f64>)>;

/// The paths of the seed, simulated with `truth` (different noise seeds).
fn records(m: &Machine, truth: &Truth) -> Vec<(&'static str, Record)> {
    ["K4", "K1", "K2"]
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let mut t = truth.clone();
            t.seed = truth.seed.wrapping_add(i as u64);
            let path = builtin_path(m, name).unwrap().unwrap();
            (*name, simulate(m, &t, &path).unwrap())
        })
        .collect()
}

/// The identification of `model` on `record`, as `identify --json` writes it and
/// `compensate` reads it back.
fn identified(m: &Machine, model: &Model, record: &Record) -> MachineErrors {
    let (ident, refinement) = identify_refined_one(
        m,
        model,
        record,
        &IdentifyOptions::default(),
        &RefineOptions::default(),
    )
    .unwrap();
    let report = report_of_one(
        m,
        IdentificationSource {
            data: "k4.csv",
            label: "test",
            base_model: None,
        },
        &ident,
        Some(&refinement),
    )
    .unwrap();
    let json = to_json(&report).unwrap();
    let values = parse_identification("identify.json", &json, m).unwrap();
    MachineErrors::from_values(m, &values.values, &values.file)
        .unwrap()
        .0
}

/// A random five-axis path of `n` poses: random A and C within their ranges (|A| ≥ 10°), a
/// random workpiece point on the table, the linear axes on it.
fn random_path(m: &Machine, n: usize, seed: u64) -> Poses {
    let vm = VirtualMachine::new(m);
    let mut rng = Rng::new(seed);
    let mut out = Vec::new();
    while out.len() < n {
        let mut params = m.default_parameters();
        for name in ["Xw", "Yw", "Zw"] {
            let s = m.symbol_by_name(name).unwrap();
            params[s] += rng.uniform_in(-80.0, 80.0);
        }
        let mut q = vec![0.0; m.axes.len()];
        for a in m.rotary_axes() {
            let [lo, hi] = m.axes[a].limits;
            let mut v = rng.uniform_in(lo.max(-180.0), hi.min(180.0));
            if v.abs() < 10.0 {
                v = 10.0_f64.copysign(v);
            }
            q[a] = v.to_radians();
        }
        if vm.tool_centre_point_ik(&mut q, &params).is_ok() && m.check_pose(&q).is_ok() {
            out.push((q, params));
        }
    }
    out
}

/// The compensated commands of one pose `q` with kinematic parameters `params`.
fn compensated(m: &Machine, errors: &MachineErrors, q: &[f64], params: &[f64]) -> Vec<f64> {
    let commanded = [CommandedPose {
        line: 1,
        commands: q.to_vec(),
    }];
    let values_at = |c: &[f64], out: &mut [f64]| errors.values_at(m, c, out);
    compensate_poses(
        m,
        errors.errors(),
        params.to_vec(),
        "test",
        &commanded,
        &values_at,
    )
    .unwrap()
    .poses
    .remove(0)
}

/// Error RMS (mm, over the three directions as `validate` reports it) of poses (with their
/// parameters) on the exact machine, before and after compensation.
fn before_after(
    m: &Machine,
    truth: &Truth,
    errors: &MachineErrors,
    poses: &[(Vec<f64>, Vec<f64>)],
) -> (f64, f64) {
    let corrected: Vec<Vec<f64>> = poses
        .iter()
        .map(|(q, params)| compensated(m, errors, q, params))
        .collect();
    let before: Vec<(&[f64], &[f64])> = poses
        .iter()
        .map(|(q, p)| (q.as_slice(), p.as_slice()))
        .collect();
    let after: Vec<(&[f64], &[f64])> = corrected
        .iter()
        .zip(poses)
        .map(|(q, (_, p))| (q.as_slice(), p.as_slice()))
        .collect();
    (
        machine_error_rms(m, truth, &before),
        machine_error_rms(m, truth, &after),
    )
}

fn path_poses(m: &Machine, r: &Record) -> Poses {
    r.samples
        .iter()
        .map(|s| (s.commands.clone(), m.default_parameters()))
        .collect()
}

#[test]
fn demo_truth_error_falls_by_ninety_percent() {
    let m = builtin("seed-ac").unwrap().unwrap();
    let truth = builtin_truth("seed-ac-demo", &m).unwrap().unwrap();
    let recs = records(&m, &truth);
    let reduced = Model::of(&m, "reduced").unwrap();
    let held: Vec<(String, Record)> = recs[1..]
        .iter()
        .map(|(n, r)| (n.to_string(), r.clone()))
        .collect();
    let (fitted, held) = one_record(
        recs[0].0,
        recs[0].1.clone(),
        held,
        m.default_parameters(),
        false,
    )
    .unwrap();
    let diagnosis = diagnose(
        &m,
        &reduced,
        &fitted,
        &held,
        &DiagnoseOptions::default(),
        &Unwatched,
    )
    .unwrap();
    assert!(
        diagnosis.recommendation.recommended,
        "the diagnosis recommends its extension on the demo truth"
    );
    let model = diagnosis.extended_terms();
    let errors = identified(&m, &model, &recs[0].1);
    let mut paths: Vec<(&str, Poses)> = recs.iter().map(|(n, r)| (*n, path_poses(&m, r))).collect();
    paths.push(("random", random_path(&m, 60, 11)));
    for (name, poses) in &paths {
        let (before, after) = before_after(&m, &truth, &errors, poses);
        let fall = 1.0 - after / before;
        eprintln!(
            "demo truth, {name}: error RMS {:.3} µm before, {:.4} µm after: {:.1} % less",
            before * 1e3,
            after * 1e3,
            fall * 100.0
        );
        assert!(
            fall >= 0.9,
            "{name}: the error fell by {:.1} %",
            fall * 100.0
        );
    }
}

/// The R-test's view of the compensated machine on `poses`: the exact error vector with the
/// whole truth (the ball where it really is) minus the ball's set-up as identified (its
/// predicted contribution at each pose): RMS, mm. This is what a second measurement with the
/// compensated commands, read against the identified set-up, shows; to first order it is the
/// validation residual of the model, noise aside. RMS over the three directions.
fn rtest_view(
    m: &Machine,
    truth: &Truth,
    errors: &MachineErrors,
    setup: &[(usize, f64)],
    poses: &Poses,
) -> f64 {
    let vm = VirtualMachine::new(m);
    let ids: Vec<usize> = setup.iter().map(|&(e, _)| e).collect();
    let gains = codegen::GainModel::derive(m, &ids);
    let motion = vec![1i8; m.axes.len()];
    let mut sum = 0.0;
    for (q, params) in poses {
        let qc = &compensated(m, errors, q, params);
        let cx = BasisContext {
            commands: qc,
            motion: &motion,
            tau: 0.0,
            elapsed_s: 0.0,
            since_start_s: 0.0,
            velocity: &[],
            reading: [0.0; 3],
        };
        let e = vm.error_vector(qc, params, &truth.error_values(m, &cx));
        let g = gains.evaluate(qc, params);
        let mut r = e.position;
        for (gi, &(_, v)) in g.iter().zip(setup) {
            for k in 0..3 {
                r[k] -= gi[k] * v;
            }
        }
        sum += r.norm_squared();
    }
    (sum / (3.0 * poses.len() as f64)).sqrt()
}

#[test]
fn budget_truth_compensated_within_the_validated_residual() {
    let m = builtin("seed-ac").unwrap().unwrap();
    let truth = builtin_truth("seed-ac-budget", &m).unwrap().unwrap();
    let recs = records(&m, &truth);
    let model = Model::of(&m, "reduced").unwrap();
    let errors = identified(&m, &model, &recs[0].1);
    let (ident, _) = identify_refined_one(
        &m,
        &model,
        &recs[0].1,
        &IdentifyOptions::default(),
        &RefineOptions::default(),
    )
    .unwrap();
    let setup: Vec<(usize, f64)> = ["XOW", "YOW", "ZOW"]
        .iter()
        .map(|n| {
            let i = ident.fit.names.iter().position(|x| x == n).unwrap();
            (m.error_by_name(n).unwrap(), ident.fit.values[i].unwrap())
        })
        .collect();
    // The paths not fitted as validated without the noise and the drift of the R-test's zero:
    // the compensated machine shows neither, and a drift from the start of a record has a mean
    // that the validated residual would carry.
    let mut quiet = truth.clone();
    quiet.noise_mm = 0.0;
    for (k, (t, _)) in truth.model.columns().into_iter().enumerate() {
        if matches!(truth.model.terms[t].effect, Effect::SensorOffset(_)) {
            quiet.coefficients[k] = 0.0;
        }
    }
    let quiet_recs = records(&m, &quiet);
    for (name, r) in &quiet_recs[1..] {
        let v = validate_one(
            &m,
            &ident.model,
            &ident.fit.values,
            r,
            false,
            &ValidateOptions::new().exact(true),
        )
        .unwrap();
        let residual = v.overall.residual_rms;
        let poses = path_poses(&m, r);
        let seen = rtest_view(&m, &truth, &errors, &setup, &poses);
        let (before, machine) = before_after(&m, &truth, &errors, &poses);
        eprintln!(
            "budget truth, {name}: validated residual RMS {:.3} µm; compensated, as the R-test sees it {:.3} µm; the machine's own error {:.3} µm before, {:.3} µm after",
            residual * 1e3,
            seen * 1e3,
            before * 1e3,
            machine * 1e3
        );
        assert!(
            seen <= 1.1 * residual,
            "{name}: compensated {seen:e} mm against the validated residual {residual:e} mm"
        );
    }
}
