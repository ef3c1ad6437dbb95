//! Replaying a real frame capture through the frame pipeline (issue 26):
//! PresentMon's measured CPU and GPU times, frame by frame, run through the
//! CPU -> command FIFO -> GPU -> swap chain -> display model, and what the
//! model predicts set against what the capture measured.
//!
//! How a captured frame becomes the model's (`kind = "frames"`, see
//! [`FramesWorkload`]): the CPU works `MsCPUBusy`; the GPU work
//! (`MsGPUBusy`, one command after the frame's clear) is submitted after
//! `MsGPULatency` of it (the GPU cannot start earlier than it did; without
//! that column, at the present), and the GPU does not finish the frame
//! before `MsGPULatency + MsGPUTime` after its CPU start (it waited for
//! the CPU's later submissions); the CPU then presents, and the next frame
//! begins `MsCPUWait` later (the present call) or when the model lets it
//! (frames in flight), whichever is later: the two waits overlap as they
//! do in a real present call. So a what-if that frees the pipeline cannot
//! make the CPU faster than it was measured, and one that holds it longer
//! does not count the captured wait twice. The refresh period is fitted to
//! the displayed frames' screen times (least squares over their refresh
//! counts), and the simulation starts at a vertical blank of that grid, at
//! or before the first frame's CPU start, so the model's vertical blanks
//! fall where the capture's did. With tearing (`immediate`) the screen
//! times lie off any grid: the refresh is then models/replay.toml's 60 Hz
//! and the simulation starts at the first CPU start. What a capture does
//! not record (swap-chain images, frames in flight, the refresh, variable
//! refresh) can be given as assumptions (`--assume`), which patch the
//! as-captured model before any what-if. rendersim's own `frames.csv`
//! replays exactly (`tests/it/replay_round_trip.rs`).
//!
//! Present modes: the hardware flips (`Hardware: Legacy Flip`,
//! `Hardware: Independent Flip`, ...) are `fifo` at a sync interval of 1 or
//! more, `immediate` at 0 with tearing allowed, and `mailbox` at 0 without.
//! `Composed: ...` modes are the same with `display.composition =
//! "composed"` and the compositor's wake and refreshes inferred from the
//! swap chain's frames (`capture::display::infer_compositor`); a composed present without a sync interval (-1, a blit) is
//! `fifo`.

pub mod compare;
pub mod config;
pub mod display_stats;
pub mod images;
pub mod refresh;
pub mod report;
pub mod results;
mod setup;
pub mod system;
pub mod validation;

pub use refresh::fit_phase;
pub use results::{
    Agreement, ErrorStats, InputLatency, RefreshFrom, Replay, ReplayErrors, ReplayFrame, ReplaySummary, ReplayedFrames,
    WhatIf,
};

use std::path::Path;

use self::display_stats::{DisplayStats, FrameTimes};
use self::setup::{Setup, fill_frames, frames_into, model_of, setup};
use crate::capture::presentmon::{Capture, CaptureError};
use crate::components::swap_chain::Composition;
use crate::config::{ModelSource, invalid};
use crate::systems::error::SystemError;
use crate::systems::frame_pipeline::config::{FramesWorkload, WorkloadConfig};
use crate::systems::frame_pipeline::records::{FrameRecord, GeneratedRecord};
use crate::systems::frame_pipeline::{FramePipelineConfig, run_pipeline};

/// The replay's base model (the frame pipeline with no costs of its own).
pub const REPLAY_MODEL: &str = include_str!("../../../models/replay.toml");

