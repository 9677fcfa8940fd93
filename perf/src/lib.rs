//! In-process performance comparisons (`rtest bench`): medians of repeated runs on this
//! computer, reported as ratios. The criterion benchmarks (`cargo bench`) and callgrind
//! instruction counts in BENCHMARKS.md are the careful versions; these take seconds.
//!
//! 1. Gains of the whole `seed-ac` model (44 errors × 6) at one pose by (a) the generated code,
//!    (b) the IR evaluator, (c) the exact HTM chain with central finite differences (what an
//!    engineer writes without a generator), (d) a runtime first-order product of the chain.
//!    Every method includes the sines and cosines of the pose.
//! 2. The H matrix of the full model (3 rows × 44 columns per pose, the generated
//!    `position_gains` writing straight into the rows) filled for many poses in blocks into a
//!    reused buffer, against a plain write of the same bytes into that buffer.
//! 3. Identification of a long record (the reduced model) streamed in blocks and in memory, in
//!    the same run, each with its own peak memory ([`identification`]).
//! 4. Code generation of every built-in machine.
//!
//! This crate also holds the baseline the generated code is measured against, a runtime
//! first-order product of the chain ([`first_order`]). None of it is part of the libraries'
//! API: it serves `rtest bench`, the criterion benchmarks and the callgrind example.

#![warn(missing_docs)]

pub mod first_order;
pub mod identification;
pub mod report;

pub use identification::{IdentifyRun, memory_identify, peak_rss_bytes, streaming_identify};

use crate::first_order::FirstOrderChain;
use codegen::{GainModel, compile};
use generated::seed_ac::{Params, Pose, full};
use model_spec::{AxisKind, Machine};
use simulation::exact::{VirtualMachine, tool_centre_point_ik};
use simulation::fd::{FdSteps, fd_gains_with};
use simulation::rng::Rng;
use std::hint::black_box;
use std::time::Instant;

/// The median of `runs` timings of `f`, in seconds.
pub fn median_seconds(runs: usize, mut f: impl FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..runs.max(1))
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

/// One method of computing the gains.
#[derive(Clone, Debug, PartialEq)]
pub struct MethodTime {
    /// What it is.
    pub method: &'static str,
    /// Median time per pose, ns.
    pub ns_per_pose: f64,
    /// Its time over the generated code's.
    pub ratio_to_generated: f64,
}

pub(crate) fn machine() -> Machine {
    model_spec::builtin("seed-ac")
        .expect("built in")
        .expect("valid")
}

/// Random on-ball poses of seed-ac: `(commands, params)`.
fn poses(m: &Machine, n: usize) -> Vec<Vec<f64>> {
    let mut rng = Rng::new(17);
    let params = m.default_parameters();
    (0..n)
        .map(|_| {
            let mut c: Vec<f64> = m
                .axes
                .iter()
                .map(|a| match a.kind {
                    AxisKind::Rotary => rng.uniform_in(-1.5, 1.5),
                    AxisKind::Linear => 0.0,
                })
                .collect();
            tool_centre_point_ik(m, &mut c, &params).expect("seed-ac has three linear axes");
            c
        })
        .collect()
}

/// Gains of the full seed-ac model by the four methods (`quick`: fewer repetitions).
pub fn gain_methods(quick: bool) -> Vec<MethodTime> {
    let m = machine();
    let errors = m.model_errors("full").expect("full").to_vec();
    let params = m.default_parameters();
    let ps = poses(&m, if quick { 64 } else { 256 });
    let runs = if quick { 5 } else { 15 };
    let model = GainModel::derive(&m, &errors);
    let program = compile(&m, &model);
    let chain = FirstOrderChain::new(&m, &errors);
    let vm = VirtualMachine::new(&m);
    let typed_params = Params::default();
    let (ia, ic) = (
        m.axis_by_name("A").expect("A"),
        m.axis_by_name("C").expect("C"),
    );
    let (ix, iy, iz) = (
        m.axis_by_name("X").expect("X"),
        m.axis_by_name("Y").expect("Y"),
        m.axis_by_name("Z").expect("Z"),
    );
    let per = |s: f64, reps: usize| s * 1e9 / (ps.len() * reps) as f64;

    let mut out = [[0.0; 6]; full::N];
    let generated = per(
        median_seconds(runs, || {
            for _ in 0..10 {
                for c in &ps {
                    let (sa, ca) = c[ia].sin_cos();
                    let (sc, cc) = c[ic].sin_cos();
                    let pose = Pose {
                        sin_a: sa,
                        cos_a: ca,
                        sin_c: sc,
                        cos_c: cc,
                        x: c[ix],
                        y: c[iy],
                        z: c[iz],
                    };
                    full::gains(black_box(&pose), black_box(&typed_params), &mut out);
                    black_box(&out);
                }
            }
        }),
        10,
    );
    let (mut scratch, mut flat) = (Vec::new(), vec![0.0; 6 * errors.len()]);
    let evaluator = per(
        median_seconds(runs, || {
            for c in &ps {
                let inputs = model.atoms.values(c, &params);
                program.eval(black_box(&inputs), &mut scratch, &mut flat);
                black_box(&flat);
            }
        }),
        1,
    );
    let steps = FdSteps {
        richardson: false,
        ..FdSteps::default()
    };
    let fd_runs = if quick { 2 } else { 5 };
    let fd_poses = &ps[..ps.len().min(16)];
    let fd = median_seconds(fd_runs, || {
        for c in fd_poses {
            black_box(fd_gains_with(&vm, black_box(c), &params, &errors, steps));
        }
    }) * 1e9
        / fd_poses.len() as f64;
    let mut d = vec![[0.0; 6]; errors.len()];
    let first_order = per(
        median_seconds(runs, || {
            for c in &ps {
                chain.gains(black_box(c), &params, &mut d);
                black_box(&d);
            }
        }),
        1,
    );
    [
        ("(a) generated code", generated),
        ("(b) IR evaluator", evaluator),
        ("(c) exact HTMs + finite differences", fd),
        ("(d) runtime first-order product", first_order),
    ]
    .into_iter()
    .map(|(method, ns)| MethodTime {
        method,
        ns_per_pose: ns,
        ratio_to_generated: ns / generated,
    })
    .collect()
}

