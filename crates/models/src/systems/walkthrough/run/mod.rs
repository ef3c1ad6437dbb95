//! Running a walkthrough and its summary.
//!
//! Order of work: the model's checks (`validate.rs`), the scene, the camera
//! path, then the preprocess (`preprocess.rs`: an empty frame, the
//! single-object renders the heuristics are fitted to, the pos tables, the
//! view-cell estimators), all timed exactly (system tasks off); then per
//! frame: the view cell's PVS, frustum culling, each visible object's
//! projection, the LOD policy's levels, every estimator's estimate (each
//! timed on its own), and the frame drawn by the frame pipeline with the
//! model's noise (the actual time).
//!
//! Here: the run in that order, what every frame reads (`Model`) and the
//! frame loop's state (`Walk`); one frame's steps are in `frame.rs`, the
//! summary after the last frame in `totals.rs`.

use std::collections::BTreeMap;
use std::time::Instant;

use crate::engine::{PS_PER_MS, StreamRng};
use crate::output::trace::TraceWriter;
use crate::systems::checked::Checked;
use crate::systems::error::SystemError;
use crate::systems::summary::EventCounts;

use super::branch::BranchStats;
use super::camera::{self, Pose};
use super::config::WalkthroughConfig;
use super::culling::{Projection, Pvs, View, features};
use super::estimators::{Constants, ESTIMATORS, Features};
use super::lod::{BenefitTerms, Policy, Reactive};
use super::pos::PosTable;
use super::preprocess::{Preprocess, preprocess};
use super::render::{Counter, Draw, Renderer, frame_seeds};
use super::scene::{Prototype, Scene, build_scene};

use super::view_cells::ViewCellTables;
use crate::components::lod_select::Algorithm;

mod frame;
mod totals;

pub use super::lod::LOD_POLICIES;
pub use super::summary::{
    BASE_COLUMNS, BranchSummary, CameraSummary, EstimationSummary, LOD_COLUMNS, LodSummary, PosTables, WalkMetrics,
    WalkthroughSummary,
};

/// Everything a run produced.
#[derive(Debug)]
pub struct WalkthroughRun {
    /// The model as run.
    pub config: WalkthroughConfig,
    /// The summary, typed (`summary.json` is made from it where it is written).
    pub summary: WalkthroughSummary,
    /// Per-frame table columns.
    pub columns: Vec<String>,
    /// Per-frame rows.
    pub rows: Vec<Vec<f64>>,
    /// Trace (none is written by this system).
    pub trace: Option<TraceWriter>,
}

fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn ms(ps: f64) -> f64 {
    ps / PS_PER_MS as f64
}

/// Runs the walkthrough.
pub fn run_walkthrough(cfg: WalkthroughConfig) -> Result<WalkthroughRun, SystemError> {
    let cfg = Checked::new(cfg)?;
    let t0 = Instant::now();
    let scene = build_scene(&cfg.scene, cfg.run.seed)?;
    camera::validate(&cfg.camera, &scene)?;
    let refresh = cfg.display.refresh.period.0.max(1);
    let dt = refresh as f64 * 1e-12;
    let poses = camera::path(&cfg.camera, &scene, cfg.run.frames, dt, cfg.run.seed)?;
    let actual = Renderer::new(&cfg, &scene, true)?;
    let exact = Renderer::new(&cfg, &scene, false)?;
    let mut count = Counter::default();
    let wants: Vec<bool> = ESTIMATORS
        .iter()
        .map(|e| cfg.estimation.estimators.iter().any(|x| x == e))
        .collect();
    super::validate::check_events(&super::validate::Runs::of(
        &cfg,
        &scene,
        poses.len() as u64,
        &wants,
        exact.model(),
        actual.model(),
    ))?;
    let (policy, lod_est, algorithm) = super::lod::validate(&cfg.lod, &cfg.estimation.estimators)?;
    let Preprocess {
        empty,
        constants,
        tables,
        pos_tables,
        pvs,
        view_cells,
        clock_readings,
    } = preprocess(&cfg, &scene, &poses, &exact, &wants, policy, &mut count)?;
    let (vc_tables, vc_summary) = view_cells.unzip();
    let build_seconds = t0.elapsed().as_secs_f64();

    // The frames.
    let t1 = Instant::now();
    let target = refresh as f64 * (1.0 - cfg.lod.margin);
    let model = Model {
        cfg: &cfg,
        scene: &scene,
        actual: &actual,
        wants: &wants,
        policy,
        lod_est,
        algorithm,
        empty,
        constants,
        lod_constants: constants.unwrap_or_default(),
        tables: &tables,
        view_cells: vc_tables.as_ref(),
        refresh,
        dt,
        target,
        knapsack_budget: (target - empty).max(0.0),
        gpu_swap: cfg.gpu.swap.0 as f64,
        max_levels: scene.protos.iter().map(|p| p.levels.len()).max().unwrap_or(1),
    };
    let mut walk = Walk::new(model, pvs, count, poses.len());
    for (f, pose) in poses.iter().enumerate() {
        walk.frame(f, pose)?;
    }
    let simulate_seconds = t1.elapsed().as_secs_f64();
    let estimation = walk.estimation_summary(pos_tables, vc_summary, clock_readings);
    let metrics = walk.metrics(estimation, poses.len() as u64);
    let max_levels = walk.m.max_levels;
    let Walk { pvs, count, rows, .. } = walk;
    let summary = WalkthroughSummary {
        system: "walkthrough",
        description: cfg.description.clone(),
        fidelity: cfg.fidelity,
        seed: cfg.run.seed,
        frames: poses.len() as u64,
        events: EventCounts {
            total: count.events,
            by_kind: count
                .names
                .iter()
                .zip(&count.by_kind)
                .map(|(n, c)| (n.to_string(), *c))
                .collect::<BTreeMap<_, _>>(),
        },
        pipeline_runs: count.runs,
        wall_seconds: t0.elapsed().as_secs_f64(),
        build_seconds,
        simulate_seconds,
        preset: cfg.scene.preset.clone(),
        scene: scene.totals(),
        camera: CameraSummary {
            path: camera::resolved_kind(&cfg.camera, &scene)?.to_string(),
            length_m: path_length(&poses),
            view_cells_visited: pvs.cells_visited() as u64,
        },
        metrics,
    };
    let columns = columns(&wants, max_levels);
    Ok(WalkthroughRun {
        config: cfg.into_inner(),
        summary,
        columns,
        rows,
        trace: None,
    })
}

