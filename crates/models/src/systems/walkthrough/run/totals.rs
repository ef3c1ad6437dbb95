//! The walkthrough's summary after its last frame: the estimators' scores
//! (paper 000 Table 6 and §7.3), the LOD policy's totals and the run's
//! metrics, as typed structs (`summary.rs`).

use crate::systems::summary::Dist;

use super::super::estimators::Score;
use super::super::lod::Policy;
use super::super::summary::{BranchSummary, EstimationSummary, LodSummary, PosTables, WalkMetrics};
use super::super::timing::{TimingMode, TimingSummary};
use super::super::view_cells::{PVC, VCS, ViewCellSummary};
use super::{Walk, ms};

impl Walk<'_> {
    /// The estimators' summary after the last frame: their scores, with
    /// the preprocess's `pos_tables`, `view_cells` and `clock_readings`.
    pub(super) fn estimation_summary(
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
    pub(super) fn metrics(&self, estimation: EstimationSummary, frames: u64) -> WalkMetrics {
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
