//! Frame pacing on the CPU: when the application may start a frame (or
//! present it), set by a frame-rate limiter or by a low-latency pacer
//! (issue 26 item 3; the behaviours follow the public descriptions of
//! the tools named below, not their code).
//!
//! - **Frame limiter** (`pacing.limit`, e.g. `"58Hz"`): the CPU waits so that
//!   frames are at least one target interval apart. Measured from the CPU's
//!   start (`limit_from = "start"`, as in-game limiters and RTSS's default do)
//!   frame n starts no earlier than frame n-1's start plus the interval;
//!   measured from the present (`limit_from = "present"`, a limiter that
//!   holds the present call) frame n's present comes no earlier than frame
//!   n-1's plus the interval, the wait falling just before the present;
//!   measured from the GPU submission (`limit_from = "submit"`, the GPU
//!   driver's cap: NVIDIA's Max Frame Rate, AMD's Frame Rate Target
//!   Control, which hold the frame in the driver before its work reaches
//!   the GPU) frame n's first GPU command goes no earlier than frame n-1's
//!   plus the interval: the CPU thread waits at its submission, and the
//!   GPU gets the frame's work only after the wait, so the frame reaches
//!   the screen a GPU frame after the wait ends (the shared FrameView
//!   captures of Alan Wake 2 under the driver's cap: present to screen is
//!   the GPU time; docs/replay.md).
//! - **Low-latency pacer** (`pacing.low_latency = true`; NVIDIA Reflex, AMD
//!   Anti-Lag, LatencyFleX and DXVK's low-latency frame pacer all aim at it):
//!   the CPU starts a frame late, so that its GPU work arrives just as the GPU
//!   runs dry. The pacer forecasts from history, as those tools do: the GPU
//!   frees at the oldest unfinished frame's GPU start plus one GPU frame per
//!   frame in flight (the last finished frame's GPU busy time), and the CPU
//!   needs the last frame's CPU busy time to submit; it sleeps until the
//!   forecast free time less that CPU time. With steady costs the GPU never
//!   idles and the latency is what one frame in flight gives, at the
//!   throughput of two (`tests/it/pacing.rs`).
//!
//! A limiter and the pacer may be combined; the later start wins. Both only
//! delay the CPU; they never let it run ahead of `cpu.max_frames_ahead`.

use serde::{Deserialize, Serialize};

use crate::config::Rate;
use crate::engine::{Duration, Time};

/// Where a frame limiter measures its interval from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LimitFrom {
    /// From one CPU frame start to the next: the wait is at the frame's start.
    #[default]
    Start,
    /// From one present to the next: the wait is just before the present.
    Present,
    /// From one GPU submission to the next (the GPU driver's cap): the wait
    /// is just before the frame's first GPU command.
    Submit,
}

impl LimitFrom {
    fn is_start(&self) -> bool {
        *self == LimitFrom::Start
    }
}

/// A model file's `[pacing]` (left out of written models when off).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PacingConfig {
    /// Frame-rate limit: the least interval between frames (`"58Hz"` or a
    /// period such as `"17.2ms"`); none by default.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limit: Option<Rate>,
    /// Where the limiter measures from.
    #[serde(skip_serializing_if = "LimitFrom::is_start")]
    pub limit_from: LimitFrom,
    /// Start each frame late so the GPU's queue stays empty.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub low_latency: bool,
}

impl PacingConfig {
    /// Whether no pacing is asked for (the default).
    pub fn is_off(&self) -> bool {
        self.limit.is_none() && !self.low_latency
    }

    /// The limiter's interval when it is measured from the CPU's start.
    pub fn start_limit(&self) -> Option<Duration> {
        self.limit
            .as_ref()
            .filter(|_| self.limit_from == LimitFrom::Start)
            .map(|r| r.period)
    }

    /// The limiter's interval when it is measured from the present.
    pub fn present_limit(&self) -> Option<Duration> {
        self.limit
            .as_ref()
            .filter(|_| self.limit_from == LimitFrom::Present)
            .map(|r| r.period)
    }

    /// The limiter's interval when it is measured from the GPU submission.
    pub fn submit_limit(&self) -> Option<Duration> {
        self.limit
            .as_ref()
            .filter(|_| self.limit_from == LimitFrom::Submit)
            .map(|r| r.period)
    }
}

