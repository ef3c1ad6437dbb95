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

use std::collections::BTreeMap;
use std::time::Instant;

use serde_json::Value;

use crate::engine::{PS_PER_MS, StreamRng};
use crate::output::trace::TraceWriter;
use crate::systems::error::SystemError;
use crate::systems::summary::{Dist, EventCounts, to_json};

use super::branch::{BranchStats, Switchable, evaluate, mark_switchable};
use super::camera::{self, Pose};
use super::config::WalkthroughConfig;
use super::culling::{Projection, Pvs, View, project};
use super::estimators::{Constants, ESTIMATORS, Features, Score};
use super::lod::{BenefitTerms, Offer, Policy, Reactive, select};
use super::pos::PosTable;
use super::preprocess::{Preprocess, preprocess};
use super::render::{Draw, Renderer, Timing, frame_seeds, next_seed};
use super::scene::{Prototype, Scene, build_scene};
use super::timing::{TimingMode, TimingSummary};
use super::validate::validate;
use super::view_cells::{PVC, VCS, ViewCellSummary, ViewCellTables};
use crate::components::lod_select::Algorithm;

pub use super::lod::LOD_POLICIES;
pub use super::summary::{
    BASE_COLUMNS, BranchSummary, CameraSummary, EstimationSummary, LOD_COLUMNS, LodSummary, PosTables, WalkMetrics,
    WalkthroughSummary,
};

/// Most frames and fit samples a run may ask for.
pub const MAX_FRAMES: u64 = 10_000_000;

/// Everything a run produced.
#[derive(Debug)]
pub struct WalkthroughRun {
    /// The model as run.
    pub config: WalkthroughConfig,
    /// The summary.
    pub summary: Value,
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

pub(super) struct Counter {
    events: u64,
    by_kind: Vec<u64>,
    names: &'static [&'static str],
    runs: u64,
}

impl Counter {
    pub(super) fn add(&mut self, events: u64, by_kind: &[u64], names: &'static [&'static str]) {
        self.events += events;
        if self.by_kind.len() < by_kind.len() {
            self.by_kind.resize(by_kind.len(), 0);
        }
        for (a, b) in self.by_kind.iter_mut().zip(by_kind) {
            *a += b;
        }
        self.names = names;
        self.runs += 1;
    }
}

/// One object's features at `level` in projection `p`.
pub(super) fn features(scene: &Scene, proto: u32, level: usize, p: &Projection) -> Features {
    let l = scene.protos[proto as usize].levels[level];
    Features {
        triangles: l.triangles as f64,
        transformed: l.transformed as f64,
        vertices: l.vertices as f64,
        pixels: p.disk_pixels,
    }
}

