//! Opens a self-contained HTML page in a real headless Chromium and reports what a reader would
//! meet: every network request the page tried, console errors (script exceptions, Content
//! Security Policy violations, failed loads), the rendered size of every figure, a screenshot
//! and a printed PDF.
//!
//! The browser is driven through the DevTools protocol over a pipe (`--remote-debugging-pipe`:
//! commands in on file descriptor 3, answers out on descriptor 4, each message JSON ended by a
//! NUL byte), so everything comes from the page's own session and nothing from the browser's
//! background traffic. Every request other than `file:` and `data:` is paused by the `Fetch`
//! domain and failed before it leaves the machine, and host names resolve to nothing, so a page
//! never reaches the network even when it tries. Every run has a deadline: a browser that does
//! not answer in time is killed with its process group and the run is an error.
//!
//! Lengths are CSS pixels; with a device scale factor of 1 one CSS pixel is one screenshot pixel.

#![allow(dead_code)]

#[path = "devtools.rs"]
mod devtools;

use devtools::{Session, base64, evaluate, file_url, open_tab, print};
use serde_json::{Value, json};
use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Width of the browser window and of the screenshot, CSS px (a laptop screen).
pub const WINDOW_WIDTH: u32 = 1200;
/// Height of the browser window, CSS px; the screenshot covers the whole page below it too.
pub const WINDOW_HEIGHT: u32 = 900;
/// Tallest screenshot taken, px: a longer page is captured down to this depth.
pub const MAX_SCREENSHOT_HEIGHT: u32 = 16384;
/// Time one browser run may take from launch to exit before it is killed.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(30);

/// Names tried on the `PATH`, in order, when `RTEST_BROWSER` is not set.
const CANDIDATES: [&str; 4] = [
    "chromium",
    "chromium-browser",
    "google-chrome",
    "google-chrome-stable",
];

/// The browser to use: `RTEST_BROWSER` when set (a path, or a name looked up on the `PATH`;
/// returned even when it does not exist, so that a wrong setting fails the run loudly instead
/// of skipping it), otherwise the first of chromium, chromium-browser, google-chrome,
/// google-chrome-stable found on the `PATH`.
pub fn find_browser() -> Option<PathBuf> {
    if let Some(b) = std::env::var_os("RTEST_BROWSER").filter(|b| !b.is_empty()) {
        return Some(super::on_path(&b).unwrap_or_else(|| PathBuf::from(b)));
    }
    CANDIDATES.iter().find_map(|c| super::on_path(c.as_ref()))
}

/// The browser for the test named `test`, with [`DEFAULT_TIMEOUT`]; when there is none, `None`
/// after saying so on stderr (past the test harness's capture, so that a skip is seen), or,
/// when [`super::required_in_ci`], a panic that says how to install one.
pub fn for_test(test: &str) -> Option<Browser> {
    match find_browser() {
        Some(path) => Some(Browser {
            path,
            timeout: DEFAULT_TIMEOUT,
        }),
        None if super::required_in_ci() => panic!(
            "{test}: no browser found and CI is set: install Chromium (Debian: \
             `apt-get install -y chromium`) or set RTEST_BROWSER to a Chromium or Chrome"
        ),
        None => {
            let _ = writeln!(
                std::io::stderr(),
                "{test}: skipped, no browser found (install chromium or set RTEST_BROWSER)"
            );
            None
        }
    }
}

/// Where the screenshots and PDFs of the browser tests land for a person to look at:
/// `report-browser/` in Cargo's temporary directory for integration tests (`target/tmp/`).
pub fn artifacts_dir() -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join("report-browser")
}

/// A request the page tried to make (anything but the page itself and `data:` URLs).
#[derive(Debug, Clone)]
pub struct Request {
    /// The URL requested.
    pub url: String,
    /// What became of it: `blocked by the harness, never sent`, `blocked: csp` (by the page's
    /// Content Security Policy), `failed: <network error>`, `loaded`, `sent` (no outcome seen).
    pub outcome: String,
}

