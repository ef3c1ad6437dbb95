//! The swap chain and display: images the GPU renders into, presented with
//! vsync in one of three modes (paper 004 §4.2: with double buffering and
//! vsync, a frame that misses a refresh waits for the next one, so the frame
//! rate snaps to refresh/1, refresh/2, ...).
//!
//! - `fifo`: presented frames queue and each vertical blank shows the oldest;
//!   the GPU waits for a free image (classic double/triple buffering).
//! - `mailbox`: a newly presented frame replaces a queued one (the replaced
//!   frame is dropped and its image freed); each vertical blank shows it.
//! - `fifo_latest_ready` (Vulkan's `VK_PRESENT_MODE_FIFO_LATEST_READY_KHR`,
//!   from `VK_EXT_present_mode_fifo_latest_ready`): presented frames queue
//!   as in `fifo`, and each vertical blank dequeues them in order up to the
//!   newest one that is ready, shows it and releases the older ones unshown.
//!   Unlike `mailbox`, images are freed only at a vertical blank, several
//!   at once (every presented frame is ready here: a frame is presented
//!   when the GPU finished it).
//! - `immediate` (or vsync off): a presented frame is shown at once, tearing
//!   the picture where the scan-out is (`display.blanking`, the share of a
//!   refresh in vertical blanking: [`crate::components::tearing`]).
//!
//! One image is always the front buffer being scanned out; `buffers` counts
//! all images, so double buffering leaves one image to render into.
//!
//! `composition` says who puts a flipped frame on the screen. `independent`
//! (a hardware flip: PresentMon's `Hardware: Legacy Flip` and `Hardware:
//! Independent Flip`) shows it at the flip. `composed` (the desktop
//! compositor, PresentMon's `Composed: Flip` and `Composed: Copy with GPU
//! GDI`) takes the newest ready frame when it wakes after a vertical blank
//! and shows its composition some refreshes later
//! ([`crate::components::compositor`], `[display.compositor]`; by default
//! it wakes at the blank and is seen one refresh later). The swap chain's
//! images are taken and freed at the compositor's wake instead of the
//! vertical blank (the compositor holds the frame it took, or its own copy).
//! docs/replay.md, "Composition", says how the shared PresentMon captures
//! follow it.
//!
//! `vrr` makes the panel's refresh variable (adaptive sync: VESA
//! Adaptive-Sync, AMD FreeSync, NVIDIA G-Sync, HDMI 2.1 VRR). The panel has
//! no fixed vertical blank: it starts a scan-out when a frame is flipped,
//! as soon as the previous scan-out is done (one period of its fastest rate,
//! `max_refresh`). A frame that arrives while the panel scans waits for the
//! scan to end (above the window the frame rate is held at `max_refresh`).
//! A panel may not hold one image longer than a period of its slowest rate,
//! `min_refresh`: when no new frame came by then, it scans the old one out
//! again (a repeated refresh; low-framerate compensation, which drivers do
//! by repeating frames below the window), and a frame that arrives during
//! that repeat waits for it to end. The model is the timing rule the VESA
//! Adaptive-Sync and HDMI 2.1 specifications give the source (a vertical
//! total stretched between the two limits), not any one vendor's driver:
//! drivers that repeat frames ahead of the deadline (to leave room for the
//! next one) are not modelled.

use std::collections::VecDeque;

use serde::{Deserialize, Serialize};

use crate::components::compositor::CompositorConfig;
use crate::config::Rate;

/// How presented frames reach the screen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PresentMode {
    /// Queue; one frame per vertical blank; never drops.
    Fifo,
    /// Newest replaces the queued frame; shown at the vertical blank.
    Mailbox,
    /// Shown at once, no waiting for vertical blank.
    Immediate,
    /// Queue; each vertical blank shows the newest queued frame and drops
    /// the older ones.
    FifoLatestReady,
}

/// Who shows a flipped frame (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Composition {
    /// A hardware flip: the frame is on screen at the flip.
    #[default]
    Independent,
    /// The desktop compositor shows the frame one refresh after the flip.
    Composed,
}

