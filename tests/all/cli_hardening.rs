//! End-to-end tests of what the command line must never do: lose data through an output,
//! overwrite an input, report a failed computation as a result, accept implausible or foreign
//! data, or grow without bound. Each test checks the message and that no input or unrelated
//! file changed. Everything happens in fresh temporary directories: FIFOs, symlinks, hard links
//! and read-only files are made there; no system path is opened.

use crate::common::{self, mkfifo, temp_dir};

use common::{check_fails, fails, ok, run, stderr, words};
use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::path::Path;
use std::process::Command;

/// Every entry of `dir` (recursively): its kind, mode and contents.
fn snapshot(dir: &Path) -> BTreeMap<String, (String, u32, Vec<u8>)> {
    let mut out = BTreeMap::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let e = e.unwrap();
        let p = e.path();
        let name = e.file_name().to_string_lossy().into_owned();
        let meta = std::fs::symlink_metadata(&p).unwrap();
        let ft = meta.file_type();
        let entry = if ft.is_symlink() {
            let t = std::fs::read_link(&p).unwrap();
            (
                "link".to_string(),
                0,
                t.to_string_lossy().as_bytes().to_vec(),
            )
        } else if ft.is_dir() {
            for (k, v) in snapshot(&p) {
                out.insert(format!("{name}/{k}"), v);
            }
            ("dir".to_string(), meta.mode() & 0o7777, Vec::new())
        } else if ft.is_file() {
            (
                "file".to_string(),
                meta.mode() & 0o7777,
                std::fs::read(&p).unwrap(),
            )
        } else {
            ("special".to_string(), meta.mode() & 0o7777, Vec::new())
        };
        out.insert(name, entry);
    }
    out
}

/// Simulates `path` of seed-ac with the reduced truth into `out` in `dir`.
fn simulate(dir: &Path, path: &str, out: &str) {
    ok(
        dir,
        &words(&format!(
            "simulate --machine seed-ac --path {path} --truth seed-ac-reduced -o {out}"
        )),
    );
}

/// A thread that reads the FIFO `path` to its end.
fn reader(path: &Path) -> std::thread::JoinHandle<Vec<u8>> {
    let path = path.to_path_buf();
    std::thread::spawn(move || {
        let mut buf = Vec::new();
        std::fs::File::open(path)
            .unwrap()
            .read_to_end(&mut buf)
            .unwrap();
        buf
    })
}

fn is_root() -> bool {
    std::fs::metadata("/proc/self")
        .map(|m| m.uid())
        .unwrap_or(1)
        == 0
}

// ---------------------------------------------------------------- A. outputs

