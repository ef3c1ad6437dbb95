//! What the frame pipeline's units share (paper 000 §3-4 and Figure 4): the
//! command FIFO from the CPU thread to the GPU's front end (the command
//! buffer whose being full or empty idles one side), the triangle FIFO
//! between the geometry and fragment stages (§4.5), the unified
//! architecture's shader-core pool that both stages run on, the swap chain
//! between the front end and the display (paper 004 §4.2), the count of
//! frames the GPU completed that the CPU's frames-in-flight limit waits on,
//! and the bus that copies and the vertex fetch from AGP memory share
//! (paper 000 §4.5.3, Table 4).
//!
//! No unit holds another's state: each unit's methods get these links as
//! arguments, in an [`Env`] with the model and the per-frame records.

use crate::components::fifo::{BoundedFifo, FifoUnit};
use crate::components::shader_pool::{ShaderPool, Stream};
use crate::components::shared_bus::SharedBus;
use crate::engine::{Duration, Scheduler, Time};
use crate::systems::error::SystemError;

use super::events::Ev;
use super::records::FrameRecord;
use super::workload::{DrawItem, SceneProgram};

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

/// A triangle's fragment work: shader time (on the pool when unified; all
/// of it when split) and fixed-function time beside it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FragWork {
    /// Shader work (split: the whole fragment-stage time).
    pub shader: Duration,
    /// Fixed-function time (unified only; zero when split).
    pub fixed: Duration,
}

/// The links between the units.
#[derive(Debug)]
pub struct Links {
    /// The command FIFO (CPU thread -> front end).
    pub(super) commands: BoundedFifo<Command>,
    /// The triangle FIFO (geometry -> fragment); with binning, the draw's bins.
    pub(super) triangles: BoundedFifo<FragWork>,
    /// The triangle link's slot past the FIFO: a triangle the geometry
    /// stage finished while the FIFO was full (the stage blocks until the
    /// fragment stage takes it from here).
    pub(super) held_triangle: Option<FragWork>,
    /// The unified architecture's shader-core pool (`None`: split).
    pub(super) shaders: Option<ShaderPool>,
    /// Frames whose swap the GPU finished (what the CPU's
    /// `cpu.max_frames_ahead` counts against).
    pub(super) frames_completed: u64,
    /// The bus the CPU's copies and the GPU's vertex fetch from AGP memory
    /// share (paper 000 Table 4): what each asks for now.
    pub(super) bus: SharedBus,
    /// The fetch's ask changed since the CPU's copy last took its rate.
    pub(super) bus_changed: bool,
}

impl Links {
    /// Unified pool: whether a completion event with `tag` is `stream`'s
    /// current one (and if so, ends the item on the pool). Always true when
    /// split.
    #[inline]
    pub(super) fn shader_completes(&mut self, now: Time, stream: Stream, tag: u32) -> bool {
        match &mut self.shaders {
            Some(pool) if !pool.is_current(stream, tag) => false,
            Some(pool) => {
                pool.end(now, stream);
                true
            }
            None => true,
        }
    }

    /// Unified pool: after an instant's changes, schedules the completions
    /// whose time moved (stale ones are ignored by their tags).
    #[inline]
    pub(super) fn settle_shaders(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        // Split (and `draw` fidelity): no pool, nothing to do, no call.
        if self.shaders.is_none() {
            return Ok(());
        }
        self.settle_pool(now, s)
    }

    /// [`Links::settle_shaders`] with a pool.
    #[inline(never)]
    fn settle_pool(&mut self, now: Time, s: &mut Scheduler<Ev>) -> Result<(), SystemError> {
        if let Some(pool) = &mut self.shaders {
            // Over the two streams' slots, not `Changes::iter` (which the
            // compiler does not always inline here).
            for d in pool.settle(now)?.0.into_iter().flatten() {
                s.at(
                    d.at,
                    match d.stream {
                        Stream::Vertex => Ev::GeomTriangle { tag: d.tag },
                        Stream::Fragment => Ev::FragTriangle { tag: d.tag },
                    },
                );
            }
        }
        Ok(())
    }
}

/// What a unit's transition reads and writes besides its own state and spec:
/// the scene, the links, the per-frame records, and whether a trace
/// is written (which turns the short cuts off). The pipeline owns it as one
/// field, so a transition gets it as one reference and no struct of
/// references is built per event.
#[derive(Debug)]
pub(super) struct Env {
    /// The compiled scene (`None`: a fixed workload, which the CPU thread holds).
    pub(super) scene: Option<SceneProgram>,
    pub(super) links: Links,
    pub(super) records: Vec<FrameRecord>,
    pub(super) traced: bool,
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

/// Commands in a FIFO entry (a draw batch holds its state changes and
/// upload with the draw).
pub(super) fn command_count(scene: &Option<SceneProgram>, c: &Command) -> u64 {
    match c {
        Command::Draw { draw, .. } => scene
            .as_ref()
            .map(|s| s.draws[*draw as usize].commands as u64)
            .unwrap_or(1),
        _ => 1,
    }
}
