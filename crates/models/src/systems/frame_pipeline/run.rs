//! Building and running the frame pipeline from a model: checked
//! (`validate.rs`), built, run, summarized (`summary.rs`).

use std::path::Path;

use serde_json::Value;

use crate::engine::{Duration, Limits, RunStats, Scheduler, StopReason, Time, run};

use super::config::{FramePipelineConfig, WorkloadConfig};
use super::model::FramePipeline;
use super::records::FrameRecord;
use super::workload::{SceneProgram, compile_scene};
use crate::output::trace::TraceWriter;
use crate::systems::error::SystemError;
use crate::systems::summary::to_json;

use super::checked::CheckedPipeline;
use super::summary::{analytic_terms, positive_zeros, summarize};
use super::validate::{check_events, check_time_range};
/// Everything a run produced.
#[derive(Debug)]
pub struct PipelineRun {
    /// The model as simulated.
    pub config: FramePipelineConfig,
    /// Kernel statistics.
    pub stats: RunStats,
    /// Per-frame records.
    pub records: Vec<FrameRecord>,
    /// The JSON summary.
    pub summary: Value,
    /// The trace, when one was asked for: every event written, not yet
    /// closed ([`TraceWriter::finish`]).
    pub trace: Option<TraceWriter>,
    /// Refresh period (for trace output).
    pub refresh: Duration,
    /// Exact time per state of every unit, picoseconds (for conservation checks).
    pub clocks: ClockTotals,
    /// Commands pushed by the CPU and executed by the GPU.
    pub commands: (u64, u64),
}

/// Exact per-state totals of every unit's clock at the end of the run.
#[derive(Debug, Clone)]
pub struct ClockTotals {
    /// CPU: work, system, wait FIFO, wait frames, idle.
    pub cpu: [u64; 8],
    /// Front end states.
    pub front: [u64; 6],
    /// Geometry: busy, blocked, idle.
    pub geometry: [u64; 3],
    /// Fragment: busy, idle.
    pub fragment: [u64; 2],
    /// GPU: busy, idle.
    pub gpu: [u64; 2],
    /// Bottleneck shares.
    pub bottleneck: [u64; 6],
    /// Elapsed simulated time.
    pub elapsed: u64,
}

/// Validates, builds and runs the model.
pub fn run_pipeline(
    cfg: FramePipelineConfig,
    base_dir: &Path,
    trace: Option<TraceWriter>,
) -> Result<PipelineRun, SystemError> {
    let checked = CheckedPipeline::new(cfg)?;
    let cfg = checked.config();
    let build_start = std::time::Instant::now();
    let scene = match &cfg.workload {
        WorkloadConfig::Scene(s) => Some(compile_scene(cfg, s, base_dir).map_err(|e| match e {
            super::workload::WorkloadError::Invalid { key, message } => SystemError::Invalid { key, message },
        })?),
        WorkloadConfig::Fixed(_) | WorkloadConfig::Frames(_) => None,
    };
    let analytic = analytic_terms(cfg, scene.as_ref());
    check_time_range(cfg, &analytic)?;
    check_events(cfg, &analytic, scene.as_ref().map(|s| s.stats.triangles))?;
    let scene_stats = scene.as_ref().map(|s| s.stats.clone());
    let mut model = FramePipeline::new(checked, scene, trace)?;
    let build_seconds = build_start.elapsed().as_secs_f64();
    let mut sched = Scheduler::new();
    model.start(&mut sched)?;
    let limits = Limits {
        until: model.env.cfg.run.until.map(|d| Time(d.0)),
        max_events: model.env.cfg.run.max_events,
    };
    let stats = run(&mut model, &mut sched, limits)?;
    model.catch_up(&sched)?;
    if stats.stopped_by == StopReason::Exhausted && !model.done() {
        return Err(SystemError::Unfinished {
            at: stats.end_time,
            missing: "every frame was done".into(),
            state: format!(
                "{} of {} frames done: {}",
                model.resolved(),
                model.frames_total,
                model.describe()
            ),
        });
    }
    if !model.done() {
        // Stopped by `run.until` or `run.max_events`: frames still in flight
        // have no complete timeline, so only the completed ones are kept.
        model.keep_completed_frames();
    }
    let mut summary = to_json(&summarize(&model, &stats, analytic, scene_stats, build_seconds));
    positive_zeros(&mut summary);
    let refresh = model.display.refresh();
    let end = stats.end_time;
    let a = &model.acct;
    let clocks = ClockTotals {
        cpu: a.cpu.totals_at(end),
        front: a.front.totals_at(end),
        geometry: a.geom.totals_at(end),
        fragment: a.frag.totals_at(end),
        gpu: a.gpu.totals_at(end),
        bottleneck: a.path.totals_at(end, model.done()),
        elapsed: end.0,
    };
    let commands = model.command_counts();
    let records = std::mem::take(&mut model.env.records);
    let trace = model.acct.trace.take().map(|t| t.end(&records, refresh));
    Ok(PipelineRun {
        stats,
        summary,
        trace,
        refresh,
        clocks,
        commands,
        records,
        config: model.env.cfg,
    })
}

/// Runs a program built by the caller ([`super::workload::build_program`])
/// for `cfg.run.frames` frames, without validating, summarizing or
/// tracing: the kernel statistics and the per-frame records. For systems
/// that draw their own frames through the pipeline (the walkthrough draws
/// each frame's visible objects as a one-frame run); the model's workload
/// must be a scene.
pub fn simulate_program(
    cfg: CheckedPipeline,
    program: SceneProgram,
) -> Result<(RunStats, Vec<FrameRecord>), SystemError> {
    let mut model = FramePipeline::new(cfg, Some(program), None)?;
    let mut sched = Scheduler::new();
    model.start(&mut sched)?;
    let stats = run(&mut model, &mut sched, Limits::default())?;
    model.catch_up(&sched)?;
    if !model.done() {
        return Err(SystemError::Unfinished {
            at: stats.end_time,
            missing: "every frame was done".into(),
            state: model.describe(),
        });
    }
    Ok((stats, std::mem::take(&mut model.env.records)))
}