#[test]
fn outputs_follow_symlinks_keep_modes_and_links_and_stream_to_fifos() {
    let dir = temp_dir("kinds");
    simulate(&dir, "K4", "k4.csv");
    let expected = std::fs::read(dir.join("k4.csv")).unwrap();
    let sim = |out: &str| {
        ok(
            &dir,
            &words(&format!(
                "simulate --machine seed-ac --path K4 --truth seed-ac-reduced -o {out}"
            )),
        )
    };

    // A symlink is followed: the target gets the content, the link stays, the mode is kept.
    std::fs::write(dir.join("target.csv"), "old").unwrap();
    std::fs::set_permissions(
        dir.join("target.csv"),
        std::fs::Permissions::from_mode(0o640),
    )
    .unwrap();
    std::os::unix::fs::symlink("target.csv", dir.join("link.csv")).unwrap();
    sim("link.csv");
    assert!(
        std::fs::symlink_metadata(dir.join("link.csv"))
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(std::fs::read(dir.join("target.csv")).unwrap(), expected);
    let mode = std::fs::metadata(dir.join("target.csv")).unwrap().mode() & 0o777;
    assert_eq!(mode, 0o640);

    // A hard link survives: both names see the new content.
    std::fs::write(dir.join("one.csv"), "old").unwrap();
    std::fs::hard_link(dir.join("one.csv"), dir.join("two.csv")).unwrap();
    let inode = std::fs::metadata(dir.join("one.csv")).unwrap().ino();
    sim("two.csv");
    assert_eq!(std::fs::read(dir.join("one.csv")).unwrap(), expected);
    assert_eq!(std::fs::metadata(dir.join("one.csv")).unwrap().ino(), inode);
    assert_eq!(std::fs::metadata(dir.join("two.csv")).unwrap().nlink(), 2);

    // A FIFO, directly and through a symlink, is written to and stays a FIFO.
    mkfifo(&dir.join("pipe"));
    std::os::unix::fs::symlink("pipe", dir.join("pipe-link")).unwrap();
    for name in ["pipe", "pipe-link"] {
        let r = reader(&dir.join("pipe"));
        sim(name);
        assert_eq!(r.join().unwrap(), expected, "{name}");
        let ft = std::fs::metadata(dir.join("pipe")).unwrap().file_type();
        assert!(std::os::unix::fs::FileTypeExt::is_fifo(&ft));
    }

    // `-o -`: the CSV on standard output, the summary on standard error.
    let o = run(
        Some(&dir),
        &words("simulate --machine seed-ac --path K4 --truth seed-ac-reduced -o -"),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(o.stdout, expected);
    assert!(
        stderr(&o).contains("simulated K4 on seed-ac"),
        "{}",
        stderr(&o)
    );

    // No temporary file is left anywhere.
    let names: Vec<String> = snapshot(&dir).into_keys().collect();
    assert_eq!(
        names,
        [
            "k4.csv",
            "link.csv",
            "one.csv",
            "pipe",
            "pipe-link",
            "target.csv",
            "two.csv"
        ]
    );
}

#[test]
fn a_read_only_file_is_refused_as_a_shell_would_and_left_alone() {
    let dir = temp_dir("read-only");
    simulate(&dir, "K4", "k4.csv");
    std::fs::write(dir.join("ro.csv"), "keep").unwrap();
    std::fs::set_permissions(dir.join("ro.csv"), std::fs::Permissions::from_mode(0o444)).unwrap();
    std::fs::set_permissions(&*dir, std::fs::Permissions::from_mode(0o777)).unwrap();
    let before = snapshot(&dir);
    let args = words("simulate --machine seed-ac --path K4 --truth seed-ac-reduced -o ro.csv");
    // As root a read-only file is writable (as it is to a shell): run as an ordinary user.
    let mut c = Command::new(env!("CARGO_BIN_EXE_rtest"));
    c.args(&args).current_dir(&*dir);
    if is_root() {
        std::os::unix::process::CommandExt::uid(&mut c, 65534);
        std::os::unix::process::CommandExt::gid(&mut c, 65534);
    }
    let o = c.output().expect("rtest runs");
    check_fails(&o, &args, 1, &["-o: cannot write `ro.csv`"]);
    assert_eq!(snapshot(&dir), before);
}

#[test]
fn an_output_that_names_an_input_is_refused_before_any_work() {
    let dir = temp_dir("input");
    simulate(&dir, "K4", "k4.csv");
    ok(
        &dir,
        &words(
            "identify --machine seed-ac --model reduced --data k4.csv --first-order --json id.json",
        ),
    );
    std::fs::write(
        dir.join("m.toml"),
        model_spec::write::source_text("seed-ac").unwrap(),
    )
    .unwrap();
    std::fs::write(dir.join("path.csv"), "A,C\n0,0\n0,10\n0,20\n").unwrap();
    std::os::unix::fs::symlink("k4.csv", dir.join("k4-link.csv")).unwrap();
    std::fs::hard_link(dir.join("k4.csv"), dir.join("k4-hard.csv")).unwrap();
    let before = snapshot(&dir);
    let id = words("identify --machine seed-ac --model reduced --data k4.csv");
    for json in ["k4.csv", "./k4.csv", "k4-link.csv", "k4-hard.csv"] {
        let mut args = id.clone();
        args.extend(["--json", json]);
        fails(
            &dir,
            &args,
            2,
            &["--json: `", "is also the input of --data"],
        );
    }
    let cases: &[(&[&str], &str)] = &[
        (
            &words("validate --machine seed-ac --params id.json --data k4.csv --json id.json"),
            "--json: `id.json` is also the input of --params",
        ),
        (
            &words("generate --machine m.toml -o m.toml"),
            "-o: `m.toml` is also the input of --machine",
        ),
        (
            &words("diagnose --machine m.toml --model reduced --data k4.csv --model-out m.toml"),
            "--model-out: `m.toml` is also the input of --machine",
        ),
        (
            &words("simulate --machine seed-ac --path path.csv -o path.csv"),
            "-o: `path.csv` is also the input of --path",
        ),
        (
            &words(
                "diagnose --machine seed-ac --model reduced --data k4.csv --json x.json --model-out x.json",
            ),
            "is also the output of",
        ),
    ];
    for (args, message) in cases {
        fails(&dir, args, 2, &[message]);
    }
    assert_eq!(snapshot(&dir), before);
}

/// An output directory (`--tables`, `--plot`) that holds an input under a name the verb would
/// write there, itself or through a link, is refused before any work, naming both.
#[test]
fn an_output_directory_holding_an_input_is_refused_before_any_work() {
    let dir = temp_dir("input-dir");
    simulate(&dir, "K4", "k4.csv");
    simulate(&dir, "K1", "k1.csv");
    ok(
        &dir,
        &words(
            "identify --machine seed-ac --model reduced --terms ECC@harmonic:2,EXX@poly:2 --data k4.csv --json e.json",
        ),
    );
    std::fs::create_dir(dir.join("t")).unwrap();
    std::fs::copy(dir.join("k4.csv"), dir.join("t/axis_X.csv")).unwrap();
    std::fs::create_dir(dir.join("p")).unwrap();
    std::fs::copy(dir.join("k4.csv"), dir.join("p/k4.csv")).unwrap();
    std::fs::copy(dir.join("k1.csv"), dir.join("p/k4-path.svg")).unwrap();
    std::fs::create_dir(dir.join("q")).unwrap();
    std::fs::hard_link(dir.join("k1.csv"), dir.join("q/k1-spectrum.svg")).unwrap();
    // A machine description where --crate would write its copy, or linked to its README.
    let seed = model_spec::write::source_text("seed-ac").unwrap();
    std::fs::write(dir.join("m.toml"), &seed).unwrap();
    std::fs::create_dir_all(dir.join("c/src")).unwrap();
    std::fs::write(dir.join("c/src/lib.rs"), &seed).unwrap();
    std::fs::create_dir(dir.join("r")).unwrap();
    std::fs::hard_link(dir.join("m.toml"), dir.join("r/README.md")).unwrap();
    let before = snapshot(&dir);
    let cases: &[(&[&str], &str)] = &[
        (
            &words(
                "compensate --machine seed-ac --params e.json --path t/axis_X.csv -o kc.csv --tables t",
            ),
            "--tables: `t/axis_X.csv` is also the input of --path",
        ),
        (
            &words(
                "diagnose --machine seed-ac --model reduced --data p/k4.csv --validate p/k4-path.svg --plot p",
            ),
            "--plot: `p/k4-path.svg` is also the input of --validate",
        ),
        (
            &words(
                "diagnose --machine seed-ac --model reduced --data k4.csv --validate k1.csv --plot q",
            ),
            "--plot: `q/k1-spectrum.svg` is also the input of --validate",
        ),
        (
            &words("generate --machine c/src/lib.rs --model reduced --crate c"),
            "--crate: `c/src/lib.rs` is also the input of --machine",
        ),
        (
            &words("generate --machine m.toml --model reduced --crate r"),
            "--crate: `r/README.md` is also the input of --machine",
        ),
    ];
    for (args, message) in cases {
        fails(&dir, args, 2, &[message]);
    }
    assert_eq!(snapshot(&dir), before);
}

// ---------------------------------------------------------------- B. failures

#[test]
fn a_refinement_that_does_not_converge_is_an_error_and_writes_nothing() {
    let dir = temp_dir("diverge");
    // K4 with the demo truth (0.5 µm of noise), and K4 without noise.
    ok(
        &dir,
        &words("simulate --machine seed-ac --path K4 -o noisy.csv"),
    );
    simulate(&dir, "K4", "exact.csv");
    let first = |file: &str, n: usize| -> String {
        let text = std::fs::read_to_string(dir.join(file)).unwrap();
        let lines: Vec<&str> = text.lines().filter(|l| !l.starts_with('#')).collect();
        lines[..=n].join("\n") + "\n"
    };
    // The first five noisy samples: 15 readings for 11 parameters. The first-order fit takes
    // them, but its values are far from any machine (the noise decides the ill-conditioned
    // directions), the second-order terms there are not small, and Gauss-Newton diverges.
    std::fs::write(dir.join("few.csv"), first("noisy.csv", 5)).unwrap();
    // Eight: it crawls, and has not converged after eight steps.
    std::fs::write(dir.join("eight.csv"), first("noisy.csv", 8)).unwrap();
    let before = snapshot(&dir);
    for data in ["few.csv", "eight.csv"] {
        let json = format!("{data}.json");
        fails(
            &dir,
            &words(&format!(
                "identify --machine seed-ac --model reduced --data {data} --json {json}"
            )),
            3,
            &[
                "--data: the refinement against the exact machine did not converge: 8 Gauss-Newton steps",
                "--first-order gives the first-order values",
            ],
        );
        // Its first-order values are no result either: far beyond the plausibility bounds.
        fails(
            &dir,
            &words(&format!(
                "identify --machine seed-ac --model reduced --data {data} --first-order --json {json}"
            )),
            3,
            &["--data: implausible result: values are beyond the plausibility bounds"],
        );
    }
    assert_eq!(snapshot(&dir), before, "no file written on exit code 3");
    // The same five samples without noise: ill-conditioned (condition number 3e7), but the
    // refinement converges to its rounding floor, and the values are the truth's.
    std::fs::write(dir.join("five.csv"), first("exact.csv", 5)).unwrap();
    let out = ok(
        &dir,
        &words("identify --machine seed-ac --model reduced --data five.csv"),
    );
    assert!(out.contains(", converged;"), "{out}");
    // Fewer readings than parameters plus one: an error before fitting, naming both numbers.
    std::fs::write(dir.join("three.csv"), first("exact.csv", 3)).unwrap();
    fails(
        &dir,
        &words("identify --machine seed-ac --model reduced --data three.csv"),
        1,
        &["too few samples: 3 samples give 9 readings (3 per sample) for 11 parameters"],
    );
}

#[test]
fn non_finite_and_implausible_inputs_are_refused_naming_the_cause() {
    let dir = temp_dir("non-finite");
    simulate(&dir, "K4", "k4.csv");
    let text = std::fs::read_to_string(dir.join("k4.csv")).unwrap();
    // The tenth data line gets a reading of 1e308 µm, the twelfth one of -2400 µm.
    let mut n = 0;
    let mut line_no = Vec::new();
    let edited: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if l.starts_with('#') || l.starts_with('X') {
                return l.to_string();
            }
            n += 1;
            let mut f: Vec<String> = l.split(',').map(String::from).collect();
            match n {
                10 => f[5] = "1e308".into(),
                12 => f[7] = "-2400".into(),
                _ => return l.to_string(),
            }
            line_no.push(i + 1);
            f.join(",")
        })
        .collect();
    std::fs::write(dir.join("bad.csv"), edited.join("\n") + "\n").unwrap();
    let before = snapshot(&dir);
    fails(
        &dir,
        &words("identify --machine seed-ac --model reduced --data bad.csv"),
        1,
        &[
            "bad.csv: 2 readings beyond the plausibility bound of 1000 µm",
            &format!("line {} dx_um = 1e308", line_no[0]),
            &format!("line {} dz_um = -2400", line_no[1]),
        ],
    );
    // --noise-um beyond its range.
    fails(
        &dir,
        &words("simulate --machine seed-ac --path K4 --noise-um 1e308 -o n.csv"),
        2,
        &["--noise-um: `1e308` must be a finite number from 0 to 1000 µm"],
    );
    // A machine whose offset or stroke is 1e308.
    let seed = model_spec::write::source_text("seed-ac").unwrap();
    for (name, text) in [
        ("zc.toml", seed.replace("Zc = 29.794", "Zc = 1e308")),
        (
            "stroke.toml",
            seed.replace("[-500.0, 500.0]", "[-1e308, 1e308]"),
        ),
    ] {
        std::fs::write(dir.join(name), text).unwrap();
        fails(
            &dir,
            &words(&format!(
                "identify --machine {name} --model reduced --data k4.csv"
            )),
            1,
            &[&format!("--machine: {name}:"), "1e308"],
        );
    }
    // Identified values beyond the bounds are an error, not a result, and nothing is written.
    let snap = snapshot(&dir);
    fails(
        &dir,
        &words(
            "identify --machine seed-ac --model reduced --data k4.csv --max-error-um 1 --json id.json",
        ),
        3,
        &[
            "implausible result",
            "beyond the plausibility bounds (1 µm, 10000 µrad)",
        ],
    );
    assert_eq!(snapshot(&dir), snap);
    let mut now = snapshot(&dir);
    for name in ["zc.toml", "stroke.toml"] {
        now.remove(name);
    }
    assert_eq!(now, before);
}

