//! Building and running the frame pipeline from a model, and its summary.

use std::path::Path;

use std::collections::BTreeMap;

use serde::Serialize;
use serde_json::Value;

use crate::components::swap_chain::PresentMode;
use crate::engine::{Duration, Limits, PS_PER_MS, RunStats, Scheduler, StopReason, Time, run};

use super::accounting::{BOTTLENECKS, CPU_STATES, FRAG_STATES, FRONT_STATES, GEOM_STATES};
use super::config::{FramePipelineConfig, WorkloadConfig};
use super::model::FramePipeline;
use super::records::{FrameRecord, frame_rows};
use super::workload::{SceneProgram, compile_scene};
use crate::output::trace::TraceWriter;
use crate::systems::error::{SystemError, invalid as bad};
use crate::systems::summary::{Dist, EventCounts, events_per_second, to_json};

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
    pub cpu: [u64; 5],
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

/// Checks values serde cannot (ranges, distributions).
pub fn validate(cfg: &FramePipelineConfig) -> Result<(), SystemError> {
    if cfg.system != "frame_pipeline" {
        return Err(bad(
            "system",
            format!("expected \"frame_pipeline\", got {:?}", cfg.system),
        ));
    }
    if cfg.display.refresh.period.0 < crate::limits::MIN_REFRESH_PERIOD_PS {
        return Err(bad(
            "display.refresh",
            format!(
                "a refresh period of {} is shorter than the limit of 1us (1 MHz): every refresh is an event",
                cfg.display.refresh.period
            ),
        ));
    }
    if !(2..=16).contains(&cfg.display.buffers) {
        return Err(bad(
            "display.buffers",
            format!(
                "must be between 2 and 16 swap-chain images, got {}",
                cfg.display.buffers
            ),
        ));
    }
    cfg.gpu
        .check_architecture()
        .map_err(|(key, message)| bad(key, message))?;
    if cfg.cpu.max_frames_ahead == 0 {
        return Err(bad(
            "cpu.max_frames_ahead",
            "must be at least 1 (the frame being submitted)",
        ));
    }
    if cfg.run.frames > 0 && cfg.run.warmup_frames >= cfg.run.frames {
        return Err(bad(
            "run.warmup_frames|run.frames",
            format!(
                "run.warmup_frames ({}) must be less than run.frames ({})",
                cfg.run.warmup_frames, cfg.run.frames
            ),
        ));
    }
    cfg.cpu
        .non_render
        .validate()
        .map_err(|e| bad("cpu.non_render", e.to_string()))?;
    if let WorkloadConfig::Fixed(f) = &cfg.workload {
        f.cpu.validate().map_err(|e| bad("workload.cpu", e.to_string()))?;
        f.gpu.validate().map_err(|e| bad("workload.gpu", e.to_string()))?;
    }
    for (i, p) in cfg.noise.periodic.iter().enumerate() {
        p.duration
            .validate()
            .map_err(|e| bad(&format!("noise.periodic.{i}.duration"), e.to_string()))?;
        if p.period.0 == 0 {
            return Err(bad(&format!("noise.periodic.{i}.period"), "must be greater than zero"));
        }
    }
    for (i, r) in cfg.noise.random.iter().enumerate() {
        r.duration
            .validate()
            .map_err(|e| bad(&format!("noise.random.{i}.duration"), e.to_string()))?;
    }
    for (key, d) in [
        ("variation.cpu", &cfg.variation.cpu),
        ("variation.gpu", &cfg.variation.gpu),
    ] {
        if let Some(d) = d {
            d.validate().map_err(|e| bad(key, e.to_string()))?;
        }
    }
    if let WorkloadConfig::Scene(sc) = &cfg.workload {
        check_scene_sizes(sc)?;
    }
    Ok(())
}

