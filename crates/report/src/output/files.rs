//! Writing one output file without damaging what its path names.
//!
//! What is at the path decides how it is written:
//!
//! - `-`: standard output;
//! - a FIFO, a character or block device, a socket, or a symbolic link to
//!   one, and anything under `/dev` or `/proc` (`/dev/stdout` redirected to
//!   a file): opened and written in place (never replaced: replacing
//!   `/dev/stdout` or a FIFO by a regular file would break every later
//!   reader of it);
//! - a regular file, a symbolic link to one (the link is followed and kept),
//!   or nothing yet (missing folders above it are made): written next to the final file under a temporary name
//!   and renamed over it, so a reader never sees half a file and a failure or
//!   an interrupt leaves the old file as it was. The temporary name,
//!   `.NAME.tmp-PID`, names the writing process: one that was killed
//!   outright leaves it, and the next writer of the same file removes it.
//!
//! ```
//! use std::io::Write;
//! use rendersim_report::output::files::write_output;
//!
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("hello.txt");
//! write_output(&path, |w| w.write_all(b"hello\n")).unwrap();
//! assert_eq!(std::fs::read_to_string(&path).unwrap(), "hello\n");
//! ```

use std::io::Write;
use std::path::{Path, PathBuf};

use super::cleanup::{Registered, create_registered};
use super::error::OutputError;

/// How an output path is written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Destination {
    /// `-`: standard output.
    Stdout,
    /// Not a regular file (FIFO, device, socket): opened and written in place.
    InPlace(PathBuf),
    /// A regular file or nothing yet, with symbolic links resolved: written
    /// to a temporary sibling and renamed over this path.
    Replace(PathBuf),
}

/// Follows symbolic links from `path` to the path they finally name (which
/// may not exist yet: a dangling link names the file it will create).
pub fn resolve_links(path: &Path) -> Result<PathBuf, OutputError> {
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let target = std::fs::read_link(&p).map_err(OutputError::io("reading the link", &p))?;
                p = match p.parent() {
                    Some(dir) if target.is_relative() => dir.join(target),
                    _ => target,
                };
            }
            _ => return Ok(p),
        }
    }
    Err(OutputError::LinkLoop {
        path: path.to_path_buf(),
    })
}

/// `p` with every part that exists resolved to its real path (links, `.`
/// and `..`) and the rest normalized as written: so two spellings of one
/// place compare equal even before the place exists.
pub fn real_path(p: &Path) -> PathBuf {
    use std::path::Component;
    let Ok(abs) = std::path::absolute(p) else {
        return p.to_path_buf();
    };
    let mut cur = PathBuf::new();
    for c in abs.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if let Ok(real) = cur.canonicalize() {
                    cur = real;
                }
                cur.pop();
            }
            other => {
                cur.push(other.as_os_str());
                if std::fs::symlink_metadata(&cur).is_ok()
                    && let Ok(real) = cur.canonicalize()
                {
                    cur = real;
                }
            }
        }
    }
    cur
}

/// Refuses two of a command's files, `(option, path)`, that name one place
/// (an output that would overwrite an input or another output). Standard
/// output (`-`) and paths under `/dev` or `/proc` are not compared: they
/// are streams, written in place.
pub fn check_distinct(files: &[(&str, &Path)]) -> Result<(), OutputError> {
    let places: Vec<Option<PathBuf>> = files
        .iter()
        .map(|(_, p)| (p.as_os_str() != "-" && !is_system_path(p)).then(|| real_path(p)))
        .collect();
    for (j, b) in places.iter().enumerate() {
        for (i, a) in places[..j].iter().enumerate() {
            if a.is_some() && a == b {
                return Err(OutputError::SameFile {
                    first: files[i].0.to_string(),
                    second: files[j].0.to_string(),
                    path: files[j].1.to_path_buf(),
                });
            }
        }
    }
    Ok(())
}

/// Whether `p` lies under `/dev` or `/proc`, whose links (`/dev/stdout` ->
/// `/proc/self/fd/1` -> `pipe:[...]` or the file a shell opened) name open
/// files of a process rather than places to put a file.
fn is_system_path(p: &Path) -> bool {
    p.starts_with("/dev") || p.starts_with("/proc")
}

