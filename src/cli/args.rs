//! The command line's arguments in clap's terms: one struct per command,
//! closed choices as [`ValueEnum`]s, `--size` and `--policy` read by value
//! parsers, and conversions into the library's option structs. A value that
//! does not parse is reported in the words the command line always used
//! (`error: --size "12": expected WxH, e.g. 512x512`), exit status 2.

use std::ffi::OsStr;
use std::marker::PhantomData;
use std::path::PathBuf;

use clap::builder::{PossibleValue, TypedValueParser};
use clap::error::ErrorKind;
use clap::{Args, ValueEnum};

use rendersim::bench::Bench;
use rendersim::components::vertex_cache::CachePolicy;
use rendersim::config::Overrides;
use rendersim::measure::{DepthOrder, UnknownDepthOrder};

/// `rendersim run`.
#[derive(Args)]
pub struct RunArgs {
    /// Model file (TOML).
    pub model: Option<PathBuf>,
    /// Override a model key: --set display.buffers=3 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<String>,
    /// Master seed (overrides run.seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Frames to simulate (overrides run.frames).
    #[arg(long)]
    pub frames: Option<u64>,
    /// Print the JSON summary.
    #[arg(long)]
    pub json: bool,
    /// Write summary.json, frames.csv and model.toml into DIR.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Replace an --out folder that holds another command's results (an
    /// experiment's, a replay's); without it that is an error.
    #[arg(long)]
    pub force: bool,
    /// Write a Chrome/Perfetto trace to FILE.
    #[arg(long, value_name = "FILE")]
    pub trace: Option<PathBuf>,
    /// How much the trace shows: frame (a slice a frame on the CPU, GPU and
    /// display tracks, joined by flows), draw (also every unit's states, the
    /// geometry and fragment stages' work a slice a draw), triangle (every
    /// state change, a slice a triangle).
    #[arg(long, value_name = "DETAIL", default_value = "draw", requires = "trace")]
    pub trace_detail: rendersim::output::trace::TraceDetail,
}

impl From<&RunArgs> for Overrides {
    fn from(a: &RunArgs) -> Overrides {
        Overrides {
            sets: a.sets.clone(),
            seed: a.seed,
            frames: a.frames,
        }
    }
}

/// `rendersim experiment`.
#[derive(Args)]
pub struct ExperimentArgs {
    /// Experiment file (TOML).
    pub file: PathBuf,
    /// Output directory (default out/<experiment name>).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Replace an --out folder that holds another command's results (an
    /// experiment's, a replay's); without it that is an error.
    #[arg(long)]
    pub force: bool,
    /// Print only errors and the final line (no progress bar, no table of
    /// points, derived values or verdicts: they are in report.md).
    #[arg(long)]
    pub quiet: bool,
    /// Run only shard K of N of the (point, seed) runs, into DIR/shards/
    /// (a complete shard file is kept; merge them with --merge).
    #[arg(long, value_name = "K/N", conflicts_with_all = ["merge", "slurm"])]
    pub shard: Option<rendersim::experiment::ShardId>,
    /// Merge the shard files in DIR/shards/ into the outputs of one process.
    #[arg(long, conflicts_with = "slurm")]
    pub merge: bool,
    /// Write DIR/job.sbatch (a Slurm job array, one task per shard) and
    /// DIR/merge.sbatch (the merge, after the array).
    #[arg(long)]
    pub slurm: bool,
    /// With --slurm: the number of shards (default: the runs, at most 16).
    #[arg(long, value_name = "N", requires = "slurm")]
    pub shards: Option<usize>,
    /// With --slurm: the Slurm partition.
    #[arg(long, value_name = "P", requires = "slurm")]
    pub partition: Option<String>,
    /// With --slurm: the time limit per task (e.g. 30:00, 2-00:00:00).
    #[arg(long, value_name = "T", requires = "slurm")]
    pub time: Option<String>,
    /// With --slurm: CPUs per task (default 1).
    #[arg(long, value_name = "C", requires = "slurm")]
    pub cpus_per_task: Option<u32>,
    /// With --slurm: at most T array tasks run at once (Slurm's --array=1-N%T).
    #[arg(long, value_name = "T", requires = "slurm")]
    pub throttle: Option<usize>,
    /// With --slurm: one more #SBATCH option for both scripts, as sbatch takes it
    /// (repeatable): --slurm-opt=--account=proj --slurm-opt=--mem=4G --slurm-opt=--qos=short.
    #[arg(long, value_name = "OPTION", requires = "slurm", allow_hyphen_values = true)]
    pub slurm_opt: Vec<String>,
    /// With --slurm: submit both scripts with sbatch and print the job ids.
    #[arg(long, requires = "slurm")]
    pub submit: bool,
}

