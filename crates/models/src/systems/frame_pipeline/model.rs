//! The frame-pipeline system as a kernel [`Model`]: a CPU thread feeds a
//! bounded command FIFO; the GPU's front end, geometry stage, triangle FIFO
//! and fragment stage execute it; a swap chain and display show the frames;
//! system tasks preempt the CPU thread or the GPU's command processing.
//!
//! Follows paper 000 §3-4 and Figure 4 (CPU and GPU working in parallel
//! through the command buffer; idle time when it is full or empty) and paper
//! 004 §4.2 (vsync and double buffering). The event handlers live in
//! `cpu.rs`, `gpu.rs` and `display.rs`; time accounting in `accounting.rs`.

use crate::components::distribution::Dist;
use crate::components::fifo::{BoundedFifo, FifoUnit};
use crate::components::noise::{Arrivals, NoiseSource, NoiseTarget};
use crate::components::preemptible::{Preemptible, Wake};
use crate::components::shader_pool::{ShaderPool, Stream};
use crate::components::swap_chain::{PresentMode, SwapChain};
use crate::engine::{Control, Duration, EventKind, Model, RngStreams, Scheduler, Slot, StreamRng, Time};
use crate::systems::error::SystemError;

use super::accounting::Accounting;
use super::config::{Fidelity, FramePipelineConfig, WorkloadConfig};
use super::records::FrameRecord;
use super::workload::{DrawItem, SceneProgram};

/// Events of the frame pipeline.
#[derive(Debug, Clone, Copy)]
pub enum Ev {
    /// The CPU thread's current work item finished (tag guards preemption).
    CpuDone {
        /// Generation tag.
        tag: u32,
    },
    /// The GPU front end's current command finished.
    FrontDone {
        /// Generation tag.
        tag: u32,
    },
    /// The geometry stage finished a triangle (`triangle` fidelity; the tag
    /// guards the unified pool's rescheduling, 0 when split).
    GeomTriangle {
        /// Generation tag.
        tag: u32,
    },
    /// The fragment stage finished a triangle (`triangle` fidelity; tagged
    /// as [`Ev::GeomTriangle`]).
    FragTriangle {
        /// Generation tag.
        tag: u32,
    },
    /// The geometry part of a draw ended (`draw` fidelity).
    DrawGeometry,
    /// The fragment part of a draw began (`draw` fidelity).
    DrawFragmentStart,
    /// A draw ended (`draw` fidelity).
    DrawDone,
    /// Vertical blank.
    Vblank,
    /// A system task arrives.
    NoiseArrive {
        /// Index of the noise source.
        source: u16,
    },
    /// The running system task on a unit ends.
    NoiseEnd {
        /// Which unit.
        target: NoiseTarget,
    },
    /// The CPU thread starts a frame at the instant where more frames
    /// started than could be in flight, so frames take no time: each such
    /// frame goes through the run loop as an event, and `run.max_events`
    /// holds for it (scheduled only for zero-time frames).
    ZeroTimeFrame,
}

impl EventKind for Ev {
    const NAMES: &'static [&'static str] = &[
        "cpu_work",
        "gpu_front_end",
        "geometry_triangle",
        "fragment_triangle",
        "draw_geometry",
        "draw_fragment_start",
        "draw_done",
        "vblank",
        "noise_arrival",
        "noise_end",
        "zero_time_frame",
    ];
    #[inline]
    fn kind(&self) -> usize {
        match self {
            Ev::CpuDone { .. } => 0,
            Ev::FrontDone { .. } => 1,
            Ev::GeomTriangle { .. } => 2,
            Ev::FragTriangle { .. } => 3,
            Ev::DrawGeometry => 4,
            Ev::DrawFragmentStart => 5,
            Ev::DrawDone => 6,
            Ev::Vblank => 7,
            Ev::NoiseArrive { .. } => 8,
            Ev::NoiseEnd { .. } => 9,
            Ev::ZeroTimeFrame => 10,
        }
    }
}

