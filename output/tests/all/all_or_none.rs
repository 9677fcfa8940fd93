//! All or none: a failure at any step before the streams leaves every file as it was, no
//! temporary, no backup and no directory created for the outputs.

use std::fs;
use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::path::Path;

use crate::common::{TestDir, assert_only_changed, leftovers, read, snapshot, unprivileged};
use output::{Outputs, Target, testing};

/// Replaces `path` by a non-empty directory (a rename or an open onto it then fails, even for
/// root).
fn turn_into_directory(path: &Path) {
    fs::remove_file(path).unwrap();
    fs::create_dir(path).unwrap();
    fs::write(path.join("inside"), "x").unwrap();
}

#[test]
fn a_missing_directory_for_the_second_output_changes_nothing() {
    let dir = TestDir::new("second_missing_dir");
    let a = dir.file("a.csv", "old a");
    let before = snapshot(&dir.path);
    let mut o = Outputs::new();
    o.add("-o", Target::Path(a.clone()), "new a");
    o.add_in_dir("--plot", dir.join("plots"), "p.svg", "<svg/>");
    o.add("--json", Target::Path(dir.join("missing/b.json")), "{}");
    let err = o.write_all().unwrap_err();
    assert_eq!(
        err.to_string(),
        format!(
            "--json: cannot write `{}`: the directory `{}` does not exist",
            dir.join("missing/b.json").display(),
            dir.join("missing").display()
        )
    );
    assert_eq!(read(&a), "old a");
    assert_only_changed(&before, &snapshot(&dir.path), &[]);
}

#[test]
fn a_read_only_second_output_changes_nothing() {
    unprivileged(
        "all_or_none::a_read_only_second_output_changes_nothing",
        |dir| {
            let a = dir.join("a.csv");
            fs::write(&a, "old a").unwrap();
            let ro = dir.join("ro.csv");
            fs::write(&ro, "old ro").unwrap();
            fs::set_permissions(&ro, fs::Permissions::from_mode(0o444)).unwrap();
            let before = snapshot(dir);
            let mut o = Outputs::new();
            o.add("-o", Target::Path(a.clone()), "new a");
            o.add_in_dir("--plot", dir.join("plots"), "p.svg", "<svg/>");
            o.add("--json", Target::Path(ro.clone()), "new ro");
            let err = o.write_all().unwrap_err();
            assert_eq!(
                err.to_string(),
                format!("--json: cannot write `{}`: permission denied", ro.display())
            );
            assert_eq!(read(&a), "old a");
            assert_only_changed(&before, &snapshot(dir), &[]);
        },
    );
}

#[test]
fn a_rename_failing_midway_is_rolled_back() {
    let dir = TestDir::new("rename_rollback");
    let a = dir.file("a.csv", "old a");
    let b = dir.file("b.csv", "old b");
    fs::set_permissions(&a, fs::Permissions::from_mode(0o640)).unwrap();
    let ino_a = fs::metadata(&a).unwrap().ino();
    let before = snapshot(&dir.path);
    let mut o = Outputs::new();
    o.add("-o", Target::Path(a.clone()), "new a");
    o.add_in_dir("--plot", dir.join("plots/deep"), "p.svg", "<svg/>");
    o.add("--new", Target::Path(dir.join("c.csv")), "new c");
    o.add("--json", Target::Path(b.clone()), "new b");
    // After staging, `b.csv` becomes a directory: its rename fails after the first three.
    let hook_b = b.clone();
    testing::set_after_staging(Some(Box::new(move || turn_into_directory(&hook_b))));
    let err = o.write_all().unwrap_err();
    testing::set_after_staging(None);
    assert_eq!(
        err.to_string(),
        format!("--json: cannot write `{}`: is a directory", b.display())
    );
    // The old file itself is back (same inode), with its mode.
    let m = fs::metadata(&a).unwrap();
    assert_eq!(
        (read(&a), m.ino(), m.mode() & 0o777),
        ("old a".into(), ino_a, 0o640)
    );
    assert!(!dir.join("c.csv").exists());
    assert!(!dir.join("plots").exists());
    assert!(
        leftovers(&dir.path).is_empty(),
        "{:?}",
        leftovers(&dir.path)
    );
    assert_only_changed(&before, &snapshot(&dir.path), &["b.csv", "b.csv/inside"]);
}

#[test]
fn an_in_place_write_failing_is_rolled_back() {
    let dir = TestDir::new("in_place_rollback");
    let a = dir.file("a.csv", "old a");
    let h = dir.file("h.csv", "old h");
    fs::hard_link(&h, dir.join("h2.csv")).unwrap();
    let g = dir.file("g.csv", "old g");
    fs::hard_link(&g, dir.join("g2.csv")).unwrap();
    let before = snapshot(&dir.path);
    let mut o = Outputs::new();
    o.add("--links", Target::Path(g.clone()), "new g");
    o.add("-o", Target::Path(a.clone()), "new a");
    o.add("--json", Target::Path(h.clone()), "new h");
    let hook_h = h.clone();
    testing::set_after_staging(Some(Box::new(move || turn_into_directory(&hook_h))));
    let err = o.write_all().unwrap_err();
    testing::set_after_staging(None);
    assert_eq!(
        err.to_string(),
        format!("--json: cannot write `{}`: is a directory", h.display())
    );
    assert_eq!(read(&a), "old a");
    // The hard-linked file written in place before the failure has its old contents again.
    assert_eq!(read(&g), "old g");
    assert_eq!(read(&dir.join("h2.csv")), "old h");
    assert!(
        leftovers(&dir.path).is_empty(),
        "{:?}",
        leftovers(&dir.path)
    );
    assert_only_changed(
        &before,
        &snapshot(&dir.path),
        &["h.csv", "h.csv/inside", "h2.csv"],
    );
}

#[test]
fn an_existing_plot_directory_is_kept_on_failure() {
    let dir = TestDir::new("keep_existing_dir");
    fs::create_dir(dir.join("plots")).unwrap();
    let before = snapshot(&dir.path);
    let mut o = Outputs::new();
    o.add_in_dir("--plot", dir.join("plots"), "p.svg", "<svg/>");
    o.add("--json", Target::Path(dir.join("missing/b.json")), "{}");
    o.write_all().unwrap_err();
    assert_only_changed(&before, &snapshot(&dir.path), &[]);
}
