//! End-to-end tests of `rtest compensate`: a record simulated and identified with the binary,
//! then poses (CSV) and programs (ISO, Heidenhain) compensated; the corrected values equal the
//! library's; every line but the corrected words kept; the corrected description and the
//! tables written; bad input refused with one stderr line, the right exit code and no output.

use compensation::run::{CommandedPose, compensate_poses};
use compensation::values::MachineErrors;
use model_spec::{AxisKind, Machine};
use report::json::read_identification;
use std::path::Path;

use crate::common;
use common::{TempDir, entries, fails, ok, read_json};

fn machine() -> Machine {
    model_spec::builtin("seed-ac").unwrap().unwrap()
}

/// A directory with `k4.csv` (demo truth) and `id.json` (reduced + ECC@harmonic:2 on K4), and
/// `poses.csv`: the first 40 poses of K4 with an extra `note` column.
fn set_up(name: &str) -> TempDir {
    let dir = common::temp_dir_tagged("cli-comp", name);
    let d = &dir.0;
    ok(
        d,
        &[
            "simulate",
            "--machine",
            "seed-ac",
            "--path",
            "K4",
            "--truth",
            "seed-ac-demo",
            "-o",
            "k4.csv",
        ],
    );
    ok(
        d,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--terms",
            "ECC@harmonic:2",
            "--data",
            "k4.csv",
            "--json",
            "id.json",
        ],
    );
    let k4 = std::fs::read_to_string(d.join("k4.csv")).unwrap();
    let mut csv = String::from("X,Y,Z,A,C,note\n");
    for (i, line) in k4
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .take(40)
        .enumerate()
    {
        let f: Vec<&str> = line.split(',').take(5).collect();
        csv.push_str(&format!("{},\"pose {i}, kept\"\n", f.join(",")));
    }
    std::fs::write(d.join("poses.csv"), csv).unwrap();
    dir
}

/// The library's corrected poses of `poses.csv` (mm and degrees, in the file's column order).
fn library(dir: &Path) -> Vec<Vec<f64>> {
    let m = machine();
    let id = read_identification(&dir.join("id.json"), &m).unwrap();
    let (errors, _) = MachineErrors::from_values(&m, &id.values, &id.file).unwrap();
    let text = std::fs::read_to_string(dir.join("poses.csv")).unwrap();
    // Columns X, Y, Z, A, C; machine axes X, A, C, Y, Z.
    let column: Vec<usize> = ["X", "Y", "Z", "A", "C"]
        .iter()
        .map(|n| m.axis_by_name(n).unwrap())
        .collect();
    let poses: Vec<CommandedPose> = text
        .lines()
        .skip(1)
        .enumerate()
        .map(|(i, l)| {
            let mut commands = vec![0.0; 5];
            for (v, &a) in l.split(',').take(5).zip(&column) {
                let x: f64 = v.parse().unwrap();
                commands[a] = if m.axes[a].kind == AxisKind::Rotary {
                    x.to_radians()
                } else {
                    x
                };
            }
            CommandedPose {
                line: i + 2,
                commands,
            }
        })
        .collect();
    let values_at = |q: &[f64], out: &mut [f64]| errors.values_at(&m, q, out);
    let done = compensate_poses(
        &m,
        errors.errors(),
        m.default_parameters(),
        "poses.csv",
        &poses,
        &values_at,
    )
    .unwrap();
    done.poses
        .iter()
        .map(|q| {
            column
                .iter()
                .map(|&a| {
                    if m.axes[a].kind == AxisKind::Rotary {
                        q[a].to_degrees()
                    } else {
                        q[a]
                    }
                })
                .collect()
        })
        .collect()
}

