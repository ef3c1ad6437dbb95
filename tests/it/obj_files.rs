//! OBJ files keep the file's vertex numbering (issue 10, item 5): a mesh
//! read from `.obj` has the index buffer of the same mesh read from `.idx`,
//! so index-value-sensitive caches (lavapipe's direct-mapped reuse) see the
//! same stream. The icosphere is the H200 corpus's `ico4-ordered`, whose
//! indices are not in first-use order.

use std::path::Path;
use std::process::Command;

use rendersim::scene::generators::mesh_from_spec;

const ICO: &str = include_str!("../../docs/measurements/nvidia-h200/corpus/ico4-ordered.idx");

fn ico_indices() -> Vec<u32> {
    ICO.lines()
        .flat_map(|l| l.split('#').next().unwrap_or("").split_whitespace())
        .map(|t| t.parse().unwrap())
        .collect()
}

/// The mesh as OBJ text: one `v` per index value, faces written with
/// `corner(i)` for 0-based vertex `i`.
fn obj_text(indices: &[u32], extra: &str, corner: impl Fn(u32) -> String) -> String {
    let n = indices.iter().max().unwrap() + 1;
    let mut s: String = (0..n).map(|i| format!("v {i} 0 0\n")).collect();
    s.push_str(extra);
    for t in indices.chunks(3) {
        s.push_str(&format!("f {} {} {}\n", corner(t[0]), corner(t[1]), corner(t[2])));
    }
    s
}

/// `rendersim vcache FILE --policy lavapipe --json` without the keys that
/// name the file or measure the machine.
fn vcache(path: &Path) -> serde_json::Value {
    let o = Command::new(env!("CARGO_BIN_EXE_rendersim"))
        .args(["vcache", path.to_str().unwrap(), "--policy", "lavapipe", "--json"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let m = v.as_object_mut().unwrap();
    m.remove("mesh");
    m.remove("wall_seconds");
    v
}

#[test]
fn an_obj_icosphere_matches_its_idx_form() {
    let indices = ico_indices();
    // The premise: renumbering by first use would change the index values.
    let mut seen = std::collections::HashSet::new();
    let first_use: Vec<u32> = indices.iter().copied().filter(|i| seen.insert(*i)).collect();
    assert!(first_use.iter().enumerate().any(|(k, &i)| k as u32 != i));

    let d = tempfile::tempdir().unwrap();
    let idx = d.path().join("ico.idx");
    std::fs::write(&idx, ICO).unwrap();
    let obj = d.path().join("ico.obj");
    std::fs::write(&obj, obj_text(&indices, "", |i| (i + 1).to_string())).unwrap();
    // Texcoords and normals that agree with the positions change nothing.
    let attrs = d.path().join("ico-attrs.obj");
    let n = indices.iter().max().unwrap() + 1;
    let extra: String = (0..n).map(|i| format!("vt {i} 0\nvn 0 0 1\n")).collect();
    std::fs::write(&attrs, obj_text(&indices, &extra, |i| format!("{}/{}/1", i + 1, i + 1))).unwrap();

    let from_idx = mesh_from_spec(idx.to_str().unwrap(), d.path()).unwrap();
    assert_eq!(from_idx.indices, indices);
    for o in [&obj, &attrs] {
        let from_obj = mesh_from_spec(o.to_str().unwrap(), d.path()).unwrap();
        assert_eq!(from_obj.indices, from_idx.indices, "{}", o.display());
        assert_eq!(from_obj.vertex_count, from_idx.vertex_count);
        assert_eq!(vcache(o), vcache(&idx), "{}", o.display());
    }
}

#[test]
fn an_obj_with_seams_splits_vertices_in_first_use_order() {
    // A quad of two triangles whose shared edge has different normals on
    // each side (a crease): positions 1 and 3 are two GPU vertices each.
    let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nvn 0 1 0\n\
                f 3/3/1 4/4/1 1/1/1\nf 1/1/2 2/2/2 3/3/2\n";
    let d = tempfile::tempdir().unwrap();
    let p = d.path().join("crease.obj");
    std::fs::write(&p, text).unwrap();
    let m = mesh_from_spec(p.to_str().unwrap(), d.path()).unwrap();
    // (3,3,1) (4,4,1) (1,1,1) (1,1,2) (2,2,2) (3,3,2).
    assert_eq!(m.indices, [0, 1, 2, 3, 4, 5]);
    assert_eq!(m.vertex_count, 6);
    let v = vcache(&p);
    assert_eq!(
        (v["triangles"].as_u64(), v["unique_vertices"].as_u64()),
        (Some(2), Some(6)),
        "{v}"
    );
    assert_eq!(v["transformed"].as_u64(), Some(6), "{v}");
}