/// Errors of a replay.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The capture cannot be read or replayed.
    #[error(transparent)]
    Capture(#[from] CaptureError),
    /// The model (base plus `--set`) is wrong.
    #[error(transparent)]
    Config(#[from] crate::config::ConfigError),
    /// An assumption (`--assume`) is wrong.
    #[error("{0}")]
    Assume(crate::config::ConfigError),
    /// The simulation failed.
    #[error(transparent)]
    System(#[from] SystemError),
}

/// What to replay.
#[derive(Debug, Clone, Default)]
pub struct ReplayOptions {
    /// The process whose swap chain to replay (its swap chain with most frames).
    pub app: Option<String>,
    /// The swap chain's address.
    pub swap_chain: Option<String>,
    /// The what-if: `--set` patches on the replay's model. The capture is
    /// replayed as captured and, when there are patches, again with them.
    pub sets: Vec<String>,
    /// What the capture does not say: `--assume` patches on the
    /// as-captured model (swap-chain images, frames in flight, the refresh),
    /// applied before any what-if's.
    pub assume: Vec<String>,
    /// Whether the patches come from a model file's `[whatif]` and
    /// `[assume]` tables (errors name them so) rather than the command
    /// line's `--set` and `--assume`.
    pub from_tables: bool,
}

impl ReplayOptions {
    /// What errors call the what-if's and the assumptions' patches.
    fn option_names(&self) -> (&'static str, &'static str) {
        if self.from_tables {
            ("[whatif]", "[assume]")
        } else {
            ("--set", "--assume")
        }
    }
}

/// One simulation of the set-up frames with `sets` patched on.
struct Simulated {
    /// The frames, measured and predicted.
    frames: Vec<ReplayFrame>,
    /// The model as run (its per-frame work left out).
    model: FramePipelineConfig,
    /// The run's records.
    records: Vec<FrameRecord>,
    /// The frames frame generation made.
    generated: Vec<GeneratedRecord>,
    /// Frame generation's hold-backs of the rendered frames.
    hold_backs: Vec<(u64, crate::engine::Duration)>,
    /// The simulation's wall time, s.
    seconds: f64,
    /// The refreshes that repeated an image, as the display counted them.
    repeated_refreshes: u64,
    /// Torn frames per second, when flips do not wait for a vertical blank.
    torn_per_second: Option<f64>,
    /// The capture's time of the run's time zero, ms.
    origin: f64,
}

impl Simulated {
    /// The display figures of the predicted frames. A fixed refresh counts
    /// repeats on its grid, as the measured figures do; a variable-refresh
    /// panel has none, so its own count of repeated scan-outs stands.
    fn stats(&self) -> DisplayStats {
        let times: Vec<FrameTimes> = self.frames.iter().map(ReplayFrame::predicted_times).collect();
        let generated: Vec<f64> = self
            .generated
            .iter()
            .filter_map(|g| g.displayed)
            .map(|t| self.origin + t.as_ms_f64())
            .collect();
        let mut st = DisplayStats::with_generated(&times, &generated, self.model.display.shortest_period().as_ms_f64());
        if self.model.display.vrr.is_some() {
            st.repeated_refreshes = self.repeated_refreshes;
        }
        st.torn_per_second = self.torn_per_second;
        st
    }
}

/// The frame-pipeline model a replay of the capture at `path` runs (as
/// captured with `opts.assume`, then `opts.sets`): what `rendersim timeline`
/// draws for a `system = "replay"` model. Its times start at the vertical
/// blank before the capture's first CPU start.
pub fn replay_model(path: &Path, opts: &ReplayOptions) -> Result<(ModelSource, toml::Table), ReplayError> {
    let capture = Capture::read(path)?;
    let s = setup(&capture, opts)?;
    let (src, mut table) = model_of(&s, &opts.sets)?;
    frames_into(&mut table, &s.frames);
    Ok((src, table))
}

/// One simulation of the set-up frames with `sets` patched on.
fn simulate(s: &Setup, sets: &[String]) -> Result<Simulated, ReplayError> {
    let (src, table) = model_of(s, sets)?;
    let mut cfg = FramePipelineConfig::from_table(&table, &src)?;
    if let WorkloadConfig::Frames(w) = &mut cfg.workload {
        fill_frames(w, &s.frames);
    }
    let sim = std::time::Instant::now();
    // A value the model cannot use is blamed on the option that gave it.
    let run = run_pipeline(cfg, &src.base_dir, None).map_err(|e| match e {
        // Without what-if patches the model is the assumptions' (the
        // as-captured replay runs first, so theirs surface there).
        SystemError::Invalid { key, message } if sets.is_empty() => {
            ReplayError::Assume(invalid(&src, &key, message, None))
        }
        SystemError::Invalid { key, message } => ReplayError::Config(invalid(&src, &key, message, None)),
        e => ReplayError::System(e),
    })?;
    let seconds = sim.elapsed().as_secs_f64();
    let origin = s.origin();
    let at = |t: crate::engine::Time| origin + t.as_ms_f64();
    let mut frames = Vec::with_capacity(s.rows.len());
    let mut last_shown: Option<f64> = None;
    // Frames generated between the rendered ones (frame generation) change
    // the display too.
    let mut generated_shown = run.generated.iter().filter_map(|g| g.displayed).map(at).peekable();
    for (p, r) in s.rows.iter().zip(&run.records) {
        let predicted_present = at(r.present);
        let shown = r.displayed.map(at);
        if let Some(sh) = shown {
            while let Some(g) = generated_shown.next_if(|&g| g < sh) {
                last_shown = Some(last_shown.map_or(g, |l| l.max(g)));
            }
        }
        let between = match (shown, last_shown) {
            (Some(s), Some(l)) => Some(s - l),
            _ => None,
        };
        if shown.is_some() {
            last_shown = shown;
        }
        frames.push(ReplayFrame {
            line: p.line,
            cpu_start: (p.cpu_start, at(r.begun)),
            present: p.present,
            predicted_present,
            displayed: p.displayed(),
            predicted_displayed: shown.is_some(),
            until_displayed: (p.until_displayed, shown.map(|s| s - predicted_present)),
            between_display_change: (p.between_display_change.filter(|_| p.displayed()), between),
            render_complete: (p.render_complete, r.gpu_end.map(|g| at(g) - predicted_present)),
        });
    }
    let mut model = run.config;
    if let WorkloadConfig::Frames(w) = &mut model.workload {
        *w = FramesWorkload {
            cpu: vec![],
            submit: vec![],
            gpu: vec![],
            present: vec![],
            gpu_end: vec![],
            start: w.start,
        };
    }
    let repeated_refreshes = run.results.metrics.repeated_refreshes;
    let torn_per_second = run.results.metrics.tearing.as_ref().map(|t| t.torn_per_second);
    Ok(Simulated {
        frames,
        model,
        records: run.records,
        generated: run.generated,
        hold_backs: run.hold_backs,
        origin,
        seconds,
        repeated_refreshes,
        torn_per_second,
    })
}

/// Replays the capture at `path`.
pub fn replay(path: &Path, opts: &ReplayOptions) -> Result<Replay, ReplayError> {
    let wall = std::time::Instant::now();
    let capture = Capture::read(path)?;
    replay_capture(&capture, opts, wall)
}

/// Replays a capture already read; `wall` is when the replay began (its
/// reading included). For a capture that is not a file
/// ([`crate::bench::replay`] replays one made in memory).
pub fn replay_capture(
    capture: &Capture,
    opts: &ReplayOptions,
    wall: std::time::Instant,
) -> Result<Replay, ReplayError> {
    let mut s = setup(capture, opts)?;
    let captured = simulate(&s, &[])?;
    let (captured, images) = images::infer_images(&mut s, &opts.assume, captured)?;
    let whatif = if opts.sets.is_empty() {
        None
    } else {
        Some(simulate(&s, &opts.sets)?)
    };
    let simulate_seconds = captured.seconds + whatif.as_ref().map_or(0.0, |w| w.seconds);
    let frames = &captured.frames;
    // Fates agree over the frames whose fate the capture knows.
    let known: Vec<&ReplayFrame> = s
        .rows
        .iter()
        .zip(frames)
        .filter(|(p, _)| p.fate_known)
        .map(|(_, f)| f)
        .collect();
    let agree = known.iter().filter(|f| f.displayed == f.predicted_displayed).count();
    let swap = |(m, p): (Option<f64>, Option<f64>)| (p, m);
    let measured: Vec<FrameTimes> = frames.iter().map(ReplayFrame::measured_times).collect();
    let as_captured = captured.stats();
    let summary = ReplaySummary {
        capture: capture.file.clone(),
        columns: capture.columns,
        frames: frames.len(),
        not_rendered: capture.not_rendered(),
        application: s.rows[0].application.to_string(),
        swapchain: s.rows[0].swap_chain.to_string(),
        present_mode: s.common.present_mode.to_string(),
        model_present_mode: s.mode.to_string(),
        model_composition: if s.composed {
            Composition::Composed
        } else {
            Composition::Independent
        },
        refresh_hz: 1000.0 / s.period,
        refresh_from: s.refresh_from,
        images,
        display: s.display.clone(),
        capture_notes: capture.notes.clone(),
        capture_metadata: capture.metadata.clone(),
        assume: opts.assume.clone(),
        measured_displayed: frames.iter().filter(|f| f.displayed).count(),
        predicted_displayed: frames.iter().filter(|f| f.predicted_displayed).count(),
        agreement: Agreement {
            displayed: agree as f64 / known.len().max(1) as f64,
        },
        error_ms: ReplayErrors {
            until_displayed: ErrorStats::of(frames.iter().map(|f| swap(f.until_displayed))),
            between_display_change: ErrorStats::of(frames.iter().map(|f| swap(f.between_display_change))),
            render_complete: ErrorStats::of(frames.iter().map(|f| swap(f.render_complete))),
            present: ErrorStats::of(frames.iter().map(|f| (Some(f.predicted_present), Some(f.present)))),
        },
        measured: DisplayStats::of(&measured, s.period),
        measured_input_latency: results::InputLatency::of(&s.rows),
        whatif: WhatIf {
            sets: opts.sets.clone(),
            stats: whatif.as_ref().map_or_else(|| as_captured.clone(), Simulated::stats),
        },
        as_captured,
        compare: None,
        simulate_seconds,
        wall_seconds: wall.elapsed().as_secs_f64(),
    };
    let replayed = |records: Vec<FrameRecord>, generated: Vec<GeneratedRecord>, hold_backs| ReplayedFrames {
        records,
        generated,
        hold_backs,
        chain: s.chain.clone(),
        origin_ps: s.origin_ps,
    };
    let (whatif_frames, whatif_model, whatif_replayed) = match whatif {
        Some(w) => (
            Some(w.frames),
            Some(w.model),
            Some(replayed(w.records, w.generated, w.hold_backs)),
        ),
        None => (None, None, None),
    };
    Ok(Replay {
        summary,
        frames: captured.frames,
        model: captured.model,
        whatif_frames,
        whatif_model,
        replayed: replayed(captured.records, captured.generated, captured.hold_backs),
        whatif_replayed,
        unknown_fates: s.rows.iter().filter(|p| !p.fate_known).map(|p| p.line).collect(),
    })
}

/// The per-frame table's columns: measured and predicted as captured, then,
/// with a what-if, its present, shown state and time until displayed.
pub const FRAME_COLUMNS: [&str; 12] = [
    "Line",
    "PresentTime",
    "PredictedPresentTime",
    "Displayed",
    "PredictedDisplayed",
    "MsUntilDisplayed",
    "PredictedMsUntilDisplayed",
    "MsBetweenDisplayChange",
    "PredictedMsBetweenDisplayChange",
    "MsRenderPresentLatency",
    "PredictedMsRenderPresentLatency",
    "ErrorMsUntilDisplayed",
];

/// The what-if's columns after [`FRAME_COLUMNS`].
pub const WHATIF_COLUMNS: [&str; 4] = [
    "WhatIfPresentTime",
    "WhatIfDisplayed",
    "WhatIfMsUntilDisplayed",
    "WhatIfMsBetweenDisplayChange",
];

impl Replay {
    /// The per-frame table's header: [`FRAME_COLUMNS`], and
    /// [`WHATIF_COLUMNS`] with a what-if.
    pub fn columns(&self) -> Vec<String> {
        let extra = if self.whatif_frames.is_some() {
            &WHATIF_COLUMNS[..]
        } else {
            &[]
        };
        FRAME_COLUMNS.iter().chain(extra).map(|c| c.to_string()).collect()
    }

    /// The per-frame rows (ms; NaN where a value does not exist).
    pub fn rows(&self) -> Vec<Vec<f64>> {
        let v = |x: Option<f64>| x.unwrap_or(f64::NAN);
        self.frames
            .iter()
            .enumerate()
            .map(|(i, f)| {
                let err = match f.until_displayed {
                    (Some(m), Some(p)) => p - m,
                    _ => f64::NAN,
                };
                let mut row = vec![
                    f.line as f64,
                    f.present,
                    f.predicted_present,
                    f64::from(u8::from(f.displayed)),
                    f64::from(u8::from(f.predicted_displayed)),
                    v(f.until_displayed.0),
                    v(f.until_displayed.1),
                    v(f.between_display_change.0),
                    v(f.between_display_change.1),
                    v(f.render_complete.0),
                    v(f.render_complete.1),
                    err,
                ];
                // A what-if that ends early (`run.frames`, `run.until`)
                // has no values for the frames after its last.
                if let Some(wf) = self.whatif_frames.as_ref() {
                    match wf.get(i) {
                        Some(w) => {
                            row.extend([
                                w.predicted_present,
                                f64::from(u8::from(w.predicted_displayed)),
                                v(w.until_displayed.1),
                                v(w.between_display_change.1),
                            ]);
                        }
                        None => row.extend([f64::NAN; WHATIF_COLUMNS.len()]),
                    }
                }
                row
            })
            .collect()
    }
}
