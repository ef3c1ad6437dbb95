//! The VR pipeline in the system registry
//! ([`crate::systems::SYSTEMS`]).

use std::io::Write;
use std::path::Path;

use crate::output::trace::TraceWriter;
use crate::systems::{Outcome, SystemError, SystemModel, outcome_basics, resolved_toml};

use super::config::VrConfig;
use super::run::{COLUMNS, motion_rows};
use super::run::{VrRun, run_vr, write_motions_csv};

/// `system = "vr"`.
pub struct VrSystem;

impl SystemModel for VrSystem {
    const NAME: &'static str = "vr";
    type Config = VrConfig;
    type Run = VrRun;

    fn run(cfg: VrConfig, _base_dir: &Path, trace: Option<TraceWriter>) -> Result<VrRun, SystemError> {
        run_vr(cfg, trace)
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