/// A command in the CPU -> GPU FIFO.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    /// Clear (needs a free swap-chain image).
    Clear {
        /// Frame.
        frame: u64,
    },
    /// Fixed GPU work.
    Fixed {
        /// Frame.
        frame: u64,
        /// GPU time.
        gpu: Duration,
    },
    /// A draw batch (state changes, uploads, draw).
    Draw {
        /// Frame.
        frame: u64,
        /// Index into the scene's draws.
        draw: u32,
    },
    /// End of frame: drain the pipeline and present.
    Swap {
        /// Frame.
        frame: u64,
    },
}

/// The workload as the simulation consumes it.
#[derive(Debug)]
pub enum Program {
    /// Fixed CPU and GPU time per frame.
    Fixed {
        /// CPU time.
        cpu: Dist<Duration>,
        /// GPU time.
        gpu: Dist<Duration>,
        /// Stream for the CPU part.
        cpu_rng: StreamRng,
        /// Stream for the GPU part.
        gpu_rng: StreamRng,
    },
    /// A compiled scene.
    Scene(SceneProgram),
}

/// What the CPU thread is doing. The phases carry no data (the command
/// to push is in [`FramePipeline::cpu_cmd`]), so a phase is one byte,
/// written and read back whole on the hot path.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CpuPhase {
    /// About to start frame `cpu_frame` (transient).
    NextFrame,
    /// Blocked: too many frames in flight.
    WaitFrames,
    /// About to run operation `cpu_op` (transient).
    Ready,
    /// Running operation `cpu_op` (possibly preempted).
    Running,
    /// Must push the command in `cpu_cmd`; at rest this means the FIFO is
    /// full.
    Push,
    /// Pushed into a FIFO beyond its capacity (rendezvous): waits until taken.
    Rendezvous,
    /// Waits for its [`Ev::ZeroTimeFrame`] event before starting a frame
    /// that takes no time.
    ZeroTimeWait,
    /// All frames submitted.
    Finished,
}

/// What the GPU front end is doing (its command is in
/// [`FramePipeline::front_cmd`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrontPhase {
    /// Waiting for commands (starved when at rest).
    Idle,
    /// A clear (in `front_cmd`) waits for a free swap-chain image.
    WaitImage,
    /// A swap (in `front_cmd`) waits for the pipeline to drain.
    WaitDrain,
    /// Processing the command in `front_cmd` (possibly preempted).
    Running,
    /// A draw (in `front_cmd`) waits for the geometry stage to take it.
    Handoff,
}

