//! The VR pipeline in the system registry
//! ([`crate::systems::SYSTEMS`]).

use std::io::Write;
use std::path::Path;

use crate::config::{ModelSource, deserialize};
use crate::output::trace::TraceWriter;
use crate::systems::{Outcome, SimError, System, outcome_basics, resolved_toml};

use super::config::VrConfig;
use super::run::{COLUMNS, motion_rows};
use super::run::{VrRun, run_vr, write_motions_csv};

/// `system = "vr"`.
pub struct VrSystem;

impl System for VrSystem {
    fn name(&self) -> &'static str {
        "vr"
    }

    fn run(
        &self,
        src: &ModelSource,
        table: &toml::Table,
        trace: Option<TraceWriter>,
    ) -> Result<Box<dyn Outcome>, SimError> {
        let cfg: VrConfig = deserialize(table, src)?;
        let run = run_vr(cfg, trace).map_err(|e| SimError::of(src, e))?;
        Ok(Box::new(run))
    }
}

impl Outcome for VrRun {
    outcome_basics!();

    fn table(&self) -> (Vec<String>, Vec<Vec<f64>>) {
        (
            COLUMNS.iter().map(|s| s.to_string()).collect(),
            motion_rows(&self.motions),
        )
    }

    fn write_table(&self, w: &mut dyn Write) -> std::io::Result<()> {
        write_motions_csv(&self.motions, w)
    }

    fn resolved_model(&self, _base_dir: &Path) -> String {
        resolved_toml(&self.config)
    }
}
