//! Errors from writing plots.

use std::path::PathBuf;

/// Why a plot could not be written.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The output directory could not be created.
    #[error("cannot create the directory for plot {path}: {source}")]
    Io {
        /// The plot file being written.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// The embedded font could not be registered.
    #[error("the embedded DejaVu Sans font could not be loaded")]
    Font,
    /// The plotting backend failed while drawing or saving.
    #[error("drawing plot {path} failed: {message}")]
    Draw {
        /// The plot file being written.
        path: PathBuf,
        /// The backend's message.
        message: String,
    },
    /// A single-file picture was asked for with an extension that names
    /// no format it is written in.
    #[error("{path}: the picture's extension must be .png or .svg")]
    Extension {
        /// The file asked for.
        path: PathBuf,
    },
    /// The finished picture could not be written.
    #[error("writing {path}: {message}")]
    Write {
        /// The file being written.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}
