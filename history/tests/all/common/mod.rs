//! What the tests of the history crate share: temporary directories and checks made by hand.

#![allow(dead_code)]

use history::{Check, CheckKind, InputFile, Parameter, Timestamp};
use std::path::{Path, PathBuf};

/// A fresh, empty temporary directory, removed when dropped.
pub struct TempDir(pub PathBuf);

impl TempDir {
    /// A directory named after the test file (`tag`) and the test (`name`).
    pub fn new(tag: &str, name: &str) -> TempDir {
        let (pid, n) = (std::process::id(), next_scratch_number());
        let d = std::env::temp_dir().join(format!("rtest-history-{tag}-{pid}-{n}-{name}"));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).expect("temp dir");
        TempDir(d)
    }
}

impl std::ops::Deref for TempDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A constant parameter in µm.
pub fn um(name: &str, value: f64, std: f64) -> Parameter {
    Parameter {
        name: name.into(),
        error: name.into(),
        basis: "const".into(),
        owner: None,
        of: None,
        value: Some(value),
        std: Some(std),
        unit: "um".into(),
        determined: true,
        fixed: false,
    }
}

/// A check of `machine_id` at `day` days after 2025-01-06 (a Monday), model `reduced` of
/// seed-ac measured on K4, with XOC = `xoc` ± `std` µm and AOC = 12 ± 1 µrad.
pub fn check(machine_id: &str, day: i64, xoc: f64, std: f64) -> Check {
    let start = Timestamp::parse("2025-01-06T08:00:00Z").unwrap();
    let at = Timestamp(start.0 + day * 86_400);
    let mut aoc = um("AOC", 12.0, 1.0);
    aoc.unit = "urad".into();
    Check {
        machine_id: machine_id.into(),
        fingerprint: "fa038fe9e24c960a".into(),
        machine: "seed-ac".into(),
        model: "reduced".into(),
        base_model: Some("reduced".into()),
        terms: vec!["XOC".into(), "AOC".into()],
        paths: vec!["K4".into()],
        measured_at: at,
        recorded_at: Timestamp(at.0 + 3600),
        rtest_version: "0.1.0".into(),
        kind: CheckKind::Record,
        recheck: false,
        inputs: vec![InputFile {
            role: "--data".into(),
            path: "k4.csv".into(),
            bytes: 12,
            sha256: history::sha256::sha256_hex(b"hello world\n"),
        }],
        parameters: vec![um("XOC", xoc, std), aoc],
        rank: 2,
        free_parameters: 2,
        condition: Some(3.5),
        unidentifiable: vec![],
        residual_rms_um: 0.5,
        sigma_um: Some(0.51),
        samples: 241,
        dof: 721,
        zeroed: false,
        constraint: "none".into(),
        refinement: "exact".into(),
        noise_model: Some("white, σ 0.5 µm".into()),
    }
}

/// A number no other scratch directory of this process has taken: the tests of a crate run in
/// one process, in parallel, so the process id alone does not tell two of them apart.
fn next_scratch_number() -> usize {
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}