#[test]
fn csv_poses_corrected_as_the_library_does_other_columns_kept() {
    let dir = set_up("csv");
    let d = &dir.0;
    let text = ok(
        d,
        &[
            "compensate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--path",
            "poses.csv",
            "-o",
            "out.csv",
            "--json",
            "comp.json",
        ],
    );
    assert!(text.contains("Compensated: 9 machine error(s)"), "{text}");
    assert!(text.contains("XOW: a set-up error"), "{text}");
    let out = std::fs::read_to_string(d.join("out.csv")).unwrap();
    let expected = library(d);
    let input = std::fs::read_to_string(d.join("poses.csv")).unwrap();
    for ((line, inp), want) in out
        .lines()
        .skip(1)
        .zip(input.lines().skip(1))
        .zip(&expected)
    {
        let fields: Vec<&str> = line.splitn(6, ',').collect();
        let got: Vec<f64> = fields[..5].iter().map(|v| v.parse().unwrap()).collect();
        assert_eq!(&got, want, "corrected values read back bit for bit");
        assert_eq!(fields[5], inp.splitn(6, ',').nth(5).unwrap(), "note kept");
    }
    let json = read_json(&d.join("comp.json"));
    assert_eq!(json["poses"], 40);
    assert_eq!(json["format"], "csv");
    assert!(json["position_remainder_um"].as_f64().unwrap() < 1e-3);
    assert_eq!(json["axes"].as_array().unwrap().len(), 5);
    assert!(json["axes"][0]["rounding"].is_null());
    let left: Vec<&str> = json["left_out"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["term"].as_str().unwrap())
        .collect();
    assert_eq!(left, ["XOW", "YOW", "ZOW"]);
}

#[test]
fn iso_program_keeps_every_other_byte() {
    let dir = set_up("iso");
    let d = &dir.0;
    let program = "%\r\nO1000 (R-TEST CHECK)\r\nG21 G90 G94\r\nN10 G0 X217.5040 Y-0.2790 Z56.6610 A0.0000 C0.0000\r\nN20 G1 A-30.0000 C45.0000 F1000 ; tilt\r\n(comment)\r\nN30 G1 X210.1230 Y-10.5000\r\nM30\r\n%\r\n";
    std::fs::write(d.join("p.nc"), program).unwrap();
    let text = ok(
        d,
        &[
            "compensate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--path",
            "p.nc",
            "--nc",
            "iso",
            "-o",
            "out.nc",
        ],
    );
    assert!(text.contains("3 poses, iso"), "{text}");
    let out = std::fs::read_to_string(d.join("out.nc")).unwrap();
    let (a, b): (Vec<&str>, Vec<&str>) = (
        program.split_inclusive('\n').collect(),
        out.split_inclusive('\n').collect(),
    );
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        if x.contains("G1") || x.contains("G0") {
            // Outside the axis words, the same bytes.
            let strip = |s: &str| -> String {
                s.split(' ')
                    .filter(|w| !w.starts_with(['X', 'Y', 'Z', 'A', 'C']))
                    .collect::<Vec<_>>()
                    .join(" ")
            };
            assert_eq!(strip(x), strip(y), "{x:?} -> {y:?}");
            assert_ne!(x, y, "the pose line was corrected");
        } else {
            assert_eq!(x, y);
        }
    }
}

#[test]
fn heidenhain_program_compensated() {
    let dir = set_up("heidenhain");
    let d = &dir.0;
    let program = "0 BEGIN PGM TEST MM\n1 L X+217.504 Y-0.279 Z+56.661 A+0 C+0 R0 FMAX\n2 L A-30.000 C+45.000 F1000\n3 END PGM TEST MM\n";
    std::fs::write(d.join("p.h"), program).unwrap();
    ok(
        d,
        &[
            "compensate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--path",
            "p.h",
            "--nc",
            "heidenhain",
            "--decimals",
            "4",
            "-o",
            "out.h",
        ],
    );
    let out = std::fs::read_to_string(d.join("out.h")).unwrap();
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines[0], "0 BEGIN PGM TEST MM");
    assert_eq!(lines[3], "3 END PGM TEST MM");
    // Four decimals asked for; signs kept; the modal axes of block 2 inserted after its last
    // axis word, before the feed.
    let words: Vec<&str> = lines[1].split(' ').collect();
    assert_eq!(words[..2], ["1", "L"]);
    assert_eq!(words[7..], ["R0", "FMAX"]);
    for (w, axis) in words[2..7].iter().zip(["X+", "Y-", "Z+", "A", "C"]) {
        assert!(w.starts_with(axis), "{w}");
        assert_eq!(w.split('.').nth(1).unwrap().len(), 4, "{w}");
    }
    assert_ne!(words[5], "A+0", "A corrected at the singular pose");
    let block2: Vec<&str> = lines[2].split(' ').collect();
    assert_eq!(block2.len(), 8, "{}", lines[2]);
    assert_eq!(block2[7], "F1000");
}

