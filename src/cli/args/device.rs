//! The arguments of the device commands: `measure`, `calibrate`, `predict`
//! and `study` (feature `wgpu` for the ones that measure), with the depth
//! orders and the studies they name.

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use rendersim::components::vertex_cache::CachePolicy;

use rendersim::measure::{DepthOrder, UnknownDepthOrder};

use super::values::{Choice, Plain, Size, parse_max_median, parse_max_p90, parse_size, parse_vertex_cache};
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
    #[arg(long, value_name = "PCT", requires = "holdout", value_parser = Plain::new(parse_max_median))]
    pub holdout_max_median: Option<f64>,
    /// With --holdout: fail (exit status 1) when the held-out half's 90th
    /// percentile |error| exceeds PCT percent (the profile is still written).
    #[arg(long, value_name = "PCT", requires = "holdout", value_parser = Plain::new(parse_max_p90))]
    pub holdout_max_p90: Option<f64>,
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
    /// Study name: h1, h2, h3, h4, all (H1-H4), estimation (h1-h4 and pos
    /// fitted on single-object passes, scored on multi-object passes), or
    /// profile (designed passes for `rendersim calibrate`).
    #[arg(value_parser = Choice::<Study>::new(unknown_study))]
    pub name: Study,
    /// Recorded passes per timed measurement, interleaved across a study's
    /// passes (the median is used). Default 5 (9 for `profile`).
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

pub(super) fn unknown_order(s: &str) -> String {
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
    /// Profile passes: a designed set for `rendersim calibrate`, rounds interleaved.
    Profile,
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
    format!("unknown study {s:?} (available: h1, h2, h3, h4, all, estimation, profile)")
}
