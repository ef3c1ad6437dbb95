//! A folder of results written as one unit.
//!
//! `rendersim run --out DIR` and `rendersim experiment --out DIR` write
//! several files that belong together (a summary, a per-frame table, the
//! resolved model; or runs, points, plots and a report). A [`ResultSet`] is
//! written into a staging folder beside `DIR` and swapped in only when
//! complete, so at any moment, even after a kill, `DIR` holds either the old
//! set or the new one, never a mix:
//!
//! 1. [`ResultSet::begin`] checks `DIR` before any work is done (it must be a
//!    folder rendersim wrote earlier, an empty folder, or absent) and creates
//!    the staging folder `.DIR.partial-PID` beside it, which also proves the
//!    place is writable before a long simulation starts;
//! 2. the caller writes into [`ResultSet::dir`];
//! 3. [`ResultSet::commit`] exchanges the two folders in one `renameat2`
//!    call (Linux; elsewhere two renames) and removes the old set.
//!
//! Dropping an uncommitted set removes its staging folder; an interrupt
//! (SIGINT, SIGTERM, SIGHUP) removes it too (see [`super::cleanup`]); a
//! staging folder left by a killed process is removed by the next `begin`
//! on the same `DIR`.
//!
//! A test can hold a process between staging and swap with the environment
//! variable `RENDERSIM_HOLD_BEFORE_SWAP` (see [`ResultSet::commit_to`]).
//!
//! Each set holds a marker file, [`MARKER`], which is how rendersim knows a
//! folder is its own to replace. It never replaces a folder holding files
//! it did not write. A set of a kind ([`ResultSet::begin_kind`]: `run`,
//! `experiment`, `replay`) names it in its marker, and a set of another
//! kind does not replace it unless forced (an experiment's folder is not
//! lost to a `run --out` into it).
//!
//! ```
//! use std::io::Write;
//! use rendersim_report::output::result_set::ResultSet;
//!
//! let parent = tempfile::tempdir().unwrap();
//! let out = parent.path().join("results");
//! let set = ResultSet::begin(&out, |_| false).unwrap();
//! std::fs::write(set.dir().join("a.txt"), "first").unwrap();
//! set.commit().unwrap();
//! assert_eq!(std::fs::read_to_string(out.join("a.txt")).unwrap(), "first");
//! ```

use std::path::{Path, PathBuf};

use super::cleanup::{Registered, create_registered, remove_stale_temps, while_locked};
use super::error::OutputError;
use super::files::{real_path, resolve_links};

/// The marker file in every result set.
pub const MARKER: &str = ".rendersim-set";

/// A result set being written (see the module documentation).
#[derive(Debug)]
pub struct ResultSet {
    target: PathBuf,
    staging: PathBuf,
    registered: Option<Registered>,
    kind: Option<&'static str>,
}

/// The marker's text for a set of `kind`.
fn marker_text(kind: Option<&str>) -> String {
    let mut t = format!(
        "This folder is a result set written by rendersim {}; rendersim replaces it as a whole when it writes here again.\n",
        env!("CARGO_PKG_VERSION")
    );
    if let Some(k) = kind {
        t.push_str(&format!("kind: {k}\n"));
    }
    t
}