#[test]
fn description_and_tables_written() {
    let dir = set_up("tables");
    let d = &dir.0;
    let text = ok(
        d,
        &[
            "compensate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--kinematics-out",
            "corrected.toml",
            "--tables",
            "tables",
            "--pitch-deg",
            "10",
        ],
    );
    assert!(text.contains("folded: XOC"), "{text}");
    // C's angular location errors turn its direction; A's (a tilted A) cannot be folded.
    assert!(
        text.contains("into the direction of C: (0, 0, 1) -> ("),
        "{text}"
    );
    assert!(text.contains("not folded: BOA"), "{text}");
    assert!(!text.contains("not folded: AOC"), "{text}");
    assert_eq!(entries(&d.join("tables")), ["axis_C.csv"]);
    let table = std::fs::read_to_string(d.join("tables/axis_C.csv")).unwrap();
    let rows = table.lines().filter(|l| !l.starts_with('#')).count();
    assert_eq!(rows, 1 + 37, "header and 0..360 every 10 degrees: {table}");
    let corrected = std::fs::read_to_string(d.join("corrected.toml")).unwrap();
    model_spec::parse_machine("corrected.toml", &corrected).unwrap();
}

#[test]
fn bad_input_refused_without_output() {
    let dir = set_up("bad");
    let d = &dir.0;
    let base = ["compensate", "--machine", "seed-ac", "--params", "id.json"];
    let with = |extra: &[&'static str]| -> Vec<&'static str> {
        base.iter().copied().chain(extra.iter().copied()).collect()
    };
    // Nothing asked for, --json without poses: usage errors.
    fails(d, &with(&[]), 2, &["nothing to write"]);
    fails(
        d,
        &with(&["--tables", "t", "--json", "c.json"]),
        2,
        &["--json"],
    );
    // An incremental move, an arc: the line is named, nothing written.
    std::fs::write(d.join("g91.nc"), "G90\nG0 X1 Y1 Z1 A0 C0\nG91\nG1 X1\n").unwrap();
    fails(
        d,
        &with(&["--path", "g91.nc", "--nc", "iso", "-o", "o.nc"]),
        1,
        &["g91.nc", "3"],
    );
    std::fs::write(d.join("arc.nc"), "G90\nG0 X1 Y1 Z1 A0 C0\nG2 X2 Y2 I1 J0\n").unwrap();
    fails(
        d,
        &with(&["--path", "arc.nc", "--nc", "iso", "-o", "o.nc"]),
        1,
        &["arc.nc", "3"],
    );
    // A commanded pose outside a stroke.
    std::fs::write(d.join("far.csv"), "X,Y,Z,A,C\n0,0,0,0,0\n9999,0,0,0,0\n").unwrap();
    fails(
        d,
        &with(&["--path", "far.csv", "-o", "o.csv"]),
        1,
        &["far.csv", "line 3"],
    );
    // A corrected pose that leaves the stroke: X at its limit, corrected outwards.
    let m = machine();
    let x = m.axis_by_name("X").unwrap();
    let [lo, hi] = m.axes[x].limits;
    let probe = format!("X,Y,Z,A,C\n{lo},0,0,-30,45\n{hi},0,0,-30,45\n");
    std::fs::write(d.join("edge.csv"), probe).unwrap();
    fails(
        d,
        &with(&["--path", "edge.csv", "-o", "o.csv"]),
        1,
        &["edge.csv", "leave a stroke or range"],
    );
    // Values from another machine.
    std::fs::write(d.join("bc.csv"), "X,Y,Z,B,C\n0,0,0,0,0\n").unwrap();
    fails(
        d,
        &[
            "compensate",
            "--machine",
            "head-table-bc",
            "--params",
            "id.json",
            "--path",
            "bc.csv",
            "-o",
            "o.csv",
        ],
        1,
        &["--params", "seed-ac"],
    );
    // A rank-deficient identification: the undetermined term is named.
    ok(
        d,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--terms",
            "XOW,YOW,ZOW,XOC,YOC,AOC,BOC,dx0",
            "--data",
            "k4.csv",
            "--json",
            "deficient.json",
        ],
    );
    fails(
        d,
        &[
            "compensate",
            "--machine",
            "seed-ac",
            "--params",
            "deficient.json",
            "--path",
            "poses.csv",
            "-o",
            "o.csv",
        ],
        1,
        &["XOC", "--constraint"],
    );
    for f in ["o.nc", "o.csv", "t", "c.json"] {
        assert!(!d.join(f).exists(), "{f} written on failure");
    }
}

