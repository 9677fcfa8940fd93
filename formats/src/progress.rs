//! Progress of long work, for a program that shows it: the library reports how much of a piece
//! of work is done and never draws anything itself (the command line owns the progress bar).
//!
//! Two hooks: [`Progress`], called by long computations (the suggestion of `rtest plan`, the
//! diagnosis) with the work done so far, and [`ReadProgress`] in
//! [`crate::csv::ReadOptions::progress`], called by every CSV reader with the bytes it has
//! read of its source.

use std::sync::Arc;

/// Receives the progress of a long computation. Calls come from the thread doing the work, in
/// order; `done` never exceeds `total` and grows within one `what` (a new `what` starts again
/// from 0).
pub trait Progress {
    /// `done` of `total` units of the work `what` (a few words for people: `candidates`,
    /// `selection step 2`) are done.
    fn update(&self, what: &str, done: u64, total: u64);
}

impl<F: Fn(&str, u64, u64)> Progress for F {
    fn update(&self, what: &str, done: u64, total: u64) {
        self(what, done, total)
    }
}

/// Progress nobody watches.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Unwatched;

impl Progress for Unwatched {
    fn update(&self, _: &str, _: u64, _: u64) {}
}

/// Called by a CSV reader with the number of bytes it has read of its source so far (after
/// every read of at most [`crate::csv::READ_BUFFER_BYTES`]). A reader that reads a file
/// twice (the time span first) counts each pass from 0.
#[derive(Clone)]
pub struct ReadProgress(pub Arc<dyn Fn(u64) + Send + Sync>);

impl ReadProgress {
    /// A hook calling `f` with the bytes read so far.
    pub fn new(f: impl Fn(u64) + Send + Sync + 'static) -> ReadProgress {
        ReadProgress(Arc::new(f))
    }

    /// Reports `bytes` read so far.
    pub fn read(&self, bytes: u64) {
        (self.0)(bytes)
    }
}

impl std::fmt::Debug for ReadProgress {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ReadProgress")
    }
}

impl PartialEq for ReadProgress {
    /// The same hook (the same function object).
    fn eq(&self, other: &ReadProgress) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicU64, Ordering};

    #[test]
    fn closures_are_progress_and_unwatched_ignores_it() {
        let last = std::cell::Cell::new((0, 0));
        let p = |_: &str, d: u64, t: u64| last.set((d, t));
        p.update("candidates", 3, 7);
        assert_eq!(last.get(), (3, 7));
        Unwatched.update("candidates", 1, 2);
    }

    #[test]
    fn a_read_hook_is_equal_only_to_itself() {
        let seen = Arc::new(AtomicU64::new(0));
        let s = seen.clone();
        let a = ReadProgress::new(move |b| s.store(b, Ordering::Relaxed));
        a.read(42);
        assert_eq!(seen.load(Ordering::Relaxed), 42);
        assert_eq!(a, a.clone());
        assert_ne!(a, ReadProgress::new(|_| {}));
    }
}
