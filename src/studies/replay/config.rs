//! The `replay` model file: a capture replayed as captured and under one
//! what-if, as a system an experiment can sweep:
//!
//! ```toml
//! system = "replay"
//! capture = "../tests/fixtures/presentmon/test_case_0.csv"   # relative to this file
//! app = "dwm.exe"               # optional: the process (its swap chain with most frames)
//! swapchain = "0x1B1B8F32850"   # optional: the swap chain's address
//!
//! [assume]                      # optional: what the capture does not say (patches on
//! display.buffers = 2           # the as-captured model, before the what-if)
//!
//! compare = "measured.csv"     # optional: a capture measured under the what-if,
//!                               # its figures beside the prediction (`replay.compare`)
//!
//! [whatif]                      # patches on models/replay.toml (none: as captured)
//! cpu.max_frames_ahead = 1
//! display.present_mode = "mailbox"
//! ```

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

/// The whole model.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReplayConfig {
    /// Always `"replay"`.
    pub system: String,
    /// A one-line description.
    #[serde(default)]
    pub description: String,
    /// The PresentMon CSV, relative to the model file.
    pub capture: PathBuf,
    /// The process whose swap chain to replay.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub app: Option<String>,
    /// The swap chain's address.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub swapchain: Option<String>,
    /// What the capture does not say (swap-chain images, frames in flight,
    /// the refresh): keys of the replay's frame-pipeline model patched on
    /// the replay as captured, nested as in a model file.
    #[serde(default, skip_serializing_if = "toml::Table::is_empty")]
    pub assume: toml::Table,
    /// A capture of the same game measured under the what-if's setting,
    /// relative to the model file: its figures go beside the prediction
    /// (`replay.compare`, as `rendersim replay --compare` gives them).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compare: Option<PathBuf>,
    /// The what-if: keys of the replay's frame-pipeline model
    /// (models/replay.toml) and their values, nested as in a model file.
    #[serde(default)]
    pub whatif: toml::Table,
    /// Seed (experiments set it; a replay is deterministic, so it changes
    /// nothing).
    #[serde(default)]
    pub run: RunConfig,
}

/// `[run]`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunConfig {
    /// Unused (see [`ReplayConfig::run`]).
    #[serde(default)]
    pub seed: u64,
}

/// A what-if or assumption table as `key=value` assignments (dotted keys,
/// TOML values), in key order.
pub fn whatif_sets(table: &toml::Table) -> Vec<String> {
    let mut pairs = Vec::new();
    crate::config::flatten("", table, &mut pairs);
    pairs.into_iter().map(|(k, v)| format!("{k}={v}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_nested_what_if_flattens_to_dotted_assignments() {
        let t: toml::Table = "cpu.max_frames_ahead = 1\n[display]\npresent_mode = \"mailbox\"\nrefresh = \"30Hz\""
            .parse()
            .unwrap();
        assert_eq!(
            whatif_sets(&t),
            [
                "cpu.max_frames_ahead=1",
                "display.present_mode=\"mailbox\"",
                "display.refresh=\"30Hz\""
            ]
        );
        assert!(whatif_sets(&toml::Table::new()).is_empty());
    }
}
