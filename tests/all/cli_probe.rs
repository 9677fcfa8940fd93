//! End to end with a touch probe: hits simulated on the exact virtual machine, a campaign of
//! two sphere positions identified through the sphere fits, validated, diagnosed, compensated
//! and recorded; bad probe data refused with its file and line, nothing written.

use crate::common::{entries, fails, ok, read_json, temp_dir};
use std::path::Path;

const PROBE: &str =
    "name = \"TS 460\"\ntip_radius_mm = 1.5\nsphere_radius_mm = 12.5\nnoise_um = 0.5\n";

/// Five positions of A and six of C (degrees), the other at 0.
const POSES: &str = "A,C\n0,0\n-30,0\n-60,0\n-90,0\n30,0\n0,60\n0,120\n0,180\n0,240\n0,300\n";

/// The probe file, the poses and two records of hits: the sphere at the description's height
/// and 60 mm higher, on seed-ac with the reduced model's errors as the truth.
fn measured(dir: &Path) {
    std::fs::write(dir.join("probe.toml"), PROBE).unwrap();
    std::fs::write(dir.join("poses.csv"), POSES).unwrap();
    for (file, param, seed) in [
        ("low.csv", None, "1"),
        ("high.csv", Some("Zw=271.537"), "2"),
    ] {
        let mut args = vec![
            "simulate",
            "--machine",
            "seed-ac",
            "--truth",
            "seed-ac-reduced",
            "--path",
            "poses.csv",
            "--probe",
            "probe.toml",
            "--seed",
            seed,
            "-o",
            file,
        ];
        if let Some(p) = param {
            args.extend(["--param", p]);
        }
        ok(dir, &args);
    }
    std::fs::write(
        dir.join("c.toml"),
        "machine = \"seed-ac\"\n[[record]]\nfile = \"low.csv\"\n[[record]]\nfile = \"high.csv\"\nparams = { Zw = 271.537 }\n",
    )
    .unwrap();
}

#[test]
fn a_probe_campaign_goes_through_the_pipeline() {
    let dir = temp_dir("probe-pipeline");
    measured(&dir);
    let out = ok(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--campaign",
            "c.toml",
            "--probe",
            "probe.toml",
            "--json",
            "id.json",
            "--report",
            "id.html",
            "--record",
            "--machine-id",
            "M-1",
        ],
    );
    assert!(out.contains("Touch probe TS 460"), "{out}");
    assert!(
        out.contains("record low: 10 poses, 90 hits fitted here"),
        "{out}"
    );
    assert!(out.contains("axis A: 10 poses"), "{out}");
    let id = read_json(&dir.join("id.json"));
    let probe = &id["probe"];
    assert_eq!(probe["records"].as_array().unwrap().len(), 2);
    assert_eq!(probe["records"][1]["hits"], 90);
    for a in probe["axes"].as_array().unwrap() {
        let (before, after) = (
            a["measured_um"].as_f64().unwrap(),
            a["after_um"].as_f64().unwrap(),
        );
        assert!(after < 1.5 && before > 5.0 * after, "{a}");
    }
    // The truth (formats/truths/seed-ac-reduced.toml) within 4 std.
    let truth = formats::truth::builtin_truth(
        "seed-ac-reduced",
        &model_spec::builtin("seed-ac").unwrap().unwrap(),
    )
    .unwrap()
    .unwrap();
    let m = model_spec::builtin("seed-ac").unwrap().unwrap();
    for p in id["parameters"].as_array().unwrap() {
        let name = p["name"].as_str().unwrap();
        let Some(term) = truth
            .model
            .terms
            .iter()
            .find(|t| name.starts_with(&t.effect.name(&m)))
        else {
            continue;
        };
        let t = truth.coefficient(term).unwrap()[0] * term.display_factor(&m);
        let (v, s) = (p["value"].as_f64().unwrap(), p["std"].as_f64().unwrap());
        assert!(((v - t) / s).abs() < 4.0, "{name}: {v} ± {s}, truth {t}");
    }
    // Validation of a record through the probe, a diagnosis, a compensation, the history.
    let v = ok(
        &dir,
        &[
            "validate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--campaign",
            "c.toml",
            "--probe",
            "probe.toml",
        ],
    );
    assert!(v.contains("high"), "{v}");
    let d = ok(
        &dir,
        &[
            "diagnose",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--campaign",
            "c.toml",
            "--probe",
            "probe.toml",
        ],
    );
    assert!(!d.is_empty());
    std::fs::write(
        dir.join("job.csv"),
        "X,Y,Z,A,C\n100,50,-20,0,0\n100,50,-20,-30,90\n",
    )
    .unwrap();
    ok(
        &dir,
        &[
            "compensate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--path",
            "job.csv",
            "-o",
            "out.csv",
        ],
    );
    let h = ok(&dir, &["history"]);
    assert!(h.contains("M-1"), "{h}");
    // The HTML reports: identify's and rtest report's of the JSON, with the probe's part.
    let html = std::fs::read_to_string(dir.join("id.html")).unwrap();
    assert!(html.contains("Dispersion of the sphere centres per rotary axis"));
    ok(
        &dir,
        &[
            "report",
            "--machine",
            "seed-ac",
            "id.json",
            "-o",
            "rep.html",
        ],
    );
    let html = std::fs::read_to_string(dir.join("rep.html")).unwrap();
    assert!(html.contains("Dispersion of the sphere centres per rotary axis"));
    assert!(
        html.contains("the records are a touch probe"),
        "paths not drawn, and why"
    );
    // The poses a plan chooses make the probing program.
    ok(
        &dir,
        &[
            "plan",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--probe",
            "probe.toml",
            "--poses-out",
            "planned.csv",
        ],
    );
    let p = ok(
        &dir,
        &[
            "path",
            "--machine",
            "seed-ac",
            "--test",
            "planned.csv",
            "--probe",
            "probe.toml",
            "--nc",
            "linuxcnc",
            "-o",
            "probe.ngc",
        ],
    );
    assert!(p.contains("Wrote probe.ngc"), "{p}");
}