/// `rendersim isolate`.
#[derive(Args)]
pub struct IsolateArgs {
    /// Model file (TOML); the default model when omitted.
    pub model: Option<PathBuf>,
    /// Override a model key (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<String>,
    /// Load factor for the reduced subsystem.
    #[arg(long, default_value_t = 0.5)]
    pub factor: f64,
    /// Keep vsync on (by default it is switched off so quantization does not hide changes).
    #[arg(long)]
    pub keep_vsync: bool,
    /// Reductions of the frame time within this fraction of the best reduction are reported as a tie.
    #[arg(long, default_value_t = rendersim::studies::isolate::DEFAULT_TIE_TOLERANCE)]
    pub tie_tolerance: f64,
    /// Fidelity of the runs: draw (the default: the same verdicts as triangle on every shipped
    /// model, far faster), triangle, or model (the model file's own).
    #[arg(long, value_enum, default_value_t = IsolateFidelity::Draw)]
    pub fidelity: IsolateFidelity,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

/// `isolate --fidelity`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum IsolateFidelity {
    /// One closed form per draw call.
    Draw,
    /// Every triangle as events.
    Triangle,
    /// The model file's `fidelity`.
    Model,
}

impl IsolateFidelity {
    /// The fidelity to force, `None` for the model's.
    pub fn forced(self) -> Option<rendersim::systems::frame_pipeline::config::Fidelity> {
        use rendersim::systems::frame_pipeline::config::Fidelity;
        match self {
            IsolateFidelity::Draw => Some(Fidelity::Draw),
            IsolateFidelity::Triangle => Some(Fidelity::Triangle),
            IsolateFidelity::Model => None,
        }
    }
}

impl From<&IsolateArgs> for Overrides {
    fn from(a: &IsolateArgs) -> Overrides {
        Overrides::with_sets(&a.sets)
    }
}

/// `rendersim vcache`.
#[derive(Args)]
pub struct VcacheArgs {
    /// Mesh: grid:WxH[:shuffled:SEED|:optimized], strip:WxH, random:T:V:SEED, FILE.obj, FILE.idx.
    pub mesh: String,
    /// Cache policy: none, fifo:N, lru:N, meshopt:CACHE,WARP,PRIMGROUP, batch:V,T, direct:SLOTS,SEGMENT, lookback:V,T,WINDOW, lavapipe, nvidia.
    #[arg(long, value_parser = Plain::new(parse_policy))]
    pub policy: CachePolicy,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

/// `rendersim measure`.
#[derive(Args)]
#[cfg_attr(not(feature = "wgpu"), allow(dead_code))] // read only with the `wgpu` feature
pub struct MeasureArgs {
    /// Mesh spec (as for `vcache`).
    pub mesh: String,
    /// Extra vertex-shader ALU loop iterations.
    #[arg(long, default_value_t = 0)]
    pub vs_loops: u32,
    /// Extra fragment-shader ALU loop iterations.
    #[arg(long, default_value_t = 0)]
    pub fs_loops: u32,
    /// Depth test on.
    #[arg(long)]
    pub depth_test: bool,
    /// Copies of the mesh at different depths.
    #[arg(long, default_value_t = 1)]
    pub layers: u32,
    /// Depth order of the layers: front_to_back, back_to_front, random.
    #[arg(long, default_value = "front_to_back", value_parser = Choice::<Order>::new(unknown_order))]
    pub order: Order,
    /// Render target size, WxH.
    #[arg(long, default_value = "512x512", value_parser = Plain::new(parse_size))]
    pub size: Size,
    /// Unrecorded warm-up passes.
    #[arg(long, default_value_t = 2)]
    pub warmup: u32,
    /// Recorded passes (the median is reported).
    #[arg(long, default_value_t = 5)]
    pub repeats: u32,
    /// Collapse every vertex to one point: no fragments, the geometry stage alone.
    #[arg(long)]
    pub geometry_only: bool,
    /// Split the mesh's triangles into N draw calls, in order (0: no draw, a pass that only
    /// clears and stores its target; more draws than triangles leave some empty).
    #[arg(long, value_name = "N", default_value_t = 1,
          value_parser = clap::value_parser!(u32).range(0..=i64::from(rendersim::measure::passes::MAX_DRAWS)))]
    pub draws: u32,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    /// Append the pass as a row to FILE (header `mesh,size,vs_loops,...,pass_time_ns,draws`,
    /// written when FILE is new or empty; a file with another header is refused, and one
    /// with the header before `draws` takes passes of one draw only).
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
}