/// The frame pipeline's full state.
pub struct FramePipeline {
    pub(super) cfg: FramePipelineConfig,
    pub(super) program: Program,
    pub(super) frames_total: u64,
    // CPU thread
    pub(super) cpu: Preemptible,
    pub(super) cpu_phase: CpuPhase,
    /// The command of [`CpuPhase::Push`].
    pub(super) cpu_cmd: Command,
    /// Its weight in the FIFO's unit (so a push blocked on a full FIFO is
    /// found without a call).
    pub(super) cpu_cmd_weight: u64,
    /// Operations between the clear and the swap: the scene's draws, or the
    /// one fixed GPU command.
    pub(super) body_ops: u32,
    /// Whether those are a scene's draws (else the fixed command).
    pub(super) scene_body: bool,
    pub(super) cpu_frame: u64,
    pub(super) cpu_op: u32,
    pub(super) non_render_rng: StreamRng,
    /// Per-frame variation streams: CPU, GPU (`variation.cpu`, `variation.gpu`).
    pub(super) variation_rng: [StreamRng; 2],
    /// The instant the CPU thread last started a frame, and how many
    /// frames it started then.
    pub(super) frames_at_instant: (Time, u64),
    /// Frames started at one instant beyond which a frame is known to take
    /// no time (more than could be in flight); see [`Ev::ZeroTimeFrame`].
    pub(super) zero_time_after: u64,
    /// The pending [`Ev::ZeroTimeFrame`] was handled: start the frame.
    pub(super) zero_time_go: bool,
    pub(super) fifo: BoundedFifo<Command>,
    pub(super) commands_issued: u64,
    pub(super) commands_executed: u64,
    // GPU
    pub(super) front: Preemptible,
    pub(super) front_phase: FrontPhase,
    /// The command of every [`FrontPhase`] but `Idle`.
    pub(super) front_cmd: Command,
    pub(super) gpu_frame: Option<u64>,
    pub(super) gpu_completed: u64,
    pub(super) geom_draw: Option<ActiveDraw>,
    pub(super) geom_busy: bool,
    /// `draw` fidelity without a trace: the running draw's (geometry,
    /// fragment, total) times, credited to the stage clocks when it ends
    /// instead of with two extra events.
    pub(super) draw_split: Option<(Duration, Duration, Duration)>,
    /// `draw` fidelity: whether the running draw is fragment-limited (F >= G);
    /// the bottleneck of the whole draw goes to that stage.
    pub(super) draw_fragment_limited: Option<bool>,
    /// `draw` fidelity: when the running draw ends (its [`Ev::DrawDone`]).
    pub(super) draw_done_at: Option<Time>,
    /// The front end's draw command completing quietly: its slot in the
    /// event order and the job's tag ([`super::quiet`]).
    pub(super) front_quiet: Option<(Slot, u32)>,
    /// A finished triangle's fragment work (shader, fixed-function) that
    /// found the triangle FIFO full.
    pub(super) geom_held: Option<FragWork>,
    pub(super) tri_fifo: BoundedFifo<FragWork>,
    /// The unified architecture's shader-core pool (`None`: split).
    pub(super) pool: Option<ShaderPool>,
    /// The running draw's triangle sizes when its group sorts them
    /// (`size_order`), in drawing order; empty otherwise.
    pub(super) draw_sizes: Vec<f64>,
    pub(super) frag_busy: bool,
    pub(super) pixel_rng: StreamRng,
    /// The size stream's state at the start, restored every frame for a static view.
    pub(super) pixel_rng_start: Option<StreamRng>,
    // display
    pub(super) chain: SwapChain,
    pub(super) refresh: Duration,
    pub(super) vblanks: u64,
    pub(super) repeated_refreshes: u64,
    /// (vertical blanks, repeated refreshes, time) when the first frame after
    /// warm-up was shown; refresh metrics count from there.
    pub(super) refresh_mark: Option<(u64, u64, Time)>,
    pub(super) last_display: Option<Time>,
    pub(super) resolved: u64,
    // noise
    pub(super) noise: Vec<NoiseSource>,
    // results
    pub(super) records: Vec<FrameRecord>,
    pub(super) acct: Accounting,
}

/// A draw batch's weight in the command FIFO's unit: its commands (state
/// changes, upload, draw) or its bytes.
#[inline]
pub(super) fn draw_batch_weight(unit: FifoUnit, d: &DrawItem) -> u64 {
    match unit {
        FifoUnit::Entries => u64::from(d.commands),
        FifoUnit::Bytes => d.bytes,
    }
}

/// A triangle's fragment work: shader time (on the pool when unified; all
/// of it when split) and fixed-function time beside it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FragWork {
    /// Shader work (split: the whole fragment-stage time).
    pub shader: Duration,
    /// Fixed-function time (unified only; zero when split).
    pub fixed: Duration,
}

/// A draw in the geometry stage.
#[derive(Debug, Clone, Copy)]
pub struct ActiveDraw {
    /// Index into the scene's draws.
    pub draw: u32,
    /// Next triangle.
    pub next: u64,
    /// Triangles.
    pub triangles: u64,
}

