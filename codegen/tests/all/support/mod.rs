//! Compiling emitted code in a test: as a `no_std` library under `-D warnings`, with Clippy's
//! default lints where `clippy-driver` is installed (as in CI).

pub mod chains;

use std::path::{Path, PathBuf};
use std::process::Command;

/// A fresh scratch directory for one test.
pub fn scratch(test: &str) -> PathBuf {
    let (pid, n) = (std::process::id(), next_scratch_number());
    let dir = std::env::temp_dir().join(format!("rtest-{test}-{pid}-{n}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `clippy-driver` when it runs here, else `rustc` (`$RUSTC` if set).
pub fn compiler() -> String {
    let clippy = std::env::var("CLIPPY_DRIVER").unwrap_or_else(|_| "clippy-driver".into());
    let runs = Command::new(&clippy)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if runs {
        clippy
    } else {
        eprintln!("{clippy} does not run here: checking with rustc only");
        std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into())
    }
}

/// Compiles `file` with `args` (edition 2024) into `out`; panics with the compiler's messages
/// when it fails.
pub fn compile(compiler: &str, file: &Path, args: &[&str], out: &Path) {
    let o = Command::new(compiler)
        .args(["--edition", "2024"])
        .args(args)
        .arg("-o")
        .arg(out)
        .arg(file)
        .output()
        .expect("the compiler runs");
    assert!(
        o.status.success(),
        "{compiler} {}:\n{}",
        file.display(),
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Checks emitted `code` as the content of a `#![no_std]` library: no error, no rustc warning
/// and, where `clippy-driver` runs, no warning of Clippy's default lints.
pub fn check_no_std_lib(dir: &Path, code: &str) {
    let file = dir.join("lib.rs");
    std::fs::write(&file, format!("#![no_std]\n{code}")).unwrap();
    let args = [
        "--crate-type",
        "lib",
        "--emit",
        "metadata",
        "-D",
        "warnings",
    ];
    compile(&compiler(), &file, &args, &dir.join("lib.rmeta"));
}

/// The lints named in the `#[allow(…)]` attributes of `code`, in order.
pub fn allowed_lints(code: &str) -> Vec<String> {
    code.split("#[allow(")
        .skip(1)
        .flat_map(|rest| {
            let list = &rest[..rest.find(")]").expect("an allow attribute is closed")];
            list.split(',')
                .map(|l| l.trim().to_string())
                .collect::<Vec<_>>()
        })
        .collect()
}

/// A number no other scratch directory of this process has taken: the tests of a crate run in
/// one process, in parallel, so the process id alone does not tell two of them apart.
fn next_scratch_number() -> usize {
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}
