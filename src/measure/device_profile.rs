//! A device profile: the costs of one GPU fitted to measured passes by
//! `rendersim calibrate` (`calibrate.rs`) and run by `rendersim predict`
//! (`predict.rs`). Stored as TOML under `models/devices/`. The cost of a
//! pass (all times in nanoseconds; V vertex-shader invocations, Lv and Lf the
//! vertex and fragment loop counts, T triangles covering a pixel, P target
//! pixels, F fragments, Q quads, W warps from `coverage.rs`):
//!
//! ```text
//! geometry  G = V (vertex + vertex_per_loop Lv) + vertex_loop_latency Lv + triangle T
//! lanes     = F + helper_lane_weight (4Q - F) + warp_waste_weight (32W - 4Q)
//! fragments R = lanes (lane + lane_per_loop Lf) + fragment_loop_latency Lf
//! pass      = pass_overhead + max(clear_store_per_pixel P, G) + R
//! ```
//!
//! The loop latencies are the occupancy floor (a loop iteration cannot take
//! less than its dependent-instruction latency however few warps run); the
//! lane weights say how much of a lane wasted on a helper pixel or on a
//! partly filled warp costs; clearing and storing the target overlaps the
//! geometry work (the H200's geometry-only passes at 2048x2048 cost the
//! same 0.603 ms under any vertex load up to it).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::coverage::{Coverage, WARP_QUADS};

/// Fitted costs, nanoseconds (weights dimensionless, in [0, 1]).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeviceCosts {
    /// Fixed cost of a render pass.
    pub pass_overhead_ns: f64,
    /// Clearing and storing one target pixel (overlaps the geometry work).
    pub clear_store_per_pixel_ns: f64,
    /// One vertex-shader invocation with no loop.
    pub vertex_ns: f64,
    /// One vertex-shader loop iteration of one invocation.
    pub vertex_per_loop_ns: f64,
    /// One vertex loop iteration of the whole pass (latency floor).
    pub vertex_loop_latency_ns: f64,
    /// Setup and rasterization of one triangle that covers a pixel.
    pub triangle_ns: f64,
    /// One fragment-shader lane with no loop.
    pub lane_ns: f64,
    /// One fragment loop iteration of one lane.
    pub lane_per_loop_ns: f64,
    /// One fragment loop iteration of the whole pass (latency floor).
    pub fragment_loop_latency_ns: f64,
    /// Share of a helper lane's cost (quad pixels not covered).
    pub helper_lane_weight: f64,
    /// Share of an empty warp lane's cost (warps packed below 32 lanes).
    pub warp_waste_weight: f64,
}

/// The structural part of a profile: what is not fitted.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeviceInfo {
    /// Short name (`nvidia-h200`).
    pub name: String,
    /// Vertex-cache policy predicting vertex-shader invocations.
    pub vertex_cache: String,
    /// Shader cores of the unified pool (the H200's 132 SMs; the costs are
    /// for the whole pool, so this only shapes how the pool is shared).
    pub shader_cores: u32,
}

/// How well the fit reproduces its rows, relative errors in percent.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitAccuracy {
    /// Rows fitted.
    pub rows: usize,
    /// Median |error| over the fitted rows.
    pub median_pct: f64,
    /// 90th percentile |error|.
    pub p90_pct: f64,
    /// Worst |error|.
    pub worst_pct: f64,
    /// Median |error| of each row predicted by a fit without it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loo_median_pct: Option<f64>,
    /// 90th percentile of the leave-one-out |error|.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loo_p90_pct: Option<f64>,
}

/// A device profile file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeviceProfile {
    /// What is not fitted.
    pub device: DeviceInfo,
    /// The fitted costs.
    pub costs: DeviceCosts,
    /// Standard error of each fitted cost (same key), from the fit's
    /// covariance; the lane weights are found by a grid search and have none.
    #[serde(default)]
    pub uncertainty: BTreeMap<String, f64>,
    /// The fit's accuracy.
    pub fit: FitAccuracy,
}

/// Errors reading a profile.
#[derive(Debug, thiserror::Error)]
pub enum ProfileError {
    /// The file cannot be read.
    #[error("cannot read device profile {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// Not TOML of this shape.
    #[error("device profile {path}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// The parser's message (names the key).
        message: String,
    },
    /// A value out of range.
    #[error("device profile {path}: {key} = {value}: {why}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// The key.
        key: String,
        /// Its value.
        value: String,
        /// What it must be.
        why: &'static str,
    },
}

/// What a pass is made of, for the cost formula.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct PassLoad {
    /// Target pixels.
    pub pixels: f64,
    /// Vertex-shader invocations.
    pub vertices: f64,
    /// Vertex loop iterations.
    pub vs_loops: f64,
    /// Fragment loop iterations.
    pub fs_loops: f64,
    /// What the triangles cover (all zero for geometry-only passes).
    pub coverage: Coverage,
}

