//! Regular files, hard links and symbolic links: what is written where, what is kept.

use std::fs;
use std::os::unix::fs::{MetadataExt, PermissionsExt, symlink};
use std::path::Path;

use crate::common::{TestDir, assert_only_changed, leftovers, mode, read, snapshot};
use output::{Outputs, Target};

fn write_one(path: &Path, contents: &str) -> Result<Vec<output::Written>, output::WriteError> {
    let mut o = Outputs::new();
    o.add("-o", Target::Path(path.to_path_buf()), contents);
    o.write_all()
}

#[test]
fn new_file_gets_exact_contents_and_the_shell_mode() {
    let dir = TestDir::new("new_file");
    let other = dir.file("other.txt", "untouched");
    let reference = dir.join("reference");
    fs::File::create(&reference).unwrap(); // 0o666 less the umask, as a shell creates files
    let before = snapshot(&dir.path);
    let out = dir.join("new.csv");
    let contents = "a,b\n1,2\n\u{b5}m\n";
    let written = write_one(&out, contents).unwrap();
    assert_eq!(read(&out), contents);
    assert_eq!(mode(&out), mode(&reference));
    assert_eq!(written.len(), 1);
    assert_eq!(written[0].label, "-o");
    assert_eq!(written[0].bytes, contents.len());
    assert_eq!(written[0].to_string(), format!("`{}`", out.display()));
    assert_eq!(read(&other), "untouched");
    assert_only_changed(&before, &snapshot(&dir.path), &["new.csv"]);
    assert!(leftovers(&dir.path).is_empty());
}

#[test]
fn replacing_keeps_the_mode() {
    let dir = TestDir::new("keeps_mode");
    for (name, m) in [("private.csv", 0o600), ("script.sh", 0o755), ("odd", 0o640)] {
        let p = dir.file(name, "old contents that are longer than the new ones\n");
        fs::set_permissions(&p, fs::Permissions::from_mode(m)).unwrap();
        let ino = fs::metadata(&p).unwrap().ino();
        let before = snapshot(&dir.path);
        write_one(&p, "new\n").unwrap();
        assert_eq!(read(&p), "new\n");
        assert_eq!(mode(&p), m, "{name}");
        // Replaced, not rewritten: a reader holding the old file keeps the old contents.
        assert_ne!(fs::metadata(&p).unwrap().ino(), ino);
        assert_only_changed(&before, &snapshot(&dir.path), &[name]);
        assert!(leftovers(&dir.path).is_empty());
    }
}

#[test]
fn replacing_keeps_the_owner_where_permitted() {
    if !crate::common::is_root() {
        return; // only root can make a file owned by someone else
    }
    let dir = TestDir::new("keeps_owner");
    let p = dir.file("owned.csv", "old");
    std::os::unix::fs::chown(&p, Some(crate::common::NOBODY), Some(crate::common::NOBODY)).unwrap();
    write_one(&p, "new").unwrap();
    let m = fs::metadata(&p).unwrap();
    assert_eq!(
        (m.uid(), m.gid()),
        (crate::common::NOBODY, crate::common::NOBODY)
    );
    assert_eq!(read(&p), "new");
}

#[test]
fn hard_links_all_see_the_new_contents() {
    let dir = TestDir::new("hard_links");
    let a = dir.file("a.csv", "old old old\n");
    let b = dir.join("b.csv");
    fs::hard_link(&a, &b).unwrap();
    fs::set_permissions(&a, fs::Permissions::from_mode(0o640)).unwrap();
    let ino = fs::metadata(&a).unwrap().ino();
    let before = snapshot(&dir.path);
    write_one(&b, "new\n").unwrap();
    for p in [&a, &b] {
        let m = fs::metadata(p).unwrap();
        assert_eq!(read(p), "new\n");
        assert_eq!((m.ino(), m.nlink(), m.mode() & 0o777), (ino, 2, 0o640));
    }
    assert_only_changed(&before, &snapshot(&dir.path), &["a.csv", "b.csv"]);
}

