//! Progress bars on standard error for the long work of a verb: reading a measurement file or
//! the records of a campaign, validating a campaign's records, the suggestion of `rtest plan`,
//! a diagnosis. The library reports progress
//! (`formats::progress`); this module alone draws.
//!
//! A bar is drawn only when standard error is a terminal, never when standard output carries
//! the JSON report (`--json -`: the text for people then goes to standard error), and only once
//! the work has taken [`DEFAULT_DELAY`] (or `RTEST_PROGRESS_DELAY_MS` milliseconds): short work
//! draws nothing. The bar is cleared when the work ends, finished or failed, so nothing else
//! on standard error changes.

use formats::progress::{Progress, ReadProgress};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// How long work runs before its bar is drawn.
pub const DEFAULT_DELAY: Duration = Duration::from_millis(500);

/// The environment variable that sets the delay before a bar is drawn, in milliseconds.
pub const DELAY_VARIABLE: &str = "RTEST_PROGRESS_DELAY_MS";

/// The delay before a bar is drawn: [`DELAY_VARIABLE`] when it holds a whole number of
/// milliseconds, else [`DEFAULT_DELAY`].
fn delay() -> Duration {
    std::env::var(DELAY_VARIABLE)
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok())
        .map_or(DEFAULT_DELAY, Duration::from_millis)
}

/// Whether a verb may draw a bar: standard error is a terminal and standard output does not
/// carry the JSON report (`json_on_stdout`).
pub fn wanted(json_on_stdout: bool) -> bool {
    !json_on_stdout && std::io::stderr().is_terminal()
}

/// What a bar shares with the hooks that move it.
#[derive(Clone)]
struct Shared {
    bar: ProgressBar,
    start: Instant,
    delay: Duration,
    drawn: Arc<AtomicBool>,
}

impl Shared {
    /// Moves the bar to `done` of `total` of `what`, drawing it once the delay has passed.
    fn set(&self, what: &str, done: u64, total: u64) {
        if !self.drawn.load(Ordering::Relaxed) && self.start.elapsed() >= self.delay {
            self.drawn.store(true, Ordering::Relaxed);
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
        // The numbers first, in one update, then the words when they change: the bar never
        // shows the count of one piece of work against the total of another.
        self.bar.update(|s| {
            s.set_len(total);
            s.set_pos(done.min(total));
        });
        if self.bar.message() != what {
            self.bar.set_message(what.to_string());
        }
    }
}

/// A bar for one piece of work, cleared when dropped (the work finished or failed). Without
/// [`wanted`] it draws nothing at all.
pub struct Bar {
    shared: Option<Shared>,
}

impl Bar {
    /// A bar, drawn only when `wanted` (see [`wanted`]) and once the work has lasted the delay;
    /// `bytes` shows the counts as sizes (reading a file).
    pub fn new(wanted: bool, bytes: bool) -> Bar {
        if !wanted {
            return Bar { shared: None };
        }
        let template = if bytes {
            "{msg} [{bar:30}] {bytes}/{total_bytes} ({eta} left)"
        } else {
            "{msg} [{bar:30}] {pos}/{len} ({elapsed})"
        };
        let bar = ProgressBar::with_draw_target(Some(0), ProgressDrawTarget::hidden());
        if let Ok(style) = ProgressStyle::with_template(template) {
            bar.set_style(style.progress_chars("=> "));
        }
        Bar {
            shared: Some(Shared {
                bar,
                start: Instant::now(),
                delay: delay(),
                drawn: Arc::new(AtomicBool::new(false)),
            }),
        }
    }

    /// The hook for a CSV reader of `path`: the bar follows the bytes read of the file's size
    /// (`None` without a bar, or when the size is unknown: a pipe has none).
    pub fn read_hook(&self, path: &Path) -> Option<ReadProgress> {
        let s = self.shared.clone()?;
        let size = std::fs::metadata(path).ok().filter(|f| f.is_file())?.len();
        let what = format!("reading {}", path.display());
        Some(ReadProgress::new(move |read| s.set(&what, read, size)))
    }
}

impl Bar {
    /// The hook for CSV readers of `paths`, read whole one after the other (the records of a
    /// campaign): the bar follows the bytes read of all of them together (`None` without a
    /// bar, or when a size is unknown). A reader's count falling back marks the next file.
    pub fn read_all_hook(&self, paths: &[std::path::PathBuf]) -> Option<ReadProgress> {
        let s = self.shared.clone()?;
        let mut sizes = Vec::with_capacity(paths.len());
        for p in paths {
            sizes.push(std::fs::metadata(p).ok().filter(|f| f.is_file())?.len());
        }
        let total: u64 = sizes.iter().sum();
        let what = match paths.len() {
            1 => format!("reading {}", paths[0].display()),
            n => format!("reading {n} records"),
        };
        // (bytes of the files done, bytes read of the current one)
        let state = Arc::new(std::sync::Mutex::new((0u64, 0u64)));
        Some(ReadProgress::new(move |read| {
            let done = {
                let Ok(mut st) = state.lock() else {
                    return;
                };
                if read < st.1 {
                    st.0 += st.1;
                }
                st.1 = read;
                st.0 + read
            };
            s.set(&what, done, total);
        }))
    }
}

impl Progress for Bar {
    fn update(&self, what: &str, done: u64, total: u64) {
        if let Some(s) = &self.shared {
            s.set(what, done, total);
        }
    }
}

impl Drop for Bar {
    fn drop(&mut self) {
        if let Some(s) = &self.shared {
            s.bar.finish_and_clear();
        }
    }
}

/// A bar for reading `path` and the read options that move it (a copy of `read`): keep the
/// bar while the file is read, and drop it after (it clears itself).
pub fn reading(
    wanted: bool,
    path: &Path,
    read: &formats::csv::ReadOptions,
) -> (Bar, formats::csv::ReadOptions) {
    let bar = Bar::new(wanted, true);
    let mut read = read.clone();
    read.progress = bar.read_hook(path);
    (bar, read)
}

/// A bar for reading the records `paths` one after the other and the read options that move it
/// (a copy of `read`): keep the bar while they are read, and drop it after.
pub fn reading_all(
    wanted: bool,
    paths: &[std::path::PathBuf],
    read: &formats::csv::ReadOptions,
) -> (Bar, formats::csv::ReadOptions) {
    let bar = Bar::new(wanted, true);
    let mut read = read.clone();
    read.progress = bar.read_all_hook(paths);
    (bar, read)
}

/// A bar counting `what` (records validated), drawn as the others.
pub fn counting(wanted: bool) -> Bar {
    Bar::new(wanted, false)
}
