//! Validating, running and summarizing a multi-frame-rate model.

use std::io::Write;

use std::collections::BTreeMap;

use serde::Serialize;

use crate::engine::{Duration, Limits, RunStats, Scheduler, StopReason, Time, run};
use crate::output::trace::TraceWriter;
use crate::systems::summary::{Dist, EventCounts, events_per_second, mean_stages};

use super::analytic::{Analytic, Bounds, Terms, analytic};
use super::config::MultiRateConfig;
use super::latency::{CONV_STAGES, EventRecord, FAST_STAGES, SLOW_STAGES, event_rows, total_ms};
use super::migration::ArtifactCounts;
use super::model::MultiRate;
use crate::systems::checked::{Check, Checked};
use crate::systems::error::{SystemError, invalid as bad};

/// Everything a run produced.
#[derive(Debug)]
pub struct MultiRateRun {
    /// The model as simulated.
    pub config: MultiRateConfig,
    /// Kernel statistics.
    pub stats: RunStats,
    /// The final model state (counts of every client's frames; its
    /// records are moved to `events`).
    pub model: MultiRate,
    /// Every input event's fate.
    pub events: Vec<EventRecord>,
    /// Closed forms.
    pub analytic: Analytic,
    /// The summary, typed (`summary.json` is made from it where it is written).
    pub summary: MultiRateSummary,
    /// The trace, when one was asked for: written, not yet closed.
    pub trace: Option<TraceWriter>,
}

impl Check for MultiRateConfig {
    fn check(&self) -> Result<(), SystemError> {
        validate(self)
    }
}

/// Checks values serde cannot ([`Checked::new`] runs it).
pub fn validate(cfg: &MultiRateConfig) -> Result<(), SystemError> {
    let [w, h] = cfg.resolution;
    if w == 0 || h == 0 || w > 65536 || h > 65536 {
        return Err(bad(
            "resolution",
            format!("must be [width, height] with each between 1 and 65536 pixels, got [{w}, {h}]"),
        ));
    }
    if cfg.bytes_per_pixel == 0 || cfg.bytes_per_pixel > 64 {
        return Err(bad(
            "bytes_per_pixel",
            format!("must be between 1 and 64, got {}", cfg.bytes_per_pixel),
        ));
    }
    if cfg.tracker.period.0 == 0 {
        return Err(bad("tracker.period", "must be greater than zero"));
    }
    if cfg.input.mean_interval.0 == 0 {
        return Err(bad("input.mean_interval", "must be greater than zero"));
    }
    let t = Terms::of(cfg);
    if t.sc_frame().0 == 0 {
        return Err(bad(
            "slow_client.render",
            "SC's frame (render + read-back) must take some time",
        ));
    }
    if t.fc_frame().0 == 0 {
        return Err(bad(
            "fast_client.render",
            "FC's frame (upload + render) must take some time",
        ));
    }
    if t.transfer.0 == 0 {
        // Its rate (metrics.rates_hz.transfer) would be infinite, written
        // as null where a number is expected.
        let (key, fix) = match cfg.transfer.path {
            super::config::TransferPath::ZeroCopy => {
                ("zero_copy.lock".to_string(), "give the lock at least 1ps".to_string())
            }
            p => (
                format!("{}.bandwidth", p.name()),
                format!(
                    "lower it so that an image ({} bytes) takes at least 1ps",
                    cfg.frame_bytes()
                ),
            ),
        };
        return Err(bad(
            &key,
            format!(
                "an image over the {} path would take no time, so the link's rate (metrics.rates_hz.transfer) \
                 would be infinite; {fix}",
                cfg.transfer.path.name()
            ),
        ));
    }
    for (key, rate) in [
        ("slow_client.rate", &cfg.slow_client.rate),
        ("fast_client.rate", &cfg.fast_client.rate),
    ] {
        if let Some(r) = rate
            && r.period.0 == 0
        {
            return Err(bad(key, format!("{:?} has a zero period", r.text)));
        }
    }
    if cfg.conventional.enabled && t.conventional_frame.0 == 0 {
        // Blame the key the value came from: without `conventional.frame`
        // the conventional client renders for `slow_client.render`.
        return Err(match cfg.conventional.frame {
            Some(_) => bad("conventional.frame", "must be greater than zero"),
            None => bad(
                "slow_client.render",
                "must be greater than zero: the conventional client (conventional.enabled) renders each frame for slow_client.render when conventional.frame is absent",
            ),
        });
    }
    cfg.run.validate(&cfg.input, "input event")?;
    check_span(cfg)?;
    for (i, w) in cfg.migration.script.windows(2).enumerate() {
        if w[1].at < w[0].at {
            return Err(bad(
                &format!("migration.script.{}.at", i + 1),
                "actions must be in time order",
            ));
        }
    }
    let d = &cfg.deferred;
    if d.enabled {
        if !matches!(d.normal_bits, 24 | 48 | 96) {
            return Err(bad(
                "deferred.normal_bits",
                format!("must be 24, 48 or 96 (3 x 8, 16 or 32 bits), got {}", d.normal_bits),
            ));
        }
        if !(1..=64).contains(&d.index_bits) {
            return Err(bad(
                "deferred.index_bits",
                format!("must be between 1 and 64, got {}", d.index_bits),
            ));
        }
        if cfg.bytes_per_pixel != 8 {
            return Err(bad(
                "bytes_per_pixel",
                "deferred shading sets the bytes per pixel from its G-buffer; leave bytes_per_pixel at 8",
            ));
        }
    }
    Ok(())
}

