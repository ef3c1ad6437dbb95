//! The `nvidia` vertex-reuse policy (`lookback:32,32,42`) against
//! vertex-shader invocations measured on an NVIDIA H200
//! (docs/measurements/nvidia-h200): the 39-mesh corpus in
//! `vertex-reuse.csv`, the built-in probe cases of `probe-builtin.txt`, and
//! study H1's probes and validation meshes in `studies.md`. These run
//! without a device: the measured numbers are the oracle.

use crate::common::list;
use std::path::{Path, PathBuf};

use rendersim::components::vertex_cache::CachePolicy;
use rendersim::scene::generators::mesh_from_spec;
use rendersim::scene::mesh::Mesh;

fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/measurements/nvidia-h200")
}

/// One corpus row: file (relative to the data directory), its mesh, and the
/// measured invocations.
struct Row {
    file: String,
    mesh: Mesh,
    measured: u64,
}

/// Every row of `vertex-reuse.csv` with its `.idx` file loaded; checks the
/// file's index and unique-vertex counts against the row.
fn corpus() -> Vec<Row> {
    let dir = data_dir();
    let csv = std::fs::read_to_string(dir.join("vertex-reuse.csv")).expect("vertex-reuse.csv");
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("file,indices,unique_vertices,vs_invocations"),
        "header"
    );
    let rows: Vec<Row> = lines
        .filter(|l| !l.trim().is_empty())
        .map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            assert_eq!(f.len(), 4, "{line}");
            let num = |s: &str| s.trim().parse::<u64>().unwrap_or_else(|_| panic!("{line}"));
            let mesh = mesh_from_spec(f[0], &dir).unwrap_or_else(|e| panic!("{}: {e}", f[0]));
            assert_eq!(mesh.index_count(), num(f[1]), "{} indices", f[0]);
            assert_eq!(mesh.unique_vertices(), num(f[2]), "{} unique vertices", f[0]);
            Row {
                file: f[0].to_string(),
                mesh,
                measured: num(f[3]),
            }
        })
        .collect();
    assert_eq!(rows.len(), 39, "corpus rows");
    rows
}

fn tv(m: &Mesh, policy: &CachePolicy) -> u64 {
    m.cache_stats(policy).transformed
}

/// Rows where `policy` differs from the measurement: (file, predicted - measured).
fn misses(rows: &[Row], policy: &str) -> Vec<(String, i64)> {
    let p: CachePolicy = policy.parse().unwrap();
    rows.iter()
        .filter_map(|r| {
            let d = tv(&r.mesh, &p) as i64 - r.measured as i64;
            (d != 0).then(|| (r.file.clone(), d))
        })
        .collect()
}

#[test]
fn nvidia_matches_every_corpus_mesh_and_meshopt_does_not() {
    let rows = corpus();
    assert_eq!(misses(&rows, "nvidia"), []);
    assert_eq!(misses(&rows, "lookback:32,32,42"), []);
    // meshoptimizer's NVIDIA profile misses the icospheres in generation
    // order and the rings of at most 32 vertices: the test can fail.
    let meshopt = misses(&rows, "meshopt:32,32,32");
    assert_eq!(meshopt.len(), 10, "{meshopt:?}");
    assert!(meshopt.contains(&("corpus/ico6-ordered.idx".to_string(), 69_120 - 72_960)));
    assert!(meshopt.contains(&("corpus/ring16x8.idx".to_string(), 64 - 138)));
}

#[test]
fn the_corpus_pins_the_window_to_41_to_43_indices() {
    let rows = corpus();
    for w in 41..=43 {
        assert_eq!(misses(&rows, &format!("lookback:32,32,{w}")), [], "window {w}");
    }
    // One index shorter loses two reuses at distance 41 in ico1-ordered; one
    // longer wrongly reuses the ring of 16 at distance 44.
    assert_eq!(
        misses(&rows, "lookback:32,32,40"),
        [("corpus/ico1-ordered.idx".to_string(), 2)]
    );
    assert_eq!(
        misses(&rows, "lookback:32,32,44"),
        [("corpus/ring16x8.idx".to_string(), -74)]
    );
    // The batch limits are pinned too.
    for other in [
        "lookback:31,32,42",
        "lookback:33,32,42",
        "lookback:32,31,42",
        "lookback:32,33,42",
    ] {
        assert!(!misses(&rows, other).is_empty(), "{other}");
    }
}

