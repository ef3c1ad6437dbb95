//! Frame generation by interpolation (NVIDIA DLSS 3 Frame Generation, AMD
//! FSR 3 frame generation, Intel XeSS-FG): between two rendered frames the
//! GPU makes a third, interpolated from both, and the display shows it
//! before the newer rendered frame, doubling the frames shown.
//!
//! The interpolated frame needs the newer rendered frame, so that frame is
//! held back: when rendered frame `n` is done, the GPU first interpolates
//! (`frame_generation.cost` of GPU time, which delays the next frame's
//! rendering like any GPU work), presents the generated frame, and presents
//! frame `n` half a rendered interval later, so that generated and
//! rendered frames reach the display evenly spaced (the frame pacing these
//! implementations do). The rendered interval is the one just measured:
//! `n`'s GPU end (interpolation included) less `n - 1`'s. A held frame is
//! presented at once when the next rendered frame is done first (frames
//! are never reordered). Frame 0 has no predecessor and is presented as it
//! is.
//!
//! What it costs is latency: every rendered frame reaches the screen
//! `cost` plus half an interval later than it would have, and a GPU-bound
//! game renders fewer frames (the interpolation takes GPU time). What it
//! gives is twice the frames shown. A generated frame is rendered into a
//! swap-chain image like any other: with no free image when it is ready, it
//! is discarded (counted), so frame generation needs at least three images
//! to show anything.
//!
//! ```
//! use rendersim_models::components::frame_generation::held_present;
//! use rendersim_engine::Time;
//!
//! // Rendered frames done every 18 ms: the newer one goes out 9 ms after
//! // its generated predecessor.
//! let at = held_present(Time(36_000_000_000), Time(18_000_000_000));
//! assert_eq!(at, Time(45_000_000_000));
//! ```

use serde::{Deserialize, Serialize};

use crate::engine::{Duration, Time};

/// A model file's `[frame_generation]` (left out of written models when off).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FrameGenerationConfig {
    /// One generated frame before every rendered frame after the first.
    pub enabled: bool,
    /// GPU time to interpolate one frame.
    pub cost: Duration,
}

impl Default for FrameGenerationConfig {
    fn default() -> Self {
        FrameGenerationConfig {
            enabled: false,
            cost: Duration::ms(1),
        }
    }
}

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
}

/// When a rendered frame done at `done` (its interpolation included) is
/// presented after the generated frame shown before it: half the rendered
/// interval (`done - previous_done`) later.
pub fn held_present(done: Time, previous_done: Time) -> Time {
    Time(done.0.saturating_add(done.0.saturating_sub(previous_done.0) / 2))
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
    fn ids_and_the_held_present() {
        assert_eq!(generated_before(generated_id(7)), Some(7));
        assert_eq!(generated_before(7), None);
        assert_eq!(held_present(Time(30), Time(10)), Time(40));
        assert_eq!(held_present(Time(10), Time(10)), Time(10));
        let c = FrameGenerationConfig {
            enabled: true,
            cost: Duration(5),
        };
        assert_eq!(c.cost_before_present(0), Duration::ZERO);
        assert_eq!(c.cost_before_present(1), Duration(5));
        assert!(FrameGenerationConfig::default().is_off());
    }
}
