//! The wgpu side: the adapter ([`Gpu`]), what a measurement is asked
//! ([`MeasureOptions`]) and gives ([`Measurement`]), the pipeline, query and
//! readback helpers every measured pass shares, and the measuring itself:
//! one pass at a time or many in interleaved rounds (a pass's own resources
//! and rounds: `measured_pass.rs`).

use std::time::Instant;

use crate::scene::mesh::Mesh;

use super::geometry::DepthOrder;
use super::measured_pass::{MeasuredPass, PassRun};
use super::passes::{PassRow, pool};

/// Errors of a measurement.
#[derive(Debug, thiserror::Error)]
pub enum MeasureError {
    /// No Vulkan adapter (install Mesa's lavapipe: `mesa-vulkan-drivers`).
    #[error(
        "no Vulkan adapter found (on a machine without a GPU install Debian's mesa-vulkan-drivers for lavapipe): {0}"
    )]
    NoAdapter(String),
    /// The adapter lacks a feature the measurement needs.
    #[error("adapter {adapter:?} lacks {feature}")]
    MissingFeature {
        /// Adapter name.
        adapter: String,
        /// Missing feature.
        feature: &'static str,
    },
    /// Device creation failed.
    #[error("cannot open the device: {0}")]
    Device(String),
    /// Reading results back failed.
    #[error("reading results back failed: {0}")]
    Readback(String),
    /// A bad option.
    #[error("{0}")]
    Option(String),
}

/// Knobs of a measurement.
#[derive(Debug, Clone, serde::Serialize)]
pub struct MeasureOptions {
    /// Extra ALU loop iterations in the vertex shader.
    pub vs_loops: u32,
    /// Extra ALU loop iterations in the fragment shader.
    pub fs_loops: u32,
    /// Depth test (less) on.
    pub depth_test: bool,
    /// Copies of the mesh drawn at different depths (instances).
    pub layers: u32,
    /// Order of the layers.
    pub order: DepthOrder,
    /// Render target width and height, pixels.
    pub size: (u32, u32),
    /// Unrecorded passes before measuring.
    pub warmup: u32,
    /// Recorded passes.
    pub repeats: u32,
    /// Every vertex at one point: every triangle is degenerate and produces
    /// no fragments, so the pass measures the geometry stage alone (index
    /// fetch, vertex shading, setup of empty triangles).
    pub geometry_only: bool,
    /// Draw calls the mesh's triangles are split into, in order (as equal
    /// as whole triangles allow; more draws than triangles leave some
    /// empty). 0 draws nothing: the pass only clears and stores its target.
    pub draws: u32,
}

impl Default for MeasureOptions {
    fn default() -> Self {
        MeasureOptions {
            vs_loops: 0,
            fs_loops: 0,
            depth_test: false,
            layers: 1,
            order: DepthOrder::FrontToBack,
            size: (512, 512),
            warmup: 2,
            repeats: 5,
            geometry_only: false,
            draws: 1,
        }
    }
}

/// The adapter that measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct AdapterSummary {
    /// Device name.
    pub name: String,
    /// Driver name.
    pub driver: String,
    /// Driver version details.
    pub driver_info: String,
    /// Cpu, DiscreteGpu, ...
    pub device_type: String,
    /// Backend (Vulkan).
    pub backend: String,
}

/// A measurement's results.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Measurement {
    /// The adapter.
    pub adapter: AdapterSummary,
    /// Vertex shader invocations of one pass.
    pub vs_invocations: u64,
    /// Clipper invocations (primitives entering clipping).
    pub clipper_invocations: u64,
    /// Primitives leaving the clipper.
    pub clipper_primitives_out: u64,
    /// Fragment shader invocations (on lavapipe: see docs/measurements/README.md).
    pub fs_invocations: u64,
    /// Median GPU time of the pass (timestamp queries), nanoseconds.
    pub pass_time_ns: f64,
    /// Every recorded pass time, nanoseconds.
    pub pass_times_ns: Vec<f64>,
    /// Whether the statistics agreed over all repeats.
    pub stable_counters: bool,
    /// Options used.
    pub options: MeasureOptions,
    /// Wall time of the whole measurement (device setup included), seconds.
    pub wall_seconds: f64,
}

