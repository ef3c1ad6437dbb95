//! Frame generation by interpolation (NVIDIA DLSS 3 Frame Generation, AMD
//! FSR 3 frame generation, Intel XeSS-FG): between two rendered frames the
//! GPU makes a third, interpolated from both, and the display shows it
//! before the newer rendered frame, doubling the frames shown.
//!
//! The model follows the frame-pacing rules AMD publishes for FSR 3's
//! frame-interpolation swap chain (FidelityFX SDK, "Frame Pacing in FSR3"
//! and "Frame Interpolation Swapchain": a proxy swap chain with a present
//! thread of its own), which the DLSS captures in
//! `../shared/measurements/presentmon/whatif` also show (presents evenly
//! spaced at twice the rendered rate, the game unthrottled by the display):
//!
//! - **The game renders into the proxy's images**, `display.buffers` of
//!   them. A rendered frame keeps its image until it has been copied into
//!   the real swap chain (its present) and the next frame's interpolation,
//!   which reads it, is done ([`PresentThread`]).
//! - **Interpolation is GPU work of the newer frame** (`cost`): when
//!   rendered frame `n >= 1` is done, the generated frame between `n - 1`
//!   and `n` is ready, and so is `n`.
//! - **A present thread paces the presents**: it presents the generated
//!   frame, then the rendered one, each no sooner than a present delta
//!   after the previous present. The delta aims at half the rendered frame
//!   time, a moving average of the last `pacing_frames` intervals between
//!   rendered frames' GPU ends (seven in FSR 3), so that generated and
//!   rendered frames reach the display evenly spaced and one slow frame
//!   does not upset the pacing; it is shortened by `pacing_variance_factor`
//!   times the intervals' spread and by `pacing_margin` (FSR 3's frame
//!   pacing tuning: "target delta = average frame time - variance x
//!   variance factor - safety margin", defaults 0.1 and 0.1 ms; we read
//!   its variance as the standard deviation of the halved intervals). The
//!   shortening is what drains a backlog: paced at exactly half the
//!   rendered interval the thread would keep any queue it once had, and
//!   the game, short of proxy images behind it, would slow to match.
//! - **It holds back only the newest frame's pair**: frames still waiting
//!   when a newer rendered frame is done go out at once, so the thread
//!   cannot build a queue that would slow the game behind it.
//! - **Each present takes an image of the real swap chain** (the display's,
//!   in its present mode): with none free, the present thread waits for
//!   one, and the game, short of proxy images, waits behind it. So with
//!   vsync on (`fifo`) the rendered rate falls to half the refresh, as the
//!   FSR 3 documentation says; on a composed or `mailbox` chain a newer
//!   frame replaces a queued one (dropped, counted).
//!
//! What it costs is latency: every rendered frame reaches the screen
//! `cost` plus about half a rendered interval later than it would have,
//! and a GPU-bound game renders fewer frames (the interpolation takes GPU
//! time). What it gives is twice the frames shown.
//!
//! ```
//! use rendersim_models::components::frame_generation::{FrameGenerationConfig, PresentThread, Next, generated_id};
//! use rendersim_engine::{Duration, Time};
//!
//! let ms = |m: u64| Time(m * 1_000_000_000);
//! // Two proxy images; a moving average over 7 frames, no shortening.
//! let config = FrameGenerationConfig {
//!     pacing_margin: Duration::ZERO,
//!     ..FrameGenerationConfig::default()
//! };
//! let mut t = PresentThread::new(2, &config);
//! assert!(t.acquire());
//! t.rendered(0, ms(18)); // frame 0: nothing to interpolate from
//! assert_eq!(t.next(ms(18)), Some(Next::Now(0)));
//! t.presented(ms(18));
//! assert!(t.acquire());
//! t.rendered(1, ms(36)); // frame 1: 18 ms later; the delta is 9 ms
//! assert_eq!(t.next(ms(36)), Some(Next::Now(generated_id(1))));
//! t.presented(ms(36));
//! assert_eq!(t.next(ms(36)), Some(Next::At(ms(45))));
//! assert_eq!(t.next(ms(45)), Some(Next::Now(1)));
//! ```

use std::collections::VecDeque;

use serde::{Deserialize, Serialize};

use crate::engine::{Duration, Time};

