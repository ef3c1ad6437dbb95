//! Errors from loading and running experiments.

use std::path::PathBuf;

use crate::plot::PlotError;

/// Why an experiment could not be loaded or run.
#[derive(Debug, thiserror::Error)]
pub enum ExperimentError {
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// A TOML file is not valid TOML (an unknown key or a wrong type is
    /// [`ExperimentError::Invalid`], with its line). Written as a model's
    /// syntax error is: `FILE: malformed TOML: MESSAGE`.
    #[error("{}: malformed TOML: {message}", file.display())]
    Parse {
        /// The file concerned.
        file: PathBuf,
        /// The parser's message (it names the key and line).
        message: String,
    },
    /// An experiment file parsed but is not valid.
    /// Written as a model's errors are: `FILE:LINE: key `KEY`: MESSAGE`.
    #[error("{}{}: key `{key}`: {message}", file.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    Invalid {
        /// The experiment file.
        file: PathBuf,
        /// 1-based line of the entry in the file, when found.
        line: Option<usize>,
        /// Which entry is wrong, e.g. `sweep[1].range`.
        key: String,
        /// What is wrong with it.
        message: String,
    },
    /// An inverse what-if (`[[search]]`) failed.
    #[error("search {name:?} failed: {source}")]
    Search {
        /// The search's name.
        name: String,
        /// Why.
        source: Box<super::inverse::SearchError>,
    },
    /// A model file could not be read as a model (its hardware file
    /// included).
    #[error(transparent)]
    Model(#[from] crate::config::ConfigError),
    /// A dotted-key patch could not be applied to a model.
    #[error(transparent)]
    Patch(#[from] crate::config::PatchError),
    /// The simulator failed for one run, or its output lacked something.
    #[error("run failed at point {point} ({label}), seed {seed}: {message}")]
    Run {
        /// Index of the point (0-based, in expansion order).
        point: usize,
        /// The point's sweep assignments, e.g. `workload.gpu=17ms, display.buffers=2`.
        label: String,
        /// The seed of the failed run.
        seed: u64,
        /// The runner's message.
        message: String,
    },
    /// The caller's progress report asked to stop ([`super::Progress`]):
    /// the runs not yet started were left out.
    #[error("stopped after {done} of {total} runs, as asked")]
    Stopped {
        /// Runs that had ended when it stopped.
        done: u64,
        /// Runs the experiment has.
        total: u64,
    },
    /// A plot could not be written.
    #[error("plot `{file}`: {source}")]
    Plot {
        /// The plot's `file` name from the experiment.
        file: String,
        /// The plotting error.
        source: PlotError,
    },
    /// A shard file cannot be used (`--shard`, `--merge`).
    #[error("{}: {message}", file.display())]
    Shard {
        /// The shard file.
        file: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// A `--shard K/N` that does not fit the experiment.
    #[error(transparent)]
    ShardId(#[from] super::shard::ShardIdError),
    /// The shard files of an experiment do not make a whole (`--merge`).
    #[error("{}: {message}", dir.display())]
    Shards {
        /// The folder of shard files.
        dir: PathBuf,
        /// What is missing or twice.
        message: String,
    },
    /// An output file could not be written.
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
}