/// A program of more poses than rtest reads, or poses outside a stroke by the dozen: refused
/// before any pose is corrected, with the file and the limit, or the first poses and the count
/// of the others; nothing written.
#[test]
fn too_many_poses_refused_before_the_correction() {
    use formats::poses::MAX_POSES;
    let dir = set_up("limit");
    let d = &dir.0;
    let mut long = String::with_capacity(3 * MAX_POSES + 64);
    long.push_str("G90 G1 X0 Y0 Z0 A-30 C0\n");
    for _ in 0..MAX_POSES {
        long.push_str("C1\n");
    }
    std::fs::write(d.join("long.nc"), long).unwrap();
    let args = [
        "compensate",
        "--machine",
        "seed-ac",
        "--params",
        "id.json",
        "--path",
        "long.nc",
        "--nc",
        "iso",
        "-o",
        "o.nc",
    ];
    let limit = format!("more than {MAX_POSES} poses");
    let err = fails(d, &args, 1, &["--path", "long.nc", &limit]);
    assert!(err.contains(&format!("line {}", MAX_POSES + 1)), "{err}");
    let mut far = String::from("X,Y,Z,A,C\n0,0,0,0,0\n");
    for _ in 0..12 {
        far.push_str("9999,0,0,0,0\n");
    }
    std::fs::write(d.join("far.csv"), far).unwrap();
    let err = fails(
        d,
        &[
            "compensate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--path",
            "far.csv",
            "-o",
            "o.csv",
        ],
        1,
        &[
            "far.csv: 12 commanded pose(s) are outside",
            "line 3:",
            "and 2 more",
        ],
    );
    assert!(
        err.contains("line 12:") && !err.contains("line 13:"),
        "{err}"
    );
    for f in ["o.nc", "o.csv"] {
        assert!(!d.join(f).exists(), "{f} written on failure");
    }
}

/// The loop in commands: compensate K4, run the compensated path on the machine (the record
/// labelled with the program's poses, as a compensating controller reports them), identify
/// again: the compensated errors are gone (within the two identifications' noise), the ball's
/// set-up is untouched.
#[test]
fn identify_after_compensation_finds_the_errors_gone() {
    let dir = set_up("loop");
    let d = &dir.0;
    ok(
        d,
        &[
            "compensate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--path",
            "k4.csv",
            "-o",
            "k4c.csv",
        ],
    );
    ok(
        d,
        &[
            "simulate",
            "--machine",
            "seed-ac",
            "--path",
            "k4c.csv",
            "--commanded",
            "k4.csv",
            "--truth",
            "seed-ac-demo",
            "--seed",
            "5",
            "-o",
            "after.csv",
        ],
    );
    ok(
        d,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--terms",
            "ECC@harmonic:2",
            "--data",
            "after.csv",
            "--json",
            "after.json",
        ],
    );
    let (before, after) = (
        read_json(&d.join("id.json")),
        read_json(&d.join("after.json")),
    );
    for (b, a) in before["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .zip(after["parameters"].as_array().unwrap())
    {
        let name = a["name"].as_str().unwrap();
        let (vb, sb) = (b["value"].as_f64().unwrap(), b["std"].as_f64().unwrap());
        let (va, sa) = (a["value"].as_f64().unwrap(), a["std"].as_f64().unwrap());
        let combined = (sa * sa + sb * sb).sqrt();
        if name.ends_with("OW") {
            assert!(
                (va - vb).abs() < 4.0 * combined,
                "{name}: set-up {vb} -> {va}"
            );
        } else {
            assert!(
                va.abs() < 4.0 * combined,
                "{name}: {vb} -> {va} ± {combined}"
            );
            assert!(vb.abs() > 5.0 * combined, "{name} was there before: {vb}");
        }
    }
    // The poses of another program: refused, nothing written.
    fails(
        d,
        &[
            "simulate",
            "--machine",
            "seed-ac",
            "--path",
            "k4c.csv",
            "--commanded",
            "poses.csv",
            "-o",
            "x.csv",
        ],
        1,
        &["--commanded", "40 poses", "241 samples"],
    );
    assert!(!d.join("x.csv").exists());
}

