//! A walkthrough with rendering-time estimation (paper 000 §5-7): a scene of
//! objects with bounding spheres and LOD chains (presets after Table 5), a
//! recorded camera path, per frame view-cell PVS and frustum culling, the
//! estimators h1-h4 and per-object sampling (pos) with their cost, and the
//! frame drawn by the frame pipeline's GPU model (its real time recorded).
//! Table 6 compares the estimators' errors (`experiments/table6.toml`).
//!
//! - `config`: the model file (the frame pipeline's hardware sections, plus
//!   scene, camera, estimation, lod);
//! - `scene`: objects, prototypes, LOD chains, the presets;
//! - `camera`: the camera paths;
//! - `culling`: frustum, PVS, projections (α, γ, φ, pixels);
//! - `render`: one frame through the frame pipeline;
//! - `estimators`: h1-h4, their least-squares fit, the scores;
//! - `pos`: per-object sampling tables;
//! - `timing`: how preprocess renders are timed (time stamps or a CPU clock
//!   around a synchronising finish, §6.1-6.2);
//! - `view_cells`: view-cell sampling (vcs) and per-view-cell estimation
//!   (pvc), §5.1-5.2, compared in `experiments/view-cells.toml` (§7.3);
//! - `lod`: the level-of-detail policies (reactive, predictive) and
//!   paper 001's benefit;
//! - `branch`: paper 000 §6.4's conditional branch in the frame's GPU work;
//! - `perceived`: perceived speed per displayed refresh (Figure 6);
//! - `validate`: the model's checks serde cannot make;
//! - `preprocess`: the empty frame, the fit renders, the pos tables and the
//!   view-cell estimators, before the first frame;
//! - `run`, `summary`, `report`, `system`: the frames and the summary, the
//!   summary's structs, the report, the registry.

pub mod branch;
pub mod camera;
pub mod config;
pub mod culling;
pub mod estimators;
pub mod lod;
pub mod perceived;
pub mod pos;
mod preprocess;
pub mod render;
pub mod report;
pub mod run;
pub mod scene;
pub mod summary;
pub mod system;
pub mod timing;
mod validate;
pub mod view_cells;

pub use config::WalkthroughConfig;
pub use run::{WalkthroughRun, run_walkthrough};
