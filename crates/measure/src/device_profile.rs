//! A device profile: the costs of one GPU fitted to measured passes by
//! `rendersim calibrate` (`calibrate.rs`) and run by `rendersim predict`
//! (`device_predict.rs`). Stored as TOML under `models/devices/`. The cost
//! of a pass (all times in nanoseconds; D draw calls, V vertex-shader
//! invocations, B the
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
//! pass      = pass_overhead + draw D + max(clear_store_per_pixel P, G) + R
//!             - shared_core_overlap Gl R / (Gl + R)
//!   with Gl the loop part of G: (vertex_loop_latency + vertex_lane_per_loop 32B) Lv
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
//! it). Vertex and fragment work share the shader cores, so the pass is
//! close to their sum, not their maximum, but not quite the sum: the
//! H200's heavy vertex and heavy fragment loads together (67,390 and 7,681
//! loop iterations) take 40.3 ms against 18.8 + 22.8 ms apart. The last
//! term takes that overlap off: a fraction `shared_core_overlap` (0 to 1)
//! of `Gl R / (Gl + R)`, which is 0 when either side is absent, about the
//! smaller side when one dominates, and half of either when they are equal.
//! Only the vertex shader's loop work enters it (the work that occupies the
//! shader cores); fitted on the H200 rows, an overlap of the loop parts of
//! both sides came out at 0, and one of the whole of G predicted whole meshes
//! held out less well. Every cost but the overlap is linear, so calibration
//! is a non-negative least squares fit per side of the max, with the
//! overlap's `Gl R / (Gl + R)` taken from the previous fit until it settles.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::coverage::{Coverage, WARP_QUADS};

/// The fewest rows `rendersim calibrate` fits a profile to (and a
/// profile's `fit.rows` may say).
pub const MIN_ROWS: usize = 12;

/// Largest cost a profile may give one unit of work (a pass, a draw, a
/// vertex, a pixel): one second. Fitted costs are nanoseconds to
/// microseconds; the bound keeps a prediction (costs times counts of up to
/// 2^28 vertices and 2^28 pixels) finite.
pub const MAX_COST_NS: f64 = 1e9;

/// Fitted costs, nanoseconds.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeviceCosts {
    /// Fixed cost of a render pass.
    pub pass_overhead_ns: f64,
    /// Fixed cost of a draw call (0 when absent, as in profiles written
    /// before it; rows of one draw a pass cannot tell it from the pass's).
    #[serde(default)]
    pub draw_ns: f64,
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
    /// Fraction (0 to 1) of `Gl R / (Gl + R)` (Gl the vertex loop work) by
    /// which vertex and fragment work on the shared cores overlap (not a time; 0 when absent, as in
    /// profiles written before it). At 1 a pass is never shorter than the
    /// larger of G and R.
    #[serde(default)]
    pub shared_core_overlap: f64,
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

impl DeviceInfo {
    /// Whether an adapter of this name is the profile's device: every word
    /// of the profile's short name (letters and digits, any case) is a word
    /// of the adapter's name.
    ///
    /// ```
    /// use rendersim_measure::device_profile::DeviceInfo;
    ///
    /// let h200 = DeviceInfo { name: "nvidia-h200".into(), vertex_cache: "nvidia".into(), shader_cores: 132 };
    /// assert!(h200.matches_adapter("NVIDIA H200"));
    /// assert!(!h200.matches_adapter("llvmpipe (LLVM 15.0.7, 256 bits)"));
    /// ```
    pub fn matches_adapter(&self, adapter: &str) -> bool {
        let words = |s: &str| -> Vec<String> {
            s.to_lowercase()
                .split(|c: char| !c.is_ascii_alphanumeric())
                .filter(|w| !w.is_empty())
                .map(str::to_string)
                .collect()
        };
        let have = words(adapter);
        let want = words(&self.name);
        !want.is_empty() && want.iter().all(|w| have.contains(w))
    }
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
    /// Median |error| of k-fold cross-validation by mesh (whole meshes
    /// held out: what a new user's pass is).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kfold_median_pct: Option<f64>,
    /// 90th percentile of the k-fold |error|.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kfold_p90_pct: Option<f64>,
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
    /// Not TOML of this shape, or a value out of range: names the file,
    /// the line and the key (the model files' machinery, `config::load`).
    #[error(transparent)]
    Config(#[from] crate::config::ConfigError),
    /// A profile value out of range (a profile not read from a file).
    #[error("device profile: {key} = {value}: {why}")]
    Invalid {
        /// The key.
        key: String,
        /// Its value.
        value: String,
        /// What it must be.
        why: String,
    },
}

/// Most shader cores a profile may give (as `gpu.shader_cores`).
pub const MAX_SHADER_CORES: u32 = 1 << 20;

/// What a pass is made of, for the cost formula.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct PassLoad {
    /// Target pixels.
    pub pixels: f64,
    /// Draw calls (0: the pass only clears and stores its target).
    pub draws: f64,
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
    /// The vertex loop part of G (Gl), ns.
    pub vertex_loop_ns: f64,
    /// What vertex loop and fragment work overlap on the shared cores, ns
    /// (taken off the pass).
    pub overlap_ns: f64,
    /// The draw calls' fixed costs, ns.
    pub draws_ns: f64,
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
    /// `x[0] + max(x[1], sum x[2..=6]) + sum x[7..]` (R is 7..=13, the
    /// draws 14), each `x` times its cost, less the overlap.
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
            self.draws,
        ]
    }
}