impl Composition {
    /// Whether this is the default (`independent`), which model files and
    /// written models leave out.
    pub fn is_independent(&self) -> bool {
        *self == Composition::Independent
    }
}

/// A model file's `[display]`: the swap chain and the display it feeds
/// (paper 004 §4.2), shared by every system that has one.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DisplayConfig {
    /// Refresh rate.
    pub refresh: Rate,
    /// Wait for vertical blank (false = `immediate`, whatever `present_mode` says).
    pub vsync: bool,
    /// Swap-chain images (2 = double, 3 = triple buffering).
    pub buffers: u32,
    /// How presented frames reach the screen.
    pub present_mode: PresentMode,
    /// Who shows a flipped frame: a hardware flip (`independent`, the
    /// default) or the desktop compositor one refresh later (`composed`).
    #[serde(skip_serializing_if = "Composition::is_independent")]
    pub composition: Composition,
    /// When a composed display's compositor takes frames and when they
    /// are seen (`[display.compositor]`; only with `composition =
    /// "composed"`). Left out: it wakes at the vertical blank and is seen
    /// one refresh later.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compositor: Option<CompositorConfig>,
    /// Variable refresh (see the module docs); `None`, the default, is a
    /// fixed refresh.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vrr: Option<VrrConfig>,
    /// The share of each refresh spent in vertical blanking: where an
    /// `immediate` flip tears ([`crate::components::tearing`]); 0.04 unless
    /// given.
    #[serde(skip_serializing_if = "is_default_blanking")]
    pub blanking: f64,
}

fn is_default_blanking(b: &f64) -> bool {
    *b == crate::components::tearing::DEFAULT_BLANKING
}

/// A variable-refresh panel's window (`[display.vrr]`, see the module docs).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VrrConfig {
    /// The slowest refresh: no image is held longer than its period (below
    /// it, frames are repeated).
    pub min_refresh: Rate,
    /// The fastest refresh: a scan-out takes its period. Left out, it is
    /// `display.refresh` (the panel's native rate).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_refresh: Option<Rate>,
}

/// The periods of a variable-refresh window.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct VrrWindow {
    /// One scan-out: the period of the fastest refresh.
    pub shortest: crate::engine::Duration,
    /// The longest an image is held: the period of the slowest refresh.
    pub longest: crate::engine::Duration,
}

impl DisplayConfig {
    /// The present mode the run follows: `present_mode`, or `immediate` when
    /// `vsync` is off. The one place this rule is written: every system and
    /// study that reads a `[display]` asks here.
    pub fn effective_mode(&self) -> PresentMode {
        if self.vsync {
            self.present_mode
        } else {
            PresentMode::Immediate
        }
    }

    /// Whether presented frames wait for a vertical blank (any mode but
    /// `immediate`, with vsync on).
    pub fn waits_for_vblank(&self) -> bool {
        self.effective_mode() != PresentMode::Immediate
    }

    /// The shortest time between two refreshes: the period of the refresh,
    /// or of a variable-refresh panel's fastest rate.
    pub fn shortest_period(&self) -> crate::engine::Duration {
        self.vrr_window().map_or(self.refresh.period, |w| w.shortest)
    }

    /// The variable-refresh window, when `vrr` is set.
    pub fn vrr_window(&self) -> Option<VrrWindow> {
        self.vrr.as_ref().map(|v| VrrWindow {
            shortest: v.max_refresh.as_ref().unwrap_or(&self.refresh).period,
            longest: v.min_refresh.period,
        })
    }

    /// The first key this display sets that only the frame pipeline models
    /// (composition, variable refresh, the blanking tearing reads), with
    /// what to say; `None` when a
    /// system with a plain fixed-refresh display can run it.
    pub fn beyond_fixed_refresh(&self) -> Option<(&'static str, &'static str)> {
        if !self.composition.is_independent() {
            Some(("display.composition", "a composed display"))
        } else if self.vrr.is_some() {
            Some(("display.vrr", "a variable-refresh display"))
        } else if !is_default_blanking(&self.blanking) {
            Some(("display.blanking", "the tear line of a display's scan-out"))
        } else {
            None
        }
    }

