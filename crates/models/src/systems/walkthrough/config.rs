//! The walkthrough's model file: the frame pipeline's hardware sections
//! (`[cpu]`, `[bus]`, `[command_fifo]`, `[gpu]`, `[display]`, `[noise]`, `[variation]`,
//! the same structs and keys), plus the scene, the camera path, the
//! estimators and the level-of-detail policy (paper 000 §5-7). Lengths are
//! metres, angles degrees, speeds metres per second.

use serde::{Deserialize, Serialize};

use crate::config::Bytes;
use crate::engine::Duration;
use crate::scene::config::DepthOrder;
use crate::systems::frame_pipeline::config::{
    BusConfig, CommandFifoConfig, CpuConfig, DisplayConfig, Fidelity, GpuConfig, NoiseConfig, VariationConfig,
};

use super::timing::TimingMode;

/// The whole model.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WalkthroughConfig {
    /// Always `"walkthrough"`.
    pub system: String,
    /// A one-line description.
    #[serde(default)]
    pub description: String,
    /// How each frame is drawn by the frame pipeline: `"draw"` (default,
    /// one closed form per draw call) or `"triangle"`.
    #[serde(default = "draw_fidelity")]
    pub fidelity: Fidelity,
    /// Frames and seed.
    #[serde(default)]
    pub run: WalkRun,
    /// The application/driver thread (frame pipeline keys).
    #[serde(default)]
    pub cpu: CpuConfig,
    /// The bus (frame pipeline keys).
    #[serde(default)]
    pub bus: BusConfig,
    /// The command buffer (frame pipeline keys).
    #[serde(default)]
    pub command_fifo: CommandFifoConfig,
    /// The GPU (frame pipeline keys; unified shader pool by default).
    #[serde(default)]
    pub gpu: GpuConfig,
    /// The display; its refresh is the frame budget.
    #[serde(default)]
    pub display: DisplayConfig,
    /// System tasks (frame pipeline keys).
    #[serde(default)]
    pub noise: NoiseConfig,
    /// Per-frame variation of the CPU's and the GPU's work (frame pipeline
    /// keys, `[variation]`): the frames' own spread beside the system tasks
    /// (paper 000 §4.2, Figure 3). Every render takes it, the walk's
    /// frames and the preprocess's (whose fits then carry its mean, as
    /// measured fits do); system tasks stay out of the preprocess. Off
    /// unless given.
    #[serde(default, skip_serializing_if = "VariationConfig::is_off")]
    pub variation: VariationConfig,
    /// The scene.
    #[serde(default)]
    pub scene: SceneConfig,
    /// The camera path and view.
    #[serde(default)]
    pub camera: CameraConfig,
    /// The estimators and their preprocess.
    #[serde(default)]
    pub estimation: EstimationConfig,
    /// Level-of-detail selection.
    #[serde(default)]
    pub lod: LodConfig,
}

fn draw_fidelity() -> Fidelity {
    Fidelity::Draw
}

/// Run length.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WalkRun {
    /// Frames along the camera path (one per display refresh).
    pub frames: u64,
    /// Master seed of all RNG streams.
    pub seed: u64,
    /// Most memory the run may need (default 8 GiB).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_memory: Option<Bytes>,
}

impl Default for WalkRun {
    fn default() -> Self {
        WalkRun {
            frames: 1000,
            seed: 1,
            max_memory: None,
        }
    }
}

/// The scene: a preset after paper 000 Table 5 and/or listed objects.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SceneConfig {
    /// `"city"`, `"forest"` or `"terrain"` (paper 000 Table 5), or none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// Fraction of the preset's objects and triangles (1.0 = the paper's).
    pub scale: f64,
    /// Levels of detail of each preset object (1 = a single level).
    pub lod_levels: u32,
    /// Triangles of each level relative to the one before (0 < r < 1).
    pub lod_ratio: f64,
    /// Surfaces per pixel behind each object's own coverage, for the
    /// early-z pass probability (as the frame pipeline's `workload`).
    pub depth_complexity: f64,
    /// Drawing order relative to depth (early-z).
    pub depth_order: DepthOrder,
    /// View-cell size of a listed-object scene (metres; 0 = no view cells;
    /// presets set their own: the city 10 m).
    pub view_cell: f64,
    /// Objects added after the preset's.
    pub objects: Vec<ObjectConfig>,
}

impl Default for SceneConfig {
    fn default() -> Self {
        SceneConfig {
            preset: None,
            scale: 1.0,
            lod_levels: 4,
            lod_ratio: 0.5,
            depth_complexity: 1.0,
            depth_order: DepthOrder::FrontToBack,
            view_cell: 0.0,
            objects: Vec::new(),
        }
    }
}