#[test]
fn bad_probe_data_is_refused_with_its_file_and_line() {
    let dir = temp_dir("probe-refusals");
    measured(&dir);
    // A 20 µm dirty hit: the third hit of the first pose (approached along +X) 20 µm farther
    // out along X (seed-ac's X moves the table).
    let text = std::fs::read_to_string(dir.join("low.csv")).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let first = lines.iter().position(|l| l.starts_with("p1,")).unwrap();
    let at = first + 2;
    let mut fields: Vec<String> = lines[at].split(',').map(String::from).collect();
    let x: f64 = fields[1].parse().unwrap();
    fields[1] = format!("{}", x + 0.02);
    lines[at] = fields.join(",");
    std::fs::write(dir.join("dirty.csv"), lines.join("\n") + "\n").unwrap();
    let before = entries(&dir);
    let e = fails(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "dirty.csv",
            "--probe",
            "probe.toml",
            "--json",
            "id.json",
        ],
        1,
        &[&format!(
            "dirty.csv:{}: pose `p1`: sphere fit refused (residual): hit 3 of the pose (line {}) is ",
            at + 1,
            at + 1
        )],
    );
    assert!(e.contains("µm off the fitted sphere"), "{e}");
    assert_eq!(entries(&dir), before, "nothing written");
    // The probe with an R-test instrument, or a static record: usage errors.
    fails(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "low.csv",
            "--probe",
            "probe.toml",
            "--instrument",
            "rtest-3",
        ],
        2,
        &["--probe", "--instrument"],
    );
    fails(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "low.csv",
            "--probe",
            "probe.toml",
            "--noise-record",
            "low.csv",
        ],
        2,
        &["--noise-record low.csv: a record of the machine standing still is an R-test's"],
    );
    // A probe file without noise_um.
    std::fs::write(
        dir.join("quiet.toml"),
        "tip_radius_mm = 1.5\nsphere_radius_mm = 12.5\n",
    )
    .unwrap();
    fails(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "low.csv",
            "--probe",
            "quiet.toml",
        ],
        1,
        &["low.csv:", "declares no noise_um"],
    );
    // A probe file that is no TOML.
    std::fs::write(dir.join("bad.toml"), "tip_radius_mm = \n").unwrap();
    fails(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "low.csv",
            "--probe",
            "bad.toml",
        ],
        1,
        &["--probe: bad.toml:1:"],
    );
}