#[test]
fn poses_off_stroke_or_off_the_ball_are_refused_unless_allowed() {
    let dir = temp_dir("poses");
    // A beyond its range of ±120°, the linear axes filled by inverse kinematics.
    std::fs::write(dir.join("path.csv"), "A,C\n0,0\n-60,10\n-125,20\n").unwrap();
    fails(
        &dir,
        &words("simulate --machine seed-ac --path path.csv -o p.csv"),
        1,
        &["path.csv", "line 4", "A = -125"],
    );
    ok(
        &dir,
        &words("simulate --machine seed-ac --path path.csv --allow-off-stroke -o p.csv"),
    );
    // gains --at: a pose off the ball is evaluated, with a note that the numbers are the gain
    // functions there; a kinematic parameter beyond any machine is refused.
    let out = ok(
        &dir,
        &words("gains --machine seed-ac --at X=0,Y=0,Z=0,A=30,C=45"),
    );
    assert!(
        out.contains("Note: this pose puts the nominal tool point 301.493833 mm from the nominal workpiece point"),
        "{out}"
    );
    let out = ok(&dir, &words("gains --machine seed-ac --at A=30,C=45"));
    assert!(!out.contains("Note:"), "{out}");
    fails(
        &dir,
        &words("gains --machine seed-ac --at A=30,C=45 --param Zp=1e200"),
        2,
        &["--param: `Zp` = 1e200 mm is beyond the largest length a machine may have, 100000 mm"],
    );
    // gains --at checks the pose too.
    fails(
        &dir,
        &words("gains --machine seed-ac --at A=130,C=0"),
        2,
        &["--at: ", "A", "--allow-off-stroke"],
    );
    // A three-axis grid with the commanded motion in the readings is not an R-test record.
    let mut grid = String::from("X,Y,Z,dx_um,dy_um,dz_um\n");
    for (i, x) in [0.0, 10.0, 20.0, 30.0].iter().enumerate() {
        grid.push_str(&format!("{x},{},0,{},0,0\n", 5 * i, x * 1e3));
    }
    std::fs::write(dir.join("grid.csv"), grid).unwrap();
    let err = fails(
        &dir,
        &words("identify --machine seed-3axis --model full --data grid.csv"),
        1,
        &["grid.csv", "line 3", "R-test"],
    );
    assert!(err.contains("follow the ball"), "{err}");
}