#[test]
fn builtin_probe_cases() {
    let nv = CachePolicy::Nvidia;
    // The same triangle repeated n times: one batch per 32 triangles.
    for (n, measured) in [(32, 3), (33, 6), (341, 33), (342, 33), (682, 66), (683, 66), (1000, 96)] {
        assert_eq!(tv(&list([0, 1, 2].repeat(n)), &nv), measured, "same triangle x{n}");
    }
    // Indices 0..k drawn twice as triangles.
    for (k, measured) in [
        (15u32, 15),
        (48, 96),
        (96, 192),
        (255, 510),
        (258, 516),
        (384, 768),
        (510, 1020),
        (768, 1536),
    ] {
        let once: Vec<u32> = (0..k).collect();
        assert_eq!(tv(&list(once.repeat(2)), &nv), measured, "0..{k} twice");
    }
    // The 64x64-vertex grid in row order (the probe's buffer: meshoptimizer's
    // analyzer gives 8064 with a FIFO of 16 on it, as on this one).
    let grid = mesh_from_spec("grid:63x63", Path::new(".")).unwrap();
    assert_eq!(tv(&grid, &CachePolicy::Fifo(16)), 8064);
    assert_eq!(tv(&grid, &nv), 8568);
}

#[test]
fn study_h1_meshes_measured_on_the_h200() {
    let nv = CachePolicy::Nvidia;
    for (k, measured) in [
        (1, 3),
        (100, 12),
        (341, 33),
        (342, 33),
        (683, 66),
        (684, 66),
        (1000, 96),
    ] {
        assert_eq!(tv(&list([0, 1, 2].repeat(k)), &nv), measured, "{k} repeats");
    }
    let c: Vec<u32> = (0..100u32).flat_map(|i| [i, i + 256, i + 512]).collect();
    assert_eq!(tv(&list(c.repeat(2)), &nv), 600);
    let c: Vec<u32> = (0..100u32).flat_map(|i| [i, i + 128, i + 1000]).collect();
    assert_eq!(tv(&list(c.repeat(2)), &nv), 600);
    for (n, measured) in [
        (64u32, 136),
        (128, 272),
        (200, 426),
        (256, 544),
        (257, 548),
        (300, 636),
        (600, 1276),
    ] {
        let once: Vec<u32> = (0..n - 2).flat_map(|i| [i, i + 1, i + 2]).collect();
        assert_eq!(tv(&list(once.repeat(2)), &nv), measured, "run over {n}");
    }
    for (spec, measured) in [
        ("grid:16x16", 576),
        ("grid:33x17", 1224),
        ("grid:64x64", 8832),
        ("grid:100x40", 8612),
        ("grid:64x64:shuffled:5", 24496),
        ("grid:48x48:optimized", 3883),
        ("strip:20x20", 888),
        ("random:3000:700:3", 8784),
    ] {
        let m = mesh_from_spec(spec, Path::new(".")).unwrap();
        assert_eq!(tv(&m, &nv), measured, "{spec}");
    }
    // These meshes were not used to find the rule, and one of them narrows
    // the window further: 43 indices shade one vertex too few, and
    // meshoptimizer's NVIDIA profile ten too few.
    let m = mesh_from_spec("grid:48x48:optimized", Path::new(".")).unwrap();
    let under = |p: &str| tv(&m, &p.parse().unwrap());
    assert_eq!(under("lookback:32,32,41"), 3883);
    assert_eq!(under("lookback:32,32,43"), 3882);
    assert_eq!(under("meshopt:32,32,32"), 3873);
}