/// Runs the walkthrough.
pub fn run_walkthrough(cfg: WalkthroughConfig) -> Result<WalkthroughRun, SystemError> {
    validate(&cfg)?;
    let t0 = Instant::now();
    let scene = build_scene(&cfg.scene, cfg.run.seed)?;
    camera::validate(&cfg.camera, &scene)?;
    let refresh = cfg.display.refresh.period.0.max(1);
    let dt = refresh as f64 * 1e-12;
    let poses = camera::path(&cfg.camera, &scene, cfg.run.frames, dt, cfg.run.seed)?;
    let actual = Renderer::new(&cfg, &scene, true)?;
    let exact = Renderer::new(&cfg, &scene, false)?;
    let mut count = Counter {
        events: 0,
        by_kind: Vec::new(),
        names: &[],
        runs: 0,
    };
    let wants: Vec<bool> = ESTIMATORS
        .iter()
        .map(|e| cfg.estimation.estimators.iter().any(|x| x == e))
        .collect();
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
        config: cfg,
        summary: to_json(&summary),
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

    /// Runs frame `f` at `pose`: culling, the benefit's terms, the level
    /// choice, the draw order and the branch, the estimates, the frame
    /// drawn, its display, its benefit and popping, and its table row.
    fn frame(&mut self, f: usize, pose: &Pose) -> Result<(), SystemError> {
        let view = View::new(pose, &self.m.cfg.camera);
        self.cull(pose, &view);
        self.benefit_terms(&view);
        let plan = self.choose_levels()?;
        let (switchable, mut draw_cost) = self.draw_order(pose);
        self.collect_draws();
        let seed = next_seed(&mut self.seeds);
        let branch = self.branch(&switchable, &mut draw_cost, seed)?;
        let sums = self.estimate(pose);
        let timing = self.render(seed, &sums)?;
        let shown = self.display(&timing);
        let levels = self.tally_levels(view, &plan);
        self.record(f, pose, &timing, &shown, &plan, &levels, &branch);
        self.start = self.start.saturating_add(shown.interval);
        Ok(())
    }

    /// Culling: the view cell's PVS (or every object), then the frustum;
    /// each visible object's projection.
    fn cull(&mut self, pose: &Pose, view: &View) {
        let scene = self.m.scene;
        self.visible.clear();
        let visible = &mut self.visible;
        self.pvs
            .for_each_visible(scene, pose.eye, view, self.m.cfg.camera.far, |i| {
                let o = &scene.objects[i as usize];
                visible.push((i, project(view, o, &scene.protos[o.proto as usize])));
            });
        if self.visible.iter().any(|(_, p)| p.inside) {
            self.inside_frames += 1;
        }
    }

    /// The benefit's view-dependent terms of each visible object.
    fn benefit_terms(&mut self, view: &View) {
        self.terms.clear();
        for (i, p) in &self.visible {
            let o = &self.m.scene.objects[*i as usize];
            let v = view.to_view(o.center);
            self.terms.push(BenefitTerms::of(
                &self.m.cfg.lod,
                p.disk_pixels,
                v,
                self.prev_view.map(|pv| pv.to_view(o.center)),
                self.m.dt,
            ));
        }
    }

    /// The level choice: the LOD policy's level (None: not drawn) per
    /// visible object, into `chosen`.
    fn choose_levels(&mut self) -> Result<Plan, SystemError> {
        let m = &self.m;
        let lod = &m.cfg.lod;
        self.chosen.clear();
        let mut plan = Plan {
            cost: f64::NAN,
            dropped: 0,
        };
        match m.policy {
            Policy::None => self.chosen.extend(self.visible.iter().map(|_| Some(0))),
            Policy::Reactive => {
                for (i, p) in &self.visible {
                    let proto = m.proto(*i);
                    self.chosen.push(Some(
                        self.reactive
                            .level(proto.levels.iter().map(|l| l.triangles), p.disk_pixels),
                    ));
                }
            }
            Policy::Predictive | Policy::PredictiveBranch => {
                let mut offers = Vec::with_capacity(self.visible.len());
                let mut previous = Vec::with_capacity(self.visible.len());
                for (vi, v) in self.visible.iter().enumerate() {
                    let proto = m.proto(v.0);
                    let before = self.prev_level[v.0 as usize];
                    offers.push(Offer {
                        levels: proto
                            .levels
                            .iter()
                            .enumerate()
                            .map(|(l, lv)| {
                                (
                                    m.cost(v, l, &mut self.lod_reads),
                                    self.terms[vi].selection(lod, lv.triangles, l as u32, before),
                                )
                            })
                            .collect(),
                    });
                    previous.push(before);
                }
                let (sel, unaffordable) = select(&offers, m.knapsack_budget as u64, m.algorithm, &previous)?;
                self.unaffordable_total += unaffordable as u64;
                plan.cost = sel.total_cost as f64;
                self.chosen.extend(sel.levels.iter().copied());
                // Dropped: on screen (positive size) and not drawn; an
                // object whose disk is clipped away has no benefit and is
                // never drawn by the knapsack (not counted).
                plan.dropped = self
                    .chosen
                    .iter()
                    .zip(&self.terms)
                    .filter(|(l, t)| l.is_none() && t.size > 0.0)
                    .count() as u64;
            }
        }
        Ok(plan)
    }

    /// The draw order, into `order`: the visible objects drawn, in scene
    /// order; with the branch, its switchable objects last, nearest first
    /// (branch.rs). Returns the switchable objects and the estimated cost
    /// of each draw in order (both empty without the branch).
    fn draw_order(&mut self, pose: &Pose) -> (Vec<Switchable>, Vec<f64>) {
        let m = &self.m;
        self.order.clear();
        self.order
            .extend((0..self.visible.len()).filter(|&vi| self.chosen[vi].is_some()));
        let mut switchable: Vec<Switchable> = Vec::new();
        let mut draw_cost: Vec<f64> = Vec::new();
        if m.policy == Policy::PredictiveBranch && m.cfg.lod.branch_objects > 0 {
            let visible = &self.visible;
            let chosen = &self.chosen;
            let lod_reads = &mut self.lod_reads;
            let dist = |vi: usize| {
                let o = &m.scene.objects[visible[vi].0 as usize];
                let d = sub3(o.center, pose.eye);
                (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
            };
            switchable = mark_switchable(
                &mut self.order,
                &m.cfg.lod,
                |vi| chosen[vi].unwrap_or(0) as usize,
                |vi| m.proto(visible[vi].0).levels.len(),
                dist,
                |vi, l| m.cost(&visible[vi], l, lod_reads),
            );
            for &vi in &self.order {
                draw_cost.push(m.cost(&visible[vi], chosen[vi].unwrap_or(0) as usize, lod_reads));
            }
        }
        (switchable, draw_cost)
    }

    /// The frame's draws, into `draws`: each object in `order` at its level.
    fn collect_draws(&mut self) {
        self.draws.clear();
        for &vi in &self.order {
            let (i, p) = &self.visible[vi];
            let o = &self.m.scene.objects[*i as usize];
            self.draws.push(Draw {
                proto: o.proto,
                level: self.chosen[vi].unwrap_or(0),
                pixels: p.covered_pixels,
                state: o.state,
            });
        }
    }

    /// The branch (with switchable objects): evaluates the draw prefixes
    /// with run seed `seed`, coarsens the switched objects' levels in
    /// `draws` and `chosen`, and adds to the branch's totals.
    fn branch(
        &mut self,
        switchable: &[Switchable],
        draw_cost: &mut [f64],
        seed: u64,
    ) -> Result<BranchStats, SystemError> {
        if switchable.is_empty() {
            return Ok(BranchStats::default());
        }
        let (actual, start, gpu_swap) = (self.m.actual, self.start, self.m.gpu_swap);
        let count = &mut self.count;
        let bstats = evaluate(
            &mut self.draws,
            switchable,
            draw_cost,
            self.m.refresh as f64,
            gpu_swap,
            |prefix| {
                let (t, by_kind, names) = actual.render_counted(prefix, seed, start)?;
                count.add(t.events, &by_kind, names);
                Ok((t.rt as f64 - gpu_swap).max(0.0))
            },
        )?;
        for (d, &vi) in self.draws.iter().zip(&self.order) {
            self.chosen[vi] = Some(d.level);
        }
        self.branch_total.switched += bstats.switched;
        self.branch_total.tokens += bstats.tokens;
        self.branch_total.prefix_runs += bstats.prefix_runs;
        if bstats.switched > 0 {
            self.branch_frames += 1;
        }
        Ok(bstats)
    }

    /// Every wanted estimator's estimate of the frame's draws at `pose`
    /// (ps, before the frame's own terms), each timed on its own.
    fn estimate(&mut self, pose: &Pose) -> [f64; ESTIMATORS.len()] {
        let m = &self.m;
        self.feats.clear();
        for (d, &vi) in self.draws.iter().zip(&self.order) {
            self.feats
                .push(features(m.scene, d.proto, d.level as usize, &self.visible[vi].1));
        }
        let mut sums = [0.0f64; ESTIMATORS.len()];
        for (k, sum_k) in sums.iter_mut().enumerate().take(4) {
            if !m.wants[k] {
                continue;
            }
            let c = m.constants.expect("constants exist when a heuristic is wanted");
            let t = Instant::now();
            let sum: f64 = self.feats.iter().map(|x| c.object(k, x)).sum();
            self.wall[k] += t.elapsed().as_secs_f64();
            self.ops[k] += self.feats.len() as u64;
            *sum_k = sum;
        }
        if m.wants[4] {
            let t = Instant::now();
            let mut reads = 0u64;
            let mut sum = 0.0;
            for (d, &vi) in self.draws.iter().zip(&self.order) {
                let p = &self.visible[vi].1;
                if let Some(Some(tb)) = m.tables[d.proto as usize].get(d.level as usize) {
                    sum += tb.lookup(p.alpha, p.gamma, p.phi, &mut reads);
                }
            }
            self.wall[4] += t.elapsed().as_secs_f64();
            self.ops[4] += reads;
            sums[4] = sum;
        }
        if let Some(vc) = m.view_cells {
            for k in [VCS, PVC] {
                if m.wants[k] {
                    let t = Instant::now();
                    sums[k] = vc.lookup(k, pose);
                    self.wall[k] += t.elapsed().as_secs_f64();
                    self.ops[k] += 1;
                }
            }
        }
        sums
    }

    /// The frame drawn by the actual renderer with run seed `seed`; each
    /// wanted estimator's estimate of it (ms) from its `sums`.
    fn render(&mut self, seed: u64, sums: &[f64; ESTIMATORS.len()]) -> Result<Timing, SystemError> {
        let (timing, by_kind, names) = self.m.actual.render_counted(&self.draws, seed, self.start)?;
        self.count.add(timing.events, &by_kind, names);
        // RT = the frame's own terms + max(ET_cpu, ET_gpu) (paper 000 §4.1):
        // the empty frame, the CPU's submission work (known), the estimate.
        for (k, &sum) in sums.iter().enumerate() {
            if self.m.wants[k] {
                // vcs measured whole frames: its table holds RT itself.
                self.est[k].push(if k == VCS {
                    ms(sum)
                } else {
                    ms(self.m.empty + sum.max(timing.cpu_submit as f64))
                });
            }
        }
        Ok(timing)
    }

    /// The display: the frame started at a vertical blank and is shown at
    /// the first one after its rendering time; the refreshes in between
    /// show the frame before again (skips). Feeds the reactive policy the
    /// frame's time.
    fn display(&mut self, timing: &Timing) -> Shown {
        let refresh = self.m.refresh;
        let shown = timing.rt.div_ceil(refresh).max(1);
        self.skips += shown - 1;
        self.refreshes += shown;
        let interval = if self.m.cfg.display.waits_for_vblank() {
            shown * refresh
        } else {
            timing.rt.max(1)
        };
        if self.m.policy == Policy::Reactive {
            self.k_series.push(self.reactive.k);
            self.reactive.record(timing.rt as f64);
        }
        if timing.rt > refresh {
            self.over += 1;
        }
        Shown {
            refreshes: shown,
            interval,
        }
    }

    /// The frame's benefit, levels and popping against the frame before;
    /// then this frame (its levels, what was on screen, `view`) becomes
    /// the frame before, and the totals take the frame's.
    fn tally_levels(&mut self, view: View, plan: &Plan) -> Levels {
        let m = &self.m;
        let lod = &m.cfg.lod;
        let mut t = Levels {
            benefit: 0.0,
            finest: 0.0,
            level_sum: 0,
            switches: 0,
            at_level: vec![0u64; m.max_levels],
        };
        for (vi, (i, _)) in self.visible.iter().enumerate() {
            let proto = m.proto(*i);
            t.finest += self.terms[vi].image(lod, proto.levels[0].triangles);
            if let Some(l) = self.chosen[vi] {
                t.benefit += self.terms[vi].image(lod, proto.levels[l as usize].triangles);
                t.level_sum += l as u64;
                t.at_level[l as usize] += 1;
            }
            // Popping: a level change of an object on screen in both frames
            // (an object whose disk is clipped away entirely is not seen).
            if self.terms[vi].size > 0.0
                && self.prev_seen[*i as usize]
                && self.prev_level[*i as usize] != self.chosen[vi]
            {
                t.switches += 1;
            }
        }
        for &j in &self.prev_list {
            self.prev_seen[j as usize] = false;
            self.prev_level[j as usize] = None;
        }
        self.prev_list.clear();
        for (vi, (i, _)) in self.visible.iter().enumerate() {
            self.prev_seen[*i as usize] = self.terms[vi].size > 0.0;
            self.prev_level[*i as usize] = self.chosen[vi];
            self.prev_list.push(*i);
        }
        self.prev_view = Some(view);
        self.switches += t.switches;
        self.benefit_sum += t.benefit;
        self.finest_sum += t.finest;
        self.dropped_total += plan.dropped;
        for (a, b) in self.level_counts.iter_mut().zip(&t.at_level) {
            *a += b;
        }
        t
    }

    /// Frame `f`'s table row and its per-frame series.
    #[allow(clippy::too_many_arguments)]
    fn record(
        &mut self,
        f: usize,
        pose: &Pose,
        timing: &Timing,
        shown: &Shown,
        plan: &Plan,
        levels: &Levels,
        branch: &BranchStats,
    ) {
        let m = &self.m;
        let rt = ms(timing.rt as f64);
        let moved = self.prev_eye.map_or(0.0, |e| {
            let d = sub3(pose.eye, e);
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
        });
        self.prev_eye = Some(pose.eye);
        let tris: u64 = self
            .draws
            .iter()
            .map(|d| m.scene.protos[d.proto as usize].levels[d.level as usize].triangles)
            .sum();
        let pix: f64 = self.draws.iter().map(|d| d.pixels).sum();
        let mut row = vec![
            f as f64,
            self.start as f64 * 1e-12,
            self.visible.len() as f64,
            tris as f64,
            pix,
            rt,
            ms(timing.gpu as f64),
            ms(m.refresh as f64),
        ];
        for k in 0..ESTIMATORS.len() {
            if m.wants[k] {
                row.push(self.est[k][f]);
            }
        }
        row.extend([
            (shown.refreshes - 1) as f64,
            self.refreshes as f64,
            moved,
            levels.benefit,
            levels.finest,
            if self.draws.is_empty() {
                0.0
            } else {
                levels.level_sum as f64 / self.draws.len() as f64
            },
            self.draws.len() as f64,
            plan.dropped as f64,
            levels.switches as f64,
            ms(m.empty + plan.cost),
            if m.policy == Policy::Reactive {
                *self.k_series.last().unwrap_or(&f64::NAN)
            } else {
                f64::NAN
            },
            branch.tokens as f64,
            branch.switched as f64,
        ]);
        row.extend(levels.at_level.iter().map(|&n| n as f64));
        self.rows.push(row);
        self.actual_ms.push(rt);
        self.gpu_ms.push(ms(timing.gpu as f64));
        self.visible_n.push(self.visible.len() as f64);
        self.tris_n.push(tris as f64);
        self.pix_n.push(pix);
    }

    /// The estimators' summary after the last frame: their scores, with
    /// the preprocess's `pos_tables`, `view_cells` and `clock_readings`.
    fn estimation_summary(
        &self,
        pos_tables: Option<PosTables>,
        view_cells: Option<ViewCellSummary>,
        clock_readings: u64,
    ) -> EstimationSummary {
        let m = &self.m;
        let e = &m.cfg.estimation;
        let score = |k: usize| m.wants[k].then(|| Score::of(&self.est[k], &self.actual_ms, self.wall[k], self.ops[k]));
        EstimationSummary {
            empty_frame_ms: ms(m.empty),
            fit_samples: if m.constants.is_some() { e.fit_samples } else { 0 },
            constants: m.constants,
            pos_tables,
            h1: score(0),
            h2: score(1),
            h3: score(2),
            h4: score(3),
            pos: score(4),
            vcs: score(VCS),
            pvc: score(PVC),
            view_cells,
            timing: (e.timing == TimingMode::CpuClock).then(|| TimingSummary {
                mode: TimingMode::CpuClock.name(),
                overhead_ms: ms(e.clock_overhead.0 as f64),
                noise_ms: ms(e.clock_noise.0 as f64),
                readings: clock_readings,
                per_object_bias_ms: ms(e.clock_overhead.0 as f64) / e.repeats as f64,
            }),
        }
    }

    /// The LOD policy's summary after the last of `frames` frames, with
    /// its notes.
    fn lod_summary(&self, frames: u64) -> LodSummary {
        let m = &self.m;
        let per_frame = |x: f64| if frames > 0 { x / frames as f64 } else { 0.0 };
        let drawn_total: u64 = self.level_counts.iter().sum();
        let mut notes = Vec::new();
        if m.policy.predictive() && m.knapsack_budget <= 0.0 && !self.visible_n.iter().all(|v| *v == 0.0) {
            notes.push(format!(
                "the target {:.3} ms (refresh x (1 - lod.margin)) is not above the empty frame's {:.3} ms: no object fits the knapsack, nothing is drawn",
                ms(m.target),
                ms(m.empty)
            ));
        } else if self.unaffordable_total > 0 {
            notes.push(format!(
                "{} visible (object, frame) pairs had no level within the knapsack budget of {:.3} ms and were not drawn",
                self.unaffordable_total,
                ms(m.knapsack_budget)
            ));
        }
        LodSummary {
            policy: m.cfg.lod.policy.clone(),
            estimator: m.cfg.lod.estimator.clone(),
            algorithm: m.cfg.lod.algorithm.clone(),
            target_ms: ms(m.target),
            knapsack_budget_ms: ms(m.knapsack_budget),
            mean_level: if drawn_total > 0 {
                self.level_counts
                    .iter()
                    .enumerate()
                    .map(|(l, n)| l as f64 * *n as f64)
                    .sum::<f64>()
                    / drawn_total as f64
            } else {
                0.0
            },
            objects_per_level: self.level_counts.iter().map(|n| per_frame(*n as f64)).collect(),
            dropped_per_frame: per_frame(self.dropped_total as f64),
            unaffordable_object_frames: self.unaffordable_total,
            switches: self.switches,
            reactive_k: (m.policy == Policy::Reactive).then(|| Dist::of(&self.k_series)),
            branch: (m.policy == Policy::PredictiveBranch).then_some(BranchSummary {
                tokens_per_frame: per_frame(self.branch_total.tokens as f64),
                switched_objects: self.branch_total.switched as u64,
                frames_with_switch: self.branch_frames,
                prefix_runs: self.branch_total.prefix_runs as u64,
            }),
            notes,
        }
    }

    /// The walkthrough's metrics after the last of `frames` frames, with
    /// the estimators' summary `estimation`.
    fn metrics(&self, estimation: EstimationSummary, frames: u64) -> WalkMetrics {
        let refresh = self.m.refresh;
        let per_frame = |x: f64| if frames > 0 { x / frames as f64 } else { 0.0 };
        let displayed_seconds = self.refreshes as f64 * refresh as f64 * 1e-12;
        WalkMetrics {
            frame_time_ms: Dist::of(&self.actual_ms),
            gpu_time_ms: Dist::of(&self.gpu_ms),
            budget_ms: ms(refresh as f64),
            frames_over_budget: self.over,
            over_budget_fraction: if frames > 0 {
                self.over as f64 / frames as f64
            } else {
                0.0
            },
            visible_objects: Dist::of(&self.visible_n),
            triangles: Dist::of(&self.tris_n),
            pixels_covered: Dist::of(&self.pix_n),
            frames_inside_an_object: self.inside_frames,
            estimation,
            frame_skips: self.skips,
            frame_skips_per_minute: if displayed_seconds > 0.0 {
                self.skips as f64 / (displayed_seconds / 60.0)
            } else {
                0.0
            },
            displayed_seconds,
            benefit_mean: per_frame(self.benefit_sum),
            benefit_fraction: if self.finest_sum > 0.0 {
                self.benefit_sum / self.finest_sum
            } else {
                1.0
            },
            lod_switches_per_second: if displayed_seconds > 0.0 {
                self.switches as f64 / displayed_seconds
            } else {
                0.0
            },
            lod: self.lod_summary(frames),
        }
    }
}
