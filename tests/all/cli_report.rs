//! End-to-end tests of the HTML report: `identify --report`, `diagnose --report`, `compensate
//! --report` and `rtest report` from the JSON files, on measurements simulated by `rtest
//! simulate` on the exact virtual machine; every report self-contained (no address, no script,
//! every figure sized and scalable); bad inputs refused with one stderr line, the project's exit
//! code and no output file.

use std::path::Path;

use crate::common::{self, temp_dir};
use common::{TempDir, entries, fails, ok};

/// k4.csv and k1.csv of seed-ac with the demo truth, and `id.json`: the reduced model
/// identified on K4, and `v1.json`: its validation on K1.
fn set_up(name: &str) -> TempDir {
    let dir = temp_dir(name);
    for (path, seed) in [("K4", "1"), ("K1", "2")] {
        let out = format!("{}.csv", path.to_ascii_lowercase());
        ok(
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
        );
    }
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
    ok(
        &dir,
        &[
            "validate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--data",
            "k1.csv",
            "--json",
            "v1.json",
        ],
    );
    dir
}

fn read(dir: &Path, name: &str) -> String {
    std::fs::read_to_string(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The value of attribute `name` in the tag starting `tag`.
fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let p = format!(" {name}=\"");
    let start = tag.find(&p)? + p.len();
    Some(&tag[start..start + tag[start..].find('"')?])
}

/// Checks what a browser needs of `html` to make no request and draw every figure: the
/// Content-Security-Policy, no address, no script, references to `data:` and `#` only, every
/// `<svg>` with a positive width and height and a viewBox, inside a `<figure>` with an id and a
/// caption. Returns the number of figures.
fn check_self_contained(html: &str) -> usize {
    assert!(html.starts_with("<!DOCTYPE html>"));
    assert!(html.contains(
        "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; style-src 'unsafe-inline'; font-src data:; img-src data:\">"
    ));
    for bad in [
        "http://",
        "https://",
        "<script",
        "<link",
        "<iframe",
        "<img",
        "javascript:",
    ] {
        assert!(!html.contains(bad), "the report contains {bad}");
    }
    for key in ["src=", "href=", "url("] {
        for (at, _) in html.match_indices(key) {
            let r = &html[at..(at + 30).min(html.len())];
            assert!(
                r.starts_with("src=\"data:")
                    || r.starts_with("url(\"data:")
                    || r.starts_with("href=\"#"),
                "a reference that leaves the page: {r}"
            );
        }
    }
    let svgs: Vec<&str> = html
        .match_indices("<svg")
        .map(|(at, _)| {
            let rest = &html[at..];
            &rest[..rest.find('>').unwrap()]
        })
        .collect();
    for tag in &svgs {
        for a in ["width", "height"] {
            let v: f64 = attribute(tag, a)
                .unwrap_or_else(|| panic!("no {a}: {tag}"))
                .parse()
                .unwrap();
            assert!(v > 0.0, "{tag}");
        }
        assert!(attribute(tag, "viewBox").is_some(), "{tag}");
    }
    assert_eq!(html.matches("<figure id=\"fig-").count(), svgs.len());
    assert_eq!(html.matches("<figcaption>").count(), svgs.len());
    svgs.len()
}

/// The headings of a report, in order.
fn headings(html: &str) -> Vec<&str> {
    html.lines()
        .filter(|l| l.starts_with("<h2>") || l.starts_with("<h3>"))
        .collect()
}

#[test]
fn identify_report_holds_the_values_and_says_what_is_absent() {
    let dir = set_up("identify");
    let out = ok(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "k4.csv",
            "--report",
            "id.html",
        ],
    );
    assert!(out.contains("Wrote id.html"), "{out}");
    let html = read(&dir, "id.html");
    // The fitted record, measured against predicted along its path (against C).
    assert_eq!(check_self_contained(&html), 1);
    assert!(html.contains("<figure id=\"fig-k4-path\">"));
    assert!(html.contains("identified model (reduced)"));
    assert!(html.contains("Abscissa: C (deg)."));
    assert!(html.contains("<h1>R-test check of seed-ac</h1>"));
    // The values of the JSON, with their uncertainty, in the table.
    let id: serde_json::Value = serde_json::from_str(&read(&dir, "id.json")).unwrap();
    let xoc = id["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "XOC")
        .unwrap();
    let std = xoc["std"].as_f64().unwrap();
    assert!(std > 0.0);
    assert!(
        html.contains("<td>XOC</td><td class=\"num\">"),
        "no XOC row"
    );
    // The input file with its SHA-256, the axes of the machine.
    assert!(html.contains("<td>--data</td><td>k4.csv</td>"));
    assert!(html.contains("<span class=\"hash\">"));
    assert!(html.contains("<caption>Axes</caption>"));
    // Absent parts, one line each.
    for part in ["No validation", "No diagnosis", "No compensation"] {
        assert!(
            html.contains(&format!("<p class=\"absent\">{part} in this report")),
            "{part}"
        );
    }
}

#[test]
fn the_whole_check_from_json_files_and_from_the_verbs() {
    let dir = set_up("whole");
    ok(
        &dir,
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
            "--json",
            "d.json",
            "--report",
            "d.html",
        ],
    );
    let d_html = read(&dir, "d.html");
    // Path figures of K4 and K1 and the spectrum of K4.
    assert_eq!(check_self_contained(&d_html), 3, "{:?}", headings(&d_html));
    assert!(d_html.contains("<figure id=\"fig-k4-path\">"));
    assert!(d_html.contains("<figure id=\"fig-k1-path\">"));
    assert!(d_html.contains("<figure id=\"fig-diagnosis-spectrum\">"));
    assert!(d_html.contains("ECC@harmonic:2"));

    // The poses of the compensation: the first 20 of K1.
    let k1 = read(&dir, "k1.csv");
    let mut poses = String::from("X,Y,Z,A,C\n");
    for line in k1.lines().filter(|l| !l.starts_with('#')).skip(1).take(20) {
        poses.push_str(&line.split(',').take(5).collect::<Vec<_>>().join(","));
        poses.push('\n');
    }
    std::fs::write(dir.join("poses.csv"), poses).unwrap();
    ok(
        &dir,
        &[
            "compensate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--path",
            "poses.csv",
            "-o",
            "corrected.csv",
            "--json",
            "c.json",
            "--report",
            "c.html",
        ],
    );
    let c_html = read(&dir, "c.html");
    check_self_contained(&c_html);
    assert!(c_html.contains("<h2>6. Compensation</h2>"));
    assert!(c_html.contains("<caption>Corrections per axis"));
    assert!(
        c_html.contains("<h2>3. Identified values</h2>\n<dl"),
        "the identification of --params"
    );

    let out = ok(
        &dir,
        &[
            "report",
            "id.json",
            "v1.json",
            "d.json",
            "c.json",
            "--machine",
            "seed-ac",
            "-o",
            "check.html",
        ],
    );
    assert!(out.contains("Wrote check.html"), "{out}");
    let html = read(&dir, "check.html");
    // The validation figure, the spectrum, and the paths of K4 (fitted) and K1 (validation)
    // read from the records the reports name.
    assert_eq!(check_self_contained(&html), 4);
    assert!(html.contains("<figure id=\"fig-k4-path\">"));
    assert!(html.contains("<figure id=\"fig-k1-path\">"));
    assert!(html.contains("k1.csv (validation): measured and predicted error"));
    // Without the records (beside the reports), the report says what is not drawn and where
    // each record was looked for.
    let away = dir.join("away");
    std::fs::create_dir(&away).unwrap();
    for f in ["id.json", "v1.json"] {
        std::fs::copy(dir.join(f), away.join(f)).unwrap();
    }
    ok(&away, &["report", "id.json", "v1.json", "-o", "away.html"]);
    let html_away = read(&away, "away.html");
    assert_eq!(
        check_self_contained(&html_away),
        1,
        "the validation figure only"
    );
    assert!(html_away.contains("k4.csv is not drawn: k4.csv: cannot be read here"));
    assert!(html_away.contains("k1.csv is not drawn: k1.csv: cannot be read here"));
    assert!(html_away.contains("not hashed: cannot be read here"));
    assert!(!html.contains(" in this report ("), "every part is given");
    // The records the reports name are hashed, found beside the reports.
    for f in ["k4.csv", "k1.csv", "poses.csv", "id.json"] {
        assert!(
            html.contains(&format!("<td>{f}</td><td class=\"num\">")),
            "{f} hashed"
        );
    }
    // With the time each was last modified (UTC).
    let at = html.rfind("<td>k4.csv</td><td class=\"num\">").unwrap();
    let cells: Vec<&str> = html[at..].splitn(5, "<td").collect();
    assert!(
        cells[3].starts_with(">20") && cells[3].contains('T') && cells[3].contains("Z</td>"),
        "{}",
        cells[3]
    );
    insta::assert_snapshot!(headings(&html).join("\n"));
}

