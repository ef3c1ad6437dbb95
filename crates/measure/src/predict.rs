//! The simulator's prediction of one measured pass: a frame-pipeline model
//! (paper 000 §4) with one object per drawn layer of a mesh, costs per
//! transformed vertex and per fragment taken from a device's calibration
//! passes, run at `triangle` fidelity so the geometry and fragment stages
//! overlap through the triangle FIFO exactly as the simulator models them.
//! Everything outside the GPU's geometry and fragment stages costs nothing,
//! so the frame's GPU time is the pass.

use crate::config::ModelSource;
use crate::engine::Duration;
use crate::systems::{SimError, run_model};

/// A pass to predict.
#[derive(Debug, Clone, PartialEq)]
pub struct PassModel {
    /// Mesh generator spec (`grid:64x64`, ...).
    pub mesh: String,
    /// Vertex-cache policy (`lavapipe`, `fifo:32`, ...).
    pub cache: String,
    /// Copies of the mesh drawn, one object each, all covering the same pixels.
    pub layers: u32,
    /// Cost per transformed vertex.
    pub per_vertex: Duration,
    /// Cost per fragment shaded.
    pub per_fragment: Duration,
    /// Cost per fragment rejected by early-z.
    pub per_rejected_fragment: Duration,
    /// Fragments per triangle (the device's unit: on lavapipe, shader
    /// invocations counted per 4x4 block).
    pub fragments_per_triangle: f64,
    /// `front_to_back`, `back_to_front` or `random` (with `layers` > 1).
    pub depth_order: String,
    /// Triangles the FIFO between geometry and fragment stage holds.
    pub fifo_depth: u32,
    /// Sort-middle binning (`gpu.fragment.binning = "draw"`) instead of the FIFO.
    pub binning: bool,
    /// `gpu.architecture = "unified"` (vertex and fragment shading share
    /// the shader pool) instead of `"split"`.
    pub unified: bool,
}

impl PassModel {
    /// The model file the simulator runs.
    pub fn toml(&self) -> String {
        format!(
            r#"system = "frame_pipeline"
description = "one measured pass: {mesh} x {layers}"
fidelity = "triangle"
[run]
frames = 1
warmup_frames = 0
seed = 1
[cpu]
max_frames_ahead = 1
[gpu]
architecture = "{arch}"
[gpu.geometry]
vertex_shader = "{pv}"
vertex_cache = "{cache}"
[gpu.fragment]
fifo_depth = {fifo}
binning = "{binning}"
per_fragment = "{pf}"
per_rejected_fragment = "{pr}"
[display]
vsync = false
present_mode = "immediate"
[noise]
enabled = false
[workload]
kind = "scene"
depth_complexity = {layers}.0
depth_order = "{order}"
[[workload.groups]]
name = "layer"
count = {layers}
mesh = "{mesh}"
triangle_pixels = {frag:?}
"#,
            mesh = self.mesh,
            layers = self.layers,
            pv = self.per_vertex,
            cache = self.cache,
            fifo = self.fifo_depth,
            binning = if self.binning { "draw" } else { "off" },
            arch = if self.unified { "unified" } else { "split" },
            pf = self.per_fragment,
            pr = self.per_rejected_fragment,
            order = self.depth_order,
            frag = self.fragments_per_triangle,
        )
    }
}

/// What the simulator predicts for a pass.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PassPrediction {
    /// GPU time of the frame (= the pass), milliseconds.
    pub gpu_ms: f64,
    /// Transformed vertices per frame (all layers).
    pub transformed_vertices: u64,
    /// Events the simulation handled.
    pub events: u64,
    /// Wall time of the simulation, seconds.
    pub wall_seconds: f64,
}

