//! The frame pipeline's summary (`summary.json`): the expected per-frame
//! terms of paper 000 §4.1 beside the simulated metrics, each unit's time
//! per state, the commands, the bottleneck shares along the critical path.

use std::collections::BTreeMap;

use serde::Serialize;
use serde_json::Value;

use crate::engine::{PS_PER_MS, RunStats, StopReason};

pub use super::analytic::AnalyticTerms;
use super::config::WorkloadConfig;
use super::model::FramePipeline;
use super::records::{metric, metric_rows};
use super::unit_states::{BOTTLENECKS, CPU_STATES, FRAG_STATES, FRONT_STATES, GEOM_STATES};
use crate::systems::summary::{Dist, EventCounts, events_per_second};

/// Replaces every -0.0 in `v` by 0.0 (an empty sum of floats is -0.0, and
/// "-0" in an output reads like a negative time).
pub(super) fn positive_zeros(v: &mut Value) {
    match v {
        Value::Number(n) if n.as_f64() == Some(0.0) && n.as_f64().is_some_and(|x| x.is_sign_negative()) => {
            *v = Value::from(0.0);
        }
        Value::Object(m) => m.values_mut().for_each(positive_zeros),
        Value::Array(a) => a.iter_mut().for_each(positive_zeros),
        _ => {}
    }
}

/// The summary as written (`summary.json`): its JSON with every -0.0 made
/// 0.0.
pub(super) fn as_json(summary: &PipelineSummary) -> Value {
    let mut v = crate::systems::summary::to_json(summary);
    positive_zeros(&mut v);
    v
}