/// The length (m) of the camera's path through `poses`.
fn path_length(poses: &[Pose]) -> f64 {
    poses
        .windows(2)
        .map(|p: &[Pose]| (0..3).map(|a| (p[1].eye[a] - p[0].eye[a]).powi(2)).sum::<f64>().sqrt())
        .sum()
}

/// The per-frame table's columns: the base ones, one per estimator in
/// `wants`, the LOD ones, then one per level up to `max_levels`.
fn columns(wants: &[bool], max_levels: usize) -> Vec<String> {
    let mut columns: Vec<String> = BASE_COLUMNS.iter().map(|s| s.to_string()).collect();
    for (k, e) in ESTIMATORS.iter().enumerate() {
        if wants[k] {
            columns.push(format!("Est{}Ms", e.to_uppercase()));
        }
    }
    columns.extend(LOD_COLUMNS.iter().map(|s| s.to_string()));
    columns.extend((0..max_levels).map(|l| format!("AtLevel{l}")));
    columns
}

/// What every frame reads and none changes: the model, the scene, the
/// renderer with the model's noise, the preprocess's results and the LOD
/// policy's fixed terms.
struct Model<'a> {
    cfg: &'a WalkthroughConfig,
    scene: &'a Scene,
    /// The renderer of the actual frames (the model's noise on).
    actual: &'a Renderer,
    /// Which estimators run (indexed as [`ESTIMATORS`]).
    wants: &'a [bool],
    policy: Policy,
    /// The LOD policy's estimator (indexed as [`ESTIMATORS`]).
    lod_est: usize,
    algorithm: Algorithm,
    /// Rendering time of an empty frame (ps).
    empty: f64,
    /// h1-h4's fitted constants (none when no heuristic is estimated).
    constants: Option<Constants>,
    /// The constants the LOD policy's cost reads (the default without any).
    lod_constants: Constants,
    /// Per prototype and level, its pos table.
    tables: &'a [Vec<Option<PosTable>>],
    /// The view-cell estimators' tables.
    view_cells: Option<&'a ViewCellTables>,
    /// The display's refresh period (ps, at least 1).
    refresh: u64,
    /// The refresh period (s): the camera path's time step.
    dt: f64,
    /// The LOD target (ps): refresh x (1 - lod.margin).
    target: f64,
    /// The knapsack's budget (ps): the target less the empty frame.
    knapsack_budget: f64,
    /// The GPU's swap time (ps).
    gpu_swap: f64,
    /// The most levels any prototype has.
    max_levels: usize,
}

impl Model<'_> {
    /// The cost (ps) of the visible object `(i, p)` at `level` under the
    /// LOD policy's estimator, counting pos table reads in `reads`.
    fn cost(&self, (i, p): &(u32, Projection), level: usize, reads: &mut u64) -> f64 {
        let o = &self.scene.objects[*i as usize];
        if self.lod_est < 4 {
            self.lod_constants
                .object(self.lod_est, &features(self.scene, o.proto, level, p))
        } else {
            self.tables[o.proto as usize]
                .get(level)
                .and_then(|t| t.as_ref())
                .map_or(0.0, |t| t.lookup(p.alpha, p.gamma, p.phi, reads))
                .max(0.0)
        }
    }

    /// The prototype of object `i`.
    fn proto(&self, i: u32) -> &Prototype {
        &self.scene.protos[self.scene.objects[i as usize].proto as usize]
    }
}

