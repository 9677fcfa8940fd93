//! FIFOs and standard output: written directly, after the files.

use std::fs;
use std::os::unix::fs::{FileTypeExt, symlink};
use std::path::PathBuf;
use std::thread;

use crate::common::{
    TestDir, assert_only_changed, child_command, is_child, mkfifo, read, snapshot,
};
use output::{Outputs, Target};

/// Reads a FIFO to its end on another thread.
fn reader(fifo: PathBuf) -> thread::JoinHandle<Vec<u8>> {
    thread::spawn(move || fs::read(fifo).unwrap())
}

#[test]
fn a_fifo_is_written_directly_and_stays_a_fifo() {
    let dir = TestDir::new("fifo");
    let fifo = dir.join("pipe");
    mkfifo(&fifo);
    let before = snapshot(&dir.path);
    // More than a pipe holds, so the writer really waits for the reader.
    let contents: Vec<u8> = (0..200_000u32).map(|i| (i % 251) as u8).collect();
    let r = reader(fifo.clone());
    let mut o = Outputs::new();
    o.add("--json", Target::Path(fifo.clone()), contents.clone());
    o.write_all().unwrap();
    assert_eq!(r.join().unwrap(), contents);
    assert!(fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
    assert_only_changed(&before, &snapshot(&dir.path), &[]);
}

#[test]
fn a_symlink_to_a_fifo_writes_the_fifo() {
    let dir = TestDir::new("fifo_link");
    let fifo = dir.join("pipe");
    mkfifo(&fifo);
    symlink("pipe", dir.join("link")).unwrap();
    let before = snapshot(&dir.path);
    let r = reader(fifo.clone());
    let mut o = Outputs::new();
    o.add("-o", Target::Path(dir.join("link")), "through the link\n");
    o.write_all().unwrap();
    assert_eq!(r.join().unwrap(), b"through the link\n");
    assert!(fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
    assert!(
        fs::symlink_metadata(dir.join("link"))
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_only_changed(&before, &snapshot(&dir.path), &[]);
}

#[test]
fn the_fifo_is_written_after_the_files() {
    let dir = TestDir::new("fifo_last");
    let fifo = dir.join("pipe");
    mkfifo(&fifo);
    let file = dir.file("a.csv", "old");
    // The reader looks at the file as soon as the FIFO is opened: it must be in place already.
    let r = {
        let (fifo, file) = (fifo.clone(), file.clone());
        thread::spawn(move || {
            let mut f = fs::File::open(&fifo).unwrap();
            let seen = read(&file);
            // Read the stream to its end: closing it early would break the writer's pipe.
            let mut rest = Vec::new();
            std::io::Read::read_to_end(&mut f, &mut rest).unwrap();
            seen
        })
    };
    let mut o = Outputs::new();
    o.add("--json", Target::Path(fifo), "{}");
    o.add("-o", Target::Path(file.clone()), "new");
    o.write_all().unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(r.join().unwrap(), "new");
}

const STDOUT_CONTENTS: &[u8] = b"x,y\n1,2\n\xff\x00binary tail without newline";

#[test]
fn stdout_gets_exactly_the_contents() {
    const TEST: &str = "streams::stdout_gets_exactly_the_contents";
    if is_child(TEST) {
        let mut o = Outputs::new();
        o.add("-o", Target::parse("-"), STDOUT_CONTENTS);
        let written = o.write_all().unwrap();
        assert_eq!(written[0].to_string(), "standard output");
        std::process::exit(0); // before the test harness prints its result line
    }
    let dir = TestDir::new(TEST);
    let exe = std::env::current_exe().unwrap();
    let out = child_command(&exe, TEST, &dir.path).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The harness prints "running 1 test" first; what follows is ours alone.
    let ours = out
        .stdout
        .strip_suffix(STDOUT_CONTENTS)
        .unwrap_or_else(|| panic!("stdout: {:?}", String::from_utf8_lossy(&out.stdout)));
    assert!(!String::from_utf8_lossy(ours).contains("x,y"));
}

#[test]
fn stdout_is_not_written_when_a_file_fails() {
    const TEST: &str = "streams::stdout_is_not_written_when_a_file_fails";
    if is_child(TEST) {
        let dir = crate::common::child_dir();
        let mut o = Outputs::new();
        o.add("-o", Target::Stdout, STDOUT_CONTENTS);
        o.add("--json", Target::Path(dir.join("missing/a.json")), "{}");
        let err = o.write_all().unwrap_err();
        assert!(err.to_string().starts_with("--json: cannot write"), "{err}");
        std::process::exit(0);
    }
    let dir = TestDir::new(TEST);
    let exe = std::env::current_exe().unwrap();
    let out = child_command(&exe, TEST, &dir.path).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(!String::from_utf8_lossy(&out.stdout).contains("x,y"));
}

#[test]
fn standard_output_redirected_to_an_output_file_is_refused() {
    const TEST: &str = "streams::standard_output_redirected_to_an_output_file_is_refused";
    if is_child(TEST) {
        let dir = crate::common::child_dir();
        let mut o = Outputs::new();
        o.add("-o", Target::Stdout, "table\n");
        o.add("--json", Target::Path(dir.join("./out.txt")), "{}");
        let err = o.write_all().unwrap_err();
        eprintln!("ERROR: {err}");
        std::process::exit(0);
    }
    let dir = TestDir::new(TEST);
    let out = dir.file("out.txt", "");
    let exe = std::env::current_exe().unwrap();
    let child = child_command(&exe, TEST, &dir.path)
        .stdout(fs::File::create(&out).unwrap())
        .output()
        .unwrap();
    assert!(child.status.success());
    let stderr = String::from_utf8_lossy(&child.stderr);
    let expected = format!(
        "ERROR: --json: `{}` is also the output of -o (standard output)\n",
        dir.join("./out.txt").display()
    );
    assert!(stderr.contains(&expected), "{stderr}");
    assert!(!read(&out).contains("table"));
}

#[test]
fn a_character_device_stays_a_device() {
    // A null device node made in the test's own directory (root only; skipped where the
    // system does not allow it).
    let dir = TestDir::new("char_device");
    let node = dir.join("null");
    let c = std::ffi::CString::new(node.as_os_str().as_encoded_bytes()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    let rc = unsafe { libc::mknod(c.as_ptr(), libc::S_IFCHR | 0o666, libc::makedev(1, 3)) };
    if rc != 0 || fs::OpenOptions::new().write(true).open(&node).is_err() {
        return;
    }
    symlink("null", dir.join("link")).unwrap();
    let before = snapshot(&dir.path);
    let mut o = Outputs::new();
    o.add("-o", Target::Path(node.clone()), "discarded");
    // Two outputs may share a character device (nothing is lost writing twice to it).
    o.add("--json", Target::Path(dir.join("link")), "discarded too");
    o.write_all().unwrap();
    assert!(
        fs::symlink_metadata(&node)
            .unwrap()
            .file_type()
            .is_char_device()
    );
    assert_only_changed(&before, &snapshot(&dir.path), &[]);
}