/// Checks a scene's object counts and scale against [`crate::limits`]
/// before anything is compiled or allocated.
fn check_scene_sizes(sc: &crate::scene::config::SceneWorkload) -> Result<(), SystemError> {
    use crate::limits::{MAX_SCENE_OBJECTS, MAX_SCENE_SCALE};
    if sc.scale.is_finite() && sc.scale > MAX_SCENE_SCALE {
        return Err(bad(
            "workload.scale",
            format!(
                "{:?} is more than the limit of {MAX_SCENE_SCALE:?} (times the paper's scene)",
                sc.scale
            ),
        ));
    }
    let mut total = 0u64;
    if let Some(p) = &sc.preset
        && sc.scale.is_finite()
        && sc.scale > 0.0
        && let Some(groups) = crate::scene::presets::preset_groups(p, sc.scale)
    {
        total = groups.iter().fold(0u64, |t, g| t.saturating_add(g.count));
    }
    for (i, g) in sc.groups.iter().enumerate() {
        if g.count > MAX_SCENE_OBJECTS {
            return Err(bad(
                &format!("workload.groups.{i}.count"),
                format!(
                    "{} objects is more than the limit of {MAX_SCENE_OBJECTS} per scene",
                    g.count
                ),
            ));
        }
        total = total.saturating_add(g.count);
        if total > MAX_SCENE_OBJECTS {
            return Err(bad(
                &format!("workload.groups.{i}.count"),
                format!(
                    "the scene has {total} objects up to this group, more than the limit of {MAX_SCENE_OBJECTS} per scene"
                ),
            ));
        }
    }
    if total > MAX_SCENE_OBJECTS {
        return Err(bad(
            "workload.scale",
            format!(
                "preset {:?} at scale {} has {total} objects, more than the limit of {MAX_SCENE_OBJECTS} per scene",
                sc.preset.as_deref().unwrap_or(""),
                sc.scale
            ),
        ));
    }
    Ok(())
}

/// Bytes a frame's results take: its record, its table row and the metric
/// columns built from it.
const BYTES_PER_FRAME: usize = std::mem::size_of::<FrameRecord>() + 14 * 8 + 8 * 8;

/// Estimates the memory a run needs from its inputs, before simulating:
/// per-frame records, the scene's draws and generated index buffers (a
/// trace takes none: it streams to its file). Returns the bytes and a
/// description of the terms.
pub fn estimate_memory(cfg: &FramePipelineConfig) -> (u64, String) {
    use crate::limits::{add_bytes, show_bytes};
    let mut parts = Vec::new();
    let mut total = 0u64;
    let mut frames_bytes = 0u64;
    add_bytes(&mut frames_bytes, cfg.run.frames, BYTES_PER_FRAME);
    total = total.saturating_add(frames_bytes);
    parts.push(format!(
        "{} frames x {BYTES_PER_FRAME} bytes = {}",
        cfg.run.frames,
        show_bytes(frames_bytes)
    ));
    if let WorkloadConfig::Scene(sc) = &cfg.workload {
        let mut objects: u64 = sc.groups.iter().fold(0, |t, g| t.saturating_add(g.count));
        if let Some(p) = &sc.preset
            && sc.scale.is_finite()
            && sc.scale > 0.0
            && let Some(groups) = crate::scene::presets::preset_groups(p, sc.scale)
        {
            objects = groups.iter().fold(objects, |t, g| t.saturating_add(g.count));
        }
        let per_object = std::mem::size_of::<super::workload::DrawItem>() + 48;
        let mut b = 0u64;
        add_bytes(&mut b, objects, per_object);
        total = total.saturating_add(b);
        parts.push(format!("{objects} objects x {per_object} bytes = {}", show_bytes(b)));
        // A generated mesh: its 4-byte indices, a per-triangle count, and
        // the reordering's temporaries (about 4 more words per index).
        let mut mesh = 0u64;
        for g in &sc.groups {
            if let crate::scene::config::MeshRef::Spec(spec) = &g.mesh
                && let Some(n) = crate::scene::generators::spec_index_count(spec)
                && n <= crate::limits::MAX_MESH_INDICES
            {
                let per_index = if spec.contains("optimized") || spec.contains("shuffled") || spec.contains("local") {
                    20
                } else {
                    6
                };
                add_bytes(&mut mesh, n, per_index);
            }
        }
        if mesh > 0 {
            total = total.saturating_add(mesh);
            parts.push(format!("generated meshes {}", show_bytes(mesh)));
        }
    }
    (total, parts.join(", "))
}

