//! The input files of a report and of a recorded check are hashed from the bytes the verb read:
//! `rtest report` looks for the files a report names relative to the report's directory (or
//! `--data-dir`), refuses an absolute name or one that leaves it, and hashes only regular files
//! (a FIFO is listed as not hashed and never opened); `identify --report` and `--record` of a
//! record given through a FIFO finish, with the digest of the bytes written into it.
//!
//! Every run of the binary that could wait on a FIFO is given 60 s, then killed: a regression
//! fails the test instead of hanging it.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::{self, mkfifo, temp_dir};
use common::{TempDir, check_fails, entries, ok, run};
use history::sha256::sha256_hex;

/// `k4.csv` of seed-ac with the demo truth, and `id.json`: the reduced model identified on it.
fn set_up(name: &str) -> TempDir {
    let dir = temp_dir(name);
    ok(
        &dir,
        &[
            "simulate",
            "--machine",
            "seed-ac",
            "--path",
            "K4",
            "--truth",
            "seed-ac-demo",
            "--seed",
            "1",
            "-o",
            "k4.csv",
        ],
    );
    ok(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "k4.csv",
            "--json",
            "id.json",
        ],
    );
    dir
}

/// `id.json` of `dir` with every `"k4.csv"` replaced by `name` (as a JSON string), written to
/// `to`.
fn naming(dir: &Path, name: &str, to: &Path) {
    let text = std::fs::read_to_string(dir.join("id.json")).unwrap();
    let quoted = serde_json::to_string(name).unwrap();
    assert!(text.contains("\"k4.csv\""));
    std::fs::write(to, text.replace("\"k4.csv\"", &quoted)).unwrap();
}

/// Runs the binary with `args` in `dir`, for at most 60 s (then it is killed and the test
/// fails); its exit code, standard output and standard error.
fn run_bounded(dir: &Path, args: &[&str]) -> (Option<i32>, String, String) {
    let out_path = dir.join(".stdout");
    let err_path = dir.join(".stderr");
    let mut child = Command::new(env!("CARGO_BIN_EXE_rtest"))
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out_path).unwrap())
        .stderr(std::fs::File::create(&err_path).unwrap())
        .spawn()
        .expect("the rtest binary runs");
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("rtest {args:?} did not finish within 60 s: it waits on a FIFO");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let out = std::fs::read_to_string(&out_path).unwrap();
    let err = std::fs::read_to_string(&err_path).unwrap();
    std::fs::remove_file(out_path).unwrap();
    std::fs::remove_file(err_path).unwrap();
    (status.code(), out, err)
}

/// The `(path, bytes, sha256)` of every row of the report's input files table.
fn hashed_files(html: &str) -> Vec<(String, String, String)> {
    let start = html
        .find("<caption>Input files")
        .expect("an input files table");
    let end = start + html[start..].find("</table>").unwrap();
    html[start..end]
        .split("<tr>")
        .skip(2)
        .map(|row| {
            let cells: Vec<&str> = row
                .split("<td")
                .skip(1)
                .map(|c| {
                    let c = &c[c.find('>').unwrap() + 1..];
                    let c = &c[..c.find("</td>").unwrap()];
                    c.trim_start_matches("<span class=\"hash\">")
                        .trim_end_matches("</span>")
                })
                .collect();
            (
                cells[1].to_string(),
                cells[2].to_string(),
                cells[4].to_string(),
            )
        })
        .collect()
}

