//! The multi-frame-rate model file (paper 003 §3, Figure 4): a master with a
//! tracker, a slow client (SC) that renders the whole scene and reads its
//! frame buffer back, a transfer path from SC to the fast client (FC), and an
//! FC that uploads the latest SC image and renders the interactive objects.
//! A conventional single client (the paper's baseline) runs beside them.
//!
//! Readings of the paper chosen here (see `docs/latency.md`):
//! - read-back and upload are bandwidths, so they scale with resolution and
//!   stereo: 10 MiB (1280x1024x8 B) in 20 ms = 500 MiB/s read-back, in
//!   10 ms = 1000 MiB/s upload (Table 1's "<= 20 ms" and "<= 10 ms");
//! - render times are the scene's and do not scale with resolution;
//! - the paper's "MB" are 2^20 bytes (10 MB in 111 ms at 90 MB/s), so the
//!   models write `MiB`;
//! - the process-shared copy is "just slightly better than" loopback: the
//!   default 2.4 Gbit/s (20 % better) is an assumption, not a paper number.

use serde::{Deserialize, Serialize};

use crate::config::{Bandwidth, Rate};
use crate::engine::Duration;
use crate::systems::tracked_input;

/// `[run]`: 5000 input events after a 1000 ms warm-up.
pub type RunConfig = tracked_input::RunConfig<MultiRateDefaults>;
/// `[input]`: a Poisson process, 97 ms apart on average.
pub use tracked_input::InputConfig;
/// `[tracker]`: a sample every 20 ms, delivered 40 ms later.
pub type TrackerConfig = tracked_input::TrackerConfig<MultiRateDefaults>;

/// This system's defaults for the shared tables.
#[derive(Debug, Clone)]
pub struct MultiRateDefaults;

impl tracked_input::Defaults for MultiRateDefaults {
    const WARMUP_MS: u64 = 1000;
    const TRACKER_PERIOD_MS: u64 = 20;
    const TRACKER_LATENCY_MS: u64 = 40;
}

/// The whole model.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MultiRateConfig {
    /// Always `"multi_rate"`.
    pub system: String,
    /// A one-line description.
    #[serde(default)]
    pub description: String,
    /// Frame-buffer size in pixels, `[width, height]`.
    #[serde(default = "default_resolution")]
    pub resolution: [u32; 2],
    /// Bytes per pixel moved from SC to FC (8 = 32-bit colour + 32-bit depth;
    /// 18 = deferred shading's 144 bits).
    #[serde(default = "default_bpp")]
    pub bytes_per_pixel: u32,
    /// Two frame buffers per frame (left and right eye).
    #[serde(default)]
    pub stereo: bool,
    /// Run length, seed.
    #[serde(default)]
    pub run: RunConfig,
    /// Input events (the user's actions).
    #[serde(default)]
    pub input: InputConfig,
    /// The master's tracker.
    #[serde(default)]
    pub tracker: TrackerConfig,
    /// The slow client.
    #[serde(default)]
    pub slow_client: SlowClientConfig,
    /// The fast client.
    #[serde(default)]
    pub fast_client: FastClientConfig,
    /// The conventional single client (the baseline).
    #[serde(default)]
    pub conventional: ConventionalConfig,
    /// Which path carries SC's frame buffer to FC.
    #[serde(default)]
    pub transfer: TransferConfig,
    /// Gigabit Ethernet (cluster setup).
    #[serde(default)]
    pub network: LinkConfig,
    /// Local loopback device.
    #[serde(default = "loopback_default")]
    pub loopback: LinkConfig,
    /// Copy through process-shared memory.
    #[serde(default = "shared_copy_default")]
    pub shared_copy: LinkConfig,
    /// Zero-copy triple buffering with a lock.
    #[serde(default)]
    pub zero_copy: ZeroCopyConfig,
    /// The display's own latency, added after the last client frame ends.
    #[serde(default)]
    pub display: DisplayConfig,
    /// Multi-GPU deferred shading (paper 003 §6): SC sends G-buffers, FC shades.
    #[serde(default)]
    pub deferred: DeferredConfig,
    /// An interaction script for migration artifacts (paper 003 §4).
    #[serde(default)]
    pub migration: MigrationConfig,
}

