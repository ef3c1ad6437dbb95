//! The frame pipeline's model file: every cost and capacity of the CPU
//! thread, command FIFO, GPU stages, display and system noise, plus the
//! workload. Durations carry units (`"1.85us"`); unknown keys are errors.
//!
//! The cost structure follows paper 000 §4 (RT = ETsystem + max(ETcpu,
//! ETgpu), with CPU non-rendering, rendering and memory-management terms and
//! GPU per-frame, per-primitive-group, per-vertex and per-fragment terms).

use serde::{Deserialize, Serialize};

use crate::components::distribution::Dist;
use crate::components::fifo::FifoUnit;
pub use crate::components::frame_generation::FrameGenerationConfig;
pub use crate::components::frame_pacing::PacingConfig;
use crate::components::noise::NoiseTarget;
pub use crate::components::swap_chain::DisplayConfig;
use crate::components::vertex_cache::CachePolicy;
use crate::config::{Bandwidth, Bytes, Rate};
use crate::engine::Duration;
use crate::scene::config::GeometryMemory;
pub use crate::scene::config::SceneWorkload;

/// How finely the GPU's geometry and fragment work is simulated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Fidelity {
    /// Each triangle travels geometry -> FIFO -> fragment as events.
    Triangle,
    /// One closed form per draw call from the same parameters.
    Draw,
}

/// The whole model.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FramePipelineConfig {
    /// Always `"frame_pipeline"`.
    #[serde(default = "default_system")]
    pub system: String,
    /// A one-line description.
    #[serde(default)]
    pub description: String,
    /// Simulation fidelity.
    #[serde(default = "default_fidelity")]
    pub fidelity: Fidelity,
    /// Run length and seed.
    #[serde(default)]
    pub run: RunConfig,
    /// The application/driver thread.
    #[serde(default)]
    pub cpu: CpuConfig,
    /// The bus uploads cross.
    #[serde(default)]
    pub bus: BusConfig,
    /// CPU -> GPU command buffer.
    #[serde(default)]
    pub command_fifo: CommandFifoConfig,
    /// The GPU.
    #[serde(default)]
    pub gpu: GpuConfig,
    /// Swap chain and display.
    #[serde(default)]
    pub display: DisplayConfig,
    /// System tasks.
    #[serde(default)]
    pub noise: NoiseConfig,
    /// Per-frame variation of the CPU's and the GPU's times (none unless
    /// given; written to the resolved model only when given).
    #[serde(default, skip_serializing_if = "VariationConfig::is_off")]
    pub variation: VariationConfig,
    /// Frame limiter and low-latency pacer (off unless given; written to the
    /// resolved model only when given).
    #[serde(default, skip_serializing_if = "PacingConfig::is_off")]
    pub pacing: PacingConfig,
    /// Frame generation by interpolation (off unless enabled; written to the
    /// resolved model only when enabled).
    #[serde(default, skip_serializing_if = "FrameGenerationConfig::is_off")]
    pub frame_generation: FrameGenerationConfig,
    /// What is rendered.
    pub workload: WorkloadConfig,
}

fn default_system() -> String {
    "frame_pipeline".into()
}
fn default_fidelity() -> Fidelity {
    Fidelity::Triangle
}

/// Run length.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RunConfig {
    /// Frames to simulate (each ends displayed or dropped).
    pub frames: u64,
    /// Leading frames left out of the metrics.
    pub warmup_frames: u64,
    /// Master seed of all RNG streams.
    pub seed: u64,
    /// Optional cap on handled events (a safety net for huge models).
    pub max_events: Option<u64>,
    /// Optional end of simulated time: the run stops there even if frames remain.
    pub until: Option<Duration>,
    /// Most memory the run may need, estimated from the inputs before
    /// simulating (default [`crate::limits::DEFAULT_MAX_MEMORY`], 8 GiB).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_memory: Option<Bytes>,
}

impl Default for RunConfig {
    fn default() -> Self {
        RunConfig {
            frames: 600,
            warmup_frames: 0,
            seed: 1,
            max_events: None,
            until: None,
            max_memory: None,
        }
    }
}

