//! Everything refused before anything changes: the message, and an untouched directory.

use std::fs;
use std::os::unix::fs::{PermissionsExt, symlink};
use std::path::{Path, PathBuf};

use crate::common::{TestDir, assert_only_changed, read, snapshot, unprivileged};
use output::{Outputs, Target, WriteError, check_dir, check_targets};

fn path(p: impl Into<PathBuf>) -> Target {
    Target::Path(p.into())
}

/// Writes `outputs`, expecting the error `message`, with nothing changed in `dir`; the same
/// outputs checked early (without contents) give the same message.
fn refused(dir: &Path, outputs: &[(&str, Target)], message: &str) -> WriteError {
    let before = snapshot(dir);
    let pairs: Vec<(&str, &Target)> = outputs.iter().map(|(l, t)| (*l, t)).collect();
    let early = check_targets(&pairs).unwrap_err();
    assert_eq!(early.to_string(), message);
    let mut o = Outputs::new();
    for (label, target) in outputs {
        o.add(*label, target.clone(), "contents");
    }
    let err = o.write_all().unwrap_err();
    assert_eq!(err.to_string(), message);
    assert_only_changed(&before, &snapshot(dir), &[]);
    err
}

#[test]
fn a_directory_is_refused() {
    let dir = TestDir::new("directory");
    fs::create_dir(dir.join("sub")).unwrap();
    symlink("sub", dir.join("link")).unwrap();
    for name in ["sub", "link", "sub/", "sub/.."] {
        let t = path(dir.join(name));
        refused(
            &dir.path,
            &[("-o", t.clone())],
            &format!("-o: cannot write `{t}`: it is a directory"),
        );
    }
}

#[test]
fn a_missing_directory_is_refused() {
    let dir = TestDir::new("missing_dir");
    let t = path(dir.join("nope/out.csv"));
    let err = refused(
        &dir.path,
        &[("--json", t.clone())],
        &format!(
            "--json: cannot write `{t}`: the directory `{}` does not exist",
            dir.join("nope").display()
        ),
    );
    assert!(!err.is_usage());
    assert_eq!(err.label(), "--json");
    // Through a dangling link, the link's target's directory is the one missing.
    symlink("gone/x.csv", dir.join("link")).unwrap();
    let t = path(dir.join("link"));
    refused(
        &dir.path,
        &[("-o", t.clone())],
        &format!(
            "-o: cannot write `{t}`: the directory `{}` does not exist",
            dir.join("gone").display()
        ),
    );
    // A file where the directory should be.
    dir.file("plain", "x");
    for name in ["plain/out.csv", "plain/deeper/out.csv"] {
        let t = path(dir.join(name));
        refused(
            &dir.path,
            &[("-o", t.clone())],
            &format!(
                "-o: cannot write `{t}`: `{}` is not a directory",
                dir.join("plain").display()
            ),
        );
    }
}

#[test]
fn a_path_naming_no_file_is_refused() {
    let dir = TestDir::new("no_file_name");
    for t in [path(""), path(dir.join("new/")), path(dir.join("nope/.."))] {
        let err = refused(
            &dir.path,
            &[("-o", t.clone())],
            &format!("-o: cannot write `{t}`: it does not name a file"),
        );
        assert!(err.is_usage());
    }
    for name in ["a/b", "..", ".", ""] {
        let mut o = Outputs::new();
        o.add_in_dir("--plot", dir.join("plots"), name, "x");
        let err = o.write_all().unwrap_err();
        assert!(
            err.to_string().ends_with("it does not name a file"),
            "{err}"
        );
    }
    assert!(snapshot(&dir.path).is_empty());
}

#[test]
fn two_outputs_naming_one_file_are_refused() {
    let dir = TestDir::new("same_file");
    let a = dir.file("a.csv", "old");
    fs::hard_link(&a, dir.join("hard.csv")).unwrap();
    symlink("a.csv", dir.join("soft.csv")).unwrap();
    fs::create_dir(dir.join("sub")).unwrap();
    for other in ["a.csv", "./a.csv", "sub/../a.csv", "hard.csv", "soft.csv"] {
        let t = path(dir.join(other));
        refused(
            &dir.path,
            &[("--json", path(&a)), ("-o", t.clone())],
            &format!("-o: `{t}` is also the output of --json"),
        );
    }
    // Two spellings of a file that does not exist yet.
    let t = path(dir.join("sub/../new.csv"));
    refused(
        &dir.path,
        &[("--json", path(dir.join("new.csv"))), ("-o", t.clone())],
        &format!("-o: `{t}` is also the output of --json"),
    );
    // add_in_dir into a directory yet to be created.
    let mut o = Outputs::new();
    o.add_in_dir("--plot", dir.join("plots"), "p.svg", "1");
    o.add_in_dir("--plot-again", dir.join("sub/../plots/./"), "p.svg", "2");
    let err = o.write_all().unwrap_err();
    assert_eq!(
        err.to_string(),
        format!(
            "--plot-again: `{}` is also the output of --plot",
            dir.join("sub/../plots/./p.svg").display()
        )
    );
    assert!(!dir.join("plots").exists());
    assert_eq!(read(&a), "old");
}

#[test]
fn standard_output_twice_is_refused() {
    let dir = TestDir::new("two_stdout");
    let err = refused(
        &dir.path,
        &[("-o", Target::Stdout), ("--json", Target::Stdout)],
        "--json: standard output is also the output of -o",
    );
    assert!(err.is_usage());
}

#[test]
fn a_read_only_file_is_refused() {
    unprivileged("refusals::a_read_only_file_is_refused", |dir| {
        let ro = dir.join("ro.csv");
        fs::write(&ro, "keep me").unwrap();
        fs::set_permissions(&ro, fs::Permissions::from_mode(0o444)).unwrap();
        let t = path(&ro);
        refused(
            dir,
            &[("-o", t.clone())],
            &format!("-o: cannot write `{t}`: permission denied"),
        );
        assert_eq!(read(&ro), "keep me");
    });
}

#[test]
fn a_directory_without_write_permission_is_refused() {
    unprivileged(
        "refusals::a_directory_without_write_permission_is_refused",
        |dir| {
            let locked = dir.join("locked");
            fs::create_dir(&locked).unwrap();
            let inside = locked.join("x.csv");
            fs::write(&inside, "old").unwrap();
            fs::set_permissions(&locked, fs::Permissions::from_mode(0o555)).unwrap();
            for t in [path(&inside), path(locked.join("new.csv"))] {
                refused(
                    dir,
                    &[("-o", t.clone())],
                    &format!(
                        "-o: cannot write `{t}`: cannot create files in the directory `{}`: \
                     permission denied",
                        locked.display()
                    ),
                );
            }
            let err = check_dir("--plot", &locked.join("plots")).unwrap_err();
            assert!(err.to_string().ends_with("permission denied"), "{err}");
            fs::set_permissions(&locked, fs::Permissions::from_mode(0o755)).unwrap();
            assert_eq!(read(&inside), "old");
        },
    );
}

#[test]
fn check_dir_accepts_new_and_existing_directories() {
    let dir = TestDir::new("check_dir");
    check_dir("--plot", &dir.path).unwrap();
    check_dir("--plot", &dir.join("a/b/c")).unwrap();
    dir.file("f", "");
    let err = check_dir("--plot", &dir.join("f/plots")).unwrap_err();
    assert_eq!(
        err.to_string(),
        format!(
            "--plot: cannot write `{}`: `{}` is not a directory",
            dir.join("f/plots").display(),
            dir.join("f").display()
        )
    );
    assert!(!dir.join("a").exists());
}