#[test]
fn values_of_another_machine_are_refused() {
    let dir = temp_dir("foreign");
    simulate(&dir, "K4", "k4.csv");
    ok(
        &dir,
        &words("identify --machine seed-ac --model reduced --data k4.csv --json id.json"),
    );
    // The same machine with C turning the other way: another fingerprint.
    let seed = model_spec::write::source_text("seed-ac").unwrap();
    let reversed = seed.replacen(
        "direction = \"+z\"\noffset = [0, 0, \"Zc\"]",
        "direction = \"-z\"\noffset = [0, 0, \"Zc\"]",
        1,
    );
    assert_ne!(reversed, seed);
    std::fs::write(dir.join("reversed.toml"), reversed).unwrap();
    let before = snapshot(&dir);
    fails(
        &dir,
        &words("validate --machine reversed.toml --params id.json --data k4.csv"),
        1,
        &["--params: id.json: field `fingerprint`", "another topology"],
    );
    // A parameter missing from the file.
    let mut json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("id.json")).unwrap()).unwrap();
    json["parameters"].as_array_mut().unwrap().remove(0);
    std::fs::write(dir.join("short.json"), json.to_string()).unwrap();
    fails(
        &dir,
        &words("validate --machine seed-ac --params short.json --data k4.csv"),
        1,
        &[
            "--params: short.json: field `terms`",
            "a parameter is missing or extra",
        ],
    );
    // Only three of the eleven parameters, with `terms` cut to match: the base model says what
    // is missing.
    let mut json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("id.json")).unwrap()).unwrap();
    json["parameters"].as_array_mut().unwrap().truncate(3);
    json["terms"].as_array_mut().unwrap().truncate(3);
    std::fs::write(dir.join("partial.json"), json.to_string()).unwrap();
    fails(
        &dir,
        &words("validate --machine seed-ac --params partial.json --data k4.csv"),
        1,
        &["--params: partial.json: field `parameters`: the base model `reduced` has YOA, ZOA"],
    );
    let mut now = snapshot(&dir);
    now.remove("short.json");
    now.remove("partial.json");
    assert_eq!(now, before);
}

