//! The `profile` study: a designed set of passes for `rendersim calibrate`,
//! measured in one process with the rounds interleaved, so that a device
//! profile is fitted (and its held-out half checked) on passes that span
//! every cost the profile has (`device_profile.rs`): meshes from a few
//! triangles to tens of thousands, in cache-friendly and shuffled orders and
//! with triangles from sub-pixel to a quarter of the screen; targets of one
//! to sixteen 64x64 tiles; light and heavy vertex and fragment loops, alone
//! and together; geometry-only passes; passes that only clear the target
//! (no draw) and meshes split into many draws.
//!
//! Why one process and interleaved rounds: on lavapipe (which runs on the
//! machine's CPU) the same pass measured by two `rendersim measure`
//! processes can differ by 40-70% (measured on the 2-core CI machine:
//! `grid:64x64` at 256x256 took 1.1 ms in one process and 2.1-2.2 ms in
//! five others), and within one process a slow spell of a few passes
//! would fall on one condition's rounds if they ran back to back. Here the
//! rounds run round 1 of every pass, then round 2, and the median of each
//! pass's rounds is its time (see [`Gpu::measure_interleaved`]).

use std::time::Instant;

use serde::Serialize;

use super::device::{Gpu, MeasureError, MeasureOptions, Measurement};
use super::fit::median;
use crate::scene::generators::mesh_from_spec;
use crate::scene::mesh::Mesh;

/// Interleaved rounds a profile pass is measured in unless told otherwise:
/// the design's passes are short and many, and 9 rounds keep the medians'
/// scatter on lavapipe below what CI's held-out check allows (5 rounds
/// reached a 90th percentile of 30.8% once in six runs; 9 stayed at 20-25%).
pub const DEFAULT_ROUNDS: u32 = 9;

/// The meshes of the design (specs as for `rendersim measure`).
pub const MESHES: [&str; 6] = [
    "grid:16x16",
    "grid:32x32",
    "strip:32x32",
    "grid:64x64:shuffled:1",
    "grid:96x96:optimized",
    "random:1000:300:7",
];

/// The render-target sizes (one, four and sixteen 64x64 tiles).
pub const SIZES: [(u32, u32); 3] = [(64, 64), (128, 128), (256, 256)];

/// The loads: vertex loops, fragment loops, geometry only.
pub const LOADS: [(u32, u32, bool); 7] = [
    (0, 0, false),
    (100, 0, false),
    (0, 30, false),
    (100, 30, false),
    (1000, 100, false),
    (100, 0, true),
    (1000, 0, true),
];

/// Draw counts of the split-draw passes (`grid:32x32`, no loops, each size):
/// 0 is a pass that only clears and stores its target.
pub const DRAWS: [u32; 3] = [0, 16, 256];

/// One measured pass of the design.
#[derive(Debug, Clone, Serialize)]
pub struct ProfilePass {
    /// Mesh spec.
    pub mesh: String,
    /// Target width and height.
    pub size: (u32, u32),
    /// Vertex-shader loops.
    pub vs_loops: u32,
    /// Fragment-shader loops.
    pub fs_loops: u32,
    /// Every vertex at one point (no fragments).
    pub geometry_only: bool,
    /// Draw calls.
    pub draws: u32,
    /// Median of the rounds, ns.
    pub median_ns: f64,
    /// Smallest and largest round, ns.
    pub range_ns: (f64, f64),
}

/// What the study measured.
#[derive(Debug, Clone, Serialize)]
pub struct ProfileStudy {
    /// Interleaved rounds per pass.
    pub rounds: u32,
    /// Every pass.
    pub passes: Vec<ProfilePass>,
    /// Median over the passes of (largest - smallest round) / median.
    pub median_spread: f64,
    /// Wall time, seconds.
    pub seconds: f64,
}

impl ProfileStudy {
    /// One line.
    pub fn verdict(&self) -> String {
        format!(
            "{} passes for `rendersim calibrate` ({} interleaved round{} each, the median kept; \
             a pass's rounds spread over {:.0}% of its median, the median pass)",
            self.passes.len(),
            self.rounds,
            if self.rounds == 1 { "" } else { "s" },
            self.median_spread * 100.0
        )
    }

    /// The Markdown section.
    pub fn markdown(&self) -> String {
        let mut s = format!(
            "## Profile passes\n\n{}.\n\n| mesh | size | vs loops | fs loops | geometry only | draws | median ms | rounds min-max ms |\n|---|---|---|---|---|---|---|---|\n",
            self.verdict()
        );
        for p in &self.passes {
            s += &format!(
                "| {} | {}x{} | {} | {} | {} | {} | {:.4} | {:.4}-{:.4} |\n",
                p.mesh,
                p.size.0,
                p.size.1,
                p.vs_loops,
                p.fs_loops,
                if p.geometry_only { "yes" } else { "" },
                p.draws,
                p.median_ns / 1e6,
                p.range_ns.0 / 1e6,
                p.range_ns.1 / 1e6
            );
        }
        s
    }
}