    /// The scan-out an `immediate` flip tears, `None` when flips wait for a
    /// vertical blank.
    pub fn scan_out(&self) -> Option<crate::components::tearing::ScanOut> {
        (!self.waits_for_vblank()).then(|| crate::components::tearing::ScanOut::new(self.refresh.period, self.blanking))
    }

    /// The compositor's timing when composed (`None` for a hardware flip):
    /// `[display.compositor]`, or its defaults.
    pub fn compositor_timing(&self) -> Option<CompositorConfig> {
        match self.composition {
            Composition::Independent => None,
            Composition::Composed => Some(self.compositor.unwrap_or_default()),
        }
    }

    /// When the swap chain's frames are taken after each vertical blank:
    /// at the blank for a hardware flip, at the compositor's wake when
    /// composed.
    pub fn latch_phase(&self) -> crate::engine::Duration {
        self.compositor_timing()
            .map_or(crate::engine::Duration::ZERO, |c| c.wake)
    }

    /// Time from a frame's being taken to its being on screen: none for a
    /// hardware flip; when composed, the compositor's delay from its wake
    /// ([`CompositorConfig::delay`]; one refresh by default).
    pub fn compositor_delay(&self) -> crate::engine::Duration {
        self.compositor_timing()
            .map_or(crate::engine::Duration::ZERO, |c| c.delay(self.refresh.period))
    }

    /// Checks the display every system can run: a refresh period of at
    /// least [`crate::limits::MIN_REFRESH_PERIOD_PS`] (every refresh is an
    /// event), 2 to 16 swap-chain images, and composition only with a
    /// vertical blank to compose at; a variable-refresh window whose slowest
    /// rate is below its fastest, with vsync and a hardware flip; the error
    /// is (key, message).
    pub fn check(&self) -> Result<(), (&'static str, String)> {
        if self.refresh.period.0 < crate::limits::MIN_REFRESH_PERIOD_PS {
            return Err(too_short("display.refresh", self.refresh.period));
        }
        if let Some(v) = &self.vrr {
            self.check_vrr(v)?;
        }
        if !(0.0..1.0).contains(&self.blanking) {
            return Err((
                "display.blanking",
                format!(
                    "must be at least 0 and below 1 (the share of a refresh in vertical blanking), got {}",
                    self.blanking
                ),
            ));
        }
        if !(2..=16).contains(&self.buffers) {
            return Err((
                "display.buffers",
                format!("must be between 2 and 16 swap-chain images, got {}", self.buffers),
            ));
        }
        if self.composition == Composition::Composed && !self.waits_for_vblank() {
            return Err((
                "display.composition",
                "a composed frame is shown by the desktop compositor at a vertical blank: \
                 `composed` needs `display.vsync = true` and `present_mode` `fifo`, `mailbox` or `fifo_latest_ready`"
                    .to_string(),
            ));
        }
        if let Some(c) = &self.compositor {
            if self.composition.is_independent() {
                return Err((
                    "display.compositor",
                    "the compositor's timing applies to a composed display: set `display.composition = \"composed\"` \
                     or leave `[display.compositor]` out"
                        .to_string(),
                ));
            }
            c.check(self.refresh.period)?;
        }
        Ok(())
    }
}

/// The error of a refresh period below [`crate::limits::MIN_REFRESH_PERIOD_PS`].
fn too_short(key: &'static str, period: crate::engine::Duration) -> (&'static str, String) {
    (
        key,
        format!("a refresh period of {period} is shorter than the limit of 1us (1 MHz): every refresh is an event"),
    )
}