/// Number of linear costs (every fitted value but the overlap).
pub const COSTS: usize = 15;

/// Number of fitted values: the linear costs and `shared_core_overlap`.
pub const FITTED: usize = COSTS + 1;

/// `Gl R / (Gl + R)`: the work the overlap term scales (0 when both are
/// 0), from the vertex loop work Gl and the fragment work R.
pub fn shared_work(vertex_loop_ns: f64, fragment_ns: f64) -> f64 {
    let sum = vertex_loop_ns + fragment_ns;
    if sum > 0.0 {
        vertex_loop_ns * fragment_ns / sum
    } else {
        0.0
    }
}

impl DeviceCosts {
    /// The linear costs as an array, in [`DeviceCosts::entries`] order.
    pub fn to_array(&self) -> [f64; COSTS] {
        let e = self.entries();
        std::array::from_fn(|i| e[i].1)
    }

    /// Linear costs from an array in [`DeviceCosts::entries`] order, no
    /// overlap.
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
            draw_ns: b[14],
            shared_core_overlap: 0.0,
        }
    }

    /// The cost of `load`.
    pub fn cost(&self, load: &PassLoad) -> PassCost {
        let x = load.regressors();
        let b = self.to_array();
        let term = |i: usize| x[i] * b[i];
        let geometry_ns: f64 = (2..=6).map(term).sum();
        let fragment_base_ns: f64 = (7..=9).map(term).sum();
        let fragment_ns = fragment_base_ns + (10..=13).map(term).sum::<f64>();
        let draws_ns = term(14);
        let clear_ns = term(1);
        let vertex_loop_ns = term(5) + term(6);
        let overlap_ns = self.shared_core_overlap * shared_work(vertex_loop_ns, fragment_ns);
        PassCost {
            geometry_ns,
            clear_ns,
            fragment_ns,
            fragment_base_ns,
            vertex_loop_ns,
            overlap_ns,
            draws_ns,
            pass_ns: self.pass_overhead_ns + draws_ns + clear_ns.max(geometry_ns) + fragment_ns - overlap_ns,
        }
    }

    /// `(key, value)` of every fitted value, in file order: the linear
    /// costs ([`COSTS`] of them), then `shared_core_overlap`.
    pub fn entries(&self) -> [(&'static str, f64); FITTED] {
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
            ("draw_ns", self.draw_ns),
            ("shared_core_overlap", self.shared_core_overlap),
        ]
    }
}

impl DeviceProfile {
    /// Reads and validates a profile file.
    pub fn read(path: &Path) -> Result<DeviceProfile, ProfileError> {
        let text = crate::limits::read_input_string(path, crate::limits::InputKind::Text).map_err(|source| {
            ProfileError::Io {
                path: path.to_path_buf(),
                source,
            }
        })?;
        Self::parse(&text, path)
    }

    /// Parses and validates profile text (`path` names it in errors): every
    /// error names the file, the line and the key.
    pub fn parse(text: &str, path: &Path) -> Result<DeviceProfile, ProfileError> {
        let src = crate::config::ModelSource::from_text(&path.display().to_string(), text);
        let table = src.table()?;
        let p: DeviceProfile = crate::config::deserialize(&table, &src)?;
        if let Err(ProfileError::Invalid { key, value, why }) = p.validate() {
            return Err(crate::config::invalid(&src, &key, format!("{value}: {why}"), None).into());
        }
        Ok(p)
    }