/// A model file's `[frame_generation]` (left out of written models when off).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FrameGenerationConfig {
    /// One generated frame before every rendered frame after the first.
    pub enabled: bool,
    /// GPU time to interpolate one frame.
    pub cost: Duration,
    /// Rendered frames whose intervals the present pacing averages (FSR 3:
    /// seven).
    pub pacing_frames: u32,
    /// How much sooner than half the average rendered interval the present
    /// thread presents (FSR 3's `safetyMarginInMs`, 0.1 ms).
    pub pacing_margin: Duration,
    /// Times the spread of the halved rendered intervals the present delta
    /// is shortened by (FSR 3's `varianceFactor`, 0.1; 0 to 1).
    pub pacing_variance_factor: f64,
}

impl Default for FrameGenerationConfig {
    fn default() -> Self {
        FrameGenerationConfig {
            enabled: false,
            cost: Duration::ms(1),
            pacing_frames: 7,
            pacing_margin: Duration::us(100),
            pacing_variance_factor: 0.1,
        }
    }
}

/// The most rendered intervals the present pacing may average.
pub const MAX_PACING_FRAMES: u32 = 120;

impl FrameGenerationConfig {
    /// Whether frame generation is off (the default).
    pub fn is_off(&self) -> bool {
        !self.enabled
    }

    /// The GPU time frame `frame`'s interpolation adds before its present
    /// (none for frame 0 or with generation off).
    pub fn cost_before_present(&self, frame: u64) -> Duration {
        if self.enabled && frame > 0 {
            self.cost
        } else {
            Duration::ZERO
        }
    }

    /// Refuses a pacing window outside 1..=[`MAX_PACING_FRAMES`]: the key
    /// and why.
    pub fn check(&self) -> Result<(), (&'static str, String)> {
        if !(1..=MAX_PACING_FRAMES).contains(&self.pacing_frames) {
            return Err((
                "frame_generation.pacing_frames",
                format!(
                    "must be 1 to {MAX_PACING_FRAMES} rendered frames (got {})",
                    self.pacing_frames
                ),
            ));
        }
        if !(0.0..=1.0).contains(&self.pacing_variance_factor) {
            return Err((
                "frame_generation.pacing_variance_factor",
                format!("must be 0 to 1 (got {})", self.pacing_variance_factor),
            ));
        }
        Ok(())
    }
}

/// What the present thread does next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Next {
    /// Present this frame (swap-chain id) now, if the real swap chain has
    /// a free image.
    Now(u64),
    /// The next present is due at this time.
    At(Time),
}

/// Frame generation's proxy swap chain and present thread: the images the
/// game renders into, the frames waiting to be presented in order, and the
/// present pacing (see the module's documentation).
#[derive(Debug, Clone)]
pub struct PresentThread {
    /// Proxy images free for the game to render into.
    free: u32,
    /// Rendered frames holding a proxy image: (frame, copied into the real
    /// swap chain, a newer frame's interpolation done).
    held: VecDeque<(u64, bool, bool)>,
    /// Frames ready, in present order: (swap-chain id, ready).
    queue: VecDeque<(u64, Time)>,
    /// The last rendered frame's GPU end.
    last_done: Option<Time>,
    /// The last present.
    last_present: Option<Time>,
    /// The last `window` intervals between rendered frames' GPU ends, ps.
    intervals: VecDeque<u64>,
    window: usize,
    /// Shortening of the delta: a fixed margin, and a factor of the
    /// spread.
    margin: Duration,
    variance_factor: f64,
}

impl PresentThread {
    /// A present thread whose proxy has `images` images, pacing as
    /// `config` says.
    pub fn new(images: u32, config: &FrameGenerationConfig) -> Self {
        PresentThread {
            free: images,
            held: VecDeque::new(),
            queue: VecDeque::new(),
            last_done: None,
            last_present: None,
            intervals: VecDeque::new(),
            window: config.pacing_frames.max(1) as usize,
            margin: config.pacing_margin,
            variance_factor: config.pacing_variance_factor,
        }
    }

    /// Whether a proxy image is free for the game.
    pub fn can_acquire(&self) -> bool {
        self.free > 0
    }

    /// The game takes a proxy image to render into; false if none is free.
    pub fn acquire(&mut self) -> bool {
        if self.free > 0 {
            self.free -= 1;
            true
        } else {
            false
        }
    }

