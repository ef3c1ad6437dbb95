//! Temporary outputs that must not outlive an interrupted run.
//!
//! Every temporary file or staging folder that rendersim writes beside an
//! output is registered here while it exists. [`remove_on_signals`] starts a
//! thread that, on SIGINT, SIGTERM or SIGHUP, removes everything registered
//! and ends the process with status 128 + the signal number, as a shell
//! reports a process ended by that signal. Only temporary paths are ever
//! registered, never a finished output, so the cleanup cannot remove results.
//!
//! Renames that move a staged output into place run under [`while_locked`],
//! so the cleanup never runs in the middle of one: it sees either the staged
//! copy (and removes it) or the swapped-out old copy (and removes that).

use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, Once};

static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn pending() -> MutexGuard<'static, Vec<PathBuf>> {
    PENDING.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// A registered temporary path; dropping it deregisters it (it does not
/// remove the path: the owner does that, or keeps it).
#[derive(Debug)]
pub struct Registered(PathBuf);

impl Registered {
    /// Registers `path` for removal if the process is interrupted.
    pub fn new(path: &Path) -> Self {
        pending().push(path.to_path_buf());
        Registered(path.to_path_buf())
    }
}

impl Drop for Registered {
    fn drop(&mut self) {
        let mut p = pending();
        if let Some(i) = p.iter().rposition(|x| *x == self.0) {
            p.swap_remove(i);
        }
    }
}

/// Runs `f` while no interrupt cleanup can run (renames into place).
pub fn while_locked<R>(f: impl FnOnce() -> R) -> R {
    let _held = pending();
    f()
}

fn remove_path(p: &Path) {
    match std::fs::symlink_metadata(p) {
        Ok(m) if m.is_dir() => {
            let _ = std::fs::remove_dir_all(p);
        }
        Ok(_) => {
            let _ = std::fs::remove_file(p);
        }
        Err(_) => {}
    }
}

/// Removes every registered temporary path now (what the signal thread does).
pub fn remove_all() {
    let mut p = pending();
    for path in p.drain(..) {
        remove_path(&path);
    }
}

/// Starts (once) the thread that removes registered temporary paths on
/// SIGINT, SIGTERM and SIGHUP and then ends the process. Call it from a
/// binary's `main`; a library user who handles signals can call
/// [`remove_all`] from their own handler instead.
pub fn remove_on_signals() {
    static START: Once = Once::new();
    START.call_once(|| {
        #[cfg(unix)]
        {
            use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
            let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
                return;
            };
            let _ = std::thread::Builder::new()
                .name("rendersim-cleanup".into())
                .spawn(move || {
                    if let Some(sig) = signals.forever().next() {
                        // Hold the lock to the end: no rename can start after
                        // the removal and before the exit.
                        let mut p = pending();
                        for path in p.drain(..) {
                            remove_path(&path);
                        }
                        std::process::exit(128 + sig);
                    }
                });
        }
    });
}
