//! The VR pipeline's model file (paper 001, Zachmann, "Ein naives
//! VR-System" and the decoupled scheme with a warping renderer).
//!
//! Readings of the slides chosen here (see `docs/latency.md`): the naive
//! system's example gives 10 ms, 30 ms, 50 ms and 8 ms between the instants
//! T0..T4 and a 16.6 ms stereo frame on a 120 Hz field-sequential display;
//! the PDF text scrambles which interval is which. We read T0->T1 = tracker
//! latency 10 ms, T1->T2 = application (simulation) 30 ms, T2->T3 = renderer
//! 50 ms (then the swap lock waits for the next stereo-pair boundary),
//! T3->T4 = display 8 ms (one 120 Hz field, 8.33 ms). The tracker's sample
//! period is not given: 5 ms (200 Hz) is an assumption.

use serde::{Deserialize, Serialize};

use crate::config::Rate;
use crate::engine::Duration;
use crate::systems::tracked_input;

/// `[run]`: 5000 input events after a 500 ms warm-up.
pub type RunConfig = tracked_input::RunConfig<VrDefaults>;
/// `[input]`: a Poisson process, 97 ms apart on average.
pub use tracked_input::InputConfig;
/// `[tracker]`: a sample every 5 ms, delivered 10 ms later.
pub type TrackerConfig = tracked_input::TrackerConfig<VrDefaults>;

/// This system's defaults for the shared tables.
#[derive(Debug, Clone)]
pub struct VrDefaults;

impl tracked_input::Defaults for VrDefaults {
    const WARMUP_MS: u64 = 500;
    const TRACKER_PERIOD_MS: u64 = 5;
    const TRACKER_LATENCY_MS: u64 = 10;
}

/// Naive single loop or decoupled warping.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Scheme {
    /// Tracker -> simulation -> renderer -> swap lock -> display, one loop.
    Naive,
    /// Simulation, application renderer and a warping renderer decoupled.
    Warp,
}

/// The whole model.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VrConfig {
    /// Always `"vr"`.
    pub system: String,
    /// A one-line description.
    #[serde(default)]
    pub description: String,
    /// `naive` or `warp`.
    pub scheme: Scheme,
    /// Run length and seed.
    #[serde(default)]
    pub run: RunConfig,
    /// Motion events (head and object).
    #[serde(default)]
    pub input: InputConfig,
    /// The tracker.
    #[serde(default)]
    pub tracker: TrackerConfig,
    /// The simulation / animation step.
    #[serde(default)]
    pub simulation: SimulationConfig,
    /// The (application) renderer.
    #[serde(default)]
    pub renderer: RendererConfig,
    /// The warping renderer (`warp` scheme only).
    #[serde(default)]
    pub warp: WarpConfig,
    /// The display.
    #[serde(default)]
    pub display: DisplayConfig,
}

/// The simulation / animation step.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimulationConfig {
    /// Time of one step (slides: 30 ms).
    pub step: Duration,
}

impl Default for SimulationConfig {
    fn default() -> Self {
        SimulationConfig { step: Duration::ms(30) }
    }
}

/// The renderer of the naive loop, or the application renderer of the
/// warp scheme.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RendererConfig {
    /// Render time of one frame (slides: 50 ms, i.e. 20 Hz application frames).
    pub render: Duration,
}

impl Default for RendererConfig {
    fn default() -> Self {
        RendererConfig {
            render: Duration::ms(50),
        }
    }
}

/// The warping renderer: starts at every stereo-pair boundary (60 Hz), reads
/// the newest camera pose and object transforms, re-projects the newest
/// application frame, swaps at the next boundary.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WarpConfig {
    /// Time to warp one frame (must fit in one stereo pair; not in the
    /// slides: 10 ms is an assumption and does not change the latency).
    pub render: Duration,
}

impl Default for WarpConfig {
    fn default() -> Self {
        WarpConfig {
            render: Duration::ms(10),
        }
    }
}

/// A field-sequential stereo display.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DisplayConfig {
    /// Field rate (slides: 120 Hz, left and right alternating).
    pub field_rate: Rate,
    /// Two fields (left, right) per image: swaps only at pair boundaries.
    pub stereo: bool,
    /// Swap to visible; absent = one field (slides: 8 ms).
    pub latency: Option<Duration>,
}

impl Default for DisplayConfig {
    fn default() -> Self {
        DisplayConfig {
            field_rate: Rate::parse("120Hz").expect("built-in rate"),
            stereo: true,
            latency: None,
        }
    }
}

impl VrConfig {
    /// Time between swap opportunities (one stereo pair, or one field in mono).
    pub fn pair(&self) -> Duration {
        let f = self.display.field_rate.period;
        if self.display.stereo {
            Duration(f.0.saturating_mul(2))
        } else {
            f
        }
    }

    /// Swap to visible.
    pub fn display_latency(&self) -> Duration {
        self.display.latency.unwrap_or(self.display.field_rate.period)
    }
}