impl DisplayConfig {
    fn check_vrr(&self, v: &VrrConfig) -> Result<(), (&'static str, String)> {
        if let Some(max) = &v.max_refresh
            && max.period.0 < crate::limits::MIN_REFRESH_PERIOD_PS
        {
            return Err(too_short("display.vrr.max_refresh", max.period));
        }
        let w = self.vrr_window().expect("vrr is set");
        if w.longest.0 <= w.shortest.0 {
            let max = v
                .max_refresh
                .as_ref()
                .map_or(format!("display.refresh = {:?}", self.refresh.text), |m| {
                    format!("display.vrr.max_refresh = {:?}", m.text)
                });
            return Err((
                "display.vrr.min_refresh",
                format!(
                    "the slowest refresh {:?} must be slower than the fastest ({max}): a variable-refresh window runs \
                     from min_refresh up to max_refresh",
                    v.min_refresh.text
                ),
            ));
        }
        if !self.waits_for_vblank() {
            return Err((
                "display.vrr",
                "a variable-refresh panel shows each frame at a scan-out start; with vsync off frames above \
                 its range would tear, which is not modelled: `display.vrr` needs `display.vsync = true` and \
                 `present_mode` `fifo`, `mailbox` or `fifo_latest_ready`"
                    .to_string(),
            ));
        }
        if !self.composition.is_independent() {
            return Err((
                "display.vrr",
                "variable refresh follows the application's own flips: it needs an independent flip, not \
                 `display.composition = \"composed\"` (the compositor refreshes at a fixed rate)"
                    .to_string(),
            ));
        }
        Ok(())
    }
}

impl Default for DisplayConfig {
    fn default() -> Self {
        DisplayConfig {
            refresh: Rate::parse("60Hz").expect("valid literal"),
            vsync: true,
            buffers: 2,
            present_mode: PresentMode::Fifo,
            composition: Composition::Independent,
            compositor: None,
            vrr: None,
            blanking: crate::components::tearing::DEFAULT_BLANKING,
        }
    }
}

/// A frame identifier (its index).
pub type FrameId = u64;

/// The images and what is on screen.
///
/// The renderer [`acquire`](SwapChain::acquire)s a free image, renders and
/// [`present`](SwapChain::present)s it; the display shows it at a
/// [`vblank`](SwapChain::vblank) (or at once in `immediate` mode). With two
/// buffers and `fifo`, one image is on screen and one is rendered into, so
/// the renderer waits for every vertical blank:
///
/// ```
/// use rendersim_models::components::swap_chain::{PresentMode, SwapChain};
///
/// let mut chain = SwapChain::new(2, PresentMode::Fifo);
/// assert!(chain.acquire()); // the back buffer
/// assert!(!chain.acquire()); // the other image is the (blank) front
/// chain.present(0);
/// assert_eq!(chain.queued(), 1);
/// let flip = chain.vblank();
/// assert_eq!((flip.shown, flip.freed), (Some(0), true));
/// assert_eq!(chain.front(), Some(0));
/// assert!(chain.acquire()); // the old front image is free again
///
/// // Mailbox with three images: a newer frame replaces a queued one.
/// let mut mailbox = SwapChain::new(3, PresentMode::Mailbox);
/// assert!(mailbox.acquire());
/// mailbox.present(0);
/// assert!(mailbox.acquire());
/// assert_eq!(mailbox.present(1).dropped, Some(0)); // never shown
/// assert_eq!(mailbox.vblank().shown, Some(1));
///
/// // FIFO latest ready with four images: frames queue as in FIFO, and the
/// // vertical blank releases the older ones and shows the newest.
/// let mut latest = SwapChain::new(4, PresentMode::FifoLatestReady);
/// for f in 0..3 {
///     assert!(latest.acquire());
///     latest.present(f);
/// }
/// assert!(!latest.acquire()); // every image is queued or on screen
/// assert_eq!(latest.release_stale(), Some(0));
/// assert_eq!(latest.release_stale(), Some(1));
/// assert_eq!(latest.release_stale(), None);
/// assert_eq!(latest.vblank().shown, Some(2));
/// // Three images come back at once: the two released and the old front.
/// assert!(latest.acquire() && latest.acquire() && latest.acquire());
/// assert!(!latest.acquire());
/// ```
#[derive(Debug, Clone)]
pub struct SwapChain {
    mode: PresentMode,
    free: u32,
    queued: VecDeque<FrameId>,
    front: Option<FrameId>,
}

/// What a present or a vertical blank did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Flip {
    /// The frame that became visible now, if any.
    pub shown: Option<FrameId>,
    /// A frame discarded without ever being shown (mailbox), if any.
    pub dropped: Option<FrameId>,
    /// Whether an image became free (a waiting GPU may acquire it).
    pub freed: bool,
}

