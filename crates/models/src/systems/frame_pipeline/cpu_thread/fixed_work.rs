//! A fixed workload's per-frame times (`workload.kind = "fixed"`, drawn from
//! distributions, or `"frames"`, a replayed capture's frame by frame): what
//! the CPU thread runs before and after its frame's submission, and the
//! GPU time of the frame's one command (paper 004's fixed-cost frames; the
//! replay of PresentMon captures).

use crate::components::distribution::Dist;
use crate::engine::{Duration, StreamRng, Time};

use super::super::config::FramesWorkload;
use super::super::records::FrameRecord;

/// A fixed workload's CPU and GPU time per frame: drawn from distributions
/// by the CPU thread (the GPU's when it issues the frame's one command), or
/// given frame by frame (a replayed capture, `kind = "frames"`).
#[derive(Debug)]
pub enum FixedWork {
    /// Drawn each frame (`kind = "fixed"`).
    Drawn {
        /// CPU time.
        cpu: Dist<Duration>,
        /// GPU time.
        gpu: Dist<Duration>,
        /// Stream for the CPU part.
        cpu_rng: StreamRng,
        /// Stream for the GPU part.
        gpu_rng: StreamRng,
    },
    /// Given frame by frame (`kind = "frames"`; every list holds at least
    /// `run.frames` entries, checked by the model's validation).
    PerFrame(FramesWorkload),
}

impl FixedWork {
    /// CPU time after the frame's clear is pushed, before its GPU work is
    /// (none for a frame given frame by frame: its GPU work, clear
    /// included, is submitted together, [`FixedWork::before_clear`]).
    pub(super) fn before_submit(&mut self) -> Duration {
        match self {
            FixedWork::Drawn { cpu, cpu_rng, .. } => Duration::from_ps_f64(cpu.sample(cpu_rng)),
            FixedWork::PerFrame(_) => Duration::ZERO,
        }
    }

    /// CPU time of frame `f` before its clear is pushed (a frame given frame
    /// by frame: its work up to the GPU submission).
    pub(super) fn before_clear(&self, f: u64) -> Duration {
        match self {
            FixedWork::Drawn { .. } => Duration::ZERO,
            FixedWork::PerFrame(w) => w.submit[f as usize],
        }
    }

    /// GPU time of frame `f`.
    pub(super) fn gpu(&mut self, f: u64) -> Duration {
        match self {
            FixedWork::Drawn { gpu, gpu_rng, .. } => Duration::from_ps_f64(gpu.sample(gpu_rng)),
            FixedWork::PerFrame(w) => w.gpu[f as usize],
        }
    }

    /// CPU time of frame `f` after its GPU work is submitted, up to its
    /// present (none for a drawn workload).
    pub(super) fn after_submit(&self, f: u64) -> Duration {
        match self {
            FixedWork::Drawn { .. } => Duration::ZERO,
            FixedWork::PerFrame(w) => Duration(w.cpu[f as usize].0.saturating_sub(w.submit[f as usize].0)),
        }
    }

    /// When frame `f` may begin: the previous frame's present plus the time
    /// in its present call, or the workload's start for frame 0 (`None`: at
    /// once, as for a drawn workload).
    pub(super) fn begins_at(&self, f: u64, records: &[FrameRecord]) -> Option<Time> {
        let FixedWork::PerFrame(w) = self else {
            return None;
        };
        let at = match f {
            0 => Time::ZERO.0.saturating_add(w.start.0),
            _ => records[f as usize - 1]
                .present
                .0
                .saturating_add(w.present[f as usize - 1].0),
        };
        Some(Time(at))
    }
}
