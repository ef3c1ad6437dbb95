//! The command line's arguments in clap's terms: one struct per command,
//! closed choices as [`ValueEnum`]s, `--size` and `--policy` read by value
//! parsers, and conversions into the library's option structs. A value that
//! does not parse is reported in the words the command line always used
//! (`error: --size "12": expected WxH, e.g. 512x512`), exit status 2. The
//! device commands' arguments (`measure`, `calibrate`, `predict`, `study`)
//! are in `device.rs`, the value parsers in `values.rs`.

mod device;
mod values;

pub use device::*;
pub use values::{Choice, Plain};

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use rendersim::bench::Bench;
use rendersim::components::vertex_cache::CachePolicy;
use rendersim::config::Overrides;

use values::parse_policy;
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
    /// Print the result as JSON (points, checks, claims, Sobol' indices,
    /// searches, wall times, and where the files are) instead of the text.
    #[arg(long, conflicts_with_all = ["shard", "merge", "slurm"])]
    pub json: bool,
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
    /// Keep vsync on (by default it is switched off so quantization does not hide changes; a VRR display keeps it, as VRR needs it).
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

/// `rendersim bench`.
#[derive(Args)]
pub struct BenchArgs {
    /// Which: kernel, pipeline, hour, pixelflow, build, replay, all.
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
    /// Print every benchmark's measurements as one JSON object (keyed by
    /// benchmark) at the end instead of a line each.
    #[arg(long)]
    pub json: bool,
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
    use super::device::unknown_order;
    use super::values::{Size, parse_size};
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

/// `rendersim explore`.
#[derive(Args)]
pub struct ExploreArgs {
    /// Model file (TOML) of a frame pipeline; the embedded default model when omitted.
    pub model: Option<PathBuf>,
    /// The port to serve on (0: any free one; the address is printed).
    #[arg(long, default_value_t = 8765)]
    pub port: u16,
    /// The address to listen on (default 127.0.0.1: this machine only).
    #[arg(long, value_name = "ADDR")]
    pub listen: Option<std::net::IpAddr>,
    /// Open the page in the system's browser once it is served.
    #[arg(long)]
    pub open: bool,
    /// Where the page starts: a model key set as --set does (repeatable).
    /// Without a --set of `fidelity`, the page starts at `fidelity="draw"`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<String>,
    /// Most events one run of the page may process (a run that needs more
    /// is refused with a message, not shown cut short).
    #[arg(long, value_name = "N", default_value_t = 50_000_000, value_parser = clap::value_parser!(u64).range(1..))]
    pub budget_events: u64,
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
    /// A capture of the same game measured under the what-if's setting:
    /// its figures (fps, displayed fps, display change, until displayed,
    /// display latency, PC latency medians) are put beside the prediction
    /// (`replay.compare`).
    #[arg(long, value_name = "MEASURED.csv")]
    pub compare: Option<PathBuf>,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
    /// Write replay.json, frames.csv (the replay as PresentMon frames),
    /// comparison.csv (measured against predicted), model.toml and, with a
    /// what-if, whatif-frames.csv and whatif-model.toml into DIR.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Write a validation report of every swap chain of the capture into
    /// DIR: report.md (accuracy, the inferred display, the frames where
    /// measured and replayed disagree and why), chains.csv, and per swap
    /// chain chain-N.csv and chain-N-screen.png.
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
    /// Replace an --out folder that holds another command's results (an
    /// experiment's, a replay's); without it that is an error.
    #[arg(long)]
    pub force: bool,
}