#[cfg(feature = "wgpu")]
impl From<&MeasureArgs> for rendersim::measure::MeasureOptions {
    fn from(a: &MeasureArgs) -> Self {
        rendersim::measure::MeasureOptions {
            vs_loops: a.vs_loops,
            fs_loops: a.fs_loops,
            depth_test: a.depth_test,
            layers: a.layers,
            order: a.order.into(),
            size: (a.size.width, a.size.height),
            warmup: a.warmup,
            repeats: a.repeats,
            geometry_only: a.geometry_only,
            draws: a.draws,
        }
    }
}

/// `rendersim calibrate`.
#[derive(Args)]
pub struct CalibrateArgs {
    /// Measured passes (CSV: mesh,size,vs_loops,fs_loops,geometry_only,vs_invocations,fs_invocations,pass_time_ns[,draws]).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Where to write the profile (TOML), e.g. models/devices/NAME.toml.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Device name in the profile (default: the file name of --out).
    #[arg(long)]
    pub name: Option<String>,
    /// Vertex-cache policy predicting the device's vertex-shader invocations.
    #[arg(long, value_parser = Plain::new(parse_vertex_cache), default_value = "meshopt:32,32,32")]
    pub vertex_cache: CachePolicy,
    /// Shader cores of the unified pool (the H200 has 132 SMs).
    #[arg(long, default_value_t = 132)]
    pub shader_cores: u32,
    /// Also predict each row from a fit to the others (leave-one-out) and report it.
    #[arg(long)]
    pub loo: bool,
    /// Also cross-validate by mesh: the distinct meshes dealt into K folds
    /// (name order, round-robin), each fold's passes predicted by a fit to
    /// the others, so every prediction is of a mesh the fit has not seen
    /// (at least 2; fewer folds when there are fewer meshes).
    #[arg(long, value_name = "K", value_parser = clap::value_parser!(u32).range(2..=1000))]
    pub kfold: Option<u32>,
    /// Also fit on a fixed pseudo-random half of the rows and report the
    /// errors of predicting the other half.
    #[arg(long)]
    pub holdout: bool,
    /// With --holdout: fail (exit status 1) when the held-out half's median
    /// |error| exceeds PCT percent (the profile is still written).
    #[arg(long, value_name = "PCT", requires = "holdout")]
    pub holdout_max_median: Option<f64>,
    /// Also write a Markdown report: every row measured against its
    /// leave-one-out prediction and against `predict`'s simulation, with
    /// the wall time of measuring vs simulating.
    #[arg(long, value_name = "FILE.md")]
    pub report: Option<PathBuf>,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// `rendersim predict`.
#[derive(Args)]
pub struct PredictArgs {
    /// Mesh spec (as for `measure`).
    pub mesh: String,
    /// Device profile (TOML) written by `rendersim calibrate`.
    #[arg(long, value_name = "FILE")]
    pub device: PathBuf,
    /// Render target size, WxH.
    #[arg(long, default_value = "512x512", value_parser = Plain::new(parse_size))]
    pub size: Size,
    /// Extra vertex-shader ALU loop iterations.
    #[arg(long, default_value_t = 0)]
    pub vs_loops: u32,
    /// Extra fragment-shader ALU loop iterations.
    #[arg(long, default_value_t = 0)]
    pub fs_loops: u32,
    /// Collapse every vertex to one point: no fragments.
    #[arg(long)]
    pub geometry_only: bool,
    /// Copies of the mesh drawn.
    #[arg(long, default_value_t = 1)]
    pub layers: u32,
    /// Depth order of the layers: front_to_back, back_to_front, random.
    #[arg(long, default_value = "front_to_back", value_parser = Choice::<Order>::new(unknown_order))]
    pub order: Order,
    /// Early depth test on.
    #[arg(long)]
    pub depth_test: bool,
    /// Split the mesh's triangles into N draw calls (0: no draw, a pass that only clears and
    /// stores its target).
    #[arg(long, value_name = "N", default_value_t = 1,
          value_parser = clap::value_parser!(u32).range(0..=i64::from(rendersim::measure::passes::MAX_DRAWS)))]
    pub draws: u32,
    /// Also measure the same pass on this machine's adapter (feature `wgpu`)
    /// and print the prediction's error and the wall times of measuring and
    /// simulating, both timed in this run.
    #[arg(long)]
    pub measure: bool,
    /// Recorded passes of --measure (the median is used; 2 warm-ups before).
    #[arg(long, default_value_t = 5)]
    pub repeats: u32,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