/// The result sets this process claimed ([`claim_folder`]): it writes into
/// them piece by piece, so [`check_outside_sets`] lets it.
static CLAIMED: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Refuses an output at `path` that lies inside a result set (a folder
/// holding [`MARKER`], at any depth above `path`) other than one this
/// process claimed: a file written there would be lost to, or mixed into,
/// the set of the command that wrote it (`run --trace DIR/summary.json`
/// over a run's folder, `timeline --out` into an experiment's). A
/// command's own set is written through [`ResultSet::place`] instead.
///
/// ```
/// use rendersim_report::output::result_set::{ResultSet, check_outside_sets};
///
/// let parent = tempfile::tempdir().unwrap();
/// let out = parent.path().join("results");
/// ResultSet::begin(&out, |_| false).unwrap().commit().unwrap();
/// assert!(check_outside_sets(&out.join("trace.json")).is_err());
/// assert!(check_outside_sets(&parent.path().join("trace.json")).is_ok());
/// ```
pub fn check_outside_sets(path: &Path) -> Result<(), OutputError> {
    if path.as_os_str() == "-" || path.starts_with("/dev") || path.starts_with("/proc") {
        return Ok(());
    }
    let real = real_path(path);
    let claimed = CLAIMED.lock().map(|c| c.clone()).unwrap_or_default();
    for folder in real.ancestors().skip(1) {
        if folder.join(MARKER).is_file() && !claimed.iter().any(|c| c == folder) {
            return Err(OutputError::InsideSet {
                path: path.to_path_buf(),
                set: folder.to_path_buf(),
                kind: marker_kind(folder).unwrap_or_else(|| "rendersim".into()),
            });
        }
    }
    Ok(())
}

/// The kind a set's marker names (`None`: none, as markers before kinds).
fn marker_kind(target: &Path) -> Option<String> {
    let text = std::fs::read_to_string(target.join(MARKER)).ok()?;
    text.lines()
        .find_map(|l| l.strip_prefix("kind: "))
        .map(|k| k.trim().to_string())
}

/// A marked set of another kind than `kind` is refused unless `force`.
fn check_kind(target: &Path, kind: Option<&str>, force: bool) -> Result<(), OutputError> {
    if force {
        return Ok(());
    }
    if let (Some(wanted), Some(found)) = (kind, marker_kind(target))
        && found != wanted
    {
        return Err(OutputError::OtherKind {
            path: target.to_path_buf(),
            found,
            wanted: wanted.to_string(),
        });
    }
    Ok(())
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| "out".into())
}

fn parent_of(p: &Path) -> PathBuf {
    p.parent()
        .filter(|d| !d.as_os_str().is_empty())
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

/// Checks that `target` may be replaced by a result set: absent, empty,
/// marked as rendersim's, or holding only regular files for which `legacy`
/// says rendersim wrote them (sets written before the marker existed).
fn check_replaceable(target: &Path, legacy: &dyn Fn(&str) -> bool) -> Result<(), OutputError> {
    let meta = match std::fs::metadata(target) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(OutputError::io("looking at", target)(e)),
    };
    if !meta.is_dir() {
        return Err(OutputError::NotAFolder {
            path: target.to_path_buf(),
        });
    }
    if target.join(MARKER).is_file() {
        return check_writable(target);
    }
    let mut foreign = Vec::new();
    for entry in std::fs::read_dir(target).map_err(OutputError::io("reading folder", target))? {
        let entry = entry.map_err(OutputError::io("reading folder", target))?;
        let name = entry.file_name().to_string_lossy().to_string();
        let is_file = entry.file_type().map(|t| t.is_file()).unwrap_or(false);
        let temp = name.starts_with('.') && name.contains(".tmp-");
        if !(is_file && (legacy(&name) || temp)) {
            foreign.push(name);
        }
    }
    if foreign.is_empty() {
        return check_writable(target);
    }
    foreign.sort();
    let more = foreign.len().saturating_sub(3);
    let mut examples = foreign
        .iter()
        .take(3)
        .map(|n| format!("{n:?}"))
        .collect::<Vec<_>>()
        .join(", ");
    if more > 0 {
        examples.push_str(&format!(" and {more} more"));
    }
    Err(OutputError::ForeignFolder {
        path: target.to_path_buf(),
        examples,
    })
}

/// Refuses a set folder that could not be removed once replaced: the folder
/// or a folder inside it without write permission (a removal would fail and
/// leave the old set beside the new one). Checked before any work is done.
fn check_writable(target: &Path) -> Result<(), OutputError> {
    let mut folders = vec![(target.to_path_buf(), 0)];
    while let Some((dir, depth)) = folders.pop() {
        let meta = std::fs::symlink_metadata(&dir).map_err(OutputError::io("looking at", &dir))?;
        if meta.permissions().readonly() {
            return Err(OutputError::ReadOnlyFolder { path: dir });
        }
        // A set is a handful of folders deep (plots, shards, logs).
        if depth >= 8 {
            continue;
        }
        let Ok(entries) = std::fs::read_dir(&dir) else {
            return Err(OutputError::ReadOnlyFolder { path: dir });
        };
        for e in entries.flatten() {
            if e.file_type().is_ok_and(|t| t.is_dir()) {
                folders.push((e.path(), depth + 1));
            }
        }
    }
    Ok(())
}

