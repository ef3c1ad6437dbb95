//! Scene descriptions: groups of objects sharing a mesh, their states, their
//! screen-space triangle sizes, and the draw order (paper 000 §4.5.2: state
//! sorting, Table 2; depth order and early-z, Table 3).

use serde::{Deserialize, Serialize};

use crate::components::distribution::Dist;
use crate::config::Bytes;

fn yes() -> bool {
    true
}

/// Order in which objects are drawn relative to depth (early-z efficiency).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DepthOrder {
    /// Nearest first: only the front layer is shaded.
    FrontToBack,
    /// Farthest first: every layer is shaded.
    BackToFront,
    /// Unsorted: layer k of d is shaded with probability 1/k.
    Random,
}

/// The order of a draw's triangle sizes (paper 000 §4.5.1: the bottleneck
/// moves inside one object when its triangles' sizes come in runs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum SizeOrder {
    /// Each triangle's size drawn independently.
    #[default]
    Random,
    /// The draw's sampled sizes sorted smallest first: a terrain or street
    /// in perspective drawn from the horizon towards the viewer.
    Ascending,
    /// Largest first (near to far).
    Descending,
}

/// Where a group's vertices live (paper 000 §4.5.3, Table 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum GeometryMemory {
    /// Video memory: the GPU fetches vertices without crossing the bus; an
    /// upload is copied at `bus.video_copy`.
    #[default]
    Video,
    /// AGP memory: the GPU fetches `vertex_bytes` per transformed vertex
    /// over the bus, sharing it with any copy running then; an upload is
    /// copied at `bus.bandwidth`.
    Agp,
}

impl GeometryMemory {
    /// Whether this is the default (left out of a resolved model).
    pub fn is_video(&self) -> bool {
        *self == GeometryMemory::Video
    }
}

/// Whether consecutive frames show the same view.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum View {
    /// The same triangle sizes every frame.
    Static,
    /// New triangle sizes every frame.
    Varying,
}

fn static_view() -> View {
    View::Static
}

/// Order in which objects are submitted relative to their state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StateOrder {
    /// As listed (instances of a group interleave their states).
    AsListed,
    /// Sorted by shader, texture, material (paper 000 Table 2).
    Sorted,
}

/// A scene of objects.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneWorkload {
    /// `static`: every frame shows the same view (the same triangle sizes,
    /// as when one viewpoint is rendered repeatedly); `varying`: sizes are
    /// drawn afresh every frame (a moving camera).
    #[serde(default = "static_view")]
    pub view: View,
    /// Optional synthetic scene after paper 000 Table 5: city, terrain, forest.
    #[serde(default)]
    pub preset: Option<String>,
    /// Fraction of the preset's objects and triangles (1.0 = paper size).
    #[serde(default = "one")]
    pub scale: f64,
    /// Average surfaces per pixel.
    #[serde(default = "one")]
    pub depth_complexity: f64,
    /// Depth order of drawing.
    #[serde(default = "random_order")]
    pub depth_order: DepthOrder,
    /// State order of drawing.
    #[serde(default = "as_listed")]
    pub state_order: StateOrder,
    /// Object groups (added after the preset's groups).
    #[serde(default)]
    pub groups: Vec<ObjectGroup>,
}

fn one() -> f64 {
    1.0
}
fn random_order() -> DepthOrder {
    DepthOrder::Random
}
fn as_listed() -> StateOrder {
    StateOrder::AsListed
}

/// A mesh: generated, loaded, or described only by its statistics.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum MeshRef {
    /// A generator or file spec: `grid:64x64`, `strip:8x8`, `random:T:V:SEED`, `file.obj`, `file.idx`.
    Spec(String),
    /// Statistics only: triangle count and transformed vertices per triangle.
    Stats {
        /// Triangles.
        triangles: u64,
        /// Actually transformed vertices per triangle (0..=3).
        acmr: f64,
    },
}

/// `count` objects sharing a mesh, with states cycled over the instances.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectGroup {
    /// Name, for traces and errors.
    pub name: String,
    /// Instances.
    #[serde(default = "one_u64")]
    pub count: u64,
    /// The mesh.
    pub mesh: MeshRef,
    /// Indexed draws go through the vertex cache; non-indexed ones transform 3 vertices per triangle.
    #[serde(default = "yes")]
    pub indexed: bool,
    /// Screen-space triangle area in pixels.
    pub triangle_pixels: Dist<f64>,
    /// Order of the sizes within a draw: `"random"` (default), `"ascending"`
    /// or `"descending"` (the draw's sampled sizes sorted).
    #[serde(default)]
    pub size_order: SizeOrder,
    /// Distinct shaders cycled over the instances.
    #[serde(default = "one_u64")]
    pub shaders: u64,
    /// Distinct textures cycled over the instances.
    #[serde(default = "one_u64")]
    pub textures: u64,
    /// Distinct materials cycled over the instances.
    #[serde(default = "one_u64")]
    pub materials: u64,
    /// Each instance sets its own transformation matrix (default true;
    /// not beside `changes`, whose `matrix` count replaces it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub matrix_per_object: Option<bool>,
    /// Dynamic geometry uploaded per instance per frame.
    #[serde(default)]
    pub geometry_upload: Bytes,
    /// Texture data uploaded per instance per frame.
    #[serde(default)]
    pub texture_upload: Bytes,
    /// Where the vertices live: `"video"` (default) or `"agp"` (fetched
    /// over the bus, Table 4).
    #[serde(default, skip_serializing_if = "GeometryMemory::is_video")]
    pub geometry_memory: GeometryMemory,
    /// Bytes fetched over the bus per transformed vertex when
    /// `geometry_memory = "agp"` (default 32: position, normal and one
    /// texture coordinate, interleaved).
    #[serde(default = "vertex_bytes", skip_serializing_if = "is_default_vertex_bytes")]
    pub vertex_bytes: Bytes,
    /// The group's draws as a measured state sequence instead of cycled
    /// ids: how many of its draws change each kind of state (paper 000
    /// Table 2 counts them per sort order). Replaces `shaders`,
    /// `textures`, `materials` and `matrix_per_object`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub changes: Option<StateChanges>,
}

/// How many of a group's `count` draws change each kind of state, in the
/// order drawn; the changes of a kind are spread evenly over the draws,
/// the first draw always among them (it sets the group's first state).
/// Paper 000 Table 2 gives these counts for four sort orders of one city
/// view; `docs/models.md`, "Table 2", says how they are read.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StateChanges {
    /// Draws that bind a shader (1 to `count`; default 1: one shader).
    #[serde(default = "one_u64")]
    pub shader: u64,
    /// Draws that bind a texture (1 to `count`).
    pub texture: u64,
    /// Draws that set material parameters (1 to `count`).
    pub material: u64,
    /// Draws that switch blending (alpha) state (0 to `count`; the frame
    /// starts opaque, and a group with 0 draws opaque: its first draw
    /// switches back if the draw before it blended).
    #[serde(default)]
    pub alpha: u64,
    /// Draws that set a transformation matrix (0 to `count`).
    pub matrix: u64,
    /// Whether the CPU sorts the draws into this order every frame:
    /// each draw then costs `cpu.sort_per_draw` more (a dynamic sort;
    /// `false`: presorted, or not sorted at all).
    #[serde(default)]
    pub sorted_each_frame: bool,
}

fn vertex_bytes() -> Bytes {
    Bytes(32)
}

fn is_default_vertex_bytes(b: &Bytes) -> bool {
    b.0 == 32
}

fn one_u64() -> u64 {
    1
}
