//! Hooks for this crate's own tests; not part of the API. They are per thread, so tests running
//! in parallel threads do not see each other's hooks, and they are off unless a test sets them.

use std::cell::RefCell;
use std::ffi::{OsStr, OsString};

type NameSource = Box<dyn FnMut() -> u64>;
type Hook = Box<dyn Fn()>;

thread_local! {
    static NAME_SOURCE: RefCell<Option<NameSource>> = const { RefCell::new(None) };
    static AFTER_STAGING: RefCell<Option<Hook>> = const { RefCell::new(None) };
    static AFTER_RENAME: RefCell<Option<Hook>> = const { RefCell::new(None) };
}

/// Makes this thread's temporary and backup names use the bits `source` returns instead of
/// random ones (`None`: random again), so that a test can plant files at the exact names.
pub fn set_name_source(source: Option<NameSource>) {
    NAME_SOURCE.with(|s| *s.borrow_mut() = source);
}

/// Runs `hook` on this thread after every temporary of a `write_all` is staged and before any
/// rename (`None`: no hook), so that a test can change the file system or send a signal there.
pub fn set_after_staging(hook: Option<Hook>) {
    AFTER_STAGING.with(|h| *h.borrow_mut() = hook);
}

/// Runs `hook` on this thread after every rename of a temporary over its file (`None`: no
/// hook), so that a test can send a signal between two renames.
pub fn set_after_rename(hook: Option<Hook>) {
    AFTER_RENAME.with(|h| *h.borrow_mut() = hook);
}

/// The name of the temporary for a file `name` whose unpredictable part is `bits`.
pub fn temp_name(name: &OsStr, bits: u64) -> OsString {
    crate::temp::name_for(name, bits, "tmp")
}

/// The name of the backup link for a file `name` whose unpredictable part is `bits`.
pub fn backup_name(name: &OsStr, bits: u64) -> OsString {
    crate::temp::name_for(name, bits, "bak")
}

pub(crate) fn next_name_bits() -> Option<u64> {
    NAME_SOURCE.with(|s| s.borrow_mut().as_mut().map(|f| f()))
}

pub(crate) fn after_staging() {
    AFTER_STAGING.with(|h| {
        if let Some(hook) = h.borrow().as_ref() {
            hook();
        }
    });
}

pub(crate) fn after_rename() {
    AFTER_RENAME.with(|h| {
        if let Some(hook) = h.borrow().as_ref() {
            hook();
        }
    });
}