/// Costs of a state change by kind (paper 000 §4.5: shader > texture >
/// material > matrix).
#[derive(Debug, Clone, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct StateCosts {
    /// Vertex/fragment program bind.
    pub shader: Duration,
    /// Texture bind.
    pub texture: Duration,
    /// Material parameters.
    pub material: Duration,
    /// Transformation matrix.
    pub matrix: Duration,
    /// Blending (alpha) state.
    #[serde(skip_serializing_if = "Duration::is_zero")]
    pub alpha: Duration,
}

/// The CPU thread's costs.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CpuConfig {
    /// Reading input at the start of a frame.
    pub input_sampling: Duration,
    /// Non-rendering work per frame (AI, physics, ...).
    pub non_render: Dist<Duration>,
    /// Traversal and culling per object.
    pub per_object: Duration,
    /// Driver cost per draw call.
    pub per_draw: Duration,
    /// Driver cost per state change.
    pub state_change: StateCosts,
    /// Sorting cost per draw, paid by the draws of a group sorted into
    /// its order every frame (`changes.sorted_each_frame`; paper 000
    /// Table 2's dynamic sorts).
    #[serde(skip_serializing_if = "Duration::is_zero")]
    pub sort_per_draw: Duration,
    /// API cost of the clear command.
    pub clear: Duration,
    /// API cost of the swap (present) command.
    pub swap: Duration,
    /// Frames the CPU may run ahead of the GPU (frames in flight, >= 1).
    pub max_frames_ahead: u32,
}

impl Default for CpuConfig {
    fn default() -> Self {
        CpuConfig {
            input_sampling: Duration::ZERO,
            non_render: Dist::Const { value: Duration::ZERO },
            per_object: Duration::ZERO,
            per_draw: Duration::ZERO,
            state_change: StateCosts::default(),
            sort_per_draw: Duration::ZERO,
            clear: Duration::ZERO,
            swap: Duration::ZERO,
            max_frames_ahead: 2,
        }
    }
}

impl FramePipelineConfig {
    /// Reads the model from its `table` (with `--set` patches applied), as
    /// [`crate::config::deserialize`] does; one function, so the crates
    /// above compile this model's reader once, here, not again each.
    pub fn from_table(
        table: &toml::Table,
        src: &crate::config::ModelSource,
    ) -> Result<Self, crate::config::ConfigError> {
        crate::config::deserialize(table, src)
    }

    /// The model as TOML text (no header), for the crates above to write
    /// without compiling its writer again.
    pub fn to_toml(&self) -> Result<String, toml::ser::Error> {
        toml::to_string(self)
    }
}

/// The bus uploads cross (paper 000 §4.3.1 memory management).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BusConfig {
    /// The bus's bandwidth: a copy into AGP memory runs at it, and the
    /// GPU's vertex fetch from AGP memory shares it with any copy running
    /// then ([`crate::components::shared_bus`]).
    pub bandwidth: Bandwidth,
    /// The rate of a copy into video memory (a group with
    /// `geometry_memory = "video"`, the default); unset, `bandwidth`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub video_copy: Option<Bandwidth>,
}

impl BusConfig {
    /// The rate a copy into `memory` runs at alone.
    pub fn copy_bandwidth(&self, memory: GeometryMemory) -> &Bandwidth {
        match (memory, &self.video_copy) {
            (GeometryMemory::Video, Some(v)) => v,
            _ => &self.bandwidth,
        }
    }
}

impl Default for BusConfig {
    fn default() -> Self {
        BusConfig {
            bandwidth: Bandwidth::parse("4GB/s").expect("valid literal"),
            video_copy: None,
        }
    }
}

/// Command sizes, for byte-limited FIFOs.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CommandBytes {
    /// A draw call.
    pub draw: Bytes,
    /// A state change.
    pub state: Bytes,
    /// Clear.
    pub clear: Bytes,
    /// Swap.
    pub swap: Bytes,
    /// An upload command (the data itself goes over the bus).
    pub upload: Bytes,
}

impl Default for CommandBytes {
    fn default() -> Self {
        CommandBytes {
            draw: Bytes(32),
            state: Bytes(16),
            clear: Bytes(16),
            swap: Bytes(16),
            upload: Bytes(32),
        }
    }
}

