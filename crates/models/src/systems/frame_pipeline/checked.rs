//! A frame-pipeline model checked once (the parsed [`FramePipelineConfig`]
//! turned into a [`CheckedPipeline`], as ripgrep turns its `LowArgs` into
//! `HiArgs` and statrs's constructors return `Result`): every check of
//! `validate.rs` that needs only the model (ranges, distributions, the
//! display, the architecture, the noise's share, the scene's sizes, the
//! memory the results would take) runs in [`CheckedPipeline::new`], the
//! only way to make one. It is the first half of the pipeline's plan
//! ([`super::plan::PipelinePlan::new`], which then compiles the scene and
//! bounds the clock's range and the count of events); the walkthrough keeps
//! one checked model and moves it to each of its one-frame runs
//! ([`CheckedPipeline::for_run_at`], then
//! [`super::plan::PipelinePlan::with_program`]), so no code below can meet
//! an unchecked model or needs to check it again.

use crate::engine::Duration;
use crate::systems::error::SystemError;

use super::config::FramePipelineConfig;
use super::validate::{check_memory, estimate_events, validate};

/// A [`FramePipelineConfig`] that passed every model check.
#[derive(Debug, Clone)]
pub struct CheckedPipeline {
    cfg: FramePipelineConfig,
}

impl CheckedPipeline {
    /// Checks `cfg`: the values serde cannot check, then the memory its
    /// results would take (`run.max_memory`).
    pub fn new(cfg: FramePipelineConfig) -> Result<Self, SystemError> {
        validate(&cfg)?;
        check_memory(&cfg)?;
        Ok(CheckedPipeline { cfg })
    }

    /// The checked model.
    #[inline]
    pub fn config(&self) -> &FramePipelineConfig {
        &self.cfg
    }

    /// The checked model, given back.
    pub fn into_config(self) -> FramePipelineConfig {
        self.cfg
    }

    /// The same model for a run with seed `seed` that starts `start`
    /// picoseconds into a longer stretch of time (a walkthrough's frame):
    /// every periodic system task keeps its period and its phase moves by
    /// `start`, within the period. Neither change can make the model
    /// invalid, so it is not checked again.
    pub fn for_run_at(&self, seed: u64, start: u64) -> Self {
        let mut cfg = self.cfg.clone();
        cfg.run.seed = seed;
        for p in &mut cfg.noise.periodic {
            let period = p.period.0.max(1);
            p.phase = Duration(if start <= p.phase.0 {
                p.phase.0 - start
            } else {
                (period - (start - p.phase.0) % period) % period
            });
        }
        CheckedPipeline { cfg }
    }

    /// A lower bound, in parts (the key to blame, what, how many), of the
    /// events one run of this model needs whatever its scene draws: the
    /// frames, and over the span the per-frame fixed costs alone take
    /// (`cpu.clear`, `cpu.swap`, `gpu.clear`, `gpu.swap`, ...), the display's
    /// refreshes and the system tasks. The walkthrough multiplies it by its
    /// one-frame runs to refuse, before simulating, a walk that could not
    /// finish.
    pub fn events_floor(&self) -> Vec<crate::limits::EventPart> {
        estimate_events(&self.cfg, &super::analytic::analytic_terms(&self.cfg, None), None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{Overrides, deserialize, load_model};

    fn model(sets: &[&str]) -> FramePipelineConfig {
        let m = load_model(None, &Overrides::with_sets(sets)).unwrap();
        deserialize(&m.table, &m.source).unwrap()
    }

    #[test]
    fn an_invalid_model_is_refused_and_a_valid_one_kept_as_it_was() {
        let e = CheckedPipeline::new(model(&["display.buffers=0"]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("display.buffers"), "{e}");
        let cfg = model(&[]);
        let checked = CheckedPipeline::new(cfg.clone()).unwrap();
        assert_eq!(format!("{:?}", checked.config()), format!("{cfg:?}"));
    }

    #[test]
    fn a_later_start_moves_each_periodic_phase_back_within_its_period() {
        let checked = CheckedPipeline::new(model(&[])).unwrap();
        let periodic = &checked.config().noise.periodic;
        assert!(!periodic.is_empty(), "the default model has periodic system tasks");
        for start in [0u64, 1, 7_000_000_000, 1_000_000_000_000_000] {
            let moved = checked.for_run_at(42, start);
            assert_eq!(moved.config().run.seed, 42);
            for (a, b) in periodic.iter().zip(&moved.config().noise.periodic) {
                let period = a.period.0;
                assert!(b.phase.0 < period || start <= a.phase.0, "{b:?}");
                // The task's arrivals are the same instants, seen from `start`.
                assert_eq!((b.phase.0 + start) % period, a.phase.0 % period);
            }
            CheckedPipeline::new(moved.into_config()).unwrap();
        }
    }
}