// ---------------------------------------------------------------- D. bounded resources

#[test]
fn an_endless_stream_without_line_ends_ends_quickly_with_an_error() {
    let dir = temp_dir("endless");
    mkfifo(&dir.join("zeros"));
    for stream in [true, false] {
        let path = dir.join("zeros");
        let feeder = std::thread::spawn(move || {
            let mut f = std::fs::OpenOptions::new().write(true).open(path).unwrap();
            let block = vec![0u8; 1 << 16];
            // Until the reader goes away (EPIPE), at most 1 GiB.
            for _ in 0..(1 << 14) {
                if f.write_all(&block).is_err() {
                    break;
                }
            }
        });
        let mut args = words("identify --machine seed-ac --model reduced --data zeros");
        if stream {
            args.push("--stream");
        }
        fails(&dir, &args, 1, &["--data: ", "longer than 65536 bytes"]);
        feeder.join().unwrap();
    }
    assert_eq!(snapshot(&dir).len(), 1);
}

#[test]
fn simulate_never_writes_a_record_that_identify_would_refuse() {
    let dir = temp_dir("unreadable");
    // A set-up error of 5 mm: every reading beyond the plausibility bound of 1000 µm.
    std::fs::write(
        dir.join("far.toml"),
        "machine = \"seed-ac\"\n[errors]\nXOW = 5000\n",
    )
    .unwrap();
    let before = snapshot(&dir);
    fails(
        &dir,
        &words("simulate --machine seed-ac --path K4 --truth far.toml -o k4.csv"),
        3,
        &[
            "-o: the simulated record would not be accepted by identify, so it is not written",
            "beyond the plausibility bound of 1000 µm",
        ],
    );
    assert_eq!(snapshot(&dir), before);
    // With a bound that admits it, simulate and identify agree.
    ok(
        &dir,
        &words(
            "simulate --machine seed-ac --path K4 --truth far.toml -o k4.csv --max-reading-um 10000",
        ),
    );
    fails(
        &dir,
        &words("identify --machine seed-ac --model reduced --data k4.csv"),
        1,
        &["k4.csv: ", "beyond the plausibility bound of 1000 µm"],
    );
    let out = ok(
        &dir,
        &words(
            "identify --machine seed-ac --model reduced --data k4.csv --max-reading-um 10000 --max-error-um 10000",
        ),
    );
    assert!(out.contains("XOW"), "{out}");
}