/// A message the page's console showed.
#[derive(Debug, Clone)]
pub struct ConsoleMessage {
    /// `error`, `warning`, `info`, `verbose`.
    pub level: String,
    /// Who said it: `exception` (uncaught script error), `console-api` (the page's `console`
    /// calls), or the browser's own sources (`security` for CSP violations, `network`, ...).
    pub source: String,
    /// The message.
    pub text: String,
    /// `url:line` where known (line 1-based), else empty.
    pub location: String,
}

/// The rendered box of one outermost `<svg>` or one `<figure>`.
#[derive(Debug, Clone)]
pub struct RenderedBox {
    /// `svg` or `figure`, with its position among the elements of that name (1-based).
    pub element: String,
    /// What names it for a reader: `id`, `aria-label`, the svg's `<title>` or the figure's
    /// caption (at most 60 characters), else empty.
    pub label: String,
    /// Rendered width, CSS px.
    pub width: f64,
    /// Rendered height, CSS px.
    pub height: f64,
}

/// One font face the page declares (`@font-face`), as the browser's font loading left it.
#[derive(Debug, Clone)]
pub struct FontFaceState {
    /// The family name it declares.
    pub family: String,
    /// `loaded` (decoded and used), `unloaded` (declared, never needed), `error` (the source
    /// did not load or decode: the text falls back to another font), `loading`.
    pub status: String,
}

/// Everything one browser run found out about a page.
#[derive(Debug, Clone)]
pub struct BrowserRun {
    /// The browser's product and version, as it reports them.
    pub browser: String,
    /// Every request the page tried beyond itself and `data:` URLs, in order.
    pub requests: Vec<Request>,
    /// Every console message of the page, in order.
    pub console: Vec<ConsoleMessage>,
    /// Rendered boxes of every outermost `<svg>` and every `<figure>`, in document order.
    pub figures: Vec<RenderedBox>,
    /// Every declared font face, in the order of the page's `document.fonts`.
    pub fonts: Vec<FontFaceState>,
    /// Width and height of the laid-out page, CSS px (`scrollWidth`, `scrollHeight`).
    pub page_size: (f64, f64),
    /// The screenshot (PNG), in [`artifacts_dir`].
    pub screenshot: PathBuf,
    /// Width and height of the screenshot read from its PNG header, px.
    pub screenshot_size: (u32, u32),
    /// Distinct colours in the screenshot, counted on the pixels the browser decoded from it.
    pub screenshot_colours: usize,
    /// The printed PDF, in [`artifacts_dir`].
    pub pdf: PathBuf,
    /// Pages of the PDF (its `/Type /Page` objects).
    pub pdf_pages: usize,
    /// Size of the PDF, bytes.
    pub pdf_bytes: usize,
    /// Size of the PDF the same browser prints from an empty page, bytes.
    pub blank_pdf_bytes: usize,
    /// Time from launching the browser to its exit.
    pub elapsed: Duration,
}

impl BrowserRun {
    /// The console messages at level `error`.
    pub fn errors(&self) -> Vec<&ConsoleMessage> {
        self.console.iter().filter(|m| m.level == "error").collect()
    }

