//! `rtest segment`: a simulated R-test log of a measurement program's run, cut by its plan,
//! identifies with `rtest identify`; errors name the flag, the file, the line or the sample.

use crate::common;

use common::{fails, ok, temp_dir_tagged, words};
use formats::nc::Dialect;
use formats::truth::builtin_truth;
use programs::measure::{
    MeasureMode, MeasureOptions, StaticTiming, format_plan, measurement_program,
};
use programs::stream::{StreamOptions, write_stream};
use simulation::builtin_path;
use std::path::Path;

/// Writes `plan.csv` (K4 of seed-ac, static, every other pose) and `log.csv` (its simulated
/// run with the reduced truth, 0.2 µm noise, starting 4.5 s before the program) into `dir`.
fn files(dir: &Path) {
    let m = model_spec::builtin("seed-ac").unwrap().unwrap();
    let mut k4 = builtin_path(&m, "K4").unwrap().unwrap();
    k4.samples = k4.samples.into_iter().step_by(2).collect();
    let mode = MeasureMode::Static(StaticTiming::default());
    let p = measurement_program(&m, &k4, &MeasureOptions::new(&m, Dialect::Iso, mode)).unwrap();
    let plan = format_plan(&m, &p.plan, &["K4 every other pose".into()]).unwrap();
    std::fs::write(dir.join("plan.csv"), plan).unwrap();
    std::fs::write(dir.join("k4.nc"), &p.text).unwrap();
    let mut truth = builtin_truth("seed-ac-reduced", &m).unwrap().unwrap();
    truth.noise_mm = 2e-4;
    let o = StreamOptions {
        lead_s: 4.5,
        ..StreamOptions::default()
    };
    let mut log = Vec::new();
    write_stream(&m, &truth, &p.plan, &o, &mut log).unwrap();
    std::fs::write(dir.join("log.csv"), log).unwrap();
}

#[test]
fn a_segmented_log_identifies() {
    let dir = temp_dir_tagged("segment", "identifies");
    files(&dir);
    let out = ok(
        &dir,
        &words(
            "segment --machine seed-ac --plan plan.csv --log log.csv -o rec.csv --windows win.csv",
        ),
    );
    assert!(
        out.starts_with("Segmented log.csv into 121 samples (static plan): "),
        "{out}"
    );
    assert!(
        out.contains("Program start on the log's clock (t_s): 4.5"),
        "{out}"
    );
    assert!(
        out.contains("Alignment: 121 of 121 poses at an edge of their still period"),
        "{out}"
    );
    assert!(out.contains("Flagged windows: none\n"), "{out}");
    assert!(out.ends_with("Wrote rec.csv\nWrote win.csv\n"), "{out}");
    let rec = std::fs::read_to_string(dir.join("rec.csv")).unwrap();
    assert!(rec.contains("\nX,Y,Z,A,C,dx_um,dy_um,dz_um,t_s\n"), "{rec}");
    let win = std::fs::read_to_string(dir.join("win.csv")).unwrap();
    assert_eq!(win.lines().count(), 122);
    let fit = ok(
        &dir,
        &words("identify --machine seed-ac --model reduced --data rec.csv"),
    );
    assert!(fit.contains("XOC"), "{fit}");
    // The same with the start given.
    let given = ok(
        &dir,
        &words(
            "segment --machine seed-ac --plan plan.csv --log log.csv -o rec2.csv --offset-s 4.5",
        ),
    );
    assert!(given.contains("4.5 s, given"), "{given}");
}

#[test]
fn errors_name_the_flag_and_the_place() {
    let dir = temp_dir_tagged("segment", "errors");
    files(&dir);
    let base = "segment --machine seed-ac --plan plan.csv -o rec.csv --log";
    std::fs::write(dir.join("bad.csv"), "t_s,s1_um\n0,1\n0.01,x\n").unwrap();
    fails(
        &dir,
        &words(&format!("{base} bad.csv")),
        1,
        &["--log: bad.csv:3: column 2 `s1_um`: `x` is not a finite number"],
    );
    // The error vector and a sensor column: the record would hold both, which `identify`
    // refuses, so it is refused here, at the column, before the log is cut.
    let log = std::fs::read_to_string(dir.join("log.csv")).unwrap();
    let mixed: String = log
        .lines()
        .map(|l| match l {
            _ if l.starts_with('#') || l.is_empty() => format!("{l}\n"),
            _ if l.contains("dz_um") => format!("{l},s1_um\n"),
            _ => format!("{l},0.5\n"),
        })
        .collect();
    std::fs::write(dir.join("mixed.csv"), mixed).unwrap();
    fails(
        &dir,
        &words(&format!("{base} mixed.csv")),
        1,
        &[
            "--log: mixed.csv:",
            "`s1_um`: a reading column beside the error vector's `dx_um`",
        ],
    );
    let log = std::fs::read_to_string(dir.join("log.csv")).unwrap();
    let short: String = log.lines().take(20_000).collect::<Vec<_>>().join("\n");
    std::fs::write(dir.join("short.csv"), short).unwrap();
    fails(
        &dir,
        &words(&format!("{base} short.csv")),
        1,
        &["--log: short.csv:", "the log is shorter than the program"],
    );
    fails(
        &dir,
        &words(&format!("{base} missing.csv")),
        1,
        &["--log:", "missing.csv"],
    );
    fails(
        &dir,
        &words("segment --machine seed-ac --plan log.csv --log log.csv -o rec.csv"),
        1,
        &["--plan: log.csv:1: column 1 `t_s`: unknown column `t_s`"],
    );
    fails(
        &dir,
        &words(&format!("{base} log.csv --margin-s 5")),
        2,
        &["--margin-s: a margin of 5 s at each end leaves nothing"],
    );
    fails(
        &dir,
        &words(&format!("{base} log.csv --still-um 0")),
        2,
        &["--still-um"],
    );
    fails(
        &dir,
        &words("segment --machine seed-ac --plan plan.csv --log log.csv -o log.csv"),
        2,
        &["log.csv"],
    );
    assert!(!dir.join("rec.csv").exists());
}
