//! The HTML report of a whole check, and of a campaign's, opened in a real headless browser
//! (`docs/testing-reports.md`):
//! no request of any kind, no console error, every figure drawn with a non-zero size, the
//! embedded font loaded, a screenshot for a person to look at and the same report printed to
//! PDF through the browser's print. Without a browser the test says so and passes, except in
//! CI (`CI` set), where it fails.

use std::path::Path;

use crate::common;
use common::{TempDir, ok};

use crate::support::browser;

/// Simulates K4 and K1 of seed-ac with the demo truth; identifies the reduced model on K4,
/// validates on K1 against a tolerance file (its verdicts in the report), diagnoses, compensates the first poses of K1; writes the report of the
/// diagnosis (`d.html`) and of the whole check (`check.html`).
fn a_whole_check(dir: &TempDir) {
    for (path, seed) in [("K4", "1"), ("K1", "2")] {
        let out = format!("{}.csv", path.to_ascii_lowercase());
        ok(
            dir,
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
    let run = |line: &str| ok(dir, &line.split_whitespace().collect::<Vec<_>>());
    run("identify --machine seed-ac --model reduced --data k4.csv --json id.json");
    std::fs::write(
        dir.join("tol.toml"),
        "[[test]]\nname = \"K1\"\ndirection = [\"x\", \"y\", \"z\"]\nmax_um = 10\nrange_um = 15\n",
    )
    .unwrap();
    run(
        "validate --machine seed-ac --params id.json --data k1.csv --tolerance tol.toml --json v1.json",
    );
    run(
        "diagnose --machine seed-ac --model reduced --data k4.csv --validate k1.csv --json d.json --report d.html",
    );
    let k1 = std::fs::read_to_string(dir.join("k1.csv")).unwrap();
    let mut poses = String::from("X,Y,Z,A,C\n");
    for line in k1.lines().filter(|l| !l.starts_with('#')).skip(1).take(20) {
        poses.push_str(&line.split(',').take(5).collect::<Vec<_>>().join(","));
        poses.push('\n');
    }
    std::fs::write(dir.join("poses.csv"), poses).unwrap();
    run(
        "compensate --machine seed-ac --params id.json --path poses.csv -o corrected.csv --json c.json",
    );
    run("report id.json v1.json d.json c.json --machine seed-ac -o check.html");
}

/// Simulates K4, K1 (the ball 40 mm higher) and K2 of seed-ac; identifies the campaign of K4
/// and K1 (two set-ups), validates on K2 (a new set-up, refitted), compensates the first poses of
/// K2; writes the report of the campaign's identification (`c.html`) and of the whole check
/// (`campaign.html`).
fn a_campaign_check(dir: &TempDir) {
    let run = |line: &str| ok(dir, &line.split_whitespace().collect::<Vec<_>>());
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
    run(
        "identify --machine seed-ac --model reduced --campaign c.toml --json c.json --report c.html",
    );
    run("validate --machine seed-ac --params c.json --data k2.csv --json v.json");
    let k2 = std::fs::read_to_string(dir.join("k2.csv")).unwrap();
    let mut poses = String::from("X,Y,Z,A,C\n");
    for line in k2.lines().filter(|l| !l.starts_with('#')).skip(1).take(20) {
        poses.push_str(&line.split(',').take(5).collect::<Vec<_>>().join(","));
        poses.push('\n');
    }
    std::fs::write(dir.join("poses.csv"), poses).unwrap();
    run(
        "compensate --machine seed-ac --params c.json --path poses.csv -o corrected.csv --json comp.json",
    );
    run("report c.json v.json comp.json --machine seed-ac -o campaign.html");
}

/// Opens `page` and asserts it has no problem and at least `figures` figures drawn.
fn opens_cleanly(b: &browser::Browser, dir: &Path, page: &str, figures: usize) {
    let scratch = dir.join(format!("browser-{page}"));
    std::fs::create_dir_all(&scratch).unwrap();
    let run = b
        .open(&dir.join(page), &scratch)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(run.problems(), Vec::<String>::new(), "{page}: {run:#?}");
    let drawn = run
        .figures
        .iter()
        .filter(|f| f.element.starts_with("figure"))
        .count();
    assert!(
        drawn >= figures,
        "{page}: {drawn} figures: {:#?}",
        run.figures
    );
    assert!(
        run.fonts.iter().any(|f| f.status == "loaded"),
        "{page}: the embedded font is used: {:?}",
        run.fonts
    );
    assert!(run.pdf_pages >= 2, "{page}: {} PDF pages", run.pdf_pages);
    eprintln!(
        "{page}: {} figures, {} PDF pages; screenshot {}, PDF {}",
        drawn,
        run.pdf_pages,
        run.screenshot.display(),
        run.pdf.display()
    );
}

#[test]
fn the_report_of_a_check_reads_and_prints_in_a_browser() {
    let Some(b) = browser::for_test("the_report_of_a_check_reads_and_prints_in_a_browser") else {
        return;
    };
    let dir = common::temp_dir_tagged("report-browser", "check");
    a_whole_check(&dir);
    // The validation bars, the spectrum, the paths of K4 and K1; the verdicts' table.
    opens_cleanly(&b, &dir, "check.html", 4);
    let check = std::fs::read_to_string(dir.join("check.html")).unwrap();
    assert!(check.contains("<h3>Verdicts against the tolerances of tol.toml</h3>"));
    // The identified model's paths, the spectrum, the diagnosis's paths of K4 and K1.
    opens_cleanly(&b, &dir, "d.html", 3);
    // A campaign: its records' paths (K4 and K1 fitted, K2 validated) and the validation bars.
    let campaign = common::temp_dir_tagged("report-browser", "campaign");
    a_campaign_check(&campaign);
    opens_cleanly(&b, &campaign, "c.html", 2);
    opens_cleanly(&b, &campaign, "campaign.html", 4);
}