/// Fails with an error naming `run.max_memory` when the estimate exceeds it.
fn check_memory(cfg: &FramePipelineConfig) -> Result<(), SystemError> {
    let limit = cfg.run.max_memory.map_or(crate::limits::DEFAULT_MAX_MEMORY, |b| b.0);
    let (estimate, parts) = estimate_memory(cfg);
    if estimate > limit {
        return Err(bad(
            "run.max_memory",
            crate::limits::over_memory_message(estimate, &parts, limit),
        ));
    }
    Ok(())
}

/// Validates, builds and runs the model.
pub fn run_pipeline(
    cfg: FramePipelineConfig,
    base_dir: &Path,
    trace: Option<TraceWriter>,
) -> Result<PipelineRun, SystemError> {
    validate(&cfg)?;
    check_memory(&cfg)?;
    let build_start = std::time::Instant::now();
    let scene = match &cfg.workload {
        WorkloadConfig::Scene(s) => Some(compile_scene(&cfg, s, base_dir).map_err(|e| match e {
            super::workload::WorkloadError::Invalid { key, message } => SystemError::Invalid { key, message },
        })?),
        WorkloadConfig::Fixed(_) => None,
    };
    let analytic = analytic_terms(&cfg, scene.as_ref());
    check_time_range(&cfg, &analytic)?;
    let scene_stats = scene.as_ref().map(|s| s.stats.clone());
    let mut model = FramePipeline::new(cfg, scene, trace)?;
    let build_seconds = build_start.elapsed().as_secs_f64();
    let mut sched = Scheduler::new();
    model.start(&mut sched)?;
    let limits = Limits {
        until: model.cfg.run.until.map(|d| Time(d.0)),
        max_events: model.cfg.run.max_events,
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
    let refresh = model.refresh;
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
    let records = std::mem::take(&mut model.records);
    let trace = model.acct.trace.take().map(|t| t.end(&records, refresh));
    Ok(PipelineRun {
        stats,
        summary,
        trace,
        refresh,
        clocks,
        commands,
        records,
        config: model.cfg,
    })
}

/// Replaces every -0.0 in `v` by 0.0 (an empty sum of floats is -0.0, and
/// "-0" in an output reads like a negative time).
fn positive_zeros(v: &mut Value) {
    match v {
        Value::Number(n) if n.as_f64() == Some(0.0) && n.as_f64().is_some_and(|x| x.is_sign_negative()) => {
            *v = Value::from(0.0);
        }
        Value::Object(m) => m.values_mut().for_each(positive_zeros),
        Value::Array(a) => a.iter_mut().for_each(positive_zeros),
        _ => {}
    }
}

fn ms(ps: u64) -> f64 {
    ps as f64 / PS_PER_MS as f64
}

/// Refuses, before simulating, expected per-frame terms that are not finite
/// numbers (naming the distribution), and a run whose simulated time certainly passes
/// the clock's range (`u64` picoseconds, about 213 days): `run.frames`
/// frames take at least the largest expected per-frame term each (the
/// units work in parallel, the slowest one bounds the frame rate; with a
/// vsynced FIFO swap chain a frame also takes at least a refresh). Such a
/// run would otherwise simulate, possibly for a long time (every refresh
/// of a vsynced display is an event), before failing at the overflow. Runs
/// with `run.until` or `run.max_events` may stop earlier and are left to the
/// clock's own checks.
fn check_time_range(cfg: &FramePipelineConfig, a: &AnalyticTerms) -> Result<(), SystemError> {
    let (cpu_key, gpu_key) = match &cfg.workload {
        WorkloadConfig::Fixed(_) => ("workload.cpu", "workload.gpu"),
        WorkloadConfig::Scene(_) => ("workload", "workload"),
    };
    // An expected term that is not a finite number (a distribution whose
    // mean overflows or does not exist) would be written as null.
    for (value, is_cpu, what) in [
        (a.cpu_ms, true, "CPU time"),
        (a.gpu_front_end_ms, false, "GPU front-end time"),
        (a.geometry_ms, false, "geometry time"),
        (a.fragment_ms, false, "fragment time"),
    ] {
        if value.is_finite() {
            continue;
        }
        let mut keys = vec![];
        if !cfg.cpu.non_render.mean().is_finite() {
            keys.push("cpu.non_render".to_string());
        }
        match &cfg.workload {
            WorkloadConfig::Fixed(f) => {
                if !f.cpu.mean().is_finite() {
                    keys.push("workload.cpu".into());
                }
                if !f.gpu.mean().is_finite() {
                    keys.push("workload.gpu".into());
                }
            }
            WorkloadConfig::Scene(sc) => keys.extend(
                sc.groups
                    .iter()
                    .enumerate()
                    .filter(|(_, g)| !g.triangle_pixels.mean().is_finite())
                    .map(|(i, _)| format!("workload.groups.{i}.triangle_pixels")),
            ),
        }
        if keys.is_empty() {
            keys.push(if is_cpu { cpu_key } else { gpu_key }.to_string());
        }
        return Err(bad(
            &keys.join("|"),
            format!(
                "the expected {what} per frame is not a finite number: the mean of {} overflows or does not exist",
                keys.join(", ")
            ),
        ));
    }
    if cfg.run.until.is_some() || cfg.run.max_events.is_some() {
        return Ok(());
    }
    // (Every term is finite here: the loop above returned otherwise.)
    let term = |ms: f64| ms * PS_PER_MS as f64;
    let mut terms = vec![
        ("CPU work", cpu_key, term(a.cpu_ms)),
        ("GPU front end work", gpu_key, term(a.gpu_front_end_ms)),
        ("geometry work", gpu_key, term(a.geometry_ms)),
        ("fragment work", gpu_key, term(a.fragment_ms)),
    ];
    // A vsynced FIFO swap chain shows every frame for at least one refresh.
    if cfg.display.vsync && cfg.display.present_mode == PresentMode::Fifo {
        terms.push((
            "display refresh",
            "display.refresh",
            cfg.display.refresh.period.0 as f64,
        ));
    }
    let (what, source, per_frame) = terms.into_iter().max_by(|a, b| a.2.total_cmp(&b.2)).expect("terms");
    let total = per_frame * cfg.run.frames as f64;
    if total < u64::MAX as f64 {
        return Ok(());
    }
    Err(bad(
        &format!("{source}|run.frames"),
        format!(
            "run.frames = {} frames of at least {} s each ({what}, {source}) need about {:.3e} s of simulated time: \
             the simulated clock would overflow (64-bit picoseconds, about 213 days); lower {source} or run.frames, or set run.until",
            cfg.run.frames,
            per_frame / PS_PER_MS as f64 / 1000.0,
            total / PS_PER_MS as f64 / 1000.0,
        ),
    ))
}

/// Expected per-frame terms of paper 000 §4.1: ET_cpu, and ET_gpu split into
/// front end, geometry and fragment. `gpu_max_ms` = max of the three (the
/// front end overlaps the stages: it prepares the next draw while they work),
/// a lower bound of the GPU time when the GPU never starves; `gpu_sum_ms` =
/// their sum, the time with no overlap at all (§4.5.1's "sum" estimate).
fn analytic_terms(cfg: &FramePipelineConfig, scene: Option<&SceneProgram>) -> AnalyticTerms {
    let c = &cfg.cpu;
    // In f64: sums of huge costs must not wrap before the range check.
    let base_cpu = c.input_sampling.0 as f64 + c.clear.0 as f64 + c.swap.0 as f64 + c.non_render.mean();
    let base_front = cfg.gpu.clear.0 as f64 + cfg.gpu.swap.0 as f64 + 2.0 * cfg.gpu.command.0 as f64;
    let (cpu, front, geo, frag) = match (&cfg.workload, scene) {
        (WorkloadConfig::Fixed(f), _) => (
            base_cpu + f.cpu.mean(),
            base_front + f.gpu.mean() + cfg.gpu.command.0 as f64,
            0.0,
            0.0,
        ),
        (WorkloadConfig::Scene(_), Some(s)) => {
            let cpu: f64 = s.draws.iter().map(|d| d.cpu.0 as f64).sum();
            let front: f64 = s.draws.iter().map(|d| d.front.0 as f64).sum();
            let geo: f64 = s
                .draws
                .iter()
                .map(|d| s.meshes[d.mesh as usize].geometry_time.0 as f64)
                .sum();
            let frag: f64 = s
                .draws
                .iter()
                .map(|d| {
                    let g = &s.groups[d.group as usize];
                    s.meshes[d.mesh as usize].triangles as f64 * g.pixels.mean() * g.cost_per_pixel()
                })
                .sum();
            (base_cpu + cpu, base_front + front, geo, frag)
        }
        _ => (base_cpu, base_front, 0.0, 0.0),
    };
    let p = PS_PER_MS as f64;
    AnalyticTerms {
        cpu_ms: cpu / p,
        gpu_front_end_ms: front / p,
        geometry_ms: geo / p,
        fragment_ms: frag / p,
        gpu_max_ms: front.max(geo).max(frag) / p,
        gpu_sum_ms: (front + geo + frag) / p,
        frame_max_ms: cpu.max(front.max(geo).max(frag)) / p,
        frame_sum_ms: cpu.max(front + geo + frag) / p,
    }
}

/// The closed-form frame terms from the expected costs (no queueing),
/// milliseconds: what a frame costs each unit, and the two classic readings
/// of the frame time (the slowest unit; the GPU's units in series).
#[derive(Debug, Clone, Serialize)]
pub struct AnalyticTerms {
    /// CPU work per frame.
    pub cpu_ms: f64,
    /// GPU front end per frame.
    pub gpu_front_end_ms: f64,
    /// Geometry per frame.
    pub geometry_ms: f64,
    /// Fragment per frame.
    pub fragment_ms: f64,
    /// The slowest GPU unit.
    pub gpu_max_ms: f64,
    /// The GPU's units added up.
    pub gpu_sum_ms: f64,
    /// The slowest unit, CPU included.
    pub frame_max_ms: f64,
    /// The CPU or the GPU's sum, whichever is larger.
    pub frame_sum_ms: f64,
}

/// Time per state of each unit, milliseconds (state names as in the trace).
#[derive(Debug, Clone, Serialize)]
pub struct StatesMs {
    /// The CPU.
    pub cpu: BTreeMap<String, f64>,
    /// The GPU front end.
    pub gpu_front_end: BTreeMap<String, f64>,
    /// Geometry.
    pub geometry: BTreeMap<String, f64>,
    /// Fragment.
    pub fragment: BTreeMap<String, f64>,
    /// The GPU as a whole: busy when any unit is.
    pub gpu: BTreeMap<String, f64>,
}

/// Commands through the CPU -> GPU FIFO.
#[derive(Debug, Clone, Serialize)]
pub struct CommandCounts {
    /// Put into the FIFO by the CPU.
    pub issued: u64,
    /// Finished by the GPU front end.
    pub executed: u64,
    /// Most FIFO entries in use at once.
    pub fifo_max_used: u64,
}

/// `metrics` of a frame-pipeline summary (frames after the warm-up).
#[derive(Debug, Clone, Serialize)]
pub struct PipelineMetrics {
    /// Time between a frame's CPU start and the next frame's.
    pub frame_time_ms: Dist,
    /// Time between displayed frames (PresentMon's MsBetweenDisplayChange).
    pub display_interval_ms: Dist,
    /// Present to display.
    pub display_latency_ms: Dist,
    /// CPU start to display.
    pub until_displayed_ms: Dist,
    /// GPU time per frame (first to last GPU work).
    pub gpu_time_ms: Dist,
    /// CPU busy per frame.
    pub cpu_busy_ms: Dist,
    /// GPU busy per frame.
    pub gpu_busy_ms: Dist,
    /// Share of the run the CPU worked (its own work and system tasks).
    pub cpu_busy_fraction: f64,
    /// Share of the run the CPU waited (FIFO full, frames ahead).
    pub cpu_wait_fraction: f64,
    /// Share of the run any GPU unit was busy.
    pub gpu_busy_fraction: f64,
    /// Share of the run the GPU was idle.
    pub gpu_idle_fraction: f64,
    /// Display refreshes after the warm-up.
    pub refreshes: u64,
    /// Refreshes that showed the same image again.
    pub repeated_refreshes: u64,
    /// `repeated_refreshes / refreshes` (0 without refreshes).
    pub repeated_refresh_fraction: f64,
    /// Frames shown.
    pub displayed_frames: usize,
    /// Frames replaced before they were shown.
    pub dropped_frames: usize,
    /// Share of the run each unit was on the critical path (the time
    /// shortening its work would save; see `critical_path.rs`).
    pub bottleneck: BTreeMap<String, f64>,
    /// Time per state of each unit.
    pub states_ms: StatesMs,
    /// Commands through the FIFO.
    pub commands: CommandCounts,
    /// The closed-form terms beside the simulation.
    pub analytic: AnalyticTerms,
}

/// The summary of a frame-pipeline run (`summary.json`).
#[derive(Debug, Clone, Serialize)]
pub struct PipelineSummary {
    /// `"frame_pipeline"`.
    pub system: &'static str,
    /// The model's description.
    pub description: String,
    /// `triangle`, `draw` or `frame`.
    pub fidelity: super::config::Fidelity,
    /// Master seed.
    pub seed: u64,
    /// Frames completed (in the per-frame table).
    pub frames: usize,
    /// The same as `frames`.
    pub frames_simulated: usize,
    /// `run.frames`.
    pub frames_requested: u64,
    /// Frames left out of the statistics.
    pub warmup_frames: u64,
    /// Kernel events.
    pub events: EventCounts,
    /// Wall time: building the scene plus simulating.
    pub wall_seconds: f64,
    /// Wall time building the scene.
    pub build_seconds: f64,
    /// Wall time simulating.
    pub simulate_seconds: f64,
    /// Kernel events per wall second of simulation.
    pub events_per_second: f64,
    /// Simulated time at the end.
    pub simulated_seconds: f64,
    /// Why the run stopped (`model`: every frame done; `time_limit`,
    /// `event_limit`, `exhausted`).
    pub stopped_by: StopReason,
    /// The results.
    pub metrics: PipelineMetrics,
    /// Scene statistics per frame (absent for a fixed workload).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scene: Option<super::workload::SceneStats>,
}

fn states(names: &[&str], totals: &[u64]) -> BTreeMap<String, f64> {
    names.iter().zip(totals).map(|(n, t)| (n.to_string(), ms(*t))).collect()
}

fn summarize(
    m: &FramePipeline,
    stats: &RunStats,
    analytic: AnalyticTerms,
    scene: Option<super::workload::SceneStats>,
    build_seconds: f64,
) -> PipelineSummary {
    let end = stats.end_time;
    let elapsed = end.0.max(1) as f64;
    let warm = m.cfg.run.warmup_frames as usize;
    let rows = frame_rows(&m.records);
    let col = |i: usize| -> Dist { Dist::of_finite(&rows.iter().skip(warm).map(|r| r[i]).collect::<Vec<f64>>()) };
    let cpu = m.acct.cpu.totals_at(end);
    let front = m.acct.front.totals_at(end);
    let geom = m.acct.geom.totals_at(end);
    let frag = m.acct.frag.totals_at(end);
    let gpu = m.acct.gpu.totals_at(end);
    let bott = m.acct.path.totals_at(end, m.done());
    let displayed = m.records.iter().skip(warm).filter(|r| r.displayed.is_some()).count();
    let dropped = m.records.iter().skip(warm).filter(|r| r.dropped).count();
    let (mark_vblanks, mark_repeated, mark_time) = m.refresh_mark.unwrap_or((0, 0, crate::engine::Time::ZERO));
    let refreshes = if m.chain.mode() == crate::components::swap_chain::PresentMode::Immediate {
        end.0 / m.refresh.0 - mark_time.0 / m.refresh.0
    } else {
        m.vblanks - mark_vblanks
    };
    let repeated = m.repeated_refreshes - mark_repeated;
    let (issued, executed) = m.command_counts();
    PipelineSummary {
        system: "frame_pipeline",
        description: m.cfg.description.clone(),
        fidelity: m.cfg.fidelity,
        seed: m.cfg.run.seed,
        frames: m.records.len(),
        frames_simulated: m.records.len(),
        frames_requested: m.cfg.run.frames,
        warmup_frames: m.cfg.run.warmup_frames,
        events: EventCounts::of(stats),
        wall_seconds: build_seconds + stats.wall_seconds,
        build_seconds,
        simulate_seconds: stats.wall_seconds,
        events_per_second: events_per_second(stats),
        simulated_seconds: end.0 as f64 / 1e12,
        stopped_by: stats.stopped_by,
        metrics: PipelineMetrics {
            frame_time_ms: col(2),
            display_interval_ms: col(11),
            display_latency_ms: col(10),
            until_displayed_ms: col(9),
            gpu_time_ms: col(6),
            cpu_busy_ms: col(3),
            gpu_busy_ms: col(7),
            cpu_busy_fraction: (cpu[0] + cpu[1]) as f64 / elapsed,
            cpu_wait_fraction: (cpu[2] + cpu[3]) as f64 / elapsed,
            gpu_busy_fraction: gpu[0] as f64 / elapsed,
            gpu_idle_fraction: gpu[1] as f64 / elapsed,
            refreshes,
            repeated_refreshes: repeated,
            repeated_refresh_fraction: if refreshes > 0 {
                repeated as f64 / refreshes as f64
            } else {
                0.0
            },
            displayed_frames: displayed,
            dropped_frames: dropped,
            bottleneck: BOTTLENECKS
                .iter()
                .zip(bott)
                .map(|(n, t)| (n.to_string(), t as f64 / elapsed))
                .collect(),
            states_ms: StatesMs {
                cpu: states(&CPU_STATES, &cpu),
                gpu_front_end: states(&FRONT_STATES, &front),
                geometry: states(&GEOM_STATES, &geom),
                fragment: states(&FRAG_STATES, &frag),
                gpu: states(&["busy", "idle"], &gpu),
            },
            commands: CommandCounts {
                issued,
                executed,
                fifo_max_used: m.fifo.max_used(),
            },
            analytic,
        },
        scene,
    }
}

/// Runs a program built by the caller ([`super::workload::build_program`])
/// for `cfg.run.frames` frames, without validating, summarizing or
/// tracing: the kernel statistics and the per-frame records. For systems
/// that draw their own frames through the pipeline (the walkthrough draws
/// each frame's visible objects as a one-frame run); `cfg` must have been
/// checked with [`validate`] and its workload must be a scene.
pub fn simulate_program(
    cfg: FramePipelineConfig,
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
    Ok((stats, std::mem::take(&mut model.records)))
}
