//! The event simulation of one PixelFlow frame (paper 002 §4-6), per node
//! and screen region.
//!
//! Deferred-shading architectures (standard, presort), per rasterizing node:
//! geometry (standard: the whole frame, bucket sorted; presort: the sorting
//! pass, then instructions generated region by region), then for each region
//! in order: rasterize -> depth-composite the appearance parameters over the
//! network (one region at a time, all rasterizers' results) into the
//! communication registers of shader `region mod shaders` -> shade -> send
//! the color over the network's other direction -> load into frame-buffer
//! memory. A node starts rasterizing region j once the composition of region
//! j-1 has begun (its pixel memory holds one region, the communication
//! registers the other); a composition waits for its shader's input buffer.
//!
//! Non-texturing architecture: per node, geometry and rasterization in
//! batches of `batch_primitives` (fine-grained pipelining), into the
//! completely instanced frame buffer; for every further sample, the stored
//! instructions are rasterized again after the previous sample's whole-screen
//! composition; the last composition runs region by region, pipelined with
//! the loads into the frame buffer.
//!
//! The frame starts at time zero on an idle machine: the latency is the time
//! the last region is in frame-buffer memory.

use std::collections::VecDeque;

use crate::engine::{Control, Duration, EventKind, Model, Scheduler, Time, TimeError};
use crate::systems::checked::Checked;
use crate::systems::error::SystemError;

use super::config::{Architecture, PixelFlowConfig};
use super::layout::Layout;

mod deferred;
mod nontex;

/// Events of the PixelFlow model.
#[derive(Debug, Clone, Copy)]
pub enum Ev {
    /// A node's geometry pass (standard) or sorting pass (presort) is done.
    GeomDone(u32),
    /// Presort: a node generated the instructions of its next region.
    GenDone(u32),
    /// A node rasterized a region (deferred architectures).
    RastDone(u32),
    /// The network composited a region.
    CompDone(u32),
    /// A shader shaded a region.
    ShadeDone(u32),
    /// A region's color reached the frame-buffer node.
    ColorDone(u32),
    /// A region is in frame-buffer memory.
    LoadDone(u32),
    /// Nontex: a node's geometry finished a batch.
    BatchGeomDone(u32),
    /// Nontex: a node rasterized a batch (first sample) or a whole further
    /// sample pass.
    BatchRastDone(u32),
    /// Nontex: the whole-screen composition of a non-final sample is done.
    PassCompDone,
}

impl EventKind for Ev {
    const NAMES: &'static [&'static str] = &[
        "geometry_done",
        "generate_done",
        "rasterize_done",
        "composite_done",
        "shade_done",
        "color_done",
        "load_done",
        "batch_geometry_done",
        "batch_rasterize_done",
        "pass_composite_done",
    ];
    fn kind(&self) -> usize {
        match self {
            Ev::GeomDone(_) => 0,
            Ev::GenDone(_) => 1,
            Ev::RastDone(_) => 2,
            Ev::CompDone(_) => 3,
            Ev::ShadeDone(_) => 4,
            Ev::ColorDone(_) => 5,
            Ev::LoadDone(_) => 6,
            Ev::BatchGeomDone(_) => 7,
            Ev::BatchRastDone(_) => 8,
            Ev::PassCompDone => 9,
        }
    }
}

/// Trace processes, one per node role.
pub const ROLES: [&str; 5] = [
    "rasterizer geometry processors",
    "rasterizer pixel arrays",
    "shading nodes",
    "composition network",
    "frame-buffer node",
];

/// One span of the timeline.
#[derive(Debug, Clone)]
pub struct Span {
    /// Role index into [`ROLES`].
    pub role: u8,
    /// Node (or network direction) within the role.
    pub unit: u32,
    /// What was done.
    pub name: &'static str,
    /// Region or batch.
    pub arg: u32,
    /// Start.
    pub start: Time,
    /// End.
    pub end: Time,
}

/// Per-region timestamps.
#[derive(Debug, Clone, Default)]
pub struct RegionRecord {
    /// Last rasterizer finished the region (final sample for nontex).
    pub rasterized: Option<Time>,
    /// Composition started.
    pub comp_start: Option<Time>,
    /// Composition done.
    pub comp_done: Option<Time>,
    /// Shading started.
    pub shade_start: Option<Time>,
    /// Shading done.
    pub shade_done: Option<Time>,
    /// In frame-buffer memory.
    pub loaded: Option<Time>,
}

/// Per-unit busy totals (for per-stage times).
#[derive(Debug, Clone, Default)]
pub struct Busy {
    /// Geometry processors per node (geometry, sorting pass, generation).
    pub geometry: Vec<Duration>,
    /// Presort generation per node.
    pub generate: Vec<Duration>,
    /// Pixel arrays per rasterizing node.
    pub rasterize: Vec<Duration>,
    /// Network, compositing direction.
    pub composite: Duration,
    /// Network, color direction.
    pub color: Duration,
    /// Shaders.
    pub shade: Vec<Duration>,
    /// Frame-buffer loads.
    pub load: Duration,
}