/// Decides how `path` is written (see the module documentation).
pub fn destination(path: &Path) -> Result<Destination, OutputError> {
    if path.as_os_str() == "-" {
        return Ok(Destination::Stdout);
    }
    // What the kernel finds at the path, following every link.
    let found = std::fs::metadata(path);
    if let Ok(m) = &found {
        if m.is_dir() {
            return Err(OutputError::IsAFolder {
                path: path.to_path_buf(),
            });
        }
        if !m.is_file() {
            return Ok(Destination::InPlace(path.to_path_buf()));
        }
    }
    let target = if is_system_path(path) {
        path.to_path_buf()
    } else {
        resolve_links(path)?
    };
    if is_system_path(&target) {
        // A file a process has open (a shell's `> file` seen through
        // /dev/stdout): written in place, never replaced.
        return Ok(Destination::InPlace(path.to_path_buf()));
    }
    super::result_set::check_outside_sets(&target)?;
    match found {
        Ok(_) => Ok(Destination::Replace(target)),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Destination::Replace(target)),
        Err(e) => Err(OutputError::Io {
            action: "looking at",
            path: path.to_path_buf(),
            source: e,
        }),
    }
}

/// An output file open for writing while a run goes on (a trace streamed
/// from the simulation). Write through the writer [`open_output`] returns,
/// drop it, then [`OutputFile::commit`] puts the file in place. Dropping an
/// uncommitted `OutputFile` removes its temporary file; the old file stays.
#[derive(Debug)]
pub struct OutputFile {
    /// For a replaced file: (temporary, final) paths.
    replace: Option<(PathBuf, PathBuf)>,
    registered: Option<Registered>,
}

/// Opens the output `path` (see the module documentation for what happens
/// to FIFOs, devices, links and `-`). Opening a FIFO waits for its reader.
pub fn open_output(path: &Path) -> Result<(OutputFile, Box<dyn Write + Send>), OutputError> {
    match destination(path)? {
        Destination::Stdout => Ok((
            OutputFile {
                replace: None,
                registered: None,
            },
            Box::new(std::io::BufWriter::new(std::io::stdout())),
        )),
        Destination::InPlace(p) => {
            // A regular file reached through /dev or /proc is truncated like
            // `tee` does; FIFOs and devices are not (they cannot be).
            let regular = std::fs::metadata(&p).is_ok_and(|m| m.is_file());
            let f = std::fs::OpenOptions::new()
                .write(true)
                .truncate(regular)
                .open(&p)
                .map_err(OutputError::io("opening", &p))?;
            Ok((
                OutputFile {
                    replace: None,
                    registered: None,
                },
                // A FIFO whose reader closes it: an error, not SIGPIPE.
                super::pipe::in_place_writer(f),
            ))
        }
        Destination::Replace(p) => {
            let dir = p
                .parent()
                .filter(|d| !d.as_os_str().is_empty())
                .unwrap_or(Path::new("."));
            let name = p
                .file_name()
                .map(|n| n.to_string_lossy().to_string())
                .unwrap_or_else(|| "out".into());
            std::fs::create_dir_all(dir).map_err(OutputError::io("creating folder", dir))?;
            // What a killed writer of this file left (`kill -9` leaves its
            // temporary file; an interrupt removes it itself).
            super::cleanup::remove_stale_temps(dir, &name, &["tmp"]);
            let tmp = dir.join(format!(".{name}.tmp-{}", std::process::id()));
            let (registered, f) =
                create_registered(&tmp, |p| std::fs::File::create(p)).map_err(OutputError::io("creating", &tmp))?;
            Ok((
                OutputFile {
                    replace: Some((tmp, p)),
                    registered: Some(registered),
                },
                Box::new(std::io::BufWriter::new(f)),
            ))
        }
    }
}

impl OutputFile {
    /// Puts the written file in place (a rename over the old one, keeping
    /// its permissions); nothing to do for files written in place. Flush and
    /// drop the writer first.
    pub fn commit(mut self) -> Result<(), OutputError> {
        if let Some((tmp, path)) = self.replace.take() {
            let r = (|| {
                if let Ok(old) = std::fs::metadata(&path) {
                    std::fs::set_permissions(&tmp, old.permissions())?;
                }
                super::cleanup::while_locked(|| std::fs::rename(&tmp, &path))
            })();
            if let Err(e) = r {
                let _ = std::fs::remove_file(&tmp);
                return Err(OutputError::io("writing", &path)(e));
            }
        }
        self.registered.take();
        Ok(())
    }
}

