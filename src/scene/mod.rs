//! Workloads: meshes, generators, OBJ files, synthetic scenes.
pub mod config;
pub mod generators;
pub mod mesh;
pub mod presets;