/// The CPU -> GPU command buffer (paper 000 §4.4).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CommandFifoConfig {
    /// Capacity in `unit`s; 0 = rendezvous (the CPU waits until the GPU takes each batch).
    pub capacity: u64,
    /// What the capacity counts.
    pub unit: FifoUnit,
    /// Command sizes (used when `unit = "bytes"`).
    pub bytes: CommandBytes,
}

impl Default for CommandFifoConfig {
    fn default() -> Self {
        CommandFifoConfig {
            capacity: 1024,
            unit: FifoUnit::Entries,
            bytes: CommandBytes::default(),
        }
    }
}

/// The GPU.
#[derive(Debug, Clone, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct GpuConfig {
    /// Front-end cost per command.
    pub command: Duration,
    /// Front-end cost per state change.
    pub state_change: StateCosts,
    /// Whether a draw's state changes wait for the geometry stage to
    /// finish the draw before (a pipeline bubble): their
    /// `gpu.state_change` time then runs while that stage waits instead of
    /// beside its work (paper 000 §4.5, state setup as a stage of the
    /// pipeline; Table 2); the commands' `gpu.command` cost still overlaps.
    /// Default false: they overlap the draw before, as any command does.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub state_change_stalls: bool,
    /// Clearing the frame buffer.
    pub clear: Duration,
    /// The swap at the end of a frame.
    pub swap: Duration,
    /// `"unified"` (vertex and fragment shading share one pool of shader
    /// cores) or `"split"` (dedicated geometry and fragment units).
    pub architecture: Architecture,
    /// Unified: cores in the shader pool (default 16). Costs stay the time
    /// of the whole pool; the count sets how finely it is divided.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shader_cores: Option<u32>,
    /// Unified: how the pool is divided while vertex and fragment work both
    /// wait: `"fair"` (default), `"vertex_first"`, `"fragment_first"` or
    /// `"reserved"` (with `vertex_cores`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scheduling: Option<SchedulingPolicy>,
    /// Unified with `scheduling = "reserved"`: cores that serve only vertex
    /// work; the rest serve only fragments.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vertex_cores: Option<u32>,
    /// Vertex processing.
    pub geometry: GeometryConfig,
    /// Rasterization and fragment processing.
    pub fragment: FragmentConfig,
}

/// The GPU's shader architecture.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Architecture {
    /// One pool of shader cores runs vertex and fragment shading (every GPU
    /// since about 2006); fixed-function setup, depth test and blending keep
    /// their own rates ([`crate::components::shader_pool`]).
    #[default]
    Unified,
    /// A geometry unit and a fragment unit, each with its own rate, joined by
    /// the triangle FIFO (the GeForce3 of paper 000 §4.5).
    Split,
}

/// How a unified pool is divided (see [`crate::components::shader_pool::Scheduling`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum SchedulingPolicy {
    /// Half each while both wait.
    #[default]
    Fair,
    /// Vertex work first.
    VertexFirst,
    /// Fragment work first.
    FragmentFirst,
    /// `gpu.vertex_cores` serve only vertices, the rest only fragments.
    Reserved,
}

/// Cores of a unified pool when `gpu.shader_cores` is not given.
pub const DEFAULT_SHADER_CORES: u32 = 16;

impl GpuConfig {
    /// The unified pool's cores and policy; `None` for the split architecture.
    pub fn pool(&self) -> Option<(u32, crate::components::shader_pool::Scheduling)> {
        use crate::components::shader_pool::Scheduling as S;
        if self.architecture == Architecture::Split {
            return None;
        }
        let cores = self.shader_cores.unwrap_or(DEFAULT_SHADER_CORES);
        let policy = match self.scheduling.unwrap_or_default() {
            SchedulingPolicy::Fair => S::Fair,
            SchedulingPolicy::VertexFirst => S::VertexFirst,
            SchedulingPolicy::FragmentFirst => S::FragmentFirst,
            SchedulingPolicy::Reserved => S::Reserved {
                vertex_cores: self.vertex_cores.unwrap_or(cores / 2),
            },
        };
        Some((cores, policy))
    }