    /// Everything that keeps the page from being a self-contained, readable, printable
    /// report, one sentence each; empty when the page passes.
    pub fn problems(&self) -> Vec<String> {
        let mut p = Vec::new();
        for r in &self.requests {
            p.push(format!("network request to {} ({})", r.url, r.outcome));
        }
        for m in self.errors() {
            p.push(format!(
                "console error [{}] {} at {}",
                m.source, m.text, m.location
            ));
        }
        for f in &self.figures {
            if !(f.width > 0.0 && f.height > 0.0) {
                p.push(format!(
                    "{} {:?} renders {}×{} px",
                    f.element, f.label, f.width, f.height
                ));
            }
        }
        for f in self.fonts.iter().filter(|f| f.status == "error") {
            p.push(format!("font face {:?} did not load or decode", f.family));
        }
        if self.page_size.0 > f64::from(WINDOW_WIDTH) {
            p.push(format!(
                "the page is {} px wide in a {WINDOW_WIDTH} px window (scrolls sideways)",
                self.page_size.0
            ));
        }
        if self.screenshot_colours < 2 {
            p.push(format!(
                "the screenshot {} is one colour",
                self.screenshot.display()
            ));
        }
        if self.pdf_pages == 0 {
            p.push(format!("the PDF {} has no page", self.pdf.display()));
        }
        if self.pdf_bytes <= self.blank_pdf_bytes {
            p.push(format!(
                "the PDF {} ({} bytes) is no larger than an empty page's ({} bytes)",
                self.pdf.display(),
                self.pdf_bytes,
                self.blank_pdf_bytes
            ));
        }
        p
    }
}

/// A browser executable with the deadline of one run.
#[derive(Debug, Clone)]
pub struct Browser {
    /// The executable (Chromium or Chrome).
    pub path: PathBuf,
    /// Time one run may take from launch to exit before the browser is killed.
    pub timeout: Duration,
}

/// Opens `html` in the browser [`find_browser`] gives, with [`DEFAULT_TIMEOUT`]; see
/// [`Browser::open`].
pub fn open_in_browser(html: &Path, scratch: &Path) -> Result<BrowserRun, String> {
    let path = find_browser().ok_or("no browser found (set RTEST_BROWSER or install chromium)")?;
    Browser {
        path,
        timeout: DEFAULT_TIMEOUT,
    }
    .open(html, scratch)
}

impl Browser {
    /// Opens `html` headless in a [`WINDOW_WIDTH`]×[`WINDOW_HEIGHT`] window with a fresh
    /// profile in `scratch`, waits for the load event and the page's fonts, measures the
    /// figures, takes a full-page screenshot and prints to PDF. The screenshot and the PDF are
    /// written to [`artifacts_dir`] as `<file stem>.png` and `<file stem>.pdf`; the browser's
    /// own log goes to `scratch/browser.log`. An error names what failed and ends with the tail
    /// of that log.
    pub fn open(&self, html: &Path, scratch: &Path) -> Result<BrowserRun, String> {
        let html = html
            .canonicalize()
            .map_err(|e| format!("{}: {e}", html.display()))?;
        let stem = html
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .ok_or_else(|| format!("{}: no file name", html.display()))?;
        let out = artifacts_dir();
        std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
        let log = scratch.join("browser.log");
        let started = Instant::now();
        let mut session = Session::launch(self, scratch, &log)?;
        let result = inspect(&mut session, &html, &out.join(&stem));
        let closed = session.close();
        let log_tail = || tail(&log);
        let mut run = result.map_err(|e| format!("{}: {e}{}", html.display(), log_tail()))?;
        closed.map_err(|e| format!("{}: {e}{}", html.display(), log_tail()))?;
        run.elapsed = started.elapsed();
        Ok(run)
    }
}

/// The last lines of the browser's log, as a suffix of an error message.
fn tail(log: &Path) -> String {
    let text = std::fs::read_to_string(log).unwrap_or_default();
    let lines: Vec<&str> = text.lines().collect();
    let last = &lines[lines.len().saturating_sub(8)..];
    if last.is_empty() {
        String::new()
    } else {
        format!("\nlast lines of {}:\n{}", log.display(), last.join("\n"))
    }
}