/// The interaction script; empty = no migration analysis.
#[derive(Debug, Clone, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct MigrationConfig {
    /// Actions in time order, e.g. `{ at = "2s", action = "hover" }`.
    pub script: Vec<super::migration::Step>,
}

fn default_resolution() -> [u32; 2] {
    [1280, 1024]
}
fn default_bpp() -> u32 {
    8
}

/// The slow client: render the whole scene, then read colour and depth back.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SlowClientConfig {
    /// Render time of the whole scene (paper: TRender = 166 ms).
    pub render: Duration,
    /// Read-back bandwidth (paper: 10 MiB in <= 20 ms).
    pub readback: Bandwidth,
    /// Optional frame-rate cap (`"6Hz"` or a period like `"200ms"`): a frame
    /// starts no earlier than the next tick of this rate (ticks from the
    /// client's start phase), so frames come every
    /// `ceil(frame / period) * period`. Unset: free-running (the paper).
    pub rate: Option<Rate>,
}

impl Default for SlowClientConfig {
    fn default() -> Self {
        SlowClientConfig {
            render: Duration::ms(166),
            readback: bw("500MiB/s"),
            rate: None,
        }
    }
}

/// The fast client: upload the latest SC image (TDraw), render the
/// interactive parts (TRender), every frame.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FastClientConfig {
    /// Render time of the interactive parts (paper: 23 ms).
    pub render: Duration,
    /// Upload bandwidth of SC's image (paper: 10 MiB in <= 10 ms).
    pub upload: Bandwidth,
    /// Optional frame-rate cap, as for the slow client (e.g. `"60Hz"`:
    /// a display-locked fast client). Unset: free-running (the paper).
    pub rate: Option<Rate>,
}

impl Default for FastClientConfig {
    fn default() -> Self {
        FastClientConfig {
            render: Duration::ms(23),
            upload: bw("1000MiB/s"),
            rate: None,
        }
    }
}

/// The conventional single client: renders everything at SC's render time.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ConventionalConfig {
    /// Simulate it beside the multi-frame-rate clients.
    pub enabled: bool,
    /// Its frame time; absent = `slow_client.render` (the paper's reading).
    pub frame: Option<Duration>,
}

impl Default for ConventionalConfig {
    fn default() -> Self {
        ConventionalConfig {
            enabled: true,
            frame: None,
        }
    }
}

/// The transfer path in use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TransferPath {
    /// `[network]`: Gigabit Ethernet between cluster nodes.
    Network,
    /// `[loopback]`: sockets on one machine.
    Loopback,
    /// `[shared_copy]`: copy through process-shared memory.
    SharedCopy,
    /// `[zero_copy]`: pointer swap under a lock.
    ZeroCopy,
}

impl TransferPath {
    /// The name as written in model files.
    pub fn name(self) -> &'static str {
        match self {
            TransferPath::Network => "network",
            TransferPath::Loopback => "loopback",
            TransferPath::SharedCopy => "shared_copy",
            TransferPath::ZeroCopy => "zero_copy",
        }
    }
}

/// Which path carries the frame buffer.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TransferConfig {
    /// `network`, `loopback`, `shared_copy` or `zero_copy`.
    pub path: TransferPath,
}

impl Default for TransferConfig {
    fn default() -> Self {
        TransferConfig {
            path: TransferPath::Network,
        }
    }
}

/// A copying link: one buffer at a time; a buffer read back while the link
/// is busy waits in a one-slot mailbox and replaces an older waiting one
/// (the paper decouples reading from sending; we read it as latest-wins).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LinkConfig {
    /// Application-level bandwidth.
    pub bandwidth: Bandwidth,
}