#[test]
fn symlinks_are_followed_and_stay_links() {
    let dir = TestDir::new("symlinks");
    fs::create_dir(dir.join("sub")).unwrap();
    let target = dir.file("sub/target.csv", "old");
    fs::set_permissions(&target, fs::Permissions::from_mode(0o600)).unwrap();
    // Relative (resolved against the link's directory), absolute, in another directory, chained.
    symlink("target.csv", dir.join("sub/rel")).unwrap();
    symlink(&target, dir.join("abs")).unwrap();
    symlink("sub/target.csv", dir.join("up")).unwrap();
    symlink("sub/rel", dir.join("chain")).unwrap();
    for (i, link) in ["sub/rel", "abs", "up", "chain"].into_iter().enumerate() {
        let before = snapshot(&dir.path);
        let contents = format!("new {i}\n");
        write_one(&dir.join(link), &contents).unwrap();
        assert!(
            fs::symlink_metadata(dir.join(link))
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(read(&target), contents);
        assert_eq!(mode(&target), 0o600);
        assert_only_changed(&before, &snapshot(&dir.path), &["sub/target.csv"]);
        assert!(leftovers(&dir.path).is_empty() && leftovers(&dir.join("sub")).is_empty());
    }
}

#[test]
fn a_dangling_link_creates_its_target() {
    let dir = TestDir::new("dangling");
    fs::create_dir(dir.join("sub")).unwrap();
    symlink("sub/made.csv", dir.join("link")).unwrap();
    let before = snapshot(&dir.path);
    write_one(&dir.join("link"), "made\n").unwrap();
    assert_eq!(read(&dir.join("sub/made.csv")), "made\n");
    assert!(
        fs::symlink_metadata(dir.join("link"))
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_only_changed(&before, &snapshot(&dir.path), &["sub/made.csv"]);
}

#[test]
fn a_symlink_loop_is_an_error() {
    let dir = TestDir::new("loop");
    symlink("b", dir.join("a")).unwrap();
    symlink("a", dir.join("b")).unwrap();
    let before = snapshot(&dir.path);
    let err = write_one(&dir.join("a"), "x").unwrap_err();
    assert_eq!(
        err.to_string(),
        format!(
            "-o: cannot write `{}`: too many levels of symbolic links",
            dir.join("a").display()
        )
    );
    assert_only_changed(&before, &snapshot(&dir.path), &[]);
}

#[test]
fn a_long_chain_of_links_is_followed_up_to_forty() {
    let dir = TestDir::new("chain40");
    dir.file("end", "old");
    let mut prev = "end".to_string();
    for i in 0..41 {
        let name = format!("l{i}");
        symlink(&prev, dir.join(&name)).unwrap();
        prev = name;
    }
    write_one(&dir.join("l39"), "forty").unwrap();
    assert_eq!(read(&dir.join("end")), "forty");
    let err = write_one(&dir.join("l40"), "forty-one").unwrap_err();
    assert!(
        err.to_string()
            .ends_with("too many levels of symbolic links")
    );
    assert_eq!(read(&dir.join("end")), "forty");
}

#[test]
fn several_outputs_and_a_new_directory() {
    let dir = TestDir::new("several");
    let a = dir.file("a.json", "{}");
    let before = snapshot(&dir.path);
    let mut o = Outputs::new();
    o.add("--json", Target::Path(a.clone()), "{\"a\":1}");
    o.add_in_dir("--plot", dir.join("plots/deep"), "p.svg", "<svg/>");
    o.add_in_dir("--plot", dir.join("plots/deep"), "q.svg", "<svg></svg>");
    assert_eq!(o.len(), 3);
    o.check().unwrap();
    let written = o.write_all().unwrap();
    let names: Vec<String> = written.iter().map(|w| w.label.clone()).collect();
    assert_eq!(names, ["--json", "--plot", "--plot"]);
    assert_eq!(read(&a), "{\"a\":1}");
    assert_eq!(read(&dir.join("plots/deep/p.svg")), "<svg/>");
    assert_eq!(read(&dir.join("plots/deep/q.svg")), "<svg></svg>");
    assert_only_changed(
        &before,
        &snapshot(&dir.path),
        &[
            "a.json",
            "plots",
            "plots/deep",
            "plots/deep/p.svg",
            "plots/deep/q.svg",
        ],
    );
}
