//! Tests for [`super::mesh_from_spec`].

use super::*;
use crate::components::vertex_cache::CachePolicy;
use std::path::PathBuf;

fn build(spec: &str) -> Mesh {
    mesh_from_spec(spec, Path::new(".")).unwrap_or_else(|e| panic!("{spec}: {e}"))
}

fn err(spec: &str) -> String {
    mesh_from_spec(spec, Path::new(".")).expect_err(spec).to_string()
}

fn sorted_tris(m: &Mesh) -> Vec<[u32; 3]> {
    let mut v: Vec<[u32; 3]> = m
        .to_triangle_list()
        .indices
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    v.sort_unstable();
    v
}

/// Twice the signed area of a grid triangle (positive = counter-clockwise).
fn grid_area(w: u32, t: &[u32]) -> i64 {
    let p = |v: u32| ((v % (w + 1)) as i64, (v / (w + 1)) as i64);
    let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
    (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0)
}

#[test]
fn grid_counts_and_winding() {
    let m = build("grid:4x3");
    m.validate().unwrap();
    assert_eq!(m.topology, Topology::TriangleList);
    assert_eq!((m.vertex_count, m.triangles()), (20, 24));
    assert_eq!(m.unique_vertices(), 20);
    assert_eq!(&m.indices[..6], &[0, 1, 5, 5, 1, 6]);
    assert!(m.indices.chunks(3).all(|t| grid_area(4, t) > 0));
}

/// Row-major grid under a FIFO, derived by hand. Quad `(i, j)` uses
/// `a b c` then `c b d`, so vertex `(k, j)` of a bottom row is last used as
/// `a` of quad `k` (or as `b` of the last quad). In the first row of quads
/// every quad inserts two new vertices (`b` and `d`; quad 0 also `a` and
/// `c`); in later rows only the top vertex `d` (quad 0 also `c`), as the bottom
/// ones are reused from the row below. Counting insertions between a vertex's
/// insertion as a top vertex and its last use as a bottom vertex one row
/// later: vertex `(k, 1)` sees `2W - k + 1` for `k >= 1` (`2W - 1` for
/// `k = 0`), so the worst is `(1, 1)` with `2W`; from the second row of
/// quads on, every vertex sees `W + 1`. So a FIFO of `2W + 1` entries
/// transforms every vertex exactly once: transformed = (W+1)(H+1),
/// ACMR = (W+1)(H+1) / (2WH) (-> 1/2 for large grids), ATVR = 1. With `2W`
/// entries vertex `(1, 1)` is evicted just before its last use.
#[test]
fn grid_row_major_acmr_by_hand() {
    let m = build("grid:4x3");
    let s = m.cache_stats(&CachePolicy::Fifo(9));
    assert_eq!((s.transformed, s.triangles), (20, 24));
    assert_eq!(s.acmr(), 20.0 / 24.0);
    assert_eq!(s.atvr(), 1.0);
    let small = m.cache_stats(&CachePolicy::Fifo(8));
    assert!(small.transformed > 20, "{small:?}");
    // A single row of quads needs no reuse across rows at all.
    let one = build("grid:5x1").cache_stats(&CachePolicy::Fifo(3));
    assert_eq!(one.transformed, 12);
    assert_eq!(one.acmr(), 12.0 / 10.0);
    // Bigger grid: 2W + 1 entries suffice.
    let big = build("grid:32x32").cache_stats(&CachePolicy::Fifo(65));
    assert_eq!(big.transformed, 33 * 33);
    assert_eq!(big.acmr(), (33.0 * 33.0) / (2.0 * 32.0 * 32.0));
}

#[test]
fn strip_matches_grid() {
    let s = build("strip:4x3");
    s.validate().unwrap();
    assert_eq!(s.topology, Topology::TriangleStrip);
    assert_eq!((s.vertex_count, s.triangles()), (20, 24));
    assert_eq!(s.index_count(), 3 * 10);
    assert_eq!(s.indices.iter().filter(|&&i| i == RESTART).count(), 2);
    let list = s.to_triangle_list();
    assert!(list.indices.chunks(3).all(|t| grid_area(4, t) > 0));
    let st = s.cache_stats(&CachePolicy::Fifo(64));
    assert_eq!(st.transformed, 20);
    assert_eq!(
        s.misses_per_triangle(&CachePolicy::Fifo(64))
            .iter()
            .map(|&m| u64::from(m))
            .sum::<u64>(),
        20
    );
}

#[test]
fn shuffled_is_deterministic_permutation() {
    let a = build("grid:8x8:shuffled:7");
    let b = build("grid:8x8:shuffled:7");
    let c = build("grid:8x8:shuffled:8");
    let g = build("grid:8x8");
    assert_eq!(a, b);
    assert_ne!(a.indices, c.indices);
    assert_ne!(a.indices, g.indices);
    assert_eq!(sorted_tris(&a), sorted_tris(&g));
    a.validate().unwrap();
}