/// `rendersim study`.
#[derive(Args)]
#[cfg_attr(not(feature = "wgpu"), allow(dead_code))] // read only with the `wgpu` feature
pub struct StudyArgs {
    /// Study name: h1, h2, h3, h4, all (H1-H4), or estimation (h1-h4 and pos
    /// fitted on single-object passes, scored on multi-object passes).
    #[arg(value_parser = Choice::<Study>::new(unknown_study))]
    pub name: Study,
    /// Recorded passes per timed measurement, interleaved across a study's
    /// passes (the median is used). Default 5.
    #[arg(long)]
    pub repeats: Option<u32>,
    /// Also write the device's Markdown document to FILE (e.g. docs/measurements/<adapter>.md).
    #[arg(long, value_name = "FILE")]
    pub markdown: Option<PathBuf>,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    /// Append every pass the studies measured to FILE, one row per distinct
    /// pass (as `measure --csv`; H1's probes and layered passes are left out).
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Fail (exit status 2) when H1's fitted policy does not predict every
    /// validation mesh exactly; without it that is a finding, printed with
    /// its residuals, and the exit status is 0. For CI on lavapipe.
    #[arg(long)]
    pub require_exact: bool,
    /// estimation: single-object passes measured to fit h1-h4 (default 1000).
    #[arg(long, value_name = "N")]
    pub single: Option<usize>,
    /// estimation: multi-object passes measured to score the estimators (default 300).
    #[arg(long, value_name = "M")]
    pub multi: Option<usize>,
    /// estimation: master seed of the pass generator (default 1).
    #[arg(long)]
    pub seed: Option<u64>,
    /// estimation: multiplies every prototype's shader loop counts (default 1,
    /// for lavapipe; a GPU needs more work for measurable times).
    #[arg(long, value_name = "X")]
    pub load_scale: Option<f64>,
}

/// `rendersim bench`.
#[derive(Args)]
pub struct BenchArgs {
    /// Which: kernel, pipeline, hour, pixelflow, build, all.
    #[arg(default_value = "all", value_parser = Choice::<BenchTarget>::new(unknown_bench))]
    pub which: BenchTarget,
    /// Scale the work down (0.01 .. 1) for a quick check.
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// Repeats of every measurement (1 .. 1000): each line prints the
    /// median and, in brackets, the minimum and maximum. The kernel splits
    /// its events into this many slices; the others run whole again.
    #[arg(long, default_value_t = 5, value_name = "N")]
    pub repeats: usize,
    /// With `kernel`: also draw ns per event against the number pending
    /// (1e3 .. 1e6, log axes) for the engine and the bare heap, hold and
    /// stiff, into FILE (.png; an .svg beside it), from the measurements
    /// the lines print (medians, bars from minimum to maximum).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
}

