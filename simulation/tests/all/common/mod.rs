//! Helpers shared by the integration tests of the numeric crates (each test binary includes
//! this file and uses part of it).
#![allow(dead_code)]

use model_spec::{AxisKind, Machine};
use simulation::model::BasisContext;
use simulation::record::Sample;
use std::path::PathBuf;

/// A small deterministic generator (xorshift64*), so the tests need no extra crate.
pub struct Rng(u64);

impl Rng {
    /// Seeded generator.
    pub fn new(seed: u64) -> Self {
        Rng(seed.max(1))
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d);
        (x >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
}

/// Commands with random rotary entries (rad, within the axis range, ±180° when unlimited) and
/// zero linear entries.
pub fn random_rotary(m: &Machine, rng: &mut Rng) -> Vec<f64> {
    m.axes
        .iter()
        .map(|a| match a.kind {
            AxisKind::Linear => 0.0,
            AxisKind::Rotary => {
                let lo = a.limits[0].max(-180.0);
                let hi = a.limits[1].min(180.0);
                rng.range(lo, hi).to_radians()
            }
        })
        .collect()
}

/// Builds the commands vector of `m` from `(axis name, value)` pairs (mm, rad); others zero.
pub fn commands(m: &Machine, values: &[(&str, f64)]) -> Vec<f64> {
    let mut c = vec![0.0; m.axes.len()];
    for (name, v) in values {
        c[m.axis_by_name(name).expect("axis exists")] = *v;
    }
    c
}

/// The built-in machine `name`.
pub fn builtin(name: &str) -> Machine {
    model_spec::builtin(name).expect("built-in").expect("valid")
}

/// A fixture machine of the repository, by its path from the workspace root.
pub fn fixture(path: &str) -> Machine {
    let file = format!("{}/../{path}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&file).expect("fixture");
    model_spec::parse_machine(&file, &text).expect("valid fixture")
}

/// The catalogue id of `name` on `m`.
pub fn id(m: &Machine, name: &str) -> usize {
    m.error_by_name(name)
        .unwrap_or_else(|| panic!("{} has no error {name}", m.name))
}

/// The value of kinematic symbol `name` in `params`.
pub fn sym(m: &Machine, params: &[f64], name: &str) -> f64 {
    params[m.symbol_by_name(name).expect("symbol exists")]
}

/// A fresh scratch directory under the system's temporary directory, removed on drop.
pub struct Scratch(pub PathBuf);

impl Scratch {
    /// The directory `rtest-solver-{tag}-{pid}-{n}` (`n` counts this process's scratch
    /// directories), emptied if it was left by an earlier run.
    pub fn new(tag: &str) -> Scratch {
        let (pid, n) = (std::process::id(), next_scratch_number());
        let d = std::env::temp_dir().join(format!("rtest-solver-{tag}-{pid}-{n}"));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Scratch(d)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The basis context of a sample at normalised time `tau` (no velocities, no reading).
pub fn context(s: &Sample, tau: f64) -> BasisContext<'_> {
    BasisContext {
        commands: &s.commands,
        motion: &s.motion,
        tau,
        elapsed_s: 0.0,
        since_start_s: 0.0,
        velocity: &[],
        reading: [0.0; 3],
    }
}

/// A number no other scratch directory of this process has taken: the tests of a crate run in
/// one process, in parallel, so the process id alone does not tell two of them apart.
fn next_scratch_number() -> usize {
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}
