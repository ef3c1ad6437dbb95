//! Errors of writing outputs.

use std::path::PathBuf;

/// Why an output could not be written.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The operating system refused a read, write, rename or removal.
    #[error("{action} {path}: {source}")]
    Io {
        /// What was being done ("writing", "creating folder", ...).
        action: &'static str,
        /// The path it was done to.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// A file output names a folder.
    #[error("{path} is a folder; give a file name (or `-` for standard output)")]
    IsAFolder {
        /// The path given.
        path: PathBuf,
    },
    /// A result-set output names something that is not a folder.
    #[error("{path} exists and is not a folder; give a folder for --out")]
    NotAFolder {
        /// The path given.
        path: PathBuf,
    },
    /// A result-set output names a folder that holds files rendersim did not
    /// write. A result set replaces its folder as a whole, so rendersim will
    /// not take over a folder that holds anything else.
    #[error(
        "output folder {path} exists and holds files rendersim did not write ({examples}); \
         rendersim replaces its output folder as a whole, so give a new or empty folder \
         (or remove that one)"
    )]
    ForeignFolder {
        /// The folder given.
        path: PathBuf,
        /// A few of the entries that are not rendersim's.
        examples: String,
    },
    /// A result-set output names a folder holding another command's result
    /// set (an experiment's folder given to `run --out`): replacing it would
    /// lose that set.
    #[error(
        "output folder {path} holds the results of `rendersim {found}`, and this is `rendersim {wanted}`: \
         give another folder, or --force to replace those results"
    )]
    OtherKind {
        /// The folder given.
        path: PathBuf,
        /// The kind of set it holds.
        found: String,
        /// The kind of set being written.
        wanted: String,
    },
    /// A result-set output names a folder (or a folder inside it) that
    /// cannot be written: replacing it would leave the old set behind,
    /// unremovable.
    #[error(
        "output folder {path} is read-only; rendersim replaces its output folder as a whole and could not \
         remove the old one: make it writable (chmod u+w) or give another folder"
    )]
    ReadOnlyFolder {
        /// The read-only folder.
        path: PathBuf,
    },
    /// A single-file output (such as `--trace`) names a file of the result
    /// set written to `--out`, which the set would overwrite or lose.
    #[error(
        "{path} is the result set's own `{name}` in {set}; give the file another name (a trace may go inside \
         the --out folder under any name the set does not use)"
    )]
    PartOfSet {
        /// The path given.
        path: PathBuf,
        /// The set's folder.
        set: PathBuf,
        /// The set's file it names.
        name: String,
    },
    /// An output inside a result set another command wrote.
    #[error(
        "{path} is inside {set}, a result set of `rendersim {kind}`: a file written there would be lost when \
         that set is written again, or mixed into it; write it outside the folder (a command writes only into \
         its own set, its --out)"
    )]
    InsideSet {
        /// The path given.
        path: PathBuf,
        /// The set's folder.
        set: PathBuf,
        /// The kind of set (the command that wrote it).
        kind: String,
    },
    /// Two files of one command name the same place.
    #[error("{second} {path} names the same file as {first}; give each its own file")]
    SameFile {
        /// The option (or argument) given first.
        first: String,
        /// The option naming the same place again.
        second: String,
        /// The path as given to `second`.
        path: PathBuf,
    },
    /// A symbolic link chain that does not end.
    #[error("{path}: too many levels of symbolic links")]
    LinkLoop {
        /// The path given.
        path: PathBuf,
    },
}

impl OutputError {
    /// An I/O error while doing `action` to `path`.
    pub fn io(action: &'static str, path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> OutputError {
        let path = path.into();
        move |source| OutputError::Io { action, path, source }
    }
}