/// One listed object: a box standing on the ground (its bounding sphere
/// encloses the box), with a chain of levels of detail.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectConfig {
    /// Name, for errors.
    pub name: String,
    /// Centre of the box's base, `[x, y, z]` (z up).
    pub position: [f64; 3],
    /// Box width (x), depth (y) and height (z) before rotation.
    pub size: [f64; 3],
    /// Rotation about the vertical axis, degrees.
    #[serde(default)]
    pub yaw: f64,
    /// Levels of detail, finest first.
    pub levels: Vec<LevelConfig>,
    /// Shader id.
    #[serde(default)]
    pub shader: u64,
    /// Texture id.
    #[serde(default)]
    pub texture: u64,
    /// Material id.
    #[serde(default)]
    pub material: u64,
    /// Surfaces of the object itself per covered pixel (leaves: > 1).
    #[serde(default = "one")]
    pub overdraw: f64,
    /// Spread (lognormal sigma) of the object's triangle sizes on screen.
    #[serde(default = "one")]
    pub size_sigma: f64,
}

fn one() -> f64 {
    1.0
}

/// One level of detail as mesh statistics.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LevelConfig {
    /// Triangles.
    pub triangles: u64,
    /// Actually transformed vertices per triangle under the vertex cache
    /// (0..=3; paper 000 Table 5's #tv/tri).
    pub acmr: f64,
    /// Distinct vertices (default triangles / 2 + 2, a closed mesh).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vertices: Option<u64>,
}

/// The camera path and the view.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CameraConfig {
    /// `"preset"` (the scene preset's own path: a street walk in the city,
    /// a forest path, a flight over the terrain), `"street"`, `"forest"`,
    /// `"flight"` or `"keyframes"`.
    pub path: String,
    /// Speed along the path, metres per second (0 = standing still).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub speed: Option<f64>,
    /// Keyframes of a `"keyframes"` path, visited in order at `speed`.
    pub keyframes: Vec<Keyframe>,
    /// Horizontal field of view, degrees.
    pub fov: f64,
    /// Viewport width, pixels.
    pub width: u32,
    /// Viewport height, pixels.
    pub height: u32,
    /// Near plane, metres.
    pub near: f64,
    /// Far plane, metres.
    pub far: f64,
    /// A street walk's looking around: the heading swings this many
    /// degrees to either side of the street's direction (0 to 180; 0
    /// looks straight along the street).
    #[serde(skip_serializing_if = "is_default_look_around")]
    pub look_around: f64,
    /// A street walk's looking around: the period of one swing to both
    /// sides and back.
    #[serde(skip_serializing_if = "is_default_look_period")]
    pub look_period: Duration,
}

/// Default `camera.look_around` (degrees to either side).
pub const DEFAULT_LOOK_AROUND: f64 = 25.0;
/// Default `camera.look_period` (5 s).
pub const DEFAULT_LOOK_PERIOD: Duration = Duration(5_000_000_000_000);

fn is_default_look_around(v: &f64) -> bool {
    *v == DEFAULT_LOOK_AROUND
}
fn is_default_look_period(d: &Duration) -> bool {
    *d == DEFAULT_LOOK_PERIOD
}

impl Default for CameraConfig {
    fn default() -> Self {
        CameraConfig {
            path: "preset".into(),
            speed: None,
            keyframes: Vec::new(),
            fov: 60.0,
            width: 1024,
            height: 768,
            near: 0.5,
            far: 1500.0,
            look_around: DEFAULT_LOOK_AROUND,
            look_period: DEFAULT_LOOK_PERIOD,
        }
    }
}

/// A camera keyframe.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Keyframe {
    /// Eye position `[x, y, z]`.
    pub position: [f64; 3],
    /// Heading, degrees (0 = +x, counter-clockwise).
    #[serde(default)]
    pub yaw: f64,
    /// Pitch, degrees (positive looks up).
    #[serde(default)]
    pub pitch: f64,
}

