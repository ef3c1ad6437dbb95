//! The walkthrough in the system registry ([`crate::systems::SYSTEMS`]).

use std::io::Write;
use std::path::Path;

use crate::output::trace::TraceWriter;
use crate::systems::{Outcome, SystemError, SystemModel, outcome_basics, resolved_toml};

use super::config::WalkthroughConfig;
use super::run::{WalkthroughRun, run_walkthrough};

/// `system = "walkthrough"`.
pub struct WalkthroughSystem;

impl SystemModel for WalkthroughSystem {
    const NAME: &'static str = "walkthrough";
    const WRITES_TRACE: bool = false;
    type Config = WalkthroughConfig;
    type Run = WalkthroughRun;

    fn run(
        cfg: WalkthroughConfig,
        _base_dir: &Path,
        trace: Option<TraceWriter>,
    ) -> Result<WalkthroughRun, SystemError> {
        let mut run = run_walkthrough(cfg)?;
        // No trace of its own (`rendersim run --trace` refuses the model): a
        // trace writer handed in through the library is closed empty.
        run.trace = trace;
        Ok(run)
    }
}

impl Outcome for WalkthroughRun {
    outcome_basics!();

    fn table(&self) -> (Vec<String>, Vec<Vec<f64>>) {
        (self.columns.clone(), self.rows.clone())
    }

    fn write_table(&self, w: &mut dyn Write) -> std::io::Result<()> {
        crate::output::table::write_number_table(std::io::BufWriter::new(w), &self.columns, &self.rows)
    }

    fn resolved_model(&self, _base_dir: &Path) -> String {
        resolved_toml(&self.config)
    }
}