pub(super) fn ms(ps: u64) -> f64 {
    ps as f64 / PS_PER_MS as f64
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
    /// Input sampled to display (`frames.csv`'s `MsInputLatency`).
    pub display_latency_ms: Dist,
    /// Present to display (PresentMon's `MsUntilDisplayed`).
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
    /// Where `immediate` flips tore the picture (left out when flips wait
    /// for a vertical blank).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tearing: Option<TearingStats>,
    /// What frame generation did (left out when it is off).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frame_generation: Option<GenerationStats>,
    /// The CPU's copies of the frame's uploads (scenes only; 0 without uploads):
    /// their bytes at their memory's rate, or, when copies share the bus
    /// with vertex fetch from AGP memory, as long as the bus's shares made
    /// them (paper 000 Table 4's copying times).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub copy_ms: Option<Dist>,
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

/// Tearing of a display whose flips do not wait for a vertical blank
/// (`metrics.tearing`, frames after the warm-up;
/// [`crate::components::tearing`]).
#[derive(Debug, Clone, Serialize)]
pub struct TearingStats {
    /// Frames (generated ones too) whose flip landed in the scan-out and
    /// tore the picture.
    pub torn_frames: usize,
    /// Torn frames per second, from the first frame shown after the warm-up
    /// to the end of the run.
    pub torn_per_second: f64,
    /// Where they tore: the fraction of the picture's height from the top.
    pub tear_line: Dist,
}

/// Frame generation (`metrics.frame_generation`, frames after the warm-up;
/// [`crate::components::frame_generation`]).
#[derive(Debug, Clone, Serialize)]
pub struct GenerationStats {
    /// Generated frames presented.
    pub generated_frames: usize,
    /// Of them, shown.
    pub generated_shown: usize,
    /// Of them, replaced by a newer frame before they were shown.
    pub generated_dropped: usize,
    /// Frames shown a second, rendered and generated, from the first frame
    /// shown after the warm-up to the end of the run.
    pub displayed_fps: f64,
    /// Rendered frames shown a second, over the same span.
    pub rendered_fps: f64,
    /// From a rendered frame's GPU end (its interpolation included) to its
    /// present: the hold-back.
    pub hold_back_ms: Dist,
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

pub(super) fn summarize(
    m: &FramePipeline,
    stats: &RunStats,
    analytic: AnalyticTerms,
    scene: Option<super::workload::SceneStats>,
    build_seconds: f64,
) -> PipelineSummary {
    let end = stats.end_time;
    let elapsed = end.0.max(1) as f64;
    let warm = m.cfg.run.warmup_frames as usize;
    let rows = metric_rows(&m.env.records);
    let col = |i: usize| -> Dist { Dist::of_finite(&rows.iter().skip(warm).map(|r| r[i]).collect::<Vec<f64>>()) };
    let cpu = m.acct.cpu.totals_at(end);
    let front = m.acct.front.totals_at(end);
    let geom = m.acct.geom.totals_at(end);
    let frag = m.acct.frag.totals_at(end);
    let gpu = m.acct.gpu.totals_at(end);
    let bott = m.acct.path.totals_at(end, m.done());
    let displayed = m
        .env
        .records
        .iter()
        .skip(warm)
        .filter(|r| r.displayed.is_some())
        .count();
    let dropped = m.env.records.iter().skip(warm).filter(|r| r.dropped).count();
    let (mark_vblanks, mark_repeated, mark_time) =
        m.display.refresh_mark().unwrap_or((0, 0, crate::engine::Time::ZERO));
    let refreshes = if m.display.mode() == crate::components::swap_chain::PresentMode::Immediate {
        end.0 / m.display.refresh().0 - mark_time.0 / m.display.refresh().0
    } else {
        m.display.vblanks() - mark_vblanks
    };
    let repeated = m.display.repeated_refreshes() - mark_repeated;
    let (issued, executed) = m.command_counts();
    PipelineSummary {
        system: "frame_pipeline",
        description: m.cfg.description.clone(),
        fidelity: m.cfg.fidelity,
        seed: m.cfg.run.seed,
        frames: m.env.records.len(),
        frames_simulated: m.env.records.len(),
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
            frame_time_ms: col(metric::FRAME_TIME),
            display_interval_ms: col(metric::DISPLAY_INTERVAL),
            display_latency_ms: col(metric::INPUT_LATENCY),
            until_displayed_ms: col(metric::UNTIL_DISPLAYED),
            gpu_time_ms: col(metric::GPU_TIME),
            cpu_busy_ms: col(metric::CPU_WORK),
            gpu_busy_ms: col(metric::GPU_BUSY),
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
            frame_generation: generation_stats(m, warm, displayed, end.0.saturating_sub(mark_time.0)),
            tearing: tearing_stats(m, warm, end.0.saturating_sub(mark_time.0)),
            copy_ms: copy_stats(m, warm),
            bottleneck: BOTTLENECKS
                .iter()
                .zip(bott)
                .map(|(n, t)| (n.to_string(), t as f64 / elapsed))
                .collect(),
            states_ms: StatesMs {
                // The pacing states only where `[pacing]` is on, the present
                // call only for a workload given frame by frame.
                cpu: {
                    let pacing = !m.cfg.pacing.is_off();
                    let frames = matches!(m.cfg.workload, WorkloadConfig::Frames(_));
                    let shown = |i: usize| i < 5 || (pacing && (i < 7 || i == 8)) || (frames && i == 7);
                    CPU_STATES
                        .iter()
                        .zip(cpu)
                        .enumerate()
                        .filter(|&(i, _)| shown(i))
                        .map(|(_, (n, t))| (n.to_string(), ms(t)))
                        .collect()
                },
                gpu_front_end: states(&FRONT_STATES, &front),
                geometry: states(&GEOM_STATES, &geom),
                fragment: states(&FRAG_STATES, &frag),
                gpu: states(&["busy", "idle"], &gpu),
            },
            commands: CommandCounts {
                issued,
                executed,
                fifo_max_used: m.env.links.commands.max_used(),
            },
            analytic,
        },
        scene,
    }
}

/// `metrics.frame_generation`: the generated frames after the warm-up
/// (`warm` frames), `displayed` rendered frames shown, over `span_ps`.
fn generation_stats(m: &FramePipeline, warm: usize, displayed: usize, span_ps: u64) -> Option<GenerationStats> {
    let g = m.display.generation()?;
    let after = |f: u64| f >= warm as u64;
    let span = span_ps as f64 / 1e12;
    let frames: Vec<_> = g.frames.iter().filter(|x| after(x.before)).collect();
    let shown = frames.iter().filter(|x| x.displayed.is_some()).count();
    let per_s = |n: usize| if span > 0.0 { n as f64 / span } else { 0.0 };
    let holds: Vec<f64> = g
        .hold_backs
        .iter()
        .filter(|(f, _)| after(*f))
        .map(|(_, d)| d.as_ms_f64())
        .collect();
    Some(GenerationStats {
        generated_frames: frames.len(),
        generated_shown: shown,
        generated_dropped: frames.iter().filter(|x| x.dropped).count(),
        displayed_fps: per_s(displayed + shown),
        rendered_fps: per_s(displayed),
        hold_back_ms: Dist::of_finite(&holds),
    })
}

/// `metrics.copy_ms`: the frames after the warm-up (`warm`); `None` for
/// a workload without a scene (0 for a scene without uploads).
fn copy_stats(m: &FramePipeline, warm: usize) -> Option<Dist> {
    let sc = m.env.scene.as_ref()?;
    let frames = m.env.records.iter().skip(warm);
    let ms: Vec<f64> = if sc.bus_shared {
        frames.map(|r| r.copy as f64 / PS_PER_MS as f64).collect()
    } else {
        let per_frame = sc.draws.iter().map(|d| d.copy.0 as f64).sum::<f64>() / PS_PER_MS as f64;
        frames.map(|_| per_frame).collect()
    };
    Some(Dist::of_finite(&ms))
}

/// `metrics.tearing`: every frame flipped after the warm-up (`warm`
/// frames), generated ones too, over `span_ps`; `None` when flips wait for
/// a vertical blank.
fn tearing_stats(m: &FramePipeline, warm: usize, span_ps: u64) -> Option<TearingStats> {
    m.cfg.display.scan_out()?;
    let generated = m.display.generation().map_or(&[][..], |g| g.frames);
    let lines: Vec<f64> = m
        .env
        .records
        .iter()
        .skip(warm)
        .filter_map(|r| r.tear_line)
        .chain(
            generated
                .iter()
                .filter(|g| g.before >= warm as u64)
                .filter_map(|g| g.tear_line),
        )
        .collect();
    let span = span_ps as f64 / 1e12;
    Some(TearingStats {
        torn_frames: lines.len(),
        torn_per_second: if span > 0.0 { lines.len() as f64 / span } else { 0.0 },
        tear_line: Dist::of_finite(&lines),
    })
}