#[test]
fn a_name_that_is_absolute_or_leaves_the_reports_directory_is_refused() {
    let dir = set_up("refused");
    std::fs::create_dir(dir.join("sub")).unwrap();
    let absolute: PathBuf = std::fs::canonicalize(dir.join("k4.csv")).unwrap();
    let absolute = absolute.display().to_string();
    naming(&dir, &absolute, &dir.join("abs.json"));
    naming(&dir, "../k4.csv", &dir.join("sub/up.json"));
    naming(&dir, "sub/../../k4.csv", &dir.join("sub2.json"));
    let before = entries(&dir);
    for (json, name, what) in [
        ("abs.json", absolute.as_str(), "an absolute path"),
        (
            "sub/up.json",
            "../k4.csv",
            "a path that leaves the report's directory",
        ),
        (
            "sub2.json",
            "sub/../../k4.csv",
            "a path that leaves the report's directory",
        ),
    ] {
        let args = ["report", json, "-o", "r.html"];
        let o = run(Some(&dir), &args);
        check_fails(
            &o,
            &args,
            1,
            &[
                json,
                "field `records[0].data`",
                &format!("`{name}` is {what}"),
            ],
        );
        // With --data-dir the name is still refused.
        let args = ["report", json, "--data-dir", ".", "-o", "r.html"];
        let o = run(Some(&dir), &args);
        check_fails(&o, &args, 1, &[json, "records[0].data", name, "--data-dir"]);
    }
    // Nothing written.
    assert_eq!(entries(&dir), before);
}

#[test]
fn names_are_read_beside_the_report_or_in_the_data_directory() {
    let dir = set_up("data-dir");
    let sha = sha256_hex(&std::fs::read(dir.join("k4.csv")).unwrap());
    std::fs::create_dir(dir.join("sub")).unwrap();
    std::fs::copy(dir.join("id.json"), dir.join("sub/id.json")).unwrap();
    // Beside the report: sub/k4.csv does not exist, so it is listed without a hash.
    ok(&dir, &["report", "sub/id.json", "-o", "beside.html"]);
    let html = std::fs::read_to_string(dir.join("beside.html")).unwrap();
    let files = hashed_files(&html);
    assert_eq!(files[1].0, "sub/k4.csv", "{files:?}");
    assert!(
        files[1].2.starts_with("not hashed: cannot be read here"),
        "{files:?}"
    );
    assert!(
        html.contains("k4.csv is not drawn: sub/k4.csv: cannot be read here"),
        "the figure says where the record was looked for"
    );
    // In --data-dir: found, hashed and drawn.
    ok(
        &dir,
        &[
            "report",
            "sub/id.json",
            "--data-dir",
            ".",
            "-o",
            "in-dir.html",
        ],
    );
    let html = std::fs::read_to_string(dir.join("in-dir.html")).unwrap();
    let files = hashed_files(&html);
    assert_eq!(files[0].0, "sub/id.json");
    assert_eq!(
        files[0].2,
        sha256_hex(&std::fs::read(dir.join("sub/id.json")).unwrap())
    );
    assert_eq!(files[1].0, "./k4.csv", "{files:?}");
    assert_eq!(files[1].2, sha, "{files:?}");
    assert!(html.contains("<figure id=\"fig-k4-path\">"));
    // A --data-dir that is no directory is refused, naming the flag.
    let before = entries(&dir);
    let args = [
        "report",
        "sub/id.json",
        "--data-dir",
        "k4.csv",
        "-o",
        "x.html",
    ];
    check_fails(
        &run(Some(&dir), &args),
        &args,
        2,
        &["--data-dir: `k4.csv` is not a directory"],
    );
    assert_eq!(entries(&dir), before);
    // A name inside the report's directory through `..` is accepted.
    naming(&dir, "sub/../k4.csv", &dir.join("inside.json"));
    ok(&dir, &["report", "inside.json", "-o", "inside.html"]);
    let files = hashed_files(&std::fs::read_to_string(dir.join("inside.html")).unwrap());
    assert_eq!(files[1].2, sha, "{files:?}");
}

