//! Feedback while a command works: a spinner on standard error saying what
//! is being done and for how long, drawn only when standard error is a
//! terminal and only once the work has taken two seconds, so quick commands
//! and everything piped or redirected print nothing extra. `experiment`
//! draws its own bar over the runs instead.
//!
//! Lines a command prints while the spinner may be drawn go through
//! [`suspend`], which takes the spinner off the screen for the print.
//! `RENDERSIM_PROGRESS_AFTER_MS` changes the two seconds (0: at once).

use std::io::IsTerminal;
use std::sync::Mutex;
use std::sync::mpsc::{self, RecvTimeoutError};
use std::thread::JoinHandle;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// The spinner on the screen now, if any.
static BAR: Mutex<Option<ProgressBar>> = Mutex::new(None);

/// How long work runs before the spinner appears.
fn delay() -> Duration {
    let ms = std::env::var("RENDERSIM_PROGRESS_AFTER_MS")
        .ok()
        .and_then(|s| s.trim().parse::<u64>().ok())
        .unwrap_or(2000);
    Duration::from_millis(ms)
}

/// A spinner for one command's work, removed when this is dropped.
pub(crate) struct Activity {
    stop: Option<mpsc::Sender<()>>,
    thread: Option<JoinHandle<()>>,
}

impl Activity {
    /// Starts timing `what` (e.g. `isolate models/city.toml`); the spinner
    /// shows after the delay, on a terminal only.
    pub(crate) fn start(what: String) -> Activity {
        if !std::io::stderr().is_terminal() {
            return Activity {
                stop: None,
                thread: None,
            };
        }
        let (tx, rx) = mpsc::channel::<()>();
        let delay = delay();
        let thread = std::thread::spawn(move || {
            match rx.recv_timeout(delay) {
                Err(RecvTimeoutError::Timeout) => {}
                _ => return,
            }
            let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
            if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} [{elapsed}]") {
                bar.set_style(style);
            }
            bar.set_message(what);
            bar.enable_steady_tick(Duration::from_millis(120));
            *BAR.lock().unwrap_or_else(|e| e.into_inner()) = Some(bar);
            // Until the work ends (a message or the sender dropped).
            let _ = rx.recv();
            if let Some(bar) = BAR.lock().unwrap_or_else(|e| e.into_inner()).take() {
                bar.finish_and_clear();
            }
        });
        Activity {
            stop: Some(tx),
            thread: Some(thread),
        }
    }
}

impl Drop for Activity {
    fn drop(&mut self) {
        drop(self.stop.take());
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// Writes `line` and a newline to standard output; where it cannot be
/// written (a full disk, a closed or broken pipe), says so on standard
/// error and exits with status 2 instead of panicking (everything the
/// command writes to files is written before it prints).
pub(crate) fn print_line(line: &str) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    if let Err(e) = writeln!(out, "{line}").and_then(|()| out.flush()) {
        drop(out);
        eprintln!("error: cannot write to standard output: {e}");
        std::process::exit(2);
    }
}

/// Runs `f` (a print) with the spinner, if one is drawn, off the screen.
pub(crate) fn suspend<R>(f: impl FnOnce() -> R) -> R {
    let bar = BAR.lock().unwrap_or_else(|e| e.into_inner());
    match bar.as_ref() {
        Some(b) => b.suspend(f),
        None => f(),
    }
}

/// `println!` that keeps the spinner's line intact.
macro_rules! say {
    ($($arg:tt)*) => {
        {
            let line = format!($($arg)*);
            $crate::cli::progress::suspend(|| $crate::cli::progress::print_line(&line))
        }
    };
}
pub(crate) use say;

/// `eprintln!` that keeps the spinner's line intact.
macro_rules! esay {
    ($($arg:tt)*) => {
        {
            let line = format!($($arg)*);
            $crate::cli::progress::suspend(|| eprintln!("{line}"))
        }
    };
}
pub(crate) use esay;
