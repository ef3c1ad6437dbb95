//! Vertex-cache simulation speed against meshoptimizer's own analyzer
//! (`meshopt::analyze_vertex_cache`, C++), on the same >= 1M-index buffers,
//! printed as a ratio (median of several repetitions, same process).
//! Run: `cargo bench --bench vcache`.

use std::time::Instant;

use rendersim::components::vertex_cache::CachePolicy;
use rendersim::scene::generators::mesh_from_spec;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn main() {
    // cargo bench passes --bench; nothing else is accepted.
    for spec in ["grid:600x600", "grid:600x600:shuffled:1", "grid:600x600:optimized"] {
        let m = mesh_from_spec(spec, std::path::Path::new(".")).expect("generator");
        let n = m.indices.len();
        assert!(n >= 1_000_000);
        for (c, w, p) in [(32u32, 0u32, 0u32), (32, 32, 32), (14, 64, 128)] {
            let policy = CachePolicy::Meshopt {
                cache: c,
                warp: w,
                primgroup: p,
            };
            let mut ours = vec![];
            let mut theirs = vec![];
            let mut check = (0, 0);
            for _ in 0..7 {
                let t = Instant::now();
                let s = m.cache_stats(&policy);
                ours.push(t.elapsed().as_secs_f64());
                let t = Instant::now();
                let r = meshopt::analyze_vertex_cache(&m.indices, m.vertex_count as usize, c, w, p);
                theirs.push(t.elapsed().as_secs_f64());
                check = (s.transformed, u64::from(r.vertices_transformed));
            }
            assert_eq!(check.0, check.1, "results differ");
            let (o, t) = (median(ours), median(theirs));
            println!(
                "{spec} ({n} indices), meshopt:{c},{w},{p}: rendersim {:.2} ms, meshoptimizer {:.2} ms, ratio (meshoptimizer time / ours) {:.2}",
                o * 1e3,
                t * 1e3,
                t / o
            );
        }
    }
}
