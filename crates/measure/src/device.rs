//! The wgpu side: adapter, pipeline, queries, readback.

use std::time::Instant;

use wgpu::util::DeviceExt;

use crate::scene::mesh::Mesh;

use super::geometry::{DepthOrder, mesh_positions};
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

/// The recorded rounds of one pass: its counters and times as they come.
struct PassRun {
    opts: MeasureOptions,
    times: Vec<f64>,
    counters: Vec<[u64; 4]>,
    seconds: f64,
}

impl PassRun {
    fn new(opts: MeasureOptions) -> PassRun {
        PassRun {
            opts,
            times: Vec::new(),
            counters: Vec::new(),
            seconds: 0.0,
        }
    }

    /// Keeps one pass's read-back words: the four counters and the time
    /// stamps (words 32 and 33, in ticks of `period` ns).
    fn record(&mut self, words: &[u64], period: f64) {
        self.counters.push([words[0], words[1], words[2], words[3]]);
        let (t0, t1) = (words[32], words[33]);
        self.times.push(t1.saturating_sub(t0) as f64 * period);
    }

    fn finish(self, adapter: &AdapterSummary) -> Measurement {
        let stable = self.counters.windows(2).all(|w| w[0] == w[1]);
        let last = *self.counters.last().unwrap_or(&[0; 4]);
        let median = super::fit::median(&self.times).unwrap_or(f64::NAN);
        Measurement {
            adapter: adapter.clone(),
            vs_invocations: last[0],
            clipper_invocations: last[1],
            clipper_primitives_out: last[2],
            fs_invocations: last[3],
            pass_time_ns: median,
            pass_times_ns: self.times,
            stable_counters: stable,
            options: self.opts,
            wall_seconds: self.seconds,
        }
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

/// What every measured pass of one mesh draws with: its buffers, the
/// pipeline and its bindings, the render and depth targets, and the
/// queries (pipeline statistics, time stamps) with their resolve buffer.
struct MeasuredPass {
    vbuf: wgpu::Buffer,
    ibuf: wgpu::Buffer,
    index_count: u32,
    /// The uniform and order buffers the bind group reads (kept alive with it).
    _buffers: [wgpu::Buffer; 2],
    bind: wgpu::BindGroup,
    pipeline: wgpu::RenderPipeline,
    /// The render and depth targets (kept alive with their views).
    _targets: [wgpu::Texture; 2],
    tview: wgpu::TextureView,
    dview: wgpu::TextureView,
    stats_q: wgpu::QuerySet,
    time_q: wgpu::QuerySet,
    resolve: wgpu::Buffer,
}

impl MeasuredPass {
    /// Uploads `mesh` (positions from its generator `spec`, or all at the
    /// centre with `geometry_only`) and builds the pipeline, targets and
    /// queries for `opts`.
    fn new(device: &wgpu::Device, mesh: &Mesh, spec: &str, opts: &MeasureOptions) -> MeasuredPass {
        let list = mesh.to_triangle_list();
        let positions = if opts.geometry_only {
            vec![[0.5, 0.5]; mesh.vertex_count as usize]
        } else {
            mesh_positions(mesh, spec)
        };
        let vbuf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("positions"),
            contents: &bytes_f32(&positions),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let ibuf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("indices"),
            contents: &bytes_u32(&list.indices),
            usage: wgpu::BufferUsages::INDEX,
        });
        let params = [opts.vs_loops, opts.fs_loops, opts.layers, 0u32];
        let ubuf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("params"),
            contents: &bytes_u32(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let slots = opts.order.slots(opts.layers);
        let obuf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("order"),
            contents: &bytes_u32(&slots),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let (bind, pipeline) = measure_pipeline(device, &ubuf, &obuf, opts.depth_test);
        let (target, depth) = targets(device, opts.size);
        let tview = target.create_view(&Default::default());
        let dview = depth.create_view(&Default::default());
        let stats_q = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("stats"),
            ty: wgpu::QueryType::PipelineStatistics(stats_types()),
            count: 1,
        });
        let time_q = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("time"),
            ty: wgpu::QueryType::Timestamp,
            count: 2,
        });
        let resolve = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("resolve"),
            size: 256 * 2,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        MeasuredPass {
            vbuf,
            ibuf,
            index_count: list.indices.len() as u32,
            _buffers: [ubuf, obuf],
            bind,
            pipeline,
            _targets: [target, depth],
            tview,
            dview,
            stats_q,
            time_q,
            resolve,
        }
    }

    /// Draws one pass of `layers` instances in `draws` draw calls and reads
    /// its queries back: words 0-3 the pipeline statistics, 32 and 33 the
    /// time stamps.
    fn run(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        layers: u32,
        draws: u32,
    ) -> Result<Vec<u64>, MeasureError> {
        let mut enc = device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("measured pass"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &self.tview,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.dview,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: Some(wgpu::RenderPassTimestampWrites {
                    query_set: &self.time_q,
                    beginning_of_pass_write_index: Some(0),
                    end_of_pass_write_index: Some(1),
                }),
                occlusion_query_set: None,
                ..Default::default()
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind, &[]);
            pass.set_vertex_buffer(0, self.vbuf.slice(..));
            pass.set_index_buffer(self.ibuf.slice(..), wgpu::IndexFormat::Uint32);
            pass.begin_pipeline_statistics_query(&self.stats_q, 0);
            for range in draw_ranges(self.index_count, draws) {
                pass.draw_indexed(range, 0, 0..layers);
            }
            pass.end_pipeline_statistics_query();
        }
        enc.resolve_query_set(&self.stats_q, 0..1, &self.resolve, 0);
        enc.resolve_query_set(&self.time_q, 0..2, &self.resolve, 256);
        let read = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("read"),
            size: 512,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        enc.copy_buffer_to_buffer(&self.resolve, 0, &read, 0, 512);
        queue.submit([enc.finish()]);
        read_words(device, &read)
    }
}

