//! The frame pipeline in the system registry ([`crate::systems::SYSTEMS`]).

use std::io::Write;
use std::path::Path;

use crate::output::trace::TraceWriter;
use crate::systems::{Outcome, SystemError, SystemModel, outcome_basics, resolved_toml};

use super::config::{FramePipelineConfig, WorkloadConfig};
use super::records::{COLUMNS, ChainInfo, frame_rows, frame_values_with, write_frames_csv};
use super::run::{PipelineRun, run_pipeline};

/// `system = "frame_pipeline"` (the default).
pub struct FramePipelineSystem;

impl SystemModel for FramePipelineSystem {
    const NAME: &'static str = "frame_pipeline";
    type Config = FramePipelineConfig;
    type Run = PipelineRun;

    fn run(cfg: FramePipelineConfig, base_dir: &Path, trace: Option<TraceWriter>) -> Result<PipelineRun, SystemError> {
        run_pipeline(cfg, base_dir, trace)
    }
}

impl PipelineRun {
    /// Writes the run's `frames.csv` (PresentMon 2 columns, [`super::records`]).
    pub fn write_frames_csv(&self, w: impl Write) -> std::io::Result<()> {
        write_frames_csv(
            &self.records,
            &self.generated,
            &ChainInfo::of_display(&self.config.display),
            0,
            w,
        )
    }

    /// The summary as written (`summary.json`, without what the CLI adds),
    /// made from [`PipelineRun::results`]; reports and studies read the
    /// typed one.
    pub fn summary(&self) -> serde_json::Value {
        super::summary::as_json(&self.results)
    }

    /// The rows of its `frames.csv`: rendered frames and generated ones.
    pub fn table_rows(&self) -> usize {
        self.records.len() + self.generated.len()
    }

    /// The rows of its `frames.csv` as numbers handed to `put(k, value)`
    /// ([`frame_values_with`]): the text columns (the same on every row)
    /// and whether each row is a generated frame.
    pub fn frame_values_with(&self, put: impl FnMut(usize, f64)) -> ([String; 8], Vec<bool>) {
        let kinds = frame_values_with(&self.records, &self.generated, 0, put);
        (ChainInfo::of_display(&self.config.display).text(), kinds)
    }
}

impl Outcome for PipelineRun {
    outcome_basics!(
        summary = results,
        report = super::report::write_report,
        json = super::summary::as_json
    );

    fn table(&self) -> (Vec<String>, Vec<Vec<f64>>) {
        (
            COLUMNS.iter().map(|s| s.to_string()).collect(),
            frame_rows(&self.records, &self.generated, 0),
        )
    }

    fn write_table(&self, w: &mut dyn Write) -> std::io::Result<()> {
        PipelineRun::write_frames_csv(self, w)
    }

    /// Mesh files named relative to the model are made absolute, so the
    /// resolved model runs from anywhere.
    fn resolved_model(&self, base_dir: &Path) -> String {
        let mut cfg = self.config.clone();
        if let WorkloadConfig::Scene(s) = &mut cfg.workload {
            for g in &mut s.groups {
                if let crate::scene::config::MeshRef::Spec(spec) = &mut g.mesh {
                    let p = Path::new(spec.as_str());
                    if (spec.ends_with(".obj") || spec.ends_with(".idx")) && p.is_relative() {
                        let abs = base_dir.join(p);
                        *spec = abs.canonicalize().unwrap_or(abs).display().to_string();
                    }
                }
            }
        }
        resolved_toml(&cfg)
    }
}
