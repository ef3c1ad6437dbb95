//! What a player sees of a run of frames, as the figures latency studies
//! report them (PresentMon's and CapFrameX's conventions): display latency
//! (CPU start to the frame appearing, PresentMon 2's `DisplayLatency` without
//! input), frame rate and its "1% low", refreshes that repeat the previous
//! frame, frames presented but never shown, and stutter. The same function
//! reads a capture's measured frames and a replay's predicted ones, so the
//! measured, as-captured and what-if columns of a replay mean the same thing.

use serde::Serialize;

use crate::stats::quantile::quantile;

/// One frame's times, ms on one clock.
#[derive(Debug, Clone, Copy)]
pub struct FrameTimes {
    /// The CPU started the frame.
    pub cpu_start: f64,
    /// The present call started.
    pub present: f64,
    /// The frame appeared (`None`: never shown).
    pub screen: Option<f64>,
}

/// Median, 90th and 99th percentile (`None` without values).
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct Percentiles {
    /// 0.5 quantile.
    pub median: Option<f64>,
    /// 0.9 quantile.
    pub p90: Option<f64>,
    /// 0.99 quantile.
    pub p99: Option<f64>,
}

impl Percentiles {
    pub(super) fn of(mut v: Vec<f64>) -> Percentiles {
        v.sort_by(f64::total_cmp);
        let q = |x: f64| (!v.is_empty()).then(|| quantile(&v, x));
        Percentiles {
            median: q(0.5),
            p90: q(0.9),
            p99: q(0.99),
        }
    }
}

/// The display figures of a run of frames.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct DisplayStats {
    /// Frames presented.
    pub frames: usize,
    /// Frames shown (generated ones too).
    pub displayed: usize,
    /// Frames presented and never shown.
    pub dropped: usize,
    /// CPU start to the frame appearing, over the shown frames, ms.
    pub display_latency_ms: Percentiles,
    /// Presents per second over the presents' span.
    pub fps: Option<f64>,
    /// The "1% low": 1000 / the 99th percentile of the intervals between
    /// presents (CapFrameX's percentile reading of it).
    pub low_1pct_fps: Option<f64>,
    /// Display changes per second over the shown frames' span.
    pub displayed_fps: Option<f64>,
    /// Refreshes that showed the same frame as the refresh before, between
    /// the first and the last shown frame: per display change, its interval
    /// in refreshes (rounded) less one.
    pub repeated_refreshes: u64,
    /// Display changes whose interval differs from the previous one by more
    /// than half a refresh (a changed display cadence).
    pub stutters: usize,
    /// Frames a second whose flip tore the picture, for a simulated display
    /// whose flips do not wait for a vertical blank (`null` otherwise, and
    /// for a capture, which does not record tear lines).
    pub torn_per_second: Option<f64>,
}

impl DisplayStats {
    /// The figures of `frames` (in present order) on a display refreshing
    /// every `refresh_ms`.
    pub fn of(frames: &[FrameTimes], refresh_ms: f64) -> DisplayStats {
        DisplayStats::with_generated(frames, &[], refresh_ms)
    }

