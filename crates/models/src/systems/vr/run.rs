//! Validating, running and summarizing a VR model; per-motion latencies
//! with their stages (they telescope: each is the gap between two instants
//! on the motion's own path, so they add up to its latency exactly).

use std::io::Write;

use std::collections::BTreeMap;

use serde::Serialize;

use crate::engine::{Duration, Limits, RunStats, Scheduler, StopReason, run};
use crate::output::trace::TraceWriter;
use crate::systems::summary::{Dist, EventCounts, mean_stages};

use super::analytic::{Analytic, Bounds, analytic};
use super::config::{Scheme, VrConfig};
use super::latency::{MotionRecord, NAIVE_STAGES, WARP_HEAD_STAGES, WARP_OBJECT_STAGES};
use super::model::Vr;
use crate::systems::checked::{Check, Checked};
use crate::systems::error::{SystemError, invalid as bad};

/// Everything a run produced.
#[derive(Debug)]
pub struct VrRun {
    /// The model as simulated.
    pub config: VrConfig,
    /// Kernel statistics.
    pub stats: RunStats,
    /// Final state (counts of frames; its records are moved to `motions`).
    pub model: Vr,
    /// Every motion.
    pub motions: Vec<MotionRecord>,
    /// Closed forms.
    pub analytic: Analytic,
    /// The summary, typed (`summary.json` is made from it where it is written).
    pub summary: VrSummary,
    /// The trace, when one was asked for: written, not yet closed.
    pub trace: Option<TraceWriter>,
}

impl Check for VrConfig {
    fn check(&self) -> Result<(), SystemError> {
        validate(self)
    }
}

/// Checks values serde cannot ([`Checked::new`] runs it).
pub fn validate(cfg: &VrConfig) -> Result<(), SystemError> {
    for (key, d) in [
        ("tracker.period", cfg.tracker.period),
        ("input.mean_interval", cfg.input.mean_interval),
        ("simulation.step", cfg.simulation.step),
        ("renderer.render", cfg.renderer.render),
    ] {
        if d.0 == 0 {
            return Err(bad(key, "must be greater than zero"));
        }
    }
    if cfg.scheme == Scheme::Warp && cfg.warp.render > cfg.pair() {
        return Err(bad(
            "warp.render",
            format!(
                "{:.3} ms does not fit in one stereo pair of the display ({:.3} ms): the warping renderer must keep the display rate",
                cfg.warp.render.as_ms_f64(),
                cfg.pair().as_ms_f64()
            ),
        ));
    }
    cfg.run.validate(&cfg.input, "motion event")?;
    check_span(cfg)?;
    cfg.run.check_events(&cfg.input, "motion event", &loops(cfg))?;
    Ok(())
}

/// The model's loops for the event estimate (the tracker is no event): the
/// naive loop (start, simulation end, render end, swap) at most a step, a
/// render and a stereo pair apart; or the simulation (start, end), the
/// application renderer (start, end) and the warping renderer (start, end,
/// swap, once per stereo pair).
fn loops(cfg: &VrConfig) -> Vec<crate::systems::tracked_input::Loop> {
    use crate::systems::tracked_input::Loop;
    let f = |d: Duration| d.0 as f64;
    match cfg.scheme {
        Scheme::Naive => vec![Loop {
            key: "simulation.step|renderer.render|display.field_rate".into(),
            what: "naive loop frames",
            interval_ps: f(cfg.simulation.step) + f(cfg.renderer.render) + f(cfg.pair()),
            events: 4.0,
        }],
        Scheme::Warp => vec![
            Loop {
                key: "simulation.step".into(),
                what: "simulation steps",
                interval_ps: f(cfg.simulation.step),
                events: 2.0,
            },
            Loop {
                key: "renderer.render".into(),
                what: "application frames",
                interval_ps: f(cfg.renderer.render),
                events: 2.0,
            },
            Loop {
                key: "display.field_rate".into(),
                what: "warped frames",
                interval_ps: f(cfg.pair()),
                events: 3.0,
            },
        ],
    }
}

