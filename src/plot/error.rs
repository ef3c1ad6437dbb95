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
}
