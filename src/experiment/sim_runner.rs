//! The [`Runner`] that runs the simulator itself.

use std::path::{Path, PathBuf};

use crate::config::{DEFAULT_MODEL, DEFAULT_MODEL_NAME, ModelSource};
use crate::systems::run_model;

use super::runner::{FrameTable, RunError, RunOutput, Runner};
use super::spec::{Experiment, ModelSource as ExperimentModel};

/// Runs models with the simulator; relative paths inside models resolve
/// against `base_dir`.
///
/// Per-frame data leave out the warm-up frames (`run.warmup_frames`, as the
/// summary reports them), so that histograms and derived frame statistics
/// describe the same frames as the summary's metrics.
#[derive(Debug, Clone)]
pub struct SimRunner {
    /// Name used in error messages.
    pub name: String,
    /// Directory of the model file.
    pub base_dir: PathBuf,
    /// The model file's text, so that errors name the line of a key (empty:
    /// no lines).
    pub text: String,
    /// Keys the experiment writes and where their values come from
    /// ([`crate::experiment::Experiment::value_origins`]): an error in such a
    /// value names the experiment file, not the model file.
    pub origins: Vec<(String, String)>,
}

impl SimRunner {
    /// The runner for `exp`'s base model: its file (relative paths inside
    /// it resolve against the file's folder), or the embedded default.
    pub fn for_experiment(exp: &Experiment) -> SimRunner {
        SimRunner::for_source(&exp.model, exp.value_origins())
    }

    /// The runner for one model source (the experiment's, or a file a
    /// `[[sweep]] key = "model"` picks), with the experiment's value origins.
    fn for_source(source: &ExperimentModel, origins: Vec<(String, String)>) -> SimRunner {
        let (name, base_dir, text) = match source {
            ExperimentModel::Default => (
                DEFAULT_MODEL_NAME.to_string(),
                PathBuf::from("."),
                DEFAULT_MODEL.to_string(),
            ),
            ExperimentModel::File(p) => (
                p.display().to_string(),
                p.parent().map(Path::to_path_buf).unwrap_or_default(),
                crate::limits::read_input_string(p, crate::limits::InputKind::Text).unwrap_or_default(),
            ),
        };
        SimRunner {
            name,
            base_dir,
            text,
            origins,
        }
    }
}

impl Runner for SimRunner {
    fn run(&self, model: &toml::Table, seed: u64, want_frames: bool) -> Result<RunOutput, RunError> {
        self.run_noted(model, seed, want_frames, &[])
    }

    fn run_from(
        &self,
        source: &ExperimentModel,
        model: &toml::Table,
        seed: u64,
        want_frames: bool,
    ) -> Result<RunOutput, RunError> {
        SimRunner::for_source(source, self.origins.clone()).run_noted(model, seed, want_frames, &[])
    }

    fn run_noted(
        &self,
        model: &toml::Table,
        seed: u64,
        want_frames: bool,
        origins: &[(String, String)],
    ) -> Result<RunOutput, RunError> {
        let mut table = model.clone();
        crate::config::set_dotted(&mut table, "run.seed", toml::Value::Integer(seed as i64))?;
        let src = ModelSource {
            name: self.name.clone(),
            text: self.text.clone(),
            base_dir: self.base_dir.clone(),
            overrides: self.origins.iter().chain(origins).cloned().collect(),
        };
        let run = run_model(&src, &table, None)?;
        // Made once: each call makes the JSON from the typed summary.
        let mut summary = run.summary();
        let warmup = summary
            .get("warmup_frames")
            .and_then(serde_json::Value::as_u64)
            .unwrap_or(0);
        let frames = want_frames.then(|| {
            let (columns, rows) = run.frame_table();
            without_warmup(FrameTable { columns, rows }, warmup)
        });
        crate::output::timing::fix_wall_times(&mut summary);
        Ok(RunOutput { summary, frames })
    }
}

/// `table` without the rows of frames before `warmup` (by the `Frame`
/// column; by row position when there is no such column).
pub(crate) fn without_warmup(mut table: FrameTable, warmup: u64) -> FrameTable {
    if warmup == 0 {
        return table;
    }
    match table.columns.iter().position(|c| c == "Frame") {
        Some(i) => table
            .rows
            .retain(|r| r.get(i).is_none_or(|&f| f.is_nan() || f >= warmup as f64)),
        None => {
            let n = (warmup as usize).min(table.rows.len());
            table.rows.drain(..n);
        }
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(frames: &[f64]) -> FrameTable {
        FrameTable {
            columns: vec!["Frame".into(), "FrameTime".into()],
            rows: frames.iter().map(|&f| vec![f, 10.0 + f]).collect(),
        }
    }

    #[test]
    fn warmup_rows_are_dropped_by_frame_index() {
        let t = without_warmup(table(&[0.0, 1.0, 2.0, 3.0]), 2);
        assert_eq!(t.column("Frame").unwrap(), vec![2.0, 3.0]);
        assert_eq!(t.column("FrameTime").unwrap(), vec![12.0, 13.0]);
        // A sum of columns, row by row; a missing part is no column.
        assert_eq!(t.column("Frame+FrameTime").unwrap(), vec![14.0, 16.0]);
        assert_eq!(t.column("Frame + FrameTime + Frame").unwrap(), vec![16.0, 19.0]);
        assert_eq!(t.column("Frame+Missing"), None);
        assert_eq!(without_warmup(table(&[0.0, 1.0]), 0).rows.len(), 2);
        assert!(without_warmup(table(&[0.0, 1.0]), 5).rows.is_empty());
        let no_index = FrameTable {
            columns: vec!["FrameTime".into()],
            rows: vec![vec![1.0], vec![2.0], vec![3.0]],
        };
        assert_eq!(without_warmup(no_index, 1).column("FrameTime").unwrap(), vec![2.0, 3.0]);
    }

    #[test]
    fn simulator_frames_match_the_summary_frames() {
        let text = "system = \"frame_pipeline\"\n\
                    [run]\nframes = 30\nwarmup_frames = 5\n\
                    [noise]\nenabled = false\n\
                    [workload]\nkind = \"fixed\"\ncpu = \"2ms\"\ngpu = \"5ms\"\n";
        let model: toml::Table = text.parse().unwrap();
        let runner = SimRunner {
            name: "test".into(),
            base_dir: PathBuf::from("."),
            text: String::new(),
            origins: Vec::new(),
        };
        let out = runner.run(&model, 1, true).unwrap();
        let frames = out.frames.unwrap();
        let index = frames.column("Frame").unwrap();
        assert_eq!(index.len(), 25);
        assert_eq!(index[0], 5.0);
        let count = crate::experiment::json_number(&out.summary, "metrics.frame_time_ms.count")
            .unwrap()
            .unwrap();
        assert_eq!(count as usize, frames.column("FrameTime").unwrap().len());
    }
}