    /// Checks the architecture keys against each other: `(key, message)`.
    pub fn check_architecture(&self) -> Result<(), (&'static str, String)> {
        if self.architecture == Architecture::Split {
            for (key, given) in [
                ("gpu.shader_cores", self.shader_cores.is_some()),
                ("gpu.scheduling", self.scheduling.is_some()),
                ("gpu.vertex_cores", self.vertex_cores.is_some()),
            ] {
                if given {
                    return Err((
                        key,
                        "applies only to gpu.architecture = \"unified\" (this model is \"split\")".into(),
                    ));
                }
            }
            return Ok(());
        }
        let cores = self.shader_cores.unwrap_or(DEFAULT_SHADER_CORES);
        if !(1..=1 << 20).contains(&cores) {
            return Err((
                "gpu.shader_cores",
                format!("must be between 1 and 1048576, got {cores}"),
            ));
        }
        let reserved = self.scheduling == Some(SchedulingPolicy::Reserved);
        match self.vertex_cores {
            Some(_) if !reserved => Err((
                "gpu.vertex_cores",
                "applies only to gpu.scheduling = \"reserved\"".into(),
            )),
            Some(k) if k == 0 || k >= cores => Err((
                "gpu.vertex_cores",
                format!("must be between 1 and gpu.shader_cores - 1 ({}), got {k}", cores - 1),
            )),
            None if reserved && cores < 2 => Err((
                "gpu.shader_cores",
                "scheduling = \"reserved\" needs at least 2 cores (some for vertices, some for fragments)".into(),
            )),
            _ => Ok(()),
        }
    }
}

/// The geometry stage: index fetch -> vertex cache -> vertex shader per
/// actually transformed vertex -> triangle setup (paper 000 §4.5).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GeometryConfig {
    /// Per index fetched.
    pub index_fetch: Duration,
    /// Per actually transformed vertex.
    pub vertex_shader: Duration,
    /// Per triangle.
    pub triangle_setup: Duration,
    /// Post-transform vertex cache.
    pub vertex_cache: CachePolicy,
}

impl Default for GeometryConfig {
    fn default() -> Self {
        GeometryConfig {
            index_fetch: Duration::ZERO,
            vertex_shader: Duration::ZERO,
            triangle_setup: Duration::ZERO,
            vertex_cache: CachePolicy::Fifo(24),
        }
    }
}

/// How triangles reach the fragment stage.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Binning {
    /// Immediate mode: each triangle goes through the triangle FIFO as soon
    /// as its geometry is done, so the two stages overlap (paper 000 §4.5.1).
    #[default]
    Off,
    /// Sort-middle: all of a draw's triangles are transformed and binned
    /// before its first fragment is shaded, and the next draw's geometry
    /// waits until the bins are drained; the stages never overlap and a
    /// draw costs G + F. `fifo_depth` is unused (the bins hold the draw).
    /// Software rasterizers such as Mesa's llvmpipe work this way (study H2,
    /// docs/measurements/).
    Draw,
}

/// The fragment stage and the triangle FIFO in front of it (§4.5.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FragmentConfig {
    /// Triangles the FIFO between geometry and fragment holds (0 = direct hand-off).
    pub fifo_depth: u32,
    /// `"off"` (immediate: triangles stream through the FIFO) or `"draw"`
    /// (sort-middle: a draw's fragments start after all its geometry).
    pub binning: Binning,
    /// Per shaded fragment.
    pub per_fragment: Duration,
    /// Per fragment rejected by the early depth test.
    pub per_rejected_fragment: Duration,
    /// Fixed-function time (rasterization, depth test, blending) per shaded
    /// fragment. Unified: runs beside the shader work (`per_fragment`, on the
    /// pool) and a triangle's fragments take the longer of the two; split:
    /// added to `per_fragment`.
    pub fixed_per_fragment: Duration,
}

impl FragmentConfig {
    /// The FIFO depth the closed form uses: `None` when binning.
    pub fn depth(&self) -> Option<u32> {
        match self.binning {
            Binning::Off => Some(self.fifo_depth),
            Binning::Draw => None,
        }
    }

    /// Whether a draw's fragments wait for all of its geometry.
    #[inline]
    pub fn binned(&self) -> bool {
        self.binning == Binning::Draw
    }
}

