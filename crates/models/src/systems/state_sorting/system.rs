//! The `state_sorting` run, its summary (`metrics.state_changes.<strategy>`,
//! `metrics.lower_bound`, `metrics.over_bound.<strategy>`,
//! `metrics.over_best.<strategy>`, ...), its table
//! (one row per strategy) and the registry entry
//! ([`crate::systems::SYSTEMS`]).

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use serde::Serialize;

use crate::components::sorting_buffer::{
    MAX_OFFLINE_LEN, SortBufferError, StateId, Strategy, check_buffer, distinct_states, input_runs, lower_bound,
    offline_optimum, sequence::sequence_from_spec, simulate,
};
use crate::output::trace::TraceWriter;
use crate::scene::states::{StatesError, scene_state_ids};
use crate::systems::error::invalid;
use crate::systems::{Outcome, SystemError, SystemModel, outcome_basics, resolved_toml};

use super::config::StateSortingConfig;

/// `system = "state_sorting"`.
pub struct StateSortingSystem;

/// The summary's numbers.
#[derive(Debug, Clone, Serialize)]
pub struct StateSortingMetrics {
    /// Elements in the sequence.
    pub sequence_length: usize,
    /// Distinct states among them.
    pub distinct_states: usize,
    /// State changes without a buffer (runs of the input).
    pub input_runs: u64,
    /// The sorting buffer's slots.
    pub buffer: usize,
    /// A lower bound of the offline optimum.
    pub lower_bound: u64,
    /// The exact offline optimum (sequences of at most `MAX_OFFLINE_LEN`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub offline_optimum: Option<u64>,
    /// State changes per strategy.
    pub state_changes: BTreeMap<&'static str, u64>,
    /// State changes over the lower bound, per strategy.
    pub over_bound: BTreeMap<&'static str, f64>,
    /// State changes over the changes without a buffer, per strategy.
    pub over_input: BTreeMap<&'static str, f64>,
    /// Overflows (the strategy's choices), per strategy.
    pub overflows: BTreeMap<&'static str, u64>,
    /// State changes over the fewest any of the strategies run sent, per
    /// strategy (1 for the best).
    pub over_best: BTreeMap<&'static str, f64>,
}

/// The summary of a state-sorting run (`summary.json`).
#[derive(Debug, Clone, Serialize)]
pub struct StateSortingSummary {
    /// `"state_sorting"`.
    pub system: &'static str,
    /// The model's description.
    pub description: String,
    /// The sequence spec.
    pub sequence: String,
    /// Master seed.
    pub seed: u64,
    /// Wall time of the run.
    pub wall_seconds: f64,
    /// Wall time of the strategies' runs.
    pub simulate_seconds: f64,
    /// The results.
    pub metrics: StateSortingMetrics,
}

/// A finished run.
#[derive(Debug)]
pub struct StateSortingRun {
    /// The summary, typed (`summary.json` is made from it where it is written).
    pub summary: StateSortingSummary,
    config: StateSortingConfig,
    /// (strategy, state changes, overflows), in the model's order.
    rows: Vec<(Strategy, u64, u64)>,
    lower_bound: u64,
    trace: Option<TraceWriter>,
}

/// Columns of the per-strategy table.
const COLUMNS: [&str; 5] = ["Strategy", "Buffer", "StateChanges", "LowerBound", "Overflows"];

fn strategy_of(name: &str) -> Option<Strategy> {
    Strategy::ALL.into_iter().find(|s| s.name() == name)
}