/// The depth order of `measure --order`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
#[value(rename_all = "snake_case")]
pub enum Order {
    /// Nearest layer first.
    #[value(alias = "f2b")]
    FrontToBack,
    /// Farthest layer first.
    #[value(alias = "b2f")]
    BackToFront,
    /// A fixed pseudo-random permutation.
    Random,
}

impl From<Order> for DepthOrder {
    fn from(o: Order) -> DepthOrder {
        match o {
            Order::FrontToBack => DepthOrder::FrontToBack,
            Order::BackToFront => DepthOrder::BackToFront,
            Order::Random => DepthOrder::Random,
        }
    }
}

fn unknown_order(s: &str) -> String {
    format!("--order: {}", UnknownDepthOrder(s.to_string()))
}

/// The studies of `rendersim study`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Study {
    /// H1, vertex reuse.
    H1,
    /// H2, sum vs max.
    H2,
    /// H3, draw order.
    H3,
    /// H4, cost per vertex.
    H4,
    /// All four.
    All,
    /// Rendering-time estimation: h1-h4 and pos on measured passes.
    Estimation,
}

#[cfg_attr(not(feature = "wgpu"), allow(dead_code))]
impl Study {
    /// The name as given on the command line.
    pub fn name(self) -> String {
        self.to_possible_value()
            .map(|v| v.get_name().to_string())
            .unwrap_or_default()
    }
}

fn unknown_study(s: &str) -> String {
    format!("unknown study {s:?} (available: h1, h2, h3, h4, all, estimation)")
}

/// The benchmarks of `rendersim bench`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum BenchTarget {
    /// The event kernel.
    Kernel,
    /// One frame at both fidelities.
    Pipeline,
    /// One simulated hour.
    Hour,
    /// PixelFlow's Figures 3 and 4.
    Pixelflow,
    /// Scene building (the vertex-cache reordering) against simulation.
    Build,
    /// Replaying a 10,000-frame capture against reading it.
    Replay,
    /// All of them.
    All,
}

impl From<BenchTarget> for Vec<Bench> {
    fn from(t: BenchTarget) -> Vec<Bench> {
        match t {
            BenchTarget::Kernel => vec![Bench::Kernel],
            BenchTarget::Pipeline => vec![Bench::Pipeline],
            BenchTarget::Hour => vec![Bench::Hour],
            BenchTarget::Pixelflow => vec![Bench::Pixelflow],
            BenchTarget::Build => vec![Bench::Build],
            BenchTarget::Replay => vec![Bench::Replay],
            BenchTarget::All => Bench::ALL.to_vec(),
        }
    }
}

fn unknown_bench(s: &str) -> String {
    format!("unknown benchmark {s:?} (kernel, pipeline, hour, pixelflow, build, all)")
}

/// A render target size, `WxH`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Size {
    /// Pixels across.
    pub width: u32,
    /// Pixels down.
    pub height: u32,
}

fn parse_size(size: &str) -> anyhow::Result<Size> {
    size.split_once('x')
        .and_then(|(w, h)| {
            Some(Size {
                width: w.parse().ok()?,
                height: h.parse().ok()?,
            })
        })
        .ok_or_else(|| anyhow::anyhow!("--size {size:?}: expected WxH, e.g. 512x512"))
}

fn parse_policy(policy: &str) -> anyhow::Result<CachePolicy> {
    policy.parse().map_err(|e| anyhow::anyhow!("--policy {policy:?}: {e}"))
}

/// `calibrate --vertex-cache`: the same policies as `--policy`, its errors
/// naming the option they came from.
fn parse_vertex_cache(policy: &str) -> anyhow::Result<CachePolicy> {
    policy
        .parse()
        .map_err(|e| anyhow::anyhow!("--vertex-cache {policy:?}: {e}"))
}

/// A usage error with `message` as its whole text (`error: ` before it),
/// exit status 2.
fn invalid_value(cmd: &clap::Command, message: String) -> clap::Error {
    clap::Error::raw(ErrorKind::InvalidValue, format!("{message}\n")).with_cmd(cmd)
}