/// Loads the page in a fresh tab and collects everything; `out` is the path of the screenshot
/// and PDF without extension.
fn inspect(s: &mut Session, html: &Path, out: &Path) -> Result<BrowserRun, String> {
    let browser = s.call("Browser.getVersion", json!({}), None)?["product"]
        .as_str()
        .unwrap_or("unknown")
        .to_string();
    let page = open_tab(s)?;
    let tab = Some(page.as_str());
    for domain in ["Page", "Runtime", "Log", "Network"] {
        s.call(&format!("{domain}.enable"), json!({}), tab)?;
    }
    s.call(
        "Fetch.enable",
        json!({ "patterns": [{ "urlPattern": "*" }] }),
        tab,
    )?;
    let nav = s.call("Page.navigate", json!({ "url": file_url(html) }), tab)?;
    if let Some(e) = nav["errorText"].as_str() {
        return Err(format!("the page did not load: {e}"));
    }
    let document = nav["loaderId"].as_str().unwrap_or_default();
    let mut events = Events::new(document, &page);
    while !events.take(&s.next_event()?) {}
    let measured = evaluate(s, tab, MEASURE)?;
    let measured: Value = serde_json::from_str(measured.as_str().unwrap_or("null"))
        .map_err(|e| format!("the figures' measurement is not JSON: {e}"))?;
    let figures = measured["figures"]
        .as_array()
        .ok_or("the figures were not measured")?
        .iter()
        .map(|f| RenderedBox {
            element: f["element"].as_str().unwrap_or_default().to_string(),
            label: f["label"].as_str().unwrap_or_default().to_string(),
            width: f["width"].as_f64().unwrap_or(f64::NAN),
            height: f["height"].as_f64().unwrap_or(f64::NAN),
        })
        .collect();
    let fonts = measured["fonts"]
        .as_array()
        .ok_or("the fonts were not listed")?
        .iter()
        .map(|f| FontFaceState {
            family: f["family"]
                .as_str()
                .unwrap_or_default()
                .trim_matches('"')
                .to_string(),
            status: f["status"].as_str().unwrap_or_default().to_string(),
        })
        .collect();
    let page_size = (
        measured["width"].as_f64().ok_or("no page width")?,
        measured["height"].as_f64().ok_or("no page height")?,
    );
    let height = (page_size.1.ceil() as u32).clamp(1, MAX_SCREENSHOT_HEIGHT);
    let png = s.call(
        "Page.captureScreenshot",
        json!({ "format": "png", "captureBeyondViewport": true,
                "clip": { "x": 0, "y": 0, "width": WINDOW_WIDTH, "height": height, "scale": 1 } }),
        tab,
    )?;
    let png_b64 = png["data"]
        .as_str()
        .ok_or("no screenshot data")?
        .to_string();
    let png = base64(&png_b64)?;
    let screenshot_size = png_size(&png).ok_or("the screenshot is not a PNG")?;
    if screenshot_size != (WINDOW_WIDTH, height) {
        return Err(format!(
            "the screenshot is {}×{} px, not the {WINDOW_WIDTH}×{height} px asked for",
            screenshot_size.0, screenshot_size.1
        ));
    }
    let screenshot = out.with_extension("png");
    std::fs::write(&screenshot, &png).map_err(|e| format!("{}: {e}", screenshot.display()))?;
    let pdf = print(s, tab)?;
    let pdf_path = out.with_extension("pdf");
    std::fs::write(&pdf_path, &pdf).map_err(|e| format!("{}: {e}", pdf_path.display()))?;
    // An empty tab decodes the screenshot (the browser's own PNG decoder) and prints the
    // empty-page PDF that the page's PDF is compared with.
    let blank = open_tab(s)?;
    let decoded = evaluate(s, Some(&blank), &COUNT_COLOURS.replace("DATA", &png_b64))?;
    let decoded: Value = serde_json::from_str(decoded.as_str().unwrap_or("null"))
        .map_err(|e| format!("the screenshot's decoding is not JSON: {e}"))?;
    if decoded["width"].as_u64() != Some(u64::from(screenshot_size.0))
        || decoded["height"].as_u64() != Some(u64::from(screenshot_size.1))
    {
        return Err(format!(
            "the screenshot decodes to {decoded}, not to its header's size"
        ));
    }
    let blank_pdf = print(s, Some(&blank))?;
    // What the page said after its load event, up to now.
    while let Some(m) = s.pending.pop_front() {
        events.take(&m);
    }
    Ok(BrowserRun {
        browser,
        requests: events.requests,
        console: events.console,
        figures,
        fonts,
        page_size,
        screenshot,
        screenshot_size,
        screenshot_colours: decoded["colours"].as_u64().unwrap_or(0) as usize,
        pdf: pdf_path,
        pdf_pages: pdf_pages(&pdf).ok_or("the PDF does not start with %PDF-")?,
        pdf_bytes: pdf.len(),
        blank_pdf_bytes: blank_pdf.len(),
        elapsed: Duration::ZERO,
    })
}