pub(crate) fn stats_types() -> wgpu::PipelineStatisticsTypes {
    wgpu::PipelineStatisticsTypes::VERTEX_SHADER_INVOCATIONS
        | wgpu::PipelineStatisticsTypes::CLIPPER_INVOCATIONS
        | wgpu::PipelineStatisticsTypes::CLIPPER_PRIMITIVES_OUT
        | wgpu::PipelineStatisticsTypes::FRAGMENT_SHADER_INVOCATIONS
}

/// The colour format the measurement pipelines render to.
pub(crate) const TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// Maps `read` (a `MAP_READ` buffer whose copies were submitted), waits for
/// the device, and returns its contents as little-endian `u64` words (query
/// results), unmapping it again.
pub(crate) fn read_words(device: &wgpu::Device, read: &wgpu::Buffer) -> Result<Vec<u64>, MeasureError> {
    let slice = read.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| MeasureError::Readback(e.to_string()))?;
    rx.recv()
        .map_err(|e| MeasureError::Readback(e.to_string()))?
        .map_err(|e| MeasureError::Readback(e.to_string()))?;
    let data = slice
        .get_mapped_range()
        .map_err(|e| MeasureError::Readback(e.to_string()))?;
    let words = data
        .chunks_exact(8)
        .map(|c| u64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
        .collect();
    drop(data);
    read.unmap();
    Ok(words)
}

/// The bind group of whole `buffers` at bindings 0, 1, ... (each with its
/// binding type and the stages that read it) and the pipeline layout over
/// it: the resources of `rendersim measure`'s passes and `study
/// estimation`'s.
pub(crate) fn buffer_bindings(
    device: &wgpu::Device,
    buffers: &[(&wgpu::Buffer, wgpu::BufferBindingType, wgpu::ShaderStages)],
) -> (wgpu::BindGroup, wgpu::PipelineLayout) {
    let entries: Vec<wgpu::BindGroupLayoutEntry> = buffers
        .iter()
        .enumerate()
        .map(|(i, &(_, ty, visibility))| wgpu::BindGroupLayoutEntry {
            binding: i as u32,
            visibility,
            ty: wgpu::BindingType::Buffer {
                ty,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        })
        .collect();
    let bgl = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: None,
        entries: &entries,
    });
    let resources: Vec<wgpu::BindGroupEntry> = buffers
        .iter()
        .enumerate()
        .map(|(i, (buffer, _, _))| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: buffer.as_entire_binding(),
        })
        .collect();
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &bgl,
        entries: &resources,
    });
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: None,
        bind_group_layouts: &[Some(&bgl)],
        ..Default::default()
    });
    (bind, layout)
}