/// A pose of the K4-like sweep the fill benchmarks use, at C = `theta` (rad): A = −45°·(1 − cos C)
/// and the linear axes on a circle. Returns the generated code's `Pose` (sines and cosines
/// computed here) and the commands in seed-ac's axis order X, A, C, Y, Z (mm, rad).
#[inline]
pub fn sweep_pose(theta: f64) -> (Pose, [f64; 5]) {
    let (sc, cc) = theta.sin_cos();
    let a = -std::f64::consts::FRAC_PI_4 * (1.0 - cc);
    let (sa, ca) = a.sin_cos();
    let pose = Pose {
        sin_a: sa,
        cos_a: ca,
        sin_c: sc,
        cos_c: cc,
        x: 200.0 * cc,
        y: 200.0 * sc,
        z: 50.0 * ca,
    };
    (pose, [pose.x, a, theta, pose.y, pose.z])
}

/// The H-matrix fill against a plain write.
#[derive(Clone, Debug, PartialEq)]
pub struct FillBandwidth {
    /// Poses filled.
    pub poses: usize,
    /// Poses per block (the reused buffer).
    pub block: usize,
    /// Bytes of H written: poses × 3 rows × 44 columns × 8.
    pub bytes: f64,
    /// Fill time, s (median).
    pub fill_seconds: f64,
    /// Plain write of the same bytes into the same buffer, s (median).
    pub write_seconds: f64,
}

impl FillBandwidth {
    /// The fill's bandwidth as a fraction of the plain write's.
    pub fn fraction(&self) -> f64 {
        self.write_seconds / self.fill_seconds
    }
}

/// Fills the full seed-ac H matrix (position rows) for `poses` poses of a K4-like sweep, in
/// blocks of `block` poses.
pub fn fill_bandwidth(poses: usize, block: usize, runs: usize) -> FillBandwidth {
    let params = Params::default();
    let cols = full::N;
    let mut buffer = vec![0.0f64; block * 3 * cols];
    // Touch every page before timing, so that neither side pays the first-touch page faults.
    buffer.fill(1.0);
    black_box(&buffer);
    let fill = median_seconds(runs, || {
        let mut done = 0;
        while done < poses {
            let b = block.min(poses - done);
            let (rows, _) = buffer[..b * 3 * cols].as_chunks_mut::<{ full::N }>();
            for (i, pose_rows) in rows.chunks_exact_mut(3).enumerate() {
                let (pose, _) = sweep_pose((done + i) as f64 * 1e-4);
                let out: &mut [[f64; full::N]; 3] = pose_rows.try_into().expect("three rows");
                full::position_gains(&pose, &params, out);
            }
            black_box(&buffer);
            done += b;
        }
    });
    let write = median_seconds(runs, || {
        let mut done = 0;
        while done < poses {
            let b = block.min(poses - done);
            buffer[..b * 3 * cols].fill(black_box(done as f64));
            black_box(&buffer);
            done += b;
        }
    });
    FillBandwidth {
        poses,
        block,
        bytes: (poses * 3 * cols * 8) as f64,
        fill_seconds: fill,
        write_seconds: write,
    }
}

/// Time to generate the Rust source of every model of every built-in machine, s (median).
pub fn codegen_times(runs: usize) -> Vec<(String, f64)> {
    model_spec::all_builtin()
        .into_iter()
        .map(|m| {
            let s = median_seconds(runs, || {
                black_box(codegen::emit::generate_machine(&m, &[]).expect("built-ins generate"));
            });
            (m.name.clone(), s)
        })
        .collect()
}