/// The page's requests and console messages, gathered from its events.
struct Events {
    /// The request id of the page's own document (its navigation's loader id).
    document: String,
    tab: String,
    requests: Vec<Request>,
    by_id: HashMap<String, usize>,
    console: Vec<ConsoleMessage>,
}

impl Events {
    fn new(document: &str, tab: &str) -> Events {
        Events {
            document: document.into(),
            tab: tab.into(),
            requests: Vec::new(),
            by_id: HashMap::new(),
            console: Vec::new(),
        }
    }

    /// Takes one event in; true at the page's load event.
    fn take(&mut self, m: &Value) -> bool {
        if m["sessionId"].as_str() != Some(&self.tab) {
            return false;
        }
        let p = &m["params"];
        match m["method"].as_str().unwrap_or_default() {
            "Page.loadEventFired" => return true,
            "Page.javascriptDialogOpening" => {
                self.note(
                    "error",
                    "dialog",
                    p["message"].as_str().unwrap_or_default(),
                    "",
                );
            }
            "Network.requestWillBeSent" => {
                let url = p["request"]["url"].as_str().unwrap_or_default();
                let own = p["requestId"].as_str() == Some(&self.document);
                if !own && !url.starts_with("data:") {
                    let id = p["requestId"].as_str().unwrap_or_default().to_string();
                    self.by_id.insert(id, self.requests.len());
                    self.requests.push(Request {
                        url: url.into(),
                        outcome: "sent".into(),
                    });
                }
            }
            "Network.loadingFailed" => {
                let outcome = match p["blockedReason"].as_str() {
                    Some("inspector") => "blocked by the harness, never sent".to_string(),
                    Some(b) => format!("blocked: {b}"),
                    None => format!("failed: {}", p["errorText"].as_str().unwrap_or_default()),
                };
                self.outcome(p, outcome);
            }
            "Network.loadingFinished" => self.outcome(p, "loaded".into()),
            "Runtime.exceptionThrown" => {
                let d = &p["exceptionDetails"];
                let text = d["exception"]["description"]
                    .as_str()
                    .or(d["text"].as_str());
                let at = location(d["url"].as_str(), d["lineNumber"].as_u64().map(|l| l + 1));
                self.note("error", "exception", text.unwrap_or_default(), &at);
            }
            "Runtime.consoleAPICalled" => {
                let level = match p["type"].as_str().unwrap_or_default() {
                    "error" | "assert" => "error",
                    "warning" => "warning",
                    "debug" => "verbose",
                    _ => "info",
                };
                let text: Vec<String> = p["args"]
                    .as_array()
                    .into_iter()
                    .flatten()
                    .map(|a| match &a["value"] {
                        Value::String(s) => s.clone(),
                        Value::Null => a["description"].as_str().unwrap_or_default().to_string(),
                        v => v.to_string(),
                    })
                    .collect();
                let frame = &p["stackTrace"]["callFrames"][0];
                let at = location(
                    frame["url"].as_str(),
                    frame["lineNumber"].as_u64().map(|l| l + 1),
                );
                self.note(level, "console-api", &text.join(" "), &at);
            }
            "Log.entryAdded" => {
                let e = &p["entry"];
                let at = location(e["url"].as_str(), e["lineNumber"].as_u64().map(|l| l + 1));
                let (level, source) = (e["level"].as_str(), e["source"].as_str());
                let text = e["text"].as_str().unwrap_or_default();
                self.note(
                    level.unwrap_or("info"),
                    source.unwrap_or("other"),
                    text,
                    &at,
                );
            }
            _ => {}
        }
        false
    }

