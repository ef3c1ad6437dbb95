//! Running the present system: validation, the run, its summary, per-frame
//! table, report, and its entry in the registry ([`PresentSystem`]).

use std::io::Write;
use std::path::Path;
use std::time::Instant;

use serde::Serialize;

use crate::components::swap_chain::PresentMode;
use crate::engine::{Limits, RunStats, Scheduler, StopReason, Time, run};
use crate::output::table::write_number_table;
use crate::output::text::{fixed, number};
use crate::output::trace::TraceWriter;
use crate::systems::checked::{Check, Checked};
use crate::systems::error::invalid;
use crate::systems::summary::{Dist, EventCounts};
use crate::systems::{Outcome, SystemError, SystemModel, outcome_basics, resolved_toml};

use super::config::PresentConfig;
use super::model::{FrameTimes, Present};

/// `system = "present"`.
pub struct PresentSystem;

impl SystemModel for PresentSystem {
    const NAME: &'static str = "present";
    type Config = PresentConfig;
    type Run = PresentRun;

    fn run(cfg: PresentConfig, _base_dir: &Path, trace: Option<TraceWriter>) -> Result<PresentRun, SystemError> {
        run_present(cfg, trace)
    }
}

/// A finished run.
#[derive(Debug)]
pub struct PresentRun {
    /// The summary, typed (`summary.json` is made from it where it is written).
    pub summary: PresentSummary,
    /// The model as run.
    pub config: PresentConfig,
    /// Every frame, in order.
    pub frames: Vec<FrameTimes>,
    trace: Option<TraceWriter>,
}

/// The mean interval between displayed frames (ms) for render times drawn
/// independently from `render` (paper 004 §4.2). With two images and vsync
/// a frame starts at a vertical blank and is shown at the first one after
/// it is done, so its interval is its render time `T` rounded up to whole
/// refreshes `R`: `E[max(1, ceil(T/R))] R = R (1 + sum_k>=1 P(T > kR))`,
/// exact. With three or more images the renderer goes on while a frame
/// waits, so in the long run the mean interval is the larger of `E[T]` and
/// `R` (exact for a constant render time); `immediate` shows each frame
/// when it is done: `E[T]`.
pub fn analytic_interval_ms(
    render: &crate::components::distribution::Dist<crate::engine::Duration>,
    refresh_ms: f64,
    buffers: u32,
    mode: PresentMode,
) -> f64 {
    let mean_ms = render.mean() / 1e9;
    match mode {
        PresentMode::Immediate => mean_ms,
        _ if buffers == 2 => {
            let r = refresh_ms * 1e9;
            let mut sum = 1.0;
            // The tail terms fall below 1e-12 for every light-tailed kind;
            // a heavy tail is cut at a million refreshes.
            for k in 1..=1_000_000u32 {
                let p = render.survival(f64::from(k) * r);
                if p < 1e-12 {
                    break;
                }
                sum += p;
            }
            sum * refresh_ms
        }
        _ => mean_ms.max(refresh_ms),
    }
}

impl Check for PresentConfig {
    fn check(&self) -> Result<(), SystemError> {
        validate(self)
    }
}

/// Checks what the simulator cannot run ([`Checked::new`] runs it): a render-time distribution with
/// bad parameters, the display ([`crate::components::swap_chain::DisplayConfig::check`]),
/// warm-up frames that leave none, and work that could not finish.
pub fn validate(cfg: &PresentConfig) -> Result<(), SystemError> {
    cfg.render
        .time
        .validate()
        .map_err(|e| invalid("render.time", e.to_string()))?;
    cfg.display.check().map_err(|(key, message)| invalid(key, message))?;
    if let Some((key, what)) = cfg.display.beyond_fixed_refresh() {
        return Err(invalid(
            key,
            format!(
                "the present system models a hardware flip at a fixed refresh only; {what} is modelled by \
                 the frame pipeline (`system = \"frame_pipeline\"`)"
            ),
        ));
    }
    if cfg.run.warmup_frames > cfg.run.frames {
        return Err(invalid(
            "run.warmup_frames",
            format!(
                "{} warm-up frames of {} leave none to measure",
                cfg.run.warmup_frames, cfg.run.frames
            ),
        ));
    }
    // Each frame takes at least its mean render time and, waiting for a
    // vertical blank, a refresh: the span must fit the clock, and its
    // vertical blanks the event budget.
    let render = cfg.render.time.mean();
    let refresh = cfg.display.refresh.period.0 as f64;
    let vsync = cfg.display.waits_for_vblank();
    let per_frame = if vsync { render.max(refresh) } else { render };
    let span = per_frame * cfg.run.frames as f64;
    if let Some((key, message)) = crate::limits::span_check(&[("render.time|run.frames", span)]) {
        return Err(invalid(&key, message));
    }
    let parts = [
        ("run.frames".to_string(), "frames".to_string(), cfg.run.frames as f64),
        (
            "display.refresh".to_string(),
            "vertical blanks".to_string(),
            if vsync { span / refresh } else { 0.0 },
        ),
    ];
    if let Some((key, message)) = crate::limits::events_check(&parts, cfg.run.max_events, "lower run.frames") {
        return Err(invalid(&key, message));
    }
    Ok(())
}

