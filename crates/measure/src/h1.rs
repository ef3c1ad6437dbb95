//! Study H1 (vertex reuse): identify the adapter's vertex-reuse policy from
//! probe meshes, then check that the fitted policy predicts the measured
//! vertex-shader invocations exactly on meshes not used for fitting.
//!
//! Probes: one triangle repeated k times (when is a repeated triangle
//! re-shaded?), a strip-like run of triangles over n vertices drawn twice
//! (how many vertices does the cache hold?), vertices 256 apart in the
//! same triangle (are slots chosen by index?), and rings of 15 and 16
//! vertices walked 8 times (is a vertex met again 41 or 44 indices later,
//! in the same batch, reused?). Candidates: direct-mapped caches with
//! periodic flushes, FIFO, LRU, meshoptimizer's profiles, hardware batches,
//! and batches that look back only a window of indices (`lookback:`). The
//! candidate with the least total error on the probes is chosen (ties: the
//! first listed).

use std::time::Instant;

use crate::components::vertex_cache::CachePolicy;
use crate::scene::generators::mesh_from_spec;
use crate::scene::mesh::{Mesh, Topology};

use super::device::{Gpu, MeasureError, MeasureOptions};

/// One mesh: measured and predicted vertex-shader invocations.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Row {
    /// Mesh name or spec.
    pub mesh: String,
    /// Indices drawn.
    pub indices: u64,
    /// Distinct vertices.
    pub unique_vertices: u64,
    /// Measured vertex-shader invocations.
    pub measured: u64,
    /// Predicted by the chosen policy.
    pub predicted: u64,
}

/// A candidate policy's total absolute error.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Candidate {
    /// Policy.
    pub policy: String,
    /// Sum of |predicted - measured| over the probes.
    pub probe_error: u64,
    /// Sum of |predicted - measured| over the validation meshes.
    pub validation_error: u64,
}

/// The study's result.
#[derive(Debug, Clone, serde::Serialize)]
pub struct H1 {
    /// Adapter name, driver, type.
    pub adapter: String,
    /// The chosen policy.
    pub chosen: String,
    /// Probes (used for fitting).
    pub probes: Vec<Row>,
    /// Validation meshes (not used for fitting).
    pub validation: Vec<Row>,
    /// Every candidate's errors.
    pub candidates: Vec<Candidate>,
    /// Whether the chosen policy predicts every validation mesh exactly.
    pub exact: bool,
    /// Seconds spent measuring.
    pub measure_seconds: f64,
    /// Seconds spent simulating all candidates on all meshes.
    pub simulate_seconds: f64,
}

fn list(name: &str, indices: Vec<u32>) -> (String, Mesh) {
    let vc = indices.iter().copied().max().map_or(1, |m| m + 1);
    (
        name.to_string(),
        Mesh {
            name: name.into(),
            topology: Topology::TriangleList,
            indices,
            vertex_count: vc,
        },
    )
}

fn probes() -> Vec<(String, Mesh)> {
    let mut v = Vec::new();
    for k in [1u32, 100, 341, 342, 683, 684, 1000] {
        v.push(list(
            &format!("triangle 0 1 2 repeated {k} times"),
            [0, 1, 2].repeat(k as usize),
        ));
    }
    for n in [64u32, 128, 200, 256, 257, 300, 600] {
        let once: Vec<u32> = (0..n - 2).flat_map(|i| [i, i + 1, i + 2]).collect();
        v.push(list(&format!("run over {n} vertices, drawn twice"), once.repeat(2)));
    }
    let conflict: Vec<u32> = (0..100u32).flat_map(|i| [i, i + 256, i + 512]).collect();
    v.push(list("vertices i, i+256, i+512, drawn twice", conflict.repeat(2)));
    let conflict128: Vec<u32> = (0..100u32).flat_map(|i| [i, i + 128, i + 1000]).collect();
    v.push(list("vertices i, i+128, i+1000, drawn twice", conflict128.repeat(2)));
    for n in [15u32, 16] {
        v.push(list(&format!("ring of {n} vertices walked 8 times"), ring(n, 8)));
    }
    v
}

/// Triangles (i, i+1, i+2) mod `n` for i in 0..n*`laps`: each vertex comes
/// back 3n - 4 indices after its last use, in the middle of a batch when n
/// is small.
fn ring(n: u32, laps: u32) -> Vec<u32> {
    (0..n * laps).flat_map(|i| [i % n, (i + 1) % n, (i + 2) % n]).collect()
}

const VALIDATION: &[&str] = &[
    "grid:16x16",
    "grid:33x17",
    "grid:64x64",
    "grid:100x40",
    "grid:64x64:shuffled:5",
    "grid:48x48:optimized",
    "strip:20x20",
    "random:3000:700:3",
];

fn candidates() -> Vec<CachePolicy> {
    // The named `lavapipe` policy is not a candidate: the fit must find its
    // parameters among the direct-mapped family on its own.
    let mut v = Vec::new();
    for slots in [64u32, 128, 256, 512] {
        for segment in [128u32, 170, 256, 341, 342, 512, 1024] {
            v.push(CachePolicy::Direct { slots, segment });
        }
    }
    for n in [16u32, 32, 64, 128, 256] {
        v.push(CachePolicy::Fifo(n));
        v.push(CachePolicy::Lru(n));
    }
    for (cache, warp, primgroup) in [(32, 32, 32), (16, 32, 32), (14, 64, 128), (128, 0, 0)] {
        v.push(CachePolicy::Meshopt { cache, warp, primgroup });
    }
    v.push(CachePolicy::Batch {
        vertices: 32,
        triangles: 32,
    });
    // Likewise not the named `nvidia` (`lookback:32,32,42`): the ring probes
    // must pick the window.
    for window in [16u32, 32, 42, 48, 64, 96] {
        v.push(CachePolicy::Lookback {
            vertices: 32,
            triangles: 32,
            window,
        });
    }
    v.push(CachePolicy::None);
    v
}

