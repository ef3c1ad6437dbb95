//! A what-if checked against reality (issue 56, item 4): `rendersim replay
//! BASE.csv --set K=V ... --compare MEASURED.csv` puts the figures of a
//! capture measured under the changed setting beside the replay's
//! prediction of them.
//!
//! The two captures are different minutes of play, so frames are not
//! paired: each side's distribution gives the same figures, computed the
//! same way from its frames (`Figures::of`): presents per second and
//! display changes per second (generated frames included, as a capture
//! without `FrameType` lists them), the median interval between display
//! changes, the median time from a present to its display, the median
//! display latency (CPU start to the screen), the median PC latency, and
//! the frame time (the interval between presents) at its median and 99th
//! percentile.
//!
//! PC latency (NVIDIA Reflex's: the game sampling input to the frame on
//! screen) is measured where the capture has `MsPCLatency`. The replay
//! predicts it from where the game samples input, which the replayed
//! capture shows when it has `MsPCLatency` itself: so many of the game's
//! frames before PresentMon's CPU start (the end of the previous present
//! call; [`super::results::InputLead`]), kept in frames under the what-if;
//! without it, at each frame's start after any wait a pacer or a limiter
//! placed there ([`PC_LATENCY_ASSUMPTION`]). Where a limiter sits relative
//! to the game's input (before it, as The Talos Principle 2's does, or
//! after) is the engine's and is not in a capture: that is a finding of
//! the comparison, not a constant fitted to it.

use std::path::Path;

use serde::Serialize;

use super::{Replay, ReplayError};
use crate::capture::presentmon::{Capture, Present};
use crate::stats::quantile::quantile;

/// Where the replay's model samples input, which its PC latency assumes.
pub const PC_LATENCY_ASSUMPTION: &str = "input sampled as many of the game's frames before PresentMon's CPU start \
                                         (the end of the previous present call) as the replayed capture's \
                                         MsPCLatency shows (replay.measured_input_latency.input_lead); without \
                                         it, at each frame's start after any wait a pacer or limiter puts there";

/// One figure, predicted and measured.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct Compared {
    /// The replay's prediction.
    pub predicted: Option<f64>,
    /// The measured capture's.
    pub measured: Option<f64>,
    /// Predicted over measured.
    pub ratio: Option<f64>,
}

impl Compared {
    fn of(predicted: Option<f64>, measured: Option<f64>) -> Compared {
        let ratio = match (predicted, measured) {
            (Some(p), Some(m)) if m != 0.0 => Some(p / m),
            _ => None,
        };
        Compared {
            predicted,
            measured,
            ratio,
        }
    }
}

/// The what-if's figures beside the measured capture's (`replay.compare`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Comparison {
    /// The measured capture, as given.
    pub capture: String,
    /// Its swap chain compared (the replayed application's with most frames).
    pub application: String,
    /// Its address.
    pub swapchain: String,
    /// Its presents (generated frames included).
    pub frames: usize,
    /// Presents per second.
    pub fps: Compared,
    /// Display changes per second.
    pub displayed_fps: Compared,
    /// Median interval between display changes, ms.
    pub display_change_ms_median: Compared,
    /// Median present to display, ms.
    pub until_displayed_ms_median: Compared,
    /// Median CPU start to display, ms.
    pub display_latency_ms_median: Compared,
    /// Median PC latency, ms (measured: `MsPCLatency`).
    pub pc_latency_ms_median: Compared,
    /// Frame time (the interval between presents), median, ms.
    pub frame_time_ms_p50: Compared,
    /// Frame time, 99th percentile, ms.
    pub frame_time_ms_p99: Compared,
    /// Where the prediction samples input.
    pub pc_latency_assumption: &'static str,
}