/// The terms of a pass's cost.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PassCost {
    /// Geometry work G, ns.
    pub geometry_ns: f64,
    /// Clearing and storing the target, ns.
    pub clear_ns: f64,
    /// Fragment work R, ns.
    pub fragment_ns: f64,
    /// Fragment lanes charged.
    pub lanes: f64,
    /// The pass, ns.
    pub pass_ns: f64,
}

impl PassLoad {
    /// Fragment lanes charged under the two weights.
    pub fn lanes(&self, helper: f64, waste: f64) -> f64 {
        let c = &self.coverage;
        let (f, q4, w32) = (
            c.fragments as f64,
            4.0 * c.quads as f64,
            f64::from(WARP_QUADS * 4) * c.warps as f64,
        );
        f + helper * (q4 - f) + waste * (w32 - q4)
    }
}

impl DeviceCosts {
    /// The cost of `load`.
    pub fn cost(&self, load: &PassLoad) -> PassCost {
        let geometry_ns = load.vertices * (self.vertex_ns + self.vertex_per_loop_ns * load.vs_loops)
            + self.vertex_loop_latency_ns * load.vs_loops
            + self.triangle_ns * load.coverage.triangles as f64;
        let lanes = load.lanes(self.helper_lane_weight, self.warp_waste_weight);
        let fragment_ns = if load.coverage.fragments > 0 {
            lanes * (self.lane_ns + self.lane_per_loop_ns * load.fs_loops)
                + self.fragment_loop_latency_ns * load.fs_loops
        } else {
            0.0
        };
        let clear_ns = self.clear_store_per_pixel_ns * load.pixels;
        PassCost {
            geometry_ns,
            clear_ns,
            fragment_ns,
            lanes,
            pass_ns: self.pass_overhead_ns + clear_ns.max(geometry_ns) + fragment_ns,
        }
    }

    /// `(key, value)` of every cost, in file order.
    pub fn entries(&self) -> [(&'static str, f64); 11] {
        [
            ("pass_overhead_ns", self.pass_overhead_ns),
            ("clear_store_per_pixel_ns", self.clear_store_per_pixel_ns),
            ("vertex_ns", self.vertex_ns),
            ("vertex_per_loop_ns", self.vertex_per_loop_ns),
            ("vertex_loop_latency_ns", self.vertex_loop_latency_ns),
            ("triangle_ns", self.triangle_ns),
            ("lane_ns", self.lane_ns),
            ("lane_per_loop_ns", self.lane_per_loop_ns),
            ("fragment_loop_latency_ns", self.fragment_loop_latency_ns),
            ("helper_lane_weight", self.helper_lane_weight),
            ("warp_waste_weight", self.warp_waste_weight),
        ]
    }
}

impl DeviceProfile {
    /// Reads and validates a profile file.
    pub fn read(path: &Path) -> Result<DeviceProfile, ProfileError> {
        let text = std::fs::read_to_string(path).map_err(|source| ProfileError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(&text, path)
    }

    /// Parses and validates profile text (`path` names it in errors).
    pub fn parse(text: &str, path: &Path) -> Result<DeviceProfile, ProfileError> {
        let p: DeviceProfile = toml::from_str(text).map_err(|e| ProfileError::Parse {
            path: path.to_path_buf(),
            message: e.to_string().trim_end().to_string(),
        })?;
        let bad = |key: &str, value: String, why| ProfileError::Invalid {
            path: path.to_path_buf(),
            key: key.to_string(),
            value,
            why,
        };
        for (key, v) in p.costs.entries() {
            if !v.is_finite() || v < 0.0 {
                return Err(bad(
                    &format!("costs.{key}"),
                    v.to_string(),
                    "must be a finite number >= 0",
                ));
            }
            if key.ends_with("_weight") && v > 1.0 {
                return Err(bad(&format!("costs.{key}"), v.to_string(), "must be in [0, 1]"));
            }
        }
        if p.device.shader_cores == 0 {
            return Err(bad("device.shader_cores", "0".into(), "must be at least 1"));
        }
        if let Err(e) = p
            .device
            .vertex_cache
            .parse::<crate::components::vertex_cache::CachePolicy>()
        {
            return Err(ProfileError::Invalid {
                path: path.to_path_buf(),
                key: "device.vertex_cache".into(),
                value: format!("{:?} ({e})", p.device.vertex_cache),
                why: "must be a vertex-cache policy",
            });
        }
        Ok(p)
    }

    /// The file text: `header` (comment lines, `# ` added) then the TOML.
    pub fn to_toml(&self, header: &[String]) -> String {
        let mut s: String = header.iter().map(|l| format!("# {l}\n")).collect();
        s.push('\n');
        s.push_str(&toml::to_string_pretty(self).unwrap_or_default());
        s
    }
}
