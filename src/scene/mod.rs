//! Workloads: meshes, mesh generators, OBJ/index files, synthetic scenes.

pub mod generators;
pub mod mesh;
pub mod optimize;
