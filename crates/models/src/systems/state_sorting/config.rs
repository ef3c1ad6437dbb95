//! The `state_sorting` model file:
//!
//! ```toml
//! system = "state_sorting"
//! sequence = "lru-worst:8"     # a file of ids, lru-worst:M, or scene:MODEL.toml[:state|shader|texture|material]
//! buffer = 65                  # slots K
//! strategies = ["lru", "bounded-waste", "random", "round-robin"]   # default: all four
//! [run]
//! seed = 1                     # the random strategy's stream
//! ```
//!
//! Relative paths (a sequence file, a scene's model) are relative to the
//! model file.

use serde::{Deserialize, Serialize};

/// The whole model.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StateSortingConfig {
    /// Always `"state_sorting"`.
    pub system: String,
    /// A one-line description.
    #[serde(default)]
    pub description: String,
    /// Where the state ids come from.
    pub sequence: String,
    /// Buffer slots K.
    pub buffer: usize,
    /// Strategies to run (names as `rendersim sortbuf --strategy`).
    #[serde(default = "all_strategies")]
    pub strategies: Vec<String>,
    /// `[run]`.
    #[serde(default)]
    pub run: RunConfig,
}

/// `[run]`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunConfig {
    /// Master seed of the random strategy's stream.
    #[serde(default)]
    pub seed: u64,
}

fn all_strategies() -> Vec<String> {
    ["lru", "bounded-waste", "random", "round-robin"]
        .map(String::from)
        .to_vec()
}
