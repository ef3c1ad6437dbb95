//! Drawing one frame of the walkthrough through the frame pipeline: the
//! frame's visible objects become the draws of a one-frame frame-pipeline
//! run (CPU thread, command FIFO, GPU front end, geometry and fragment work
//! on the configured architecture, system-task noise, swap), built with
//! the pipeline's own workload code (`build_program`) and simulated by its
//! event model (`PipelinePlan::with_program`). Nothing of the GPU model is copied.
//!
//! Each frame is run on its own, from an idle pipeline, and timed from the
//! CPU's start to the GPU's last work: the frame's rendering time RT, as
//! paper 000 §7.1 measured it (the pipeline synchronised around each
//! measurement). Each frame's run draws from its own seed, taken in frame
//! order from the `walkthrough.frames` stream, and periodic system tasks
//! keep their phase along the walkthrough's timeline.

use rand::Rng;

use crate::components::distribution::Dist;
use crate::engine::{Duration, RngStreams, StreamRng};
use crate::scene::config::{SceneWorkload, StateOrder, View};
use crate::systems::checked::Checked;
use crate::systems::error::SystemError;
use crate::systems::frame_pipeline::config::{FramePipelineConfig, RunConfig, WorkloadConfig};
use crate::systems::frame_pipeline::workload::{
    GroupInfo, Instance, MeshInfo, Misses, build_program, early_z_pass, fragment_costs, timed_mesh,
};
use crate::systems::frame_pipeline::{CheckedPipeline, PipelinePlan};

use super::config::WalkthroughConfig;
use super::scene::Scene;

/// One object drawn in a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Draw {
    /// Prototype.
    pub proto: u32,
    /// Level of detail.
    pub level: u32,
    /// Pixels covered (overdraw included).
    pub pixels: f64,
    /// Shader, texture, material.
    pub state: (u64, u64, u64),
}

/// The times of a drawn frame, picoseconds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Timing {
    /// Rendering time: CPU start to the GPU's last work.
    pub rt: u64,
    /// GPU start to GPU end.
    pub gpu: u64,
    /// The CPU's submission work for the draws (traversal, driver calls,
    /// state changes against the previous draw), known from the model's
    /// costs before the frame runs (paper 000 §4's ET_cpu terms).
    pub cpu_submit: u64,
    /// Kernel events of the run.
    pub events: u64,
}

/// Draws frames of a scene through the frame pipeline.
#[derive(Debug, Clone)]
pub struct Renderer {
    template: CheckedPipeline,
    /// Timed meshes per prototype and level.
    meshes: Vec<Vec<MeshInfo>>,
    sigmas: Vec<f64>,
    shade: f64,
    fixed: f64,
    pass: f64,
}

impl Renderer {
    /// A renderer for `scene` on the model's hardware; `noise = false` turns
    /// system tasks off (the preprocess's timings). The per-frame variation
    /// (`[variation]`) is in every render.
    pub fn new(cfg: &Checked<WalkthroughConfig>, scene: &Scene, noise: bool) -> Result<Renderer, SystemError> {
        let mut noise_cfg = cfg.noise.clone();
        if !noise {
            noise_cfg.enabled = false;
        }
        let template = CheckedPipeline::new(FramePipelineConfig {
            system: "frame_pipeline".into(),
            description: String::new(),
            fidelity: cfg.fidelity,
            run: RunConfig {
                frames: 1,
                warmup_frames: 0,
                seed: cfg.run.seed,
                max_events: None,
                until: None,
                max_memory: None,
            },
            cpu: cfg.cpu.clone(),
            bus: cfg.bus.clone(),
            command_fifo: cfg.command_fifo.clone(),
            gpu: cfg.gpu.clone(),
            display: cfg.display.clone(),
            noise: noise_cfg,
            variation: cfg.variation.clone(),
            pacing: Default::default(),
            frame_generation: Default::default(),
            workload: WorkloadConfig::Scene(SceneWorkload {
                view: View::Static,
                preset: None,
                scale: 1.0,
                depth_complexity: cfg.scene.depth_complexity,
                depth_order: cfg.scene.depth_order,
                state_order: StateOrder::AsListed,
                groups: Vec::new(),
            }),
        })?;
        let pass = early_z_pass(cfg.scene.depth_order, cfg.scene.depth_complexity);
        let (shade, fixed) = fragment_costs(template.config(), pass);
        let mut meshes = Vec::with_capacity(scene.protos.len());
        for p in &scene.protos {
            let mut levels = Vec::with_capacity(p.levels.len());
            for (l, lv) in p.levels.iter().enumerate() {
                let info = MeshInfo {
                    name: format!("{} level {l}", p.name),
                    triangles: lv.triangles,
                    transformed: lv.transformed,
                    indices: lv.triangles.saturating_mul(3),
                    misses: Misses::Spread {
                        transformed: lv.transformed,
                    },
                    geometry_time: Duration::ZERO,
                    geometry_shader: Duration::ZERO,
                };
                levels.push(timed_mesh(
                    template.config(),
                    info,
                    &format!("scene ({} level {l})", p.name),
                )?);
            }
            meshes.push(levels);
        }
        Ok(Renderer {
            template,
            meshes,
            sigmas: scene.protos.iter().map(|p| p.size_sigma).collect(),
            shade,
            fixed,
            pass,
        })
    }

