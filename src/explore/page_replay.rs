//! A capture dropped on the page: read from the uploaded bytes (PresentMon
//! 1 and 2, FrameView, OCAT, CapFrameX: the reader `rendersim replay`
//! uses), replayed through the frame pipeline as `rendersim replay` does,
//! with the page's display and pacing controls as the what-if.
//!
//! What the page shows is the replay's own summary: the fates' agreement,
//! `MsUntilDisplayed`'s error, the display inferred from the capture, and
//! the measured against the replayed screen times frame by frame (and the
//! what-if's, where there is one).

use serde::Serialize;

use crate::capture::presentmon::Capture;
use crate::plot::{LinePlot, Series};
use crate::studies::replay::display_stats::DisplayStats;
use crate::studies::replay::{ReplayOptions, replay_capture};

use super::page_run::{PageError, shell_quote};

/// The largest capture the page takes (a PresentMon capture of an hour at
/// 240 fps is about 100 MB; `rendersim replay` reads bigger ones).
pub const MAX_UPLOAD_BYTES: u64 = 64 * 1024 * 1024;

/// The keys a page's what-if may set on a replay: the display's, the
/// pacing's, frame generation's and the frames in flight (the replayed
/// frames' own work comes from the capture).
pub const WHATIF_PREFIXES: &[&str] = &["display.", "pacing.", "frame_generation.", "cpu.max_frames_ahead"];

/// What the page shows of a replay.
#[derive(Debug, Clone, Serialize)]
pub struct ReplayShown {
    /// The file's name as uploaded.
    pub file: String,
    /// The process and swap chain replayed.
    pub application: String,
    /// Its swap chain.
    pub swapchain: String,
    /// Frames replayed.
    pub frames: usize,
    /// Fraction of the frames of known fate whose displayed-or-dropped
    /// state the replay got right.
    pub agreement: f64,
    /// `MsUntilDisplayed`'s |error|, median and p90 (ms).
    pub until_displayed_error_ms: (Option<f64>, Option<f64>),
    /// Present to GPU done, |error| median (ms).
    pub render_complete_error_ms: Option<f64>,
    /// The refresh the replay inferred, and from what.
    pub refresh_hz: f64,
    /// Where the refresh came from (`compositor`, `display_changes`, ...).
    pub refresh_from: String,
    /// The capture's present mode, and the model's.
    pub present_mode: (String, String),
    /// Measured, as captured, and under the what-if.
    pub measured: DisplayStats,
    /// The replay as captured.
    pub as_captured: DisplayStats,
    /// The what-if's patches and figures.
    pub whatif: (Vec<String>, DisplayStats),
    /// What the reader noted of the capture.
    pub capture_notes: Vec<String>,
    /// The equivalent command.
    pub command: String,
    /// Measured and replayed `MsUntilDisplayed` over the frames (SVG).
    pub view: String,
}

/// Replays the uploaded capture `bytes` (named `file`) with the what-if
/// `sets`, the swap chain of `app` where given.
pub fn replay_upload(file: &str, bytes: &[u8], sets: &[String], app: Option<String>) -> Result<ReplayShown, PageError> {
    if let Some(s) = sets
        .iter()
        .find(|s| !WHATIF_PREFIXES.iter().any(|p| s.trim_start().starts_with(p)))
    {
        return Err(PageError::Request(format!(
            "--set {s}: a replay's what-if sets the display, pacing, frame generation or cpu.max_frames_ahead \
             (the frames' work comes from the capture)"
        )));
    }
    let wall = std::time::Instant::now();
    let capture = Capture::parse(file, bytes).map_err(|e| PageError::Model(crate::error_line(&e)))?;
    let opts = ReplayOptions {
        app: app.clone(),
        sets: sets.to_vec(),
        ..ReplayOptions::default()
    };
    let r = replay_capture(&capture, &opts, wall).map_err(|e| PageError::Model(crate::error_line(&e)))?;
    let s = &r.summary;
    let mut words = vec!["rendersim".to_string(), "replay".into(), shell_quote(file)];
    if let Some(a) = &app {
        words.extend(["--app".into(), shell_quote(a)]);
    }
    for set in sets {
        words.extend(["--set".into(), shell_quote(set)]);
    }
    let series = |name: &str, frames: &[crate::studies::replay::results::ReplayFrame], predicted: bool| Series {
        name: name.into(),
        points: frames
            .iter()
            .enumerate()
            .filter_map(|(i, f)| {
                let v = if predicted {
                    f.until_displayed.1
                } else {
                    f.until_displayed.0
                };
                Some((i as f64, v?))
            })
            .collect(),
        ..Series::default()
    };
    let mut lines = vec![
        series("measured", &r.frames, false),
        series("replayed as captured", &r.frames, true),
    ];
    if let Some(w) = &r.whatif_frames {
        lines.push(series("what-if", w, true));
    }
    let view = crate::plot::line_plot_svg(&LinePlot {
        title: format!("{} ({}): present to screen", s.application, s.swapchain),
        x_label: "frame".into(),
        y_label: "MsUntilDisplayed (ms)".into(),
        series: lines,
        ..LinePlot::default()
    })
    .map_err(|e| PageError::View(e.to_string()))?;
    Ok(ReplayShown {
        file: file.to_string(),
        application: s.application.clone(),
        swapchain: s.swapchain.clone(),
        frames: s.frames,
        agreement: s.agreement.displayed,
        until_displayed_error_ms: (s.error_ms.until_displayed.median, s.error_ms.until_displayed.p90),
        render_complete_error_ms: s.error_ms.render_complete.median,
        refresh_hz: s.refresh_hz,
        refresh_from: crate::studies::replay::results::json_name(s.refresh_from),
        present_mode: (s.present_mode.clone(), s.model_present_mode.clone()),
        measured: s.measured.clone(),
        as_captured: s.as_captured.clone(),
        whatif: (s.whatif.sets.clone(), s.whatif.stats.clone()),
        capture_notes: s.capture_notes.clone(),
        command: words.join(" "),
        view,
    })
}
