//! Validating, running and summarizing a VR model; per-motion latencies
//! with their stages (they telescope: each is the gap between two instants
//! on the motion's own path, so they add up to its latency exactly).

use std::io::Write;

use serde_json::{Value, json};

use crate::engine::{Duration, Limits, RunStats, Scheduler, StopReason, Time, run};
use crate::output::trace::TraceWriter;
use crate::stats::quantile::Summary;

use super::analytic::{Analytic, Bounds, analytic};
use super::config::{Scheme, VrConfig};
use super::model::{Vr, VrError};

/// Stages of a naive-loop motion (head and object alike).
pub const NAIVE_STAGES: [&str; 7] = [
    "input_sample",
    "sensor_transport",
    "simulation_wait",
    "simulation",
    "render",
    "swap_lock",
    "display",
];
/// Stages of a head motion in the warp scheme: the warping renderer reads
/// the newest pose at its frame start (`simulation_wait`, as a client's
/// frame start in the multi-frame-rate chain) and re-projects the newest
/// application frame (`composite_render`, as the fast client composites the
/// slow client's image). Names from [`crate::systems::LATENCY_STAGES`].
pub const WARP_HEAD_STAGES: [&str; 6] = [
    "input_sample",
    "sensor_transport",
    "simulation_wait",
    "composite_render",
    "swap_lock",
    "display",
];
/// Stages of an object motion in the warp scheme: after the simulation step,
/// the wait for the warping frame that takes its transforms is
/// `composite_wait` (as the fast client's wait for the slow client's image).
pub const WARP_OBJECT_STAGES: [&str; 8] = [
    "input_sample",
    "sensor_transport",
    "simulation_wait",
    "simulation",
    "composite_wait",
    "composite_render",
    "swap_lock",
    "display",
];

/// One motion's latencies (stage gaps, picoseconds).
#[derive(Debug, Clone)]
pub struct MotionRecord {
    /// When it happened.
    pub time: Time,
    /// Head motion stages.
    pub head: Option<Vec<u64>>,
    /// Object motion stages.
    pub object: Option<Vec<u64>>,
    /// Warp only: age of the re-projected application frame at the swap
    /// that showed the head motion (swap minus the application frame's start).
    pub app_age: Option<u64>,
}