/// The whole simulated machine for one frame.
#[derive(Debug)]
pub struct PixelFlow {
    /// The configuration.
    pub cfg: PixelFlowConfig,
    /// The primitive layout.
    pub layout: Layout,
    nodes: usize,
    regions: usize,
    shaders: usize,
    frames: usize,
    /// Regions over all frames (frame f's region j is `f * regions + j`).
    total: usize,
    geom_frame: Vec<u32>,
    sorted: Vec<u32>,
    /// Per frame: geometry start (earliest node), front end done (last node), done.
    pub frame_times: Vec<(Option<Time>, Time, Option<Time>)>,
    // per node
    gen_ready: Vec<u32>,
    gen_busy: Vec<bool>,
    gen_end: Vec<Time>,
    rast_next: Vec<u32>,
    rast_busy: Vec<bool>,
    region_rast: Vec<u32>,
    comp_next: u32,
    net_busy: bool,
    shader_reserved: Vec<bool>,
    shader_ready: Vec<Option<u32>>,
    shader_busy: Vec<Option<u32>>,
    color_queue: VecDeque<u32>,
    color_busy: Option<u32>,
    load_queue: VecDeque<u32>,
    load_busy: Option<u32>,
    loaded: usize,
    // nontex
    batches: Vec<u64>,
    geom_batches: Vec<u64>,
    geom_busy: Vec<bool>,
    rast_batches: Vec<u64>,
    pass: u32,
    pass_done_nodes: usize,
    final_comp: bool,
    /// Time the front end finished on every node.
    pub front_end_done: Time,
    /// Time the frame was in frame-buffer memory.
    pub finished: Option<Time>,
    /// Per-region timestamps.
    pub records: Vec<RegionRecord>,
    /// Busy totals.
    pub busy: Busy,
    /// Timeline, when recorded.
    pub trace: Option<Vec<Span>>,
}

fn mul(d: Duration, k: u64, what: &str) -> Result<Duration, SystemError> {
    d.checked_mul(k).ok_or_else(|| {
        SystemError::from(TimeError::Overflow {
            context: format!("computing {what} ({d} x {k})"),
            at: Time::ZERO,
            by: Duration(u64::MAX),
        })
    })
}

impl PixelFlow {
    /// A machine about to start the frame.
    pub fn new(cfg: Checked<PixelFlowConfig>, layout: Layout, trace: bool) -> Self {
        let cfg = cfg.into_inner();
        let nodes = layout.nodes;
        let regions = layout.regions;
        let shaders = cfg.shaders().max(1) as usize;
        let frames = match cfg.architecture {
            Architecture::Nontex => 1,
            _ => cfg.frames.max(1) as usize,
        };
        let total = frames * regions;
        let b = cfg.nontex.batch_primitives.max(1);
        let batches = layout.prims.iter().map(|&p| p.div_ceil(b).max(1)).collect();
        PixelFlow {
            nodes,
            regions,
            shaders,
            frames,
            total,
            geom_frame: vec![0; nodes],
            sorted: vec![0; nodes],
            frame_times: vec![(None, Time::ZERO, None); frames],
            gen_ready: vec![0; nodes],
            gen_busy: vec![false; nodes],
            gen_end: vec![Time::ZERO; nodes],
            rast_next: vec![0; nodes],
            rast_busy: vec![false; nodes],
            region_rast: vec![0; total],
            comp_next: 0,
            net_busy: false,
            shader_reserved: vec![false; shaders],
            shader_ready: vec![None; shaders],
            shader_busy: vec![None; shaders],
            color_queue: VecDeque::new(),
            color_busy: None,
            load_queue: VecDeque::new(),
            load_busy: None,
            loaded: 0,
            batches,
            geom_batches: vec![0; nodes],
            geom_busy: vec![false; nodes],
            rast_batches: vec![0; nodes],
            pass: 1,
            pass_done_nodes: 0,
            final_comp: false,
            front_end_done: Time::ZERO,
            finished: None,
            records: vec![RegionRecord::default(); total],
            busy: Busy {
                geometry: vec![Duration::ZERO; nodes],
                generate: vec![Duration::ZERO; nodes],
                rasterize: vec![Duration::ZERO; nodes],
                shade: vec![Duration::ZERO; shaders],
                ..Busy::default()
            },
            trace: trace.then(Vec::new),
            layout,
            cfg,
        }
    }

    /// Regions in frame-buffer memory.
    pub fn loaded(&self) -> usize {
        self.loaded
    }