/// `p` as an absolute path that ends in a name (so it has a parent to stage
/// beside): `.` and `..` are resolved.
fn absolute_folder(p: &Path) -> Result<PathBuf, OutputError> {
    let abs = std::path::absolute(p).map_err(OutputError::io("looking at", p))?;
    if abs.file_name().is_some() && !abs.ends_with("..") {
        return Ok(abs);
    }
    abs.canonicalize().map_err(OutputError::io("looking at", p))
}

/// Exchanges two existing folders in one step where the system can.
fn exchange(a: &Path, b: &Path) -> std::io::Result<bool> {
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::ffi::OsStrExt;
        let ca = std::ffi::CString::new(a.as_os_str().as_bytes()).map_err(std::io::Error::other)?;
        let cb = std::ffi::CString::new(b.as_os_str().as_bytes()).map_err(std::io::Error::other)?;
        // SAFETY: two valid NUL-terminated paths, relative to the working folder.
        let r = unsafe {
            libc::renameat2(
                libc::AT_FDCWD,
                ca.as_ptr(),
                libc::AT_FDCWD,
                cb.as_ptr(),
                libc::RENAME_EXCHANGE,
            )
        };
        if r == 0 {
            return Ok(true);
        }
        let e = std::io::Error::last_os_error();
        match e.raw_os_error() {
            // Not supported by this kernel or file system: fall back.
            Some(libc::EINVAL) | Some(libc::ENOSYS) | Some(libc::ENOTSUP) => Ok(false),
            _ => Err(e),
        }
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = (a, b);
        Ok(false)
    }
}