/// Bytes per motion event: its record with the stages of two paths, and its
/// table row.
const BYTES_PER_EVENT: usize = std::mem::size_of::<MotionRecord>() + 2 * 12 * 8 + 4 * 8;

/// Estimates the memory a run needs from its inputs before simulating: the
/// motions' records. Frames are not kept (each is folded into the motions
/// it shows when it swaps), so the simulated span costs time, not memory.
/// Returns the bytes and a description.
pub fn estimate_memory(cfg: &VrConfig) -> (u64, String) {
    crate::limits::latency_estimate(cfg.run.events, BYTES_PER_EVENT, "motion events")
}

/// Validates, runs and summarizes. With a `trace` writer, the run's trace is
/// written into it as the run goes (a track per stage: simulation,
/// renderer, warping renderer, display; motions as instants) and handed back
/// in [`VrRun::trace`], to be closed by the caller.
pub fn run_vr(cfg: VrConfig, trace: Option<TraceWriter>) -> Result<VrRun, SystemError> {
    let cfg = Checked::new(cfg)?;
    let max_memory = cfg.run.memory_budget(estimate_memory(&cfg))?;
    let a = analytic(&cfg);
    let mut model = Vr::new(cfg.clone());

    model.max_memory = max_memory;
    model.trace = trace;
    let mut sched = Scheduler::new();
    model.start(&mut sched)?;
    let limits = Limits {
        until: None,
        max_events: cfg.run.max_events,
    };
    let stats = run(&mut model, &mut sched, limits)?;
    if stats.stopped_by != StopReason::Model || !model.done() {
        return Err(SystemError::Unfinished {
            at: stats.end_time,
            missing: "every motion event was visible".into(),
            state: model.describe(),
        });
    }
    let motions = std::mem::take(&mut model.follower.records);
    let summary = summarize(&cfg, &model, &motions, &a, &stats);
    let trace = model.finish_trace();
    Ok(VrRun {
        config: cfg.into_inner(),
        stats,
        model,
        motions,
        analytic: a,
        summary,
        trace,
    })
}

fn total_ms(g: &[u64]) -> f64 {
    g.iter().sum::<u64>() as f64 / 1e9
}

/// One value per motion kind.
#[derive(Debug, Clone, Serialize)]
pub struct Motions<T> {
    /// Head motion (camera pose).
    pub head: T,
    /// Object motion (through the simulation).
    pub object: T,
}

/// `metrics` of a VR summary.
#[derive(Debug, Clone, Serialize)]
pub struct VrMetrics {
    /// Simulated motion-to-photon latency of every motion.
    pub motion_to_photon_ms: Motions<Dist>,
    /// The closed forms and the bounds over all phases.
    pub analytic_latency_ms: Motions<Bounds>,
    /// Mean milliseconds per latency stage (stage names in
    /// [`crate::systems::LATENCY_STAGES`]); `null` when none was measured.
    pub latency_breakdown_ms: Motions<BTreeMap<String, Option<f64>>>,
    /// One stereo pair of the display (the swap period).
    pub display_frame_ms: f64,
    /// Frames that swapped.
    pub displayed_frames: usize,
    /// Warp only: age of the re-projected application frame at the swap
    /// that showed each head motion.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub app_frame_age_ms: Option<Dist>,
    /// Warp only: application frames started.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub application_frames: Option<usize>,
    /// Warp only: simulation steps started.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub simulation_steps: Option<usize>,
}

/// The summary of a VR run (`summary.json`).
#[derive(Debug, Clone, Serialize)]
pub struct VrSummary {
    /// `"vr"`.
    pub system: &'static str,
    /// `naive` or `warp`.
    pub scheme: Scheme,
    /// The model's description.
    pub description: String,
    /// Master seed.
    pub seed: u64,
    /// Motions followed.
    pub input_events: usize,
    /// Kernel events.
    pub events: EventCounts,
    /// Wall time of the run.
    pub wall_seconds: f64,
    /// Wall time of the simulation (the same: nothing is built first).
    pub simulate_seconds: f64,
    /// Simulated time at the end.
    pub simulated_seconds: f64,
    /// Why the run stopped (`model`: every motion shown).
    pub stopped_by: StopReason,
    /// The results.
    pub metrics: VrMetrics,
}