impl Drop for OutputFile {
    fn drop(&mut self) {
        if let Some((tmp, _)) = self.replace.take() {
            let _ = std::fs::remove_file(tmp);
        }
    }
}

/// Writes the output `path` through `fill` (see the module documentation
/// for what happens to FIFOs, devices, links and `-`).
pub fn write_output(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<(), OutputError> {
    let (file, mut w) = open_output(path)?;
    let shown = if path.as_os_str() == "-" {
        PathBuf::from("standard output")
    } else {
        path.to_path_buf()
    };
    fill(&mut w)
        .and_then(|()| w.flush())
        .map_err(OutputError::io("writing", shown))?;
    drop(w);
    file.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failure_keeps_old_file() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("a.txt");
        write_output(&p, |w| w.write_all(b"old")).unwrap();
        let r = write_output(&p, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("boom"))
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "old");
        assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 1);
    }

    #[cfg(unix)]
    #[test]
    fn a_link_to_a_regular_file_stays_a_link_and_its_target_is_replaced() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("real.json");
        std::fs::write(&target, "old").unwrap();
        let link = d.path().join("link.json");
        std::os::unix::fs::symlink("real.json", &link).unwrap();
        write_output(&link, |w| w.write_all(b"new")).unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
        // A dangling link creates the file it names.
        std::fs::remove_file(&target).unwrap();
        write_output(&link, |w| w.write_all(b"again")).unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "again");
        assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 2);
    }

    #[cfg(unix)]
    #[test]
    fn replacing_keeps_the_old_files_permissions() {
        use std::os::unix::fs::PermissionsExt;
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("a.csv");
        std::fs::write(&p, "old").unwrap();
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o640)).unwrap();
        write_output(&p, |w| w.write_all(b"new")).unwrap();
        assert_eq!(std::fs::metadata(&p).unwrap().permissions().mode() & 0o777, 0o640);
    }

    #[cfg(unix)]
    #[test]
    fn special_files_are_written_in_place() {
        let d = tempfile::tempdir().unwrap();
        assert_eq!(destination(Path::new("-")).unwrap(), Destination::Stdout);
        // A FIFO (made inside the temp folder) and a link to it.
        let fifo = d.path().join("pipe");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: a valid NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        assert_eq!(destination(&fifo).unwrap(), Destination::InPlace(fifo.clone()));
        let link = d.path().join("to-pipe");
        std::os::unix::fs::symlink(&fifo, &link).unwrap();
        assert_eq!(destination(&link).unwrap(), Destination::InPlace(link.clone()));
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::read(&fifo).unwrap())
        };
        write_output(&link, |w| w.write_all(b"through the pipe")).unwrap();
        assert_eq!(reader.join().unwrap(), b"through the pipe");
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        use std::os::unix::fs::FileTypeExt;
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
        assert!(matches!(destination(d.path()), Err(OutputError::IsAFolder { .. })));
    }

    #[test]
    fn two_files_of_one_command_naming_one_place_are_refused() {
        let d = tempfile::tempdir().unwrap();
        let a = d.path().join("a.csv");
        std::fs::write(&a, "x").unwrap();
        let same = d.path().join("sub/../a.csv");
        let e = check_distinct(&[("FILES", &a), ("--out", &d.path().join("p.toml")), ("--report", &same)]).unwrap_err();
        assert!(
            e.to_string().contains("--report") && e.to_string().contains("FILES"),
            "{e}"
        );
        check_distinct(&[("FILES", &a), ("--out", &d.path().join("p.toml"))]).unwrap();
        check_distinct(&[("--markdown", Path::new("-")), ("--csv", Path::new("-"))]).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_link_loop_is_an_error() {
        let d = tempfile::tempdir().unwrap();
        let a = d.path().join("a");
        let b = d.path().join("b");
        std::os::unix::fs::symlink(&b, &a).unwrap();
        std::os::unix::fs::symlink(&a, &b).unwrap();
        assert!(matches!(destination(&a), Err(OutputError::LinkLoop { .. })));
    }
}
