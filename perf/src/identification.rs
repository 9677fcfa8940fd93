//! Identification of one long synthetic record of seed-ac (the reduced model, 11 parameters),
//! two ways, for `rtest bench`: streamed in blocks ([`streaming_identify`]: `[H | y]` folded
//! block by block, never held whole) and in memory ([`memory_identify`]: the whole record as a
//! campaign of one, its whole H and the one [`fitting::identify()`]). Both generate the same samples, so their
//! times compare; each reports the peak memory of its own run.

use fitting::hmatrix::GainSource;
use fitting::streaming::identify_streaming;
use fitting::{Constraint, Fit, IdentifyOptions, Tolerances, identify};
use model_spec::Machine;
use simulation::campaign::Campaign;
use simulation::model::Model;
use simulation::record::{Record, Sample};
use simulation::rng::Rng;
use std::hint::black_box;
use std::time::Instant;

/// One identification run of the synthetic record.
#[derive(Clone, Debug, PartialEq)]
pub struct IdentifyRun {
    /// Samples.
    pub samples: usize,
    /// Generating the record alone (poses, first-order readings, noise), s.
    pub generate_seconds: f64,
    /// Generating and identifying, s.
    pub total_seconds: f64,
    /// The process's peak resident memory during the run (Linux `VmHWM`), bytes: the peak is
    /// reset just before the run (`/proc/self/clear_refs`), so it is this run's peak, the
    /// memory the process held before it ([`IdentifyRun::rss_before_bytes`]) included; `None`
    /// when the system does not say or the peak could not be reset (it would then be an earlier
    /// step's as well).
    pub peak_rss_bytes: Option<u64>,
    /// The process's resident memory just before the run (Linux `VmRSS`), bytes, if known.
    pub rss_before_bytes: Option<u64>,
    /// Largest estimate error against the values used to generate, in units of its standard
    /// uncertainty.
    pub worst_z: f64,
}

/// The values of the `seed-ac-reduced` truth, mm and rad, in the reduced model's column order:
/// the readings are generated from them.
const TRUTH: [f64; 11] = [
    12e-3, -18e-3, 15e-3, 20e-3, -15e-3, 25e-6, -18e-6, 10e-3, -22e-3, 30e-6, -12e-6,
];

/// Samples per block of the streamed run (the CLI's default block).
const BLOCK: usize = 4096;

/// Blocks of a long dynamic record of seed-ac: C turning continuously, A swinging, readings from
/// the first-order reduced model at [`TRUTH`] (mm, rad) plus 0.5 µm noise. The samples do not
/// depend on `block`.
fn synthetic_blocks(
    m: &Machine,
    samples: usize,
    block: usize,
) -> impl Iterator<Item = Result<Record, std::convert::Infallible>> + '_ {
    let model = Model::of(m, "reduced").expect("seed-ac has a reduced model");
    let params = m.default_parameters();
    let mut source = GainSource::new(m, &model.errors(), &params).expect("compiled");
    let mut rng = Rng::new(99);
    let (ia, ic) = (
        m.axis_by_name("A").expect("A"),
        m.axis_by_name("C").expect("C"),
    );
    let mut done = 0;
    std::iter::from_fn(move || {
        if done >= samples {
            return None;
        }
        let b = block.max(1).min(samples - done);
        let mut rec = Record::default();
        rec.samples.reserve_exact(b);
        rec.measured.reserve_exact(b);
        let mut g = vec![[0.0; 3]; model.errors().len()];
        for i in done..done + b {
            let t = i as f64 * 1e-3;
            let mut c = vec![0.0; m.axes.len()];
            c[ic] = 0.7 * t;
            c[ia] = -0.6 * (1.0 - (0.05 * t).cos());
            source.position_gains(&c, &mut g).expect("valid pose");
            let mut y = [0.0; 3];
            for (j, v) in TRUTH.iter().enumerate() {
                for d in 0..3 {
                    y[d] += g[j][d] * v;
                }
            }
            rec.measured.push(y.map(|v| v + 0.5e-3 * rng.normal()));
            rec.samples.push(Sample {
                commands: c,
                t,
                motion: vec![1; m.axes.len()],
                timed: true,
            });
        }
        done += b;
        Some(Ok(rec))
    })
}