/// Validates and runs a model, writing its trace into `trace` if given.
pub fn run_present(cfg: PresentConfig, trace: Option<TraceWriter>) -> Result<PresentRun, SystemError> {
    let cfg = Checked::new(cfg)?;
    let mut model = Present::new(&cfg, trace);
    let mut sched = Scheduler::new();
    let start = Instant::now();
    model.start(&mut sched)?;
    let limits = Limits {
        until: None,
        max_events: cfg.run.max_events,
    };
    let mut stats = run(&mut model, &mut sched, limits)?;
    if !model.done() {
        return Err(SystemError::Unfinished {
            at: stats.end_time,
            missing: "every frame was shown or dropped".into(),
            state: model.describe(),
        });
    }
    stats.wall_seconds = start.elapsed().as_secs_f64();
    let done = model.finish(stats.end_time);
    let summary = summarize(&cfg, &done, &stats);
    Ok(PresentRun {
        summary,
        config: cfg.into_inner(),
        frames: done.frames,
        trace: done.trace,
    })
}

/// `metrics` of a present summary (frames after the warm-up).
#[derive(Debug, Clone, Serialize)]
pub struct PresentMetrics {
    /// Frames rendered and measured.
    pub frames: usize,
    /// Frames that reached the screen.
    pub displayed_frames: usize,
    /// Frames replaced in the mailbox before they were shown.
    pub dropped_frames: usize,
    /// Render time per frame.
    pub render_ms: Dist,
    /// Time between successive displayed frames.
    pub display_interval_ms: Dist,
    /// Render start to screen, per displayed frame.
    pub latency_ms: Dist,
    /// Present to screen, per displayed frame (the wait for the vertical
    /// blank and for the frames queued before it).
    pub present_to_display_ms: Dist,
    /// The closed form of the mean display interval,
    /// [`analytic_interval_ms`].
    pub analytic_interval_ms: f64,
    /// Vertical blanks over the whole run.
    pub vblanks: u64,
    /// Vertical blanks that showed the frame before again.
    pub repeated_refreshes: u64,
    /// Share of the run the renderer waited for a free image.
    pub renderer_wait_share: f64,
}

/// The summary of a present run (`summary.json`).
#[derive(Debug, Clone, Serialize)]
pub struct PresentSummary {
    /// `"present"`.
    pub system: &'static str,
    /// The model's description.
    pub description: String,
    /// Master seed.
    pub seed: u64,
    /// Kernel events.
    pub events: EventCounts,
    /// Wall time of the run.
    pub wall_seconds: f64,
    /// Wall time of the simulation (the same: nothing is built first).
    pub simulate_seconds: f64,
    /// Simulated time at the end.
    pub simulated_seconds: f64,
    /// Why the run stopped (`model`: every frame shown or dropped).
    pub stopped_by: StopReason,
    /// The results.
    pub metrics: PresentMetrics,
}