impl Default for FragmentConfig {
    fn default() -> Self {
        FragmentConfig {
            fifo_depth: 16,
            binning: Binning::Off,
            per_fragment: Duration::ZERO,
            per_rejected_fragment: Duration::ZERO,
            fixed_per_fragment: Duration::ZERO,
        }
    }
}

/// System tasks (paper 000 §4.2).
#[derive(Debug, Clone, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct NoiseConfig {
    /// Master switch.
    #[serde(default = "yes")]
    pub enabled: bool,
    /// Periodic tasks.
    pub periodic: Vec<PeriodicTask>,
    /// Random (Poisson) tasks.
    pub random: Vec<RandomTask>,
}

fn yes() -> bool {
    true
}

/// Per-frame variation of the units' times (paper 000 §4.2, Figure 3).
///
/// Besides system tasks, a real frame's CPU and GPU times vary from frame to
/// frame (cache and TLB state, driver work, memory traffic, clock changes):
/// Figure 3's density is smooth between its two modes, not two spikes. Each
/// frame draws one extra CPU time (added to its non-rendering work) and one
/// extra GPU time (added to its clear on the front end), each from its own
/// distribution and its own RNG stream (`variation.cpu`, `variation.gpu`),
/// so switching one on changes no other draw. None is drawn unless given:
/// the teaching models, where exact periods are the point, have none.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct VariationConfig {
    /// Master switch (on when the section is given).
    pub enabled: bool,
    /// Extra CPU time per frame.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cpu: Option<Dist<Duration>>,
    /// Extra GPU (front-end) time per frame.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gpu: Option<Dist<Duration>>,
}

impl Default for VariationConfig {
    fn default() -> Self {
        VariationConfig {
            enabled: true,
            cpu: None,
            gpu: None,
        }
    }
}

impl VariationConfig {
    /// Whether no unit varies (nothing given, or switched off).
    pub fn is_off(&self) -> bool {
        !self.enabled || (self.cpu.is_none() && self.gpu.is_none())
    }

    /// The extra CPU time's distribution, when on.
    pub fn cpu(&self) -> Option<&Dist<Duration>> {
        self.cpu.as_ref().filter(|_| self.enabled)
    }

    /// The extra GPU time's distribution, when on.
    pub fn gpu(&self) -> Option<&Dist<Duration>> {
        self.gpu.as_ref().filter(|_| self.enabled)
    }
}

/// A periodic system task.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PeriodicTask {
    /// Name (names its RNG stream).
    pub name: String,
    /// Switch.
    #[serde(default = "yes")]
    pub enabled: bool,
    /// What it preempts.
    #[serde(default = "cpu_target")]
    pub target: NoiseTarget,
    /// Period.
    pub period: Duration,
    /// First arrival.
    #[serde(default)]
    pub phase: Duration,
    /// Uniform random delay of each arrival, in [0, jitter).
    #[serde(default)]
    pub jitter: Duration,
    /// Duration of each task.
    pub duration: Dist<Duration>,
}

/// A task arriving at random (Poisson).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RandomTask {
    /// Name (names its RNG stream).
    pub name: String,
    /// Switch.
    #[serde(default = "yes")]
    pub enabled: bool,
    /// What it preempts.
    #[serde(default = "cpu_target")]
    pub target: NoiseTarget,
    /// Mean arrival rate.
    pub rate: Rate,
    /// Duration of each task (e.g. lognormal or pareto).
    pub duration: Dist<Duration>,
}

fn cpu_target() -> NoiseTarget {
    NoiseTarget::Cpu
}

/// What is rendered each frame. Written as a table with `kind = "fixed"` or
/// `kind = "scene"` and that kind's keys.
#[derive(Debug, Clone, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum WorkloadConfig {
    /// Fixed CPU and GPU time per frame, for teaching and checks.
    Fixed(FixedWorkload),
    /// Objects with meshes, states and screen-space triangle sizes.
    Scene(SceneWorkload),
    /// Measured times given frame by frame (a replayed capture).
    Frames(FramesWorkload),
}

