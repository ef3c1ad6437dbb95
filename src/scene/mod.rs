//! Workloads: meshes, mesh generators, OBJ/index files, synthetic scenes.

pub mod mesh;