    /// The present delta: half the moving average of the rendered
    /// intervals, less the variance factor times their (halved) standard
    /// deviation and the margin, never below zero (zero before the second
    /// rendered frame).
    pub fn delta(&self) -> Duration {
        let n = self.intervals.len();
        if n == 0 {
            return Duration::ZERO;
        }
        let half: Vec<f64> = self.intervals.iter().map(|&i| i as f64 / 2.0).collect();
        let mean = half.iter().sum::<f64>() / n as f64;
        let var = half.iter().map(|h| (h - mean) * (h - mean)).sum::<f64>() / n as f64;
        let target = mean - self.variance_factor * var.sqrt() - self.margin.0 as f64;
        Duration(target.max(0.0).round() as u64)
    }

    /// Rendered frame `frame` is done at `done` (its interpolation
    /// included): the generated frame before it (none for frame 0) and the
    /// frame itself join the queue, the interval joins the average, and
    /// the older frames' images, no longer an interpolation's source, are
    /// freed once copied.
    pub fn rendered(&mut self, frame: u64, done: Time) {
        if let Some(last) = self.last_done {
            self.intervals.push_back(done.0.saturating_sub(last.0));
            if self.intervals.len() > self.window {
                self.intervals.pop_front();
            }
        }
        self.last_done = Some(done);
        for h in &mut self.held {
            h.2 = true;
        }
        self.held.push_back((frame, false, false));
        self.release();
        if frame > 0 {
            self.queue.push_back((generated_id(frame), done));
        }
        self.queue.push_back((frame, done));
    }

    /// What to do next at `now` (`None`: nothing is waiting). A frame is
    /// due a present delta after the last present, or at once when a newer
    /// rendered frame is already done: the thread never holds more than
    /// the newest frame's pair back, so a backlog (after a hitch that
    /// lengthened the average) cannot outlast the next frame.
    pub fn next(&self, now: Time) -> Option<Next> {
        let &(id, ready) = self.queue.front()?;
        let superseded = self.last_done.is_some_and(|done| ready < done);
        let due = match self.last_present {
            Some(last) if !superseded => ready.max(Time(last.0.saturating_add(self.delta().0))),
            _ => ready,
        };
        Some(if due > now { Next::At(due) } else { Next::Now(id) })
    }

    /// The queue's first frame was presented at `now` (after
    /// [`Next::Now`]): its id and when it was ready.
    pub fn presented(&mut self, now: Time) -> Option<(u64, Time)> {
        let (id, ready) = self.queue.pop_front()?;
        self.last_present = Some(now);
        if generated_before(id).is_none()
            && let Some(h) = self.held.iter_mut().find(|h| h.0 == id)
        {
            h.1 = true;
        }
        self.release();
        Some((id, ready))
    }

    /// Frees the images of the oldest frames both copied and superseded.
    fn release(&mut self) {
        while self.held.front().is_some_and(|h| h.1 && h.2) {
            self.held.pop_front();
            self.free += 1;
        }
    }
}

/// The swap-chain id of the frame generated before rendered frame `n`
/// (rendered frames are their own index; generated ones have the top bit).
pub const fn generated_id(n: u64) -> u64 {
    n | GENERATED
}

/// The top bit of a generated frame's id.
pub const GENERATED: u64 = 1 << 63;