impl FramePipeline {
    /// Builds the system from a validated model and its compiled workload.
    pub fn new(
        cfg: FramePipelineConfig,
        scene: Option<SceneProgram>,
        trace: Option<crate::output::trace::TraceWriter>,
    ) -> Result<Self, SystemError> {
        let streams = RngStreams::new(cfg.run.seed);
        let program = match (&cfg.workload, scene) {
            (WorkloadConfig::Fixed(f), _) => Program::Fixed {
                cpu: f.cpu.clone(),
                gpu: f.gpu.clone(),
                cpu_rng: streams.stream("workload.cpu"),
                gpu_rng: streams.stream("workload.gpu"),
            },
            (WorkloadConfig::Scene(_), Some(s)) => Program::Scene(s),
            (WorkloadConfig::Scene(_), None) => {
                return Err(SystemError::Invalid {
                    key: "workload".into(),
                    message: "scene not compiled".into(),
                });
            }
        };
        let mut noise = Vec::new();
        if cfg.noise.enabled {
            for (i, p) in cfg.noise.periodic.iter().enumerate().filter(|(_, p)| p.enabled) {
                let src = NoiseSource::new(
                    p.name.clone(),
                    p.target,
                    Arrivals::Periodic {
                        period: p.period,
                        phase: p.phase,
                        jitter: p.jitter,
                    },
                    p.duration.clone(),
                    streams.stream(&format!("noise.{}", p.name)),
                )
                .map_err(|e| SystemError::Invalid {
                    key: format!("noise.periodic.{i}"),
                    message: e.to_string(),
                })?;
                noise.push(src);
            }
            for (i, r) in cfg.noise.random.iter().enumerate().filter(|(_, r)| r.enabled) {
                let src = NoiseSource::new(
                    r.name.clone(),
                    r.target,
                    Arrivals::Poisson {
                        mean_gap: r.rate.period,
                    },
                    r.duration.clone(),
                    streams.stream(&format!("noise.{}", r.name)),
                )
                .map_err(|e| SystemError::Invalid {
                    key: format!("noise.random.{i}"),
                    message: e.to_string(),
                })?;
                noise.push(src);
            }
        }
        let mode = cfg.display.effective_mode();
        let fifo_cap = cfg.command_fifo.capacity;
        let frames_total = cfg.run.frames;
        let (body_ops, scene_body) = match &program {
            Program::Fixed { .. } => (1, false),
            Program::Scene(s) => (s.draws.len() as u32, true),
        };
        Ok(FramePipeline {
            refresh: cfg.display.refresh.period,
            chain: SwapChain::new(cfg.display.buffers, mode),
            // Binning: the FIFO is the draw's bins and holds all of it.
            tri_fifo: BoundedFifo::new(if cfg.gpu.fragment.binned() {
                u64::MAX
            } else {
                cfg.gpu.fragment.fifo_depth as u64
            }),
            non_render_rng: streams.stream("cpu.non_render"),
            variation_rng: [streams.stream("variation.cpu"), streams.stream("variation.gpu")],
            frames_at_instant: (Time::ZERO, 0),
            zero_time_after: u64::from(cfg.cpu.max_frames_ahead) + u64::from(cfg.display.buffers) + 1,
            zero_time_go: false,
            pixel_rng: streams.stream("fragment.pixels"),
            pixel_rng_start: match &cfg.workload {
                WorkloadConfig::Scene(sc) if sc.view == crate::scene::config::View::Static => {
                    Some(streams.stream("fragment.pixels"))
                }
                _ => None,
            },
            program,
            frames_total,
            cpu: Preemptible::new(),
            cpu_phase: CpuPhase::NextFrame,
            cpu_cmd: Command::Clear { frame: 0 },
            cpu_cmd_weight: 1,
            body_ops,
            scene_body,
            cpu_frame: 0,
            cpu_op: 0,
            fifo: BoundedFifo::new(fifo_cap),
            commands_issued: 0,
            commands_executed: 0,
            front: Preemptible::new(),
            front_phase: FrontPhase::Idle,
            front_cmd: Command::Clear { frame: 0 },
            gpu_frame: None,
            gpu_completed: 0,
            geom_draw: None,
            geom_busy: false,
            draw_split: None,
            draw_fragment_limited: None,
            draw_done_at: None,
            front_quiet: None,
            geom_held: None,
            draw_sizes: Vec::new(),
            pool: match cfg.fidelity {
                Fidelity::Triangle => cfg.gpu.pool().map(|(n, p)| ShaderPool::new(n, p)),
                Fidelity::Draw => None,
            },
            frag_busy: false,
            vblanks: 0,
            repeated_refreshes: 0,
            refresh_mark: None,
            last_display: None,
            resolved: 0,
            noise,
            records: Vec::with_capacity(frames_total.min(1 << 16) as usize),
            acct: Accounting::new(
                trace,
                (mode != PresentMode::Immediate).then_some(cfg.display.refresh.period),
            ),
            cfg,
        })
    }