/// Everything a run produced.
#[derive(Debug)]
pub struct VrRun {
    /// The model as simulated.
    pub config: VrConfig,
    /// Kernel statistics.
    pub stats: RunStats,
    /// Final state.
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

fn bad(key: &str, message: impl Into<String>) -> VrError {
    VrError::Invalid {
        key: key.to_string(),
        message: message.into(),
    }
}

/// Checks values serde cannot.
pub fn validate(cfg: &VrConfig) -> Result<(), VrError> {
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
    Ok(())
}

/// Bytes per motion event after the run: its time, its record with the
/// stages of two paths, and its table row.
const BYTES_PER_EVENT: usize = std::mem::size_of::<Time>() + std::mem::size_of::<MotionRecord>() + 2 * 12 * 8 + 4 * 8;

/// Estimates the memory a run needs from its inputs before simulating: the
/// expected simulated span (warm-up plus `run.events` x
/// `input.mean_interval`) over each loop's period, plus the motions'
/// records. Returns the bytes and a description.
pub fn estimate_memory(cfg: &VrConfig) -> (u64, String) {
    use crate::limits::add_bytes;
    use std::mem::size_of;
    // After the last motion the run goes on until it is shown: the tracker's
    // delay, a few loop periods and the display.
    let tail = [
        (1.0, cfg.tracker.period.0),
        (1.0, cfg.tracker.latency.0),
        (3.0, cfg.simulation.step.0),
        (3.0, cfg.renderer.render.0),
        (3.0, cfg.pair().0),
        (2.0, cfg.display_latency().0),
    ]
    .iter()
    .map(|&(k, x)| k * x as f64)
    .sum::<f64>();
    let span = cfg.run.warmup.0 as f64 + cfg.run.events as f64 * cfg.input.mean_interval.0 as f64 + tail;
    let frames = |interval: u64| crate::limits::records_over(span, interval);
    let (step, render) = (cfg.simulation.step.0, cfg.renderer.render.0);
    let mut total = 0u64;
    let desc = match cfg.scheme {
        Scheme::Naive => {
            let n = frames(step.saturating_add(render));
            add_bytes(&mut total, n, size_of::<super::model::LoopFrame>());
            format!("{n} loop frames")
        }
        Scheme::Warp => {
            let (sims, apps, warps) = (frames(step), frames(render), frames(cfg.pair().0));
            add_bytes(&mut total, sims, size_of::<super::model::SimStep>());
            add_bytes(&mut total, apps, size_of::<super::model::AppFrame>());
            add_bytes(&mut total, warps, size_of::<super::model::WarpFrame>());
            format!("{sims} simulation steps, {apps} application and {warps} warped frames")
        }
    };
    crate::limits::latency_estimate(
        total,
        cfg.run.events,
        BYTES_PER_EVENT,
        "motion events",
        span,
        "the loops",
        &desc,
    )
}

fn gaps(points: &[Time], display: u64) -> Vec<u64> {
    let mut g: Vec<u64> = points.windows(2).map(|w| w[1].0.saturating_sub(w[0].0)).collect();
    g.push(display);
    g
}

/// Follows every motion through the recorded frames.
pub fn follow(m: &Vr) -> Vec<MotionRecord> {
    let d = m.cfg.display_latency().0;
    let l = m.cfg.tracker.latency.0;
    let mut out = Vec::with_capacity(m.inputs.len());
    let (mut hi, mut oi) = (0usize, 0usize);
    for &t in &m.inputs {
        let j = m.capturing_sample(t);
        let sampled = m.sample_time(j);
        // The simulation scheduled this delivery with checked time, so it fits.
        let delivered = Time(sampled.0.saturating_add(l));
        let rec = match m.cfg.scheme {
            Scheme::Naive => {
                let frames = &m.frames[..m.swapped];
                while hi < frames.len() && frames[hi].sample < Some(j) {
                    hi += 1;
                }
                let stages = frames
                    .get(hi)
                    .map(|f| gaps(&[t, sampled, delivered, f.start, f.sim_end, f.render_end, f.swap], d));
                MotionRecord {
                    time: t,
                    head: stages.clone(),
                    object: stages,
                    app_age: None,
                }
            }
            Scheme::Warp => {
                let warps = &m.warps[..m.swapped];
                while hi < warps.len() && warps[hi].camera < Some(j) {
                    hi += 1;
                }
                let head = warps
                    .get(hi)
                    .map(|w| gaps(&[t, sampled, delivered, w.start, w.render_end, w.swap], d));
                let app_age = warps
                    .get(hi)
                    .and_then(|w| w.app.map(|a| w.swap.0.saturating_sub(m.apps[a].start.0)));
                while oi < warps.len() && warps[oi].sim.and_then(|s| m.sims[s].sample) < Some(j) {
                    oi += 1;
                }
                let object = warps.get(oi).and_then(|w| {
                    let s = &m.sims[w.sim?];
                    Some(gaps(
                        &[t, sampled, delivered, s.start, s.end, w.start, w.render_end, w.swap],
                        d,
                    ))
                });
                MotionRecord {
                    time: t,
                    head,
                    object,
                    app_age,
                }
            }
        };
        out.push(rec);
    }
    out
}

/// Validates, runs and summarizes.
pub fn run_vr(cfg: VrConfig) -> Result<VrRun, VrError> {
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
    let mut sched = Scheduler::new();
    model.start(&mut sched)?;
    let limits = Limits {
        until: None,
        max_events: cfg.run.max_events,
    };
    let stats = run(&mut model, &mut sched, limits)?;
    if stats.stopped_by != StopReason::Model || !model.done() {
        return Err(VrError::Unfinished {
            at: stats.end_time,
            state: model.describe(),
        });
    }
    let motions = follow(&model);
    let summary = summarize(&cfg, &model, &motions, &a, &stats);
    Ok(VrRun {
        config: cfg,
        stats,
        model,
        motions,
        analytic: a,
        summary,
        trace: None,
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
        metrics["application_frames"] = json!(m.apps.len());
        metrics["simulation_steps"] = json!(m.sims.len());
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

/// Writes a Perfetto trace: a track per stage (simulation, renderer, warping
/// renderer, display) and motion instants.
pub fn write_trace(r: &VrRun, t: &mut TraceWriter) {
    let m = &r.model;
    t.process(1, "VR pipeline");
    for (tid, name) in [
        (1, "tracker (motions)"),
        (2, "simulation"),
        (3, "renderer"),
        (4, "warping renderer"),
        (5, "display"),
    ] {
        t.track(1, tid, name);
    }
    for (i, at) in m.inputs.iter().enumerate() {
        t.instant(1, 1, &format!("motion {i}"), *at);
    }
    let field = m.cfg.display_latency();
    for (i, f) in m.frames.iter().take(m.swapped).enumerate() {
        t.span(1, 2, &format!("frame {i} simulation"), f.start, f.sim_end, None);
        t.span(1, 3, &format!("frame {i} render"), f.sim_end, f.render_end, None);
        t.span(1, 3, &format!("frame {i} swap lock"), f.render_end, f.swap, None);
    }
    for (i, s) in m.sims.iter().enumerate().filter(|(_, s)| s.end > s.start) {
        t.span(1, 2, &format!("step {i}"), s.start, s.end, None);
    }
    for (i, a) in m.apps.iter().enumerate().filter(|(_, a)| a.end > a.start) {
        t.span(1, 3, &format!("app frame {i}"), a.start, a.end, None);
    }
    for (i, f) in m.warps.iter().take(m.swapped).enumerate() {
        t.span(1, 4, &format!("warp {i}"), f.start, f.render_end, None);
    }
    let swaps: Vec<Time> = match m.cfg.scheme {
        Scheme::Naive => m.frames.iter().take(m.swapped).map(|f| f.swap).collect(),
        Scheme::Warp => m.warps.iter().take(m.swapped).map(|f| f.swap).collect(),
    };
    for (i, s) in swaps.iter().enumerate() {
        // The last image stays for two fields (saturating: a trace end, not a result).
        let end = swaps
            .get(i + 1)
            .copied()
            .unwrap_or_else(|| Time(s.0.saturating_add(field.0.saturating_mul(2))));
        t.span(1, 5, &format!("image {i}"), *s, end, None);
    }
}

/// Refuses, before simulating, a run whose input events alone reach past
/// the clock's range ([`crate::limits::input_span_message`]).
fn check_time_range(events: u64, warmup: Duration, mean_interval: Duration) -> Result<(), VrError> {
    match crate::limits::input_span_message(events, warmup.0, mean_interval.0) {
        Some(message) => Err(bad(crate::limits::INPUT_SPAN_KEYS, message)),
        None => Ok(()),
    }
}