/// A value parser for a closed choice `E`, whose refusal reads `unknown(value)`.
#[derive(Clone)]
pub struct Choice<E> {
    unknown: fn(&str) -> String,
    choice: PhantomData<fn() -> E>,
}

impl<E> Choice<E> {
    fn new(unknown: fn(&str) -> String) -> Self {
        Choice {
            unknown,
            choice: PhantomData,
        }
    }
}

impl<E: ValueEnum + Clone + Send + Sync + 'static> TypedValueParser for Choice<E> {
    type Value = E;

    fn parse_ref(&self, cmd: &clap::Command, _arg: Option<&clap::Arg>, value: &OsStr) -> Result<E, clap::Error> {
        let text = value.to_string_lossy();
        E::from_str(&text, false).map_err(|_| invalid_value(cmd, (self.unknown)(&text)))
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(
            E::value_variants().iter().filter_map(|v| v.to_possible_value()),
        ))
    }
}

/// A value parser from a function whose error is the whole message.
#[derive(Clone)]
pub struct Plain<T> {
    parse: fn(&str) -> anyhow::Result<T>,
}

impl<T> Plain<T> {
    fn new(parse: fn(&str) -> anyhow::Result<T>) -> Self {
        Plain { parse }
    }
}

impl<T: Clone + Send + Sync + 'static> TypedValueParser for Plain<T> {
    type Value = T;

    fn parse_ref(&self, cmd: &clap::Command, _arg: Option<&clap::Arg>, value: &OsStr) -> Result<T, clap::Error> {
        (self.parse)(&value.to_string_lossy()).map_err(|e| invalid_value(cmd, e.to_string()))
    }
}

/// `rendersim lod-select`.
#[derive(Args)]
pub struct LodSelectArgs {
    /// Knapsack instance (TOML, or JSON with the same keys when named *.json):
    /// budget = "10ms", [[objects]] name, levels = [{ cost, benefit }].
    pub instance: PathBuf,
    /// Selection algorithm: greedy (the lecture's), incremental (frame to frame), optimal (exact, <= 30 objects).
    #[arg(long, value_enum, default_value = "greedy")]
    pub algorithm: LodAlgorithm,
    /// Incremental only: the previous frame's selection, one entry per object, comma separated
    /// (a level index, or - for not drawn); default nothing drawn.
    #[arg(long, value_name = "LIST")]
    pub previous: Option<String>,
    /// Print the JSON result.
    #[arg(long)]
    pub json: bool,
}

/// The algorithms of `rendersim lod-select`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LodAlgorithm {
    /// Tuples by benefit/cost, highest first; one per object, while they fit.
    Greedy,
    /// From the previous selection: repair over budget, then upgrade by marginal value.
    Incremental,
    /// Exact branch and bound (at most 30 objects).
    Optimal,
}

impl From<LodAlgorithm> for rendersim::components::lod_select::Algorithm {
    fn from(a: LodAlgorithm) -> Self {
        use rendersim::components::lod_select::Algorithm;
        match a {
            LodAlgorithm::Greedy => Algorithm::Greedy,
            LodAlgorithm::Incremental => Algorithm::Incremental,
            LodAlgorithm::Optimal => Algorithm::Optimal,
        }
    }
}

/// `rendersim sortbuf`.
#[derive(Args)]
pub struct SortbufArgs {
    /// State ids: a file of whitespace-separated non-negative integers (# comments);
    /// lru-worst:M (the lecture's worst case for LRU, meant for a buffer of M*M+1 slots);
    /// or scene:MODEL.toml[:state|shader|texture|material] (a scene's objects in submission order).
    pub sequence: String,
    /// Buffer slots K (>= 1).
    #[arg(long, conflicts_with = "sweep", required_unless_present = "sweep")]
    pub buffer: Option<usize>,
    /// Strategy: lru, bounded-waste, random, round-robin (with --sweep: a comma list, default all).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub strategy: Vec<SortStrategy>,
    /// Buffer sizes to sweep, comma separated (a table of every strategy at every size).
    #[arg(long, value_delimiter = ',', value_name = "K,K,...")]
    pub sweep: Vec<usize>,
    /// Master seed of the random strategy's stream.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print the JSON result.
    #[arg(long)]
    pub json: bool,
}

