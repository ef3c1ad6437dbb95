//! The [`Runner`] that runs the simulator itself.

use std::path::PathBuf;

use crate::config::ModelSource;
use crate::systems::run_model;

use super::runner::{FrameTable, RunOutput, Runner};

/// Runs models with the simulator; relative paths inside models resolve
/// against `base_dir`.
#[derive(Debug, Clone)]
pub struct SimRunner {
    /// Name used in error messages.
    pub name: String,
    /// Directory of the model file.
    pub base_dir: PathBuf,
}

impl Runner for SimRunner {
    fn run(&self, model: &toml::Table, seed: u64, want_frames: bool) -> Result<RunOutput, String> {
        let mut table = model.clone();
        crate::config::set_dotted(&mut table, "run.seed", toml::Value::Integer(seed as i64))?;
        let src = ModelSource {
            name: self.name.clone(),
            text: String::new(),
            base_dir: self.base_dir.clone(),
        };
        let run = run_model(&src, &table, false).map_err(|e| e.to_string())?;
        let frames = want_frames.then(|| {
            let (columns, rows) = run.frame_table();
            FrameTable { columns, rows }
        });
        Ok(RunOutput {
            summary: run.summary().clone(),
            frames,
        })
    }
}