#[test]
fn a_fifo_named_by_a_report_is_listed_not_hashed_and_never_opened() {
    let dir = set_up("fifo-named");
    mkfifo(&dir.join("f.csv"));
    naming(&dir, "f.csv", &dir.join("fifo.json"));
    // Nobody writes into the FIFO: opening it to read would wait forever.
    let (code, out, err) = run_bounded(&dir, &["report", "fifo.json", "-o", "r.html"]);
    assert_eq!(code, Some(0), "{out}{err}");
    let html = std::fs::read_to_string(dir.join("r.html")).unwrap();
    let files = hashed_files(&html);
    assert_eq!(files[1].0, "f.csv");
    assert_eq!(files[1].1, "–");
    assert_eq!(files[1].2, "not hashed: not a regular file", "{files:?}");
    assert!(html.contains("f.csv is not drawn: f.csv: not a regular file"));
    // A directory is no regular file either.
    std::fs::create_dir(dir.join("d.csv")).unwrap();
    naming(&dir, "d.csv", &dir.join("dir.json"));
    ok(&dir, &["report", "dir.json", "-o", "d.html"]);
    let files = hashed_files(&std::fs::read_to_string(dir.join("d.html")).unwrap());
    assert_eq!(files[1].2, "not hashed: not a regular file", "{files:?}");
}

#[test]
fn a_record_read_from_a_fifo_is_hashed_as_read_for_the_report_and_the_history() {
    let dir = set_up("fifo-data");
    let bytes = std::fs::read(dir.join("k4.csv")).unwrap();
    let sha = sha256_hex(&bytes);
    let fifo = dir.join("k4-fifo.csv");
    mkfifo(&fifo);
    // The writer opens the FIFO (waiting for the reader), writes the record once and closes it.
    let writer = {
        let (fifo, bytes) = (fifo.clone(), bytes.clone());
        std::thread::spawn(move || std::fs::write(fifo, bytes))
    };
    let (code, out, err) = run_bounded(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "k4-fifo.csv",
            "--report",
            "r.html",
            "--record",
            "--db",
            "h.sqlite",
            "--machine-id",
            "SN-1",
        ],
    );
    assert_eq!(code, Some(0), "{out}{err}");
    writer.join().unwrap().unwrap();
    let files = hashed_files(&std::fs::read_to_string(dir.join("r.html")).unwrap());
    assert_eq!(
        files[0],
        (
            "k4-fifo.csv".to_string(),
            bytes.len().to_string(),
            sha.clone()
        )
    );
    let listing = ok(
        &dir,
        &["history", "--db", "h.sqlite", "--json", "list.json"],
    );
    assert!(listing.contains("SN-1"), "{listing}");
    let list: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("list.json")).unwrap()).unwrap();
    let input = &list["checks"][0]["inputs"][0];
    assert_eq!(input["role"], "--data");
    assert_eq!(input["path"], "k4-fifo.csv");
    assert_eq!(input["bytes"], bytes.len());
    assert_eq!(input["sha256"], sha);
}

#[test]
fn the_values_and_poses_of_a_compensation_are_hashed_as_read_from_fifos() {
    let dir = set_up("fifo-compensate");
    // The poses of K4 (extra columns are kept as they are).
    let values = std::fs::read(dir.join("id.json")).unwrap();
    let poses = std::fs::read(dir.join("k4.csv")).unwrap();
    mkfifo(&dir.join("values.json"));
    mkfifo(&dir.join("poses-fifo.csv"));
    let writers: Vec<_> = [
        ("values.json", values.clone()),
        ("poses-fifo.csv", poses.clone()),
    ]
    .into_iter()
    .map(|(name, bytes)| {
        let path = dir.join(name);
        std::thread::spawn(move || std::fs::write(path, bytes))
    })
    .collect();
    let (code, out, err) = run_bounded(
        &dir,
        &[
            "compensate",
            "--machine",
            "seed-ac",
            "--params",
            "values.json",
            "--path",
            "poses-fifo.csv",
            "-o",
            "corrected.csv",
            "--report",
            "c.html",
        ],
    );
    assert_eq!(code, Some(0), "{out}{err}");
    for w in writers {
        w.join().unwrap().unwrap();
    }
    let files = hashed_files(&std::fs::read_to_string(dir.join("c.html")).unwrap());
    assert_eq!(files[0].0, "values.json");
    assert_eq!(files[0].2, sha256_hex(&values));
    assert_eq!(files[1].0, "poses-fifo.csv");
    assert_eq!(files[1].2, sha256_hex(&poses));
}
