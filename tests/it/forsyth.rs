//! The fast vertex-cache reordering (`optimize_vertex_cache`) against its
//! first, direct form (`optimize_vertex_cache_reference`), the oracle: the
//! same index buffer, byte for byte, on grids in every generated order,
//! strips, random meshes (high valences: scores past the table), the H200
//! corpus, odd inputs, and random triangle lists. The reordered buffer
//! feeds every simulated vertex count, so any difference would change
//! results.

use std::path::Path;

use proptest::prelude::*;
use rendersim::scene::generators::mesh_from_spec;
use rendersim::scene::optimize::{optimize_vertex_cache, optimize_vertex_cache_reference};

fn same(indices: &[u32], vertex_count: u32, what: &str) {
    let fast = optimize_vertex_cache(indices, vertex_count);
    let reference = optimize_vertex_cache_reference(indices, vertex_count);
    assert_eq!(
        fast, reference,
        "{what}: the fast reordering differs from the reference"
    );
    // Reordering an already reordered buffer walks other ties.
    assert_eq!(
        optimize_vertex_cache(&fast, vertex_count),
        optimize_vertex_cache_reference(&reference, vertex_count),
        "{what}, reordered twice"
    );
}

#[test]
fn generated_meshes_reorder_exactly_as_the_reference_does() {
    let specs = [
        "grid:1x1",
        "grid:2x3",
        "grid:7x5",
        "grid:33x2",
        "grid:96x96",
        "grid:48x48:shuffled:1",
        "grid:96x96:shuffled:7",
        "grid:64x64:local:16:3",
        "grid:150x40",
        "strip:30x20",
        "random:1:1:1",
        "random:50:3:2",
        "random:2000:40:3",
        "random:3000:10:4",
        "random:20000:5000:5",
    ];
    for spec in specs {
        let m = mesh_from_spec(spec, Path::new(".")).expect(spec).to_triangle_list();
        same(&m.indices, m.vertex_count, spec);
    }
}

#[test]
fn the_h200_corpus_reorders_exactly_as_the_reference_does() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/measurements/nvidia-h200/corpus");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).expect("the corpus folder") {
        let path = entry.expect("a corpus entry").path();
        if path.extension().is_some_and(|e| e == "idx") {
            let m = mesh_from_spec(path.to_str().expect("a UTF-8 path"), Path::new(".")).expect("a corpus mesh");
            same(&m.indices, m.vertex_count, &path.display().to_string());
            n += 1;
        }
    }
    assert!(n >= 10, "only {n} corpus meshes found in {}", dir.display());
}

#[test]
fn odd_inputs_reorder_exactly_as_the_reference_does() {
    same(&[], 0, "empty");
    same(&[0, 1], 2, "no whole triangle");
    same(&[0, 1, 5, 7], 2, "index past vertex_count, trailing partial triangle");
    same(
        &[0, 1, 2, 2, 1, 3, 4, 5, 6, 6, 5, 7, 0, 2, 4, 9, 9, 9],
        10,
        "degenerate triangle",
    );
    same(&[3, 3, 3, 3, 3, 3, 1, 1, 2], 0, "repeated degenerate triangles");
    // One vertex in 100 triangles: a valence past the score table.
    let fan: Vec<u32> = (0..100u32).flat_map(|i| [0, i + 1, i + 2]).collect();
    same(&fan, 102, "fan of 100");
}