/// Runs the study on `gpu`.
pub fn h1(gpu: &Gpu, repeats: u32) -> Result<H1, MeasureError> {
    let opts = MeasureOptions {
        repeats,
        warmup: 1,
        size: (256, 256),
        ..MeasureOptions::default()
    };
    let t = Instant::now();
    let adapter = gpu.describe();
    let measure_all = |meshes: &[(String, Mesh)], spec_of: &dyn Fn(&str) -> String| -> Result<Vec<u64>, MeasureError> {
        meshes
            .iter()
            .map(|(name, m)| Ok(gpu.measure(m, &spec_of(name), &opts)?.vs_invocations))
            .collect()
    };
    let probe_meshes = probes();
    let probe_measured = measure_all(&probe_meshes, &|_| "probe".to_string())?;
    let val_meshes: Vec<(String, Mesh)> = VALIDATION
        .iter()
        .map(|s| mesh_from_spec(s, std::path::Path::new(".")).map(|m| (s.to_string(), m)))
        .collect::<Result<_, _>>()
        .map_err(|e| MeasureError::Option(e.to_string()))?;
    let val_measured = measure_all(&val_meshes, &|name| name.to_string())?;
    let measure_seconds = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let err = |p: &CachePolicy, meshes: &[(String, Mesh)], measured: &[u64]| -> (u64, Vec<u64>) {
        let preds: Vec<u64> = meshes.iter().map(|(_, m)| m.cache_stats(p).transformed).collect();
        (preds.iter().zip(measured).map(|(a, b)| a.abs_diff(*b)).sum(), preds)
    };
    let mut cands = Vec::new();
    let mut best: Option<(u64, CachePolicy)> = None;
    for p in candidates() {
        let (pe, _) = err(&p, &probe_meshes, &probe_measured);
        let (ve, _) = err(&p, &val_meshes, &val_measured);
        cands.push(Candidate {
            policy: p.to_string(),
            probe_error: pe,
            validation_error: ve,
        });
        if best.as_ref().is_none_or(|b| pe < b.0) {
            best = Some((pe, p));
        }
    }
    let chosen = best.map(|b| b.1).unwrap_or(CachePolicy::None);
    let rows = |meshes: &[(String, Mesh)], measured: &[u64]| -> Vec<Row> {
        let (_, preds) = err(&chosen, meshes, measured);
        meshes
            .iter()
            .zip(measured.iter().zip(preds))
            .map(|((name, m), (meas, pred))| Row {
                mesh: name.clone(),
                indices: m.index_count(),
                unique_vertices: m.unique_vertices(),
                measured: *meas,
                predicted: pred,
            })
            .collect()
    };
    let probes = rows(&probe_meshes, &probe_measured);
    let validation = rows(&val_meshes, &val_measured);
    let simulate_seconds = t.elapsed().as_secs_f64();
    let exact = validation.iter().all(|r| r.measured == r.predicted);
    Ok(H1 {
        adapter,
        chosen: chosen.to_string(),
        probes,
        validation,
        candidates: cands,
        exact,
        measure_seconds,
        simulate_seconds,
    })
}

impl H1 {
    /// One line: the policy found and whether it predicts exactly.
    pub fn verdict(&self) -> String {
        format!(
            "vertex reuse: `{}` predicts every validation mesh {}",
            self.chosen,
            if self.exact { "exactly" } else { "NOT exactly" }
        )
    }

    /// The result as a Markdown section.
    pub fn markdown(&self) -> String {
        let mut s = format!(
            "## H1: vertex reuse\n\nAdapter: {}\n\nChosen policy (least total error on the probes): `{}` (the simulator's `lavapipe` policy is `direct:256,341`, its `nvidia` policy `lookback:32,32,42`). \
             It predicts the validation meshes (not used for fitting) {}.\n\n\
             Measuring took {:.2} s; simulating {} candidate policies on all {} meshes took {:.4} s.\n\n",
            self.adapter,
            self.chosen,
            if self.exact {
                "exactly"
            } else {
                "NOT exactly (see the table)"
            },
            self.measure_seconds,
            self.candidates.len(),
            self.probes.len() + self.validation.len(),
            self.simulate_seconds
        );
        for (title, rows) in [
            ("Probes (fitting)", &self.probes),
            ("Validation (not used for fitting)", &self.validation),
        ] {
            s += &format!(
                "### {title}\n\n| mesh | indices | unique vertices | measured VS invocations | predicted | error |\n|---|---|---|---|---|---|\n"
            );
            for r in rows.iter() {
                s += &format!(
                    "| {} | {} | {} | {} | {} | {} |\n",
                    r.mesh,
                    r.indices,
                    r.unique_vertices,
                    r.measured,
                    r.predicted,
                    r.predicted as i64 - r.measured as i64
                );
            }
            s += "\n";
        }
        let mut c = self.candidates.clone();
        c.sort_by_key(|x| (x.probe_error, x.validation_error));
        s += "### Candidates (10 best by probe error, then the usual suspects)\n\n| policy | probe error | validation error |\n|---|---|---|\n";
        let usual = [
            "fifo:32",
            "lru:32",
            "meshopt:32,32,32",
            "meshopt:14,64,128",
            "batch:32,32",
            "lookback:32,32,42",
            "none",
        ];
        for x in c
            .iter()
            .take(10)
            .chain(c.iter().filter(|x| usual.contains(&x.policy.as_str())))
        {
            s += &format!("| `{}` | {} | {} |\n", x.policy, x.probe_error, x.validation_error);
        }
        s
    }
}
