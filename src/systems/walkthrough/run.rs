//! Validating, preparing and running a walkthrough, and its summary.
//!
//! Order of work: the scene, the camera path, then the preprocess (an
//! empty frame, the single-object renders the heuristics are fitted to,
//! the pos tables), all timed exactly (system tasks off: ideal timing, the
//! time-stamp reading of paper 000 §6.2); then per frame: the view cell's
//! PVS, frustum culling, each visible object's projection, every
//! estimator's estimate (each timed on its own), and the frame drawn by
//! the frame pipeline with the model's noise (the actual time).

use std::collections::BTreeMap;
use std::time::Instant;

use rand::Rng;
use serde::Serialize;
use serde_json::Value;

use crate::engine::{PS_PER_MS, RngStreams};
use crate::output::trace::TraceWriter;
use crate::systems::error::{SystemError, invalid};
use crate::systems::summary::{Dist, EventCounts, to_json};

use super::camera::{self, Pose};
use super::config::WalkthroughConfig;
use super::culling::{Projection, Pvs, View, project, sample_projection};
use super::estimators::{Constants, ESTIMATORS, Features, Score, fit};
use super::pos::{PosTable, build as build_table};
use super::render::{Draw, Renderer, frame_seeds, next_seed};
use super::scene::{Scene, SceneTotals, build_scene};
use super::timing::{Clock, TimingMode, TimingSummary};
use super::view_cells::{PVC, VCS, ViewCellSummary, ViewCellTables};

/// LOD policies known by name; only `none` is built so far.
pub const LOD_POLICIES: [&str; 4] = ["none", "reactive", "predictive", "predictive+branch"];

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

/// Checks the keys serde cannot.
pub fn validate(cfg: &WalkthroughConfig) -> Result<(), SystemError> {
    if cfg.system != "walkthrough" {
        return Err(invalid(
            "system",
            format!("expected \"walkthrough\", got {:?}", cfg.system),
        ));
    }
    match cfg.lod.policy.as_str() {
        "none" => {}
        p if LOD_POLICIES.contains(&p) => {
            return Err(invalid(
                "lod.policy",
                format!("{p:?} is not built yet (issue 11 item 5); only \"none\" runs so far"),
            ));
        }
        p => {
            return Err(invalid(
                "lod.policy",
                format!("unknown policy {p:?} (known: {})", LOD_POLICIES.join(", ")),
            ));
        }
    }
    for (i, e) in cfg.estimation.estimators.iter().enumerate() {
        if !ESTIMATORS.contains(&e.as_str()) {
            return Err(invalid(
                &format!("estimation.estimators.{i}"),
                format!("unknown estimator {e:?} (known: {})", ESTIMATORS.join(", ")),
            ));
        }
        if cfg.estimation.estimators[..i].contains(e) {
            return Err(invalid(
                &format!("estimation.estimators.{i}"),
                format!("{e:?} is listed twice"),
            ));
        }
    }
    if cfg.run.frames > MAX_FRAMES {
        return Err(invalid(
            "run.frames",
            format!("{} frames is more than the limit of {MAX_FRAMES}", cfg.run.frames),
        ));
    }
    let heuristics = cfg
        .estimation
        .estimators
        .iter()
        .any(|e| ESTIMATORS[..4].contains(&e.as_str()));
    if cfg.estimation.fit_samples > MAX_FRAMES {
        return Err(invalid(
            "estimation.fit_samples",
            format!("{} is more than the limit of {MAX_FRAMES}", cfg.estimation.fit_samples),
        ));
    }
    if heuristics && cfg.estimation.fit_samples == 0 {
        return Err(invalid(
            "estimation.fit_samples",
            "must be at least 1 when h1-h4 are estimated (their constants are fitted to these renders)",
        ));
    }
    if !(1..=1024).contains(&cfg.estimation.repeats) {
        return Err(invalid(
            "estimation.repeats",
            format!("must be between 1 and 1024, got {}", cfg.estimation.repeats),
        ));
    }
    let p = &cfg.estimation.pos;
    for (key, v, lo) in [
        ("estimation.pos.alpha_steps", p.alpha_steps, 2),
        ("estimation.pos.gamma_steps", p.gamma_steps, 1),
        ("estimation.pos.phi_steps", p.phi_steps, 1),
    ] {
        if !(lo..=256).contains(&v) {
            return Err(invalid(key, format!("must be between {lo} and 256, got {v}")));
        }
    }
    if !(p.phi_min.is_finite()
        && p.phi_max.is_finite()
        && -90.0 <= p.phi_min
        && p.phi_min <= p.phi_max
        && p.phi_max <= 90.0)
    {
        return Err(invalid(
            "estimation.pos.phi_min|estimation.pos.phi_max",
            format!(
                "need -90 <= phi_min <= phi_max <= 90 degrees, got {} and {}",
                p.phi_min, p.phi_max
            ),
        ));
    }
    if !(p.prune_tolerance.is_finite() && (0.0..=1.0).contains(&p.prune_tolerance)) {
        return Err(invalid(
            "estimation.pos.prune_tolerance",
            format!("must be between 0 and 1, got {}", p.prune_tolerance),
        ));
    }
    let v = &cfg.estimation.view_cells;
    if !(1..=360).contains(&v.directions) {
        return Err(invalid(
            "estimation.view_cells.directions",
            format!("must be between 1 and 360, got {}", v.directions),
        ));
    }
    if !(1..=4096).contains(&v.samples) {
        return Err(invalid(
            "estimation.view_cells.samples",
            format!("must be between 1 and 4096, got {}", v.samples),
        ));
    }
    super::timing::validate(cfg.estimation.clock_overhead, cfg.estimation.clock_noise)?;
    check_memory(cfg)
}