impl SwapChain {
    /// A chain of `buffers` images (>= 2) in `mode`.
    pub fn new(buffers: u32, mode: PresentMode) -> Self {
        debug_assert!(buffers >= 2);
        SwapChain {
            mode,
            free: buffers - 1,
            queued: VecDeque::new(),
            front: None,
        }
    }

    /// The present mode.
    pub fn mode(&self) -> PresentMode {
        self.mode
    }

    /// Whether an image is free for [`SwapChain::acquire`] to take.
    #[inline]
    pub fn can_acquire(&self) -> bool {
        self.free > 0
    }

    /// Takes a free image to render into; false if none is free.
    #[inline]
    pub fn acquire(&mut self) -> bool {
        if self.free > 0 {
            self.free -= 1;
            true
        } else {
            false
        }
    }

    /// Frames waiting for a vertical blank.
    pub fn queued(&self) -> usize {
        self.queued.len()
    }

    /// The frame on screen.
    pub fn front(&self) -> Option<FrameId> {
        self.front
    }

    /// The GPU finished rendering `frame` into its image and presents it.
    pub fn present(&mut self, frame: FrameId) -> Flip {
        match self.mode {
            PresentMode::Immediate => {
                // The old front image (at start-up the blank one) is freed.
                self.front = Some(frame);
                self.free += 1;
                Flip {
                    shown: Some(frame),
                    dropped: None,
                    freed: true,
                }
            }
            PresentMode::Fifo | PresentMode::FifoLatestReady => {
                self.queued.push_back(frame);
                Flip::default()
            }
            PresentMode::Mailbox => {
                let dropped = self.queued.pop_front();
                self.queued.push_back(frame);
                if dropped.is_some() {
                    self.free += 1;
                }
                Flip {
                    shown: None,
                    dropped,
                    freed: dropped.is_some(),
                }
            }
        }
    }

    /// At a vertical blank in `fifo_latest_ready`, before [`SwapChain::vblank`]:
    /// the oldest queued frame, released unshown and its image freed, while
    /// a newer one is queued (`None`: nothing more to release; always in the
    /// other modes). Call it until it gives `None`.
    #[inline]
    pub fn release_stale(&mut self) -> Option<FrameId> {
        if self.mode != PresentMode::FifoLatestReady || self.queued.len() < 2 {
            return None;
        }
        self.free += 1;
        self.queued.pop_front()
    }

    /// A vertical blank: the oldest queued frame (if any) becomes the front
    /// buffer and the old front image is freed (in `fifo_latest_ready`,
    /// after [`SwapChain::release_stale`], the newest).
    pub fn vblank(&mut self) -> Flip {
        if self.mode == PresentMode::Immediate {
            return Flip::default();
        }
        debug_assert!(
            self.mode != PresentMode::FifoLatestReady || self.queued.len() <= 1,
            "fifo_latest_ready: release the stale frames before the vertical blank"
        );
        match self.queued.pop_front() {
            Some(f) => {
                self.front = Some(f);
                self.free += 1;
                Flip {
                    shown: Some(f),
                    dropped: None,
                    freed: true,
                }
            }
            None => Flip::default(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn double_buffered_fifo_blocks_until_vblank() {
        let mut s = SwapChain::new(2, PresentMode::Fifo);
        assert!(s.acquire());
        assert!(!s.acquire());
        s.present(0);
        assert!(!s.acquire());
        let f = s.vblank();
        assert_eq!(f.shown, Some(0));
        assert!(s.acquire());
    }

    #[test]
    fn mailbox_replaces_and_drops() {
        let mut s = SwapChain::new(3, PresentMode::Mailbox);
        assert!(s.acquire());
        s.present(0);
        assert!(s.acquire());
        let f = s.present(1);
        assert_eq!(f.dropped, Some(0));
        assert!(s.acquire());
        assert_eq!(s.vblank().shown, Some(1));
    }

    #[test]
    fn immediate_shows_at_once() {
        let mut s = SwapChain::new(2, PresentMode::Immediate);
        assert!(s.acquire());
        assert_eq!(s.present(7).shown, Some(7));
        assert!(s.acquire());
        assert_eq!(s.vblank(), Flip::default());
    }
}