/// The RMS of the readings of a measurement CSV written by `rtest simulate`, µm.
fn readings_rms(path: &Path) -> f64 {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let cols: Vec<usize> = ["dx_um", "dy_um", "dz_um"]
        .iter()
        .map(|c| header.iter().position(|h| h == c).unwrap())
        .collect();
    let (mut sum, mut n) = (0.0, 0usize);
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        for &c in &cols {
            let x: f64 = f[c].parse().unwrap();
            sum += x * x;
            n += 1;
        }
    }
    (sum / n as f64).sqrt()
}

/// The terms a compensation report lists as left out.
fn left_out(json: &serde_json::Value) -> Vec<String> {
    json["left_out"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["term"].as_str().unwrap().to_string())
        .collect()
}

/// Every location error of `table-table-bc`'s model with its squareness, a value each (µm,
/// µrad), as `[errors]` lines of a truth.
const TABLE_TABLE_ERRORS: &str = "XOB = 15.0\nZOB = -10.0\nAOB = 20.0\nCOB = -15.0\nXOC = 12.0\nYOC = -9.0\nAOC = 25.0\nBOC = -18.0\nCOY = 10.0\nAOZ = -12.0\nBOZ = 8.0\n";

/// A campaign of `table-table-bc`: two ball set-ups (the ball at the default height and 80 mm
/// higher), three records, each set-up's ball off its place by its own amount, each record with
/// its own zero drift (`dz0@time:1`). Its identification compensates the machine's shared errors
/// only; the set-up and record terms are listed as left out; on the exact machine the
/// compensated path of a test not fitted has almost none of the machine's error left.
#[test]
fn a_campaign_identification_compensates_the_machine_and_lists_the_set_ups_and_records() {
    let dir = common::temp_dir_tagged("cli-comp", "campaign-table-table");
    let d = &dir.0;
    let truth = |setup: &str, seed: u32| {
        format!(
            "machine = \"table-table-bc\"\nnoise_um = 0.3\nseed = {seed}\n[errors]\n{TABLE_TABLE_ERRORS}{setup}"
        )
    };
    std::fs::write(
        d.join("low.toml"),
        truth("XOW = 8.0\nYOW = -6.0\nZOW = 5.0\n", 1),
    )
    .unwrap();
    std::fs::write(
        d.join("high.toml"),
        truth("XOW = -4.0\nYOW = 9.0\nZOW = -7.0\n", 2),
    )
    .unwrap();
    // The machine alone (the ball exactly where the description puts it, no noise): what the
    // compensation is checked on.
    std::fs::write(
        d.join("machine.toml"),
        format!("machine = \"table-table-bc\"\n[errors]\n{TABLE_TABLE_ERRORS}"),
    )
    .unwrap();
    let run = |line: &str| ok(d, &common::words(line));
    run("simulate --machine table-table-bc --path pair-B-C --truth low.toml -o low.csv");
    run("simulate --machine table-table-bc --path turn-B --truth low.toml --seed 3 -o lowb.csv");
    run(
        "simulate --machine table-table-bc --path pair-B-C --truth high.toml --param Zw=200 -o high.csv",
    );
    std::fs::write(
        d.join("c.toml"),
        "[[record]]\nfile = \"low.csv\"\nsetup = \"low\"\n\n[[record]]\nfile = \"lowb.csv\"\nsetup = \"low\"\n\n[[record]]\nfile = \"high.csv\"\nsetup = \"high\"\nparams = { Zw = 200 }\n",
    )
    .unwrap();
    run(
        "identify --machine table-table-bc --model location --terms dz0@time:1 --campaign c.toml --json c.json",
    );
    // A test the campaign did not fit, at the default ball position, measured on the machine
    // alone: its commanded poses, compensated, run again.
    run("simulate --machine table-table-bc --path turn-C --truth machine.toml -o turnc.csv");
    let text = run(
        "compensate --machine table-table-bc --params c.json --path turnc.csv -o turnc-comp.csv \
         --json comp.json --kinematics-out corrected.toml --tables tables",
    );
    assert!(text.contains("Compensated: 11 machine error(s)"), "{text}");
    assert!(text.contains("XOW[high]: a set-up error"), "{text}");
    assert!(text.contains("dz0@time:1[lowb]: a zero offset"), "{text}");
    let json = read_json(&d.join("comp.json"));
    let compensated: Vec<&str> = json["compensated"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect();
    assert_eq!(
        compensated,
        [
            "COY", "AOZ", "BOZ", "XOB", "ZOB", "AOB", "COB", "XOC", "YOC", "AOC", "BOC"
        ]
    );
    assert_eq!(
        left_out(&json),
        [
            "XOW[low]",
            "YOW[low]",
            "ZOW[low]",
            "XOW[high]",
            "YOW[high]",
            "ZOW[high]",
            "dz0@time:1[low]",
            "dz0@time:1[lowb]",
            "dz0@time:1[high]",
        ]
    );
    // The corrected description folds the shared location translations, as for one record.
    let k = json["kinematics"]["folded"].to_string();
    assert!(
        k.contains("XOB") && k.contains("XOC") && k.contains("YOC"),
        "{k}"
    );
    run(
        "simulate --machine table-table-bc --path turnc-comp.csv --commanded turnc.csv \
         --truth machine.toml -o after.csv",
    );
    let (before, after) = (
        readings_rms(&d.join("turnc.csv")),
        readings_rms(&d.join("after.csv")),
    );
    eprintln!(
        "table-table-bc turn-C: the machine's error {before:.3} µm RMS before, {after:.3} µm after"
    );
    assert!(before > 10.0, "{before}");
    assert!(after < 0.02 * before, "{before} -> {after}");

    // A record modelled with another probe length (a symbol of the machine's side, not the
    // ball's): the identification does not say which the machine has; refused, nothing written.
    run(
        "simulate --machine table-table-bc --path pair-B-C --truth high.toml --param Zw=200,Zp=210 -o highp.csv",
    );
    std::fs::write(
        d.join("p.toml"),
        "[[record]]\nfile = \"low.csv\"\nsetup = \"low\"\n\n[[record]]\nfile = \"highp.csv\"\nsetup = \"high\"\nparams = { Zw = 200, Zp = 210 }\n",
    )
    .unwrap();
    run("identify --machine table-table-bc --model location --campaign p.toml --json p.json");
    fails(
        d,
        &common::words(
            "compensate --machine table-table-bc --params p.json --path turnc.csv -o x.csv --json x.json",
        ),
        1,
        &[
            "p.json",
            "`Zp`",
            "200 and 210 mm",
            "records `low` and `highp`",
        ],
    );
    assert!(!d.join("x.csv").exists() && !d.join("x.json").exists());
}

/// seed-ac: K4 and K1 fitted together (each its own ball set-up), the demo truth's missing
/// harmonic in the model; K2 compensated and run again on the machine alone: the machine's error
/// falls, the set-ups are left out and listed.
#[test]
fn a_seed_campaign_compensates_the_shared_errors() {
    let dir = common::temp_dir_tagged("cli-comp", "campaign-seed");
    let d = &dir.0;
    let run = |line: &str| ok(d, &common::words(line));
    run("simulate --machine seed-ac --path K4 --truth seed-ac-demo -o k4.csv");
    run("simulate --machine seed-ac --path K1 --truth seed-ac-demo --seed 2 -o k1.csv");
    run(
        "identify --machine seed-ac --model reduced --terms ECC@harmonic:2 --data k4.csv,k1.csv --json c.json",
    );
    // The machine alone: the demo truth without its ball set-up and noise.
    let demo = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("formats/truths/seed-ac-demo.toml"),
    )
    .unwrap();
    let machine: String = demo
        .lines()
        .filter(|l| {
            !["XOW", "YOW", "ZOW", "noise_um", "seed"]
                .iter()
                .any(|k| l.starts_with(k))
        })
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(d.join("machine.toml"), machine).unwrap();
    run("simulate --machine seed-ac --path K2 --truth machine.toml -o k2.csv");
    run("compensate --machine seed-ac --params c.json --path k2.csv -o k2c.csv --json comp.json");
    let json = read_json(&d.join("comp.json"));
    assert_eq!(
        left_out(&json),
        [
            "XOW[k4]", "YOW[k4]", "ZOW[k4]", "XOW[k1]", "YOW[k1]", "ZOW[k1]"
        ]
    );
    assert_eq!(json["compensated"].as_array().unwrap().len(), 9);
    run(
        "simulate --machine seed-ac --path k2c.csv --commanded k2.csv --truth machine.toml -o after.csv",
    );
    let (before, after) = (
        readings_rms(&d.join("k2.csv")),
        readings_rms(&d.join("after.csv")),
    );
    eprintln!("seed-ac K2: the machine's error {before:.3} µm RMS before, {after:.3} µm after");
    assert!(before > 10.0, "{before}");
    assert!(after < 0.05 * before, "{before} -> {after}");
}