/// The index ranges of `draws` draw calls over `index_count` indices (a
/// triangle list): consecutive, whole triangles, as equal as they allow.
pub(crate) fn draw_ranges(index_count: u32, draws: u32) -> impl Iterator<Item = std::ops::Range<u32>> {
    let triangles = u64::from(index_count / 3);
    let n = u64::from(draws);
    (0..n).map(move |k| {
        let at = |k: u64| (3 * (k * triangles / n)) as u32;
        at(k)..at(k + 1)
    })
}

/// The measuring shader's pipeline (depth test on or off) and its bind
/// group over the uniform `ubuf` and the order buffer `obuf`.
fn measure_pipeline(
    device: &wgpu::Device,
    ubuf: &wgpu::Buffer,
    obuf: &wgpu::Buffer,
    depth_test: bool,
) -> (wgpu::BindGroup, wgpu::RenderPipeline) {
    let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("measure"),
        source: wgpu::ShaderSource::Wgsl(include_str!("shader.wgsl").into()),
    });
    let (bind, layout) = buffer_bindings(
        device,
        &[
            (
                ubuf,
                wgpu::BufferBindingType::Uniform,
                wgpu::ShaderStages::VERTEX_FRAGMENT,
            ),
            (
                obuf,
                wgpu::BufferBindingType::Storage { read_only: true },
                wgpu::ShaderStages::VERTEX,
            ),
        ],
    );
    let pipeline = position_pipeline(
        device,
        "measure",
        &shader,
        &layout,
        Some(wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(depth_test),
            depth_compare: Some(if depth_test {
                wgpu::CompareFunction::Less
            } else {
                wgpu::CompareFunction::Always
            }),
            stencil: Default::default(),
            bias: Default::default(),
        }),
    );
    (bind, pipeline)
}

/// The render target (`TARGET_FORMAT`) and depth target of `size` pixels.
fn targets(device: &wgpu::Device, size: (u32, u32)) -> (wgpu::Texture, wgpu::Texture) {
    let extent = wgpu::Extent3d {
        width: size.0,
        height: size.1,
        depth_or_array_layers: 1,
    };
    let texture = |label: &str, format: wgpu::TextureFormat| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: extent,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        })
    };
    (
        texture("target", TARGET_FORMAT),
        texture("depth", wgpu::TextureFormat::Depth32Float),
    )
}

fn bytes_f32(v: &[[f32; 2]]) -> Vec<u8> {
    v.iter()
        .flat_map(|p| p[0].to_le_bytes().into_iter().chain(p[1].to_le_bytes()))
        .collect()
}

fn bytes_u32(v: &[u32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

#[cfg(test)]
mod tests {
    use super::draw_ranges;

    #[test]
    fn draws_split_the_triangles_in_order_and_whole() {
        let all = |n, d| draw_ranges(n, d).collect::<Vec<_>>();
        assert_eq!(all(30, 1), vec![std::ops::Range { start: 0, end: 30 }]);
        assert_eq!(all(30, 0), []);
        assert_eq!(all(30, 3), [0..9, 9..18, 18..30]);
        assert_eq!(all(30, 4), [0..6, 6..15, 15..21, 21..30]);
        // More draws than triangles: some draws are empty.
        assert_eq!(all(6, 4), [0..0, 0..3, 3..3, 3..6]);
        for (n, d) in [(3 * 131_072, 4096), (3 * 7, 5), (0, 3), (3 * 1000, 1)] {
            let r = all(n, d);
            assert_eq!(r.len(), d as usize);
            assert!(r.windows(2).all(|w| w[0].end == w[1].start));
            assert!(r.iter().all(|x| x.start % 3 == 0 && x.end % 3 == 0 && x.start <= x.end));
            assert_eq!((r[0].start, r[r.len() - 1].end), (0, n));
        }
    }
}
