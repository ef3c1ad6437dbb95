//! The discrete-event kernel: integer-picosecond time, the `(time, sequence)`
//! ordered event queue, the run loop with per-kind counters and stop
//! conditions, and named RNG streams. It knows nothing of GPUs.
//!
//! This crate is rendersim's bottom layer: it depends on no other rendersim
//! crate, and can drive any discrete-event model on its own (see its
//! README and `examples/`).

#![warn(missing_docs)]

pub mod queue;
pub mod radix_heap;
pub mod rng;
pub mod sim;
pub mod time;

pub use queue::{EventQueue, QueueKind};
pub use rng::{RngStreams, StreamRng};
pub use sim::{Control, EngineError, EventKind, Limits, Model, RunStats, Scheduler, Slot, StopReason, run};
pub use time::{Duration, PS_PER_MS, PS_PER_NS, PS_PER_S, PS_PER_US, Time, TimeError};