fn summarize(cfg: &PresentConfig, done: &super::model::Finished, stats: &RunStats) -> PresentSummary {
    let measured = &done.frames[(cfg.run.warmup_frames as usize).min(done.frames.len())..];
    let ms = |a: Time, b: Time| b.since(a).as_ms_f64();
    // The displayed frames, each with the time it reached the screen.
    let shown: Vec<(&FrameTimes, Time)> = measured.iter().filter_map(|f| f.shown.map(|t| (f, t))).collect();
    let of_shown =
        |f: &dyn Fn(&FrameTimes, Time) -> f64| Dist::of(&shown.iter().map(|&(fr, t)| f(fr, t)).collect::<Vec<_>>());
    let end = stats.end_time.0 as f64;
    PresentSummary {
        system: "present",
        description: cfg.description.clone(),
        seed: cfg.run.seed,
        events: EventCounts::of(stats),
        wall_seconds: stats.wall_seconds,
        simulate_seconds: stats.wall_seconds,
        simulated_seconds: end / 1e12,
        stopped_by: stats.stopped_by,
        metrics: PresentMetrics {
            frames: measured.len(),
            displayed_frames: shown.len(),
            dropped_frames: measured.len() - shown.len(),
            display_interval_ms: Dist::of(&shown.windows(2).map(|w| ms(w[0].1, w[1].1)).collect::<Vec<_>>()),
            latency_ms: of_shown(&|f, t| ms(f.start, t)),
            present_to_display_ms: of_shown(&|f, t| ms(f.present, t)),
            analytic_interval_ms: analytic_interval_ms(
                &cfg.render.time,
                cfg.display.refresh.period.as_ms_f64(),
                cfg.display.buffers,
                cfg.display.effective_mode(),
            ),
            render_ms: Dist::of(&measured.iter().map(|f| ms(f.start, f.present)).collect::<Vec<_>>()),
            vblanks: done.vblanks,
            repeated_refreshes: done.repeated,
            renderer_wait_share: if end > 0.0 { done.waited.0 as f64 / end } else { 0.0 },
        },
    }
}

/// Columns of the per-frame table.
pub const COLUMNS: [&str; 6] = ["Frame", "StartMs", "RenderMs", "PresentMs", "ShownMs", "LatencyMs"];

/// The per-frame table (NaN where a frame was not shown).
pub fn frame_rows(frames: &[FrameTimes]) -> Vec<Vec<f64>> {
    frames
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let shown = f.shown.map_or(f64::NAN, |t| t.as_ms_f64());
            vec![
                i as f64,
                f.start.as_ms_f64(),
                f.present.since(f.start).as_ms_f64(),
                f.present.as_ms_f64(),
                shown,
                shown - f.start.as_ms_f64(),
            ]
        })
        .collect()
}

/// Writes the human-readable report of the run of the model named `model`
/// whose summary is `s`.
pub fn write_report(s: &PresentSummary, model: &str, w: &mut dyn Write) -> std::io::Result<()> {
    let m = &s.metrics;
    writeln!(w, "{model} (present), {} frames, seed {}", m.frames, s.seed)?;
    writeln!(
        w,
        "  displayed {} dropped {}   repeated refreshes {} of {}",
        m.displayed_frames, m.dropped_frames, m.repeated_refreshes, m.vblanks
    )?;
    for (label, d) in [
        ("render time     ", &m.render_ms),
        ("display interval", &m.display_interval_ms),
        ("latency         ", &m.latency_ms),
    ] {
        writeln!(
            w,
            "  {label} mean {:>8} p99 {:>8} max {:>8} ms",
            fixed(number(d.mean), 3),
            fixed(number(d.p99), 3),
            fixed(number(d.max), 3)
        )?;
    }
    writeln!(
        w,
        "  closed form mean interval {} ms (paper 004 §4.2); renderer waited {}% of the run",
        fixed(m.analytic_interval_ms, 3),
        fixed(100.0 * m.renderer_wait_share, 1)
    )?;
    crate::output::text::events_line(w, s.events.total, s.wall_seconds, s.simulated_seconds)
}

impl Outcome for PresentRun {
    outcome_basics!(report = write_report);

    fn table(&self) -> (Vec<String>, Vec<Vec<f64>>) {
        (
            COLUMNS.iter().map(|s| s.to_string()).collect(),
            frame_rows(&self.frames),
        )
    }

    fn write_table(&self, w: &mut dyn Write) -> std::io::Result<()> {
        write_number_table(std::io::BufWriter::new(w), &COLUMNS, &frame_rows(&self.frames))
    }

    fn resolved_model(&self, _base_dir: &Path) -> String {
        resolved_toml(&self.config)
    }
}