#[test]
fn messages_say_what_happened() {
    let dir = temp_dir("messages");
    simulate(&dir, "K4", "k4.csv");
    // Blocks of one sample: the first block reads ahead until every axis has moved, and says so.
    let out = ok(
        &dir,
        &words("identify --machine seed-ac --model reduced --data k4.csv --stream --block 1"),
    );
    assert!(
        out.contains("Read in 240 blocks of up to 1 sample (the first read ahead to 2 samples, until every axis had moved)"),
        "{out}"
    );
    fails(
        &dir,
        &words("identify --machine seed-ac --model reduced --data k4.csv --stream --block 0"),
        2,
        &["--block"],
    );
    // A model with no terms.
    let seed = model_spec::write::source_text("seed-ac").unwrap();
    std::fs::write(
        dir.join("empty.toml"),
        format!("{seed}\n[models.empty]\ndescription = \"nothing\"\nerrors = []\n"),
    )
    .unwrap();
    fails(
        &dir,
        &words("identify --machine empty.toml --model empty --data k4.csv"),
        2,
        &["--model: model `empty` of machine seed-ac has no terms (its `errors` list is empty)"],
    );
    // An identification report with a byte-order mark is read; one that is not UTF-8 is
    // refused with its line and column.
    ok(
        &dir,
        &words("identify --machine seed-ac --model reduced --data k4.csv --json id.json"),
    );
    let json = std::fs::read(dir.join("id.json")).unwrap();
    let mut bom = b"\xef\xbb\xbf".to_vec();
    bom.extend(&json);
    std::fs::write(dir.join("bom.json"), bom).unwrap();
    ok(
        &dir,
        &words("validate --machine seed-ac --params bom.json --data k4.csv"),
    );
    let mut bad = json.clone();
    let at = bad.iter().position(|&b| b == b'\n').unwrap() + 3;
    bad[at] = 0xff;
    std::fs::write(dir.join("bad.json"), bad).unwrap();
    fails(
        &dir,
        &words("validate --machine seed-ac --params bad.json --data k4.csv"),
        1,
        &["--params: bad.json:2:3: not UTF-8 text (byte 0xff)"],
    );
    // The seed has one range everywhere.
    fails(
        &dir,
        &words("simulate --machine seed-ac --path K4 --seed 9223372036854775808 -o s.csv"),
        2,
        &["--seed"],
    );
    ok(
        &dir,
        &words("simulate --machine seed-ac --path K4 --seed 9223372036854775807 -o s.csv"),
    );
}

#[test]
fn a_closed_standard_output_is_an_error_not_a_panic() {
    let dir = temp_dir("closed-stdout");
    for args in [
        words("gains --machine seed-ac --format latex"),
        words("machines"),
        words("simulate --machine seed-ac --path K4 -o -"),
    ] {
        // A pipe whose reading end is closed before rtest starts: every write fails.
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let o = Command::new(env!("CARGO_BIN_EXE_rtest"))
            .args(&args)
            .current_dir(&*dir)
            .stdout(writer)
            .output()
            .unwrap();
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(
            err.starts_with("rtest: error: ") && err.contains("standard output"),
            "{args:?}: {err}"
        );
    }
}

// ---------------------------------------------------------------- limits