/// Bytes per input event: its record with the stages of three paths, and
/// its table row.
const BYTES_PER_EVENT: usize = std::mem::size_of::<EventRecord>() + 3 * 12 * 8 + 8 * 8;

/// Estimates the memory a run needs from its inputs before simulating: the
/// input events' records. Frames are not kept (each is folded into the
/// events it shows when it ends), so the simulated span costs time, not
/// memory. Returns the bytes and a description.
pub fn estimate_memory(cfg: &MultiRateConfig) -> (u64, String) {
    crate::limits::latency_estimate(cfg.run.events, BYTES_PER_EVENT, "input events")
}

/// Validates, runs and summarizes a model. With a `trace` writer, the run's
/// trace is written into it as the run goes (one track per client, one for
/// the link, input events as instants on the master's track) and handed
/// back in [`MultiRateRun::trace`], to be closed by the caller.
pub fn run_multi_rate(cfg: MultiRateConfig, trace: Option<TraceWriter>) -> Result<MultiRateRun, SystemError> {
    let cfg = Checked::new(cfg)?;
    let max_memory = cfg.run.memory_budget(estimate_memory(&cfg))?;
    let mut model = MultiRate::new(&cfg);
    let a = analytic(&model.terms);
    model.max_memory = max_memory;
    model.trace = trace;
    if !cfg.migration.script.is_empty() {
        model.migration = Some(super::migration::Artifacts::new(&cfg.migration.script));
    }
    if let Some(last) = cfg.migration.script.iter().map(|s| s.at).max() {
        model.min_end = Time::ZERO
            .add(last, "migration.script")?
            .add(crate::engine::Duration::ms(1000), "migration.script")?;
    }
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
            missing: "every input event was visible".into(),
            state: model.describe(),
        });
    }
    let events = std::mem::take(&mut model.follower.records);
    let summary = summarize(&cfg, &model, &events, &a, &stats);
    let trace = model.trace.take();
    Ok(MultiRateRun {
        config: cfg.into_inner(),
        stats,
        model,
        events,
        analytic: a,
        summary,
        trace,
    })
}

/// One value per path: through FC, through SC's image, and through the
/// conventional client (when it runs).
#[derive(Debug, Clone, Serialize)]
pub struct Paths<T> {
    /// Input visible in FC's own rendering.
    pub fast: T,
    /// Input visible in SC's image, composited by FC.
    pub slow: T,
    /// Input visible through the conventional single client.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub conventional: Option<T>,
}

