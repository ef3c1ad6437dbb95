//! A device profile: the costs of one GPU fitted to measured passes by
//! `rendersim calibrate` (`calibrate.rs`) and run by `rendersim predict`
//! (`device_predict.rs`). Stored as TOML under `models/devices/`. The cost
//! of a pass (all times in nanoseconds; V vertex-shader invocations, B the
//! vertex batches (warps of 32 lanes) the cache policy cuts, T triangles
//! drawn, Tc triangles covering a pixel centre, Lv and Lf the vertex and
//! fragment loop counts, P target pixels; from `coverage.rs`: F fragments,
//! H = 4Q - F helper lanes of the Q quads, E = 32W - 4Q empty lanes of the
//! W fragment warps):
//!
//! ```text
//! geometry  G = vertex V + triangle T + covered_triangle Tc
//!             + (vertex_loop_latency + vertex_lane_per_loop 32B) Lv
//! fragments R = fragment F + helper_lane H + empty_lane E
//!             + (fragment_per_loop F + helper_lane_per_loop H
//!                + empty_lane_per_loop E + fragment_loop_latency) Lf
//! pass      = pass_overhead + max(clear_store_per_pixel P, G) + R
//! ```
//!
//! Why this shape (fitted to the H200 passes of `docs/measurements`): a
//! loop iteration of a vertex warp costs the same however many of its 32
//! lanes hold a vertex, so the vertex loop cost follows the batches, not
//! the invocations (geometry-only passes of six meshes cost 0.48-0.50 ns
//! per batch lane and loop once there are a few batches per SM, and
//! 0.0106-0.0224 ns per invocation and loop); every drawn triangle pays
//! for setup and culling even when it covers no pixel (`grid:256x256` at
//! 64x64); and a fragment lane's cost at zero loops (rasterization, quad
//! packing, blending) and per loop iteration (shader issue) weigh helper
//! and empty lanes differently, so each has its own cost. The loop
//! latencies are the occupancy floor (an iteration cannot take less than
//! its dependent-instruction latency however few warps run); clearing and
//! storing the target overlaps the geometry work (the H200's geometry-only
//! passes at 2048x2048 cost the same 0.603 ms under any vertex load up to
//! it). Every cost is linear, so calibration is one non-negative least
//! squares fit per side of the max.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::coverage::{Coverage, WARP_QUADS};

/// Fitted costs, nanoseconds.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeviceCosts {
    /// Fixed cost of a render pass.
    pub pass_overhead_ns: f64,
    /// Clearing and storing one target pixel (overlaps the geometry work).
    pub clear_store_per_pixel_ns: f64,
    /// One vertex-shader invocation with no loop.
    pub vertex_ns: f64,
    /// Setup (and culling) of one drawn triangle.
    pub triangle_ns: f64,
    /// Rasterization of one triangle that covers a pixel centre.
    pub covered_triangle_ns: f64,
    /// One vertex loop iteration of the whole pass (latency floor).
    pub vertex_loop_latency_ns: f64,
    /// One loop iteration of one lane of a vertex batch (32 lanes a batch).
    pub vertex_lane_per_loop_ns: f64,
    /// One covered fragment with no loop.
    pub fragment_ns: f64,
    /// One helper lane (quad pixel not covered) with no loop.
    pub helper_lane_ns: f64,
    /// One empty lane of a fragment warp packed below 32 lanes, no loop.
    pub empty_lane_ns: f64,
    /// One loop iteration of one covered fragment.
    pub fragment_per_loop_ns: f64,
    /// One loop iteration of one helper lane.
    pub helper_lane_per_loop_ns: f64,
    /// One loop iteration of one empty warp lane.
    pub empty_lane_per_loop_ns: f64,
    /// One fragment loop iteration of the whole pass (latency floor).
    pub fragment_loop_latency_ns: f64,
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
    /// covariance (zero for a cost the fit pinned at zero).
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
    /// Vertex batches (warps of up to 32 vertices) the cache policy cuts.
    pub vertex_batches: f64,
    /// Triangles drawn (geometry-only passes too).
    pub triangles: f64,
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
    /// The part of R that does not depend on the loop count, ns.
    pub fragment_base_ns: f64,
    /// The pass, ns.
    pub pass_ns: f64,
}

/// Lanes of the fragment warps: covered, helper and empty.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FragmentLanes {
    /// Covered fragments F.
    pub covered: f64,
    /// Helper lanes H = 4Q - F.
    pub helper: f64,
    /// Empty lanes E = 32W - 4Q.
    pub empty: f64,
}

