//! The estimation study's passes on a device (`rendersim study estimation`,
//! analysis in `estimation.rs`; paper 000 §5 and §6.2's time stamps): one
//! pipeline (`estimation.wgsl`), every prototype's mesh uploaded once, and
//! the passes recorded in submissions of up to [`CHUNK`] render passes, each
//! pass with its own timestamp pair around it and a pipeline-statistics
//! query over its draws (one `draw_indexed` per object). Rounds are
//! interleaved: round 1 of every pass in the plan's seeded order, then
//! round 2, ...; the median of the rounds is kept.

use std::time::Instant;

use wgpu::util::DeviceExt;

use super::device::{Gpu, MeasureError, TARGET_FORMAT, buffer_bindings, position_pipeline, read_words, stats_types};
use super::estimation::{EstimationStudy, PassMeasurement, Plan, PlannedPass, analyze};
use super::fit::median;
use super::geometry::mesh_positions;
use super::studies::StudyError;

/// Render passes per submission.
pub const CHUNK: usize = 32;

/// Bytes of one object's entry in the storage buffer (`Object` of the shader).
const OBJECT_BYTES: u64 = 32;

/// Bytes of one pipeline-statistics result (four counters).
const STATS_BYTES: u64 = 32;

/// The note on a software rasterizer's times.
const CPU_NOTE: &str = "The adapter is a software rasterizer on this machine's CPU: a pass time is the CPU time it \
    spends plus any time its threads wait for a core. On a busy machine a long pass is likely to be stretched more \
    than a short one (its threads are more likely to be preempted), which estimators fitted to single-object passes \
    (mostly short) cannot know: compare the mean errors on single- and multi-object passes.";

/// The study's result with what it was computed from.
#[derive(Debug)]
pub struct EstimationRun {
    /// The plan (prototypes and passes).
    pub plan: Plan,
    /// Every pass's measurement, in plan order.
    pub measured: Vec<PassMeasurement>,
    /// The analysis.
    pub study: EstimationStudy,
}

/// Measures `plan` on `gpu` and analyses it; `command` is quoted in the
/// result.
pub fn run_estimation(gpu: &Gpu, plan: Plan, command: &str) -> Result<EstimationRun, StudyError> {
    let start = Instant::now();
    let measured = measure_plan(gpu, &plan)?;
    let wall = start.elapsed().as_secs_f64();
    let mut study =
        analyze(&plan, &measured, &gpu.describe(), command, wall).map_err(|e| StudyError::Mesh(e.to_string()))?;
    if gpu.adapter.device_type == "Cpu" {
        study.notes = CPU_NOTE.to_string();
    }
    Ok(EstimationRun { plan, measured, study })
}

struct Renderer<'a> {
    device: &'a wgpu::Device,
    queue: &'a wgpu::Queue,
    pipeline: wgpu::RenderPipeline,
    bind: wgpu::BindGroup,
    objects: wgpu::Buffer,
    meshes: Vec<(wgpu::Buffer, wgpu::Buffer, u32)>,
    view: wgpu::TextureView,
    stats: wgpu::QuerySet,
    times: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    read: wgpu::Buffer,
    time_offset: u64,
    target: [u32; 2],
    period: f64,
}

/// One pass's result of one round: time (ns), vertex and fragment shader
/// invocations.
type Round = (f64, u64, u64);

fn round_up(x: u64, to: u64) -> u64 {
    x.div_ceil(to) * to
}

