//! The frame pipeline's events (paper 000 §3-4 and Figure 4; paper 004
//! §4.2): the ends of the CPU thread's operations and of the front end's
//! commands, the geometry and fragment stages' triangles (`triangle`
//! fidelity) or a draw's closed form (`draw` fidelity), the display's
//! vertical blanks (or a variable-refresh panel's scan-outs), the system
//! tasks' arrivals and ends, and the waits of pacing and of a replayed
//! capture. Each unit
//! schedules its own; [`super::model::FramePipeline`] dispatches them.

use crate::components::noise::NoiseTarget;
use crate::engine::EventKind;

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
    /// Vertical blank (when composed, the compositor's wake after it, where
    /// it takes the newest ready frame); with variable refresh, the end of a scan-out or the
    /// slowest refresh's deadline (the tag tells the one pending event from
    /// stale ones; always 0 at a fixed refresh).
    Vblank {
        /// Generation tag.
        tag: u32,
    },
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
    /// A frame limiter's or the low-latency pacer's wait ends
    /// (`[pacing]`; scheduled only when pacing holds the CPU).
    PaceWake,
    /// A replayed frame's present call returns after the time the capture
    /// measured in it (`kind = "frames"` only).
    PresentReturn,
    /// The GPU reaches a replayed frame's measured end (`kind = "frames"`
    /// with `gpu_end` only): its swap may finish.
    GpuHoldEnd,
    /// Frame generation's present thread's next present is due (the tag
    /// tells the one pending event from stale ones).
    HeldPresent {
        /// Generation tag.
        tag: u32,
    },
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
        "pacing_wake",
        "present_return",
        "gpu_hold_end",
        "held_present",
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
            Ev::Vblank { .. } => 7,
            Ev::NoiseArrive { .. } => 8,
            Ev::NoiseEnd { .. } => 9,
            Ev::ZeroTimeFrame => 10,
            Ev::PaceWake => 11,
            Ev::PresentReturn => 12,
            Ev::GpuHoldEnd => 13,
            Ev::HeldPresent { .. } => 14,
        }
    }
}
