//! Simulated R-test readings: the exact virtual machine run with a [`Truth`] along a path.
//!
//! At every sample `i` of the path, with commands `q` (mm, rad), directions of motion,
//! normalised time `τ = record.tau(i)`, time since the first sample, the sample's time `t`
//! itself (the time since the start of `rate` and `warmup:TAU`: the path's `t = 0`) and (for
//! `velocity` terms) the axis velocities of [`Record::velocities`] — the [`BasisContext`] the H
//! matrix uses too:
//! 1. the truth gives every catalogue error's value and the sensor zero offsets
//!    ([`Truth::evaluate_into`]);
//! 2. the exact chains (no linearisation) with the truth's kinematic parameters give the error
//!    vector's position part `R_tool^T·(P_tool − P_work)` (mm, tool frame, tool minus
//!    workpiece; [`crate::exact::ErrorVector::position`]); it includes any nominal mismatch the
//!    path leaves, e.g. when the truth's kinematic parameters differ from the defaults the path
//!    was planned with;
//! 3. the instrument terms act on that displacement `d`: the reading is `(I + S)·d`
//!    ([`Truth::instrument`]); the offsets `dx0 dy0 dz0` are added, then Gaussian noise of
//!    marginal standard deviation σ = `truth.noise_mm` per direction, from standard normal
//!    draws `n_t` of [`Rng::new`]`(truth.seed)` in sample order, x, y, z (no draws when the
//!    noise is zero): an AR(1) process of lag-1 autocorrelation φ = `truth.noise_phi` per
//!    direction, stationary from the first sample, `e_0 = σ·n_0`, `e_t = φ·e_{t−1} +
//!    σ·√(1−φ²)·n_t`; with φ = 0 it is white, `e_t = σ·n_t`, the same draws as before AR(1)
//!    noise existed;
//! 4. when `truth.zeroed`, the first reading is subtracted from every reading (the first is
//!    then exactly zero), as R-test software does.

use crate::exact::VirtualMachine;
use crate::model::{Basis, BasisContext};
use crate::record::Record;
use crate::rng::Rng;
use crate::truth::Truth;
use model_spec::{Machine, Side};

/// A record or truth that does not fit the machine (programming errors, reported, not panics).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SimulateError {
    /// A sample's commands or directions are not one per axis.
    #[error(
        "machine {machine}: sample {sample} has {commands} commands and {motion} directions of motion, the machine has {axes} axes"
    )]
    Sample {
        /// The machine.
        machine: String,
        /// The sample (0-based).
        sample: usize,
        /// Its number of commands.
        commands: usize,
        /// Its number of directions of motion.
        motion: usize,
        /// The machine's number of axes.
        axes: usize,
    },
    /// The truth has `velocity`, `exp:TAU`, `rate` or `warmup:TAU` terms and the path has no
    /// real times (or too few samples, or equal times, for velocities; or, for a warm-up, a
    /// sample before time 0).
    #[error("truth {source_name}: {why}")]
    Times {
        /// The truth's source.
        source_name: String,
        /// What is missing.
        why: String,
    },
    /// The truth was made for another machine.
    #[error("truth {source_name} does not fit machine {machine}: {why}")]
    Truth {
        /// The truth's source.
        source_name: String,
        /// The machine.
        machine: String,
        /// What does not fit.
        why: String,
    },
}

