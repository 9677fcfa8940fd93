//! `rtest report` of a touch probe's check: per probe record one figure of the readings per
//! pose with their ±1σ bars, the identified model's prediction and the residual; the records
//! read again through the probe file the identification names, refused (one named line, the
//! report still written) when that file changed, is missing, or a record no longer reads.

use crate::common::{ok, read_json, temp_dir};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;

const PROBE: &str =
    "name = \"TS 460\"\ntip_radius_mm = 1.5\nsphere_radius_mm = 12.5\nnoise_um = 0.5\n";

/// Five positions of A and six of C (degrees), the other at 0: both rotary axes move.
const POSES: &str = "A,C\n0,0\n-30,0\n-60,0\n-90,0\n30,0\n0,60\n0,120\n0,180\n0,240\n0,300\n";

/// C alone swept, A at 0.
const SWEEP: &str = "A,C\n0,0\n0,45\n0,90\n0,135\n0,180\n0,225\n";

/// Hits simulated on seed-ac with the reduced model's errors as the truth: `low.csv` and
/// `high.csv` (the sphere 60 mm higher) at [`POSES`], `sweep.csv` at [`SWEEP`]; the campaign
/// file of the first two; identified (`id.json`, `id.html`) and validated (`v.json`: the
/// sweep; `vc.json`: the campaign's own records).
fn check(dir: &Path) {
    std::fs::write(dir.join("probe.toml"), PROBE).unwrap();
    std::fs::write(dir.join("poses.csv"), POSES).unwrap();
    std::fs::write(dir.join("sweep-poses.csv"), SWEEP).unwrap();
    for (file, path, param, seed) in [
        ("low.csv", "poses.csv", None, "1"),
        ("high.csv", "poses.csv", Some("Zw=271.537"), "2"),
        ("sweep.csv", "sweep-poses.csv", None, "3"),
    ] {
        let mut args = vec![
            "simulate",
            "--machine",
            "seed-ac",
            "--truth",
            "seed-ac-reduced",
            "--path",
            path,
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
    let base = ["--machine", "seed-ac", "--probe", "probe.toml"];
    let mut identify = vec!["identify", "--model", "reduced", "--campaign", "c.toml"];
    identify.extend(base);
    identify.extend(["--json", "id.json", "--report", "id.html"]);
    ok(dir, &identify);
    for (data, json) in [
        (["--data", "sweep.csv"], "v.json"),
        (["--campaign", "c.toml"], "vc.json"),
    ] {
        let mut validate = vec!["validate", "--params", "id.json"];
        validate.extend(data);
        validate.extend(base);
        validate.extend(["--json", json]);
        ok(dir, &validate);
    }
}

/// The `data-*` attributes of the `<figure>` with `id` in `html`.
fn figure_data(html: &str, id: &str) -> BTreeMap<String, String> {
    let start = html
        .find(&format!("<figure id=\"{id}\""))
        .unwrap_or_else(|| panic!("no figure {id}"));
    let tag = &html[start..start + html[start..].find('>').unwrap()];
    let mut out = BTreeMap::new();
    for part in tag.split(" data-").skip(1) {
        let (name, rest) = part.split_once("=\"").unwrap();
        out.insert(
            name.to_string(),
            rest[..rest.find('"').unwrap()].to_string(),
        );
    }
    out
}

/// Per pose `x,y,z`, poses separated by `;`.
fn triples(s: &str) -> Vec<[f64; 3]> {
    s.split(';')
        .map(|p| {
            let v: Vec<f64> = p.split(',').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

fn rms(values: impl Iterator<Item = f64>) -> f64 {
    let v: Vec<f64> = values.collect();
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

/// The report's text between its section 4 heading and section 5.
fn section_4(html: &str) -> &str {
    let s = html.find("id=\"validation\"").expect("section 4");
    let e = html.find("id=\"diagnosis\"").expect("section 5");
    &html[s..e]
}

#[test]
fn each_probe_record_is_drawn_per_pose_with_the_identified_models_prediction() {
    let dir = temp_dir("report-probe");
    check(&dir);
    let id = read_json(&dir.join("id.json"));
    // The JSON names the probe file with the digest of the bytes identify read.
    let bytes = std::fs::read(dir.join("probe.toml")).unwrap();
    let digest = model_spec::sha256::Digest::of(&bytes);
    assert_eq!(id["probe"]["file"], "probe.toml");
    assert_eq!(id["probe"]["sha256"], Value::from(digest.sha256.clone()));
    assert_eq!(id["probe"]["bytes"], Value::from(digest.bytes));

    ok(
        &dir,
        &[
            "report",
            "id.json",
            "v.json",
            "vc.json",
            "--machine",
            "seed-ac",
            "-o",
            "rep.html",
        ],
    );
    let html = std::fs::read_to_string(dir.join("rep.html")).unwrap();
    let s4 = section_4(&html);
    assert!(
        s4.contains("Measured against predicted at the probe&#39;s poses"),
        "{s4}"
    );
    assert!(!html.contains("No pose is drawn") && !html.contains("is not drawn"));
    // The probe file is listed among the inputs, hashed.
    assert!(html.contains("identification: probe") && html.contains(&digest.sha256));

    // One figure per probe record: the identification's two, the sweep's, and the campaign's
    // two validated again (ids made unique).
    let vc = read_json(&dir.join("vc.json"));
    let v = read_json(&dir.join("v.json"));
    let figures = [
        ("fig-low-poses", "low.csv", 10, &id, 0),
        ("fig-high-poses", "high.csv", 10, &id, 1),
        ("fig-sweep-poses", "sweep.csv", 6, &v, 0),
        ("fig-low-poses-2", "low.csv", 10, &vc, 0),
        ("fig-high-poses-2", "high.csv", 10, &vc, 1),
    ];
    for (fig, record, poses, _, _) in &figures {
        let d = figure_data(s4, fig);
        assert_eq!(d["record"], *record);
        assert_eq!(d["poses"], poses.to_string(), "{fig}");
        for key in ["measured-um", "sigma-um", "predicted-um", "residual-um"] {
            assert_eq!(triples(&d[key]).len(), *poses, "{fig} {key}");
        }
        // The ±1σ bars: the sphere fit's centre uncertainty at σ 0.5 µm per hit.
        for s in triples(&d["sigma-um"]).iter().flatten() {
            assert!(*s > 0.05 && *s < 1.0, "{fig}: σ {s} µm");
        }
    }
    // The predictions are the identified model's: with them, the residual's and the
    // measurement's RMS per direction are those `rtest validate` reports on the same records
    // (its exact prediction at the identified values, the campaign's records on their fitted
    // set-ups, the sweep's refitted on it).
    for (fig, _, _, report, k) in &figures[2..] {
        let d = figure_data(s4, fig);
        let measured = triples(&d["measured-um"]);
        let predicted = triples(&d["predicted-um"]);
        let residual = triples(&d["residual-um"]);
        let x = &report["records"][*k]["per_direction"];
        for (dir_k, name) in ["x", "y", "z"].iter().enumerate() {
            let r = rms(measured
                .iter()
                .zip(&predicted)
                .map(|(m, p)| m[dir_k] - p[dir_k]));
            let want = x[name]["residual_rms_um"].as_f64().unwrap();
            assert!(
                (r - want).abs() < 1e-6,
                "{fig} {name}: {r} µm, validate {want} µm"
            );
            let m = rms(measured.iter().map(|m| m[dir_k]));
            let want = x[name]["measured_rms_um"].as_f64().unwrap();
            assert!(
                (m - want).abs() < 1e-6,
                "{fig} {name}: {m} µm, validate {want} µm"
            );
            for (i, e) in residual.iter().enumerate() {
                let back = measured[i][dir_k] - predicted[i][dir_k];
                assert!((e[dir_k] - back).abs() < 1e-9);
            }
        }
    }
    // The fitted records' figures are those of the same records validated again.
    for (a, b) in [
        ("fig-low-poses", "fig-low-poses-2"),
        ("fig-high-poses", "fig-high-poses-2"),
    ] {
        let (a, b) = (figure_data(s4, a), figure_data(s4, b));
        assert_eq!(a["predicted-um"], b["predicted-um"]);
        assert_eq!(a["measured-um"], b["measured-um"]);
    }
    // The identification's residual is left after the prediction: about the probe's noise.
    let low = figure_data(s4, "fig-low-poses");
    let r = rms(triples(&low["residual-um"]).iter().flatten().copied());
    let fitted = id["records"][0]["residual_rms_um"].as_f64().unwrap();
    assert!((r - fitted).abs() < 1e-6, "{r} µm, identify {fitted} µm");

    // Abscissa: A and C both move on low.csv: the poses numbered, labelled with A and C; C
    // alone on the sweep: its angle.
    assert_eq!(low["abscissa"], "1,2,3,4,5,6,7,8,9,10");
    let low_svg = &s4[s4.find("<figure id=\"fig-low-poses\"").unwrap()..];
    let low_svg = &low_svg[..low_svg.find("</figure>").unwrap()];
    for label in [
        "pose (A, C in deg)",
        "A \u{2212}30",
        "C 300",
        "measured ± σ",
    ] {
        assert!(low_svg.contains(label), "{label}");
    }
    let sweep = figure_data(s4, "fig-sweep-poses");
    assert_eq!(sweep["abscissa"], "0,45,90,135,180,225");
    assert!(s4.contains("Abscissa: C (deg) (A at 0°)."));

    // identify --report draws the same figures of its records.
    let id_html = std::fs::read_to_string(dir.join("id.html")).unwrap();
    let from_identify = figure_data(section_4(&id_html), "fig-low-poses");
    assert_eq!(from_identify["predicted-um"], low["predicted-um"]);
}

#[test]
fn a_probe_file_or_record_that_no_longer_reads_as_identified_is_named_not_drawn() {
    let dir = temp_dir("report-probe-refused");
    check(&dir);
    let report = |out: &str| -> String {
        ok(
            &dir,
            &[
                "report",
                "id.json",
                "v.json",
                "--machine",
                "seed-ac",
                "-o",
                out,
            ],
        );
        let html = std::fs::read_to_string(dir.join(out)).unwrap();
        assert!(
            !html.contains("<figure id=\"fig-low-poses\""),
            "{out}: drawn"
        );
        section_4(&html).to_string()
    };
    // Another probe file under the same name: its digest differs from the one identify read.
    std::fs::write(dir.join("probe.toml"), PROBE.replace("1.5", "1.25")).unwrap();
    let s4 = report("changed.html");
    assert!(
        s4.contains(
            "No pose is drawn: the probe file probe.toml is not the one identify read (SHA-256 "
        ),
        "{s4}"
    );
    // The probe file gone.
    std::fs::remove_file(dir.join("probe.toml")).unwrap();
    let s4 = report("missing.html");
    assert!(
        s4.contains("No pose is drawn: the probe file ") && s4.contains("cannot be read here"),
        "{s4}"
    );
    // The probe file back, a record that no longer reads: named at its line, the others drawn.
    std::fs::write(dir.join("probe.toml"), PROBE).unwrap();
    let text = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    let last = lines.len() - 1;
    lines[last] = "p6,not-a-number";
    std::fs::write(dir.join("sweep.csv"), lines.join("\n")).unwrap();
    ok(
        &dir,
        &[
            "report",
            "id.json",
            "v.json",
            "--machine",
            "seed-ac",
            "-o",
            "bad.html",
        ],
    );
    let html = std::fs::read_to_string(dir.join("bad.html")).unwrap();
    let s4 = section_4(&html);
    assert!(
        s4.contains(&format!(
            "sweep.csv is not drawn: it could not be read (sweep.csv:{}:",
            last + 1
        )),
        "{s4}"
    );
    assert!(s4.contains("<figure id=\"fig-low-poses\""));
    // An identification written before reports named the probe file: said, not drawn.
    let mut id = read_json(&dir.join("id.json"));
    for key in ["file", "sha256", "bytes"] {
        id["probe"].as_object_mut().unwrap().remove(key);
    }
    std::fs::write(dir.join("old.json"), id.to_string()).unwrap();
    ok(
        &dir,
        &[
            "report",
            "old.json",
            "--machine",
            "seed-ac",
            "-o",
            "old.html",
        ],
    );
    let html = std::fs::read_to_string(dir.join("old.html")).unwrap();
    assert!(
        section_4(&html).contains("No pose is drawn: old.json does not name the probe file"),
        "{html}"
    );
}

#[test]
fn the_probe_report_reads_in_a_browser() {
    use crate::support::browser;
    let Some(b) = browser::for_test("the_probe_report_reads_in_a_browser") else {
        return;
    };
    let dir = temp_dir("report-probe-browser");
    check(&dir);
    ok(
        &dir,
        &[
            "report",
            "id.json",
            "v.json",
            "--machine",
            "seed-ac",
            "-o",
            "rep.html",
        ],
    );
    let scratch = dir.join("browser");
    std::fs::create_dir_all(&scratch).unwrap();
    let run = b
        .open(&dir.join("rep.html"), &scratch)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(run.problems(), Vec::<String>::new(), "{run:#?}");
    // The validation bars and the poses of low.csv, high.csv and sweep.csv, each drawn.
    let drawn: Vec<&str> = run
        .figures
        .iter()
        .filter(|f| f.element.starts_with("figure") && f.width > 0.0 && f.height > 0.0)
        .map(|f| f.label.as_str())
        .collect();
    assert!(drawn.len() >= 4, "{:#?}", run.figures);
    assert!(
        run.fonts.iter().any(|f| f.status == "loaded"),
        "{:?}",
        run.fonts
    );
    assert!(run.pdf_pages >= 2, "{} PDF pages", run.pdf_pages);
}