#[test]
fn optimized_lowers_acmr() {
    let p = CachePolicy::Fifo(32);
    let shuffled = build("grid:64x64:shuffled:1").cache_stats(&p).acmr();
    let opt_mesh = build("grid:64x64:optimized");
    assert_eq!(sorted_tris(&opt_mesh), sorted_tris(&build("grid:64x64")));
    let optimized = opt_mesh.cache_stats(&p).acmr();
    // Re-optimizing a shuffled order works as well.
    let sh = build("grid:64x64:shuffled:1");
    let reopt = Mesh {
        indices: optimize_vertex_cache(&sh.indices, sh.vertex_count),
        ..sh
    };
    let reoptimized = reopt.cache_stats(&p).acmr();
    eprintln!("ACMR fifo:32 shuffled {shuffled:.3} optimized {optimized:.3} re-optimized {reoptimized:.3}");
    assert!(shuffled > 1.5, "{shuffled}");
    assert!(optimized < 0.8, "{optimized}");
    assert!(reoptimized < 0.8, "{reoptimized}");
}

#[test]
fn random_mesh() {
    let m = build("random:100:50:3");
    m.validate().unwrap();
    assert_eq!((m.triangles(), m.vertex_count), (100, 50));
    assert_eq!(m, build("random:100:50:3"));
    assert_ne!(m.indices, build("random:100:50:4").indices);
    assert!(m.unique_vertices() <= 50);
}

#[test]
fn spec_errors() {
    for s in [
        "cube:3",
        "grid",
        "grid:4x4:foo",
        "",
        "strip:4x4:optimized",
        "random:1:2",
    ] {
        let e = err(s);
        assert!(e.contains("unknown mesh spec") && e.contains("grid:WxH"), "{e}");
    }
    assert!(err("grid:ax4").contains("width"));
    assert!(err("grid:4xq").contains("height `q`"));
    assert!(err("grid:44").contains("size"));
    assert!(err("grid:-1x4").contains("width"));
    assert!(err("grid:4x4:shuffled:s").contains("seed"));
    assert!(err("random:1:2:x").contains("seed"));
    assert!(err("random:z:2:1").contains("triangle count"));
    assert!(err("random:1:99999999999:1").contains("vertex count"));
    assert!(err("grid:0x4").contains("width must be at least 1"));
    assert!(err("strip:4x0").contains("height must be at least 1"));
    assert!(err("random:0:3:1").contains("triangle count must"));
    assert!(err("random:3:0:1").contains("vertex count must"));
    assert!(err("grid:100000x100000").contains("too large"));
    assert!(err("grid:4294967295x4294967295").contains("too large"));
    assert!(err("random:1000000000:3:1").contains("too large"));
    assert!(err("random:18446744073709551615:3:1").contains("too large"));
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn obj_files() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "tri.obj",
        "# a triangle and a quad\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n",
    );
    let m = mesh_from_spec("tri.obj", dir.path()).unwrap();
    assert_eq!(m.name, "tri.obj");
    assert_eq!((m.triangles(), m.vertex_count), (2, 4));
    assert_eq!(m.indices, [0, 1, 2, 1, 3, 2]);

    // A quad is triangulated; two objects are concatenated with offsets.
    let quad = write(
        dir.path(),
        "quad.obj",
        "o a\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\no b\nv 5 5 5\nv 6 5 5\nv 5 6 5\nf 5 6 7\n",
    );
    let m = mesh_from_spec(quad.to_str().unwrap(), Path::new("/nonexistent")).unwrap();
    m.validate().unwrap();
    assert_eq!((m.triangles(), m.vertex_count), (3, 7));
    assert_eq!(m.indices, [0, 1, 2, 0, 2, 3, 4, 5, 6]);
    assert_eq!(m.cache_stats(&CachePolicy::Fifo(8)).transformed, 7);
}