impl Comparison {
    /// The figures in order, with a name a person reads.
    pub fn rows(&self) -> [(&'static str, &Compared); 8] {
        [
            ("fps (presents/s)", &self.fps),
            ("displayed fps", &self.displayed_fps),
            ("display change median ms", &self.display_change_ms_median),
            ("until displayed median ms", &self.until_displayed_ms_median),
            ("display latency median ms", &self.display_latency_ms_median),
            ("PC latency median ms", &self.pc_latency_ms_median),
            ("frame time median ms", &self.frame_time_ms_p50),
            ("frame time p99 ms", &self.frame_time_ms_p99),
        ]
    }
}

/// One frame's times, ms on one clock.
struct Frame {
    cpu_start: Option<f64>,
    present: f64,
    screen: Option<f64>,
    pc_latency: Option<f64>,
}

/// A run of frames' figures.
struct Figures {
    fps: Option<f64>,
    displayed_fps: Option<f64>,
    display_change: Option<f64>,
    until_displayed: Option<f64>,
    display_latency: Option<f64>,
    pc_latency: Option<f64>,
    frame_time_p50: Option<f64>,
    frame_time_p99: Option<f64>,
}

/// The median of the finite values of `v` (`None` without one).
pub(super) fn median(mut v: Vec<f64>) -> Option<f64> {
    v.retain(|x| x.is_finite());
    v.sort_by(f64::total_cmp);
    (!v.is_empty()).then(|| quantile(&v, 0.5))
}

/// Events per second over their span (`None` for fewer than two).
fn rate(mut times: Vec<f64>) -> Option<f64> {
    times.retain(|x| x.is_finite());
    times.sort_by(f64::total_cmp);
    let span = times.last()? - times.first()?;
    (times.len() > 1 && span > 0.0).then(|| (times.len() - 1) as f64 * 1000.0 / span)
}

impl Figures {
    fn of(frames: &[Frame]) -> Figures {
        let mut screens: Vec<f64> = frames.iter().filter_map(|f| f.screen).collect();
        screens.sort_by(f64::total_cmp);
        let mut presents: Vec<f64> = frames.iter().map(|f| f.present).filter(|x| x.is_finite()).collect();
        presents.sort_by(f64::total_cmp);
        let mut intervals: Vec<f64> = presents.windows(2).map(|w| w[1] - w[0]).collect();
        intervals.sort_by(f64::total_cmp);
        let q = |p: f64| (!intervals.is_empty()).then(|| quantile(&intervals, p));
        Figures {
            frame_time_p50: q(0.5),
            frame_time_p99: q(0.99),
            fps: rate(frames.iter().map(|f| f.present).collect()),
            displayed_fps: rate(screens.clone()),
            display_change: median(screens.windows(2).map(|w| w[1] - w[0]).collect()),
            until_displayed: median(frames.iter().filter_map(|f| Some(f.screen? - f.present)).collect()),
            display_latency: median(frames.iter().filter_map(|f| Some(f.screen? - f.cpu_start?)).collect()),
            pc_latency: median(frames.iter().filter_map(|f| f.pc_latency).collect()),
        }
    }
}

/// The frames the replay predicts (the what-if's, or as captured without
/// one), generated frames included.
///
/// With frame generation the capture lists the presents of its present
/// thread: a rendered frame's present is the thread's (its GPU end plus
/// its hold-back), not the game's call, and PresentMon's CPU start of
/// every present, generated or rendered, is the end of the present before
/// it. A generated frame's PC latency is measured from the input of the
/// rendered frame it precedes (FrameView's: the pairs of `MsPCLatency` one
/// display change apart in the DLSS captures).
fn predicted(r: &Replay) -> Vec<Frame> {
    let (frames, replayed) = match (&r.whatif_frames, &r.whatif_replayed) {
        (Some(f), Some(rp)) => (f, rp),
        _ => (&r.frames, &r.replayed),
    };
    let origin = replayed.origin_ps as f64 / 1e9;
    let at = |t: crate::engine::Time| origin + t.as_ms_f64();
    let mut thread_present: Vec<Option<f64>> = vec![None; frames.len()];
    for &(f, hold) in &replayed.hold_backs {
        let end = replayed.records.get(f as usize).and_then(|rec| rec.gpu_end);
        if let (Some(slot), Some(end)) = (thread_present.get_mut(f as usize), end) {
            *slot = Some(at(end) + hold.as_ms_f64());
        }
    }
    let generating = !replayed.hold_backs.is_empty();
    // Where the game samples input: as many of its own frames ahead of
    // the frame's start as the capture measured (`None`: at the model's
    // input, the frame's start after any pacing wait).
    let lead = r.summary.measured_input_latency.input_lead.map(|l| l.frames);
    let mut inputs: Vec<f64> = Vec::with_capacity(frames.len());
    let mut out: Vec<Frame> = Vec::with_capacity(frames.len() + replayed.generated.len());
    for (i, (f, rec)) in frames.iter().zip(&replayed.records).enumerate() {
        let screen = f.until_displayed.1.map(|u| f.predicted_present + u);
        // PresentMon's CPU start is the end of the previous present
        // call (it cannot see a limiter's sleep after it): the
        // previous frame's predicted present plus its present call as
        // captured, unless the model began the frame earlier.
        let begun = f.cpu_start.1;
        let prev = i.checked_sub(1).map(|j| &frames[j]);
        let cpu_start = match prev {
            Some(prev) => begun.min(prev.predicted_present + (f.cpu_start.0 - prev.present).max(0.0)),
            None => begun,
        };
        let input = match (lead, prev) {
            // With frame generation the presents are the present
            // thread's: the game's own frames are paced by their starts.
            (Some(k), Some(prev)) if generating => begun - k * (begun - prev.cpu_start.1),
            (Some(k), Some(prev)) => cpu_start - k * (f.predicted_present - prev.predicted_present),
            _ => at(rec.input),
        };
        inputs.push(input);
        out.push(Frame {
            cpu_start: Some(cpu_start),
            present: thread_present[i].unwrap_or(f.predicted_present),
            screen,
            pc_latency: screen.map(|s| s - input),
        });
    }
    out.extend(replayed.generated.iter().map(|g| {
        let screen = g.displayed.map(at);
        let input = inputs.get(g.before as usize).copied();
        Frame {
            cpu_start: None,
            present: at(g.present),
            screen,
            pc_latency: screen.zip(input).map(|(s, i)| s - i),
        }
    }));
    if generating {
        out.sort_by(|a, b| a.present.total_cmp(&b.present));
        for i in 1..out.len() {
            out[i].cpu_start = Some(out[i - 1].present);
        }
    }
    out
}

/// A capture's frames as measured.
fn measured(rows: &[&Present]) -> Vec<Frame> {
    rows.iter()
        .map(|p| Frame {
            cpu_start: p.rendered().then_some(p.cpu_start),
            present: p.present,
            screen: p.screen_time(),
            pc_latency: p.pc_latency,
        })
        .collect()
}

/// Compares the replay `r` (its what-if, or as captured) with the capture
/// at `path`, measured under the setting the what-if models: the swap
/// chain with most frames of the replayed application.
pub fn compare(r: &Replay, path: &Path) -> Result<Comparison, ReplayError> {
    let capture = Capture::read(path)?;
    let app = &r.summary.application;
    let (chain, _) = capture.select(Some(app), None)?;
    let rows: Vec<&Present> = capture
        .presents
        .iter()
        .chain(&capture.generated)
        .filter(|p| {
            p.chain()
                == (
                    chain.application.as_str(),
                    chain.process_id.as_str(),
                    chain.swap_chain.as_str(),
                )
        })
        .collect();
    let m = Figures::of(&measured(&rows));
    let p = Figures::of(&predicted(r));
    Ok(Comparison {
        capture: capture.file.clone(),
        application: chain.application.to_string(),
        swapchain: chain.swap_chain.to_string(),
        frames: rows.len(),
        fps: Compared::of(p.fps, m.fps),
        displayed_fps: Compared::of(p.displayed_fps, m.displayed_fps),
        display_change_ms_median: Compared::of(p.display_change, m.display_change),
        until_displayed_ms_median: Compared::of(p.until_displayed, m.until_displayed),
        display_latency_ms_median: Compared::of(p.display_latency, m.display_latency),
        pc_latency_ms_median: Compared::of(p.pc_latency, m.pc_latency),
        frame_time_ms_p50: Compared::of(p.frame_time_p50, m.frame_time_p50),
        frame_time_ms_p99: Compared::of(p.frame_time_p99, m.frame_time_p99),
        pc_latency_assumption: PC_LATENCY_ASSUMPTION,
    })
}