/// A random triangle list: `tris` triangles over `verts` vertices, indices
/// near a moving window (so the cache finds reuse) or anywhere.
fn triangle_list() -> impl Strategy<Value = (Vec<u32>, u32)> {
    (1u32..300, 0usize..500, 1u32..80, any::<u64>(), 0u32..3).prop_map(|(verts, tris, window, seed, extra)| {
        let mut x = seed | 1;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let mut idx = Vec::with_capacity(tris * 3 + extra as usize);
        for t in 0..tris {
            let base = (t as u32 * 2) % verts;
            for _ in 0..3 {
                idx.push((base + (next() % u64::from(window)) as u32) % verts);
            }
        }
        // A trailing partial triangle.
        for _ in 0..extra {
            idx.push((next() % u64::from(verts)) as u32);
        }
        (idx, verts)
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, .. ProptestConfig::default() })]

    #[test]
    fn random_lists_reorder_exactly_as_the_reference_does((idx, verts) in triangle_list()) {
        prop_assert_eq!(optimize_vertex_cache(&idx, verts), optimize_vertex_cache_reference(&idx, verts));
    }
}

#[test]
fn the_build_benchmark_checks_both_forms_and_times_every_model() {
    // At a small scale, two repetitions each; the benchmark fails if the two
    // forms ever return different buffers.
    let b = rendersim::bench::build::build_bench(0.01, 2).expect("the build benchmark");
    let specs: Vec<&str> = b.reorders.iter().map(|r| r.spec.as_str()).collect();
    assert_eq!(specs, ["grid:96x96", "grid:96x96:shuffled:1", "grid:30x30"]);
    assert!(
        b.reorders
            .iter()
            .all(|r| r.triangles > 0 && r.reference_s.min > 0.0 && r.fast_s.min > 0.0 && r.speedup.n == 2)
    );
    let models: Vec<&str> = b.models.iter().map(|m| m.model.as_str()).collect();
    assert_eq!(models, ["default", "one-mesh", "single-view", "h2-pass"]);
    for m in &b.models {
        // Each run's whole is its build plus its event loop, so the
        // smallest whole is at least the smallest build plus the smallest loop.
        assert_eq!(m.reps, 2);
        for run in [&m.triangle, &m.draw] {
            assert!(
                run.build_s.min > 0.0 && run.simulate_s.min > 0.0,
                "{}: {run:?}",
                m.model
            );
            assert_eq!(run.wall_s.n, 2);
            assert!(run.wall_s.min >= (run.build_s.min + run.simulate_s.min) * (1.0 - 1e-9));
            assert!(run.wall_s.max <= (run.build_s.max + run.simulate_s.max) * (1.0 + 1e-9));
        }
        let ratio = m.speedup.median;
        assert!(ratio > 1.0, "{}: draw fidelity is faster: {ratio}", m.model);
    }
}

#[test]
fn an_unknown_benchmark_names_build_among_the_choices() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_rendersim"))
        .args(["bench", "nosuch"])
        .output()
        .expect("rendersim runs");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("unknown benchmark \"nosuch\"") && err.contains("build"),
        "{err}"
    );
}

#[test]
fn every_benchmark_line_carries_its_repeats_spread_and_bad_repeats_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let plot = d.path().join("kernel.png");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_rendersim"))
        .args(["bench", "kernel", "--scale", "0.0001", "--repeats", "2", "--plot"])
        .arg(&plot)
        .output()
        .expect("rendersim runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = text
        .lines()
        .filter(|l| l.starts_with("kernel hold") || l.starts_with("kernel stiff"))
        .collect();
    assert_eq!(lines.len(), rendersim::bench::KERNEL_CASES.len(), "{text}");
    for l in &lines {
        assert!(l.contains("median (min-max) of 2"), "{l}");
        // Every figure of the line: a median and its range in brackets.
        assert_eq!(l.matches(" M events/s (").count(), 3, "{l}");
        assert!(l.contains(" ns/event (") && l.contains("engine / bare "), "{l}");
    }
    assert!(text.contains("kernel scaling plot (the lines above)"), "{text}");
    assert!(std::fs::metadata(&plot).unwrap().len() > 1000);
    for bad in ["0", "1001", "x"] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_rendersim"))
            .args(["bench", "hour", "--repeats", bad])
            .output()
            .expect("rendersim runs");
        assert_eq!(out.status.code(), Some(2), "--repeats {bad}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("--repeats"), "{bad}: {err}");
    }
}
