//! Reusable parts that simulated systems are composed from.

pub mod distribution;
pub mod vertex_cache;