/// Counts and lengths that drive work are refused beyond their limits before any work, with
/// the limit named and a short message: records of a campaign (200), a label (256
/// characters), tests of a plan (50), a ball position's name (128 characters).
#[test]
fn counts_and_lengths_beyond_their_limits_are_refused_before_any_work() {
    let dir = temp_dir("limits");
    simulate(&dir, "K4", "k4.csv");
    let identify = "identify --machine seed-ac --model reduced";
    // 2 000 records of one campaign file (54 kB): refused at the list, no record read.
    let mut text = String::from("machine = \"seed-ac\"\n");
    text += &"[[record]]\nfile = \"k4.csv\"\n".repeat(2000);
    std::fs::write(dir.join("many.toml"), &text).unwrap();
    fails(
        &dir,
        &words(&format!("{identify} --campaign many.toml")),
        1,
        &["many.toml:2:1", "2000 records, more than 200"],
    );
    // 201 files of --data (none of them exists: the count is checked first).
    let files: Vec<String> = (0..201).map(|k| format!("k{k}.csv")).collect();
    for flag in ["--data", "--validate"] {
        let verb = if flag == "--data" {
            identify.to_string()
        } else {
            "diagnose --machine seed-ac --model reduced --data k4.csv".to_string()
        };
        fails(
            &dir,
            &words(&format!("{verb} {flag} {}", files.join(","))),
            2,
            &[flag, "201 records, more than 200"],
        );
    }
    // A label of 65 536 characters: one short line.
    let label = "a".repeat(65_536);
    std::fs::write(
        dir.join("long.toml"),
        format!("machine = \"seed-ac\"\n[[record]]\nfile = \"k4.csv\"\nlabel = \"{label}\"\n"),
    )
    .unwrap();
    let e = fails(
        &dir,
        &words(&format!("{identify} --campaign long.toml")),
        1,
        &["long.toml:4:9", "65536 characters, more than 256"],
    );
    assert!(e.len() < 300, "{e}");
    // A plan of 51 tests; a ball position's name of 70 000 characters.
    let plan = "plan --machine seed-ac --model reduced";
    fails(
        &dir,
        &words(&format!("{plan} --paths {}", vec!["K4"; 51].join(","))),
        2,
        &["--paths", "51 tests, more than 50"],
    );
    let name = "b".repeat(70_000);
    let e = fails(
        &dir,
        &words(&format!("{plan} --paths K4,K4:{name} --ball {name}:Zw=260")),
        2,
        &["--ball", "at most 128 characters"],
    );
    assert!(e.len() < 300, "{e}");
    assert_eq!(common::entries(&dir), ["k4.csv", "long.toml", "many.toml"]);
}

/// `rtest report` reads its JSON reports no further than 64 MiB: an endless FIFO is refused
/// with the limit named, in bounded memory, and nothing is written.
#[test]
fn a_report_json_is_read_no_further_than_its_limit() {
    let dir = temp_dir("report-json");
    let fifo = dir.join("endless.json");
    mkfifo(&fifo);
    let writer = {
        let fifo = fifo.clone();
        std::thread::spawn(move || {
            let mut f = std::fs::OpenOptions::new().write(true).open(fifo).unwrap();
            let block = vec![b' '; 1 << 20];
            // Until the reader closes its end (a broken pipe), or 1 GiB.
            (0..1024)
                .take_while(|_| f.write_all(&block).is_ok())
                .count()
        })
    };
    fails(
        &dir,
        &["report", "endless.json", "-o", "r.html"],
        1,
        &["endless.json", "larger than 67108864 bytes (64 MiB)"],
    );
    let written = writer.join().unwrap();
    assert!(written < 1024, "{written} MiB were read");
    assert_eq!(common::entries(&dir), ["endless.json"]);
}

/// A value out of its range is a usage error (exit code 2) naming its flag, with the number
/// printed short, whatever the verb: never a failed computation (3) or a file error (1).
#[test]
fn out_of_range_values_are_usage_errors_naming_their_flag() {
    let dir = temp_dir("ranges");
    simulate(&dir, "K4", "k4.csv");
    ok(
        &dir,
        &words("identify --machine seed-ac --model reduced --data k4.csv --json id.json"),
    );
    std::fs::write(dir.join("p.nc"), "G90\nG1 X0 Y0 Z0 A0 C0\nG1 A-10 C20\n").unwrap();
    let before = snapshot(&dir);
    let cases: &[(&str, &[&str])] = &[
        (
            "compensate --machine seed-ac --params id.json --nc iso --path p.nc -o q.nc --decimals 10",
            &["--decimals: 10 decimals asked for, at most 9"],
        ),
        (
            "plan --machine seed-ac --model reduced --paths K4 --target-um 1e-320",
            &["--target-um", "`1e-320` is not a number from 1e-6 to 1e6"],
        ),
        (
            "plan --machine seed-ac --model reduced --paths K4 --period-s 1e308",
            &["--period-s: period = 1e308", "at most 3600"],
        ),
        (
            "path --machine seed-ac --test K4 --nc iso -o q.nc --continuous --sample-rate-hz 1e-12",
            &["sampling rate 1e-12 Hz: from 0.1 to 100000 Hz"],
        ),
        (
            "path --machine seed-ac --test K4 --nc iso -o q.nc --settle-s 1e308",
            &["settle time 1e308 s: from 0 to 3600 s"],
        ),
        (
            "path --machine seed-ac --test K4 --nc iso -o q.nc --decimals 12",
            &["--decimals: 12 decimals asked for, at most 9"],
        ),
        (
            "simulate --machine seed-ac --path K4 -o s.csv --noise-phi 1",
            &["--noise-phi: `1` must be at least 0 and below 0.99"],
        ),
        (
            "identify --machine seed-ac --model reduced --data k4.csv --stream --block 1000000000000",
            &["--block", "1000000000000 is not in 1..=100000000"],
        ),
        (
            "validate --machine seed-ac --params id.json --data k4.csv --max-error-um 0",
            &["--max-error-um", "`0` is not a finite number above zero"],
        ),
        (
            "diagnose --machine seed-ac --model reduced --data k4.csv --alpha 1.5",
            &["--alpha", "strictly between 0 and 1"],
        ),
        (
            "volumetric --machine seed-ac --laser X=x.csv --squareness s.csv --grid g.csv --pitch 0",
            &["--pitch: `0` is not a positive number of mm"],
        ),
        (
            "segment --machine seed-ac --plan p.csv --log k4.csv -o s.csv --min-readings 0",
            &["--min-readings", "0 is not in 1..="],
        ),
    ];
    for (args, needles) in cases {
        let e = fails(&dir, &words(args), 2, needles);
        assert!(e.len() < 300, "{e}");
    }
    assert_eq!(snapshot(&dir), before);
}