/// The earliest time a limited event may happen: `interval` after the
/// previous one (`None`: no previous one, no wait).
///
/// ```
/// use rendersim_models::components::frame_pacing::limited;
/// use rendersim_engine::{Duration, Time};
///
/// let interval = Duration::ms(20);
/// assert_eq!(limited(None, interval), None);
/// assert_eq!(limited(Some(Time(Duration::ms(5).0)), interval), Some(Time(Duration::ms(25).0)));
/// ```
pub fn limited(previous: Option<Time>, interval: Duration) -> Option<Time> {
    previous.map(|p| Time(p.0.saturating_add(interval.0)))
}

/// What the low-latency pacer knows when the CPU could start a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GpuForecast {
    /// Frames submitted and not yet finished by the GPU.
    pub in_flight: u64,
    /// When the GPU began the oldest of them (`None`: not begun yet).
    pub oldest_gpu_start: Option<Time>,
    /// GPU busy time of the last finished frame (`None`: none finished yet).
    pub gpu_frame: Option<Duration>,
    /// CPU busy time of the last frame the CPU finished (`None`: none yet).
    pub cpu_frame: Option<Duration>,
}

/// When the low-latency pacer starts the next frame: at the forecast time the
/// GPU runs dry, less the CPU time the frame needs to reach it; `now` when
/// nothing is in flight, when there is no history yet, or when that time is
/// past.
///
/// ```
/// use rendersim_models::components::frame_pacing::{GpuForecast, paced_start};
/// use rendersim_engine::{Duration, Time};
///
/// let ms = |v| Time(Duration::ms(v).0);
/// // The GPU began the one frame in flight at 10 ms and takes 17 ms a frame;
/// // the CPU needs 5 ms: start at 10 + 17 - 5 = 22 ms.
/// let f = GpuForecast {
///     in_flight: 1,
///     oldest_gpu_start: Some(ms(10)),
///     gpu_frame: Some(Duration::ms(17)),
///     cpu_frame: Some(Duration::ms(5)),
/// };
/// assert_eq!(paced_start(ms(15), f), ms(22));
/// // Nothing in flight: the GPU is idle, start at once.
/// assert_eq!(paced_start(ms(15), GpuForecast { in_flight: 0, ..f }), ms(15));
/// ```
pub fn paced_start(now: Time, f: GpuForecast) -> Time {
    let (Some(gpu), Some(cpu)) = (f.gpu_frame, f.cpu_frame) else {
        return now;
    };
    if f.in_flight == 0 {
        return now;
    }
    let begun = f.oldest_gpu_start.unwrap_or(now);
    let dry = begun.0.saturating_add(gpu.0.saturating_mul(f.in_flight));
    Time(dry.saturating_sub(cpu.0).max(now.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(v: u64) -> Time {
        Time(Duration::ms(v).0)
    }

    #[test]
    fn the_pacer_counts_every_frame_in_flight_and_never_starts_in_the_past() {
        let f = GpuForecast {
            in_flight: 2,
            oldest_gpu_start: Some(ms(10)),
            gpu_frame: Some(Duration::ms(17)),
            cpu_frame: Some(Duration::ms(5)),
        };
        assert_eq!(paced_start(ms(0), f), ms(10 + 34 - 5));
        assert_eq!(paced_start(ms(100), f), ms(100));
        // No history: no forecast.
        assert_eq!(paced_start(ms(3), GpuForecast { gpu_frame: None, ..f }), ms(3));
        // The oldest frame not begun: counted from now.
        assert_eq!(
            paced_start(
                ms(3),
                GpuForecast {
                    oldest_gpu_start: None,
                    ..f
                }
            ),
            ms(3 + 34 - 5)
        );
    }

    #[test]
    fn the_config_splits_the_limit_by_where_it_is_measured() {
        let mut c = PacingConfig {
            limit: Some(Rate::parse("50Hz").unwrap()),
            ..PacingConfig::default()
        };
        assert_eq!(c.start_limit(), Some(Duration::ms(20)));
        assert_eq!(c.present_limit(), None);
        c.limit_from = LimitFrom::Present;
        assert_eq!((c.start_limit(), c.present_limit()), (None, Some(Duration::ms(20))));
        assert!(!c.is_off() && PacingConfig::default().is_off());
    }
}
