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
//! copy (and removes it) or the swapped-out old copy (and removes that). A
//! temporary path is registered and created in one step ([`create_registered`]),
//! so an interrupt never falls between the two. The cleanup removes each path
//! until it has stayed gone for a moment, since the main thread may still be
//! writing into a staging folder while it is removed.
//!
//! A process killed outright (SIGKILL) cannot clean up: its temporary paths
//! carry its process id (`.NAME.tmp-PID`, `.NAME.partial-PID`), and the next
//! writer of the same output removes those whose process no longer runs
//! ([`remove_stale_temps`]).

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

/// Registers `path` and creates it with `create` while no interrupt cleanup
/// can run, so an interrupt finds it either absent and unregistered or
/// created and registered. On failure nothing stays registered.
pub fn create_registered<T>(
    path: &Path,
    create: impl FnOnce(&Path) -> std::io::Result<T>,
) -> std::io::Result<(Registered, T)> {
    let mut p = pending();
    let made = create(path)?;
    p.push(path.to_path_buf());
    Ok((Registered(path.to_path_buf()), made))
}

/// Runs `f` while no interrupt cleanup can run (renames into place).
pub fn while_locked<R>(f: impl FnOnce() -> R) -> R {
    let _held = pending();
    f()
}

/// Whether process `pid` still runs (unknown: assume it does).
pub fn process_alive(pid: u32) -> bool {
    #[cfg(unix)]
    {
        let Ok(pid) = libc::pid_t::try_from(pid) else {
            return true;
        };
        // SAFETY: signal 0 only checks that the process exists.
        let r = unsafe { libc::kill(pid, 0) };
        r == 0 || std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
    }
    #[cfg(not(unix))]
    {
        let _ = pid;
        true
    }
}

/// Removes the temporary paths `.NAME.KIND-PID` (for each of `kinds`) in
/// `dir` that processes which no longer run left behind: what a killed
/// writer of the output `NAME` leaves. Paths of running processes, this one
/// included, are kept.
pub fn remove_stale_temps(dir: &Path, name: &str, kinds: &[&str]) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let prefix = format!(".{name}.");
    for e in entries.flatten() {
        let n = e.file_name().to_string_lossy().to_string();
        let Some(rest) = n.strip_prefix(&prefix) else {
            continue;
        };
        let pid = kinds
            .iter()
            .find_map(|k| rest.strip_prefix(k).and_then(|r| r.strip_prefix('-')))
            .and_then(|p| p.parse::<u32>().ok());
        if let Some(pid) = pid
            && pid != std::process::id()
            && !process_alive(pid)
        {
            remove_path(&e.path());
        }
    }
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

/// Removes `paths` until none of them has come back for a moment (another
/// thread may still be writing into a folder as it is removed, which can
/// make a removal fail or bring the folder back), at most about a second.
fn remove_settled(paths: &[PathBuf]) {
    let mut quiet = 0;
    for _ in 0..1000 {
        let mut any = false;
        for path in paths {
            if std::fs::symlink_metadata(path).is_ok() {
                any = true;
                remove_path(path);
            }
        }
        quiet = if any { 0 } else { quiet + 1 };
        if quiet >= 3 {
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
}

/// Removes every registered temporary path now (what the signal thread
/// does, except that it keeps the lock until the process ends).
pub fn remove_all() {
    let mut p = pending();
    let paths: Vec<PathBuf> = p.drain(..).collect();
    remove_settled(&paths);
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
                        // Hold the lock to the end: no rename or registration
                        // can start after the removal and before the exit.
                        let mut p = pending();
                        let paths: Vec<PathBuf> = p.drain(..).collect();
                        remove_settled(&paths);
                        std::process::exit(128 + sig);
                    }
                });
        }
    });
}
