//! `rendersim predict`: one pass on a calibrated device. The profile's cost
//! formula (`device_profile.rs`) gives each transformed vertex and each
//! shaded fragment its cost for this pass (loop counts, latency floors and
//! triangle setup spread over the vertices, lane waste over the fragments);
//! the frame-pipeline model ([`PassModel`], unified shader pool, triangle
//! fidelity) then runs the pass with the mesh's own triangles and the
//! profile's vertex-cache policy. What the pipeline model does not model is
//! added around it: the pass overhead and the draw calls' fixed costs
//! (a pass of 0 draws is these alone, not simulated), the part of the target's clear and
//! store that the geometry work does not hide, and (taken off) the overlap
//! of vertex and fragment work on the shared cores that the profile
//! fitted (`shared_core_overlap`).

use std::path::Path;

use serde::Serialize;

use super::calibrate::{CalibrateError, vertex_work, vertex_work_in_draws};
use super::coverage::{Coverage, coverage};
use super::device_profile::{DeviceProfile, PassCost, PassLoad};
use super::geometry::DepthOrder;
use super::predict::{PassModel, PredictError, duration_ps, simulate_pass};
use crate::components::vertex_cache::CachePolicy;
use crate::scene::generators::mesh_from_spec;

/// The pass to predict.
#[derive(Debug, Clone, PartialEq)]
pub struct DevicePass {
    /// Mesh generator spec.
    pub mesh: String,
    /// Target width and height.
    pub size: (u32, u32),
    /// Vertex loop iterations.
    pub vs_loops: u32,
    /// Fragment loop iterations.
    pub fs_loops: u32,
    /// Every vertex collapsed to one point.
    pub geometry_only: bool,
    /// Copies of the mesh drawn.
    pub layers: u32,
    /// Their depth order.
    pub order: DepthOrder,
    /// Draw calls the mesh is split into (0: the pass only clears and
    /// stores its target).
    pub draws: u32,
    /// Early depth test on.
    pub depth_test: bool,
}

impl From<&super::passes::PassRow> for DevicePass {
    /// The pass a CSV row measured: one layer, no depth test.
    fn from(r: &super::passes::PassRow) -> Self {
        DevicePass {
            mesh: r.mesh.clone(),
            size: (r.size.width, r.size.height),
            vs_loops: r.vs_loops,
            fs_loops: r.fs_loops,
            geometry_only: r.geometry_only,
            layers: 1,
            order: DepthOrder::FrontToBack,
            depth_test: false,
            draws: r.draws,
        }
    }
}

/// What `rendersim predict` prints.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DevicePrediction {
    /// Pass time, ns.
    pub pass_time_ns: f64,
    /// Vertex-shader invocations (all layers).
    pub vs_invocations: u64,
    /// Fragment-shader invocations (shaded fragments, all layers).
    pub fs_invocations: u64,
    /// The profile's closed-form cost of the pass, ns (single layer times
    /// layers; no depth test).
    pub closed_form_ns: f64,
    /// The terms of one layer's cost.
    pub terms: PassCost,
    /// What one layer covers.
    pub coverage: Coverage,
    /// Events the simulation handled.
    pub events: u64,
    /// Wall time of the simulation, seconds.
    pub sim_wall_seconds: f64,
}