impl<'a> Renderer<'a> {
    fn new(gpu: &'a Gpu, plan: &Plan) -> Renderer<'a> {
        let (device, queue) = gpu.device_queue();
        let most_objects = plan.passes.iter().map(|p| p.objects.len()).max().unwrap_or(1).max(1);
        let objects = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("objects"),
            size: CHUNK as u64 * most_objects as u64 * OBJECT_BYTES,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let meshes = plan
            .meshes
            .iter()
            .zip(&plan.prototypes)
            .map(|(mesh, proto)| {
                let list = mesh.to_triangle_list();
                let positions = mesh_positions(mesh, &proto.mesh);
                let v: Vec<u8> = positions
                    .iter()
                    .flat_map(|p| p[0].to_le_bytes().into_iter().chain(p[1].to_le_bytes()))
                    .collect();
                let i: Vec<u8> = list.indices.iter().flat_map(|x| x.to_le_bytes()).collect();
                let vbuf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("positions"),
                    contents: &v,
                    usage: wgpu::BufferUsages::VERTEX,
                });
                let ibuf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("indices"),
                    contents: &i,
                    usage: wgpu::BufferUsages::INDEX,
                });
                (vbuf, ibuf, list.indices.len() as u32)
            })
            .collect();
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("estimation"),
            source: wgpu::ShaderSource::Wgsl(include_str!("estimation.wgsl").into()),
        });
        let (bind, layout) = buffer_bindings(
            device,
            &[(
                &objects,
                wgpu::BufferBindingType::Storage { read_only: true },
                wgpu::ShaderStages::VERTEX,
            )],
        );
        let format = TARGET_FORMAT;
        let pipeline = position_pipeline(device, "estimation", &shader, &layout, None);
        let target = plan.setup.target;
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("target"),
            size: wgpu::Extent3d {
                width: target[0],
                height: target[1],
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        let stats = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("stats"),
            ty: wgpu::QueryType::PipelineStatistics(stats_types()),
            count: CHUNK as u32,
        });
        let times = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("times"),
            ty: wgpu::QueryType::Timestamp,
            count: 2 * CHUNK as u32,
        });
        let time_offset = round_up(CHUNK as u64 * STATS_BYTES, 256);
        let size = time_offset + 2 * CHUNK as u64 * 8;
        let resolve = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("resolve"),
            size,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let read = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("read"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Renderer {
            device,
            queue,
            pipeline,
            bind,
            objects,
            meshes,
            view: texture.create_view(&Default::default()),
            stats,
            times,
            resolve,
            read,
            time_offset,
            target,
            period: f64::from(queue.get_timestamp_period()),
        }
    }

    /// Draws up to [`CHUNK`] passes in one submission; their results and the
    /// submission's wall time.
    fn chunk(&self, plan: &Plan, passes: &[&PlannedPass]) -> Result<(Vec<Round>, f64), MeasureError> {
        let start = Instant::now();
        let [w, h] = self.target.map(f64::from);
        let mut bytes = Vec::new();
        let mut first = Vec::with_capacity(passes.len());
        for p in passes {
            first.push((bytes.len() as u64 / OBJECT_BYTES) as u32);
            for o in &p.objects {
                let proto = &plan.prototypes[o.prototype];
                let (x0, y0) = (o.x - o.side / 2.0, o.y - o.side / 2.0);
                let floats = [
                    (2.0 * x0 / w - 1.0) as f32,
                    (1.0 - 2.0 * y0 / h) as f32,
                    (2.0 * o.side / w) as f32,
                    (-2.0 * o.side / h) as f32,
                ];
                for f in floats {
                    bytes.extend_from_slice(&f.to_le_bytes());
                }
                for u in [proto.vs_loops, proto.fs_loops, 0, 0] {
                    bytes.extend_from_slice(&u.to_le_bytes());
                }
            }
        }
        if !bytes.is_empty() {
            self.queue.write_buffer(&self.objects, 0, &bytes);
        }
        let mut enc = self.device.create_command_encoder(&Default::default());
        for (i, (p, base)) in passes.iter().zip(&first).enumerate() {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("estimation pass"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &self.view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: Some(wgpu::RenderPassTimestampWrites {
                    query_set: &self.times,
                    beginning_of_pass_write_index: Some(2 * i as u32),
                    end_of_pass_write_index: Some(2 * i as u32 + 1),
                }),
                occlusion_query_set: None,
                ..Default::default()
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind, &[]);
            pass.begin_pipeline_statistics_query(&self.stats, i as u32);
            for (j, o) in p.objects.iter().enumerate() {
                let (vbuf, ibuf, n) = &self.meshes[o.prototype];
                let slot = base + j as u32;
                pass.set_vertex_buffer(0, vbuf.slice(..));
                pass.set_index_buffer(ibuf.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..*n, 0, slot..slot + 1);
            }
            pass.end_pipeline_statistics_query();
        }
        let n = passes.len() as u32;
        enc.resolve_query_set(&self.stats, 0..n, &self.resolve, 0);
        enc.resolve_query_set(&self.times, 0..2 * n, &self.resolve, self.time_offset);
        enc.copy_buffer_to_buffer(&self.resolve, 0, &self.read, 0, self.read.size());
        self.queue.submit([enc.finish()]);
        let words = read_words(self.device, &self.read)?;
        let t = (self.time_offset / 8) as usize;
        let out = (0..passes.len())
            .map(|i| {
                let (t0, t1) = (words[t + 2 * i], words[t + 2 * i + 1]);
                (
                    t1.saturating_sub(t0) as f64 * self.period,
                    words[4 * i],
                    words[4 * i + 3],
                )
            })
            .collect();
        Ok((out, start.elapsed().as_secs_f64()))
    }
}

/// Measures every pass of `plan` (`plan.setup.repeats` interleaved rounds
/// after one unrecorded warm-up pass per prototype), in plan order.
pub fn measure_plan(gpu: &Gpu, plan: &Plan) -> Result<Vec<PassMeasurement>, MeasureError> {
    let r = Renderer::new(gpu, plan);
    // Warm-up: each prototype once, the largest table pass.
    let warm: Vec<&PlannedPass> =
        plan.passes
            .iter()
            .filter(|p| p.objects.len() == 1)
            .fold(Vec::<&PlannedPass>::new(), |mut v, p| {
                if !v.iter().any(|q| q.objects[0].prototype == p.objects[0].prototype) {
                    v.push(p);
                }
                v
            });
    for c in warm.chunks(CHUNK) {
        r.chunk(plan, c)?;
    }
    let mut rounds: Vec<Vec<Round>> = vec![Vec::new(); plan.passes.len()];
    let mut wall = vec![0.0f64; plan.passes.len()];
    for _ in 0..plan.setup.repeats.max(1) {
        for ids in plan.order.chunks(CHUNK) {
            let passes: Vec<&PlannedPass> = ids.iter().map(|&i| &plan.passes[i]).collect();
            let (res, secs) = r.chunk(plan, &passes)?;
            let gpu_total: f64 = res.iter().map(|x| x.0).sum();
            for (&i, x) in ids.iter().zip(res) {
                wall[i] += if gpu_total > 0.0 {
                    secs * x.0 / gpu_total
                } else {
                    secs / ids.len() as f64
                };
                rounds[i].push(x);
            }
        }
    }
    Ok(rounds
        .into_iter()
        .zip(wall)
        .map(|(rs, wall_s)| {
            let times_ns: Vec<f64> = rs.iter().map(|x| x.0).collect();
            let (_, vs, fs) = rs[rs.len() - 1];
            PassMeasurement {
                time_ns: median(&times_ns).unwrap_or(f64::NAN),
                stable: rs.iter().all(|x| x.1 == vs && x.2 == fs),
                times_ns,
                vs_invocations: vs,
                fs_invocations: fs,
                wall_s,
            }
        })
        .collect())
}