/// The strategies of `rendersim sortbuf`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SortStrategy {
    /// Send the least recently written state.
    Lru,
    /// Send the state with the largest waste counter.
    BoundedWaste,
    /// Send the state of a random slot.
    Random,
    /// Send the state of the slot a round-robin pointer shows.
    RoundRobin,
}

impl From<SortStrategy> for rendersim::components::sorting_buffer::Strategy {
    fn from(s: SortStrategy) -> Self {
        use rendersim::components::sorting_buffer::Strategy;
        match s {
            SortStrategy::Lru => Strategy::Lru,
            SortStrategy::BoundedWaste => Strategy::BoundedWaste,
            SortStrategy::Random => Strategy::Random,
            SortStrategy::RoundRobin => Strategy::RoundRobin,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_choices_parse_as_before() {
        assert_eq!(
            parse_size("640x480").unwrap(),
            Size {
                width: 640,
                height: 480
            }
        );
        assert_eq!(
            parse_size("12").unwrap_err().to_string(),
            "--size \"12\": expected WxH, e.g. 512x512"
        );
        assert_eq!(Order::from_str("f2b", false), Ok(Order::FrontToBack));
        assert_eq!(Study::All.name(), "all");
        assert_eq!(Vec::<Bench>::from(BenchTarget::All), Bench::ALL.to_vec());
        assert_eq!(
            unknown_order("x"),
            "--order: unknown depth order \"x\" (front_to_back, back_to_front, random)"
        );
    }
}

/// `rendersim timeline`.
#[derive(Args)]
pub struct TimelineArgs {
    /// Model file (TOML, a frame pipeline, or a `system = "replay"` capture); the default model when omitted.
    pub model: Option<PathBuf>,
    /// Override a model key (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<String>,
    /// Frames to draw.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=rendersim::studies::timeline::MAX_TIMELINE_FRAMES))]
    pub frames: u64,
    /// The first frame drawn (the frames before it are simulated, not drawn).
    #[arg(long, value_name = "F", default_value_t = 0)]
    pub from: u64,
    /// The picture to write: FILE.png or FILE.svg.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
}

/// `rendersim perceived-speed`.
#[derive(Args)]
pub struct PerceivedSpeedArgs {
    /// Walkthrough model file (TOML, system = "walkthrough").
    pub model: PathBuf,
    /// Override a model key (repeatable), e.g. --set lod.policy=predictive.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<String>,
    /// Refreshes drawn either side of the first frame skip.
    #[arg(long, value_name = "N", default_value_t = 8)]
    pub around: u64,
    /// The picture to write: FILE.png (an .svg is written beside it, and the reverse).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
}

/// `rendersim replay`.
#[derive(Args)]
pub struct ReplayArgs {
    /// PresentMon capture (CSV, PresentMon 1 or 2 columns).
    pub capture: PathBuf,
    /// Replay this process's swap chain with most frames.
    #[arg(long, value_name = "NAME")]
    pub app: Option<String>,
    /// Replay the swap chain at this address (e.g. 0x224B280A1C0).
    #[arg(long, value_name = "ADDR")]
    pub swapchain: Option<String>,
    /// Patch the replay's model (a what-if): --set cpu.max_frames_ahead=1 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<String>,
    /// What the capture does not say, patched on the replay as captured
    /// before any what-if: --assume display.buffers=2, cpu.max_frames_ahead,
    /// display.refresh (repeatable).
    #[arg(long = "assume", value_name = "KEY=VALUE")]
    pub assume: Vec<String>,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
    /// Write replay.json, frames.csv (the replay as PresentMon frames),
    /// comparison.csv (measured against predicted), model.toml and, with a
    /// what-if, whatif-frames.csv and whatif-model.toml into DIR.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Replace an --out folder that holds another command's results (an
    /// experiment's, a replay's); without it that is an error.
    #[arg(long)]
    pub force: bool,
}