/// The rendered frame a generated frame's id precedes, or `None` for a
/// rendered frame's id.
pub const fn generated_before(id: u64) -> Option<u64> {
    if id & GENERATED != 0 {
        Some(id & !GENERATED)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_and_costs() {
        assert_eq!(generated_before(generated_id(7)), Some(7));
        assert_eq!(generated_before(7), None);
        let c = FrameGenerationConfig {
            enabled: true,
            cost: Duration(5),
            ..FrameGenerationConfig::default()
        };
        assert_eq!(c.cost_before_present(0), Duration::ZERO);
        assert_eq!(c.cost_before_present(1), Duration(5));
        assert!(FrameGenerationConfig::default().is_off());
        assert!(c.check().is_ok());
        let bad = FrameGenerationConfig {
            pacing_frames: 0,
            ..c.clone()
        };
        assert_eq!(bad.check().unwrap_err().0, "frame_generation.pacing_frames");
        let bad = FrameGenerationConfig {
            pacing_variance_factor: 1.5,
            ..c
        };
        assert_eq!(bad.check().unwrap_err().0, "frame_generation.pacing_variance_factor");
    }

    fn exact(window: u32) -> FrameGenerationConfig {
        FrameGenerationConfig {
            pacing_frames: window,
            pacing_margin: Duration::ZERO,
            pacing_variance_factor: 0.0,
            ..FrameGenerationConfig::default()
        }
    }

    #[test]
    fn the_delta_is_half_the_moving_average_less_the_spread_and_margin() {
        let run = |config: &FrameGenerationConfig| {
            let mut t = PresentThread::new(8, config);
            for (f, at) in [(0, 0), (1, 10), (2, 30), (3, 60)] {
                assert!(t.acquire());
                t.rendered(f, Time(at));
            }
            t.delta()
        };
        // The last two intervals, 20 and 30: half their mean.
        assert_eq!(run(&exact(2)), Duration(13));
        // Halved, 10 and 15: spread 2.5; a factor of 0.4 takes 1, a margin 2.
        let shortened = FrameGenerationConfig {
            pacing_variance_factor: 0.4,
            pacing_margin: Duration(2),
            ..exact(2)
        };
        assert_eq!(run(&shortened), Duration(10));
    }

    proptest::proptest! {
        /// Whatever the rendered frames' intervals and the pacing keys, the
        /// thread presents every frame once, in order (each generated frame
        /// just before its rendered one), never sooner than it is ready, at
        /// times that never go back; at the end every proxy image is free but the last
        /// frame's, the next interpolation's source.
        #[test]
        fn presents_every_frame_once_in_order(
            gaps in proptest::collection::vec(1u64..50_000, 1..60),
            window in 1u32..10,
            factor in 0.0f64..1.0,
            images in 2u32..5,
        ) {
            let config = FrameGenerationConfig {
                enabled: true,
                pacing_frames: window,
                pacing_variance_factor: factor,
                ..FrameGenerationConfig::default()
            };
            let mut t = PresentThread::new(images, &config);
            let mut presented: Vec<(u64, Time)> = Vec::new();
            let mut now = Time(0);
            let mut frame = 0u64;
            let drain = |t: &mut PresentThread, upto: Time, out: &mut Vec<(u64, Time)>| {
                while let Some(next) = t.next(upto) {
                    let at = match next {
                        Next::Now(_) => upto,
                        Next::At(due) if due <= upto => due,
                        Next::At(_) => break,
                    };
                    let (id, ready) = t.presented(at).unwrap();
                    proptest::prop_assert!(ready <= at);
                    out.push((id, at));
                }
                Ok(())
            };
            for g in &gaps {
                // The game renders the next frame when a proxy image is free.
                if !t.acquire() {
                    // Wait for the pending presents to free one.
                    drain(&mut t, Time(u64::MAX / 4), &mut presented)?;
                    proptest::prop_assert!(t.acquire() || frame == 0);
                }
                now = Time(now.0 + g);
                drain(&mut t, now, &mut presented)?;
                t.rendered(frame, now);
                frame += 1;
            }
            drain(&mut t, Time(u64::MAX / 4), &mut presented)?;
            let order: Vec<u64> = presented.iter().map(|p| p.0).collect();
            let mut want = vec![0u64];
            for n in 1..frame {
                want.push(generated_id(n));
                want.push(n);
            }
            proptest::prop_assert_eq!(order, want);
            proptest::prop_assert!(presented.windows(2).all(|w| w[0].1 <= w[1].1));
            proptest::prop_assert_eq!(t.free, images - 1);
        }
    }

    #[test]
    fn an_image_is_freed_once_copied_and_no_longer_a_source() {
        let mut t = PresentThread::new(2, &exact(7));
        assert!(t.acquire() && t.acquire() && !t.acquire());
        t.rendered(0, Time(10));
        t.presented(Time(10));
        // Frame 0 is copied but still the next interpolation's source.
        assert!(!t.can_acquire());
        t.rendered(1, Time(20));
        assert!(t.can_acquire(), "frame 1's interpolation is done");
        assert_eq!(t.next(Time(20)), Some(Next::Now(generated_id(1))));
        t.presented(Time(20));
        assert_eq!(t.next(Time(20)), Some(Next::At(Time(25))));
        assert_eq!(t.presented(Time(25)), Some((1, Time(20))));
        assert_eq!(t.next(Time(25)), None);
    }
}
