//! End-to-end tests of the safety limits of `rtest compensate`: a program whose words cannot
//! carry the correction refused (accepted with `--decimals`), values beyond `--max-change-um`
//! and `--max-change-urad` refused with the error named, and the warning that the probe's
//! length cannot be told from a location error of the pivot.

use std::path::Path;

use crate::common::{self, param, temp_dir};
use common::{fails, ok, read_json, words};

/// `dir` with `k4.csv` (demo truth) and `id.json` (seed-ac's reduced model on K4).
fn seed_identified(name: &str) -> common::TempDir {
    common::seed_ac_identified("cli", name, None)
}

/// A copy of the identification `from` with the value of parameter `name` set to `value` (its
/// unit, µm or µrad), written to `to`.
fn with_value(dir: &Path, from: &str, to: &str, name: &str, value: f64) {
    let mut j = read_json(&dir.join(from));
    let p = j["parameters"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find(|p| p["name"] == name)
        .unwrap_or_else(|| panic!("no parameter {name}"));
    p["value"] = serde_json::json!(value);
    std::fs::write(dir.join(to), serde_json::to_string_pretty(&j).unwrap()).unwrap();
}

/// An ISO program of the first pose of K4 with integer rotary words (`A0. C0`).
const INTEGER_WORDS: &str = "%\nG90 G1 X217.5040 Y-0.2790 Z56.6610 A0. C0\nG1 C90\n%\n";

#[test]
fn integer_words_are_refused_and_accepted_with_decimals() {
    let dir = seed_identified("words");
    let d = &dir.0;
    std::fs::write(d.join("int.nc"), INTEGER_WORDS).unwrap();
    let run = |extra: &[&'static str]| -> Vec<&'static str> {
        let mut a =
            words("compensate --machine seed-ac --params id.json --nc iso --path int.nc -o out.nc");
        a.extend_from_slice(extra);
        a
    };
    fails(
        d,
        &run(&[]),
        1,
        &[
            "--path: int.nc: the program's words cannot carry the correction",
            "line 2: `A0.` (0 decimals) loses",
            "of the correction of A (at most 1 µrad), 4 decimals needed",
            "line 2: `C0` (0 decimals) loses",
            "give --decimals 4",
        ],
    );
    assert!(!d.join("out.nc").exists(), "nothing written on failure");
    // --decimals 4: accepted, the rotary words written with four decimals and corrected.
    let text = ok(d, &run(&["--decimals", "4"]));
    assert!(text.contains("2 poses, iso"), "{text}");
    let out = std::fs::read_to_string(d.join("out.nc")).unwrap();
    let lines: Vec<&str> = out.lines().collect();
    let word = |line: &str, letter: char| -> f64 {
        line.split(' ')
            .find_map(|w| w.strip_prefix(letter))
            .unwrap()
            .parse()
            .unwrap()
    };
    for (w, n) in [('A', 1), ('C', 1), ('C', 2)] {
        let text = lines[n].split(' ').find(|x| x.starts_with(w)).unwrap();
        assert_eq!(text.split('.').nth(1).map(str::len), Some(4), "{text}");
    }
    assert!(word(lines[1], 'A') != 0.0, "{out}");
    assert!((word(lines[2], 'C') - 90.0).abs() > 1e-5, "{out}");
    // The program's own decimals, enough to carry the correction: written with them.
    let four = INTEGER_WORDS
        .replace("A0. C0", "A0.0000 C0.0000")
        .replace("C90", "C90.0000");
    std::fs::write(d.join("four.nc"), &four).unwrap();
    ok(
        d,
        &words(
            "compensate --machine seed-ac --params id.json --nc iso --path four.nc -o four-out.nc",
        ),
    );
    let out = std::fs::read_to_string(d.join("four-out.nc")).unwrap();
    let with_decimals = ok(
        d,
        &words(
            "compensate --machine seed-ac --params id.json --nc iso --path four.nc -o four-4.nc --decimals 4",
        ),
    );
    assert!(with_decimals.contains("2 poses"), "{with_decimals}");
    assert_eq!(out, std::fs::read_to_string(d.join("four-4.nc")).unwrap());
}

#[test]
fn values_beyond_the_change_limits_are_refused_and_named() {
    let dir = seed_identified("change");
    let d = &dir.0;
    std::fs::write(
        d.join("poses.csv"),
        "X,Y,Z,A,C\n217.504,-0.279,56.661,0,0\n",
    )
    .unwrap();
    let compensate = |params: &'static str, extra: &[&'static str]| -> Vec<&'static str> {
        let mut a = vec!["compensate", "--machine", "seed-ac", "--params", params];
        a.extend(words("--path poses.csv -o out.csv"));
        a.extend_from_slice(extra);
        a
    };
    ok(d, &compensate("id.json", &[]));
    // ZOA 62.3 µm, beyond the default 50 µm.
    with_value(d, "id.json", "zoa.json", "ZOA", 62.3);
    std::fs::remove_file(d.join("out.csv")).unwrap();
    let err = fails(
        d,
        &compensate("zoa.json", &[]),
        1,
        &[
            "--params: zoa.json: ZOA = 62.3 µm (limit 50 µm, --max-change-um)",
            "raise the limit with --max-change-um",
        ],
    );
    assert!(!err.contains("XOC"), "{err}");
    assert!(!d.join("out.csv").exists(), "nothing written on failure");
    ok(d, &compensate("zoa.json", &["--max-change-um", "70"]));
    // AOC 300 µrad, beyond the default 250 µrad; accepted below a raised limit.
    with_value(d, "id.json", "aoc.json", "AOC", 300.0);
    fails(
        d,
        &compensate("aoc.json", &[]),
        1,
        &["AOC = 300 µrad (limit 250 µrad, --max-change-urad)"],
    );
    ok(d, &compensate("aoc.json", &["--max-change-urad", "320"]));
    // The same limits guard the corrected description and the tables.
    fails(
        d,
        &words("compensate --machine seed-ac --params zoa.json --kinematics-out k.toml"),
        1,
        &["ZOA = 62.3 µm"],
    );
    assert!(!d.join("k.toml").exists());
    // The flags take a finite number above zero.
    for bad in ["0", "-5", "nan", "inf", "x"] {
        for flag in ["--max-change-um", "--max-change-urad"] {
            let given = format!("{flag}={bad}");
            let mut args = compensate("id.json", &[]);
            args.push(&given);
            fails(d, &args, 2, &[flag, "not a finite number above zero"]);
        }
    }
}

