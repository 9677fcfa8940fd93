//! Harnesses the end-to-end tests share: a headless browser session, the fuzzing helpers and the real LinuxCNC.

pub mod browser;
pub mod fuzz;
pub mod linuxcnc;

use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};

/// `name` found in a directory of the `PATH` (executable), or `name` itself when it is a path.
pub fn on_path(name: &std::ffi::OsStr) -> Option<PathBuf> {
    if Path::new(name).components().count() > 1 {
        return Some(PathBuf::from(name));
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join(name))
        .find(|p| {
            p.metadata()
                .is_ok_and(|m| m.is_file() && m.mode() & 0o111 != 0)
        })
}

/// Whether the tests must find their outside tools (a browser, LinuxCNC): set in continuous
/// integration (`CI` non-empty and not `0` or `false`), where a missing tool is a failure
/// rather than a skipped test.
pub fn required_in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "0" && v != "false")
}