/// Why a sequence spec cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum SequenceError {
    /// A `scene:MODEL.toml` sequence.
    #[error(transparent)]
    Scene(#[from] StatesError),
    /// A file or generator sequence.
    #[error(transparent)]
    Spec(#[from] SortBufferError),
}

/// The sequence a spec names (relative paths from `base`).
pub fn resolve_sequence(spec: &str, base: &Path) -> Result<Vec<StateId>, SequenceError> {
    Ok(match spec.strip_prefix("scene:") {
        Some(rest) => scene_state_ids(rest, base)?,
        None => sequence_from_spec(spec, base)?,
    })
}

/// Reads the sequence and runs every strategy.
pub fn run_state_sorting(cfg: StateSortingConfig, base_dir: &Path) -> Result<StateSortingRun, SystemError> {
    let start = Instant::now();
    check_buffer(cfg.buffer).map_err(|e| invalid("buffer", e.to_string()))?;
    if cfg.strategies.is_empty() {
        return Err(invalid("strategies", "names no strategy"));
    }
    let mut strategies = Vec::new();
    for (i, name) in cfg.strategies.iter().enumerate() {
        let s = strategy_of(name).ok_or_else(|| {
            invalid(
                &format!("strategies[{i}]"),
                format!("unknown strategy {name:?} (known: lru, bounded-waste, random, round-robin)"),
            )
        })?;
        if strategies.contains(&s) {
            return Err(invalid(
                &format!("strategies[{i}]"),
                format!("{name:?} is listed twice"),
            ));
        }
        strategies.push(s);
    }
    let seq = resolve_sequence(&cfg.sequence, base_dir).map_err(|e| invalid("sequence", e.to_string()))?;
    let sim_start = Instant::now();
    let mut rows = Vec::new();
    let mut metrics = StateSortingMetrics {
        sequence_length: seq.len(),
        distinct_states: distinct_states(&seq),
        input_runs: input_runs(&seq),
        buffer: cfg.buffer,
        lower_bound: lower_bound(&seq, cfg.buffer),
        offline_optimum: None,
        state_changes: BTreeMap::new(),
        over_bound: BTreeMap::new(),
        over_input: BTreeMap::new(),
        overflows: BTreeMap::new(),
        over_best: BTreeMap::new(),
    };
    if seq.len() <= MAX_OFFLINE_LEN {
        metrics.offline_optimum =
            Some(offline_optimum(&seq, cfg.buffer).map_err(|e| invalid("sequence", e.to_string()))?);
    }
    let ratio = |a: u64, b: u64| {
        if b == 0 {
            if a == 0 { 1.0 } else { f64::INFINITY }
        } else {
            a as f64 / b as f64
        }
    };
    for &s in &strategies {
        let r = simulate(&seq, cfg.buffer, s, cfg.run.seed, false).map_err(|e| invalid("sequence", e.to_string()))?;
        metrics.state_changes.insert(s.name(), r.state_changes);
        metrics
            .over_bound
            .insert(s.name(), ratio(r.state_changes, metrics.lower_bound));
        metrics
            .over_input
            .insert(s.name(), ratio(r.state_changes, metrics.input_runs));
        metrics.overflows.insert(s.name(), r.overflows);
        rows.push((s, r.state_changes, r.overflows));
    }
    let best = metrics.state_changes.values().copied().min().unwrap_or(0);
    for (&name, &changes) in &metrics.state_changes {
        metrics.over_best.insert(name, ratio(changes, best));
    }
    let simulate_seconds = sim_start.elapsed().as_secs_f64();
    let lower = metrics.lower_bound;
    let summary = StateSortingSummary {
        system: "state_sorting",
        description: cfg.description.clone(),
        sequence: cfg.sequence.clone(),
        seed: cfg.run.seed,
        wall_seconds: start.elapsed().as_secs_f64(),
        simulate_seconds,
        metrics,
    };
    Ok(StateSortingRun {
        summary,
        config: cfg,
        rows,
        lower_bound: lower,
        trace: None,
    })
}

impl SystemModel for StateSortingSystem {
    const NAME: &'static str = "state_sorting";
    const WRITES_TRACE: bool = false;
    type Config = StateSortingConfig;
    type Run = StateSortingRun;

    fn run(
        cfg: StateSortingConfig,
        base_dir: &Path,
        trace: Option<TraceWriter>,
    ) -> Result<StateSortingRun, SystemError> {
        let mut run = run_state_sorting(cfg, base_dir)?;
        // No events of its own (`rendersim run --trace` refuses the model): a
        // trace writer handed in through the library is closed empty.
        run.trace = trace;
        Ok(run)
    }
}

impl Outcome for StateSortingRun {
    outcome_basics!();

    fn table(&self) -> (Vec<String>, Vec<Vec<f64>>) {
        let rows = self
            .rows
            .iter()
            .map(|&(s, changes, overflows)| {
                let index = Strategy::ALL.iter().position(|&x| x == s).unwrap_or(0);
                vec![
                    index as f64,
                    self.config.buffer as f64,
                    changes as f64,
                    self.lower_bound as f64,
                    overflows as f64,
                ]
            })
            .collect();
        (COLUMNS.iter().map(|c| c.to_string()).collect(), rows)
    }

    fn write_table(&self, w: &mut dyn std::io::Write) -> std::io::Result<()> {
        let (columns, rows) = self.table();
        crate::output::table::write_number_table(std::io::BufWriter::new(w), &columns, &rows)
    }

    fn resolved_model(&self, base_dir: &Path) -> String {
        let mut cfg = self.config.clone();
        // A file or a scene's model, made absolute so the resolved model runs anywhere.
        let spec = &cfg.sequence;
        if !crate::components::sorting_buffer::sequence::is_generated(spec) {
            let (prefix, rest) = match spec.strip_prefix("scene:") {
                Some(r) => ("scene:", r),
                None => ("", spec.as_str()),
            };
            cfg.sequence = format!("{prefix}{}", base_dir.join(rest).display());
        }
        resolved_toml(&cfg)
    }
}