/// Testing aid: with `RENDERSIM_HOLD_BEFORE_SWAP=FILE` in the environment,
/// a commit creates FILE once its set is fully staged and waits (at most ten
/// minutes) until FILE is removed, so a test can interrupt a process at the
/// last moment before the swap.
fn hold_for_tests() {
    let Some(flag) = std::env::var_os("RENDERSIM_HOLD_BEFORE_SWAP") else {
        return;
    };
    let flag = PathBuf::from(flag);
    if std::fs::write(&flag, std::process::id().to_string()).is_err() {
        return;
    }
    for _ in 0..60_000 {
        if !flag.exists() {
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
}

impl ResultSet {
    /// Starts a result set for `target` (see the module documentation).
    /// `legacy` names the files an older rendersim wrote into such a folder
    /// before sets were marked, so those folders can still be replaced.
    pub fn begin(target: &Path, legacy: impl Fn(&str) -> bool) -> Result<Self, OutputError> {
        ResultSet::begin_kind(target, None, legacy, false)
    }

    /// [`ResultSet::begin`] for a set of `kind` (the command that writes
    /// it), which refuses a folder holding a set of another kind unless
    /// `force`.
    pub fn begin_kind(
        target: &Path,
        kind: Option<&'static str>,
        legacy: impl Fn(&str) -> bool,
        force: bool,
    ) -> Result<Self, OutputError> {
        let target = absolute_folder(&resolve_links(target)?)?;
        check_outside_sets(&target)?;
        check_replaceable(&target, &legacy)?;
        if target.join(MARKER).is_file() {
            check_kind(&target, kind, force)?;
        }
        let parent = parent_of(&target);
        std::fs::create_dir_all(&parent).map_err(OutputError::io("creating folder", &parent))?;
        let name = file_name(&target);
        remove_stale_temps(&parent, &name, &["partial", "old"]);
        let staging = parent.join(format!(".{name}.partial-{}", std::process::id()));
        if staging.exists() {
            let _ = std::fs::remove_dir_all(&staging);
        }
        let (registered, ()) = create_registered(&staging, |p| std::fs::create_dir(p))
            .map_err(OutputError::io("creating folder", &staging))?;
        Ok(ResultSet {
            target,
            staging,
            registered: Some(registered),
            kind,
        })
    }

    /// The folder to write the set's files into.
    pub fn dir(&self) -> &Path {
        &self.staging
    }

    /// The folder the set will replace.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Where a single-file output given as `path` (a trace) is written so
    /// that it goes through the same commit as the set: `None` when `path`
    /// lies outside the set's folder (write it where it is), else its place
    /// in the staging folder. A path that names one of the set's own files
    /// (`reserved`, or the marker) or the folder itself is refused: the set
    /// would overwrite it, or it the set.
    pub fn place(&self, path: &Path, reserved: &[&str]) -> Result<Option<PathBuf>, OutputError> {
        if path.as_os_str() == "-" {
            return Ok(None);
        }
        let Ok(rel) = real_path(path)
            .strip_prefix(real_path(&self.target))
            .map(Path::to_path_buf)
        else {
            return Ok(None);
        };
        let first = rel
            .components()
            .next()
            .map(|c| c.as_os_str().to_string_lossy().to_string());
        match first {
            None => Err(OutputError::IsAFolder {
                path: path.to_path_buf(),
            }),
            Some(name) if name == MARKER || reserved.contains(&name.as_str()) => Err(OutputError::PartOfSet {
                path: path.to_path_buf(),
                set: self.target.clone(),
                name,
            }),
            Some(_) => Ok(Some(self.staging.join(rel))),
        }
    }

    /// Puts the finished set in place of the target folder; returns it.
    pub fn commit(self) -> Result<PathBuf, OutputError> {
        let target = self.target.clone();
        self.commit_to(&target)
    }

    /// Puts the finished set in place of `other` instead (for example the
    /// partial results of a failed experiment, kept beside the old set);
    /// `other` must be replaceable as a result set too. (With
    /// `RENDERSIM_HOLD_BEFORE_SWAP=FILE` set, it first creates FILE and
    /// waits until FILE is removed: a testing aid.)
    pub fn commit_to(mut self, other: &Path) -> Result<PathBuf, OutputError> {
        let target = absolute_folder(&resolve_links(other)?)?;
        if target != self.target {
            check_replaceable(&target, &|_| false)?;
        }
        let marker = self.staging.join(MARKER);
        std::fs::write(&marker, marker_text(self.kind)).map_err(OutputError::io("writing", &marker))?;
        hold_for_tests();
        let staging = self.staging.clone();
        // Where the old set goes when the two folders cannot be exchanged in
        // one step; registered so that an interrupt removes it too.
        let name = file_name(&target);
        let old = parent_of(&target).join(format!(".{name}.old-{}", std::process::id()));
        let _old_registered = Registered::new(&old);
        let swapped = while_locked(|| -> Result<Option<PathBuf>, OutputError> {
            if !target.exists() {
                match std::fs::rename(&staging, &target) {
                    Ok(()) => return Ok(None),
                    // Another run put its set there since: exchange with it
                    // (each set stays whole; the last to commit is kept).
                    Err(e)
                        if matches!(
                            e.kind(),
                            std::io::ErrorKind::DirectoryNotEmpty | std::io::ErrorKind::AlreadyExists
                        ) && target.join(MARKER).is_file() => {}
                    Err(e) => return Err(OutputError::io("moving the results to", &target)(e)),
                }
            }
            if exchange(&staging, &target).map_err(OutputError::io("moving the results to", &target))? {
                // The staging path now holds the old set.
                return Ok(Some(staging.clone()));
            }
            std::fs::rename(&target, &old).map_err(OutputError::io("moving the old results from", &target))?;
            std::fs::rename(&staging, &target).map_err(OutputError::io("moving the results to", &target))?;
            Ok(Some(old.clone()))
        })?;
        if let Some(old) = swapped {
            let _ = std::fs::remove_dir_all(&old);
        }
        self.registered.take();
        Ok(target)
    }
}

/// Makes `target` a folder of rendersim's without replacing it: checks it
/// as [`ResultSet::begin`] does (absent, empty, marked, or holding only files
/// `legacy` names), creates it and writes the marker. For outputs written
/// into the folder piece by piece by several processes (the shards of an
/// experiment, `DIR/shards/`), which a later result set in the same folder
/// keeps with [`ResultSet::keep`]. Returns the folder (links resolved).
pub fn claim_folder(
    target: &Path,
    kind: Option<&'static str>,
    legacy: impl Fn(&str) -> bool,
    force: bool,
) -> Result<PathBuf, OutputError> {
    let target = absolute_folder(&resolve_links(target)?)?;
    check_outside_sets(&target)?;
    check_replaceable(&target, &legacy)?;
    std::fs::create_dir_all(&target).map_err(OutputError::io("creating folder", &target))?;
    let marker = target.join(MARKER);
    if marker.is_file() {
        check_kind(&target, kind, force)?;
    }
    if let Ok(mut c) = CLAIMED.lock() {
        c.push(super::files::real_path(&target));
    }
    if !marker.is_file() {
        super::files::write_output(&marker, |w| w.write_all(marker_text(kind).as_bytes()))?;
    }
    Ok(target)
}

/// Puts a copy of `from` (a file or a folder tree) at `to`, by hard links
/// where the file system allows (no data copied; a file still open for
/// writing elsewhere, such as a job's log, keeps growing under both names),
/// else by copying.
fn link_tree(from: &Path, to: &Path) -> std::io::Result<()> {
    let meta = std::fs::symlink_metadata(from)?;
    if meta.is_dir() {
        std::fs::create_dir_all(to)?;
        for e in std::fs::read_dir(from)? {
            let e = e?;
            link_tree(&e.path(), &to.join(e.file_name()))?;
        }
        Ok(())
    } else if meta.file_type().is_symlink() {
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(std::fs::read_link(from)?, to)
        }
        #[cfg(not(unix))]
        {
            std::fs::copy(from, to).map(|_| ())
        }
    } else {
        std::fs::hard_link(from, to).or_else(|_| std::fs::copy(from, to).map(|_| ()))
    }
}

impl ResultSet {
    /// Carries the entry `name` (a file or folder) of the current target
    /// into the staged set, so the swap keeps it (the shard files of an
    /// experiment, its Slurm scripts and logs). Nothing happens if the
    /// target has no such entry or the set already holds one.
    pub fn keep(&self, name: &str) -> Result<(), OutputError> {
        let from = self.target.join(name);
        let to = self.staging.join(name);
        if std::fs::symlink_metadata(&from).is_err() || std::fs::symlink_metadata(&to).is_ok() {
            return Ok(());
        }
        link_tree(&from, &to).map_err(OutputError::io("keeping", from))
    }
}

impl Drop for ResultSet {
    fn drop(&mut self) {
        if self.registered.is_some() {
            let _ = std::fs::remove_dir_all(&self.staging);
            self.registered.take();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn files(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_new_set_replaces_the_old_one_whole() {
        let d = tempfile::tempdir().unwrap();
        let out = d.path().join("out");
        let s = ResultSet::begin(&out, |_| false).unwrap();
        std::fs::write(s.dir().join("a.csv"), "1").unwrap();
        std::fs::write(s.dir().join("b.csv"), "1").unwrap();
        s.commit().unwrap();
        let s = ResultSet::begin(&out, |_| false).unwrap();
        std::fs::write(s.dir().join("a.csv"), "2").unwrap();
        s.commit().unwrap();
        assert_eq!(files(&out), vec![MARKER.to_string(), "a.csv".into()]);
        assert_eq!(std::fs::read_to_string(out.join("a.csv")).unwrap(), "2");
        assert_eq!(files(d.path()), vec!["out".to_string()], "no staging left");
    }

    #[test]
    fn an_abandoned_set_leaves_the_old_one_and_no_staging() {
        let d = tempfile::tempdir().unwrap();
        let out = d.path().join("out");
        let s = ResultSet::begin(&out, |_| false).unwrap();
        std::fs::write(s.dir().join("a.csv"), "1").unwrap();
        s.commit().unwrap();
        let s = ResultSet::begin(&out, |_| false).unwrap();
        std::fs::write(s.dir().join("a.csv"), "2").unwrap();
        drop(s);
        assert_eq!(std::fs::read_to_string(out.join("a.csv")).unwrap(), "1");
        assert_eq!(files(d.path()), vec!["out".to_string()]);
    }

    #[test]
    fn a_folder_with_other_files_is_refused_before_any_work() {
        let d = tempfile::tempdir().unwrap();
        std::fs::write(d.path().join("thesis.tex"), "mine").unwrap();
        let e = ResultSet::begin(d.path(), |_| false).unwrap_err();
        assert!(matches!(e, OutputError::ForeignFolder { .. }), "{e}");
        assert!(e.to_string().contains("thesis.tex"), "{e}");
        assert_eq!(std::fs::read_to_string(d.path().join("thesis.tex")).unwrap(), "mine");
        // A file where a folder is wanted.
        let e = ResultSet::begin(&d.path().join("thesis.tex"), |_| false).unwrap_err();
        assert!(matches!(e, OutputError::NotAFolder { .. }), "{e}");
        // Files an older rendersim wrote are accepted.
        let old = d.path().join("old");
        std::fs::create_dir(&old).unwrap();
        std::fs::write(old.join("summary.json"), "{}").unwrap();
        let s = ResultSet::begin(&old, |n| n == "summary.json").unwrap();
        s.commit().unwrap();
        assert_eq!(files(&old), vec![MARKER.to_string()]);
    }

    #[test]
    fn staging_left_by_a_dead_process_is_removed() {
        let d = tempfile::tempdir().unwrap();
        // PIDs are below 2^22 on Linux; this one does not run.
        let stale = d.path().join(".out.partial-4194999");
        std::fs::create_dir(&stale).unwrap();
        std::fs::write(stale.join("a.csv"), "x").unwrap();
        let s = ResultSet::begin(&d.path().join("out"), |_| false).unwrap();
        assert!(!stale.exists());
        s.commit().unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_link_to_a_folder_stays_a_link() {
        let d = tempfile::tempdir().unwrap();
        let real = d.path().join("real");
        let link = d.path().join("link");
        std::os::unix::fs::symlink("real", &link).unwrap();
        let s = ResultSet::begin(&link, |_| false).unwrap();
        std::fs::write(s.dir().join("a.csv"), "1").unwrap();
        s.commit().unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read_to_string(real.join("a.csv")).unwrap(), "1");
    }

    #[test]
    fn a_claimed_folder_keeps_its_kept_entries_through_a_new_set() {
        let d = tempfile::tempdir().unwrap();
        let out = d.path().join("out");
        let claimed = claim_folder(&out, None, |_| false, false).unwrap();
        assert!(claimed.join(MARKER).is_file());
        std::fs::create_dir_all(out.join("shards")).unwrap();
        std::fs::write(out.join("shards/a.json"), "shard").unwrap();
        std::fs::write(out.join("job.sbatch"), "job").unwrap();
        // Claiming again is fine (the marker is there now).
        claim_folder(&out, None, |_| false, false).unwrap();
        let s = ResultSet::begin(&out, |_| false).unwrap();
        std::fs::write(s.dir().join("runs.csv"), "1").unwrap();
        s.keep("shards").unwrap();
        s.keep("job.sbatch").unwrap();
        s.keep("absent").unwrap();
        s.commit().unwrap();
        assert_eq!(
            files(&out),
            vec![
                MARKER.to_string(),
                "job.sbatch".into(),
                "runs.csv".into(),
                "shards".into()
            ]
        );
        assert_eq!(std::fs::read_to_string(out.join("shards/a.json")).unwrap(), "shard");
        // A folder holding other files is not claimed.
        std::fs::write(d.path().join("thesis.tex"), "mine").unwrap();
        assert!(matches!(
            claim_folder(d.path(), None, |_| false, false),
            Err(OutputError::ForeignFolder { .. })
        ));
    }

    #[test]
    fn a_set_of_another_kind_is_not_replaced_unless_forced() {
        let d = tempfile::tempdir().unwrap();
        let out = d.path().join("exp");
        let set = ResultSet::begin_kind(&out, Some("experiment"), |_| false, false).unwrap();
        std::fs::write(set.dir().join("report.md"), "x").unwrap();
        set.commit().unwrap();
        assert_eq!(marker_kind(&out).as_deref(), Some("experiment"));
        let e = ResultSet::begin_kind(&out, Some("run"), |_| false, false).unwrap_err();
        assert!(matches!(&e, OutputError::OtherKind { found, wanted, .. } if found == "experiment" && wanted == "run"));
        assert!(e.to_string().contains("--force"), "{e}");
        assert!(out.join("report.md").is_file(), "nothing lost");
        // The same kind, a set without a kind, or forced: replaced.
        ResultSet::begin_kind(&out, Some("experiment"), |_| false, false).unwrap();
        ResultSet::begin(&out, |_| false).unwrap();
        let set = ResultSet::begin_kind(&out, Some("run"), |_| false, true).unwrap();
        set.commit().unwrap();
        assert_eq!(marker_kind(&out).as_deref(), Some("run"));
        assert!(!out.join("report.md").exists());
        // A claimed folder (shards) of another kind likewise.
        assert!(claim_folder(&out, Some("experiment"), |_| false, false).is_err());
    }

    #[test]
    fn commit_to_another_folder_keeps_the_target() {
        let d = tempfile::tempdir().unwrap();
        let out = d.path().join("out");
        let s = ResultSet::begin(&out, |_| false).unwrap();
        std::fs::write(s.dir().join("a.csv"), "good").unwrap();
        s.commit().unwrap();
        let s = ResultSet::begin(&out, |_| false).unwrap();
        std::fs::write(s.dir().join("a.csv"), "partial").unwrap();
        let failed = d.path().join("out.failed");
        s.commit_to(&failed).unwrap();
        assert_eq!(std::fs::read_to_string(out.join("a.csv")).unwrap(), "good");
        assert_eq!(std::fs::read_to_string(failed.join("a.csv")).unwrap(), "partial");
    }

    #[test]
    fn a_single_file_inside_the_set_is_placed_in_the_staging_folder() {
        let d = tempfile::tempdir().unwrap();
        let out = d.path().join("out");
        let s = ResultSet::begin(&out, |_| false).unwrap();
        let reserved = ["summary.json"];
        assert_eq!(s.place(&d.path().join("trace.json"), &reserved).unwrap(), None);
        assert_eq!(s.place(Path::new("-"), &reserved).unwrap(), None);
        assert_eq!(
            s.place(&out.join("trace.json"), &reserved).unwrap(),
            Some(s.dir().join("trace.json"))
        );
        assert_eq!(
            s.place(&out.join("a/../b/t.json"), &reserved).unwrap(),
            Some(s.dir().join("b/t.json"))
        );
        for bad in ["summary.json", "./summary.json", "x/../summary.json", MARKER] {
            let e = s.place(&out.join(bad), &reserved).unwrap_err();
            assert!(matches!(e, OutputError::PartOfSet { .. }), "{bad}: {e}");
        }
        let e = s.place(&out.join("."), &reserved).unwrap_err();
        assert!(matches!(e, OutputError::IsAFolder { .. }), "{e}");
        // Another spelling of the same folder, through a link.
        #[cfg(unix)]
        {
            let link = d.path().join("link");
            std::os::unix::fs::symlink(d.path(), &link).unwrap();
            let e = s.place(&link.join("out/summary.json"), &reserved).unwrap_err();
            assert!(matches!(e, OutputError::PartOfSet { .. }), "{e}");
        }
    }

    #[test]
    fn temporary_paths_of_dead_processes_are_removed_and_live_ones_kept() {
        let d = tempfile::tempdir().unwrap();
        // PIDs are below 2^22 on Linux; this one does not run.
        let dead = d.path().join(".out.partial-4194999");
        let dead_file = d.path().join(".t.json.tmp-4194998");
        let live = d.path().join(format!(".out.partial-{}", std::process::id()));
        let other = d.path().join(".other.partial-4194999");
        for p in [&dead, &live, &other] {
            std::fs::create_dir(p).unwrap();
        }
        std::fs::write(&dead_file, "x").unwrap();
        crate::output::cleanup::remove_stale_temps(d.path(), "out", &["partial", "old"]);
        crate::output::cleanup::remove_stale_temps(d.path(), "t.json", &["tmp"]);
        assert!(!dead.exists() && !dead_file.exists());
        assert!(live.exists(), "this process's own");
        assert!(other.exists(), "another output's");
    }
}
