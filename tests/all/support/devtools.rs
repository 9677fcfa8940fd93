//! The DevTools protocol over a pipe: the browser started with `--remote-debugging-pipe`
//! (commands in on file descriptor 3, answers out on descriptor 4, each message JSON ended by a
//! NUL byte), commands with their answers, events, and the tab commands the harness needs
//! (a fresh tab, evaluation, printing). Part of the browser harness (`browser.rs`).

use super::{Browser, WINDOW_HEIGHT, WINDOW_WIDTH};
use serde_json::{Value, json};
use std::collections::VecDeque;
use std::fs::File;
use std::io::{Read, Write};
use std::os::unix::fs::MetadataExt;
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::time::{Duration, Instant};

/// A running browser and its DevTools pipe.
pub(super) struct Session {
    child: Child,
    commands: ChildStdin,
    answers: Receiver<Value>,
    deadline: Instant,
    next_id: u64,
    /// Events read while waiting for an answer, not yet looked at.
    pub(super) pending: VecDeque<Value>,
}

impl Session {
    /// Starts the browser in its own process group, wiring its stdin to descriptor 3 and its
    /// stdout to descriptor 4 (through `sh`, which std cannot do by itself), its own output
    /// into `log`.
    pub(super) fn launch(browser: &Browser, scratch: &Path, log: &Path) -> Result<Session, String> {
        let profile = scratch.join("profile");
        std::fs::create_dir_all(&profile).map_err(|e| format!("{}: {e}", profile.display()))?;
        let log_file = File::create(log).map_err(|e| format!("{}: {e}", log.display()))?;
        let mut args: Vec<String> = vec![
            "--headless".into(),
            "--disable-gpu".into(),
            "--remote-debugging-pipe".into(),
            format!("--user-data-dir={}", profile.display()),
            format!("--window-size={WINDOW_WIDTH},{WINDOW_HEIGHT}"),
            "--no-first-run".into(),
            "--no-default-browser-check".into(),
            "--host-resolver-rules=MAP * ~NOTFOUND".into(),
            "--disable-background-networking".into(),
            "--disable-component-update".into(),
            "--disable-default-apps".into(),
            "--disable-extensions".into(),
            "--disable-sync".into(),
            "--password-store=basic".into(),
            "--use-mock-keychain".into(),
            "--mute-audio".into(),
            "--hide-scrollbars".into(),
            "about:blank".into(),
        ];
        // Chromium refuses to start its sandbox as root.
        if std::fs::metadata("/proc/self").is_ok_and(|m| m.uid() == 0) {
            args.insert(0, "--no-sandbox".into());
        }
        let mut child = Command::new("/bin/sh")
            .arg("-c")
            .arg(r#"exec "$0" "$@" 3<&0 4>&1 1>&2"#)
            .arg(&browser.path)
            .args(&args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(log_file)
            .process_group(0)
            .spawn()
            .map_err(|e| format!("{}: cannot start: {e}", browser.path.display()))?;
        let commands = child.stdin.take().ok_or("no pipe to the browser")?;
        let mut from = child.stdout.take().ok_or("no pipe from the browser")?;
        let (tx, answers) = channel();
        std::thread::spawn(move || {
            let mut buf = Vec::new();
            let mut chunk = vec![0u8; 1 << 16];
            while let Ok(n) = from.read(&mut chunk) {
                if n == 0 {
                    break;
                }
                buf.extend_from_slice(&chunk[..n]);
                while let Some(end) = buf.iter().position(|&b| b == 0) {
                    let message: Vec<u8> = buf.drain(..=end).collect();
                    let Ok(v) = serde_json::from_slice(&message[..end]) else {
                        return;
                    };
                    if tx.send(v).is_err() {
                        return;
                    }
                }
            }
        });
        Ok(Session {
            child,
            commands,
            answers,
            deadline: Instant::now() + browser.timeout,
            next_id: 0,
            pending: VecDeque::new(),
        })
    }

    /// Sends a command without waiting for its answer; returns its id.
    fn send(&mut self, method: &str, params: Value, session: Option<&str>) -> Result<u64, String> {
        self.next_id += 1;
        let mut m = json!({ "id": self.next_id, "method": method, "params": params });
        if let Some(s) = session {
            m["sessionId"] = json!(s);
        }
        let mut bytes = serde_json::to_vec(&m).map_err(|e| e.to_string())?;
        bytes.push(0);
        self.commands
            .write_all(&bytes)
            .and_then(|()| self.commands.flush())
            .map_err(|e| format!("the browser exited before answering (its command pipe: {e})"))?;
        Ok(self.next_id)
    }

    /// The next message from the browser, within the deadline.
    fn receive(&mut self) -> Result<Value, String> {
        let left = self.deadline.saturating_duration_since(Instant::now());
        self.answers.recv_timeout(left).map_err(|e| match e {
            RecvTimeoutError::Timeout => "the browser did not finish within its time limit".into(),
            RecvTimeoutError::Disconnected => "the browser exited before answering".into(),
        })
    }

    /// Sends a command and waits for its result; events that arrive meanwhile are kept.
    pub(super) fn call(
        &mut self,
        method: &str,
        params: Value,
        session: Option<&str>,
    ) -> Result<Value, String> {
        let id = self.send(method, params, session)?;
        loop {
            let m = self.receive()?;
            if m["id"].as_u64() == Some(id) {
                if let Some(e) = m.get("error") {
                    return Err(format!("{method} failed: {e}"));
                }
                return Ok(m["result"].clone());
            }
            if m.get("method").is_some() {
                self.answer(&m)?;
                self.pending.push_back(m);
            }
        }
    }

    /// The next event: one kept while waiting for an answer, else the next one to arrive.
    pub(super) fn next_event(&mut self) -> Result<Value, String> {
        if let Some(m) = self.pending.pop_front() {
            return Ok(m);
        }
        let m = self.receive()?;
        self.answer(&m)?;
        Ok(m)
    }

    /// Answers what holds a page up at once, whatever the harness is waiting for: a paused
    /// request goes on when its URL is `file:` or `data:` and fails otherwise, a dialog is
    /// accepted.
    fn answer(&mut self, m: &Value) -> Result<(), String> {
        let p = &m["params"];
        let tab = m["sessionId"].as_str();
        match m["method"].as_str().unwrap_or_default() {
            "Fetch.requestPaused" => {
                let url = p["request"]["url"].as_str().unwrap_or_default();
                let id = json!(p["requestId"]);
                if url.starts_with("file:") || url.starts_with("data:") {
                    self.send("Fetch.continueRequest", json!({ "requestId": id }), tab)?;
                } else {
                    let r = json!({ "requestId": id, "errorReason": "BlockedByClient" });
                    self.send("Fetch.failRequest", r, tab)?;
                }
            }
            "Page.javascriptDialogOpening" => {
                self.send(
                    "Page.handleJavaScriptDialog",
                    json!({ "accept": true }),
                    tab,
                )?;
            }
            _ => {}
        }
        Ok(())
    }

    /// Asks the browser to close and waits for it to exit until the deadline; kills it when
    /// it does not.
    pub(super) fn close(mut self) -> Result<(), String> {
        let _ = self.send("Browser.close", json!({}), None);
        loop {
            match self.child.try_wait() {
                Ok(Some(_)) => return Ok(()),
                Ok(None) if Instant::now() < self.deadline => {
                    std::thread::sleep(Duration::from_millis(20));
                }
                _ => {
                    self.kill();
                    return Err("the browser did not exit and was killed".into());
                }
            }
        }
    }

    /// Kills the browser's whole process group (its renderers and helpers too).
    pub(super) fn kill(&mut self) {
        // No `--`: dash, the `/bin/sh` of Debian, takes a negative pid as a process group
        // without it and refuses `--`.
        let group = format!("kill -KILL -{}", self.child.id());
        let _ = Command::new("/bin/sh").args(["-c", &group]).status();
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        if matches!(self.child.try_wait(), Ok(None)) {
            self.kill();
        }
    }
}
/// Opens an empty tab [`WINDOW_WIDTH`]×[`WINDOW_HEIGHT`] at scale 1; returns its session id.
pub(super) fn open_tab(s: &mut Session) -> Result<String, String> {
    let target = s.call("Target.createTarget", json!({ "url": "about:blank" }), None)?;
    let attached = s.call(
        "Target.attachToTarget",
        json!({ "targetId": target["targetId"], "flatten": true }),
        None,
    )?;
    let tab = attached["sessionId"]
        .as_str()
        .ok_or("no session id")?
        .to_string();
    s.call(
        "Emulation.setDeviceMetricsOverride",
        json!({ "width": WINDOW_WIDTH, "height": WINDOW_HEIGHT, "deviceScaleFactor": 1,
                "mobile": false }),
        Some(&tab),
    )?;
    Ok(tab)
}

/// Evaluates `expression` (a promise of a string) in the tab; DevTools evaluation is not
/// subject to the page's Content Security Policy.
pub(super) fn evaluate(
    s: &mut Session,
    tab: Option<&str>,
    expression: &str,
) -> Result<Value, String> {
    let r = s.call(
        "Runtime.evaluate",
        json!({ "expression": expression, "awaitPromise": true, "returnByValue": true }),
        tab,
    )?;
    if let Some(e) = r.get("exceptionDetails") {
        return Err(format!("evaluating in the page failed: {e}"));
    }
    Ok(r["result"]["value"].clone())
}

/// Prints the tab to PDF as the print dialog would, without header and footer, on A4 paper
/// unless the page sets its own size (`@page { size: ... }`).
pub(super) fn print(s: &mut Session, tab: Option<&str>) -> Result<Vec<u8>, String> {
    const INCH: f64 = 25.4; // mm
    let r = s.call(
        "Page.printToPDF",
        json!({ "printBackground": true, "displayHeaderFooter": false,
                "paperWidth": 210.0 / INCH, "paperHeight": 297.0 / INCH,
                "preferCSSPageSize": true }),
        tab,
    )?;
    base64(r["data"].as_str().ok_or("no PDF data")?)
}

/// The `file:` URL of an absolute path, percent-encoding every byte but letters, digits,
/// `-._~` and `/`.
pub(super) fn file_url(path: &Path) -> String {
    use std::os::unix::ffi::OsStrExt;
    let mut url = String::from("file://");
    for &b in path.as_os_str().as_bytes() {
        if b.is_ascii_alphanumeric() || b"-._~/".contains(&b) {
            url.push(char::from(b));
        } else {
            url.push_str(&format!("%{b:02X}"));
        }
    }
    url
}

/// Decodes standard base64 (the DevTools protocol's binary data).
pub(super) fn base64(text: &str) -> Result<Vec<u8>, String> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => Some(c - b'A'),
        b'a'..=b'z' => Some(c - b'a' + 26),
        b'0'..=b'9' => Some(c - b'0' + 52),
        b'+' => Some(62),
        b'/' => Some(63),
        _ => None,
    };
    let text = text.trim_end_matches('=').as_bytes();
    let mut out = Vec::with_capacity(text.len() * 3 / 4);
    let (mut acc, mut bits) = (0u32, 0);
    for &c in text {
        acc = (acc << 6) | u32::from(value(c).ok_or("the browser sent invalid base64")?);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Ok(out)
}