fn check_memory(cfg: &WalkthroughConfig) -> Result<(), SystemError> {
    use crate::limits::{DEFAULT_MAX_MEMORY, add_bytes, over_memory_message, show_bytes};
    let mut total = 0u64;
    add_bytes(&mut total, cfg.run.frames, 16 * 8 + 64);
    let mut fit = 0u64;
    add_bytes(&mut fit, cfg.estimation.fit_samples, 48);
    let parts = format!(
        "{} frames x 192 bytes = {}, {} fit samples x 48 bytes = {}",
        cfg.run.frames,
        show_bytes(total),
        cfg.estimation.fit_samples,
        show_bytes(fit)
    );
    total = total.saturating_add(fit);
    let limit = cfg.run.max_memory.map_or(DEFAULT_MAX_MEMORY, |b| b.0);
    if total > limit {
        return Err(invalid("run.max_memory", over_memory_message(total, &parts, limit)));
    }
    Ok(())
}

fn ms(ps: f64) -> f64 {
    ps / PS_PER_MS as f64
}

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

struct Counter {
    events: u64,
    by_kind: Vec<u64>,
    names: &'static [&'static str],
    runs: u64,
}

impl Counter {
    fn add(&mut self, events: u64, by_kind: &[u64], names: &'static [&'static str]) {
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
fn features(scene: &Scene, proto: u32, level: usize, p: &Projection) -> Features {
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
    let render_exact = |draws: &[Draw], count: &mut Counter| -> Result<(f64, f64), SystemError> {
        let (t, by_kind, names) = exact.render_counted(draws, 0, 0)?;
        count.add(t.events, &by_kind, names);
        Ok((t.rt as f64, t.gpu as f64))
    };
    let (empty, empty_gpu) = render_exact(&[], &mut count)?;
    // The clocks the preprocess's renders are read with (timing.rs).
    let est_cfg = &cfg.estimation;
    let clock = |stream: &str| {
        Clock::new(
            est_cfg.timing,
            est_cfg.clock_overhead,
            est_cfg.clock_noise,
            cfg.run.seed,
            stream,
        )
    };
    let (mut fit_clock, mut pos_clock, mut vcs_clock) = (
        clock("estimation.clock.fit"),
        clock("estimation.clock.pos"),
        clock("estimation.clock.vcs"),
    );
    // One object's GPU time: `repeats` copies drawn (state set once), the
    // GPU time beyond the empty frame's divided among them.
    let repeats = cfg.estimation.repeats as usize;
    let mut copies: Vec<Draw> = Vec::with_capacity(repeats);
    let mut object_time = |d: Draw, count: &mut Counter, clock: &mut Clock| -> Result<f64, SystemError> {
        copies.clear();
        copies.resize(repeats, d);
        let (_, gpu) = render_exact(&copies, count)?;
        Ok((clock.read(gpu) - empty_gpu) / repeats as f64)
    };
    let wants: Vec<bool> = ESTIMATORS
        .iter()
        .map(|e| cfg.estimation.estimators.iter().any(|x| x == e))
        .collect();
    let (w, h) = (cfg.camera.width as f64, cfg.camera.height as f64);
    let focal = 0.5 * w / (0.5 * cfg.camera.fov.to_radians()).tan();
    let alpha_range = super::pos::alphas(&cfg.estimation.pos, focal, w, h);
    let (alpha_lo, alpha_hi) = (alpha_range[0].ln(), alpha_range[alpha_range.len() - 1].ln());

    // The heuristics' constants, fitted to single-object renders.
    let constants = if wants[..4].iter().any(|w| *w) && !scene.objects.is_empty() {
        let mut rng = RngStreams::new(cfg.run.seed).stream("estimation.fit");
        let p = &cfg.estimation.pos;
        let mut samples = Vec::with_capacity(cfg.estimation.fit_samples as usize);
        for _ in 0..cfg.estimation.fit_samples {
            let o = &scene.objects[rng.random_range(0..scene.objects.len())];
            let proto = &scene.protos[o.proto as usize];
            let level = rng.random_range(0..proto.levels.len());
            let alpha = rng.random_range(alpha_lo..=alpha_hi).exp();
            let gamma = rng.random_range(0.0..std::f64::consts::TAU);
            let phi = rng.random_range(p.phi_min..=p.phi_max).to_radians();
            let pr = sample_projection(proto, alpha, gamma, phi, focal, w, h);
            let d = Draw {
                proto: o.proto,
                level: level as u32,
                pixels: pr.covered_pixels,
                state: o.state,
            };
            let y = object_time(d, &mut count, &mut fit_clock)?;
            samples.push((features(&scene, o.proto, level, &pr), y));
        }
        Some(fit(&samples))
    } else if wants[..4].iter().any(|w| *w) {
        Some(Constants::default())
    } else {
        None
    };

    // The pos tables, one per prototype in use, finest level (lod.policy = "none").
    let mut tables: Vec<Option<PosTable>> = vec![None; scene.protos.len()];
    let mut pos_tables = None;
    if wants[4] || wants[PVC] {
        let mut used = vec![false; scene.protos.len()];
        for o in &scene.objects {
            used[o.proto as usize] = true;
        }
        let (mut renders, mut full, mut n) = (0u64, 0u64, 0u64);
        for (i, proto) in scene.protos.iter().enumerate() {
            if !used[i] {
                continue;
            }
            let state = scene
                .objects
                .iter()
                .find(|o| o.proto as usize == i)
                .map_or((0, 0, 0), |o| o.state);
            let (table, r) = build_table(&cfg.estimation.pos, proto, 0, (focal, w, h), |_, covered| {
                let d = Draw {
                    proto: i as u32,
                    level: 0,
                    pixels: covered,
                    state,
                };
                object_time(d, &mut count, &mut pos_clock)
            })?;
            renders += r;
            full += table.full_size();
            n += 1;
            tables[i] = Some(table);
        }
        pos_tables = Some(PosTables {
            tables: n,
            renders,
            full_renders: full,
            pruned_fraction: if full > 0 {
                1.0 - renders as f64 / full as f64
            } else {
                0.0
            },
        });
    }
    // The view-cell estimators, for the cells the path visits.
    let mut pvs = Pvs::default();
    let mut view_cells: Option<(ViewCellTables, ViewCellSummary)> = None;
    if wants[VCS] || wants[PVC] {
        let Some(cell) = scene.view_cell else {
            let i = cfg
                .estimation
                .estimators
                .iter()
                .position(|e| e == "vcs" || e == "pvc")
                .unwrap_or(0);
            return Err(invalid(
                &format!("estimation.estimators.{i}"),
                format!(
                    "{:?} needs view cells (the city preset, or scene.view_cell > 0 with listed objects)",
                    cfg.estimation.estimators[i]
                ),
            ));
        };
        let cells = super::view_cells::visited(&poses, cell).len() as u64;
        let v = &cfg.estimation.view_cells;
        let renders = cells * v.directions as u64 * v.samples as u64;
        if wants[VCS] && renders > MAX_FRAMES {
            return Err(invalid(
                "estimation.view_cells.samples",
                format!(
                    "{cells} cells x {} directions x {} samples = {renders} sample views is more than the limit of {MAX_FRAMES}",
                    v.directions, v.samples
                ),
            ));
        }
        let inputs = super::view_cells::Inputs {
            cfg: v,
            cam: &cfg.camera,
            cell,
            poses: &poses,
            tables: &tables,
            want: (wants[VCS], wants[PVC]),
            seed: cfg.run.seed,
        };
        view_cells = Some(super::view_cells::build(
            &inputs,
            &scene,
            &mut pvs,
            &mut vcs_clock,
            |draws| render_exact(draws, &mut count).map(|(rt, _)| rt),
        )?);
    }
    let build_seconds = t0.elapsed().as_secs_f64();

    // The frames.
    let t1 = Instant::now();
    let mut seeds = frame_seeds(cfg.run.seed);
    let all: Vec<u32> = (0..scene.objects.len() as u32).collect();
    let mut est: Vec<Vec<f64>> = vec![Vec::with_capacity(poses.len()); ESTIMATORS.len()];
    let mut wall = [0.0f64; ESTIMATORS.len()];
    let mut ops = [0u64; ESTIMATORS.len()];
    let mut rows = Vec::with_capacity(poses.len());
    let (mut actual_ms, mut gpu_ms, mut visible_n, mut tris_n, mut pix_n) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut over, mut inside_frames) = (0u64, 0u64);
    let mut start = 0u64;
    let mut visible: Vec<(u32, Projection)> = Vec::new();
    let mut feats: Vec<Features> = Vec::new();
    let mut draws: Vec<Draw> = Vec::new();
    for (f, pose) in poses.iter().enumerate() {
        let view = View::new(pose, &cfg.camera);
        let candidates: &[u32] = match scene.view_cell {
            Some(c) => pvs.set(&scene, c, pose.eye, cfg.camera.far),
            None => &all,
        };
        visible.clear();
        feats.clear();
        draws.clear();
        for &i in candidates {
            let o = &scene.objects[i as usize];
            if view.sees_sphere(o.center, o.radius) {
                let p = project(&view, o, &scene.protos[o.proto as usize]);
                visible.push((i, p));
                feats.push(features(&scene, o.proto, 0, &p));
                draws.push(Draw {
                    proto: o.proto,
                    level: 0,
                    pixels: p.covered_pixels,
                    state: o.state,
                });
            }
        }
        if visible.iter().any(|(_, p)| p.inside) {
            inside_frames += 1;
        }
        let mut sums = [0.0f64; ESTIMATORS.len()];
        for k in 0..4 {
            if !wants[k] {
                continue;
            }
            let c = constants.expect("constants exist when a heuristic is wanted");
            let t = Instant::now();
            let sum: f64 = feats.iter().map(|x| c.object(k, x)).sum();
            wall[k] += t.elapsed().as_secs_f64();
            ops[k] += feats.len() as u64;
            sums[k] = sum;
        }
        if wants[4] {
            let t = Instant::now();
            let mut reads = 0u64;
            let mut sum = 0.0;
            for (i, p) in &visible {
                let o = &scene.objects[*i as usize];
                if let Some(tb) = &tables[o.proto as usize] {
                    sum += tb.lookup(p.alpha, p.gamma, p.phi, &mut reads);
                }
            }
            wall[4] += t.elapsed().as_secs_f64();
            ops[4] += reads;
            sums[4] = sum;
        }
        if let Some((vc, _)) = &view_cells {
            for k in [VCS, PVC] {
                if wants[k] {
                    let t = Instant::now();
                    sums[k] = vc.lookup(k, pose);
                    wall[k] += t.elapsed().as_secs_f64();
                    ops[k] += 1;
                }
            }
        }
        let (timing, by_kind, names) = actual.render_counted(&draws, next_seed(&mut seeds), start)?;
        count.add(timing.events, &by_kind, names);
        // RT = the frame's own terms + max(ET_cpu, ET_gpu) (paper 000 §4.1):
        // the empty frame, the CPU's submission work (known), the estimate.
        for k in 0..ESTIMATORS.len() {
            if wants[k] {
                // vcs measured whole frames: its table holds RT itself.
                est[k].push(if k == VCS {
                    ms(sums[k])
                } else {
                    ms(empty + sums[k].max(timing.cpu_submit as f64))
                });
            }
        }
        let interval = if cfg.display.vsync {
            timing.rt.div_ceil(refresh).max(1) * refresh
        } else {
            timing.rt.max(1)
        };
        let rt = ms(timing.rt as f64);
        if timing.rt > refresh {
            over += 1;
        }
        let tris: u64 = draws
            .iter()
            .map(|d| scene.protos[d.proto as usize].levels[d.level as usize].triangles)
            .sum();
        let pix: f64 = draws.iter().map(|d| d.pixels).sum();
        let mut row = vec![
            f as f64,
            start as f64 * 1e-12,
            visible.len() as f64,
            tris as f64,
            pix,
            rt,
            ms(timing.gpu as f64),
            ms(refresh as f64),
        ];
        for k in 0..ESTIMATORS.len() {
            if wants[k] {
                row.push(est[k][f]);
            }
        }
        rows.push(row);
        actual_ms.push(rt);
        gpu_ms.push(ms(timing.gpu as f64));
        visible_n.push(visible.len() as f64);
        tris_n.push(tris as f64);
        pix_n.push(pix);
        start = start.saturating_add(interval);
    }
    let simulate_seconds = t1.elapsed().as_secs_f64();
    let score = |k: usize| wants[k].then(|| Score::of(&est[k], &actual_ms, wall[k], ops[k]));
    let frames = poses.len() as u64;
    let length: f64 = poses
        .windows(2)
        .map(|p: &[Pose]| (0..3).map(|a| (p[1].eye[a] - p[0].eye[a]).powi(2)).sum::<f64>().sqrt())
        .sum();
    let summary = WalkthroughSummary {
        system: "walkthrough",
        description: cfg.description.clone(),
        fidelity: cfg.fidelity,
        seed: cfg.run.seed,
        frames,
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
            length_m: length,
            view_cells_visited: pvs.cells_visited() as u64,
        },
        metrics: WalkMetrics {
            frame_time_ms: Dist::of(&actual_ms),
            gpu_time_ms: Dist::of(&gpu_ms),
            budget_ms: ms(refresh as f64),
            frames_over_budget: over,
            over_budget_fraction: if frames > 0 { over as f64 / frames as f64 } else { 0.0 },
            visible_objects: Dist::of(&visible_n),
            triangles: Dist::of(&tris_n),
            pixels_covered: Dist::of(&pix_n),
            frames_inside_an_object: inside_frames,
            estimation: EstimationSummary {
                empty_frame_ms: ms(empty),
                fit_samples: if constants.is_some() {
                    cfg.estimation.fit_samples
                } else {
                    0
                },
                constants,
                pos_tables,
                h1: score(0),
                h2: score(1),
                h3: score(2),
                h4: score(3),
                pos: score(4),
                vcs: score(VCS),
                pvc: score(PVC),
                view_cells: view_cells.map(|(_, s)| s),
                timing: (cfg.estimation.timing == TimingMode::CpuClock).then(|| TimingSummary {
                    mode: TimingMode::CpuClock.name(),
                    overhead_ms: ms(cfg.estimation.clock_overhead.0 as f64),
                    noise_ms: ms(cfg.estimation.clock_noise.0 as f64),
                    readings: fit_clock.readings() + pos_clock.readings() + vcs_clock.readings(),
                    per_object_bias_ms: ms(cfg.estimation.clock_overhead.0 as f64) / cfg.estimation.repeats as f64,
                }),
            },
        },
    };
    let mut columns: Vec<String> = BASE_COLUMNS.iter().map(|s| s.to_string()).collect();
    for (k, e) in ESTIMATORS.iter().enumerate() {
        if wants[k] {
            columns.push(format!("Est{}Ms", e.to_uppercase()));
        }
    }
    Ok(WalkthroughRun {
        config: cfg,
        summary: to_json(&summary),
        columns,
        rows,
        trace: None,
    })
}