#[test]
fn bad_inputs_are_refused_without_an_output() {
    let dir = set_up("bad");
    let run = |args: &[&str], code: i32, needles: &[&str]| {
        fails(&dir, args, code, needles);
        assert!(!dir.join("r.html").exists(), "{args:?} left an output");
    };
    // A CSV given instead of a JSON.
    run(
        &["report", "id.json", "k4.csv", "-o", "r.html"],
        1,
        &["k4.csv: not a report of rtest (not JSON: ", "line 1 column"],
    );
    // A JSON of no verb.
    std::fs::write(dir.join("other.json"), "{\"rows\": [1, 2]}\n").unwrap();
    run(
        &["report", "other.json", "-o", "r.html"],
        1,
        &["other.json: not a report of rtest"],
    );
    // Two reports of different machines.
    let v =
        read(&dir, "v1.json").replace("\"machine\": \"seed-ac\"", "\"machine\": \"head-table-bc\"");
    std::fs::write(dir.join("v-other.json"), v).unwrap();
    run(
        &["report", "id.json", "v-other.json", "-o", "r.html"],
        1,
        &[
            "v-other.json and id.json disagree",
            "head-table-bc",
            "two machines",
        ],
    );
    // A malformed field, named with its line.
    let v = read(&dir, "v1.json").replacen("\"samples\": ", "\"samples\": -", 1);
    std::fs::write(dir.join("v-bad.json"), v).unwrap();
    run(
        &["report", "v-bad.json", "-o", "r.html"],
        1,
        &["v-bad.json: validation report: ", "line "],
    );
    // An output in a missing directory.
    fails(
        &dir,
        &["report", "id.json", "-o", "missing/r.html"],
        1,
        &["missing"],
    );
    assert!(!dir.join("missing").exists());
    fails(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "k4.csv",
            "--report",
            "missing/r.html",
        ],
        1,
        &["--report"],
    );
    // compensate --report summarises corrected poses: without --path it is a usage error.
    run(
        &[
            "compensate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--kinematics-out",
            "k.toml",
            "--report",
            "r.html",
        ],
        2,
        &["--report summarises corrected poses: give --path"],
    );
    assert!(!dir.join("k.toml").exists());
    // No report given; the report as an input.
    run(&["report", "-o", "r.html"], 2, &[]);
    fails(
        &dir,
        &["report", "id.json", "-o", "id.json"],
        2,
        &["id.json"],
    );
    assert!(
        entries(&dir).iter().all(|e| !e.ends_with(".html")),
        "{:?}",
        entries(&dir)
    );
}