/// The design's conditions: (mesh index, options).
pub fn design() -> Vec<(usize, MeasureOptions)> {
    let mut v = Vec::new();
    for (i, _) in MESHES.iter().enumerate() {
        for &size in &SIZES {
            for &(vs_loops, fs_loops, geometry_only) in &LOADS {
                v.push((
                    i,
                    MeasureOptions {
                        size,
                        vs_loops,
                        fs_loops,
                        geometry_only,
                        warmup: 1,
                        ..MeasureOptions::default()
                    },
                ));
            }
        }
    }
    for &size in &SIZES {
        for &draws in &DRAWS {
            v.push((
                1,
                MeasureOptions {
                    size,
                    draws,
                    warmup: 1,
                    ..MeasureOptions::default()
                },
            ));
        }
    }
    v
}

/// A design mesh from its spec.
fn design_mesh(spec: &str) -> Result<Mesh, MeasureError> {
    mesh_from_spec(spec, std::path::Path::new(".")).map_err(|e| MeasureError::Option(format!("{spec}: {e}")))
}

/// Measures the design on `gpu`: each pass built once and warmed up once,
/// then `rounds` interleaved rounds ([`Gpu::measure_interleaved`]).
pub fn run_profile(gpu: &Gpu, rounds: u32) -> Result<ProfileStudy, MeasureError> {
    let t = Instant::now();
    let meshes: Vec<Mesh> = MESHES.iter().map(|s| design_mesh(s)).collect::<Result<_, _>>()?;
    let design = design();
    let conds: Vec<(&str, &Mesh, MeasureOptions)> = design
        .iter()
        .map(|(i, o)| (MESHES[*i], &meshes[*i], o.clone()))
        .collect();
    let measured: Vec<Measurement> = gpu.measure_interleaved(&conds, rounds)?;
    let passes: Vec<ProfilePass> = measured
        .iter()
        .zip(&design)
        .map(|(m, (i, o))| {
            let lo = m.pass_times_ns.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = m.pass_times_ns.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            ProfilePass {
                mesh: MESHES[*i].to_string(),
                size: o.size,
                vs_loops: o.vs_loops,
                fs_loops: o.fs_loops,
                geometry_only: o.geometry_only,
                draws: o.draws,
                median_ns: m.pass_time_ns,
                range_ns: (lo, hi),
            }
        })
        .collect();
    let spreads: Vec<f64> = passes
        .iter()
        .filter(|p| p.median_ns > 0.0)
        .map(|p| (p.range_ns.1 - p.range_ns.0) / p.median_ns)
        .collect();
    Ok(ProfileStudy {
        rounds,
        median_spread: median(&spreads).unwrap_or(0.0),
        passes,
        seconds: t.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    #[test]
    fn the_design_has_every_kind_of_pass_once() {
        let d = design();
        assert_eq!(
            d.len(),
            MESHES.len() * SIZES.len() * LOADS.len() + SIZES.len() * DRAWS.len()
        );
        assert_eq!(d.len(), 135);
        // No pass twice (the pass CSV pools equal passes into one row).
        let keys: BTreeSet<String> = d
            .iter()
            .map(|(i, o)| {
                format!(
                    "{} {:?} {} {} {} {}",
                    MESHES[*i], o.size, o.vs_loops, o.fs_loops, o.geometry_only, o.draws
                )
            })
            .collect();
        assert_eq!(keys.len(), d.len());
        // What the profile's costs need: passes that only clear, many
        // draws, geometry only, each loop alone and both together, and
        // every mesh at every size.
        assert!(d.iter().any(|(_, o)| o.draws == 0));
        assert!(d.iter().any(|(_, o)| o.draws == 256));
        assert!(d.iter().any(|(_, o)| o.geometry_only && o.vs_loops > 0));
        assert!(
            d.iter()
                .any(|(_, o)| o.vs_loops > 0 && o.fs_loops == 0 && !o.geometry_only)
        );
        assert!(d.iter().any(|(_, o)| o.vs_loops == 0 && o.fs_loops > 0));
        assert!(d.iter().any(|(_, o)| o.vs_loops > 0 && o.fs_loops > 0));
        for (i, _) in MESHES.iter().enumerate() {
            for s in SIZES {
                assert!(d.iter().any(|(j, o)| *j == i && o.size == s));
            }
        }
        // Every mesh spec builds, and one pass writes a pass-CSV row (one
        // layer, no depth test: the CSV has no column for either).
        for m in MESHES {
            design_mesh(m).unwrap();
        }
        assert!(d.iter().all(|(_, o)| o.layers == 1 && !o.depth_test));
    }
}
