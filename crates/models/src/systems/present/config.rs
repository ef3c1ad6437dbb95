//! The present system's model file: `[run]`, `[render]` and `[display]`
//! (the display is every system's [`DisplayConfig`], paper 004 §4.2).

use serde::{Deserialize, Serialize};

use crate::components::distribution::Dist;
pub use crate::components::swap_chain::DisplayConfig;
use crate::engine::Duration;

/// A whole `system = "present"` model.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PresentConfig {
    /// `"present"`.
    pub system: String,
    /// What the model is for (printed in the report).
    #[serde(default)]
    pub description: String,
    /// How long to run.
    #[serde(default)]
    pub run: PresentRunConfig,
    /// The renderer.
    #[serde(default)]
    pub render: RenderConfig,
    /// The swap chain and display.
    #[serde(default)]
    pub display: DisplayConfig,
}

/// How long to run.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PresentRunConfig {
    /// Frames to render (each ends shown or dropped).
    pub frames: u64,
    /// Leading frames left out of the metrics.
    pub warmup_frames: u64,
    /// Master seed of the RNG streams (`render` draws the render times).
    pub seed: u64,
    /// Optional cap on handled events.
    pub max_events: Option<u64>,
}

impl Default for PresentRunConfig {
    fn default() -> Self {
        PresentRunConfig {
            frames: 600,
            warmup_frames: 0,
            seed: 1,
            max_events: None,
        }
    }
}

/// The renderer: it starts a frame as soon as it holds a free image.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RenderConfig {
    /// Render time of one frame, drawn per frame.
    pub time: Dist<Duration>,
}

impl Default for RenderConfig {
    fn default() -> Self {
        RenderConfig {
            time: Dist::constant(Duration::ms(12)),
        }
    }
}