/// The model's per-frame terms, milliseconds (paper 003 §3's symbols).
#[derive(Debug, Clone, Serialize)]
pub struct TermsMs {
    /// Tracker sample period `P`.
    pub tracker_period: f64,
    /// Sample to clients `L`.
    pub sensor_latency: f64,
    /// SC's render `R_sc`.
    pub sc_render: f64,
    /// SC's read-back `T_read`.
    pub sc_readback: f64,
    /// SC's frame `R_sc + T_read`.
    pub sc_frame: f64,
    /// One image over the transfer path.
    pub transfer: f64,
    /// FC's upload of SC's image `T_draw`.
    pub fc_upload: f64,
    /// FC's render (plus deferred shading when on).
    pub fc_render: f64,
    /// FC's frame.
    pub fc_frame: f64,
    /// The conventional client's frame.
    pub conventional_frame: f64,
    /// The display's own latency.
    pub display: f64,
}

/// Rates, hertz.
#[derive(Debug, Clone, Serialize)]
pub struct RatesHz {
    /// SC's frames.
    pub slow_client: f64,
    /// FC's frames.
    pub fast_client: f64,
    /// Images the link can carry (a zero-time path is refused by
    /// [`validate`]).
    pub transfer: f64,
}

/// Frames each client finished (SC: started).
#[derive(Debug, Clone, Serialize)]
pub struct FrameCounts {
    /// SC frames started.
    pub slow_client: usize,
    /// FC frames finished.
    pub fast_client: usize,
    /// Conventional frames finished.
    pub conventional: usize,
}

/// The fate of SC's read-back buffers.
#[derive(Debug, Clone, Serialize)]
pub struct BufferCounts {
    /// Buffers that reached FC.
    pub sent: u64,
    /// Buffers replaced in the one-slot mailbox by a newer one before the
    /// link was free (latest wins).
    pub replaced_before_sending: u64,
}

/// `metrics` of a multi-frame-rate summary.
#[derive(Debug, Clone, Serialize)]
pub struct MultiRateMetrics {
    /// Simulated latency of every input event, per path.
    pub event_latency_ms: Paths<Dist>,
    /// The paper's closed forms and the bounds over all phases, per path.
    pub analytic_latency_ms: Paths<Bounds>,
    /// Mean milliseconds per latency stage, per path (stage names in
    /// [`crate::systems::LATENCY_STAGES`]); `null` when none was measured.
    pub latency_breakdown_ms: Paths<BTreeMap<String, Option<f64>>>,
    /// The per-frame terms.
    pub terms_ms: TermsMs,
    /// Frame and link rates.
    pub rates_hz: RatesHz,
    /// Frames per client.
    pub frames: FrameCounts,
    /// SC's buffers.
    pub buffers: BufferCounts,
    /// Whether the link carries SC's images as fast as SC makes them.
    pub link_keeps_up: bool,
    /// One sentence per path whose closed forms' assumptions fail, with the
    /// bound that holds instead (empty when all hold; each path's
    /// `analytic_latency_ms` says the same in `holds` and `bound_max`).
    pub closed_form_caveats: Vec<String>,
    /// Migration artifacts (when the model has a migration script).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub migration: Option<ArtifactCounts>,
}