/// A render pipeline of the measurement shaders: 2-D float positions (one
/// vertex buffer, stride 8) through `vs_main`, `fs_main` into one
/// [`TARGET_FORMAT`] attachment without blending, no culling, the given
/// depth state (`rendersim measure`'s passes and `study estimation`'s).
pub(crate) fn position_pipeline(
    device: &wgpu::Device,
    label: &str,
    shader: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    depth_stencil: Option<wgpu::DepthStencilState>,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module: shader,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: 8,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &[wgpu::VertexAttribute {
                    format: wgpu::VertexFormat::Float32x2,
                    offset: 0,
                    shader_location: 0,
                }],
            })],
        },
        primitive: wgpu::PrimitiveState {
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: shader,
            entry_point: Some("fs_main"),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::ColorTargetState {
                format: TARGET_FORMAT,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// An opened adapter and device, reused across measurements (a study opens
/// one and measures dozens of meshes on it).
pub struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    /// The adapter that measures.
    pub adapter: AdapterSummary,
    /// Every pass measured on this device: its row and recorded pass times,
    /// or `None` for a pass the pass CSV cannot describe.
    log: std::sync::Mutex<Vec<Option<LoggedPass>>>,
}

/// A pass's row and its recorded pass times.
type LoggedPass = (PassRow, Vec<f64>);

/// The passes one [`Gpu`] measured, for `--csv`.
#[derive(Debug, Clone)]
pub struct MeasuredPasses {
    /// One row per distinct pass (times of repeated measurements pooled).
    pub rows: Vec<PassRow>,
    /// Measurements left out: layered or depth-tested passes, and meshes no
    /// spec names (H1's probes).
    pub left_out: usize,
}

impl Gpu {
    /// Opens the first high-performance Vulkan adapter with pipeline-statistics
    /// and timestamp queries.
    pub fn open() -> Result<Gpu, MeasureError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::VULKAN,
            ..wgpu::InstanceDescriptor::new_without_display_handle_from_env()
        });
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            apply_limit_buckets: false,
        }))
        .map_err(|e| MeasureError::NoAdapter(e.to_string()))?;
        let info = adapter.get_info();
        let summary = AdapterSummary {
            name: info.name.clone(),
            driver: info.driver.clone(),
            driver_info: info.driver_info.clone(),
            device_type: format!("{:?}", info.device_type),
            backend: format!("{:?}", info.backend),
        };
        let needed = [
            (wgpu::Features::PIPELINE_STATISTICS_QUERY, "PIPELINE_STATISTICS_QUERY"),
            (wgpu::Features::TIMESTAMP_QUERY, "TIMESTAMP_QUERY"),
        ];
        for (f, name) in needed {
            if !adapter.features().contains(f) {
                return Err(MeasureError::MissingFeature {
                    adapter: info.name.clone(),
                    feature: name,
                });
            }
        }
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("rendersim measure"),
            required_features: wgpu::Features::PIPELINE_STATISTICS_QUERY | wgpu::Features::TIMESTAMP_QUERY,
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| MeasureError::Device(e.to_string()))?;
        Ok(Gpu {
            device,
            queue,
            adapter: summary,
            log: std::sync::Mutex::new(Vec::new()),
        })
    }

    /// Every pass measured so far, one row per distinct pass, in the order
    /// each was first measured (see [`super::passes::pool`]).
    pub fn measured_passes(&self) -> MeasuredPasses {
        let log = self.log.lock().unwrap_or_else(|e| e.into_inner());
        MeasuredPasses {
            rows: pool(log.iter().flatten().cloned()),
            left_out: log.iter().filter(|p| p.is_none()).count(),
        }
    }

    /// The opened device and its queue (for the estimation study's own pipeline).
    pub(super) fn device_queue(&self) -> (&wgpu::Device, &wgpu::Queue) {
        (&self.device, &self.queue)
    }

    /// One line naming the adapter: name (driver, driver info, device type).
    pub fn describe(&self) -> String {
        let a = &self.adapter;
        format!("{} ({}, {}, {})", a.name, a.driver, a.driver_info, a.device_type)
    }
}

/// Opens the default adapter, draws `mesh` (`spec` names its generator, for
/// positions) and measures it.
pub fn measure(mesh: &Mesh, spec: &str, opts: &MeasureOptions) -> Result<Measurement, MeasureError> {
    let start = Instant::now();
    let gpu = Gpu::open()?;
    let mut r = gpu.measure(mesh, spec, opts)?;
    r.wall_seconds = start.elapsed().as_secs_f64();
    Ok(r)
}

impl Gpu {
    /// Draws `mesh` on this device and measures it; the pass is kept for
    /// [`Gpu::measured_passes`].
    pub fn measure(&self, mesh: &Mesh, spec: &str, opts: &MeasureOptions) -> Result<Measurement, MeasureError> {
        let r = self.draw(mesh, spec, opts)?;
        let row = PassRow::from_measurement(spec, &r).map(|row| (row, r.pass_times_ns.clone()));
        self.log.lock().unwrap_or_else(|e| e.into_inner()).push(row);
        Ok(r)
    }

