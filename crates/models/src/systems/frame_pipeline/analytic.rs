//! Paper 000 §4.1's expected per-frame terms from a model's costs alone (no
//! queueing): the closed-form bounds the checks use to refuse a run that
//! could not finish in time, and the summary reports beside the simulated
//! metrics. Below both, so neither imports the other.

use serde::Serialize;

use crate::engine::PS_PER_MS;

use super::config::{FramePipelineConfig, FramesWorkload, WorkloadConfig};
use super::workload::SceneProgram;

/// Expected per-frame terms of paper 000 §4.1: ET_cpu, and ET_gpu split into
/// front end, geometry and fragment. `gpu_max_ms` = max of the three (the
/// front end overlaps the stages: it prepares the next draw while they work),
/// a lower bound of the GPU time when the GPU never starves; `gpu_sum_ms` =
/// their sum, the time with no overlap at all (§4.5.1's "sum" estimate). A
/// stalling state setup (`gpu.state_change_stalls`) holds the front end and
/// the geometry stage together: it is in both their terms, once in the sum.
pub(super) fn analytic_terms(cfg: &FramePipelineConfig, scene: Option<&SceneProgram>) -> AnalyticTerms {
    let c = &cfg.cpu;
    // In f64: sums of huge costs must not wrap before the range check.
    let base_cpu = c.input_sampling.0 as f64 + c.clear.0 as f64 + c.swap.0 as f64 + c.non_render.mean();
    let base_front = cfg.gpu.clear.0 as f64 + cfg.gpu.swap.0 as f64 + 2.0 * cfg.gpu.command.0 as f64;
    let (cpu, front, geo, frag, setup) = match (&cfg.workload, scene) {
        (WorkloadConfig::Fixed(f), _) => (
            base_cpu + f.cpu.mean(),
            base_front + f.gpu.mean() + cfg.gpu.command.0 as f64,
            0.0,
            0.0,
            0.0,
        ),
        (WorkloadConfig::Frames(f), _) => (
            base_cpu + FramesWorkload::mean_ps(&f.cpu) + FramesWorkload::mean_ps(&f.present),
            base_front + FramesWorkload::mean_ps(&f.gpu) + cfg.gpu.command.0 as f64,
            0.0,
            0.0,
            0.0,
        ),
        (WorkloadConfig::Scene(_), Some(s)) => {
            // A copy on a shared bus is a step of its own: at least its
            // time alone (at its memory's rate).
            let copies = |d: &super::workload::DrawItem| if s.bus_shared { d.copy.0 as f64 } else { 0.0 };
            let cpu: f64 = s.draws.iter().map(|d| d.cpu.0 as f64 + copies(d)).sum();
            let front: f64 = s.draws.iter().map(|d| d.front.0 as f64).sum();
            let setup: f64 = s.draws.iter().map(|d| d.setup.0 as f64).sum();
            // A draw from AGP memory: no shorter than its bytes over the whole bus.
            let bus = cfg.bus.bandwidth.bytes_per_ps();
            let geo: f64 = s
                .draws
                .iter()
                .map(|d| {
                    let m = &s.meshes[d.mesh as usize];
                    let fetch = m.transformed as f64 * s.groups[d.group as usize].fetch_bytes_per_vertex / bus;
                    (m.geometry_time.0 as f64).max(fetch)
                })
                .sum();
            let frag: f64 = s
                .draws
                .iter()
                .map(|d| {
                    let g = &s.groups[d.group as usize];
                    s.meshes[d.mesh as usize].triangles as f64 * g.pixels.mean() * g.cost_per_pixel()
                })
                .sum();
            (base_cpu + cpu, base_front + front, geo, frag, setup)
        }
        _ => (base_cpu, base_front, 0.0, 0.0, 0.0),
    };
    let p = PS_PER_MS as f64;
    // The setup holds both the front end and the geometry stage.
    let (front, geo, sum) = (front + setup, geo + setup, front + geo + frag + setup);
    AnalyticTerms {
        cpu_ms: cpu / p,
        gpu_front_end_ms: front / p,
        geometry_ms: geo / p,
        fragment_ms: frag / p,
        gpu_max_ms: front.max(geo).max(frag) / p,
        gpu_sum_ms: sum / p,
        frame_max_ms: cpu.max(front.max(geo).max(frag)) / p,
        frame_sum_ms: cpu.max(sum) / p,
    }
}

/// The closed-form frame terms from the expected costs (no queueing),
/// milliseconds: what a frame costs each unit, and the two classic readings
/// of the frame time (the slowest unit; the GPU's units in series).
#[derive(Debug, Clone, Serialize)]
pub struct AnalyticTerms {
    /// CPU work per frame.
    pub cpu_ms: f64,
    /// GPU front end per frame.
    pub gpu_front_end_ms: f64,
    /// Geometry per frame.
    pub geometry_ms: f64,
    /// Fragment per frame.
    pub fragment_ms: f64,
    /// The slowest GPU unit.
    pub gpu_max_ms: f64,
    /// The GPU's units added up.
    pub gpu_sum_ms: f64,
    /// The slowest unit, CPU included.
    pub frame_max_ms: f64,
    /// The CPU or the GPU's sum, whichever is larger.
    pub frame_sum_ms: f64,
}
