//! Temporary files: never through a planted link, never left behind, not even on SIGINT or
//! SIGTERM.

use std::ffi::OsStr;
use std::fs;
use std::os::unix::fs::symlink;
use std::os::unix::process::ExitStatusExt;
use std::process::Stdio;
use std::time::Duration;

use crate::common::{
    TestDir, assert_only_changed, child_command, child_dir, is_child, leftovers, read, snapshot,
    wait_until,
};
use output::{Outputs, Target, testing};

/// Counts up from 0: the names a test planted links at are tried first.
fn counting_names() {
    let mut next = 0u64;
    testing::set_name_source(Some(Box::new(move || {
        next += 1;
        next - 1
    })));
}

#[test]
fn planted_symlinks_at_temporary_names_are_never_followed() {
    let dir = TestDir::new("planted");
    let victim = dir.file("victim", "secret");
    let out = dir.file("out.csv", "old");
    let name = OsStr::new("out.csv");
    let pid = std::process::id();
    // The names this crate will try first, and the predictable names of older writers.
    // Names count up from 0: the temporary skips 0..20 and gets 20, then the backup link of
    // the replaced file skips 21..60.
    let mut planted: Vec<String> = (0..20)
        .map(|bits| testing::temp_name(name, bits))
        .chain((0..60).map(|bits| testing::backup_name(name, bits)))
        .map(|n| n.to_string_lossy().into_owned())
        .collect();
    planted.push(format!(".out.csv.rtest-tmp-{pid}"));
    planted.extend((0..4).map(|i| format!(".out.csv.rtest-tmp-{pid}-{i}")));
    for p in &planted {
        symlink(&victim, dir.join(p)).unwrap();
    }
    let before = snapshot(&dir.path);
    counting_names();
    let mut o = Outputs::new();
    o.add("-o", Target::Path(out.clone()), "new");
    let result = o.write_all();
    testing::set_name_source(None);
    result.unwrap();
    assert_eq!(read(&out), "new");
    assert_eq!(read(&victim), "secret");
    // Every planted link is still there, still a link to the victim.
    assert_only_changed(&before, &snapshot(&dir.path), &["out.csv"]);
    // Random names too.
    let mut o = Outputs::new();
    o.add("-o", Target::Path(out.clone()), "newer");
    o.write_all().unwrap();
    assert_eq!(read(&out), "newer");
    assert_only_changed(&before, &snapshot(&dir.path), &["out.csv"]);
}

#[test]
fn no_free_temporary_name_is_an_error_that_changes_nothing() {
    let dir = TestDir::new("no_free_name");
    let out = dir.file("out.csv", "old");
    for bits in 0..100 {
        let n = testing::temp_name(OsStr::new("out.csv"), bits);
        fs::write(dir.join(n), "someone else's").unwrap();
    }
    let before = snapshot(&dir.path);
    counting_names();
    let mut o = Outputs::new();
    o.add("-o", Target::Path(out.clone()), "new");
    let result = o.write_all();
    testing::set_name_source(None);
    assert_eq!(
        result.unwrap_err().to_string(),
        format!(
            "-o: cannot write `{}`: no free name for a temporary file",
            out.display()
        )
    );
    assert_only_changed(&before, &snapshot(&dir.path), &[]);
}

/// A child's hook: tell the parent (by creating `marker`), then wait to be killed.
fn mark_and_wait(marker: std::path::PathBuf) -> Box<dyn Fn()> {
    Box::new(move || {
        fs::write(&marker, "").unwrap();
        loop {
            std::thread::sleep(Duration::from_millis(10));
        }
    })
}

/// Runs the child of `test` in `dir` and waits until it has created `marker` (`what` says what
/// that means, for the panic if it never does).
fn spawn_until(test: &str, dir: &TestDir, marker: &str, what: &str) -> std::process::Child {
    let exe = std::env::current_exe().unwrap();
    let mut child = child_command(&exe, test, &dir.path)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    if !wait_until(Duration::from_secs(20), || dir.join(marker).exists()) {
        let _ = child.kill();
        let _ = child.wait();
        panic!("the child never {what}");
    }
    child
}

/// Sends `signal` to `child` and checks that it died of it.
fn signal_and_wait(mut child: std::process::Child, signal: i32) {
    let pid = child.id() as libc::pid_t;
    // SAFETY: sends a signal to the child this test started.
    assert_eq!(unsafe { libc::kill(pid, signal) }, 0);
    let mut status = None;
    wait_until(Duration::from_secs(20), || {
        status = child.try_wait().unwrap();
        status.is_some()
    });
    let Some(status) = status else {
        let _ = child.kill();
        let _ = child.wait();
        panic!("the child did not end on the signal");
    };
    assert_eq!(status.signal(), Some(signal), "{status}");
}