/// A line of `/proc/self/status` (`VmHWM`, `VmRSS`), bytes.
fn status_bytes(key: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(key))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// The process's peak resident memory so far (Linux `VmHWM`), bytes.
pub fn peak_rss_bytes() -> Option<u64> {
    status_bytes("VmHWM:")
}

/// Resets the process's peak resident memory to its current resident memory (Linux ≥ 4.0:
/// `5` written to `/proc/self/clear_refs`); whether it was reset.
fn reset_peak_rss() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// Runs `f` (generating and identifying) with the peak memory reset before it: its time, s, the
/// memory before it and its peak, bytes.
fn measured<T>(f: impl FnOnce() -> T) -> (T, f64, Option<u64>, Option<u64>) {
    let reset = reset_peak_rss();
    let before = status_bytes("VmRSS:");
    let start = Instant::now();
    let out = f();
    let seconds = start.elapsed().as_secs_f64();
    (out, seconds, before, peak_rss_bytes().filter(|_| reset))
}

/// The largest `|value − truth| / std` of `fit` (infinite for a parameter without either).
fn worst_z(fit: &Fit) -> f64 {
    (0..TRUTH.len())
        .map(|j| match (fit.values[j], fit.std[j]) {
            (Some(v), Some(s)) => ((v - TRUTH[j]) / s).abs(),
            _ => f64::INFINITY,
        })
        .fold(0.0, f64::max)
}

/// Generating the record of `samples` samples in blocks of `block`, without identifying, s.
fn generate_seconds(m: &Machine, samples: usize, block: usize) -> f64 {
    let start = Instant::now();
    for b in synthetic_blocks(m, samples, block) {
        black_box(b.expect("infallible"));
    }
    start.elapsed().as_secs_f64()
}

/// Identifies the reduced model of seed-ac from `samples` synthetic samples in blocks of 4 096
/// (the record never held whole).
pub fn streaming_identify(samples: usize) -> IdentifyRun {
    let m = crate::machine();
    let model = Model::of(&m, "reduced").expect("reduced");
    let generate_seconds = generate_seconds(&m, samples, BLOCK);
    let (run, total_seconds, rss_before_bytes, peak_rss_bytes) = measured(|| {
        let mut source =
            GainSource::new(&m, &model.errors(), &m.default_parameters()).expect("compiled");
        identify_streaming(
            &m,
            &model,
            synthetic_blocks(&m, samples, BLOCK),
            None,
            &mut source,
            &Constraint::None,
            &Tolerances::default(),
        )
        .expect("a well-posed synthetic record")
    });
    IdentifyRun {
        samples,
        generate_seconds,
        total_seconds,
        peak_rss_bytes,
        rss_before_bytes,
        worst_z: worst_z(&run.fit),
    }
}

/// Identifies the reduced model of seed-ac from the same `samples` synthetic samples in memory:
/// the whole record generated, then [`fitting::identify()`] of it as a campaign of one (its
/// whole H, first order, default options).
pub fn memory_identify(samples: usize) -> IdentifyRun {
    let m = crate::machine();
    let model = Model::of(&m, "reduced").expect("reduced");
    let generate_seconds = generate_seconds(&m, samples, samples);
    let (ident, total_seconds, rss_before_bytes, peak_rss_bytes) = measured(|| {
        let record = synthetic_blocks(&m, samples, samples)
            .next()
            .map(|r| r.expect("infallible"))
            .unwrap_or_default();
        let campaign = Campaign::of_record(record, m.default_parameters(), false);
        identify(&m, &model, &campaign, &IdentifyOptions::default())
            .expect("a well-posed synthetic record")
            .single_record(&m)
            .expect("a campaign of one record")
    });
    IdentifyRun {
        samples,
        generate_seconds,
        total_seconds,
        peak_rss_bytes,
        rss_before_bytes,
        worst_z: worst_z(&ident.fit),
    }
}
