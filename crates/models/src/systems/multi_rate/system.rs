//! The multi-frame-rate system in the system registry
//! ([`crate::systems::SYSTEMS`]).

use std::io::Write;
use std::path::Path;

use crate::output::trace::TraceWriter;
use crate::systems::{Outcome, SystemError, SystemModel, outcome_basics, resolved_toml};

use super::config::MultiRateConfig;
use super::latency::{COLUMNS, event_rows};
use super::run::{MultiRateRun, run_multi_rate, write_events_csv};

/// `system = "multi_rate"`.
pub struct MultiRateSystem;

impl SystemModel for MultiRateSystem {
    const NAME: &'static str = "multi_rate";
    type Config = MultiRateConfig;
    type Run = MultiRateRun;

    fn run(cfg: MultiRateConfig, _base_dir: &Path, trace: Option<TraceWriter>) -> Result<MultiRateRun, SystemError> {
        run_multi_rate(cfg, trace)
    }
}

impl Outcome for MultiRateRun {
    outcome_basics!();

    fn table(&self) -> (Vec<String>, Vec<Vec<f64>>) {
        (
            COLUMNS.iter().map(|s| s.to_string()).collect(),
            event_rows(&self.events),
        )
    }

    fn write_table(&self, w: &mut dyn Write) -> std::io::Result<()> {
        write_events_csv(&self.events, w)
    }

    fn resolved_model(&self, _base_dir: &Path) -> String {
        resolved_toml(&self.config)
    }
}