impl PassLoad {
    /// The fragment lanes of this pass.
    pub fn lanes(&self) -> FragmentLanes {
        let c = &self.coverage;
        let (f, q4, w32) = (
            c.fragments as f64,
            4.0 * c.quads as f64,
            f64::from(WARP_QUADS * 4) * c.warps as f64,
        );
        FragmentLanes {
            covered: f,
            helper: (q4 - f).max(0.0),
            empty: (w32 - q4).max(0.0),
        }
    }

    /// The regressors of the cost formula, in [`DeviceCosts::entries`]
    /// order, with the clear term (index 1) and the geometry terms (2..=6)
    /// as they enter `max(clear, G)`: the cost is
    /// `x[0] + max(x[1], sum x[2..=6]) + sum x[7..]`, each `x` times its cost.
    pub fn regressors(&self) -> [f64; COSTS] {
        let l = self.lanes();
        let frag = self.coverage.fragments > 0;
        let f = |v: f64| if frag { v } else { 0.0 };
        let lf = self.fs_loops;
        [
            1.0,
            self.pixels,
            self.vertices,
            self.triangles,
            self.coverage.triangles as f64,
            self.vs_loops,
            32.0 * self.vertex_batches * self.vs_loops,
            f(l.covered),
            f(l.helper),
            f(l.empty),
            f(l.covered * lf),
            f(l.helper * lf),
            f(l.empty * lf),
            f(lf),
        ]
    }
}

/// Number of fitted costs.
pub const COSTS: usize = 14;

impl DeviceCosts {
    /// The costs as an array, in [`DeviceCosts::entries`] order.
    pub fn to_array(&self) -> [f64; COSTS] {
        self.entries().map(|(_, v)| v)
    }

    /// Costs from an array in [`DeviceCosts::entries`] order.
    pub fn from_array(b: &[f64; COSTS]) -> DeviceCosts {
        DeviceCosts {
            pass_overhead_ns: b[0],
            clear_store_per_pixel_ns: b[1],
            vertex_ns: b[2],
            triangle_ns: b[3],
            covered_triangle_ns: b[4],
            vertex_loop_latency_ns: b[5],
            vertex_lane_per_loop_ns: b[6],
            fragment_ns: b[7],
            helper_lane_ns: b[8],
            empty_lane_ns: b[9],
            fragment_per_loop_ns: b[10],
            helper_lane_per_loop_ns: b[11],
            empty_lane_per_loop_ns: b[12],
            fragment_loop_latency_ns: b[13],
        }
    }

    /// The cost of `load`.
    pub fn cost(&self, load: &PassLoad) -> PassCost {
        let x = load.regressors();
        let b = self.to_array();
        let term = |i: usize| x[i] * b[i];
        let geometry_ns: f64 = (2..=6).map(term).sum();
        let fragment_base_ns: f64 = (7..=9).map(term).sum();
        let fragment_ns = fragment_base_ns + (10..COSTS).map(term).sum::<f64>();
        let clear_ns = term(1);
        PassCost {
            geometry_ns,
            clear_ns,
            fragment_ns,
            fragment_base_ns,
            pass_ns: self.pass_overhead_ns + clear_ns.max(geometry_ns) + fragment_ns,
        }
    }

    /// `(key, value)` of every cost, in file order.
    pub fn entries(&self) -> [(&'static str, f64); COSTS] {
        [
            ("pass_overhead_ns", self.pass_overhead_ns),
            ("clear_store_per_pixel_ns", self.clear_store_per_pixel_ns),
            ("vertex_ns", self.vertex_ns),
            ("triangle_ns", self.triangle_ns),
            ("covered_triangle_ns", self.covered_triangle_ns),
            ("vertex_loop_latency_ns", self.vertex_loop_latency_ns),
            ("vertex_lane_per_loop_ns", self.vertex_lane_per_loop_ns),
            ("fragment_ns", self.fragment_ns),
            ("helper_lane_ns", self.helper_lane_ns),
            ("empty_lane_ns", self.empty_lane_ns),
            ("fragment_per_loop_ns", self.fragment_per_loop_ns),
            ("helper_lane_per_loop_ns", self.helper_lane_per_loop_ns),
            ("empty_lane_per_loop_ns", self.empty_lane_per_loop_ns),
            ("fragment_loop_latency_ns", self.fragment_loop_latency_ns),
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
