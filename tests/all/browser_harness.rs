//! The headless-browser harness on small pages with known faults: a self-contained page passes
//! everything; a page that reaches for the network, throws, breaks its Content Security Policy
//! or draws a figure of zero size is caught; a browser that hangs or dies is an error, not a
//! hung test. Without a browser the tests say so and pass, except in CI (`CI` set), where they
//! fail and say how to install one.

use crate::common;
use crate::support::browser;

use browser::{Browser, BrowserRun, WINDOW_WIDTH};
use common::{TempDir, temp_dir_tagged};
use std::path::PathBuf;
use std::time::Duration;

/// Writes `html` as `<name>.html` in a fresh scratch directory and opens it.
fn open(name: &str, html: &str) -> Option<(BrowserRun, TempDir)> {
    let b = browser::for_test(name)?;
    let dir = temp_dir_tagged("browser", name);
    let page = dir.join(format!("{name}.html"));
    std::fs::write(&page, html).expect("fixture written");
    let run = b
        .open(&page, &dir)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    eprintln!(
        "{name}: {} in {:.2} s; screenshot {} ({}×{} px, {} colours), PDF {} ({} pages, {} bytes)",
        run.browser,
        run.elapsed.as_secs_f64(),
        run.screenshot.display(),
        run.screenshot_size.0,
        run.screenshot_size.1,
        run.screenshot_colours,
        run.pdf.display(),
        run.pdf_pages,
        run.pdf_bytes
    );
    Some((run, dir))
}

/// A page like a report: strict CSP (no script, no fetch of anything), the plots' font
/// embedded as a `data:` URL in place of `FONT`, inline styles, inline SVG figures with
/// captions (the second taller than the window), a table.
const GOOD: &str = r##"<!doctype html>
<html lang="en"><head><meta charset="utf-8">
<meta http-equiv="Content-Security-Policy"
      content="default-src 'none'; style-src 'unsafe-inline'; img-src data:; font-src data:">
