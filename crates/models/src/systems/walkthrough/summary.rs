//! The walkthrough's summary (`summary.json`) as typed structs, and the
//! per-frame table's columns.

use serde::Serialize;

use crate::systems::summary::{Dist, EventCounts};

use super::estimators::{Constants, ESTIMATORS, Score};
use super::scene::SceneTotals;
use super::timing::TimingSummary;
use super::view_cells::ViewCellSummary;

/// The pos tables of the run: the built ones and the renders they took.
#[derive(Debug, Clone, Serialize)]
pub struct PosTables {
    /// Tables built (one per prototype drawn, finest level).
    pub tables: u64,
    /// Sample renders made.
    pub renders: u64,
    /// Renders the full grids would have taken.
    pub full_renders: u64,
    /// Share of the full grids' renders saved by pruning.
    pub pruned_fraction: f64,
}

/// `metrics.estimation` of a walkthrough summary.
#[derive(Debug, Clone, Serialize)]
pub struct EstimationSummary {
    /// Time of an empty frame (the frame's own terms, added to every
    /// estimate), ms.
    pub empty_frame_ms: f64,
    /// Single-object renders the constants were fitted to.
    pub fit_samples: u64,
    /// The fitted constants (absent without h1-h4).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub constants: Option<Constants>,
    /// The pos tables (absent without pos).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pos_tables: Option<PosTables>,
    /// Triangles (h1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub h1: Option<Score>,
    /// Transformed vertices (h2).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub h2: Option<Score>,
    /// Funkhouser's max (h3).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub h3: Option<Score>,
    /// Transformed vertices plus pixels (h4).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub h4: Option<Score>,
    /// Per-object sampling.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pos: Option<Score>,
    /// View-cell sampling.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vcs: Option<Score>,
    /// Per-view-cell estimation.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pvc: Option<Score>,
    /// The view-cell preprocess (absent without vcs and pvc).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub view_cells: Option<ViewCellSummary>,
    /// The CPU clock the preprocess was timed with (absent with time stamps).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub timing: Option<TimingSummary>,
}