/// The level choice's plan for one frame.
struct Plan {
    /// The knapsack's total cost (ps; NaN without a predictive policy).
    cost: f64,
    /// Objects on screen the knapsack did not draw.
    dropped: u64,
}

/// How the display showed one frame.
struct Shown {
    /// Refreshes the frame was shown at (at least 1; the extra ones skips).
    refreshes: u64,
    /// Time (ps) from this frame's start to the next one's.
    interval: u64,
}

/// One frame's benefit, levels and popping.
struct Levels {
    /// The image benefit of the levels drawn.
    benefit: f64,
    /// The image benefit had every visible object been drawn at its finest.
    finest: f64,
    /// The sum of the levels drawn.
    level_sum: u64,
    /// Level changes of objects on screen in this frame and the one before.
    switches: u64,
    /// Objects drawn per level.
    at_level: Vec<u64>,
}

/// The frame loop's state: the running sums and series over the frames so
/// far, the previous frame's levels and view, and each frame's scratch
/// buffers (visible objects, their terms, levels, draw order and draws).
struct Walk<'a> {
    m: Model<'a>,
    /// The potentially visible sets of the view cells visited so far.
    pvs: Pvs,
    /// The events of every pipeline run.
    count: Counter,
    /// The frames' run seeds.
    seeds: StreamRng,
    /// Per estimator: its estimate per frame (ms), its wall time (s) and
    /// its operations.
    est: Vec<Vec<f64>>,
    wall: [f64; ESTIMATORS.len()],
    ops: [u64; ESTIMATORS.len()],
    /// The per-frame table.
    rows: Vec<Vec<f64>>,
    /// Per frame: the actual and GPU times (ms), the visible objects, the
    /// triangles and the pixels drawn.
    actual_ms: Vec<f64>,
    gpu_ms: Vec<f64>,
    visible_n: Vec<f64>,
    tris_n: Vec<f64>,
    pix_n: Vec<f64>,
    /// Frames over the refresh period, and frames with the eye inside an object.
    over: u64,
    inside_frames: u64,
    /// This frame's start (ps into the walkthrough).
    start: u64,
    /// This frame's visible objects and projections.
    visible: Vec<(u32, Projection)>,
    /// This frame's draws' features.
    feats: Vec<Features>,
    /// This frame's draws, in order.
    draws: Vec<Draw>,
    /// The reactive policy's state.
    reactive: Reactive,
    /// Per object: its level and whether it was on screen in the frame
    /// before; the objects visible then; that frame's view and eye.
    prev_level: Vec<Option<u32>>,
    prev_seen: Vec<bool>,
    prev_list: Vec<u32>,
    prev_view: Option<View>,
    prev_eye: Option<[f64; 3]>,
    /// Per visible object: the benefit's view-dependent terms and the
    /// level chosen (None: not drawn).
    terms: Vec<BenefitTerms>,
    chosen: Vec<Option<u32>>,
    /// The draw order (indices into `visible`).
    order: Vec<usize>,
    /// Pos table reads of the LOD policy's costs.
    lod_reads: u64,
    skips: u64,
    refreshes: u64,
    switches: u64,
    benefit_sum: f64,
    finest_sum: f64,
    /// Objects drawn per level, over all frames.
    level_counts: Vec<u64>,
    dropped_total: u64,
    unaffordable_total: u64,
    /// The reactive policy's k per frame.
    k_series: Vec<f64>,
    branch_total: BranchStats,
    branch_frames: u64,
}

impl<'a> Walk<'a> {
    /// The state before the first of `frames` frames.
    fn new(m: Model<'a>, pvs: Pvs, count: Counter, frames: usize) -> Walk<'a> {
        let n_objects = m.scene.objects.len();
        Walk {
            seeds: frame_seeds(m.cfg.run.seed),
            est: vec![Vec::with_capacity(frames); ESTIMATORS.len()],
            wall: [0.0f64; ESTIMATORS.len()],
            ops: [0u64; ESTIMATORS.len()],
            rows: Vec::with_capacity(frames),
            actual_ms: Vec::new(),
            gpu_ms: Vec::new(),
            visible_n: Vec::new(),
            tris_n: Vec::new(),
            pix_n: Vec::new(),
            over: 0,
            inside_frames: 0,
            start: 0,
            visible: Vec::new(),
            feats: Vec::new(),
            draws: Vec::new(),
            reactive: Reactive::new(&m.cfg.lod, m.target),
            prev_level: vec![None; n_objects],
            prev_seen: vec![false; n_objects],
            prev_list: Vec::new(),
            prev_view: None,
            prev_eye: None,
            terms: Vec::new(),
            chosen: Vec::new(),
            order: Vec::new(),
            lod_reads: 0,
            skips: 0,
            refreshes: 0,
            switches: 0,
            benefit_sum: 0.0,
            finest_sum: 0.0,
            level_counts: vec![0u64; m.max_levels],
            dropped_total: 0,
            unaffordable_total: 0,
            k_series: Vec::new(),
            branch_total: BranchStats::default(),
            branch_frames: 0,
            m,
            pvs,
            count,
        }
    }
}