#[test]
fn the_verb_documents_itself_and_its_usage_errors_name_it() {
    let dir = temp_dir("help");
    let help = ok(&dir, &["report", "--help"]);
    for s in [
        "µm",
        "µrad",
        "SHA-256",
        "Content-Security-Policy",
        "3 a computation failed",
    ] {
        assert!(help.contains(s), "`{s}` not in the help");
    }
    fails(&dir, &["report", "--bogus"], 2, &["rtest report --help"]);
    let top = ok(&dir, &["--help"]);
    assert!(top.contains("report"), "{top}");
}

/// A campaign: K4 with the ball where the description puts it, K1 with the ball 40 mm higher
/// (each its own set-up), identified together; K2 validated on a new set-up (its set-up errors
/// refitted on it); poses compensated. `identify --report` and `rtest report` of the campaign
/// identification, its validation and the compensation hold every section: the records with
/// their ball positions and set-ups, the shared values with their uncertainties and what the
/// records cannot separate, the values of each set-up, each record's figure, the validated
/// record's new set-up with its refitted values, the compensation with the set-ups left out.
#[test]
fn the_report_of_a_campaign_and_its_validation() {
    let dir = temp_dir("campaign");
    let run = |line: &str| ok(&dir, &common::words(line));
    run("simulate --machine seed-ac --path K4 --truth seed-ac-demo --seed 1 -o k4.csv");
    run(
        "simulate --machine seed-ac --path K1 --truth seed-ac-demo --seed 2 --param Zw=251.537 -o k1.csv",
    );
    run("simulate --machine seed-ac --path K2 --truth seed-ac-demo --seed 3 -o k2.csv");
    std::fs::write(
        dir.join("c.toml"),
        "[[record]]\nfile = \"k4.csv\"\n\n[[record]]\nfile = \"k1.csv\"\nsetup = \"high\"\nparams = { Zw = 251.537 }\n",
    )
    .unwrap();
    let out = run(
        "identify --machine seed-ac --model reduced --terms ECC@harmonic:2 --campaign c.toml \
         --json c.json --report id.html",
    );
    assert!(out.contains("Wrote id.html"), "{out}");
    let html = read(&dir, "id.html");
    // Each record measured against predicted along its path.
    assert_eq!(check_self_contained(&html), 2, "{:?}", headings(&html));
    assert!(html.contains("<figure id=\"fig-k4-path\">"));
    assert!(html.contains("<figure id=\"fig-k1-path\">"));
    for h in [
        "<h3>Shared values: the machine&#39;s errors</h3>",
        "<h3>Set-up k4</h3>",
        "<h3>Set-up high</h3>",
    ] {
        assert!(html.contains(h), "{h} in {:?}", headings(&html));
    }
    // The records with their set-ups and ball positions (the machine is known: against its
    // defaults).
    assert!(
        html.contains("<td>k1</td><td>high</td><td>k1.csv</td>"),
        "records table"
    );
    assert!(html.contains("<td>Zw = 251.537</td>"), "K1's ball position");
    assert!(
        html.contains("<td>as the machine&#39;s defaults</td>"),
        "K4's"
    );
    assert!(html.contains("<td>XOW[high]</td><td class=\"num\">"));
    assert!(html.contains("<td>ECC@harmonic:2:sin</td><td class=\"num\">"));
    assert!(html.contains("2 records on 2 set-ups"));

    run("validate --machine seed-ac --params c.json --data k2.csv --json v.json");
    let k2 = read(&dir, "k2.csv");
    let mut poses = String::from("X,Y,Z,A,C\n");
    for line in k2.lines().filter(|l| !l.starts_with('#')).skip(1).take(20) {
        poses.push_str(&line.split(',').take(5).collect::<Vec<_>>().join(","));
        poses.push('\n');
    }
    std::fs::write(dir.join("poses.csv"), poses).unwrap();
    run(
        "compensate --machine seed-ac --params c.json --path poses.csv -o corrected.csv \
         --json comp.json --report comp.html",
    );
    let comp = read(&dir, "comp.html");
    check_self_contained(&comp);
    assert!(
        comp.contains("<td>XOW[high]</td><td>a set-up error"),
        "left out"
    );
    let out = run("report c.json v.json comp.json --machine seed-ac -o check.html");
    assert!(out.contains("Wrote check.html"), "{out}");
    let html = read(&dir, "check.html");
    // The validation bars, and the paths of K4, K1 (fitted) and K2 (validated).
    assert_eq!(check_self_contained(&html), 4, "{:?}", headings(&html));
    assert!(html.contains("k2.csv (validation): measured and predicted error"));
    assert!(html.contains("<h3>Set-ups of the validated records</h3>"));
    assert!(html.contains("new: its set-up errors refitted on the record"));
    assert!(html.contains("XOW[k2] = "), "the refitted values");
    assert!(html.contains("<p class=\"absent\">No diagnosis in this report"));
    for f in ["k4.csv", "k1.csv", "k2.csv", "c.json", "v.json"] {
        assert!(
            html.contains(&format!("<td>{f}</td><td class=\"num\">")),
            "{f} hashed"
        );
    }
    // The validation's JSON is of one record on a new set-up; the identification's of two.
    let v: serde_json::Value = serde_json::from_str(&read(&dir, "v.json")).unwrap();
    assert_eq!(v["version"], 2);
    assert_eq!(v["records"][0]["setup"], "k2");
    assert_eq!(v["records"][0]["setup_fitted"], false);
    let c: serde_json::Value = serde_json::from_str(&read(&dir, "c.json")).unwrap();
    assert_eq!(c["kind"], "campaign");
    assert_eq!(c["records"][1]["params"]["Zw"], 251.537);
}