    /// Schedules the first events. Call once before running.
    pub fn start(&mut self, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        if self.frames_total == 0 {
            return Ok(());
        }
        if self.chain.mode() != PresentMode::Immediate {
            s.at(Time::ZERO, Ev::Vblank);
        }
        for i in 0..self.noise.len() {
            let t = self.noise[i].next_arrival(Time::ZERO)?;
            s.at(t, Ev::NoiseArrive { source: i as u16 });
        }
        self.settle(Time::ZERO, s)?;
        self.pool_settle(Time::ZERO, s)?;
        self.account(Time::ZERO);
        Ok(())
    }

    /// The weight of a command in the FIFO's unit.
    pub(super) fn command_weight(&self, c: &Command) -> u64 {
        let unit = self.cfg.command_fifo.unit;
        let b = &self.cfg.command_fifo.bytes;
        match (unit, c) {
            (_, Command::Draw { draw, .. }) if let Some(s) = self.scene() => {
                draw_batch_weight(unit, &s.draws[*draw as usize])
            }
            (FifoUnit::Entries, _) => 1,
            (FifoUnit::Bytes, Command::Clear { .. }) => b.clear.0,
            (FifoUnit::Bytes, Command::Swap { .. }) => b.swap.0,
            (FifoUnit::Bytes, Command::Fixed { .. } | Command::Draw { .. }) => b.draw.0,
        }
    }

    /// Commands in a FIFO entry (a draw batch holds its state changes and
    /// upload with the draw).
    pub(super) fn command_count(&self, c: &Command) -> u64 {
        match c {
            Command::Draw { draw, .. } => self
                .scene()
                .map(|s| s.draws[*draw as usize].commands as u64)
                .unwrap_or(1),
            _ => 1,
        }
    }

    pub(super) fn scene(&self) -> Option<&SceneProgram> {
        match &self.program {
            Program::Scene(s) => Some(s),
            Program::Fixed { .. } => None,
        }
    }

    /// The fidelity.
    pub fn fidelity(&self) -> Fidelity {
        self.cfg.fidelity
    }

    /// Commands pushed by the CPU and commands executed by the GPU.
    pub fn command_counts(&self) -> (u64, u64) {
        (self.commands_issued, self.commands_executed)
    }

    /// Frames displayed or dropped so far.
    pub fn resolved(&self) -> u64 {
        self.resolved
    }

    /// Drops the records of frames not yet displayed or dropped (after a run
    /// stopped by a time or event limit): the leading completed frames stay.
    pub fn keep_completed_frames(&mut self) {
        let done = self
            .records
            .iter()
            .take_while(|r| r.displayed.is_some() || r.dropped)
            .count();
        self.records.truncate(done);
    }

    /// Whether all asked-for frames are done.
    pub fn done(&self) -> bool {
        self.resolved >= self.frames_total
    }

    /// A one-line description of the units' states (for stall reports).
    pub fn describe(&self) -> String {
        format!(
            "cpu {} (frame {}, op {}), command fifo {}/{}, front end {}, geometry {:?} busy={} held={}, fragment busy={}, frames completed {}, queued for display {}",
            match self.cpu_phase {
                CpuPhase::Push => format!("Push({:?})", self.cpu_cmd),
                p => format!("{p:?}"),
            },
            self.cpu_frame,
            self.cpu_op,
            self.fifo.used(),
            self.fifo.capacity(),
            match self.front_phase {
                FrontPhase::Idle => "Idle".to_string(),
                p => format!("{p:?}({:?})", self.front_cmd),
            },
            self.geom_draw,
            self.geom_busy,
            self.geom_held.is_some(),
            self.frag_busy,
            self.gpu_completed,
            self.chain.queued()
        )
    }