/// Sets field `col` (0-based) of the `row`-th data line (1-based) of the CSV `text` to
/// `value`, and returns the text with that line's number in the file.
fn with_field(text: &str, row: usize, col: usize, value: &str) -> (String, usize) {
    let mut n = 0;
    let mut at = 0;
    let lines: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if l.starts_with('#') || l.starts_with(|c: char| c.is_ascii_alphabetic()) {
                return l.to_string();
            }
            n += 1;
            if n != row {
                return l.to_string();
            }
            at = i + 1;
            let mut f: Vec<&str> = l.split(',').collect();
            f[col] = value;
            f.join(",")
        })
        .collect();
    (lines.join("\n") + "\n", at)
}

#[test]
fn a_reading_no_head_gives_is_refused_at_its_line_with_a_short_number() {
    let dir = temp_dir("sensor-1e308");
    ok(
        &dir,
        &words("simulate --machine seed-ac --path K4 --instrument inclined-45 -o s.csv"),
    );
    let text = std::fs::read_to_string(dir.join("s.csv")).unwrap();
    // Columns: X,Y,Z,A,C,s1_um,s2_um,s3_um,t_s.
    let (reading, line) = with_field(&text, 9, 7, "1e308");
    std::fs::write(dir.join("reading.csv"), reading).unwrap();
    let (time, time_line) = with_field(&text, 9, 8, "1e308");
    std::fs::write(dir.join("time.csv"), time).unwrap();
    let mut cal = String::from("dx_um,dy_um,dz_um,s1_um,s2_um,s3_um\n");
    for i in 1..=6 {
        cal += &format!("{},{},{},{i},{i},{i}\n", 10 * i, 3 * i, 2 * i);
    }
    std::fs::write(dir.join("cal-d.csv"), with_field(&cal, 3, 0, "1e308").0).unwrap();
    std::fs::write(dir.join("cal-s.csv"), with_field(&cal, 3, 3, "-1e308").0).unwrap();
    let before = snapshot(&dir);
    let identify =
        "identify --machine seed-ac --model reduced --instrument inclined-45 --json id.json --data";
    fails(
        &dir,
        &words(&format!("{identify} reading.csv")),
        1,
        &[&format!(
            "reading.csv:{line}: column 8 `s3_um`: 1e308 µm is beyond the plausibility bound of a sensor's reading, ±12000 µm"
        )],
    );
    let message = fails(
        &dir,
        &words(&format!("{identify} time.csv")),
        1,
        &[&format!(
            "time.csv:{}: column 9 `t_s`: time 9 s is before the time of the previous sample (1e308 s, line {time_line})",
            time_line + 1
        )],
    );
    assert!(message.len() < 400, "{message}");
    let calibrate = "instrument calibrate --instrument inclined-45 -o cal.toml --data";
    fails(
        &dir,
        &words(&format!("{calibrate} cal-d.csv")),
        1,
        &[
            "cal-d.csv:4: column 1 `dx_um`: 1e308 µm is beyond the plausibility bound of a known displacement, ±1000 µm",
        ],
    );
    fails(
        &dir,
        &words(&format!("{calibrate} cal-s.csv")),
        1,
        &[
            "cal-s.csv:4: column 4 `s1_um`: -1e308 µm is beyond the plausibility bound of a sensor's reading, ±12000 µm",
        ],
    );
    assert_eq!(snapshot(&dir), before);
}
