//! Removing the temporaries when the process is interrupted (SIGINT) or terminated (SIGTERM).
//!
//! The first time a temporary is about to be created, SIGINT and SIGTERM are registered with
//! the `signal-hook` crate and a watcher thread waits on its iterator. On a signal the watcher
//! takes the registry's lock, removes every registered temporary (and every directory created
//! for the outputs, if empty), and then terminates the
//! process with the signal's default action (`emulate_default_handler`), so that the parent
//! sees death by that signal, exactly as without this crate.
//!
//! Why `signal-hook` rather than `libc` with a self-pipe: it is exactly that self-pipe and
//! thread, written and reviewed once; its raw handler only writes to the pipe (the one
//! async-signal-safe thing to do), it chains with handlers other code may register through the
//! same registry, and this crate's only `unsafe` for signals is reading a disposition. All the real work —
//! removing files, which is not async-signal-safe — happens on the watcher thread.
//!
//! A signal whose disposition is not the default one when the watcher is installed (ignored, as
//! for a background job started by a non-interactive shell, or handled by the program itself) is
//! left alone: taking it over would turn an ignored signal into a deadly one or override the
//! program's own handling.

use std::sync::Once;
use std::sync::mpsc;
use std::thread;

use libc::c_int;
use signal_hook::consts::{SIGINT, SIGTERM};
use signal_hook::iterator::Signals;
use signal_hook::low_level::emulate_default_handler;

use crate::temp;

/// Installs the watcher once per process (best effort: if it cannot be installed, temporaries
/// are still removed on every error path, only not on a signal).
pub(crate) fn install() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let wanted: Vec<c_int> = [SIGINT, SIGTERM]
            .into_iter()
            .filter(|&s| has_default_action(s))
            .collect();
        if wanted.is_empty() {
            return;
        }
        // Registered on the watcher thread itself, so that nothing is registered unless the
        // thread runs (a registered signal nobody waits for would be swallowed); the caller
        // waits until registration is done.
        let (ready, registered) = mpsc::channel();
        let spawned = thread::Builder::new()
            .name("rtest-output-signals".into())
            .spawn(move || {
                let mut signals = match Signals::new(&wanted) {
                    Ok(s) => s,
                    Err(_) => {
                        let _ = ready.send(());
                        return;
                    }
                };
                let _ = ready.send(());
                if let Some(signal) = signals.forever().next() {
                    let mut live = temp::lock();
                    live.remove_all();
                    // Keeps the lock: the process ends here.
                    let _ = emulate_default_handler(signal);
                }
            });
        if spawned.is_ok() {
            let _ = registered.recv();
        }
    });
}

/// Whether `signal` currently has its default disposition (neither ignored nor handled).
fn has_default_action(signal: c_int) -> bool {
    // SAFETY: `sigaction` with a null new action only reads the current disposition into
    // `old`, a plain C structure for which all-zero bytes are a valid value.
    unsafe {
        let mut old: libc::sigaction = std::mem::zeroed();
        libc::sigaction(signal, std::ptr::null(), &mut old) == 0
            && old.sa_sigaction == libc::SIG_DFL
    }
}
