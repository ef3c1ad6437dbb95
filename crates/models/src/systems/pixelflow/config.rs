//! The PixelFlow model file (Olano, Cohen, Mine & Bishop, paper 002 §3-6):
//! node counts and roles, display and region sizes, the primitive footprint
//! behind the overlap factor, and the per-primitive, per-byte and per-region
//! costs of the three software architectures. Durations carry units
//! (`"1.85us"`); unknown keys are errors.

use serde::{Deserialize, Serialize};

use crate::engine::Duration;

/// How the system is evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Fidelity {
    /// Events per (node, region): geometry, rasterization, composition,
    /// shading, load.
    Event,
    /// Only the closed forms of §4-6 (no events).
    Analytic,
}

/// The software architecture (paper §4, §5, §6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Architecture {
    /// §4: frame pipelining, bucket sort, deferred shading, virtual buffer.
    Standard,
    /// §5: a sorting pass, then instructions generated region by region.
    Presort,
    /// §6: no texturing, completely instanced frame buffer, multi-pass
    /// supersampling.
    Nontex,
}

/// How primitives fall into screen regions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Placement {
    /// Expected counts: every node gets n / n_rast primitives and
    /// round(primitives x overlap) region entries spread evenly over the
    /// regions (the closed forms' assumption).
    Uniform,
    /// Every primitive is a `w x h` box at a uniformly random position
    /// (wrapping around the screen edges, so the expected count of regions
    /// is exactly the overlap factor) and binned by its bounding box.
    Random,
    /// Like `random`, but a fraction `cluster_fraction` of the primitives
    /// fall uniformly inside the region-aligned rectangle `cluster`
    /// (uneven region load).
    Clustered,
}

/// A width x height in pixels.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Size {
    /// Width in pixels.
    pub width: f64,
    /// Height in pixels.
    pub height: f64,
}

/// The whole model.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PixelFlowConfig {
    /// Always `"pixelflow"`.
    pub system: String,
    /// A one-line description.
    #[serde(default)]
    pub description: String,
    /// `event` (default) or `analytic`.
    #[serde(default = "default_fidelity")]
    pub fidelity: Fidelity,
    /// `standard`, `presort` or `nontex`.
    pub architecture: Architecture,
    /// PixelFlow nodes, the frame-buffer node included.
    pub nodes: u32,
    /// Nodes that shade (texturing architectures); the rest minus the frame
    /// buffer rasterize. The non-texturing system rasterizes on all nodes but
    /// the frame buffer and ignores this.
    pub shading_nodes: u32,
    /// Antialiasing samples per pixel (1 = no antialiasing).
    pub samples: u32,
    /// Primitives per frame.
    pub primitives: u64,
    /// Frames in a row (standard and presort; nontex runs one). The first
    /// starts on an idle machine; later frames start as soon as the
    /// architecture allows (standard: two instruction buffers).
    #[serde(default = "default_frames")]
    pub frames: u32,
    /// Seed (`run.seed`, as in every system; only `random` and `clustered`
    /// placement draw numbers).
    #[serde(default)]
    pub run: RunConfig,
    /// Where primitives fall.
    #[serde(default = "default_placement")]
    pub placement: Placement,
    /// Cluster rectangle (pixels, from the top-left corner) for `clustered`.
    #[serde(default)]
    pub cluster: Option<ClusterConfig>,
    /// Load imbalance across the rasterizing nodes (what-if, event fidelity
    /// only; the closed forms assume balance): `s` in `[0, 1)` gives node `r`
    /// of `n` a share of the primitives proportional to
    /// `1 + s (1 - 2r / (n - 1))`, so the first node gets `1 + s` times the
    /// mean and the last `1 - s`; 0 (default) is the balanced round robin.
    #[serde(default)]
    pub node_skew: f64,
    /// Display size (640 x 512).
    pub display: Size,
    /// Screen region: the pixel-processor array (128 x 64).
    pub region: Size,
    /// Average primitive bounding box without antialiasing (10 x 10).
    pub primitive: Size,
    /// Average primitive bounding box the single-pass supersampling
    /// architectures bin with when `samples > 1` (see the docs for the
    /// reading: 20 x 20 gives the paper's overlap of 1.52).
    pub aa_primitive: Size,
    /// Costs of the deferred-shading architectures (§4-5).
    pub deferred: DeferredCosts,
    /// Costs of the non-texturing architecture (§6).
    pub nontex: NontexCosts,
}

/// Run settings.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RunConfig {
    /// Master seed of the RNG streams.
    pub seed: u64,
}