/// The summary of a multi-frame-rate run (`summary.json`).
#[derive(Debug, Clone, Serialize)]
pub struct MultiRateSummary {
    /// `"multi_rate"`.
    pub system: &'static str,
    /// The model's description.
    pub description: String,
    /// Master seed.
    pub seed: u64,
    /// Input events followed.
    pub input_events: usize,
    /// Kernel events.
    pub events: EventCounts,
    /// Wall time of the run.
    pub wall_seconds: f64,
    /// Wall time of the simulation (the same: nothing is built first).
    pub simulate_seconds: f64,
    /// Kernel events per wall second.
    pub events_per_second: f64,
    /// Simulated time at the end.
    pub simulated_seconds: f64,
    /// Why the run stopped (`model`: every input shown on every path).
    pub stopped_by: StopReason,
    /// The transfer path from SC to FC.
    pub transfer_path: &'static str,
    /// Bytes of one image (or G-buffer) SC sends.
    pub frame_bytes: u64,
    /// FC's deferred-shading time per frame (0 when off).
    pub deferred_shading_ms: f64,
    /// The results.
    pub metrics: MultiRateMetrics,
}

fn summarize(
    cfg: &MultiRateConfig,
    m: &MultiRate,
    events: &[EventRecord],
    a: &Analytic,
    stats: &RunStats,
) -> MultiRateSummary {
    let latencies = |path: fn(&EventRecord) -> Option<&Vec<u64>>| -> Vec<f64> {
        events.iter().filter_map(|e| path(e).map(|g| total_ms(g))).collect()
    };
    fn fast(e: &EventRecord) -> Option<&Vec<u64>> {
        e.fast.as_ref().map(|f| &f.1)
    }
    fn slow(e: &EventRecord) -> Option<&Vec<u64>> {
        e.slow.as_ref().map(|s| &s.2)
    }
    fn conv(e: &EventRecord) -> Option<&Vec<u64>> {
        e.conventional.as_ref().map(|c| &c.1)
    }
    let conventional = cfg.conventional.enabled;
    let t = &m.terms;
    MultiRateSummary {
        system: "multi_rate",
        description: cfg.description.clone(),
        seed: cfg.run.seed,
        input_events: events.len(),
        events: EventCounts::of(stats),
        wall_seconds: stats.wall_seconds,
        simulate_seconds: stats.wall_seconds,
        events_per_second: events_per_second(stats),
        simulated_seconds: stats.end_time.0 as f64 / 1e12,
        stopped_by: stats.stopped_by,
        transfer_path: cfg.transfer.path.name(),
        frame_bytes: cfg.frame_bytes(),
        deferred_shading_ms: cfg.deferred_shading().as_ms_f64(),
        metrics: MultiRateMetrics {
            event_latency_ms: Paths {
                fast: Dist::of(&latencies(fast)),
                slow: Dist::of(&latencies(slow)),
                conventional: conventional.then(|| Dist::of(&latencies(conv))),
            },
            analytic_latency_ms: Paths {
                fast: a.fast,
                slow: a.slow,
                conventional: conventional.then_some(a.conventional),
            },
            latency_breakdown_ms: Paths {
                fast: mean_stages(&FAST_STAGES, events.iter().filter_map(fast)),
                slow: mean_stages(&SLOW_STAGES, events.iter().filter_map(slow)),
                conventional: conventional.then(|| mean_stages(&CONV_STAGES, events.iter().filter_map(conv))),
            },
            terms_ms: TermsMs {
                tracker_period: t.tracker_period.as_ms_f64(),
                sensor_latency: t.sensor_latency.as_ms_f64(),
                sc_render: t.sc_render.as_ms_f64(),
                sc_readback: t.sc_readback.as_ms_f64(),
                sc_frame: t.sc_frame().as_ms_f64(),
                transfer: t.transfer.as_ms_f64(),
                fc_upload: t.fc_upload.as_ms_f64(),
                fc_render: t.fc_render.as_ms_f64(),
                fc_frame: t.fc_frame().as_ms_f64(),
                conventional_frame: t.conventional_frame.as_ms_f64(),
                display: t.display.as_ms_f64(),
            },
            rates_hz: RatesHz {
                slow_client: 1e3 / t.sc_interval().as_ms_f64(),
                fast_client: 1e3 / t.fc_interval().as_ms_f64(),
                // Positive: a zero-time path is refused by `validate`.
                transfer: 1e3 / t.transfer.as_ms_f64(),
            },
            frames: FrameCounts {
                slow_client: m.sc_frames,
                fast_client: m.fc_done,
                conventional: m.conv_done,
            },
            buffers: BufferCounts {
                sent: m.sent,
                replaced_before_sending: m.replaced,
            },
            link_keeps_up: a.link_keeps_up,
            closed_form_caveats: a.caveats(t),
            migration: m.migration.as_ref().map(|x| x.counts()),
        },
    }
}