impl EstimationSummary {
    /// Each estimator's score by name, in [`ESTIMATORS`]' order (`None` for
    /// an estimator the model did not ask for).
    pub fn scores(&self) -> [(&'static str, Option<&Score>); 7] {
        let s = [&self.h1, &self.h2, &self.h3, &self.h4, &self.pos, &self.vcs, &self.pvc];
        std::array::from_fn(|i| (ESTIMATORS[i], s[i].as_ref()))
    }
}

/// `metrics` of a walkthrough summary.
#[derive(Debug, Clone, Serialize)]
pub struct WalkMetrics {
    /// The frames' rendering time RT (CPU start to the GPU's last work), ms.
    pub frame_time_ms: Dist,
    /// GPU time per frame, ms.
    pub gpu_time_ms: Dist,
    /// The frame budget: one display refresh, ms.
    pub budget_ms: f64,
    /// Frames whose rendering time exceeds the budget.
    pub frames_over_budget: u64,
    /// Their share of the frames.
    pub over_budget_fraction: f64,
    /// Objects drawn per frame (in the PVS and the frustum).
    pub visible_objects: Dist,
    /// Triangles drawn per frame.
    pub triangles: Dist,
    /// Pixels covered per frame (overdraw included).
    pub pixels_covered: Dist,
    /// Frames with the camera inside an object's bounding sphere.
    pub frames_inside_an_object: u64,
    /// The estimators.
    pub estimation: EstimationSummary,
    /// Display refreshes at which no new frame was ready (a frame of
    /// rendering time RT is shown ceil(RT / refresh) refreshes after its
    /// start: ceil(RT / refresh) - 1 skips).
    pub frame_skips: u64,
    /// Frame skips per minute of displayed walkthrough (paper 000 §6.3's
    /// goal: 1-2 at 60 Hz).
    pub frame_skips_per_minute: f64,
    /// The walkthrough's length on the display (refreshes x period), s.
    pub displayed_seconds: f64,
    /// Mean per frame of the drawn objects' image benefit (paper 001's
    /// benefit without hysteresis; `lod.rs`).
    pub benefit_mean: f64,
    /// The drawn benefit's share of the benefit of every visible object at
    /// its finest level, summed over the frames (1 with nothing visible).
    pub benefit_fraction: f64,
    /// Level changes of objects visible in two consecutive frames (not
    /// drawn counts as a level), per displayed second: popping.
    pub lod_switches_per_second: f64,
    /// The level-of-detail policy as run.
    pub lod: LodSummary,
}

/// `metrics.lod`: the level-of-detail policy as run.
#[derive(Debug, Clone, Serialize)]
pub struct LodSummary {
    /// The policy.
    pub policy: String,
    /// The estimator of the predictive policies' costs.
    pub estimator: String,
    /// The predictive policies' knapsack algorithm.
    pub algorithm: String,
    /// What the policies aim at: refresh x (1 - margin), ms.
    pub target_ms: f64,
    /// The knapsack's budget: the target less the empty frame, ms.
    pub knapsack_budget_ms: f64,
    /// Mean level of the drawn objects (0 = finest).
    pub mean_level: f64,
    /// Objects drawn per frame at each level (mean), finest first.
    pub objects_per_level: Vec<f64>,
    /// Visible objects not drawn per frame (mean; predictive policies).
    pub dropped_per_frame: f64,
    /// Visible (object, frame) pairs none of whose levels fit the
    /// knapsack's budget alone (never drawn).
    pub unaffordable_object_frames: u64,
    /// Level changes in all (see `lod_switches_per_second`).
    pub switches: u64,
    /// Reactive: the detail level k (triangles per pixel of disk) per frame.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reactive_k: Option<Dist>,
    /// predictive+branch: what the conditional branches did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub branch: Option<BranchSummary>,
    /// Edge cases met (nothing fits, objects never drawn).
    pub notes: Vec<String>,
}

/// `metrics.lod.branch`.
#[derive(Debug, Clone, Serialize)]
pub struct BranchSummary {
    /// Branch tokens (switchable objects) per frame, mean.
    pub tokens_per_frame: f64,
    /// Objects switched to a coarser level by a branch, in all.
    pub switched_objects: u64,
    /// Frames with at least one switch.
    pub frames_with_switch: u64,
    /// Prefix runs of the frame pipeline made to find when the GPU reached
    /// the tokens.
    pub prefix_runs: u64,
}

/// The camera path as run.
#[derive(Debug, Clone, Serialize)]
pub struct CameraSummary {
    /// The path kind (`street`, `forest`, `flight`, `keyframes`).
    pub path: String,
    /// Path length, metres.
    pub length_m: f64,
    /// View cells visited (their PVS computed); 0 without view cells.
    pub view_cells_visited: u64,
}

/// The summary of a walkthrough (`summary.json`).
#[derive(Debug, Clone, Serialize)]
pub struct WalkthroughSummary {
    /// `"walkthrough"`.
    pub system: &'static str,
    /// The model's description.
    pub description: String,
    /// How the frames were drawn.
    pub fidelity: crate::systems::frame_pipeline::Fidelity,
    /// Master seed.
    pub seed: u64,
    /// Frames.
    pub frames: u64,
    /// Kernel events of every frame-pipeline run (preprocess and frames).
    pub events: EventCounts,
    /// Frame-pipeline runs made (preprocess renders and frames).
    pub pipeline_runs: u64,
    /// Wall time of the whole run, seconds.
    pub wall_seconds: f64,
    /// Wall time of the scene, path and preprocess, seconds.
    pub build_seconds: f64,
    /// Wall time of the frames, seconds.
    pub simulate_seconds: f64,
    /// The scene preset (null: listed objects only).
    pub preset: Option<String>,
    /// The scene's totals.
    pub scene: SceneTotals,
    /// The camera path.
    pub camera: CameraSummary,
    /// The results.
    pub metrics: WalkMetrics,
}

/// Columns of the per-frame table before the estimates.
pub const BASE_COLUMNS: [&str; 8] = [
    "Frame",
    "TimeInSeconds",
    "Objects",
    "Triangles",
    "PixelsCovered",
    "ActualMs",
    "GpuMs",
    "BudgetMs",
];

/// Columns of the per-frame table after the estimates (then `AtLevel<l>`,
/// the objects drawn at each level): refreshes skipped before the frame was
/// shown, the refresh it was shown at, the camera's move since the frame
/// before (m), the drawn and the all-finest image benefit, the drawn
/// objects' mean level, objects drawn and dropped, level switches, the
/// policy estimator's GPU estimate of the planned selection plus the empty
/// frame (predictive; ms), the reactive detail level k, branch tokens and
/// objects the branches switched.
pub const LOD_COLUMNS: [&str; 13] = [
    "Skips",
    "ShownAtRefresh",
    "MovedM",
    "Benefit",
    "BenefitFinest",
    "MeanLevel",
    "Drawn",
    "Dropped",
    "Switches",
    "PlanEstMs",
    "DetailK",
    "BranchTokens",
    "BranchSwitched",
];