/// The estimators (paper 000 §5) and their preprocess.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EstimationConfig {
    /// Estimators to run: any of `h1`, `h2`, `h3`, `h4`, `pos`, `vcs`,
    /// `pvc` (default: the per-viewpoint five; `vcs` and `pvc` need view
    /// cells).
    pub estimators: Vec<String>,
    /// Single-object renders the heuristics' constants are fitted to.
    pub fit_samples: u64,
    /// How those renders' objects and views are chosen (paper 000 §7.2
    /// says only "10,000 test measurements of different objects"):
    /// `"log_uniform"` (default) or `"walk"`.
    #[serde(skip_serializing_if = "FitViews::is_default")]
    pub fit_views: FitViews,
    /// Copies of the object drawn in each single-object render (its state
    /// set once), the time divided among them (paper 000 §7.1 rendered
    /// each timed object several times between the two readings).
    pub repeats: u32,
    /// Per-object sampling tables.
    pub pos: PosConfig,
    /// How the preprocess's renders are timed: `"timestamps"` (exact GPU
    /// time, default) or `"cpu_clock"` (a CPU clock around a synchronising
    /// finish, paper 000 §6.1; see `timing.rs`).
    #[serde(skip_serializing_if = "is_timestamps")]
    pub timing: TimingMode,
    /// `cpu_clock`: the finish's round trip added to each reading.
    #[serde(skip_serializing_if = "is_default_overhead")]
    pub clock_overhead: Duration,
    /// `cpu_clock`: standard deviation of each reading's zero-mean normal
    /// jitter.
    #[serde(skip_serializing_if = "is_default_noise")]
    pub clock_noise: Duration,
    /// View-cell sampling (`vcs`) and per-view-cell estimation (`pvc`).
    #[serde(skip_serializing_if = "ViewCellEstimation::is_default")]
    pub view_cells: ViewCellEstimation,
}

/// Default `estimation.clock_overhead` (20 us).
pub const DEFAULT_CLOCK_OVERHEAD: Duration = Duration(20_000_000);
/// Default `estimation.clock_noise` (5 us).
pub const DEFAULT_CLOCK_NOISE: Duration = Duration(5_000_000);

fn is_timestamps(t: &TimingMode) -> bool {
    *t == TimingMode::Timestamps
}
fn is_default_overhead(d: &Duration) -> bool {
    *d == DEFAULT_CLOCK_OVERHEAD
}
fn is_default_noise(d: &Duration) -> bool {
    *d == DEFAULT_CLOCK_NOISE
}

/// How the heuristics' single-object renders choose their objects and
/// views (`estimation.fit_views`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FitViews {
    /// A random object of the scene at a random level, seen from a random
    /// direction at a size log-uniform from a one-pixel disk to the whole
    /// image: every size weighted alike.
    #[default]
    LogUniform,
    /// Objects as a walk sees them: a second walk of the camera path's
    /// kind (its own random turns, not the recorded path; a moving camera
    /// on a procedural path), a random pose on it, a random object that
    /// pose draws (its view cell's set, the frustum) at a random level,
    /// with the projection it has there.
    Walk,
}

impl FitViews {
    fn is_default(&self) -> bool {
        *self == FitViews::LogUniform
    }
}

/// The view-cell estimators' preprocess (paper 000 §5.1, §5.2): view
/// directions are discretized into `directions` equal sectors of heading
/// (bin k centred on k · 360° / directions).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ViewCellEstimation {
    /// Discretized view directions per cell (heading sectors).
    pub directions: u32,
    /// `vcs`: sample views rendered per cell and direction (their maximum
    /// is the estimate).
    pub samples: u32,
    /// `pvc`: how each object's table entry is chosen (`bound` or `point`).
    #[serde(skip_serializing_if = "PvcReading::is_default")]
    pub pvc: PvcReading,
}

/// How per-view-cell estimation (`pvc`, paper 000 §5.2) picks each
/// object's entry of its pos table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum PvcReading {
    /// A bound over every view of the cell and heading sector: the largest
    /// screen size the object can take from the cell, and the table's
    /// largest entry up to that size over every direction it is seen from
    /// (never below pos on any frame of the cell).
    #[default]
    Bound,
    /// The paper's words: the point of the cell's boundary where the
    /// object's bounding sphere appears largest in the frustum of the
    /// direction (the sector's centre heading, the path's middle pitch),
    /// and the table looked up there as pos would (size and direction of
    /// that point). Found by searching a grid of points on the cell's faces.
    Point,
}

impl PvcReading {
    fn is_default(&self) -> bool {
        *self == PvcReading::Bound
    }
}

impl Default for ViewCellEstimation {
    fn default() -> Self {
        ViewCellEstimation {
            directions: 8,
            samples: 16,
            pvc: PvcReading::Bound,
        }
    }
}

impl ViewCellEstimation {
    fn is_default(&self) -> bool {
        *self == ViewCellEstimation::default()
    }
}

