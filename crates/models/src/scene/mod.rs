//! Workloads: scene descriptions, meshes, mesh generators, OBJ/index files,
//! a vertex-cache optimizer, and synthetic scenes after paper 000 Table 5.

pub mod config;
pub mod generators;
pub mod mesh;
pub mod obj;
pub mod optimize;
pub mod presets;
pub mod states;
