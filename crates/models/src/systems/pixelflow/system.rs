//! PixelFlow in the system registry ([`crate::systems::SYSTEMS`]).

use std::io::Write;
use std::path::Path;

use crate::output::trace::TraceWriter;
use crate::systems::{Outcome, SystemError, SystemModel, outcome_basics, resolved_toml};

use super::config::PixelFlowConfig;
use super::run::{COLUMNS, PixelFlowRun, region_rows, run_pixelflow, write_regions_csv, write_trace};

/// `system = "pixelflow"`.
pub struct PixelFlowSystem;

impl SystemModel for PixelFlowSystem {
    const NAME: &'static str = "pixelflow";
    type Config = PixelFlowConfig;
    type Run = PixelFlowRun;

    /// One frame's spans are kept while it runs and written to the trace at
    /// the end (the frame pipeline and the latency systems stream theirs).
    fn run(cfg: PixelFlowConfig, _base_dir: &Path, trace: Option<TraceWriter>) -> Result<PixelFlowRun, SystemError> {
        let mut run = run_pixelflow(cfg, trace.is_some())?;
        run.trace = trace.map(|mut t| {
            write_trace(&run, &mut t);
            t
        });
        Ok(run)
    }
}

impl Outcome for PixelFlowRun {
    outcome_basics!();

    fn table(&self) -> (Vec<String>, Vec<Vec<f64>>) {
        (COLUMNS.iter().map(|s| s.to_string()).collect(), region_rows(self))
    }

    fn write_table(&self, w: &mut dyn Write) -> std::io::Result<()> {
        write_regions_csv(self, w)
    }

    fn resolved_model(&self, _base_dir: &Path) -> String {
        resolved_toml(&self.config)
    }
}
