//! The states each unit's time is split into, by name, as `summary.json`
//! (`states_ms`) and the trace write them, and the names of the units a
//! bottleneck share is counted for. Accounting
//! ([`super::accounting`]) indexes into these lists; the summary and the
//! trace name what it counted.

/// CPU states.
pub const CPU_STATES: [&str; 9] = [
    "work",
    "system task",
    "wait: command FIFO full",
    "wait: frames in flight",
    "idle",
    "wait: pacing before a frame",
    "wait: frame limiter before present",
    "wait: in the present call",
    "wait: frame limiter before GPU submission",
];
/// GPU front-end states.
pub const FRONT_STATES: [&str; 6] = [
    "busy",
    "starved",
    "wait: swap image",
    "wait: pipeline drain",
    "wait: geometry",
    "system task",
];
/// The front end's state (index into [`FRONT_STATES`]) while a draw waits
/// for the geometry stage.
pub const FRONT_WAIT_GEOMETRY: usize = 4;
/// Geometry-stage states.
pub const GEOM_STATES: [&str; 3] = ["busy", "blocked: triangle FIFO full", "idle"];
/// Fragment-stage states.
pub const FRAG_STATES: [&str; 2] = ["busy", "idle"];
/// Bottleneck units.
pub const BOTTLENECKS: [&str; 6] = ["cpu", "system", "gpu_front_end", "geometry", "fragment", "display"];
