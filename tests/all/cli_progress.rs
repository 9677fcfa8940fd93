//! Progress bars of the long verbs (reading a record, `rtest plan`, `rtest diagnose`): never on
//! a pipe (standard error here is one), standard error the same with and without the delay
//! before a bar is drawn, and a bar drawn on a terminal (under `script` from util-linux, when
//! it is there).

use std::path::Path;
use std::process::{Command, Output};

use crate::common::{self, temp_dir};
use common::{TempDir, stderr};

/// Runs the binary in `dir` with `args`, the delay before a bar set to `delay_ms` when given.
fn run(dir: &Path, args: &[&str], delay_ms: Option<&str>) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_rtest"));
    c.args(args).current_dir(dir);
    match delay_ms {
        Some(d) => c.env("RTEST_PROGRESS_DELAY_MS", d),
        None => c.env_remove("RTEST_PROGRESS_DELAY_MS"),
    };
    c.output().expect("the rtest binary runs")
}

/// A directory with k4.csv and k1.csv simulated on seed-ac with the demo truth.
fn records(name: &str) -> TempDir {
    let dir = temp_dir(name);
    for (path, seed) in [("K4", "1"), ("K1", "2")] {
        let out = format!("{}.csv", path.to_ascii_lowercase());
        let o = run(
            &dir,
            &[
                "simulate",
                "--machine",
                "seed-ac",
                "--path",
                path,
                "--truth",
                "seed-ac-demo",
                "--seed",
                seed,
                "-o",
                &out,
            ],
            None,
        );
        assert!(o.status.success(), "simulate: {}", stderr(&o));
    }
    dir
}

/// The long verbs, each with the work that reports progress.
const VERBS: [&[&str]; 4] = [
    &[
        "identify",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--data",
        "k4.csv",
    ],
    &[
        "identify",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--data",
        "k4.csv",
        "--stream",
        "--block",
        "64",
    ],
    &[
        "plan",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--paths",
        "K1,K4",
    ],
    &[
        "diagnose",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--data",
        "k4.csv",
        "--validate",
        "k1.csv",
    ],
];

#[test]
fn no_bar_on_a_pipe_and_standard_error_unchanged() {
    let dir = records("pipe");
    for args in VERBS {
        // A delay of 0 would draw at once on a terminal; standard error is a pipe here.
        let eager = run(&dir, args, Some("0"));
        assert!(eager.status.success(), "{args:?}: {}", stderr(&eager));
        let err = stderr(&eager);
        assert!(
            !err.contains('\r'),
            "{args:?}: a carriage return on stderr: {err:?}"
        );
        assert!(
            !err.contains('\u{1b}'),
            "{args:?}: an escape sequence on stderr: {err:?}"
        );
        let plain = run(&dir, args, None);
        assert_eq!(stderr(&plain), err, "{args:?}: stderr changed");
        assert_eq!(plain.stdout, eager.stdout, "{args:?}: stdout changed");
    }
}

#[test]
fn no_bar_when_the_json_report_takes_standard_output() {
    let dir = records("json");
    let args = [
        "plan",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--paths",
        "K1,K4",
        "--json",
        "-",
    ];
    let o = run(&dir, &args, Some("0"));
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(!err.contains('\r') && !err.contains('\u{1b}'), "{err:?}");
}

/// Runs `args` under a pseudo-terminal (`script` of util-linux) in `dir`; `None` when `script`
/// cannot be run here.
fn under_terminal(dir: &Path, args: &[&str]) -> Option<String> {
    let bin = env!("CARGO_BIN_EXE_rtest");
    let command = std::iter::once(bin)
        .chain(args.iter().copied())
        .map(|a| format!("'{a}'"))
        .collect::<Vec<_>>()
        .join(" ");
    let typescript = dir.join("typescript");
    let o = Command::new("script")
        .args(["-q", "-e", "-c", &command])
        .arg(&typescript)
        .current_dir(dir)
        .env("RTEST_PROGRESS_DELAY_MS", "0")
        .output()
        .ok()?;
    if !o.status.success() {
        eprintln!("script failed ({:?}): {}", o.status.code(), stderr(&o));
        return None;
    }
    Some(String::from_utf8_lossy(&o.stdout).into_owned())
}

#[test]
fn a_bar_is_drawn_on_a_terminal_and_cleared() {
    let dir = records("terminal");
    let Some(out) = under_terminal(&dir, VERBS[2]) else {
        eprintln!("skipped: `script` (util-linux) cannot run a pseudo-terminal here");
        return;
    };
    assert!(out.contains("candidates ["), "no bar drawn: {out:?}");
    // The report follows, whole, after the bar is cleared.
    assert!(
        out.contains("Suggestion") || out.contains("suggest"),
        "{out:?}"
    );
    let Some(out) = under_terminal(&dir, VERBS[3]) else {
        return;
    };
    assert!(
        out.contains("reading k4.csv ["),
        "no bar while reading: {out:?}"
    );
    assert!(
        out.contains("diagnosis [") || out.contains("selection ["),
        "{out:?}"
    );
}

#[test]
fn a_campaign_draws_its_bars_on_a_terminal() {
    let dir = records("campaign");
    let args = [
        "identify",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--data",
        "k4.csv,k1.csv",
        "--json",
        "c.json",
    ];
    let Some(out) = under_terminal(&dir, &args) else {
        eprintln!("skipped: `script` (util-linux) cannot run a pseudo-terminal here");
        return;
    };
    assert!(
        out.contains("reading 2 records ["),
        "no bar while the records are read: {out:?}"
    );
    assert!(out.contains("Campaign identification"), "{out:?}");
    let args = [
        "validate",
        "--machine",
        "seed-ac",
        "--params",
        "c.json",
        "--data",
        "k4.csv,k1.csv",
    ];
    let Some(out) = under_terminal(&dir, &args) else {
        return;
    };
    assert!(out.contains("reading 2 records ["), "{out:?}");
    assert!(
        out.contains("validating records ["),
        "no bar while the records are validated: {out:?}"
    );
    assert!(out.contains("Validation on 2 records"), "{out:?}");
}