    fn span(&mut self, role: u8, unit: u32, name: &'static str, arg: u32, start: Time, end: Time) {
        if let Some(t) = &mut self.trace {
            t.push(Span {
                role,
                unit,
                name,
                arg,
                start,
                end,
            });
        }
    }

    /// Schedules `ev` after `d`, recording a span and adding `d` to a busy total.
    #[allow(clippy::too_many_arguments)]
    fn work(
        &mut self,
        sched: &mut Scheduler<Ev>,
        d: Duration,
        ev: Ev,
        role: u8,
        unit: u32,
        name: &'static str,
        arg: u32,
    ) -> Result<Time, SystemError> {
        let now = sched.now();
        let end = sched.after(d, ev, name)?;
        self.span(role, unit, name, arg, now, end);
        Ok(end)
    }

    /// Node `r`'s rasterizer takes `work`: marks it busy, adds the work to
    /// its busy total and returns how long the step lasts. While the
    /// geometry processor still writes the instructions (`streaming`, §6:
    /// "completely pipelined") it ends no earlier than one primitive
    /// (`per_prim`) after the geometry.
    fn begin_rasterize(
        &mut self,
        r: usize,
        work: Duration,
        per_prim: Duration,
        now: Time,
        streaming: bool,
    ) -> Duration {
        let mut d = work;
        if streaming {
            let tail = self.gen_end[r].since(now).saturating_add(per_prim);
            d = d.max(tail);
        }
        self.rast_busy[r] = true;
        self.busy.rasterize[r] = self.busy.rasterize[r].saturating_add(work);
        d
    }

    /// Schedules the frame's first events.
    pub fn start(&mut self, sched: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        if self.cfg.architecture != Architecture::Nontex {
            return self.settle(sched);
        }
        self.frame_times[0].0 = Some(Time::ZERO);
        for r in 0..self.nodes {
            let p = self.layout.prims[r];
            let (d, ev, name) = match self.cfg.architecture {
                Architecture::Standard => {
                    let c = &self.cfg.deferred;
                    (
                        c.t_overhead.checked_add(mul(c.t_trans, p, "geometry")?),
                        Ev::GeomDone(r as u32),
                        "geometry + bucket sort",
                    )
                }
                Architecture::Presort => {
                    let c = &self.cfg.deferred;
                    (
                        c.t_overhead.checked_add(mul(c.t_first_pass, p, "sorting pass")?),
                        Ev::GeomDone(r as u32),
                        "sorting pass",
                    )
                }
                Architecture::Nontex => {
                    let c = &self.cfg.nontex;
                    let b = self.batch_prims(r, 0);
                    (
                        c.t_overhead.checked_add(mul(c.t_trans, b, "geometry")?),
                        Ev::BatchGeomDone(r as u32),
                        "geometry",
                    )
                }
            };
            let d = d.ok_or_else(|| {
                SystemError::from(TimeError::Overflow {
                    context: "frame start-up".into(),
                    at: Time::ZERO,
                    by: Duration(u64::MAX),
                })
            })?;
            self.busy.geometry[r] = d;
            self.geom_busy[r] = true;
            self.gen_end[r] = self.work(sched, d, ev, 0, r as u32, name, 0)?;
        }
        self.settle(sched)
    }

    // ----- nontex helpers -----

    fn batch_prims(&self, node: usize, k: u64) -> u64 {
        let b = self.cfg.nontex.batch_primitives.max(1);
        let p = self.layout.prims[node];
        p.saturating_sub(k * b).min(b)
    }

    /// Region entries of batch `k` of `node` (cumulative rounding of the
    /// node's entries in proportion to its primitives).
    fn batch_entries(&self, node: usize, k: u64) -> u64 {
        let b = self.cfg.nontex.batch_primitives.max(1);
        let p = self.layout.prims[node];
        let e = self.layout.node_entries(node);
        if p == 0 {
            return 0;
        }
        let upto = |m: u64| -> u64 { ((e as u128 * (m * b).min(p) as u128) / p as u128) as u64 };
        upto(k + 1) - upto(k)
    }

    fn settle(&mut self, sched: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        loop {
            let mut moved = false;
            match self.cfg.architecture {
                Architecture::Nontex => moved |= self.settle_nontex(sched)?,
                _ => moved |= self.settle_deferred(sched)?,
            }
            moved |= self.settle_tail(sched)?;
            if !moved {
                return Ok(());
            }
        }
    }