/// Errors of a prediction.
#[derive(Debug, thiserror::Error)]
pub enum DevicePredictError {
    /// Bad mesh.
    #[error(transparent)]
    Mesh(#[from] CalibrateError),
    /// Bad pass options.
    #[error("{0}")]
    Option(String),
    /// The simulation failed.
    #[error(transparent)]
    Sim(#[from] PredictError),
}

/// Predicts `pass` on the device of `profile`.
pub fn predict_on_device(profile: &DeviceProfile, pass: &DevicePass) -> Result<DevicePrediction, DevicePredictError> {
    let (w, h) = pass.size;
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(DevicePredictError::Option(format!(
            "size {w}x{h}: width and height must be 1..16384"
        )));
    }
    if pass.layers == 0 {
        return Err(DevicePredictError::Option("layers must be at least 1".into()));
    }
    let max_draws = super::passes::MAX_DRAWS;
    if pass.draws > max_draws {
        return Err(DevicePredictError::Option(format!(
            "--draws {}: at most {max_draws} draws in one pass",
            pass.draws
        )));
    }
    use crate::limits::{MAX_PASS_LAYERS, MAX_PASS_TRIANGLES};
    if pass.layers > MAX_PASS_LAYERS {
        return Err(DevicePredictError::Option(format!(
            "--layers {}: more than the limit of {MAX_PASS_LAYERS} layers (each layer is a copy of the mesh \
             simulated triangle by triangle, so the prediction's time grows with the layers; \
             a screen pass of depth complexity beyond {MAX_PASS_LAYERS} is not one the studies measure)",
            pass.layers
        )));
    }
    let mesh = mesh_from_spec(&pass.mesh, Path::new(".")).map_err(|e| CalibrateError::Mesh {
        spec: pass.mesh.clone(),
        message: e.to_string(),
    })?;
    let drawn = mesh.triangles().saturating_mul(u64::from(pass.layers));
    if drawn > MAX_PASS_TRIANGLES {
        return Err(DevicePredictError::Option(format!(
            "--layers {} of {} ({} triangles each) make {drawn} triangles, more than the limit of {MAX_PASS_TRIANGLES} \
             a prediction simulates (about two events each: beyond it a prediction takes minutes); use fewer layers or a smaller mesh",
            pass.layers,
            pass.mesh,
            mesh.triangles()
        )));
    }
    let policy: CachePolicy = profile
        .device
        .vertex_cache
        .parse()
        .map_err(|e| DevicePredictError::Option(format!("device.vertex_cache: {e}")))?;
    // The load counts the vertex work of the pass's draws (each starts with
    // an empty cache); the simulation runs the mesh as one draw, so each
    // of its vertices carries the draws' geometry cost over its own count.
    let work = vertex_work_in_draws(&mesh, &policy, pass.draws);
    let vertices = work.invocations;
    let sim_vertices = if pass.draws == 1 {
        vertices
    } else {
        vertex_work(&mesh, &policy).invocations
    };
    let cov = if pass.geometry_only {
        Coverage::default()
    } else {
        coverage(&mesh, &pass.mesh, w, h)
    };
    if pass.draws == 0 {
        // Nothing drawn: the pass clears and stores its target.
        let load = PassLoad {
            pixels: f64::from(w) * f64::from(h),
            ..PassLoad::default()
        };
        let terms = profile.costs.cost(&load);
        return Ok(DevicePrediction {
            pass_time_ns: terms.pass_ns,
            vs_invocations: 0,
            fs_invocations: 0,
            closed_form_ns: terms.pass_ns,
            terms,
            coverage: Coverage::default(),
            events: 0,
            sim_wall_seconds: 0.0,
        });
    }
    let load = PassLoad {
        pixels: f64::from(w) * f64::from(h),
        draws: f64::from(pass.draws),
        vertices: vertices as f64,
        vertex_batches: work.batches as f64,
        triangles: work.triangles as f64,
        vs_loops: f64::from(pass.vs_loops),
        fs_loops: f64::from(pass.fs_loops),
        coverage: cov,
    };
    let c = &profile.costs;
    let terms = c.cost(&load);
    let layers = f64::from(pass.layers);
    let per_ns = |total: f64, n: f64| if n > 0.0 { total / n } else { 0.0 };
    // Fragments shaded per layer-sized draw: every layer without depth
    // test; with it, as the simulator's early-z does by order.
    let drawn = mesh.triangles().max(1) as f64;
    let frag_cost = per_ns(terms.fragment_ns, cov.fragments as f64);
    let model = PassModel {
        mesh: pass.mesh.clone(),
        cache: profile.device.vertex_cache.clone(),
        layers: pass.layers,
        per_vertex: duration_ps(1e3 * per_ns(terms.geometry_ns, sim_vertices as f64)),
        per_fragment: duration_ps(1e3 * frag_cost),
        per_rejected_fragment: duration_ps(1e3 * per_ns(terms.fragment_base_ns, cov.fragments as f64)),
        fragments_per_triangle: cov.fragments as f64 / drawn,
        depth_order: match (pass.depth_test, pass.order) {
            (false, _) | (true, DepthOrder::BackToFront) => "back_to_front",
            (true, DepthOrder::FrontToBack) => "front_to_back",
            (true, DepthOrder::Random) => "random",
        }
        .into(),
        fifo_depth: 64,
        binning: false,
        unified: true,
    };
    let sim = simulate_pass(&model)?;
    let geometry_total = layers * terms.geometry_ns;
    // The simulated pool runs a layer's vertex and fragment work one after
    // the other; the overlap the profile fitted (`shared_core_overlap`) is
    // taken off its time as the closed form takes it off the sum.
    let overlap = layers * terms.overlap_ns;
    let pass_time_ns =
        sim.gpu_ms * 1e6 + c.pass_overhead_ns + terms.draws_ns + (terms.clear_ns - geometry_total).max(0.0) - overlap;
    let shaded_layers = match (pass.depth_test, pass.order) {
        (false, _) | (true, DepthOrder::BackToFront) => layers,
        (true, DepthOrder::FrontToBack) => 1.0,
        (true, DepthOrder::Random) => (1..=pass.layers).map(|k| 1.0 / f64::from(k)).sum(),
    };
    Ok(DevicePrediction {
        pass_time_ns,
        vs_invocations: if pass.draws == 1 {
            sim.transformed_vertices
        } else {
            vertices * u64::from(pass.layers)
        },
        fs_invocations: (cov.fragments as f64 * shaded_layers).round() as u64,
        closed_form_ns: c.pass_overhead_ns
            + terms.draws_ns
            + terms.clear_ns.max(geometry_total)
            + layers * terms.fragment_ns
            - overlap,
        terms,
        coverage: cov,
        events: sim.events,
        sim_wall_seconds: sim.wall_seconds,
    })
}