<title>Check 2026-11-30</title>
<style>
body { font-family: sans-serif; margin: 2em; color: #222; background: #fff; }
figure { margin: 1em 0; } table { border-collapse: collapse; }
td, th { border: 1px solid #999; padding: 0.2em 0.6em; text-align: right; }
@font-face { font-family: "Report Sans"; src: url(data:font/ttf;base64,FONT) format("truetype"); }
body { font-family: "Report Sans", sans-serif; }
</style></head>
<body>
<h1>R-test check</h1>
<figure>
  <svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 400 300" width="400" height="300">
    <title>Residuals</title>
    <rect x="0" y="0" width="400" height="300" fill="#f4f4f4"/>
    <polyline points="20,280 120,150 220,190 380,40" fill="none" stroke="#c03" stroke-width="3"/>
    <text x="20" y="24" font-size="16">ΔX / µm</text>
  </svg>
  <figcaption>Residuals along the path</figcaption>
</figure>
<figure id="trend">
  <svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 120" width="1000" height="1200">
    <circle cx="50" cy="60" r="40" fill="#396"/></svg>
  <figcaption>Trend</figcaption>
</figure>
<table><tr><th>error</th><th>value / µrad</th></tr><tr><td>EB0C</td><td>12.5</td></tr></table>
</body></html>
"##;

/// Standard base64 with padding.
fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        for i in 0..4 {
            if i <= c.len() {
                out.push(char::from(A[(n >> (18 - 6 * i) & 63) as usize]));
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// [`GOOD`] with the plots' DejaVu Sans embedded.
fn good_page() -> String {
    let font = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("plots/fonts/DejaVuSans.ttf");
    let font = std::fs::read(&font).unwrap_or_else(|e| panic!("{}: {e}", font.display()));
    GOOD.replace("FONT", &base64(&font))
}

#[test]
fn a_self_contained_page_passes_everything() {
    let Some((run, _dir)) = open("good", &good_page()) else {
        return;
    };
    assert_eq!(run.problems(), Vec::<String>::new(), "{run:#?}");
    assert!(run.console.is_empty(), "{:#?}", run.console);
    let fonts: Vec<(&str, &str)> = run
        .fonts
        .iter()
        .map(|f| (f.family.as_str(), f.status.as_str()))
        .collect();
    assert_eq!(fonts, [("Report Sans", "loaded")]);
    let boxes: Vec<(&str, &str, f64, f64)> = run
        .figures
        .iter()
        .map(|f| (f.element.as_str(), f.label.as_str(), f.width, f.height))
        .collect();
    assert_eq!(boxes[1], ("svg 1", "Residuals", 400.0, 300.0), "{boxes:#?}");
    assert_eq!(boxes[3], ("svg 2", "", 1000.0, 1200.0), "{boxes:#?}");
    assert_eq!(
        (boxes[0].0, boxes[0].1),
        ("figure 1", "Residuals along the path")
    );
    assert_eq!((boxes[2].0, boxes[2].1), ("figure 2", "trend"));
    assert!(boxes[0].3 > 300.0 && boxes[2].3 > 1200.0, "{boxes:#?}");
    assert_eq!(run.figures.len(), 4, "{boxes:#?}");
    // The whole page, below the window too.
    assert_eq!(run.screenshot_size.0, WINDOW_WIDTH);
    assert!(run.page_size.1 > 1500.0, "{run:#?}");
    assert_eq!(f64::from(run.screenshot_size.1), run.page_size.1.ceil());
    assert!(run.screenshot_colours > 2, "{run:#?}");
    assert!(run.pdf_pages >= 2, "{run:#?}");
    assert!(run.pdf_bytes > run.blank_pdf_bytes, "{run:#?}");
    let png = std::fs::read(&run.screenshot).expect("the screenshot is kept");
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"));
    let pdf = std::fs::read(&run.pdf).expect("the PDF is kept");
    assert!(pdf.starts_with(b"%PDF-"));
}

#[test]
fn requests_beyond_the_file_are_reported_and_never_leave_the_machine() {
    let html = r#"<!doctype html><html><head><meta charset="utf-8">
<link rel="stylesheet" href="https://example.invalid/style.css"></head><body>
<img src="http://example.invalid/x.png" alt="remote">
<img src="http://192.0.2.7/y.png" alt="by address">
<img src="data:image/gif;base64,R0lGODlhAQABAIAAAAAAAP///yH5BAEAAAAALAAAAAABAAEAAAIBRAA7" alt="inline">
</body></html>"#;
    let Some((run, _dir)) = open("network", html) else {
        return;
    };
    let urls: Vec<&str> = run.requests.iter().map(|r| r.url.as_str()).collect();
    assert_eq!(
        urls,
        [
            "https://example.invalid/style.css",
            "http://example.invalid/x.png",
            "http://192.0.2.7/y.png"
        ],
        "{:#?}",
        run.requests
    );
    for r in &run.requests {
        assert_eq!(r.outcome, "blocked by the harness, never sent", "{r:?}");
    }
    let problems = run.problems();
    assert!(
        problems
            .iter()
            .any(|p| p.contains("network request to http://192.0.2.7/y.png"))
    );
}

#[test]
fn a_script_error_is_a_console_error() {
    let html = r#"<!doctype html><html><head><meta charset="utf-8"></head><body><p>text</p>
<script>
console.log("not an error");
throw new Error("deliberate failure");
</script></body></html>"#;
    let Some((run, _dir)) = open("script-error", html) else {
        return;
    };
    let errors = run.errors();
    assert_eq!(errors.len(), 1, "{:#?}", run.console);
    assert_eq!(errors[0].source, "exception");
    assert!(
        errors[0].text.contains("deliberate failure"),
        "{:?}",
        errors[0]
    );
    assert!(
        errors[0].location.ends_with("script-error.html:4"),
        "{:?}",
        errors[0]
    );
    assert!(
        run.console
            .iter()
            .any(|m| m.level == "info" && m.text == "not an error")
    );
    assert!(
        run.problems()
            .iter()
            .any(|p| p.contains("deliberate failure"))
    );
}

#[test]
fn a_content_security_policy_violation_is_a_console_error() {
    let html = r#"<!doctype html><html><head><meta charset="utf-8">
<meta http-equiv="Content-Security-Policy" content="default-src 'none'; style-src 'unsafe-inline'">
</head><body><p>text</p>
<script>document.body.append("script ran");</script>
<img src="http://example.invalid/x.png" alt="remote">
</body></html>"#;
    let Some((run, _dir)) = open("csp", html) else {
        return;
    };
    let csp: Vec<_> = run
        .errors()
        .into_iter()
        .filter(|m| m.source == "security")
        .collect();
    assert_eq!(csp.len(), 2, "{:#?}", run.console);
    assert!(
        csp[0].text.contains("Content Security Policy"),
        "{:?}",
        csp[0]
    );
    assert!(
        csp.iter().any(|m| m.text.contains("inline script")),
        "{csp:#?}"
    );
    assert!(
        csp.iter()
            .any(|m| m.text.contains("http://example.invalid/x.png")),
        "{csp:#?}"
    );
    // The policy stopped the image before any request left the page.
    assert_eq!(run.requests.len(), 1, "{:#?}", run.requests);
    assert_eq!(run.requests[0].outcome, "blocked: csp");
}

#[test]
fn a_font_that_does_not_decode_is_reported() {
    let html = r#"<!doctype html><html><head><meta charset="utf-8"><style>
@font-face { font-family: Broken; src: url(data:font/woff2;base64,d09GMgABAAAAAA==) format("woff2"); }
body { font-family: Broken, sans-serif; }
</style></head><body><p>text in a font that does not decode</p></body></html>"#;
    let Some((run, _dir)) = open("broken-font", html) else {
        return;
    };
    assert_eq!(run.fonts.len(), 1, "{:#?}", run.fonts);
    assert_eq!(
        (run.fonts[0].family.as_str(), run.fonts[0].status.as_str()),
        ("Broken", "error")
    );
    assert_eq!(
        run.problems(),
        ["font face \"Broken\" did not load or decode"]
    );
}

#[test]
fn a_figure_of_zero_size_is_reported() {
    let html = r##"<!doctype html><html><head><meta charset="utf-8"></head><body>
<svg xmlns="http://www.w3.org/2000/svg" width="200" height="100" id="fine">
  <rect width="200" height="100" fill="#369"/></svg>
<svg xmlns="http://www.w3.org/2000/svg" width="0" height="0" id="collapsed">
  <rect width="200" height="100" fill="#369"/></svg>
<figure style="display: none"><svg xmlns="http://www.w3.org/2000/svg" width="50" height="50">
  <title>Hidden</title></svg><figcaption>Hidden figure</figcaption></figure>
</body></html>"##;
    let Some((run, _dir)) = open("zero size", html) else {
        return;
    };
    let sizes: Vec<(&str, &str, f64, f64)> = run
        .figures
        .iter()
        .map(|f| (f.element.as_str(), f.label.as_str(), f.width, f.height))
        .collect();
    assert_eq!(
        sizes,
        [
            ("svg 1", "fine", 200.0, 100.0),
            ("svg 2", "collapsed", 0.0, 0.0),
            ("figure 1", "Hidden figure", 0.0, 0.0),
            ("svg 3", "Hidden", 0.0, 0.0)
        ]
    );
    let problems = run.problems();
    assert_eq!(problems.len(), 3, "{problems:#?}");
    assert!(
        problems[0].contains("svg 2 \"collapsed\" renders 0×0 px"),
        "{problems:#?}"
    );
}

/// A stand-in browser: an executable shell script in `dir`.
fn fake_browser(dir: &std::path::Path, script: &str) -> PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let path = dir.join("fake-browser");
    std::fs::write(&path, format!("#!/bin/sh\n{script}\n")).expect("script written");
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).expect("chmod");
    path
}

#[test]
fn a_browser_that_hangs_is_killed_and_reported() {
    let dir = temp_dir_tagged("browser", "hangs");
    let page = dir.join("page.html");
    std::fs::write(&page, "<!doctype html><p>page</p>").expect("fixture written");
    let path = fake_browser(&dir, "sleep 60");
    let b = Browser {
        path,
        timeout: Duration::from_millis(500),
    };
    let e = b
        .open(&page, &dir)
        .expect_err("a silent browser is an error");
    assert!(
        e.contains("page.html: the browser did not finish within its time limit"),
        "{e}"
    );
}

#[test]
fn a_browser_that_dies_is_reported_with_its_last_words() {
    let dir = temp_dir_tagged("browser", "dies");
    let page = dir.join("page.html");
    std::fs::write(&page, "<!doctype html><p>page</p>").expect("fixture written");
    let path = fake_browser(&dir, "echo 'cannot open display' >&2; exit 1");
    let b = Browser {
        path,
        timeout: Duration::from_secs(10),
    };
    let e = b.open(&page, &dir).expect_err("a dead browser is an error");
    assert!(e.contains("the browser exited before answering"), "{e}");
    assert!(e.contains("browser.log:\ncannot open display"), "{e}");
}

#[test]
fn a_missing_page_is_an_error_naming_it() {
    let Some(b) = browser::for_test("missing") else {
        return;
    };
    let dir = temp_dir_tagged("browser", "missing");
    let e = b
        .open(&dir.join("absent.html"), &dir)
        .expect_err("no page, no run");
    assert!(e.contains("absent.html: No such file"), "{e}");
}