/// The child's part of the signal tests: stage a large output and a small one, tell the parent
/// (by creating `staged`), and wait to be killed.
fn stage_and_wait() {
    let dir = child_dir();
    testing::set_after_staging(Some(mark_and_wait(dir.join("staged"))));
    let mut o = Outputs::new();
    o.add("-o", Target::Path(dir.join("big.csv")), vec![b'x'; 4 << 20]);
    o.add_in_dir("--plot", dir.join("plots"), "p.svg", "<svg/>");
    o.add("--json", Target::Path(dir.join("new.json")), "{}");
    let _ = o.write_all();
    std::process::exit(3); // never reached: the hook waits for the signal
}

/// Runs the child, sends it `signal` once its temporaries exist, and checks that it died of
/// that signal leaving no temporary and no directory it created.
fn killed_while_staged(test: &str, signal: i32) {
    let dir = TestDir::new(test);
    dir.file("big.csv", "old");
    let child = spawn_until(test, &dir, "staged", "staged its outputs");
    // Its temporaries exist now (the plots directory holds one too).
    assert!(!leftovers(&dir.path).is_empty());
    let before = snapshot(&dir.path);
    signal_and_wait(child, signal);
    assert!(
        leftovers(&dir.path).is_empty(),
        "{:?}",
        leftovers(&dir.path)
    );
    // The directory created for the plots went with its temporary.
    assert!(!dir.join("plots").exists());
    assert_eq!(read(&dir.join("big.csv")), "old");
    assert!(!dir.join("new.json").exists());
    let after = snapshot(&dir.path);
    let temporaries: Vec<String> = before
        .keys()
        .map(|k| k.to_string_lossy().into_owned())
        .filter(|k| k.contains(".rtest-"))
        .collect();
    let mut gone: Vec<&str> = temporaries.iter().map(String::as_str).collect();
    gone.push("plots");
    assert_only_changed(&before, &after, &gone);
}

#[test]
fn sigterm_while_staged_leaves_no_temporary() {
    const TEST: &str = "temporaries::sigterm_while_staged_leaves_no_temporary";
    if is_child(TEST) {
        stage_and_wait();
    }
    killed_while_staged(TEST, libc::SIGTERM);
}

#[test]
fn sigint_while_staged_leaves_no_temporary() {
    const TEST: &str = "temporaries::sigint_while_staged_leaves_no_temporary";
    if is_child(TEST) {
        stage_and_wait();
    }
    killed_while_staged(TEST, libc::SIGINT);
}

/// The child's part of the rename test: replace `a.csv` and `b.csv` and create `new.json`;
/// after the first rename, tell the parent and wait to be killed.
fn rename_and_wait() {
    let dir = child_dir();
    testing::set_after_rename(Some(mark_and_wait(dir.join("renamed"))));
    let mut o = Outputs::new();
    o.add("-o", Target::Path(dir.join("a.csv")), "new a");
    o.add("--json", Target::Path(dir.join("new.json")), "{}");
    o.add("--other", Target::Path(dir.join("b.csv")), "new b");
    let _ = o.write_all();
    std::process::exit(3); // never reached: the hook waits for the signal
}

/// A signal between two renames undoes the renames already done: all outputs or none.
#[test]
fn sigterm_between_renames_puts_the_old_files_back() {
    const TEST: &str = "temporaries::sigterm_between_renames_puts_the_old_files_back";
    if is_child(TEST) {
        rename_and_wait();
    }
    let dir = TestDir::new(TEST);
    dir.file("a.csv", "old a");
    dir.file("b.csv", "old b");
    let original = snapshot(&dir.path);
    let child = spawn_until(TEST, &dir, "renamed", "renamed an output");
    // One file is replaced already.
    assert_eq!(read(&dir.join("a.csv")), "new a");
    signal_and_wait(child, libc::SIGTERM);
    assert_eq!(read(&dir.join("a.csv")), "old a");
    assert_eq!(read(&dir.join("b.csv")), "old b");
    assert!(!dir.join("new.json").exists());
    assert!(
        leftovers(&dir.path).is_empty(),
        "{:?}",
        leftovers(&dir.path)
    );
    let mut after = snapshot(&dir.path);
    after.remove(std::path::Path::new("renamed"));
    assert_only_changed(&original, &after, &[]);
}