/// Errors of a prediction.
#[derive(Debug, thiserror::Error)]
pub enum PredictError {
    /// The generated model or the simulation failed.
    #[error("simulating the pass failed: {0}")]
    Sim(#[from] SimError),
    /// The run did not report what a prediction needs.
    #[error("the simulator's summary lacks {0}")]
    Missing(&'static str),
}

/// Runs the pass model and reads its GPU time.
pub fn simulate_pass(m: &PassModel) -> Result<PassPrediction, PredictError> {
    let src = ModelSource::from_text("<measured pass>", &m.toml());
    let table = src.table().map_err(SimError::from)?;
    let t = std::time::Instant::now();
    let run = run_model(&src, &table, None)?;
    let wall_seconds = t.elapsed().as_secs_f64();
    let Ok(r) = run.downcast::<crate::systems::frame_pipeline::PipelineRun>() else {
        return Err(PredictError::Missing("a frame-pipeline run"));
    };
    let gpu_ms = (r.results.metrics.gpu_time_ms.mean).ok_or(PredictError::Missing("metrics.gpu_time_ms.mean"))?;
    let transformed_vertices = (r.results.scene.as_ref())
        .map(|s| s.transformed_vertices)
        .ok_or(PredictError::Missing("scene.transformed_vertices"))?;
    Ok(PassPrediction {
        gpu_ms,
        transformed_vertices: transformed_vertices * u64::from(m.layers),
        events: r.stats.events,
        wall_seconds,
    })
}

/// Picoseconds to a [`Duration`], rounded; negative or non-finite costs
/// (a calibration below its noise) become zero.
pub fn duration_ps(ps: f64) -> Duration {
    if ps.is_finite() && ps > 0.0 {
        Duration::from_ps_f64(ps)
    } else {
        Duration::ZERO
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model() -> PassModel {
        PassModel {
            mesh: "grid:16x16".into(),
            cache: "lavapipe".into(),
            layers: 1,
            per_vertex: Duration::ps(100_000),
            per_fragment: Duration::ps(1_000),
            per_rejected_fragment: Duration::ZERO,
            fragments_per_triangle: 10.0,
            depth_order: "front_to_back".into(),
            fifo_depth: 1,
            binning: false,
            unified: false,
        }
    }

    #[test]
    fn geometry_only_pass_is_vertices_times_cost() {
        let m = PassModel {
            per_fragment: Duration::ZERO,
            ..model()
        };
        let p = simulate_pass(&m).unwrap();
        // grid:16x16 under lavapipe's policy transforms 306 vertices (study H1).
        assert_eq!(p.transformed_vertices, 306);
        assert!((p.gpu_ms - 306.0 * 100e-6).abs() < 1e-9, "{}", p.gpu_ms);
    }

    #[test]
    fn deep_fifo_tends_to_max_shallow_to_sum() {
        // Geometry 306 x 100 ns = 30.6 us; fragments 512 x 10 x 6 ns = 30.72 us.
        let base = PassModel {
            per_fragment: Duration::ps(6_000),
            ..model()
        };
        let (g, f) = (306.0 * 100e-6, 512.0 * 10.0 * 6e-6);
        let shallow = simulate_pass(&base).unwrap().gpu_ms;
        let deep = simulate_pass(&PassModel {
            fifo_depth: 100_000,
            ..base.clone()
        })
        .unwrap()
        .gpu_ms;
        assert!(deep < shallow, "deep {deep} shallow {shallow}");
        assert!(deep >= f64::max(g, f) - 1e-9 && shallow <= g + f + 1e-9);
        assert!(
            deep < 0.75 * (g + f),
            "deep fifo {deep} should be near max {}",
            g.max(f)
        );
        let binned = simulate_pass(&PassModel {
            binning: true,
            ..base.clone()
        })
        .unwrap()
        .gpu_ms;
        assert!((binned - (g + f)).abs() < 1e-9, "binned {binned} vs sum {}", g + f);
    }

    #[test]
    fn early_z_layers_cost_what_the_order_passes() {
        let m = PassModel {
            layers: 4,
            per_vertex: Duration::ZERO,
            per_rejected_fragment: Duration::ps(100),
            ..model()
        };
        let f2b = simulate_pass(&m).unwrap().gpu_ms;
        let b2f = simulate_pass(&PassModel {
            depth_order: "back_to_front".into(),
            ..m.clone()
        })
        .unwrap()
        .gpu_ms;
        let frags = 4.0 * 512.0 * 10.0;
        assert!((b2f - frags * 1e-6).abs() < 1e-9, "{b2f}");
        assert!((f2b - frags * (0.25 * 1e-6 + 0.75 * 1e-7)).abs() < 1e-9, "{f2b}");
        assert_eq!(duration_ps(-5.0), Duration::ZERO);
        assert_eq!(duration_ps(f64::NAN), Duration::ZERO);
    }
}
