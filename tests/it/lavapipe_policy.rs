//! The `lavapipe` vertex-reuse policy against vertex-shader invocation
//! counts measured on Mesa 22.3.6 lavapipe (docs/measurements/
//! llvmpipe-mesa-22.3.6.md, study H1). These run without a device: the
//! measured numbers are the oracle.

use crate::common::list;
use rendersim::components::vertex_cache::CachePolicy;
use rendersim::scene::generators::mesh_from_spec;
use rendersim::scene::mesh::Mesh;

fn tv(m: &Mesh) -> u64 {
    m.cache_stats(&CachePolicy::Lavapipe).transformed
}

#[test]
fn repeated_triangle_is_reshaded_every_341_triangles() {
    for (k, measured) in [(1, 3), (341, 3), (342, 6), (683, 9), (684, 9), (1000, 9)] {
        assert_eq!(tv(&list([0, 1, 2].repeat(k))), measured, "{k} repeats");
    }
}

#[test]
fn runs_drawn_twice_and_slot_conflicts() {
    for (n, measured) in [(64u32, 64), (200, 257), (256, 425), (257, 429), (300, 601), (600, 1206)] {
        let once: Vec<u32> = (0..n - 2).flat_map(|i| [i, i + 1, i + 2]).collect();
        assert_eq!(tv(&list(once.repeat(2))), measured, "run over {n}");
    }
    let c: Vec<u32> = (0..100u32).flat_map(|i| [i, i + 256, i + 512]).collect();
    assert_eq!(tv(&list(c.repeat(2))), 600);
    let c: Vec<u32> = (0..100u32).flat_map(|i| [i, i + 128, i + 1000]).collect();
    assert_eq!(tv(&list(c.repeat(2))), 452);
}

#[test]
fn validation_meshes_measured_on_lavapipe() {
    for (spec, measured) in [
        ("grid:16x16", 306),
        ("grid:33x17", 715),
        ("grid:64x64", 5737),
        ("grid:100x40", 6454),
        ("grid:64x64:shuffled:5", 23602),
        ("grid:48x48:optimized", 3081),
        ("strip:20x20", 486),
        ("random:3000:700:3", 6580),
    ] {
        let m = mesh_from_spec(spec, std::path::Path::new(".")).unwrap();
        assert_eq!(tv(&m), measured, "{spec}");
    }
}

#[test]
fn policy_strings_round_trip_and_reject_bad_input() {
    for s in [
        "lavapipe",
        "direct:256,341",
        "meshopt:32,32,32",
        "batch:32,32",
        "fifo:24",
        "lru:8",
        "none",
    ] {
        let p: CachePolicy = s.parse().unwrap();
        assert_eq!(p.to_string(), s);
    }
    for bad in [
        "direct:0,3",
        "direct:256",
        "lavapipe:3",
        "meshopt:32,32",
        "batch:2,4",
        "meshopt:32,2,0",
    ] {
        assert!(bad.parse::<CachePolicy>().is_err(), "{bad}");
    }
}
