//! The desktop compositor as a consumer with its own timing (issue 54,
//! item 3): Windows' Desktop Window Manager (DWM) and compositors like it.
//!
//! How it works, as its designers describe it (Microsoft's "DXGI flip
//! model" documentation; the DWM's DirectFlip design notes, which draw the
//! timing): the compositor wakes shortly after a vertical blank, takes the
//! newest frame each composed swap chain has ready by then (and releases
//! the one it held before), composes the desktop into its own buffer with
//! GPU work of its own, and flips that buffer at a later vertical blank. A
//! blit present (`Composed: Copy with GPU GDI`) first copies the frame
//! into the window's redirection surface; a flip present shares it.
//!
//! The model keeps the two numbers that decide when a composed frame is
//! seen: `wake`, the time after each vertical blank at which the compositor
//! takes the newest ready frame, and `refreshes`, how many vertical blanks
//! after the one before its wake the composed desktop reaches the screen
//! (its composition, a blit's copy and the flip queue of its own buffer
//! together). A frame ready just before a wake is shown `refreshes`
//! refreshes after that blank; one ready just after waits a refresh more.
//! The defaults (`wake = 0`, `refreshes = 1`) take each frame at the
//! vertical blank where it flipped and show it one refresh later.
//!
//! ```
//! use rendersim_models::components::compositor::CompositorConfig;
//! use rendersim_engine::Duration;
//!
//! // A 120 Hz panel; the compositor wakes 1 ms after each vertical blank
//! // and its desktop is seen two blanks later.
//! let period = Duration::us(8_333);
//! let c = CompositorConfig { wake: Duration::ms(1), refreshes: 2 };
//! assert!(c.check(period).is_ok());
//! // From the wake to the screen: two refreshes less the wake.
//! assert_eq!(c.delay(period), Duration::us(2 * 8_333 - 1_000));
//! ```

use serde::{Deserialize, Serialize};

use crate::engine::Duration;

/// The most refreshes a composed frame may take to reach the screen.
pub const MAX_COMPOSITOR_REFRESHES: u32 = 16;

/// A model file's `[display.compositor]`: when a composed display's
/// compositor takes a frame and when its composition is seen (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CompositorConfig {
    /// When the compositor wakes after each vertical blank and takes the
    /// newest ready frame (below one refresh).
    pub wake: Duration,
    /// Vertical blanks from the one before its wake to its composition on
    /// screen.
    pub refreshes: u32,
}

impl Default for CompositorConfig {
    fn default() -> Self {
        CompositorConfig {
            wake: Duration::ZERO,
            refreshes: 1,
        }
    }
}

impl CompositorConfig {
    /// Whether this is the default timing (written models leave it out).
    pub fn is_default(&self) -> bool {
        *self == CompositorConfig::default()
    }

    /// From the compositor's wake to the frame it took on screen, on a
    /// display refreshing every `period`.
    pub fn delay(&self, period: Duration) -> Duration {
        Duration((period.0.saturating_mul(u64::from(self.refreshes))).saturating_sub(self.wake.0))
    }

    /// Checks the timing against the refresh `period`: a wake within the
    /// refresh, and a composition seen no earlier than the wake and within
    /// [`MAX_COMPOSITOR_REFRESHES`]; the error is (key, message).
    pub fn check(&self, period: Duration) -> Result<(), (&'static str, String)> {
        if self.wake.0 >= period.0 {
            return Err((
                "display.compositor.wake",
                format!(
                    "must be below one refresh ({period}): the compositor wakes once after each vertical blank, got {}",
                    self.wake
                ),
            ));
        }
        if !(1..=MAX_COMPOSITOR_REFRESHES).contains(&self.refreshes) {
            return Err((
                "display.compositor.refreshes",
                format!(
                    "must be 1 to {MAX_COMPOSITOR_REFRESHES} (vertical blanks from the one before the compositor's \
                     wake to its composition on screen), got {}",
                    self.refreshes
                ),
            ));
        }
        Ok(())
    }
}