#[test]
fn obj_errors() {
    let dir = tempfile::tempdir().unwrap();
    let e = mesh_from_spec("missing.obj", dir.path()).unwrap_err();
    assert!(matches!(e, MeshError::FileNotFound(_)));
    assert!(e.to_string().contains("missing.obj"), "{e}");

    write(dir.path(), "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 zz 0\nf 1 2 3\n");
    let e = mesh_from_spec("bad.obj", dir.path()).unwrap_err().to_string();
    assert!(
        e.contains("bad.obj") && e.contains("line 3") && e.contains("position parse error"),
        "{e}"
    );
    write(dir.path(), "badf.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x");
    let e = mesh_from_spec("badf.obj", dir.path()).unwrap_err().to_string();
    assert!(e.contains("line 4") && e.contains("face"), "{e}");
    write(dir.path(), "oob.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
    let e = mesh_from_spec("oob.obj", dir.path()).unwrap_err().to_string();
    assert!(e.contains("oob.obj") && e.contains("out of bounds"), "{e}");
    write(dir.path(), "empty.obj", "v 0 0 0\n");
    let e = mesh_from_spec("empty.obj", dir.path()).unwrap_err().to_string();
    assert!(e.contains("no triangles"), "{e}");
}

#[test]
fn idx_files() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "m.idx", "# two triangles\n0 1 2\n2 1 3 # second\n\n");
    let m = mesh_from_spec("m.idx", dir.path()).unwrap();
    assert_eq!(m.indices, [0, 1, 2, 2, 1, 3]);
    assert_eq!(m.vertex_count, 4);

    write(dir.path(), "tok.idx", "0 1 2\n3 4 five\n");
    let e = mesh_from_spec("tok.idx", dir.path()).unwrap_err();
    assert!(
        matches!(&e, MeshError::IdxToken { line: 2, token, .. } if token == "five"),
        "{e}"
    );
    assert!(e.to_string().contains("tok.idx"));
    write(dir.path(), "neg.idx", "0 1 -2\n");
    assert!(mesh_from_spec("neg.idx", dir.path()).is_err());
    write(dir.path(), "max.idx", "0 1 4294967295\n");
    assert!(mesh_from_spec("max.idx", dir.path()).is_err());
    write(dir.path(), "four.idx", "0 1 2 3\n");
    let e = mesh_from_spec("four.idx", dir.path()).unwrap_err().to_string();
    assert!(e.contains("4 indices, not a multiple of 3"), "{e}");
    write(dir.path(), "none.idx", "# nothing\n");
    let e = mesh_from_spec("none.idx", dir.path()).unwrap_err().to_string();
    assert!(e.contains("no triangles"), "{e}");
    let e = mesh_from_spec("gone.idx", dir.path()).unwrap_err().to_string();
    assert!(e.contains("gone.idx") && e.contains("not found"), "{e}");
}

#[test]
fn local_shuffle_keeps_windows_and_interpolates_reuse() {
    let g = build("grid:32x32");
    let one = build("grid:32x32:local:1:3");
    assert_eq!(one.indices, g.indices, "a window of one triangle keeps the order");
    let w8 = build("grid:32x32:local:8:3");
    assert_eq!(sorted_tris(&w8), sorted_tris(&g));
    // Each window of 8 triangles holds the same triangles as in row order.
    for (a, b) in w8.indices.chunks(24).zip(g.indices.chunks(24)) {
        let mut x: Vec<[u32; 3]> = a.chunks(3).map(|t| [t[0], t[1], t[2]]).collect();
        let mut y: Vec<[u32; 3]> = b.chunks(3).map(|t| [t[0], t[1], t[2]]).collect();
        x.sort();
        y.sort();
        assert_eq!(x, y);
    }
    let p = CachePolicy::Fifo(16);
    let acmr = |spec: &str| build(spec).cache_stats(&p).acmr();
    let (a1, a64, a_all) = (
        acmr("grid:32x32"),
        acmr("grid:32x32:local:64:3"),
        acmr("grid:32x32:local:4096:3"),
    );
    assert!(a1 < a64 && a64 < a_all, "{a1} {a64} {a_all}");
    assert!(matches!(
        mesh_from_spec("grid:8x8:local:0:1", std::path::Path::new(".")),
        Err(MeshError::ZeroSize { .. })
    ));
}

#[test]
fn vertex_counts_beyond_the_limit_are_refused_before_allocating() {
    let max = crate::limits::MAX_MESH_VERTICES;
    let e = err(&format!("random:1:{}:1", max + 1));
    assert!(
        e.contains("random:1:268435457:1") && e.contains("268435457 vertices") && e.contains("limit"),
        "{e}"
    );
    let e = err("random:1:4294967295:1");
    assert!(e.contains("4294967295 vertices"), "{e}");
    assert_eq!(build(&format!("random:1:{max}:1")).vertex_count as u64, max);
    let dir = tempfile::tempdir().unwrap();
    let big = dir.path().join("big.idx");
    std::fs::write(&big, "0 1 4294967294\n").unwrap();
    let e = err(big.to_str().unwrap());
    assert!(
        e.contains("big.idx") && e.contains("4294967295 vertices (its largest index + 1)"),
        "{e}"
    );
    std::fs::write(&big, format!("0 1 {}\n", max - 1)).unwrap();
    assert_eq!(build(big.to_str().unwrap()).vertex_count as u64, max);
}