    /// Whether node `r` may start the geometry (standard) or sorting pass
    /// (presort) of its next frame.
    fn geometry_may_start(&self, r: usize) -> bool {
        let f = self.geom_frame[r] as usize;
        if self.geom_busy[r] || self.gen_busy[r] || f >= self.frames {
            return false;
        }
        match self.cfg.architecture {
            // Two instruction buffers: frame f reuses frame f-2's buffer once
            // this node has rasterized all of frame f-2.
            Architecture::Standard => f < 2 || self.rast_next[r] as usize >= (f - 1) * self.regions,
            // No frame pipelining: the next sorting pass follows the
            // generation of this frame's instructions.
            _ => self.gen_ready[r] as usize >= f * self.regions,
        }
    }

    fn settle_tail(&mut self, sched: &mut Scheduler<Ev>) -> Result<bool, SystemError> {
        if self.load_busy.is_none()
            && let Some(j) = self.load_queue.pop_front()
        {
            self.load_busy = Some(j);
            let d = match self.cfg.architecture {
                Architecture::Nontex => self.cfg.nontex.t_load,
                _ => self.cfg.deferred.t_load,
            };
            self.busy.load = self.busy.load.saturating_add(d);
            self.work(sched, d, Ev::LoadDone(j), 4, 0, "load frame buffer", j)?;
            return Ok(true);
        }
        Ok(false)
    }
}

impl Model for PixelFlow {
    type Event = Ev;
    type Error = SystemError;

    fn handle(&mut self, now: Time, ev: Ev, sched: &mut Scheduler<Ev>) -> Result<Control, SystemError> {
        match ev {
            Ev::GeomDone(r) => {
                let r = r as usize;
                let f = self.geom_frame[r] as usize;
                self.geom_busy[r] = false;
                self.geom_frame[r] += 1;
                self.frame_times[f].1 = self.frame_times[f].1.max(now);
                if f == 0 {
                    self.front_end_done = self.front_end_done.max(now);
                }
                if self.cfg.architecture == Architecture::Standard {
                    self.gen_ready[r] = ((f + 1) * self.regions) as u32;
                } else {
                    self.sorted[r] += 1;
                }
            }
            Ev::GenDone(r) => {
                let r = r as usize;
                self.gen_busy[r] = false;
                self.gen_ready[r] += 1;
            }
            Ev::RastDone(r) => {
                let r = r as usize;
                let j = self.rast_next[r] as usize;
                self.rast_busy[r] = false;
                self.rast_next[r] += 1;
                self.region_rast[j] += 1;
                if self.region_rast[j] as usize == self.nodes {
                    self.records[j].rasterized = Some(now);
                }
            }
            Ev::CompDone(j) => {
                self.net_busy = false;
                self.records[j as usize].comp_done = Some(now);
                match self.cfg.architecture {
                    Architecture::Nontex => self.load_queue.push_back(j),
                    _ => self.shader_ready[j as usize % self.shaders] = Some(j),
                }
            }
            Ev::ShadeDone(s) => {
                let j = self.shader_busy[s as usize].take().unwrap_or(0);
                self.records[j as usize].shade_done = Some(now);
                self.color_queue.push_back(j);
            }
            Ev::ColorDone(j) => {
                self.color_busy = None;
                self.load_queue.push_back(j);
            }
            Ev::LoadDone(j) => {
                self.load_busy = None;
                self.records[j as usize].loaded = Some(now);
                self.loaded += 1;
                if self.loaded.is_multiple_of(self.regions) {
                    let f = self.loaded / self.regions - 1;
                    if let Some(ft) = self.frame_times.get_mut(f) {
                        ft.2 = Some(now);
                    }
                }
                if self.loaded == self.total {
                    self.finished = Some(now);
                    return Ok(Control::Stop);
                }
            }
            Ev::BatchGeomDone(r) => {
                let r = r as usize;
                self.geom_busy[r] = false;
                self.geom_batches[r] += 1;
            }
            Ev::BatchRastDone(r) => {
                let r = r as usize;
                self.rast_busy[r] = false;
                let done = if self.pass == 1 {
                    self.rast_batches[r] += 1;
                    self.rast_batches[r] == self.batches[r]
                } else {
                    true
                };
                if done {
                    self.pass_done_nodes += 1;
                    if self.pass_done_nodes == self.nodes {
                        self.nontex_pass_done(sched)?;
                    }
                }
            }
            Ev::PassCompDone => {
                // Next sample: rasterize the stored instructions again.
                self.pass += 1;
                let t = self.cfg.nontex.t_rast_per_prim;
                for r in 0..self.nodes {
                    let d = mul(t, self.layout.node_entries(r), "rasterization")?;
                    self.rast_busy[r] = true;
                    self.busy.rasterize[r] = self.busy.rasterize[r].saturating_add(d);
                    let pass = self.pass;
                    self.work(
                        sched,
                        d,
                        Ev::BatchRastDone(r as u32),
                        1,
                        r as u32,
                        "rasterize sample",
                        pass,
                    )?;
                }
            }
        }
        self.settle(sched)?;
        Ok(Control::Continue)
    }
}