impl Default for RunConfig {
    fn default() -> Self {
        RunConfig { seed: 1 }
    }
}

/// Cluster of primitives for `placement = "clustered"`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClusterConfig {
    /// Left edge, pixels.
    pub x: f64,
    /// Top edge, pixels.
    pub y: f64,
    /// Width, pixels.
    pub width: f64,
    /// Height, pixels.
    pub height: f64,
    /// Fraction of the primitives inside the rectangle (0..1).
    pub fraction: f64,
}

/// §4 and §5 constants.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeferredCosts {
    /// Frame start-up cost of a geometry pass (0.1 ms).
    pub t_overhead: Duration,
    /// Geometry per primitive, bucket sort included (1.85 us).
    pub t_trans: Duration,
    /// Rasterization per primitive per region it falls in (0.83 us).
    pub t_rast_per_prim: Duration,
    /// Depth-composite one byte of every pixel of a region (1.28 us).
    pub t_comp_byte: Duration,
    /// Bytes of appearance parameters composited (21).
    pub appearance_bytes: u32,
    /// Texture address computation per region (15.4 us).
    pub t_shade_address: Duration,
    /// Worst-case mip-map lookup per region (95 us).
    pub t_shade_texture: Duration,
    /// Bytes of color sent from a shader to the frame buffer per pixel (3),
    /// over the network's other direction.
    pub color_bytes: u32,
    /// Copy of one region's color into frame-buffer memory (52 us).
    pub t_load: Duration,
    /// Pre-sorting: first (sorting) pass per primitive (0.74 us).
    pub t_first_pass: Duration,
    /// Pre-sorting: second pass, instruction generation per primitive (1.45 us).
    pub t_gen_each: Duration,
}

/// §6 constants.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NontexCosts {
    /// Frame start-up cost (0.1 ms, as §4).
    pub t_overhead: Duration,
    /// Geometry per primitive, lighting included (0.87 us).
    pub t_trans: Duration,
    /// Rasterization per primitive per region (0.62 us).
    pub t_rast_per_prim: Duration,
    /// Depth-composite one byte of every pixel of a region (1.28 us).
    pub t_comp_byte: Duration,
    /// Bytes composited per pixel: 4 of z and 3 of color (7; 40 x 7 x
    /// 1.28 us = 358 us, the paper's "360 us").
    pub composite_bytes: u32,
    /// Copy of one region's color into frame-buffer memory (52 us).
    pub t_load: Duration,
    /// Primitives per geometry -> rasterization hand-over (the fine-grained
    /// pipelining of §6; event fidelity only).
    pub batch_primitives: u64,
}

fn default_fidelity() -> Fidelity {
    Fidelity::Event
}
fn default_frames() -> u32 {
    1
}
fn default_placement() -> Placement {
    Placement::Uniform
}

impl Size {
    /// Area in pixels.
    pub fn area(&self) -> f64 {
        self.width * self.height
    }
}

impl PixelFlowConfig {
    /// Nodes that rasterize: all but the frame buffer and, for the
    /// texturing architectures, the shaders.
    pub fn rasterizers(&self) -> u32 {
        match self.architecture {
            Architecture::Nontex => self.nodes.saturating_sub(1),
            _ => self.nodes.saturating_sub(self.shading_nodes.saturating_add(1)),
        }
    }

    /// Nodes that shade (0 for the non-texturing system).
    pub fn shaders(&self) -> u32 {
        match self.architecture {
            Architecture::Nontex => 0,
            _ => self.shading_nodes,
        }
    }

    /// Columns x rows of screen regions (partial regions at the edges count).
    pub fn region_grid(&self) -> (u32, u32) {
        let c = (self.display.width / self.region.width).ceil() as u32;
        let r = (self.display.height / self.region.height).ceil() as u32;
        (c, r)
    }

    /// Number of screen regions (40 for 640 x 512 and 128 x 64).
    pub fn regions(&self) -> u32 {
        let (c, r) = self.region_grid();
        c.saturating_mul(r)
    }

    /// The primitive footprint binned with: `aa_primitive` for the
    /// single-pass supersampling architectures when `samples > 1`,
    /// `primitive` otherwise (§6 rasterizes one sample per pass).
    pub fn footprint(&self) -> Size {
        if self.samples > 1 && self.architecture != Architecture::Nontex {
            self.aa_primitive
        } else {
            self.primitive
        }
    }

    /// Eyles's bin-replication factor (w+W)(h+H)/(W H) (§4).
    pub fn overlap(&self) -> f64 {
        let p = self.footprint();
        (p.width + self.region.width) * (p.height + self.region.height) / self.region.area()
    }
}