impl Default for LinkConfig {
    fn default() -> Self {
        LinkConfig {
            bandwidth: bw("90MiB/s"),
        }
    }
}

fn loopback_default() -> LinkConfig {
    LinkConfig {
        bandwidth: bw("2Gbit/s"),
    }
}

fn shared_copy_default() -> LinkConfig {
    LinkConfig {
        bandwidth: bw("2.4Gbit/s"),
    }
}

/// Zero-copy triple buffering: SC swaps pointers under a lock.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ZeroCopyConfig {
    /// Lock retention per swap (paper: usually <= 0.1 ms).
    pub lock: Duration,
}

impl Default for ZeroCopyConfig {
    fn default() -> Self {
        ZeroCopyConfig {
            lock: Duration::us(100),
        }
    }
}

/// The display after the last client.
#[derive(Debug, Clone, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct DisplayConfig {
    /// Fixed latency from a finished frame to light (the paper counts none).
    pub latency: Duration,
}

/// How SC's G-buffer describes materials.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Materials {
    /// 32-bit diffuse + 32-bit specular coefficients per pixel.
    Coefficients,
    /// A material index per pixel (`index_bits`), looked up on FC.
    Indices,
}

/// Deferred shading split across the clients (paper 003 §6): SC renders
/// depth, normals and materials; FC shades every pixel for every light.
/// Bits per pixel: 32 depth + `normal_bits` + 64 (coefficients) or
/// `index_bits` (indices): 144 by default, 192 with 96-bit normals. When
/// enabled it replaces `bytes_per_pixel`.
///
/// Reading: the default cost per light per pixel, 0.39 ns, is Figure 8's
/// 6 ms FC frame with four point lights at 1600x1200 in stereo, all
/// counted as shading; SC's render time is left as given (the paper says
/// shading leaves SC but gives no number).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DeferredConfig {
    /// Use deferred shading.
    pub enabled: bool,
    /// Bits of the normal (48 = 3 x 16, or 96 = 3 x 32).
    pub normal_bits: u32,
    /// Coefficients or indices.
    pub materials: Materials,
    /// Bits of a material index (paper: not given; 16 assumed).
    pub index_bits: u32,
    /// Lights FC evaluates per pixel.
    pub lights: u32,
    /// FC's cost per light per pixel.
    pub per_light_pixel: Duration,
}

impl Default for DeferredConfig {
    fn default() -> Self {
        DeferredConfig {
            enabled: false,
            normal_bits: 48,
            materials: Materials::Coefficients,
            index_bits: 16,
            lights: 4,
            per_light_pixel: Duration::ps(390),
        }
    }
}

impl DeferredConfig {
    /// G-buffer bits per pixel.
    pub fn bits_per_pixel(&self) -> u64 {
        let materials = match self.materials {
            Materials::Coefficients => 64,
            Materials::Indices => self.index_bits as u64,
        };
        32 + self.normal_bits as u64 + materials
    }
}

fn bw(s: &str) -> Bandwidth {
    Bandwidth::parse(s).expect("built-in bandwidth")
}

impl MultiRateConfig {
    /// Pixels per frame (both eyes in stereo).
    pub fn frame_pixels(&self) -> u64 {
        let [w, h] = self.resolution;
        w as u64 * h as u64 * if self.stereo { 2 } else { 1 }
    }

    /// Bytes SC sends to FC per frame (doubled in stereo).
    pub fn frame_bytes(&self) -> u64 {
        if self.deferred.enabled {
            (self.frame_pixels() * self.deferred.bits_per_pixel()).div_ceil(8)
        } else {
            self.frame_pixels() * self.bytes_per_pixel as u64
        }
    }

    /// FC's shading time per frame under deferred shading (zero otherwise).
    pub fn deferred_shading(&self) -> Duration {
        if !self.deferred.enabled {
            return Duration::ZERO;
        }
        let n = self.frame_pixels().saturating_mul(self.deferred.lights as u64);
        Duration(n.saturating_mul(self.deferred.per_light_pixel.0))
    }
}