    /// The checks every profile keeps, read ([`DeviceProfile::parse`]) or
    /// about to be written (`rendersim calibrate`): a known vertex-cache
    /// policy; 1 to [`MAX_SHADER_CORES`] shader cores; every cost finite and
    /// non-negative, the linear ones not all zero (such a profile predicts
    /// 0 ns for every pass), the overlap at most 1; standard errors only of costs, finite and non-negative;
    /// at least [`MIN_ROWS`] rows; the error statistics
    /// finite, non-negative and ordered (median <= 90th percentile <=
    /// worst). The error is [`ProfileError::Invalid`] naming the key.
    pub fn validate(&self) -> Result<(), ProfileError> {
        let bad = |key: &str, value: String, why: &str| {
            Err(ProfileError::Invalid {
                key: key.to_string(),
                value,
                why: why.to_string(),
            })
        };
        if let Err(e) = self
            .device
            .vertex_cache
            .parse::<crate::components::vertex_cache::CachePolicy>()
        {
            return bad(
                "device.vertex_cache",
                format!("{:?}", self.device.vertex_cache),
                &format!("must be a vertex-cache policy ({e})"),
            );
        }
        let cores = self.device.shader_cores;
        if !(1..=MAX_SHADER_CORES).contains(&cores) {
            return bad(
                "device.shader_cores",
                cores.to_string(),
                &format!("must be between 1 and {MAX_SHADER_CORES}"),
            );
        }
        for (key, v) in self.costs.entries() {
            if !v.is_finite() || v < 0.0 {
                return bad(&format!("costs.{key}"), v.to_string(), "must be a finite number >= 0");
            }
            if v > MAX_COST_NS {
                return bad(
                    &format!("costs.{key}"),
                    format!("{v:e}"),
                    "is more than a second (1e9 ns) per unit of work; no device is that slow, and a \
                     prediction with it would overflow",
                );
            }
        }
        let overlap = self.costs.shared_core_overlap;
        if overlap > 1.0 {
            return bad(
                "costs.shared_core_overlap",
                overlap.to_string(),
                "must be at most 1 (beyond it a pass would take less than the larger of its vertex and \
                 fragment work)",
            );
        }
        if self.costs.to_array().iter().all(|v| *v == 0.0) {
            return bad(
                "costs",
                "0 for every cost".into(),
                "such a profile predicts 0 ns for every pass; at least one cost must be above 0",
            );
        }
        let keys = self.costs.entries().map(|(k, _)| k);
        for (key, v) in &self.uncertainty {
            if !keys.contains(&key.as_str()) {
                return bad(
                    &format!("uncertainty.{key}"),
                    v.to_string(),
                    "is no cost key; standard errors are given per cost (the keys of [costs])",
                );
            }
            if !v.is_finite() || *v < 0.0 {
                return bad(
                    &format!("uncertainty.{key}"),
                    v.to_string(),
                    "must be a finite number >= 0",
                );
            }
        }
        let f = &self.fit;
        let min_rows = MIN_ROWS;
        if f.rows < min_rows {
            return bad(
                "fit.rows",
                f.rows.to_string(),
                &format!("a profile is fitted to at least {min_rows} rows"),
            );
        }
        let stats = [
            ("fit.median_pct", Some(f.median_pct)),
            ("fit.p90_pct", Some(f.p90_pct)),
            ("fit.worst_pct", Some(f.worst_pct)),
            ("fit.loo_median_pct", f.loo_median_pct),
            ("fit.loo_p90_pct", f.loo_p90_pct),
        ];
        for (key, v) in stats {
            if let Some(v) = v
                && (!v.is_finite() || v < 0.0)
            {
                return bad(key, v.to_string(), "must be a finite percentage >= 0");
            }
        }
        if f.p90_pct < f.median_pct {
            return bad(
                "fit.p90_pct",
                f.p90_pct.to_string(),
                "must not be below fit.median_pct (a 90th percentile is at least the median)",
            );
        }
        if f.worst_pct < f.p90_pct {
            return bad(
                "fit.worst_pct",
                f.worst_pct.to_string(),
                "must not be below fit.p90_pct (the worst error is at least the 90th percentile)",
            );
        }
        if let (Some(m), Some(p)) = (f.loo_median_pct, f.loo_p90_pct)
            && p < m
        {
            return bad("fit.loo_p90_pct", p.to_string(), "must not be below fit.loo_median_pct");
        }
        Ok(())
    }

    /// The file text: `header` (comment lines, `# ` added) then the TOML.
    /// Control characters in `header` (a newline in a `--name`) are
    /// written escaped (`\n`), so each header line stays one comment line;
    /// the values are TOML-escaped, so [`DeviceProfile::parse`] reads back
    /// what was written.
    pub fn to_toml(&self, header: &[String]) -> String {
        let comment = |l: &String| -> String {
            l.chars()
                .map(|c| {
                    if c.is_control() {
                        c.escape_default().collect()
                    } else {
                        c.to_string()
                    }
                })
                .collect()
        };
        let mut s: String = header.iter().map(|l| format!("# {}\n", comment(l))).collect();
        s.push('\n');
        s.push_str(&toml::to_string_pretty(self).unwrap_or_default());
        s
    }
}

#[cfg(test)]
mod tests;
