//! One frame of the walkthrough (paper 000 §7.1-7.2): culling by the view
//! cell's PVS and the frustum, the LOD policy's levels (paper 001), the
//! draw order and the conditional branch (§6.4), every estimator's
//! estimate (§5), the frame drawn by the frame pipeline with the model's
//! noise (the actual time), its display and skips, its benefit and
//! popping, and its row of the per-frame table. `Walk::frame` takes
//! them in that order.

use std::time::Instant;

use crate::systems::error::SystemError;

use super::super::branch::{BranchStats, Switchable, evaluate, mark_switchable};
use super::super::camera::Pose;
use super::super::culling::features;
use super::super::culling::{View, project};
use super::super::estimators::ESTIMATORS;
use super::super::lod::{BenefitTerms, Offer, Policy, select};
use super::super::render::{Draw, Timing, next_seed};
use super::super::view_cells::{PVC, VCS};
use super::{Levels, Plan, Shown, Walk, ms, sub3};

impl Walk<'_> {
    /// Runs frame `f` at `pose`: culling, the benefit's terms, the level
    /// choice, the draw order and the branch, the estimates, the frame
    /// drawn, its display, its benefit and popping, and its table row.
    pub(super) fn frame(&mut self, f: usize, pose: &Pose) -> Result<(), SystemError> {
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
}