    /// The figures of `frames` and of frames generated between them, shown
    /// at `generated` (ms; frame generation): display latency, frame rate
    /// and the 1% low are the rendered frames'; `displayed`, display
    /// changes, repeated refreshes and stutters count every frame shown.
    pub fn with_generated(frames: &[FrameTimes], generated: &[f64], refresh_ms: f64) -> DisplayStats {
        let mut screens: Vec<f64> = frames
            .iter()
            .filter_map(|f| f.screen)
            .chain(generated.iter().copied())
            .collect();
        screens.sort_by(f64::total_cmp);
        let rendered_shown = frames.iter().filter(|f| f.screen.is_some()).count();
        let latency = frames.iter().filter_map(|f| Some(f.screen? - f.cpu_start)).collect();
        let present_gaps: Vec<f64> = frames.windows(2).map(|w| w[1].present - w[0].present).collect();
        let changes: Vec<f64> = screens.windows(2).map(|w| w[1] - w[0]).collect();
        let rate = |count: usize, span: f64| (count > 0 && span > 0.0).then(|| count as f64 * 1000.0 / span);
        let span = |v: &[f64]| v.iter().sum::<f64>();
        let mut gaps = present_gaps.clone();
        gaps.sort_by(f64::total_cmp);
        let low = (!gaps.is_empty())
            .then(|| quantile(&gaps, 0.99))
            .filter(|&g| g > 0.0)
            .map(|g| 1000.0 / g);
        let repeated = if refresh_ms > 0.0 {
            changes
                .iter()
                .map(|d| ((d / refresh_ms).round() as i64 - 1).max(0) as u64)
                .sum()
        } else {
            0
        };
        let stutters = changes
            .windows(2)
            .filter(|w| (w[1] - w[0]).abs() > refresh_ms / 2.0)
            .count();
        DisplayStats {
            frames: frames.len(),
            displayed: screens.len(),
            dropped: frames.len() - rendered_shown,
            display_latency_ms: Percentiles::of(latency),
            fps: rate(present_gaps.len(), span(&present_gaps)),
            low_1pct_fps: low,
            displayed_fps: rate(changes.len(), span(&changes)),
            repeated_refreshes: repeated,
            stutters,
            torn_per_second: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(cpu_start: f64, present: f64, screen: Option<f64>) -> FrameTimes {
        FrameTimes {
            cpu_start,
            present,
            screen,
        }
    }

    #[test]
    fn a_steady_run_at_the_refresh_has_no_repeats_drops_or_stutter() {
        let p = 10.0;
        let f: Vec<FrameTimes> = (0..100)
            .map(|i| {
                let t = f64::from(i) * p;
                frame(t, t + 4.0, Some(t + 12.0))
            })
            .collect();
        let s = DisplayStats::of(&f, p);
        assert_eq!(
            (s.displayed, s.dropped, s.repeated_refreshes, s.stutters),
            (100, 0, 0, 0)
        );
        assert!((s.fps.unwrap() - 100.0).abs() < 1e-9);
        assert!((s.low_1pct_fps.unwrap() - 100.0).abs() < 1e-9);
        assert!((s.displayed_fps.unwrap() - 100.0).abs() < 1e-9);
        assert!((s.display_latency_ms.median.unwrap() - 12.0).abs() < 1e-12);
    }

    #[test]
    fn a_missed_refresh_is_one_repeat_two_stutters_and_a_dropped_frame_counts() {
        // Shown at refreshes 0, 1, 3, 4 (refresh 2 repeats frame 1), and a
        // fifth frame never shown.
        let p = 10.0;
        let f = vec![
            frame(0.0, 1.0, Some(10.0)),
            frame(10.0, 11.0, Some(20.0)),
            frame(20.0, 31.0, Some(40.0)),
            frame(30.0, 41.0, Some(50.0)),
            frame(40.0, 51.0, None),
        ];
        let s = DisplayStats::of(&f, p);
        assert_eq!(s.repeated_refreshes, 1);
        // Intervals 10, 20, 10: the cadence changes twice.
        assert_eq!(s.stutters, 2);
        assert_eq!((s.displayed, s.dropped), (4, 1));
        // Present gaps 10, 20, 10, 10: the 99th percentile is near 20 ms.
        assert!(s.low_1pct_fps.unwrap() < 52.0 && s.low_1pct_fps.unwrap() > 50.0);
        // Latencies 10, 10, 20, 20 over the shown frames.
        assert_eq!(s.display_latency_ms.median, Some(15.0));
    }

    #[test]
    fn no_frames_and_no_shown_frames_give_no_figures_rather_than_nan() {
        let s = DisplayStats::of(&[], 16.7);
        assert_eq!(
            (s.frames, s.fps, s.low_1pct_fps, s.display_latency_ms.median),
            (0, None, None, None)
        );
        let s = DisplayStats::of(&[frame(0.0, 1.0, None), frame(1.0, 2.0, None)], 16.7);
        assert_eq!((s.dropped, s.displayed_fps, s.repeated_refreshes), (2, None, 0));
    }
}
