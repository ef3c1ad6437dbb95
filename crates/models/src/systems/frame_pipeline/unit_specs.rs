//! What each unit reads of the model, taken out of the checked model once by
//! the plan ([`super::plan::PipelinePlan`]): the CPU thread's costs, pacing
//! and command weights; the front end's command costs, per-frame variation
//! and replayed GPU ends; the geometry stage's costs and closed forms (the
//! display's, with frame generation, is the plan's `DisplaySpec`). A unit holds its spec and never sees the raw model
//! ([`super::config::FramePipelineConfig`], which the run keeps only to
//! summarise and write `model.toml`).

use crate::components::distribution::Dist;
use crate::components::fifo::FifoUnit;
use crate::components::frame_pacing::PacingConfig;
use crate::engine::Duration;

use super::config::{Fidelity, FramePipelineConfig, GeometryConfig, WorkloadConfig};
use super::links::{Command, draw_batch_weight};
use super::workload::{ClosedForm, SceneProgram};

/// The CPU thread's spec (`[cpu]`, `variation.cpu`, `[pacing]`, the command
/// FIFO's unit).
#[derive(Debug, Clone)]
pub(super) struct CpuSpec {
    /// Reading input at a frame's start.
    pub(super) input_sampling: Duration,
    /// Non-rendering work per frame.
    pub(super) non_render: Dist<Duration>,
    /// Per-frame variation added to it (`variation.cpu`).
    pub(super) variation: Option<Dist<Duration>>,
    /// The clear's and the swap's API costs.
    pub(super) clear: Duration,
    pub(super) swap: Duration,
    /// Frames the thread may run ahead of the GPU.
    pub(super) max_frames_ahead: u32,
    /// The weights of the commands it pushes.
    pub(super) weights: CommandWeights,
    /// The frame limiter and the low-latency pacer.
    pub(super) pacing: PacingConfig,
}

/// A command's weight in the command FIFO's unit (`[command_fifo]`).
#[derive(Debug, Clone, Copy)]
pub(super) struct CommandWeights {
    pub(super) unit: FifoUnit,
    clear: u64,
    swap: u64,
    draw: u64,
}

impl CommandWeights {
    /// The weight of `c` (a scene's draw batch weighs its commands or bytes).
    #[inline]
    pub(super) fn of(&self, scene: &Option<SceneProgram>, c: &Command) -> u64 {
        match (self.unit, c) {
            (_, Command::Draw { draw, .. }) if let Some(s) = scene => {
                draw_batch_weight(self.unit, &s.draws[*draw as usize])
            }
            (FifoUnit::Entries, _) => 1,
            (FifoUnit::Bytes, Command::Clear { .. }) => self.clear,
            (FifoUnit::Bytes, Command::Swap { .. }) => self.swap,
            (FifoUnit::Bytes, Command::Fixed { .. } | Command::Draw { .. }) => self.draw,
        }
    }
}

/// The GPU front end's spec (`[gpu]` command costs, `variation.gpu`, a
/// replay's measured GPU ends; frame generation's cost is the display's).
#[derive(Debug, Clone)]
pub(super) struct FrontSpec {
    /// Processing cost of every command.
    pub(super) command: Duration,
    /// The clear's and the swap's GPU work.
    pub(super) clear: Duration,
    pub(super) swap: Duration,
    /// Per-frame variation added to the clear (`variation.gpu`).
    pub(super) variation: Option<Dist<Duration>>,
    /// Sort-middle binning: a draw's geometry waits for the bins to drain.
    pub(super) binned: bool,
    /// A replayed frame's measured GPU end after it began
    /// (`workload.gpu_end`; empty for every other workload).
    pub(super) gpu_end: Vec<Duration>,
}

/// The geometry stage's spec (`fidelity`, `[gpu.geometry]`, the fragment
/// stage's binning, the closed forms of `draw` fidelity).
#[derive(Debug, Clone)]
pub(super) struct GeometrySpec {
    pub(super) fidelity: Fidelity,
    /// Per-vertex, per-index and per-triangle costs.
    pub(super) costs: GeometryConfig,
    /// Sort-middle binning: triangles go to the bins, not a FIFO.
    pub(super) binned: bool,
    /// What a draw's closed-form times depend on besides the draw.
    pub(super) closed: ClosedForm,
}

/// The CPU thread's, the front end's and the geometry stage's specs (the
/// display's is the plan's `DisplaySpec`).
#[derive(Debug, Clone)]
pub(super) struct UnitSpecs {
    pub(super) cpu: CpuSpec,
    pub(super) front: FrontSpec,
    pub(super) geometry: GeometrySpec,
}

/// The units' specs of a checked model.
pub(super) fn unit_specs(cfg: &FramePipelineConfig) -> UnitSpecs {
    let bytes = &cfg.command_fifo.bytes;
    let cpu = CpuSpec {
        input_sampling: cfg.cpu.input_sampling,
        non_render: cfg.cpu.non_render.clone(),
        variation: cfg.variation.cpu().cloned(),
        clear: cfg.cpu.clear,
        swap: cfg.cpu.swap,
        max_frames_ahead: cfg.cpu.max_frames_ahead,
        weights: CommandWeights {
            unit: cfg.command_fifo.unit,
            clear: bytes.clear.0,
            swap: bytes.swap.0,
            draw: bytes.draw.0,
        },
        pacing: cfg.pacing.clone(),
    };
    let front = FrontSpec {
        command: cfg.gpu.command,
        clear: cfg.gpu.clear,
        swap: cfg.gpu.swap,
        variation: cfg.variation.gpu().cloned(),
        binned: cfg.gpu.fragment.binned(),
        gpu_end: match &cfg.workload {
            WorkloadConfig::Frames(w) => w.gpu_end.clone(),
            _ => Vec::new(),
        },
    };
    let geometry = GeometrySpec {
        fidelity: cfg.fidelity,
        costs: cfg.gpu.geometry.clone(),
        binned: cfg.gpu.fragment.binned(),
        closed: ClosedForm::of(cfg),
    };
    UnitSpecs { cpu, front, geometry }
}