/// The error groups of a campaign's diagnosis: the five records of `seed-ac-budget` (every
/// error of the topology) diagnosed from the command line; the groups selected after the
/// findings are in the JSON, in the text and, with what the records left out in turn say of
/// each, in the HTML report, the same in every one.
#[test]
fn the_error_groups_of_a_campaign_diagnosis_are_reported() {
    let dir = temp_dir("groups");
    let run = |line: &str| ok(&dir, &common::words(line));
    for (path, seed, file, zw) in [
        ("K4", 1, "k4", ""),
        ("K1", 2, "k1", ""),
        ("K2", 3, "k2", ""),
        ("K4", 4, "k4-high", " --param Zw=261.537"),
        ("K1", 5, "k1-high", " --param Zw=261.537"),
    ] {
        run(&format!(
            "simulate --machine seed-ac --path {path} --truth seed-ac-budget --seed {seed}{zw} -o {file}.csv"
        ));
    }
    let mut campaign = String::from("machine = \"seed-ac\"\n");
    for (file, setup) in [
        ("k4", "low"),
        ("k1", "low"),
        ("k2", "low"),
        ("k4-high", "high"),
        ("k1-high", "high"),
    ] {
        campaign.push_str(&format!(
            "[[record]]\nfile = \"{file}.csv\"\nsetup = \"{setup}\"\n"
        ));
        if setup == "high" {
            campaign.push_str("params = { Zw = 261.537 }\n");
        }
    }
    std::fs::write(dir.join("c.toml"), campaign).unwrap();
    let text = run(
        "diagnose --machine seed-ac --model reduced --campaign c.toml --json d.json --report d.html",
    );
    let json: serde_json::Value = serde_json::from_str(&read(&dir, "d.json")).unwrap();
    let groups = json["groups"].as_array().expect("groups in the JSON");
    assert!(!groups.is_empty(), "no group selected: {text}");
    assert!(text.contains("Error groups"), "{text}");
    let html = read(&dir, "d.html");
    check_self_contained(&html);
    assert!(
        html.contains("<h3>Error groups</h3>"),
        "{:?}",
        headings(&html)
    );
    for g in groups {
        let name = g["name"].as_str().unwrap();
        assert!(text.contains(name), "{name} in the text");
        let escaped = name.replace('\'', "&#39;");
        assert!(
            html.contains(&format!("<td>{escaped}</td>")),
            "{name} in the HTML"
        );
        let in_model = if g["confirmed"].as_bool().unwrap() {
            "in"
        } else {
            "left out"
        };
        let members = g["terms"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t.as_str().unwrap())
            .collect::<Vec<_>>()
            .join(" ");
        assert!(
            html.contains(&format!("<td>{members}</td>")),
            "{name}'s members"
        );
        // Its row ends with whether it is in the extended model.
        let row = &html[html.find(&format!("<td>{escaped}</td>")).unwrap()..];
        let row = &row[..row.find("</tr>").unwrap()];
        assert!(row.ends_with(&format!("<td>{in_model}</td>")), "{row}");
    }
}