    /// Measures every condition (mesh spec, mesh, options) `rounds` times,
    /// interleaved: each condition's pass is built once and warmed up
    /// (`opts.warmup` passes), then round 1 of every condition runs, then
    /// round 2, ...; each condition's `opts.repeats` is ignored. A pass
    /// built again for every round would pay its pipeline's first-use costs
    /// (on lavapipe, compiling the shaders: about 0.4 ms) in every recorded
    /// round. Returns one measurement per condition whose `pass_times_ns`
    /// holds every round and whose `pass_time_ns` is their median; each is
    /// kept for [`Gpu::measured_passes`].
    pub fn measure_interleaved(
        &self,
        conds: &[(&str, &Mesh, MeasureOptions)],
        rounds: u32,
    ) -> Result<Vec<Measurement>, MeasureError> {
        let rounds = rounds.max(1);
        let mut runs = Vec::with_capacity(conds.len());
        for (spec, mesh, opts) in conds {
            let opts = MeasureOptions {
                repeats: rounds,
                ..opts.clone()
            };
            check_options(&opts)?;
            let start = Instant::now();
            let pass = MeasuredPass::new(&self.device, mesh, spec, &opts);
            let mut run = PassRun::new(opts);
            for _ in 0..run.opts.warmup {
                pass.run(&self.device, &self.queue, run.opts.layers, run.opts.draws)?;
            }
            run.seconds += start.elapsed().as_secs_f64();
            runs.push((pass, run));
        }
        let period = self.queue.get_timestamp_period() as f64;
        for _ in 0..rounds {
            for (pass, run) in &mut runs {
                let start = Instant::now();
                let words = pass.run(&self.device, &self.queue, run.opts.layers, run.opts.draws)?;
                run.record(&words, period);
                run.seconds += start.elapsed().as_secs_f64();
            }
        }
        let out: Vec<Measurement> = runs.into_iter().map(|(_, run)| run.finish(&self.adapter)).collect();
        let mut log = self.log.lock().unwrap_or_else(|e| e.into_inner());
        for ((spec, _, _), r) in conds.iter().zip(&out) {
            log.push(PassRow::from_measurement(spec, r).map(|row| (row, r.pass_times_ns.clone())));
        }
        Ok(out)
    }

    /// Draws `mesh` (`spec` names its generator, for positions) with
    /// `opts`: the warm-up passes, then the measured ones, each read back.
    fn draw(&self, mesh: &Mesh, spec: &str, opts: &MeasureOptions) -> Result<Measurement, MeasureError> {
        check_options(opts)?;
        let start = Instant::now();
        let pass = MeasuredPass::new(&self.device, mesh, spec, opts);
        let period = self.queue.get_timestamp_period() as f64;
        let mut run = PassRun::new(opts.clone());
        for round in 0..opts.warmup + opts.repeats {
            let words = pass.run(&self.device, &self.queue, opts.layers, opts.draws)?;
            if round >= opts.warmup {
                run.record(&words, period);
            }
        }
        run.seconds = start.elapsed().as_secs_f64();
        Ok(run.finish(&self.adapter))
    }
}

/// Refuses options no pass can be drawn with: no layers, repeats or pixels,
/// or a render target over 8192x8192.
fn check_options(opts: &MeasureOptions) -> Result<(), MeasureError> {
    if opts.layers == 0 || opts.repeats == 0 || opts.size.0 == 0 || opts.size.1 == 0 {
        return Err(MeasureError::Option(
            "layers, repeats and size must be at least 1".into(),
        ));
    }
    if opts.size.0 > 8192 || opts.size.1 > 8192 {
        return Err(MeasureError::Option("render target larger than 8192x8192".into()));
    }
    if opts.draws > super::passes::MAX_DRAWS {
        return Err(MeasureError::Option(format!(
            "{} draws: at most {} in one pass",
            opts.draws,
            super::passes::MAX_DRAWS
        )));
    }
    Ok(())
}
