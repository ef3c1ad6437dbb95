//! One measured pass on the device: what it draws with (the mesh's
//! buffers, the pipeline with its bindings, the render and depth targets,
//! the pipeline-statistics and time-stamp queries) built once, run as often
//! as the rounds ask, and the rounds it recorded ([`PassRun`]) turned into a
//! [`Measurement`] (median time; counters checked equal across rounds).

use wgpu::util::DeviceExt;

use crate::scene::mesh::Mesh;

use super::device::{
    AdapterSummary, MeasureError, MeasureOptions, Measurement, TARGET_FORMAT, buffer_bindings, position_pipeline,
    read_words, stats_types,
};
use super::geometry::mesh_positions;

/// The recorded rounds of one pass: its counters and times as they come.
pub(crate) struct PassRun {
    pub(crate) opts: MeasureOptions,
    times: Vec<f64>,
    counters: Vec<[u64; 4]>,
    pub(crate) seconds: f64,
}

impl PassRun {
    pub(crate) fn new(opts: MeasureOptions) -> PassRun {
        PassRun {
            opts,
            times: Vec::new(),
            counters: Vec::new(),
            seconds: 0.0,
        }
    }

    /// Keeps one pass's read-back words: the four counters and the time
    /// stamps (words 32 and 33, in ticks of `period` ns).
    pub(crate) fn record(&mut self, words: &[u64], period: f64) {
        self.counters.push([words[0], words[1], words[2], words[3]]);
        let (t0, t1) = (words[32], words[33]);
        self.times.push(t1.saturating_sub(t0) as f64 * period);
    }

    pub(crate) fn finish(self, adapter: &AdapterSummary) -> Measurement {
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

/// What every measured pass of one mesh draws with: its buffers, the
/// pipeline and its bindings, the render and depth targets, and the
/// queries (pipeline statistics, time stamps) with their resolve buffer.
pub(crate) struct MeasuredPass {
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
    pub(crate) fn new(device: &wgpu::Device, mesh: &Mesh, spec: &str, opts: &MeasureOptions) -> MeasuredPass {
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
    pub(crate) fn run(
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
