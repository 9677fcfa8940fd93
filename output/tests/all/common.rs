//! Helpers of the output tests: a fresh directory per test, a snapshot of everything in it to
//! check that nothing but the expected files changed, and re-running this test binary as a
//! child process (for standard output, signals and an unprivileged user).
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::ffi::CString;
use std::fs;
use std::io;
use std::os::unix::ffi::OsStrExt;
use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// Set in a child process to the name of the test it runs as the child.
pub const CHILD: &str = "RTEST_OUTPUT_TEST_CHILD";
/// Set in a child process to the test's directory.
pub const CHILD_DIR: &str = "RTEST_OUTPUT_TEST_DIR";
/// The unprivileged user and group the root-only tests run as.
pub const NOBODY: u32 = 65534;

/// A fresh, empty directory for one test, removed when dropped.
pub struct TestDir {
    pub path: PathBuf,
}

impl TestDir {
    pub fn new(test: &str) -> TestDir {
        let path = std::env::temp_dir().join(format!("rtest-output-{}-{test}", std::process::id()));
        let _ = fs::remove_dir_all(&path);
        fs::create_dir_all(&path).unwrap();
        // Canonical, so that tests compare the paths the library reports.
        let path = fs::canonicalize(&path).unwrap();
        TestDir { path }
    }

    pub fn join(&self, rel: impl AsRef<Path>) -> PathBuf {
        self.path.join(rel)
    }

    /// Writes `contents` to `rel` (test set-up, not through the library).
    pub fn file(&self, rel: &str, contents: &str) -> PathBuf {
        let p = self.join(rel);
        fs::write(&p, contents).unwrap();
        p
    }
}

impl Drop for TestDir {
    fn drop(&mut self) {
        // A read-only directory left by a test would stop the removal.
        make_writable(&self.path);
        let _ = fs::remove_dir_all(&self.path);
    }
}

fn make_writable(dir: &Path) {
    let _ = fs::set_permissions(dir, fs::Permissions::from_mode(0o755));
    if let Ok(entries) = fs::read_dir(dir) {
        for e in entries.flatten() {
            if e.file_type().is_ok_and(|t| t.is_dir()) {
                make_writable(&e.path());
            }
        }
    }
}

/// What one directory entry is, in enough detail to see any change.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Entry {
    File {
        contents: Vec<u8>,
        mode: u32,
        ino: u64,
        nlink: u64,
    },
    Link(PathBuf),
    Dir(u32),
    Other(u32),
}

/// Every entry under `dir`, by path relative to it.
pub fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Entry> {
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, Entry>) {
    for e in fs::read_dir(dir).unwrap().flatten() {
        let path = e.path();
        let m = fs::symlink_metadata(&path).unwrap();
        let rel = path.strip_prefix(root).unwrap().to_path_buf();
        let entry = if m.file_type().is_symlink() {
            Entry::Link(fs::read_link(&path).unwrap())
        } else if m.is_dir() {
            walk(root, &path, out);
            Entry::Dir(m.mode())
        } else if m.is_file() {
            Entry::File {
                contents: fs::read(&path).unwrap_or_default(),
                mode: m.mode(),
                ino: m.ino(),
                nlink: m.nlink(),
            }
        } else {
            Entry::Other(m.mode())
        };
        out.insert(rel, entry);
    }
}

/// Asserts that between two snapshots nothing changed but the entries in `changed`.
pub fn assert_only_changed(
    before: &BTreeMap<PathBuf, Entry>,
    after: &BTreeMap<PathBuf, Entry>,
    changed: &[&str],
) {
    let keys: std::collections::BTreeSet<_> = before.keys().chain(after.keys()).collect();
    for key in keys {
        if changed.iter().any(|c| Path::new(c) == key.as_path()) {
            continue;
        }
        assert_eq!(
            before.get(key),
            after.get(key),
            "`{}` changed unexpectedly",
            key.display()
        );
    }
}

/// Names in `dir` (not recursive) that look like this crate's temporaries or backups.
pub fn leftovers(dir: &Path) -> Vec<String> {
    fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".rtest-"))
        .collect()
}