impl Default for EstimationConfig {
    fn default() -> Self {
        EstimationConfig {
            estimators: super::estimators::ESTIMATORS[..5]
                .iter()
                .map(|s| s.to_string())
                .collect(),
            fit_samples: 10_000,
            fit_views: FitViews::LogUniform,
            repeats: 4,
            pos: PosConfig::default(),
            timing: TimingMode::Timestamps,
            clock_overhead: DEFAULT_CLOCK_OVERHEAD,
            clock_noise: DEFAULT_CLOCK_NOISE,
            view_cells: ViewCellEstimation::default(),
        }
    }
}

/// The per-object sampling (pos) tables over the angles α, γ, φ.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PosConfig {
    /// Sizes α (log-spaced from one pixel to the whole screen).
    pub alpha_steps: u32,
    /// Directions γ around the object (azimuth).
    pub gamma_steps: u32,
    /// Elevations φ (from `phi_min` to `phi_max`).
    pub phi_steps: u32,
    /// Lowest elevation sampled, degrees.
    pub phi_min: f64,
    /// Highest elevation sampled, degrees.
    pub phi_max: f64,
    /// Pruning: once the renders of one α differ by less than this share
    /// over all directions, smaller α are sampled in one direction only
    /// (the object is geometry-limited there).
    pub prune_tolerance: f64,
}

impl Default for PosConfig {
    fn default() -> Self {
        PosConfig {
            alpha_steps: 12,
            gamma_steps: 8,
            phi_steps: 4,
            phi_min: -30.0,
            phi_max: 60.0,
            prune_tolerance: 0.01,
        }
    }
}

/// Level-of-detail selection and the soft real-time frame (paper 001's
/// reactive and predictive selection, paper 000 §6.4's conditional branch;
/// `src/systems/walkthrough/lod.rs` and `branch.rs`). Every key is read by
/// the policy named; the others ignore it.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LodConfig {
    /// `"none"` (every object at its finest level), `"reactive"` (a global
    /// detail level steered by past frame times), `"predictive"` (per frame
    /// a cost/benefit knapsack over every visible object's levels) or
    /// `"predictive+branch"` (predictive, plus the GPU's conditional branch
    /// to coarser levels when the frame runs late).
    pub policy: String,
    /// Share of the frame budget (one display refresh) kept free as a
    /// safety margin: the policies aim at `refresh x (1 - margin)`.
    pub margin: f64,
    /// Predictive: the estimator giving each (object, level)'s cost (`h1`,
    /// `h2`, `h3`, `h4` or `pos`; it must be in `estimation.estimators`).
    pub estimator: String,
    /// Predictive: `"greedy"` (the lecture's, from scratch every frame) or
    /// `"incremental"` (from the previous frame's selection).
    pub algorithm: String,
    /// Reactive: frames of rendering-time history averaged into the
    /// prediction of the next frame.
    pub history: u32,
    /// Reactive: the correction's exponent: the detail level (triangles
    /// allowed per pixel of an object's disk) is multiplied by
    /// `(target / predicted)^gain` every frame.
    pub gain: f64,
    /// Benefit: the accuracy term `1 - c / triangles` of paper 001
    /// (Funkhouser & Séquin's flat-shading reading), `c` in triangles.
    pub accuracy_triangles: f64,
    /// Benefit: objects within this angle of the view axis are in focus
    /// (paper 001: b1 = 15 degrees).
    pub focus_angle: f64,
    /// Benefit: beyond `focus_angle` the benefit falls as
    /// `exp(-(angle - focus_angle) / focus_falloff)`, degrees.
    pub focus_falloff: f64,
    /// Benefit: angular speed across the view (degrees per second) at which
    /// the velocity term halves: `1 / (1 + speed / velocity_half)`.
    pub velocity_half: f64,
    /// Benefit: hysteresis weight h: `(1 - h) + h / (1 + |L - L'|)` with L'
    /// the object's level in the frame before (0 = none).
    pub hysteresis: f64,
    /// Branch: objects per frame given coarser alternatives (the costliest
    /// drawn objects farther than `branch_min_distance` that have a
    /// cheaper coarser level).
    pub branch_objects: u32,
    /// Branch: coarser alternatives per switchable object.
    pub branch_levels: u32,
    /// Branch: objects nearer than this (metres) are never switched (to
    /// reduce popping, paper 000 §6.5).
    pub branch_min_distance: f64,
}

impl Default for LodConfig {
    fn default() -> Self {
        LodConfig {
            policy: "none".into(),
            margin: 0.1,
            estimator: "h4".into(),
            algorithm: "greedy".into(),
            history: 4,
            gain: 1.0,
            accuracy_triangles: 32.0,
            focus_angle: 15.0,
            focus_falloff: 20.0,
            velocity_half: 90.0,
            hysteresis: 0.2,
            branch_objects: 4,
            branch_levels: 2,
            branch_min_distance: 20.0,
        }
    }
}