/// A workload given frame by frame, as a frame capture measured it
/// (`rendersim replay` builds one from PresentMon's columns). Frame `i`
/// begins when the previous frame's present call returns: `present[i - 1]`
/// after that present, or later when the model holds it (frames in flight,
/// pacing), the two waits overlapping as they do in a real present call. It
/// works `cpu[i]` in all: after the first `submit[i]` of it the frame's GPU
/// work is submitted (its clear, then `gpu[i]` of work as one command on the
/// front end), and at the end of `cpu[i]` it presents. Where `gpu_end` is
/// given, the GPU does not finish the frame earlier than `gpu_end[i]` after
/// the frame began (a capture's GPU start plus its GPU time: the GPU waited
/// for the CPU's later submissions); the wait counts as GPU idle. Frame 0
/// begins at `start` (a capture's first CPU start after the vertical blank
/// the run starts at). Every list holds at least `run.frames` entries
/// (`gpu_end` may be left out); `submit[i]` is at most `cpu[i]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FramesWorkload {
    /// CPU work per frame, up to its present.
    pub cpu: Vec<Duration>,
    /// CPU work per frame before its GPU work is submitted.
    pub submit: Vec<Duration>,
    /// GPU work per frame.
    pub gpu: Vec<Duration>,
    /// Time in the present call per frame (a floor: the model's own waits
    /// overlap it).
    pub present: Vec<Duration>,
    /// The earliest GPU end per frame, after the frame began (empty: none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub gpu_end: Vec<Duration>,
    /// When frame 0 begins.
    #[serde(default, skip_serializing_if = "Duration::is_zero")]
    pub start: Duration,
}

impl FramesWorkload {
    /// The four lists every such workload gives, with their keys.
    pub fn lists(&self) -> [(&'static str, &[Duration]); 4] {
        [
            ("workload.cpu", &self.cpu),
            ("workload.submit", &self.submit),
            ("workload.gpu", &self.gpu),
            ("workload.present", &self.present),
        ]
    }

    /// Mean of a list in picoseconds (0 for an empty one).
    pub fn mean_ps(list: &[Duration]) -> f64 {
        if list.is_empty() {
            0.0
        } else {
            list.iter().map(|d| d.0 as f64).sum::<f64>() / list.len() as f64
        }
    }
}

/// A fixed per-frame workload.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FixedWorkload {
    /// CPU time per frame (after input sampling and non-rendering work).
    pub cpu: Dist<Duration>,
    /// GPU time per frame (run on the GPU front end as one command).
    pub gpu: Dist<Duration>,
}

impl<'de> Deserialize<'de> for WorkloadConfig {
    /// By hand rather than serde's internally tagged enums, so an error deep
    /// inside keeps its key path (reported as "at `a.b`: ..." and joined to
    /// the outer path by the model loader).
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let mut t = toml::Table::deserialize(d)?;
        let kind = match t.remove("kind") {
            Some(toml::Value::String(k)) => k,
            Some(other) => {
                return Err(D::Error::custom(format!(
                    "at `kind`: expected \"fixed\", \"scene\" or \"frames\", got {other}"
                )));
            }
            None => {
                return Err(D::Error::custom(
                    "missing field `kind` (\"fixed\", \"scene\" or \"frames\")",
                ));
            }
        };
        fn inner<T: serde::de::DeserializeOwned, E: Error>(t: toml::Table) -> Result<T, E> {
            serde_path_to_error::deserialize::<_, T>(crate::config::strict::Strict(t)).map_err(|e| {
                let path = e.path().to_string();
                let msg = e.inner().to_string();
                let msg = msg.lines().next().unwrap_or_default().to_string();
                if path == "." || path.is_empty() {
                    E::custom(msg)
                } else {
                    E::custom(format!("at `{path}`: {msg}"))
                }
            })
        }
        match kind.as_str() {
            "fixed" => inner(t).map(WorkloadConfig::Fixed),
            "scene" => inner(t).map(WorkloadConfig::Scene),
            "frames" => inner(t).map(WorkloadConfig::Frames),
            other => Err(D::Error::custom(format!(
                "at `kind`: unknown workload kind {other:?} (expected \"fixed\", \"scene\" or \"frames\")"
            ))),
        }
    }
}