/// The readings an R-test would give on the virtual machine `m` with truth `truth` along
/// `path` (see the module documentation). The result has the path's samples and one measured
/// vector per sample (mm, tool frame, tool minus workpiece). Any measurements `path` carries
/// are ignored.
///
/// # Errors
/// [`SimulateError`] when a sample or the truth does not fit `m`, or the truth needs real times
/// the path lacks.
pub fn simulate(m: &Machine, truth: &Truth, path: &Record) -> Result<Record, SimulateError> {
    check(m, truth, path)?;
    let times_err = |e: crate::record::TimesError| SimulateError::Times {
        source_name: truth.source.clone(),
        why: e.0,
    };
    if let Some(t) = truth.model.terms.iter().find(|t| t.basis.needs_times()) {
        path.check_times(&t.spelling(m)).map_err(times_err)?;
    }
    if let Some(t) = truth.model.terms.iter().find(|t| t.basis.starts_at_zero()) {
        path.check_started(&t.spelling(m)).map_err(times_err)?;
    }
    let n_axes = m.axes.len();
    let velocities = match truth
        .model
        .terms
        .iter()
        .find(|t| t.basis == Basis::Velocity)
    {
        Some(t) => path.velocities(&t.spelling(m), n_axes).map_err(times_err)?,
        None => Vec::new(),
    };
    let gain = truth.instrument();
    let vm = VirtualMachine::new(m);
    let params = &truth.params;
    let mut errors = vec![0.0; m.catalogue.len()];
    let mut offsets = [0.0; 3];
    let mut rng = Rng::new(truth.seed);
    let noise = truth.noise_mm;
    let phi = truth.noise_phi;
    let innovation = noise * (1.0 - phi * phi).sqrt();
    let mut previous = [0.0; 3];
    let mut measured = Vec::with_capacity(path.samples.len());
    for (i, s) in path.samples.iter().enumerate() {
        let cx = BasisContext {
            commands: &s.commands,
            motion: &s.motion,
            tau: path.tau(i),
            elapsed_s: path.elapsed_s(i),
            since_start_s: s.t,
            velocity: velocities.get(i * n_axes..(i + 1) * n_axes).unwrap_or(&[]),
            reading: [0.0; 3],
        };
        truth.evaluate_into(m, &cx, &mut errors, &mut offsets);
        let value = |id: usize| errors[id];
        let tool = vm.transform_with(Side::Tool, &s.commands, params, &value);
        let work = vm.transform_with(Side::Work, &s.commands, params, &value);
        let gap = tool.translation.vector - work.translation.vector;
        let p = tool.rotation.inverse_transform_vector(&gap);
        let d = [p.x, p.y, p.z];
        let read = |k: usize| d[k] + (0..3).map(|j| gain[k][j] * d[j]).sum::<f64>() + offsets[k];
        let mut r = [read(0), read(1), read(2)];
        if noise > 0.0 {
            for (v, e) in r.iter_mut().zip(&mut previous) {
                *e = if i == 0 || phi == 0.0 {
                    noise * rng.normal()
                } else {
                    phi * *e + innovation * rng.normal()
                };
                *v += *e;
            }
        }
        measured.push(r);
    }
    if truth.zeroed
        && let Some(&first) = measured.first()
    {
        for r in &mut measured {
            for k in 0..3 {
                r[k] -= first[k];
            }
        }
    }
    Ok(Record {
        samples: path.samples.clone(),
        measured,
        lines: path.lines.clone(),
        ..Default::default()
    })
}

fn check(m: &Machine, truth: &Truth, path: &Record) -> Result<(), SimulateError> {
    let n = m.axes.len();
    for (i, s) in path.samples.iter().enumerate() {
        if s.commands.len() != n || s.motion.len() != n {
            return Err(SimulateError::Sample {
                machine: m.name.clone(),
                sample: i,
                commands: s.commands.len(),
                motion: s.motion.len(),
                axes: n,
            });
        }
    }
    let bad = |why: String| SimulateError::Truth {
        source_name: truth.source.clone(),
        machine: m.name.clone(),
        why,
    };
    let phi_range = 0.0..crate::truth::MAX_NOISE_PHI;
    if !(truth.noise_mm.is_finite()
        && truth.noise_mm >= 0.0
        && phi_range.contains(&truth.noise_phi))
    {
        return Err(bad(format!(
            "its noise (σ = {} mm, φ = {}) is not a standard deviation ≥ 0 and a lag-1 autocorrelation in [0, {})",
            truth.noise_mm,
            truth.noise_phi,
            crate::truth::MAX_NOISE_PHI
        )));
    }
    truth.fits(m).map_err(bad)
}

/// Comment lines for the CSV of a simulation (`formats::csv::format_record`): what produced
/// it, the machine, the path, the truth and the units.
pub fn provenance(m: &Machine, path_name: &str, truth: &Truth, samples: usize) -> Vec<String> {
    vec![
        format!(
            "simulated by rtest {} (exact virtual machine, simulation::simulate)",
            env!("CARGO_PKG_VERSION")
        ),
        format!("machine: {}", m.name),
        format!("path: {path_name} ({samples} samples)"),
        truth.summary(m),
        format!(
            "readings {}",
            if truth.zeroed {
                "zeroed at the first sample"
            } else {
                "not zeroed (absolute)"
            }
        ),
        "units: linear axes mm, rotary axes degrees, dx_um dy_um dz_um µm (tool minus workpiece, tool frame), t_s s".into(),
    ]
}