pub fn read(path: &Path) -> String {
    String::from_utf8(fs::read(path).unwrap()).unwrap()
}

pub fn mode(path: &Path) -> u32 {
    fs::symlink_metadata(path).unwrap().mode() & 0o7777
}

pub fn mkfifo(path: &Path) {
    let c = CString::new(path.as_os_str().as_bytes()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    let rc = unsafe { libc::mkfifo(c.as_ptr(), 0o644) };
    assert_eq!(rc, 0, "mkfifo: {}", io::Error::last_os_error());
}

pub fn is_root() -> bool {
    // SAFETY: no arguments, no memory.
    unsafe { libc::geteuid() == 0 }
}

/// Whether this process is the child run of `test`.
pub fn is_child(test: &str) -> bool {
    std::env::var(CHILD).as_deref() == Ok(test)
}

/// The test directory handed to a child.
pub fn child_dir() -> PathBuf {
    PathBuf::from(std::env::var_os(CHILD_DIR).unwrap())
}

/// A command running only `test` of this test binary as a child, with SIGINT and SIGTERM at
/// their default dispositions whatever the parent's are.
pub fn child_command(exe: &Path, test: &str, dir: &Path) -> Command {
    let mut cmd = Command::new(exe);
    cmd.args([test, "--exact", "--nocapture", "--test-threads=1", "-q"])
        .env(CHILD, test)
        .env(CHILD_DIR, dir);
    // SAFETY: only async-signal-safe calls between fork and exec.
    unsafe {
        cmd.pre_exec(|| {
            libc::signal(libc::SIGINT, libc::SIG_DFL);
            libc::signal(libc::SIGTERM, libc::SIG_DFL);
            Ok(())
        });
    }
    cmd
}

/// Asserts that a child run of one test passed (and did run the test).
pub fn assert_child_passed(out: &Output) {
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success() && stdout.contains("1 passed"),
        "child failed: {}\n--- stdout\n{stdout}\n--- stderr\n{stderr}",
        out.status
    );
}

/// Runs `body` on the test's directory as an unprivileged user: directly when not root, else
/// in a child process of this test binary whose user and group are `nobody`, so that
/// permissions are enforced as for any user.
pub fn unprivileged(test: &str, body: impl FnOnce(&Path)) {
    if is_child(test) {
        body(&child_dir());
        return;
    }
    let dir = TestDir::new(test);
    if !is_root() {
        body(&dir.path);
        return;
    }
    std::os::unix::fs::chown(&dir.path, Some(NOBODY), Some(NOBODY)).unwrap();
    let drop_privileges = |cmd: &mut Command| {
        // SAFETY: only async-signal-safe calls between fork and exec.
        unsafe {
            cmd.pre_exec(|| {
                if libc::setgroups(0, std::ptr::null()) != 0
                    || libc::setgid(NOBODY) != 0
                    || libc::setuid(NOBODY) != 0
                {
                    return Err(io::Error::last_os_error());
                }
                Ok(())
            });
        }
    };
    let exe = std::env::current_exe().unwrap();
    let mut cmd = child_command(&exe, test, &dir.path);
    drop_privileges(&mut cmd);
    let out = match cmd.output() {
        Err(e) if e.kind() == io::ErrorKind::PermissionDenied => {
            // The build directory is not open to `nobody`: run a copy from a directory that is.
            let bin = TestDir::new(&format!("{test}-bin"));
            fs::set_permissions(&bin.path, fs::Permissions::from_mode(0o755)).unwrap();
            let copy = bin.join("test-binary");
            fs::copy(&exe, &copy).unwrap();
            fs::set_permissions(&copy, fs::Permissions::from_mode(0o755)).unwrap();
            let mut cmd = child_command(&copy, test, &dir.path);
            drop_privileges(&mut cmd);
            cmd.output().unwrap()
        }
        other => other.unwrap(),
    };
    assert_child_passed(&out);
}

/// Polls `done` every few milliseconds for at most `limit`.
pub fn wait_until(limit: Duration, mut done: impl FnMut() -> bool) -> bool {
    let start = Instant::now();
    while start.elapsed() < limit {
        if done() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    done()
}
