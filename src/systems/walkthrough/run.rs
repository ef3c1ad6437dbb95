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

use crate::engine::PS_PER_MS;
use crate::output::trace::TraceWriter;
use crate::systems::error::SystemError;
use crate::systems::summary::{Dist, EventCounts, to_json};

use super::branch::{BranchStats, Switchable, evaluate, mark_switchable};
use super::camera::{self, Pose};
use super::config::WalkthroughConfig;
use super::culling::{Projection, View, project};
use super::estimators::{ESTIMATORS, Features, Score};
use super::lod::{BenefitTerms, Offer, Policy, Reactive, select};
use super::preprocess::{Preprocess, preprocess};
use super::render::{Draw, Renderer, frame_seeds, next_seed};
use super::scene::{Scene, build_scene};
use super::timing::{TimingMode, TimingSummary};
use super::validate::validate;
use super::view_cells::{PVC, VCS};

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
        mut pvs,
        view_cells,
        clock_readings,
    } = preprocess(&cfg, &scene, &poses, &exact, &wants, policy, &mut count)?;
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
    // Level of detail: the policy's state across frames.
    let lod = &cfg.lod;
    let target = refresh as f64 * (1.0 - lod.margin);
    let knapsack_budget = (target - empty).max(0.0);
    let mut reactive = Reactive::new(lod, target);
    let c = constants.unwrap_or_default();
    let n_objects = scene.objects.len();
    let mut prev_level: Vec<Option<u32>> = vec![None; n_objects];
    let mut prev_seen: Vec<bool> = vec![false; n_objects];
    let mut prev_list: Vec<u32> = Vec::new();
    let mut prev_view: Option<View> = None;
    let mut prev_eye: Option<[f64; 3]> = None;
    let max_levels = scene.protos.iter().map(|p| p.levels.len()).max().unwrap_or(1);
    let mut terms: Vec<BenefitTerms> = Vec::new();
    let mut chosen: Vec<Option<u32>> = Vec::new();
    let mut order: Vec<usize> = Vec::new();
    let mut lod_reads = 0u64;
    let (mut skips, mut refreshes, mut switches) = (0u64, 0u64, 0u64);
    let (mut benefit_sum, mut finest_sum) = (0.0f64, 0.0f64);
    let mut level_counts = vec![0u64; max_levels];
    let (mut dropped_total, mut unaffordable_total) = (0u64, 0u64);
    let mut k_series: Vec<f64> = Vec::new();
    let mut branch_total = BranchStats::default();
    let mut branch_frames = 0u64;
    let gpu_swap = cfg.gpu.swap.0 as f64;
    for (f, pose) in poses.iter().enumerate() {
        let view = View::new(pose, &cfg.camera);
        let candidates: &[u32] = match scene.view_cell {
            Some(c) => pvs.set(&scene, c, pose.eye, cfg.camera.far),
            None => &all,
        };
        visible.clear();
        for &i in candidates {
            let o = &scene.objects[i as usize];
            if view.sees_sphere(o.center, o.radius) {
                let p = project(&view, o, &scene.protos[o.proto as usize]);
                visible.push((i, p));
            }
        }
        if visible.iter().any(|(_, p)| p.inside) {
            inside_frames += 1;
        }
        // The benefit's view-dependent terms.
        terms.clear();
        for (i, p) in &visible {
            let o = &scene.objects[*i as usize];
            let v = view.to_view(o.center);
            terms.push(BenefitTerms::of(
                lod,
                p.disk_pixels,
                v,
                prev_view.map(|pv| pv.to_view(o.center)),
                dt,
            ));
        }
        // The cost of object `vi` at `level` under the policy's estimator (ps).
        let cost_of = |vi: usize, level: usize, reads: &mut u64| -> f64 {
            let (i, p) = &visible[vi];
            let o = &scene.objects[*i as usize];
            if lod_est < 4 {
                c.object(lod_est, &features(&scene, o.proto, level, p))
            } else {
                tables[o.proto as usize]
                    .get(level)
                    .and_then(|t| t.as_ref())
                    .map_or(0.0, |t| t.lookup(p.alpha, p.gamma, p.phi, reads))
                    .max(0.0)
            }
        };
        // The levels chosen (None: not drawn), per visible object.
        chosen.clear();
        let mut plan_cost = f64::NAN;
        let mut dropped = 0u64;
        match policy {
            Policy::None => chosen.extend(visible.iter().map(|_| Some(0))),
            Policy::Reactive => {
                for (i, p) in &visible {
                    let proto = &scene.protos[scene.objects[*i as usize].proto as usize];
                    chosen.push(Some(
                        reactive.level(proto.levels.iter().map(|l| l.triangles), p.disk_pixels),
                    ));
                }
            }
            Policy::Predictive | Policy::PredictiveBranch => {
                let mut offers = Vec::with_capacity(visible.len());
                let mut previous = Vec::with_capacity(visible.len());
                for (vi, (i, _)) in visible.iter().enumerate() {
                    let proto = &scene.protos[scene.objects[*i as usize].proto as usize];
                    let before = prev_level[*i as usize];
                    offers.push(Offer {
                        levels: proto
                            .levels
                            .iter()
                            .enumerate()
                            .map(|(l, lv)| {
                                (
                                    cost_of(vi, l, &mut lod_reads),
                                    terms[vi].selection(lod, lv.triangles, l as u32, before),
                                )
                            })
                            .collect(),
                    });
                    previous.push(before);
                }
                let (sel, unaffordable) = select(&offers, knapsack_budget as u64, algorithm, &previous)?;
                unaffordable_total += unaffordable as u64;
                plan_cost = sel.total_cost as f64;
                chosen.extend(sel.levels.iter().copied());
                // Dropped: on screen (positive size) and not drawn; an
                // object whose disk is clipped away has no benefit and is
                // never drawn by the knapsack (not counted).
                dropped = chosen
                    .iter()
                    .zip(&terms)
                    .filter(|(l, t)| l.is_none() && t.size > 0.0)
                    .count() as u64;
            }
        }
        // The draw order: the visible objects in scene order; with the
        // branch, its switchable objects last, nearest first (branch.rs).
        order.clear();
        order.extend((0..visible.len()).filter(|&vi| chosen[vi].is_some()));
        let mut switchable: Vec<Switchable> = Vec::new();
        let mut draw_cost: Vec<f64> = Vec::new();
        if policy == Policy::PredictiveBranch && lod.branch_objects > 0 {
            let dist = |vi: usize| {
                let o = &scene.objects[visible[vi].0 as usize];
                let d = sub3(o.center, pose.eye);
                (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
            };
            switchable = mark_switchable(
                &mut order,
                lod,
                |vi| chosen[vi].unwrap_or(0) as usize,
                |vi| {
                    scene.protos[scene.objects[visible[vi].0 as usize].proto as usize]
                        .levels
                        .len()
                },
                dist,
                |vi, l| cost_of(vi, l, &mut lod_reads),
            );
            for &vi in &order {
                draw_cost.push(cost_of(vi, chosen[vi].unwrap_or(0) as usize, &mut lod_reads));
            }
        }
        draws.clear();
        for &vi in &order {
            let (i, p) = &visible[vi];
            let o = &scene.objects[*i as usize];
            draws.push(Draw {
                proto: o.proto,
                level: chosen[vi].unwrap_or(0),
                pixels: p.covered_pixels,
                state: o.state,
            });
        }
        let seed = next_seed(&mut seeds);
        let mut bstats = BranchStats::default();
        if !switchable.is_empty() {
            bstats = evaluate(
                &mut draws,
                &switchable,
                &mut draw_cost,
                refresh as f64,
                gpu_swap,
                |prefix| {
                    let (t, by_kind, names) = actual.render_counted(prefix, seed, start)?;
                    count.add(t.events, &by_kind, names);
                    Ok((t.rt as f64 - gpu_swap).max(0.0))
                },
            )?;
            for (d, &vi) in draws.iter().zip(&order) {
                chosen[vi] = Some(d.level);
            }
            branch_total.switched += bstats.switched;
            branch_total.tokens += bstats.tokens;
            branch_total.prefix_runs += bstats.prefix_runs;
            if bstats.switched > 0 {
                branch_frames += 1;
            }
        }
        feats.clear();
        for (d, &vi) in draws.iter().zip(&order) {
            feats.push(features(&scene, d.proto, d.level as usize, &visible[vi].1));
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
            for (d, &vi) in draws.iter().zip(&order) {
                let p = &visible[vi].1;
                if let Some(Some(tb)) = tables[d.proto as usize].get(d.level as usize) {
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
        let (timing, by_kind, names) = actual.render_counted(&draws, seed, start)?;
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
        // The display: the frame started at a vertical blank and is shown at
        // the first one after its rendering time; the refreshes in between
        // show the frame before again (skips).
        let shown = timing.rt.div_ceil(refresh).max(1);
        skips += shown - 1;
        refreshes += shown;
        let interval = if cfg.display.waits_for_vblank() {
            shown * refresh
        } else {
            timing.rt.max(1)
        };
        if policy == Policy::Reactive {
            k_series.push(reactive.k);
            reactive.record(timing.rt as f64);
        }
        let rt = ms(timing.rt as f64);
        if timing.rt > refresh {
            over += 1;
        }
        // Benefit, levels, popping.
        let (mut frame_benefit, mut frame_finest, mut level_sum) = (0.0f64, 0.0f64, 0u64);
        let mut frame_switches = 0u64;
        let mut at_level = vec![0u64; max_levels];
        for (vi, (i, _)) in visible.iter().enumerate() {
            let proto = &scene.protos[scene.objects[*i as usize].proto as usize];
            frame_finest += terms[vi].image(lod, proto.levels[0].triangles);
            if let Some(l) = chosen[vi] {
                frame_benefit += terms[vi].image(lod, proto.levels[l as usize].triangles);
                level_sum += l as u64;
                at_level[l as usize] += 1;
            }
            // Popping: a level change of an object on screen in both frames
            // (an object whose disk is clipped away entirely is not seen).
            if terms[vi].size > 0.0 && prev_seen[*i as usize] && prev_level[*i as usize] != chosen[vi] {
                frame_switches += 1;
            }
        }
        for &j in &prev_list {
            prev_seen[j as usize] = false;
            prev_level[j as usize] = None;
        }
        prev_list.clear();
        for (vi, (i, _)) in visible.iter().enumerate() {
            prev_seen[*i as usize] = terms[vi].size > 0.0;
            prev_level[*i as usize] = chosen[vi];
            prev_list.push(*i);
        }
        prev_view = Some(view);
        switches += frame_switches;
        benefit_sum += frame_benefit;
        finest_sum += frame_finest;
        dropped_total += dropped;
        for (a, b) in level_counts.iter_mut().zip(&at_level) {
            *a += b;
        }
        let moved = prev_eye.map_or(0.0, |e| {
            let d = sub3(pose.eye, e);
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
        });
        prev_eye = Some(pose.eye);
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
        row.extend([
            (shown - 1) as f64,
            refreshes as f64,
            moved,
            frame_benefit,
            frame_finest,
            if draws.is_empty() {
                0.0
            } else {
                level_sum as f64 / draws.len() as f64
            },
            draws.len() as f64,
            dropped as f64,
            frame_switches as f64,
            ms(empty + plan_cost),
            if policy == Policy::Reactive {
                *k_series.last().unwrap_or(&f64::NAN)
            } else {
                f64::NAN
            },
            bstats.tokens as f64,
            bstats.switched as f64,
        ]);
        row.extend(at_level.iter().map(|&n| n as f64));
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
    let per_frame = |x: f64| if frames > 0 { x / frames as f64 } else { 0.0 };
    let displayed_seconds = refreshes as f64 * refresh as f64 * 1e-12;
    let drawn_total: u64 = level_counts.iter().sum();
    let mut notes = Vec::new();
    if policy.predictive() && knapsack_budget <= 0.0 && !visible_n.iter().all(|v| *v == 0.0) {
        notes.push(format!(
            "the target {:.3} ms (refresh x (1 - lod.margin)) is not above the empty frame's {:.3} ms: no object fits the knapsack, nothing is drawn",
            ms(target),
            ms(empty)
        ));
    } else if unaffordable_total > 0 {
        notes.push(format!(
            "{unaffordable_total} visible (object, frame) pairs had no level within the knapsack budget of {:.3} ms and were not drawn",
            ms(knapsack_budget)
        ));
    }
    let lod_summary = LodSummary {
        policy: cfg.lod.policy.clone(),
        estimator: cfg.lod.estimator.clone(),
        algorithm: cfg.lod.algorithm.clone(),
        target_ms: ms(target),
        knapsack_budget_ms: ms(knapsack_budget),
        mean_level: if drawn_total > 0 {
            level_counts
                .iter()
                .enumerate()
                .map(|(l, n)| l as f64 * *n as f64)
                .sum::<f64>()
                / drawn_total as f64
        } else {
            0.0
        },
        objects_per_level: level_counts.iter().map(|n| per_frame(*n as f64)).collect(),
        dropped_per_frame: per_frame(dropped_total as f64),
        unaffordable_object_frames: unaffordable_total,
        switches,
        reactive_k: (policy == Policy::Reactive).then(|| Dist::of(&k_series)),
        branch: (policy == Policy::PredictiveBranch).then_some(BranchSummary {
            tokens_per_frame: per_frame(branch_total.tokens as f64),
            switched_objects: branch_total.switched as u64,
            frames_with_switch: branch_frames,
            prefix_runs: branch_total.prefix_runs as u64,
        }),
        notes,
    };
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
                    readings: clock_readings,
                    per_object_bias_ms: ms(cfg.estimation.clock_overhead.0 as f64) / cfg.estimation.repeats as f64,
                }),
            },
            frame_skips: skips,
            frame_skips_per_minute: if displayed_seconds > 0.0 {
                skips as f64 / (displayed_seconds / 60.0)
            } else {
                0.0
            },
            displayed_seconds,
            benefit_mean: per_frame(benefit_sum),
            benefit_fraction: if finest_sum > 0.0 {
                benefit_sum / finest_sum
            } else {
                1.0
            },
            lod_switches_per_second: if displayed_seconds > 0.0 {
                switches as f64 / displayed_seconds
            } else {
                0.0
            },
            lod: lod_summary,
        },
    };
    let mut columns: Vec<String> = BASE_COLUMNS.iter().map(|s| s.to_string()).collect();
    for (k, e) in ESTIMATORS.iter().enumerate() {
        if wants[k] {
            columns.push(format!("Est{}Ms", e.to_uppercase()));
        }
    }
    columns.extend(LOD_COLUMNS.iter().map(|s| s.to_string()));
    columns.extend((0..max_levels).map(|l| format!("AtLevel{l}")));
    Ok(WalkthroughRun {
        config: cfg,
        summary: to_json(&summary),
        columns,
        rows,
        trace: None,
    })
}
