//! Reusable parts that systems compose: distributions, vertex caches, bounded
//! FIFOs, swap chains, the desktop compositor, tearing, frame pacing (limiters, low-latency pacers), frame generation,
//! system-task noise, preemptible processors, a unified shader-core pool, a
//! bus shared by copies and vertex fetch, and state-time accounting.

pub mod compositor;
pub mod distribution;
pub mod fifo;
pub mod frame_generation;
pub mod frame_pacing;
pub mod lod_select;
pub mod noise;
pub mod preemptible;
pub mod shader_pool;
pub mod shared_bus;
pub mod sorting_buffer;
pub mod state_clock;
pub mod swap_chain;
pub mod tearing;
pub mod vertex_cache;