/// Writes the per-event table as CSV.
pub fn write_events_csv(events: &[EventRecord], w: &mut dyn Write) -> std::io::Result<()> {
    crate::output::table::write_number_table(
        std::io::BufWriter::new(w),
        &super::latency::COLUMNS,
        &event_rows(events),
    )
}

/// Refuses, before simulating, a run whose expected span (the input events
/// and what follows the last one until every path shows it) reaches past
/// the clock's range ([`crate::limits::span_check`]), blaming the largest
/// part's key; then one whose clients' frames certainly need more events
/// than `run.max_events` or its default (`RunConfig::check_events`).
fn check_span(cfg: &MultiRateConfig) -> Result<(), SystemError> {
    let t = Terms::of(cfg);
    let f = |d: Duration| d.0 as f64;
    // Which key makes a client's interval: its rate cap or its frame.
    let interval_key = |period: Option<Duration>, parts: [(&'static str, Duration); 2], rate_key: &'static str| {
        if period.is_some_and(|p| p.0 > parts[0].1.0.saturating_add(parts[1].1.0)) {
            rate_key
        } else if parts[0].1 >= parts[1].1 {
            parts[0].0
        } else {
            parts[1].0
        }
    };
    let sc_key = interval_key(
        t.sc_period,
        [
            ("slow_client.render", t.sc_render),
            ("slow_client.readback", t.sc_readback),
        ],
        "slow_client.rate",
    );
    let fc_key = interval_key(
        t.fc_period,
        [("fast_client.render", t.fc_render), ("fast_client.upload", t.fc_upload)],
        "fast_client.rate",
    );
    let conv_key = if cfg.conventional.frame.is_some() {
        "conventional.frame"
    } else {
        "slow_client.render"
    };
    let last_action = cfg.migration.script.iter().map(|s| s.at.0).max().unwrap_or(0);
    let mut terms = vec![
        ("run.warmup", f(cfg.run.warmup)),
        (
            "input.mean_interval",
            cfg.run.events as f64 * f(cfg.input.mean_interval),
        ),
        ("migration.script", last_action as f64),
        ("tracker.period", f(t.tracker_period)),
        ("tracker.latency", f(t.sensor_latency)),
        (sc_key, 2.0 * f(t.sc_interval())),
        (fc_key, 2.0 * f(t.fc_interval())),
        ("transfer.path", f(t.transfer)),
        ("display.latency", f(t.display)),
    ];
    if cfg.conventional.enabled {
        terms.push((conv_key, 2.0 * f(t.conventional_frame)));
    }
    if let Some((key, message)) = crate::limits::span_check(&terms) {
        return Err(bad(&key, message));
    }
    // The loops for the event estimate (the tracker is no event): SC
    // (start, render end, read-back end), FC (start, upload end, end) and
    // the conventional client (start, end), each at its frame interval.
    use crate::systems::tracked_input::Loop;
    let mut loops = vec![
        Loop {
            key: sc_key.into(),
            what: "slow-client frames",
            interval_ps: f(t.sc_interval()),
            events: 3.0,
        },
        Loop {
            key: fc_key.into(),
            what: "fast-client frames",
            interval_ps: f(t.fc_interval()),
            events: 3.0,
        },
    ];
    if cfg.conventional.enabled {
        loops.push(Loop {
            key: conv_key.into(),
            what: "conventional-client frames",
            interval_ps: f(t.conventional_frame),
            events: 2.0,
        });
    }
    cfg.run.check_events(&cfg.input, "input event", &loops)
}
