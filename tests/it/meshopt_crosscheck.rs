//! Cross-check against meshoptimizer itself (the `meshopt` crate, its C++
//! code): the `meshopt:` policy equals `meshopt_analyzeVertexCache` exactly,
//! `fifo:N` equals `meshopt:N,0,0`, and `batch:V,T` equals `meshopt:V,V,T`,
//! over random meshes and index orders.

use proptest::prelude::*;
use rendersim::components::vertex_cache::{CachePolicy, VertexCache};
use rendersim::scene::mesh::{Mesh, Topology};

fn ours(indices: &[u32], vertex_count: u32, policy: &CachePolicy) -> (u64, u64) {
    let mut c = VertexCache::new(policy, vertex_count as usize);
    let mut transformed = 0u64;
    for t in indices.chunks_exact(3) {
        transformed += u64::from(c.access_triangle([t[0], t[1], t[2]]));
    }
    (transformed, c.warps())
}

fn theirs(indices: &[u32], vertex_count: u32, cache: u32, warp: u32, prim: u32) -> (u64, u64) {
    let s = meshopt::analyze_vertex_cache(indices, vertex_count as usize, cache, warp, prim);
    (u64::from(s.vertices_transformed), u64::from(s.warps_executed))
}

/// A random triangle list: `tris` triangles over `verts` vertices, with some
/// locality (indices near a moving window) so caches and warps matter.
fn mesh() -> impl Strategy<Value = (Vec<u32>, u32)> {
    (3u32..400, 1usize..600, 1u32..64, any::<u64>()).prop_map(|(verts, tris, window, seed)| {
        let mut x = seed | 1;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let mut idx = Vec::with_capacity(tris * 3);
        for t in 0..tris {
            let base = (t as u32 * 2) % verts;
            for _ in 0..3 {
                idx.push((base + (next() % u64::from(window)) as u32) % verts);
            }
        }
        (idx, verts)
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, .. ProptestConfig::default() })]

    #[test]
    fn meshopt_policy_equals_meshoptimizer((idx, verts) in mesh(), cache in 3u32..48, warp in prop_oneof![Just(0u32), 3u32..96], prim in prop_oneof![Just(0u32), 1u32..64]) {
        let p = CachePolicy::Meshopt { cache, warp, primgroup: prim };
        prop_assert_eq!(ours(&idx, verts, &p), theirs(&idx, verts, cache, warp, prim));
    }

    #[test]
    fn fifo_equals_meshopt_without_warps((idx, verts) in mesh(), n in 3u32..48) {
        let (fifo, _) = ours(&idx, verts, &CachePolicy::Fifo(n));
        prop_assert_eq!(fifo, theirs(&idx, verts, n, 0, 0).0);
        // Also through the mesh API (index stream).
        let m = Mesh { name: "r".into(), topology: Topology::TriangleList, indices: idx.clone(), vertex_count: verts };
        prop_assert_eq!(m.cache_stats(&CachePolicy::Fifo(n)).transformed, fifo);
        prop_assert_eq!(m.cache_stats(&CachePolicy::Meshopt { cache: n, warp: 0, primgroup: 0 }).transformed, fifo);
    }

    #[test]
    fn batch_equals_meshopt_with_cache_the_size_of_a_warp((idx, verts) in mesh(), v in 3u32..64, t in 1u32..64) {
        prop_assert_eq!(ours(&idx, verts, &CachePolicy::Batch { vertices: v, triangles: t }), theirs(&idx, verts, v, v, t));
    }
}

#[test]
fn known_profiles_on_a_grid() {
    // The NVIDIA Pascal and AMD GCN profiles of meshoptimizer's vcachetuner.
    let m = rendersim::scene::generators::mesh_from_spec("grid:50x50", std::path::Path::new(".")).unwrap();
    for (c, w, p) in [(32, 32, 32), (14, 64, 128), (16, 32, 32), (128, 0, 0)] {
        let ours = m
            .cache_stats(&CachePolicy::Meshopt {
                cache: c,
                warp: w,
                primgroup: p,
            })
            .transformed;
        let theirs = meshopt::analyze_vertex_cache(&m.indices, m.vertex_count as usize, c, w, p).vertices_transformed;
        assert_eq!(ours, u64::from(theirs), "meshopt:{c},{w},{p}");
    }
}