    fn outcome(&mut self, p: &Value, outcome: String) {
        if let Some(&i) = p["requestId"].as_str().and_then(|id| self.by_id.get(id)) {
            self.requests[i].outcome = outcome;
        }
    }

    fn note(&mut self, level: &str, source: &str, text: &str, location: &str) {
        self.console.push(ConsoleMessage {
            level: level.into(),
            source: source.into(),
            text: text.into(),
            location: location.into(),
        });
    }
}

/// `url:line`, or what of it is known.
fn location(url: Option<&str>, line: Option<u64>) -> String {
    match (url.filter(|u| !u.is_empty()), line) {
        (Some(u), Some(l)) => format!("{u}:{l}"),
        (Some(u), None) => u.into(),
        _ => String::new(),
    }
}

/// Measures, once the page's fonts are in: the page's size, the box of every outermost `<svg>`
/// and every `<figure>`, the state of every declared font face.
const MEASURE: &str = r#"document.fonts.ready.then(() => {
  const count = {};
  const label = e => {
    const t = e.getAttribute('id') || e.getAttribute('aria-label')
      || (e.tagName.toLowerCase() === 'svg' ? e.querySelector(':scope > title')?.textContent
                                            : e.querySelector('figcaption')?.textContent)
      || '';
    return t.trim().replace(/\s+/g, ' ').slice(0, 60);
  };
  const figures = [...document.querySelectorAll('svg, figure')]
    .filter(e => !(e.tagName.toLowerCase() === 'svg' && e.parentElement?.closest('svg')))
    .map(e => {
      const name = e.tagName.toLowerCase();
      count[name] = (count[name] || 0) + 1;
      const r = e.getBoundingClientRect();
      return { element: name + ' ' + count[name], label: label(e), width: r.width, height: r.height };
    });
  const fonts = [...document.fonts].map(f => ({ family: f.family, status: f.status }));
  const d = document.documentElement;
  return JSON.stringify({ figures, fonts, width: d.scrollWidth, height: d.scrollHeight });
})"#;

/// Decodes the PNG (base64 in place of `DATA`) and counts its distinct colours (RGBA).
const COUNT_COLOURS: &str = r#"new Promise((ok, fail) => {
  const img = new Image();
  img.onload = () => {
    const c = document.createElement('canvas');
    c.width = img.naturalWidth; c.height = img.naturalHeight;
    const g = c.getContext('2d');
    g.drawImage(img, 0, 0);
    const px = new Uint32Array(g.getImageData(0, 0, c.width, c.height).data.buffer);
    ok(JSON.stringify({ width: c.width, height: c.height, colours: new Set(px).size }));
  };
  img.onerror = () => fail(new Error('the screenshot does not decode'));
  img.src = 'data:image/png;base64,DATA';
})"#;

/// Width and height from a PNG's signature and IHDR chunk.
fn png_size(png: &[u8]) -> Option<(u32, u32)> {
    let sig = b"\x89PNG\r\n\x1a\n";
    if png.len() < 24 || &png[..8] != sig || &png[12..16] != b"IHDR" {
        return None;
    }
    let be = |b: &[u8]| u32::from_be_bytes([b[0], b[1], b[2], b[3]]);
    Some((be(&png[16..20]), be(&png[20..24])))
}

/// Pages of a PDF (its `/Type /Page` objects, not `/Pages`); `None` when it is not a PDF.
fn pdf_pages(pdf: &[u8]) -> Option<usize> {
    if !pdf.starts_with(b"%PDF-") {
        return None;
    }
    let key = b"/Type /Page";
    let pages = pdf
        .windows(key.len() + 1)
        .filter(|w| &w[..key.len()] == key && !w[key.len()].is_ascii_alphanumeric())
        .count();
    Some(pages)
}