fn summarize(cfg: &VrConfig, m: &Vr, motions: &[MotionRecord], a: &Analytic, stats: &RunStats) -> VrSummary {
    let head: Vec<f64> = motions.iter().filter_map(|r| r.head.as_deref().map(total_ms)).collect();
    let object: Vec<f64> = motions
        .iter()
        .filter_map(|r| r.object.as_deref().map(total_ms))
        .collect();
    let (hs, os): (&[&str], &[&str]) = match cfg.scheme {
        Scheme::Naive => (&NAIVE_STAGES, &NAIVE_STAGES),
        Scheme::Warp => (&WARP_HEAD_STAGES, &WARP_OBJECT_STAGES),
    };
    let warp = cfg.scheme == Scheme::Warp;
    let ages: Vec<f64> = motions
        .iter()
        .filter_map(|r| r.app_age.map(|v| v as f64 / 1e9))
        .collect();
    VrSummary {
        system: "vr",
        scheme: cfg.scheme,
        description: cfg.description.clone(),
        seed: cfg.run.seed,
        input_events: motions.len(),
        events: EventCounts::of(stats),
        wall_seconds: stats.wall_seconds,
        simulate_seconds: stats.wall_seconds,
        simulated_seconds: stats.end_time.0 as f64 / 1e12,
        stopped_by: stats.stopped_by,
        metrics: VrMetrics {
            motion_to_photon_ms: Motions {
                head: Dist::of(&head),
                object: Dist::of(&object),
            },
            analytic_latency_ms: Motions {
                head: a.head,
                object: a.object,
            },
            latency_breakdown_ms: Motions {
                head: mean_stages(hs, motions.iter().filter_map(|r| r.head.as_ref())),
                object: mean_stages(os, motions.iter().filter_map(|r| r.object.as_ref())),
            },
            display_frame_ms: a.frame_ms,
            displayed_frames: m.swapped,
            app_frame_age_ms: warp.then(|| Dist::of(&ages)),
            application_frames: warp.then_some(m.apps),
            simulation_steps: warp.then_some(m.sims),
        },
    }
}

/// Columns of the per-motion table.
pub const COLUMNS: [&str; 4] = ["event", "input_ms", "head_latency_ms", "object_latency_ms"];

/// The per-motion table.
pub fn motion_rows(motions: &[MotionRecord]) -> Vec<Vec<f64>> {
    motions
        .iter()
        .enumerate()
        .map(|(i, r)| {
            vec![
                i as f64,
                r.time.as_ms_f64(),
                r.head.as_deref().map_or(f64::NAN, total_ms),
                r.object.as_deref().map_or(f64::NAN, total_ms),
            ]
        })
        .collect()
}

/// Writes the per-motion table as CSV.
pub fn write_motions_csv(motions: &[MotionRecord], w: &mut dyn Write) -> std::io::Result<()> {
    crate::output::table::write_number_table(std::io::BufWriter::new(w), &COLUMNS, &motion_rows(motions))
}

/// Refuses, before simulating, a run whose expected span (the motions and
/// what follows the last one until it is shown) reaches past the clock's
/// range ([`crate::limits::span_check`]), blaming the largest part's key.
fn check_span(cfg: &VrConfig) -> Result<(), SystemError> {
    let f = |d: Duration| d.0 as f64;
    let terms = [
        ("run.warmup", f(cfg.run.warmup)),
        (
            "input.mean_interval",
            cfg.run.events as f64 * f(cfg.input.mean_interval),
        ),
        ("tracker.period", f(cfg.tracker.period)),
        ("tracker.latency", f(cfg.tracker.latency)),
        ("simulation.step", 2.0 * f(cfg.simulation.step)),
        ("renderer.render", 2.0 * f(cfg.renderer.render)),
        ("display.field_rate", 2.0 * f(cfg.pair())),
        ("display.latency", f(cfg.display_latency())),
    ];
    match crate::limits::span_check(&terms) {
        Some((key, message)) => Err(bad(&key, message)),
        None => Ok(()),
    }
}