    /// Lets the CPU thread and the front end make every step they can now.
    ///
    /// Each step runs its unit until it cannot go on, and a step that finds
    /// nothing to do changes nothing; the CPU's progress depends only on what
    /// the front end changes (FIFO space, completed frames). So once the front
    /// end made no progress after a CPU step, another round would change
    /// nothing: the loop ends there.
    pub(super) fn settle(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        loop {
            self.cpu_step(now, s)?;
            if !self.front_step(now, s)? {
                return Ok(());
            }
        }
    }

    #[inline(always)]
    pub(super) fn schedule_wake(s: &mut Scheduler<Ev>, w: Wake, cpu: bool) {
        if let Wake::JobAt(t, tag) = w {
            s.at(
                t,
                if cpu {
                    Ev::CpuDone { tag }
                } else {
                    Ev::FrontDone { tag }
                },
            );
        }
    }

    fn noise_arrive(&mut self, now: Time, source: u16, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        let src = &mut self.noise[source as usize];
        let d = src.draw_duration();
        let target = src.target;
        let next = src.next_arrival(now)?;
        s.at(next, Ev::NoiseArrive { source });
        let unit = match target {
            NoiseTarget::Cpu => &mut self.cpu,
            NoiseTarget::Gpu => &mut self.front,
        };
        if let Some(end) = unit.task_arrives(now, d)? {
            s.at(end, Ev::NoiseEnd { target });
        }
        Ok(())
    }

    fn noise_end(&mut self, now: Time, target: NoiseTarget, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        let unit = match target {
            NoiseTarget::Cpu => &mut self.cpu,
            NoiseTarget::Gpu => &mut self.front,
        };
        let (next, wake) = unit.task_ends(now)?;
        if let Some(end) = next {
            s.at(end, Ev::NoiseEnd { target });
        }
        Self::schedule_wake(s, wake, target == NoiseTarget::Cpu);
        Ok(())
    }
}

impl Model for FramePipeline {
    type Event = Ev;
    type Error = SystemError;

    fn handle(&mut self, now: Time, ev: Ev, s: &mut Scheduler<Ev>) -> Result<Control, SystemError> {
        self.catch_up(s)?;
        match ev {
            Ev::CpuDone { tag } => {
                if self.cpu.complete(tag) {
                    if self.cpu_draw_done_fast(now, s)? {
                        return Ok(Control::Continue);
                    }
                    self.cpu_op_done(now);
                    if self.cpu_step_alone(now, s)? {
                        return Ok(Control::Continue);
                    }
                }
            }
            Ev::FrontDone { tag } => {
                if self.front.complete(tag) {
                    self.front_command_done(now)?;
                }
            }
            Ev::GeomTriangle { tag } => {
                if self.pool_completes(now, Stream::Vertex, tag) {
                    self.geom_triangle_done(now, s)?;
                }
            }
            Ev::FragTriangle { tag } => {
                if self.pool_completes(now, Stream::Fragment, tag) {
                    self.frag_triangle_done(now, s)?;
                }
            }
            Ev::DrawGeometry => self.geom_busy = false,
            Ev::DrawFragmentStart => self.frag_busy = true,
            Ev::DrawDone => {
                self.draw_done();
                if self.draw_done_alone(now, s)? {
                    return Ok(if self.done() { Control::Stop } else { Control::Continue });
                }
            }
            Ev::Vblank => self.vblank(now, s)?,
            Ev::NoiseArrive { source } => self.noise_arrive(now, source, s)?,
            Ev::NoiseEnd { target } => self.noise_end(now, target, s)?,
            Ev::ZeroTimeFrame => {
                self.zero_time_go = true;
                self.cpu_phase = CpuPhase::NextFrame;
            }
        }
        self.settle(now, s)?;
        self.pool_settle(now, s)?;
        self.account(now);
        Ok(if self.done() { Control::Stop } else { Control::Continue })
    }
}
