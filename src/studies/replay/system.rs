//! The `replay` system ([`crate::systems::STUDIES`]): a capture replayed as
//! captured and under the model file's what-if, so an experiment can sweep
//! what-ifs on one capture (experiments/replay-whatif.toml), and, with
//! `compare`, put a capture measured under the what-if beside it
//! (experiments/replay-whatif-pairs.toml). Its summary is
//! the replay's (`replay.*`, the keys `rendersim replay --json` prints), its
//! table the frames of the run the model describes, as PresentMon writes
//! them (`frames.csv`: the what-if's run, or the replay as captured without
//! one; `rendersim replay --out` writes the same).

use std::io::Write;
use std::path::Path;

use serde::Serialize;
use serde_json::Value;

use crate::output::trace::TraceWriter;
use crate::systems::error::invalid;
use crate::systems::frame_pipeline::records::{COLUMNS, frame_rows};
use crate::systems::{Outcome, SystemError, SystemModel, resolved_toml};

use super::config::{ReplayConfig, whatif_sets};
use super::{Replay, ReplayError, ReplayOptions, ReplaySummary, replay};

/// `system = "replay"`.
pub struct ReplaySystem;

/// The summary.
#[derive(Debug, Serialize)]
struct Summary<'a> {
    system: &'static str,
    seed: u64,
    wall_seconds: f64,
    simulate_seconds: f64,
    replay: &'a ReplaySummary,
}

/// A finished run.
#[derive(Debug)]
pub struct ReplayRun {
    config: ReplayConfig,
    /// The replay.
    pub replay: Replay,
    trace: Option<TraceWriter>,
}

fn blame(e: ReplayError) -> SystemError {
    match e {
        ReplayError::Capture(e) => invalid("capture", e.to_string()),
        ReplayError::Config(e) => invalid("whatif", e.to_string()),
        ReplayError::Assume(e) => invalid("assume", e.to_string()),
        ReplayError::System(e) => e,
    }
}

impl SystemModel for ReplaySystem {
    const NAME: &'static str = "replay";
    const WRITES_TRACE: bool = false;
    type Config = ReplayConfig;
    type Run = ReplayRun;

    fn run(cfg: ReplayConfig, base_dir: &Path, trace: Option<TraceWriter>) -> Result<ReplayRun, SystemError> {
        let opts = ReplayOptions {
            app: cfg.app.clone(),
            swap_chain: cfg.swapchain.clone(),
            sets: whatif_sets(&cfg.whatif),
            assume: whatif_sets(&cfg.assume),
            from_tables: true,
        };
        let mut replay = replay(&base_dir.join(&cfg.capture), &opts).map_err(blame)?;
        if let Some(measured) = &cfg.compare {
            let c = super::compare::compare(&replay, &base_dir.join(measured)).map_err(|e| match e {
                ReplayError::Capture(e) => invalid("compare", e.to_string()),
                e => blame(e),
            })?;
            replay.summary.compare = Some(c);
        }
        Ok(ReplayRun {
            config: cfg,
            replay,
            trace,
        })
    }
}

impl Outcome for ReplayRun {
    /// The replay's typed summary under `replay`, with the run's seed and
    /// times, as JSON.
    fn summary(&self) -> Value {
        let s = &self.replay.summary;
        crate::systems::summary::to_json(&Summary {
            system: "replay",
            seed: self.config.run.seed,
            wall_seconds: s.wall_seconds,
            simulate_seconds: s.simulate_seconds,
            replay: s,
        })
    }

    fn write_report(&self, _model: &str, w: &mut dyn Write) -> std::io::Result<()> {
        let mut text = Vec::new();
        crate::studies::replay::report::write_text(&self.replay.summary, &mut text)?;
        w.write_all(&text)
    }

    fn table(&self) -> (Vec<String>, Vec<Vec<f64>>) {
        let run = self.replay.whatif_replayed.as_ref().unwrap_or(&self.replay.replayed);
        (
            COLUMNS.iter().map(|c| c.to_string()).collect(),
            frame_rows(&run.records, &run.generated, run.origin_ps),
        )
    }

    fn write_table(&self, w: &mut dyn Write) -> std::io::Result<()> {
        self.replay
            .whatif_replayed
            .as_ref()
            .unwrap_or(&self.replay.replayed)
            .write_csv(w)
    }

    fn resolved_model(&self, base_dir: &Path) -> String {
        let mut cfg = self.config.clone();
        cfg.capture = base_dir.join(&cfg.capture);
        cfg.compare = cfg.compare.map(|c| base_dir.join(c));
        resolved_toml(&cfg)
    }

    fn take_trace(&mut self) -> Option<TraceWriter> {
        self.trace.take()
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn into_any(self: Box<Self>) -> Box<dyn std::any::Any> {
        self
    }
}