/// table-table-bc with its probe 12 µm longer than the description says, and location errors
/// of its B and C axes (µm, µrad): no ZOB.
const LONG_PROBE: &str = "noise_um = 0.3
seed = 2
[parameters]
Zp = 200.012
[errors]
XOW = 10.0
YOW = -8.0
ZOW = 6.0
XOB = 12.0
AOB = 20.0
COB = -14.0
XOC = 10.0
YOC = -13.0
AOC = 16.0
BOC = -12.0
";

#[test]
fn a_probe_length_error_ends_up_in_zob_and_is_named() {
    let dir = temp_dir("long-probe");
    let d = &dir.0;
    std::fs::write(d.join("truth.toml"), LONG_PROBE).unwrap();
    ok(
        d,
        &words("simulate --machine table-table-bc --truth truth.toml --path pair-B-C -o pair.csv"),
    );
    ok(
        d,
        &words("identify --machine table-table-bc --model location --data pair.csv --json id.json"),
    );
    // The 12 µm of the probe are identified as ZOB (the machine has none).
    let zob = param(&read_json(&d.join("id.json")), "ZOB")["value"]
        .as_f64()
        .unwrap();
    assert!((zob + 12.0).abs() < 1.0, "ZOB = {zob} µm");
    std::fs::write(d.join("poses.csv"), "X,Y,Z,B,C\n0,0,0,0,0\n").unwrap();
    let text = ok(
        d,
        &words(
            "compensate --machine table-table-bc --params id.json --path poses.csv -o out.csv --json c.json --kinematics-out k.toml --report r.html",
        ),
    );
    // The HTML report says it too, in the compensation section.
    let html = std::fs::read_to_string(d.join("r.html")).unwrap();
    let at = html
        .find("Warning: The probe")
        .unwrap_or_else(|| panic!("no warning in the report"));
    assert!(html[at..].contains("cannot be told from ZOB"));
    let warning = text
        .lines()
        .find(|l| l.starts_with("Warning: "))
        .unwrap_or_else(|| panic!("no warning: {text}"));
    for part in [
        "Warning: The probe's length Zp",
        "cannot be told from ZOB",
        "identified as ZOB",
        "tool setter",
        "--param Zp=LENGTH",
    ] {
        assert!(warning.contains(part), "{part}: {warning}");
    }
    let j = read_json(&d.join("c.json"));
    assert_eq!(j["length_confounded"]["symbol"], "Zp");
    assert_eq!(j["length_confounded"]["with"], serde_json::json!(["ZOB"]));
    assert_eq!(j["length_confounded"]["identified"], false);
    // Without --path the text says so too.
    let text = ok(
        d,
        &words("compensate --machine table-table-bc --params id.json --kinematics-out k2.toml"),
    );
    assert!(text.contains("Warning: The probe's length Zp"), "{text}");
}

/// head-table-bc's pivot length turns with its B head: identified with the location errors it
/// is determined, and compensating that identification warns of nothing.
#[test]
fn a_determinable_length_is_not_warned_of() {
    let dir = temp_dir("pivot-length");
    let d = &dir.0;
    std::fs::write(
        d.join("truth.toml"),
        "noise_um = 0.3\nseed = 4\n[parameters]\nZt = -250.02\n[errors]\nXOC = 10.0\nYOC = -13.0\nAOB = 20.0\n",
    )
    .unwrap();
    ok(
        d,
        &words("simulate --machine head-table-bc --truth truth.toml --path pair-B-C -o pair.csv"),
    );
    ok(
        d,
        &words(
            "identify --machine head-table-bc --terms COY,BOZ,XOW,YOW,ZOW,AOB,COB,XOC,YOC,AOC,BOC,Zt --data pair.csv --json id.json",
        ),
    );
    let text = ok(
        d,
        &words("compensate --machine head-table-bc --params id.json --kinematics-out k.toml"),
    );
    assert!(text.contains("folded: Zt = "), "{text}");
    assert!(!text.contains("Warning"), "{text}");
}