    /// The triangle-size distribution of a draw: mean `pixels / triangles`,
    /// lognormal with the prototype's sigma.
    fn sizes(&self, d: &Draw) -> Dist<f64> {
        let tris = self.meshes[d.proto as usize][d.level as usize].triangles.max(1) as f64;
        let mean = d.pixels / tris;
        let sigma = self.sigmas[d.proto as usize];
        if mean <= 0.0 || !mean.is_finite() {
            return Dist::Const { value: 0.0 };
        }
        if sigma <= 0.0 {
            return Dist::Const { value: mean };
        }
        Dist::Lognormal {
            median: mean / (0.5 * sigma * sigma).exp(),
            sigma,
        }
    }

    /// Draws one frame of `draws` (in that order), with run seed `seed`,
    /// starting `start` picoseconds into the walkthrough.
    pub fn render(&self, draws: &[Draw], seed: u64, start: u64) -> Result<Timing, SystemError> {
        self.render_counted(draws, seed, start).map(|(t, _, _)| t)
    }

    /// [`Renderer::render`] with the run's events per kind and the kind names.
    pub fn render_counted(
        &self,
        draws: &[Draw],
        seed: u64,
        start: u64,
    ) -> Result<(Timing, Vec<u64>, &'static [&'static str]), SystemError> {
        let checked = self.template.for_run_at(seed, start);
        let cfg = checked.config();
        let mut meshes = Vec::with_capacity(draws.len());
        let mut groups = Vec::with_capacity(draws.len());
        let mut objects = Vec::with_capacity(draws.len());
        for (i, d) in draws.iter().enumerate() {
            meshes.push(self.meshes[d.proto as usize][d.level as usize].clone());
            groups.push(GroupInfo {
                name: String::new(),
                pixels: self.sizes(d),
                order: Default::default(),
                shade_per_pixel: self.shade,
                fixed_per_pixel: self.fixed,
                memory: Default::default(),
                fetch_bytes_per_vertex: 0.0,
                sorted_each_frame: false,
            });
            objects.push(Instance {
                group: i as u32,
                mesh: i as u32,
                state: d.state,
                matrix: true,
                alpha: 0,
                upload: 0,
            });
        }
        let program = build_program(cfg, meshes, groups, &objects, self.pass)?;
        let cpu_submit = program.draws.iter().fold(0u64, |t, d| t.saturating_add(d.cpu.0));
        let (stats, records) = PipelinePlan::with_program(checked, program)?.simulate()?;
        let r = records.first().ok_or_else(|| SystemError::Unfinished {
            at: stats.end_time,
            missing: "the frame was drawn".into(),
            state: "no frame record".into(),
        })?;
        let (Some(gs), Some(ge)) = (r.gpu_start, r.gpu_end) else {
            return Err(SystemError::Unfinished {
                at: stats.end_time,
                missing: "the GPU finished the frame".into(),
                state: "the frame has no GPU end".into(),
            });
        };
        let timing = Timing {
            rt: ge.0.saturating_sub(r.start.0),
            gpu: ge.0.saturating_sub(gs.0),
            cpu_submit,
            events: stats.events,
        };
        Ok((timing, stats.by_kind, stats.kind_names))
    }

    /// The checked model each of its runs starts from.
    pub fn model(&self) -> &CheckedPipeline {
        &self.template
    }

    /// The levels' mesh statistics of prototype `p`.
    pub fn levels(&self, p: u32) -> &[MeshInfo] {
        &self.meshes[p as usize]
    }
}

/// Per-frame run seeds, drawn in frame order.
pub fn frame_seeds(seed: u64) -> StreamRng {
    RngStreams::new(seed).stream("walkthrough.frames")
}

/// The next frame seed.
pub fn next_seed(rng: &mut StreamRng) -> u64 {
    rng.random()
}

/// The simulator's events over every frame-pipeline run of a walkthrough
/// (the preprocess's renders and the frames), by kind.
#[derive(Debug, Default)]
pub(super) struct Counter {
    /// Events handled.
    pub(super) events: u64,
    /// Events by kind, indexed like `names`.
    pub(super) by_kind: Vec<u64>,
    /// The kinds' names.
    pub(super) names: &'static [&'static str],
    /// Pipeline runs.
    pub(super) runs: u64,
}

impl Counter {
    /// Adds one run's events.
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
