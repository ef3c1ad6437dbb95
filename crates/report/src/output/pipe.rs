//! Writing into a FIFO or a socket whose reader may go away.
//!
//! The binary restores the default action of SIGPIPE so that
//! `rendersim ... | head` ends quietly, like `cat`. A trace written into a
//! named FIFO (or a socket) whose reader exits would then kill the process
//! with no word. [`in_place_writer`] wraps such a file in [`PipeWriter`]:
//! each write holds SIGPIPE back for the writing thread only while it runs
//! (`pthread_sigmask`), takes the signal that a closed pipe raised, and
//! returns the write's error instead, which says what happened
//! ([`READER_CLOSED`]); the caller reports it as an error line (exit 2).
//! Standard output, however reached, keeps the default action.
//!
//! ```no_run
//! # #[cfg(unix)] {
//! use std::io::Write;
//! let f = std::fs::OpenOptions::new().write(true).open("trace.fifo").unwrap();
//! let mut w = rendersim_report::output::pipe::in_place_writer(f);
//! if let Err(e) = w.write_all(b"{}").and_then(|()| w.flush()) {
//!     eprintln!("error: writing trace.fifo: {e}");
//! }
//! # }
//! ```

use std::io::{self, Write};

/// The error text of a write into a pipe whose reader has closed it.
pub const READER_CLOSED: &str = "the reader closed the pipe before everything was written (broken pipe)";

/// A buffered writer for a file written in place: a FIFO or socket other
/// than standard output goes through [`PipeWriter`], anything else (a
/// device, standard output's pipe) is written as it is.
pub fn in_place_writer(f: std::fs::File) -> Box<dyn Write + Send> {
    if is_pipe_but_not_stdout(&f) {
        Box::new(io::BufWriter::new(PipeWriter { inner: f }))
    } else {
        Box::new(io::BufWriter::new(f))
    }
}

#[cfg(unix)]
fn is_pipe_but_not_stdout(f: &std::fs::File) -> bool {
    use std::os::unix::fs::{FileTypeExt, MetadataExt};
    let Ok(m) = f.metadata() else { return false };
    let t = m.file_type();
    if !(t.is_fifo() || t.is_socket()) {
        return false;
    }
    // SAFETY: fstat on descriptor 1 into a zeroed stat buffer; a closed
    // descriptor only makes it fail.
    let stdout = unsafe {
        let mut st: libc::stat = std::mem::zeroed();
        (libc::fstat(1, &mut st) == 0).then_some((st.st_dev as u64, st.st_ino as u64))
    };
    stdout != Some((m.dev(), m.ino()))
}

#[cfg(not(unix))]
fn is_pipe_but_not_stdout(_f: &std::fs::File) -> bool {
    false
}

/// A writer whose writes into a closed pipe fail with [`READER_CLOSED`]
/// instead of ending the process by SIGPIPE.
#[derive(Debug)]
pub struct PipeWriter<W> {
    inner: W,
}

impl<W: Write> PipeWriter<W> {
    /// Wraps `inner`.
    pub fn new(inner: W) -> Self {
        PipeWriter { inner }
    }
}

impl<W: Write> Write for PipeWriter<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        without_sigpipe(|| self.inner.write(buf)).map_err(explain)
    }

    fn flush(&mut self) -> io::Result<()> {
        without_sigpipe(|| self.inner.flush()).map_err(explain)
    }
}

fn explain(e: io::Error) -> io::Error {
    if e.kind() == io::ErrorKind::BrokenPipe {
        io::Error::new(io::ErrorKind::BrokenPipe, READER_CLOSED)
    } else {
        e
    }
}

/// Runs `f` (one write) with SIGPIPE blocked for this thread; a SIGPIPE it
/// raised (a write into a closed pipe, which also returns `EPIPE`) is taken
/// while still blocked, so restoring the mask delivers nothing.
#[cfg(unix)]
fn without_sigpipe<T>(f: impl FnOnce() -> io::Result<T>) -> io::Result<T> {
    // SAFETY: signal-set and mask calls on local, initialised sets; the
    // mask is this thread's and is restored before returning.
    unsafe {
        let mut set: libc::sigset_t = std::mem::zeroed();
        let mut old: libc::sigset_t = std::mem::zeroed();
        libc::sigemptyset(&mut set);
        libc::sigaddset(&mut set, libc::SIGPIPE);
        if libc::pthread_sigmask(libc::SIG_BLOCK, &set, &mut old) != 0 {
            return f();
        }
        let r = f();
        if matches!(&r, Err(e) if e.kind() == io::ErrorKind::BrokenPipe) {
            let mut pending: libc::sigset_t = std::mem::zeroed();
            libc::sigemptyset(&mut pending);
            if libc::sigpending(&mut pending) == 0 && libc::sigismember(&pending, libc::SIGPIPE) == 1 {
                let mut sig = 0;
                libc::sigwait(&set, &mut sig);
            }
        }
        libc::pthread_sigmask(libc::SIG_SETMASK, &old, std::ptr::null_mut());
        r
    }
}

#[cfg(not(unix))]
fn without_sigpipe<T>(f: impl FnOnce() -> io::Result<T>) -> io::Result<T> {
    f()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_broken_pipe_error_says_the_reader_closed_it() {
        struct Closed;
        impl Write for Closed {
            fn write(&mut self, _: &[u8]) -> io::Result<usize> {
                Err(io::Error::from(io::ErrorKind::BrokenPipe))
            }
            fn flush(&mut self) -> io::Result<()> {
                Ok(())
            }
        }
        let e = PipeWriter::new(Closed).write_all(b"x").unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::BrokenPipe);
        assert_eq!(e.to_string(), READER_CLOSED);
        let mut ok = PipeWriter::new(Vec::new());
        ok.write_all(b"abc").unwrap();
        assert_eq!(ok.inner, b"abc");
    }
}
