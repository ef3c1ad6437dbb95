//! `rendersim bench build`: what building a scene costs, against the
//! simulation it is built for.
//!
//! Two parts, each a ratio measured in one run:
//! - the vertex-cache reordering of paper 000 section 4.5
//!   ([`crate::scene::optimize`], Forsyth's walk) in its fast form against
//!   its first, direct form ([`optimize_vertex_cache_reference`]) on the same
//!   index buffers, checking that both return the same bytes;
//! - the shipped models that build `grid:96x96:optimized` (the default model,
//!   one-mesh, single-view, h2-pass), run as `experiments/fidelity-models.toml`
//!   runs them (10 frames after 2 warm-up frames, no noise) at `triangle` and
//!   `draw` fidelity: the scene build, the event loop and the whole run, and
//!   how many times faster the whole draw-fidelity run is.

use std::time::Instant;

use super::BenchError;
use super::spread::{Spread, paired_ratio};
use crate::config::{ModelSource, Overrides};
use crate::scene::generators::mesh_from_spec;
use crate::scene::optimize::{optimize_vertex_cache, optimize_vertex_cache_reference};
use crate::systems::frame_pipeline::run::PipelineRun;
use crate::systems::run_model;

/// One mesh reordered by both forms.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ReorderBench {
    /// The mesh spec whose index buffer is reordered.
    pub spec: String,
    /// Its triangles.
    pub triangles: u64,
    /// Repetitions.
    pub reps: usize,
    /// Seconds of [`optimize_vertex_cache_reference`].
    pub reference_s: Spread,
    /// Seconds of [`optimize_vertex_cache`].
    pub fast_s: Spread,
    /// Direct over fast, repetition by repetition.
    pub speedup: Spread,
}

/// One model at one fidelity, over `reps` runs.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ModelRun {
    /// Scene build seconds (`build_seconds` of the summary).
    pub build_s: Spread,
    /// Event-loop seconds (`simulate_seconds`).
    pub simulate_s: Spread,
    /// The whole run (`wall_seconds`: build and event loop).
    pub wall_s: Spread,
    /// The whole runs' seconds, in order (for ratios run by run).
    #[serde(skip)]
    walls: Vec<f64>,
    /// The event loops' seconds, in order.
    #[serde(skip)]
    simulates: Vec<f64>,
}

/// One model at both fidelities.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ModelBuildBench {
    /// The model's name (`default`, `one-mesh`, ...).
    pub model: String,
    /// Repetitions per fidelity.
    pub reps: usize,
    /// At `triangle` fidelity.
    pub triangle: ModelRun,
    /// At `draw` fidelity.
    pub draw: ModelRun,
    /// Whole run, triangle over draw, run by run.
    pub speedup: Spread,
    /// Event loop, triangle over draw, run by run.
    pub simulate_speedup: Spread,
}

/// The build benchmark's results.
#[derive(Debug, Clone, serde::Serialize)]
pub struct BuildBench {
    /// The reordering, fast against direct.
    pub reorders: Vec<ReorderBench>,
    /// The models.
    pub models: Vec<ModelBuildBench>,
}

/// The shipped models that build a vertex-cache-optimized grid.
const MODELS: [(&str, &str); 4] = [
    ("default", include_str!("../../models/default.toml")),
    ("one-mesh", include_str!("../../models/one-mesh.toml")),
    ("single-view", include_str!("../../models/single-view.toml")),
    ("h2-pass", include_str!("../../models/h2-pass.toml")),
];

/// Reorders `spec`'s index buffer `reps` times with each form, alternating;
/// fails if the two forms ever differ.
pub fn reorder_case(spec: &str, reps: usize) -> Result<ReorderBench, BenchError> {
    let mesh =
        mesh_from_spec(spec, std::path::Path::new(".")).map_err(|e| BenchError::Reorder(format!("{spec}: {e}")))?;
    let reps = reps.max(1);
    let (mut reference, mut fast) = (Vec::new(), Vec::new());
    for _ in 0..reps {
        let t = Instant::now();
        let a = optimize_vertex_cache_reference(&mesh.indices, mesh.vertex_count);
        reference.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        let b = optimize_vertex_cache(&mesh.indices, mesh.vertex_count);
        fast.push(t.elapsed().as_secs_f64());
        if a != b {
            return Err(BenchError::Reorder(format!(
                "{spec}: the fast reordering differs from the reference"
            )));
        }
    }
    Ok(ReorderBench {
        spec: spec.to_string(),
        triangles: mesh.triangles(),
        reps,
        reference_s: Spread::of(&reference),
        fast_s: Spread::of(&fast),
        speedup: paired_ratio(&reference, &fast),
    })
}

fn model_run(name: &str, text: &str, fidelity: &str, reps: usize) -> Result<ModelRun, BenchError> {
    let (mut build, mut simulate, mut wall) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..reps.max(1) {
        let mut src = ModelSource::from_text(&format!("models/{name}.toml"), text);
        let mut table = src.table()?;
        Overrides::with_sets(&[
            "run.frames=10".to_string(),
            "run.warmup_frames=2".to_string(),
            "noise.enabled=false".to_string(),
            format!("fidelity=\"{fidelity}\""),
        ])
        .apply(&mut src, &mut table)?;
        let r = run_model(&src, &table, None)?
            .downcast::<PipelineRun>()
            .map_err(|_| BenchError::System {
                model: src.name.clone(),
                system: "frame_pipeline",
            })?;
        let s = &r.results;
        build.push(s.build_seconds);
        simulate.push(s.simulate_seconds);
        wall.push(s.wall_seconds);
    }
    Ok(ModelRun {
        build_s: Spread::of(&build),
        simulate_s: Spread::of(&simulate),
        wall_s: Spread::of(&wall),
        walls: wall,
        simulates: simulate,
    })
}

/// The build benchmark at `scale`: at 1, `repeats` reorderings of
/// `grid:96x96` (the shipped models' mesh, in the row order it is built
/// from), `grid:96x96:shuffled:1` and `grid:300x300` (a smaller grid at
/// smaller scales), and `repeats` runs of each model at each fidelity.
pub fn build_bench(scale: f64, repeats: usize) -> Result<BuildBench, BenchError> {
    let reps = repeats.max(1);
    let big = ((300.0 * scale.sqrt()) as u32).max(8);
    let mut reorders = Vec::new();
    for spec in [
        "grid:96x96".to_string(),
        "grid:96x96:shuffled:1".to_string(),
        format!("grid:{big}x{big}"),
    ] {
        reorders.push(reorder_case(&spec, reps)?);
    }
    let mut models = Vec::new();
    for (name, text) in MODELS {
        let triangle = model_run(name, text, "triangle", reps)?;
        let draw = model_run(name, text, "draw", reps)?;
        models.push(ModelBuildBench {
            model: name.to_string(),
            reps,
            speedup: paired_ratio(&triangle.walls, &draw.walls),
            simulate_speedup: paired_ratio(&triangle.simulates, &draw.simulates),
            triangle,
            draw,
        });
    }
    Ok(BuildBench { reorders, models })
}
