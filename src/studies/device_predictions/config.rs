//! The `device_predictions` model file:
//!
//! ```toml
//! system = "device_predictions"
//! device = "nvidia-h200"               # the name in the report
//! files = ["../../docs/measurements/nvidia-h200/load-grid.csv"]   # relative to this file
//! vertex_cache = "nvidia"              # the device's vertex-reuse policy
//! shader_cores = 132                   # default 132
//!
//! [sum_vs_max]                         # optional: study H2's four cells
//! mesh = "grid:96x96:optimized"
//! size = "384x384"
//! vs_loops = 67390                     # the heavy loads (the light ones are 0)
//! fs_loops = 7681
//! measured = 0.940                     # the study's measured ratio, when known
//! ```

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

/// The whole model.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DevicePredictionsConfig {
    /// Always `"device_predictions"`.
    pub system: String,
    /// A one-line description.
    #[serde(default)]
    pub description: String,
    /// The device's name (the report's title).
    pub device: String,
    /// Measured pass CSVs (`rendersim measure --csv`'s format), relative to
    /// the model file.
    pub files: Vec<PathBuf>,
    /// The vertex-cache policy that predicts the device's vertex-shader
    /// invocations (`rendersim vcache --policy`'s names).
    pub vertex_cache: String,
    /// Shader cores of the unified pool.
    #[serde(default = "default_cores")]
    pub shader_cores: u32,
    /// Seed (experiments set it; the fit and the simulations are
    /// deterministic, so it changes nothing).
    #[serde(default)]
    pub run: RunConfig,
    /// Study H2's cells, whose sum-against-max ratio the profile predicts
    /// (`metrics.sum_vs_max`).
    #[serde(default)]
    pub sum_vs_max: Option<super::sum_vs_max::SumVsMaxConfig>,
}

/// `[run]`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunConfig {
    /// Unused (see [`DevicePredictionsConfig::run`]).
    #[serde(default)]
    pub seed: u64,
}

fn default_cores() -> u32 {
    132
}
