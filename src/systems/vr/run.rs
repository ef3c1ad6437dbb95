//! Validating, running and summarizing a VR model; per-motion latencies
//! with their stages (they telescope: each is the gap between two instants
//! on the motion's own path, so they add up to its latency exactly).

use std::io::Write;

use serde_json::{Value, json};

use crate::engine::{Duration, Limits, RunStats, Scheduler, StopReason, run};
use crate::output::trace::TraceWriter;
use crate::stats::quantile::Summary;

use super::analytic::{Analytic, Bounds, analytic};
use super::config::{Scheme, VrConfig};
use super::latency::{MotionRecord, NAIVE_STAGES, WARP_HEAD_STAGES, WARP_OBJECT_STAGES};
use super::model::Vr;
use crate::systems::error::SystemError;

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
    /// JSON summary.
    pub summary: Value,
    /// The trace, when one was asked for: written, not yet closed.
    pub trace: Option<TraceWriter>,
}

fn bad(key: &str, message: impl Into<String>) -> SystemError {
    SystemError::Invalid {
        key: key.to_string(),
        message: message.into(),
    }
}

/// Checks values serde cannot.
pub fn validate(cfg: &VrConfig) -> Result<(), SystemError> {
    if cfg.system != "vr" {
        return Err(bad("system", format!("expected \"vr\", got {:?}", cfg.system)));
    }
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
    if cfg.run.events == 0 {
        return Err(bad("run.events", "must be at least 1 motion event"));
    }
    if cfg.run.events > crate::limits::MAX_INPUT_EVENTS {
        return Err(bad(
            "run.events",
            format!(
                "{} motion events is more than the limit of {}",
                cfg.run.events,
                crate::limits::MAX_INPUT_EVENTS
            ),
        ));
    }
    check_time_range(cfg.run.events, cfg.run.warmup, cfg.input.mean_interval)?;
    check_span(cfg)?;
    Ok(())
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
    validate(&cfg)?;
    let max_memory = cfg.run.max_memory.map_or(crate::limits::DEFAULT_MAX_MEMORY, |b| b.0);
    let (estimate, parts) = estimate_memory(&cfg);
    if estimate > max_memory {
        return Err(bad(
            "run.max_memory",
            crate::limits::over_memory_message(estimate, &parts, max_memory),
        ));
    }
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
        config: cfg,
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

fn dist(v: &[f64]) -> Value {
    let s = Summary::of(v);
    let n = |x: f64| s.stat(x);
    json!({"count": s.count, "min": n(s.min), "mean": n(s.mean), "p50": n(s.p50), "p99": n(s.p99), "max": n(s.max), "std": n(s.std)})
}

fn breakdown<'a>(names: &[&str], rows: impl Iterator<Item = &'a Vec<u64>>) -> Value {
    let mut sums = vec![0f64; names.len()];
    let mut n = 0usize;
    for r in rows {
        for (s, v) in sums.iter_mut().zip(r) {
            *s += *v as f64 / 1e9;
        }
        n += 1;
    }
    let n = n.max(1) as f64;
    Value::Object(
        names
            .iter()
            .zip(sums)
            .map(|(k, s)| (k.to_string(), json!(s / n)))
            .collect(),
    )
}

fn bounds(b: &Bounds) -> Value {
    json!({"best": b.best, "worst": b.worst, "phase_min": b.phase_min, "phase_max": b.phase_max, "phase_mean": b.phase_mean})
}

fn summarize(cfg: &VrConfig, m: &Vr, motions: &[MotionRecord], a: &Analytic, stats: &RunStats) -> Value {
    let head: Vec<f64> = motions.iter().filter_map(|r| r.head.as_deref().map(total_ms)).collect();
    let object: Vec<f64> = motions
        .iter()
        .filter_map(|r| r.object.as_deref().map(total_ms))
        .collect();
    let (hs, os): (&[&str], &[&str]) = match cfg.scheme {
        Scheme::Naive => (&NAIVE_STAGES, &NAIVE_STAGES),
        Scheme::Warp => (&WARP_HEAD_STAGES, &WARP_OBJECT_STAGES),
    };
    let by_kind: serde_json::Map<String, Value> = stats
        .kind_names
        .iter()
        .zip(&stats.by_kind)
        .map(|(n, c)| (n.to_string(), json!(c)))
        .collect();
    let mut metrics = json!({
        "motion_to_photon_ms": {"head": dist(&head), "object": dist(&object)},
        "analytic_latency_ms": {"head": bounds(&a.head), "object": bounds(&a.object)},
        "latency_breakdown_ms": {
            "head": breakdown(hs, motions.iter().filter_map(|r| r.head.as_ref())),
            "object": breakdown(os, motions.iter().filter_map(|r| r.object.as_ref())),
        },
        "display_frame_ms": a.frame_ms,
        "displayed_frames": m.swapped,
    });
    if cfg.scheme == Scheme::Warp {
        let ages: Vec<f64> = motions
            .iter()
            .filter_map(|r| r.app_age.map(|v| v as f64 / 1e9))
            .collect();
        metrics["app_frame_age_ms"] = dist(&ages);
        metrics["application_frames"] = json!(m.apps);
        metrics["simulation_steps"] = json!(m.sims);
    }
    json!({
        "system": "vr",
        "scheme": cfg.scheme,
        "description": cfg.description,
        "seed": cfg.run.seed,
        "input_events": motions.len(),
        "events": {"total": stats.events, "by_kind": by_kind},
        "wall_seconds": stats.wall_seconds,
        "simulate_seconds": stats.wall_seconds,
        "simulated_seconds": stats.end_time.0 as f64 / 1e12,
        "stopped_by": stats.stopped_by,
        "metrics": metrics,
    })
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
    use crate::output::table::{number, write_table};
    let rows = motion_rows(motions)
        .into_iter()
        .map(|r| r.iter().map(|&v| number(v)).collect());
    write_table(std::io::BufWriter::new(w), &COLUMNS, rows)
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

/// Refuses, before simulating, a run whose input events alone reach past
/// the clock's range ([`crate::limits::input_span_message`]).
fn check_time_range(events: u64, warmup: Duration, mean_interval: Duration) -> Result<(), SystemError> {
    match crate::limits::input_span_message(events, warmup.0, mean_interval.0) {
        Some(message) => Err(bad(crate::limits::INPUT_SPAN_KEYS, message)),
        None => Ok(()),
    }
}
