//! The interface through which experiments reach the simulator.

/// Why a [`Runner`] could not run a model.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The simulator refused the model or failed while running it.
    #[error(transparent)]
    Sim(#[from] crate::systems::SimError),
    /// The seed could not be written into the model.
    #[error(transparent)]
    Patch(#[from] crate::config::PatchError),
    /// Another runner's failure, in its words (a fake simulator in tests).
    #[error("{0}")]
    Other(String),
}

/// Runs the simulator for one fully patched model and one seed.
///
/// Implemented by the simulator crate layer; experiments call it from several
/// threads at once, hence `Sync`.
pub trait Runner: Sync {
    /// Run one model (a fully patched TOML table) with one seed. `want_frames`
    /// asks for per-frame columns too.
    fn run(&self, model: &toml::Table, seed: u64, want_frames: bool) -> Result<RunOutput, RunError>;

    /// [`Runner::run`], with `origins` (dotted key, where its value comes
    /// from) for keys set beyond the experiment's `[set]` and sweeps (an
    /// inverse search's), so that an error in such a value names them.
    /// Runners that do not report model errors ignore them.
    fn run_noted(
        &self,
        model: &toml::Table,
        seed: u64,
        want_frames: bool,
        origins: &[(String, String)],
    ) -> Result<RunOutput, RunError> {
        let _ = origins;
        self.run(model, seed, want_frames)
    }

    /// [`Runner::run`] for a point whose model a `[[sweep]] key = "model"`
    /// took from `source` (another file than the experiment's base model),
    /// so that relative paths inside it and errors in it refer to that
    /// file. Runners that do not read files ignore it.
    fn run_from(
        &self,
        source: &super::ModelSource,
        model: &toml::Table,
        seed: u64,
        want_frames: bool,
    ) -> Result<RunOutput, RunError> {
        let _ = source;
        self.run(model, seed, want_frames)
    }
}

/// What one run produced.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutput {
    /// The run summary, e.g. `{"seed": 1, "wall_seconds": 0.01, "metrics": {...}}`;
    /// metrics are addressed by dotted paths into it.
    pub summary: serde_json::Value,
    /// Per-frame data, present when requested.
    pub frames: Option<FrameTable>,
}

/// Per-frame data: named columns, one row per frame.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FrameTable {
    /// Column names, e.g. `FrameTime`.
    pub columns: Vec<String>,
    /// Rows, each with one value per column.
    pub rows: Vec<Vec<f64>>,
}

impl FrameTable {
    /// The values of column `name`, or `None` if there is no such column.
    /// Rows too short to hold the column are skipped. `A+B` (any number of
    /// names joined by `+`) is the columns' sum row by row, `None` unless
    /// every one exists: `MsGPULatency+MsGPUTime` is a frame's time from
    /// its CPU start to its GPU end.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let idx: Vec<usize> = name
            .split('+')
            .map(|part| self.columns.iter().position(|c| c == part.trim()))
            .collect::<Option<_>>()?;
        Some(
            self.rows
                .iter()
                .filter_map(|r| idx.iter().map(|&i| r.get(i).copied()).sum::<Option<f64>>())
                .collect(),
        )
    }
}
