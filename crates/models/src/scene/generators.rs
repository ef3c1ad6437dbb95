//! Mesh workloads from a spec string: synthetic grids, strips and random
//! meshes, or index buffers loaded from `.obj` and `.idx` files.
//!
//! The grid family exercises the post-transform vertex cache of paper 000
//! (sections 2 and 4.5): the same triangles drawn row by row, shuffled, or
//! reordered by [`optimize_vertex_cache`] give very different numbers of
//! actually transformed vertices. `grid:WxH:local:WINDOW:SEED` shuffles the
//! triangles only within consecutive windows of WINDOW triangles, so the
//! locality of the order (and the reuse a cache finds) can be set between
//! row order (window 1) and a full shuffle (a window as large as the mesh).
//!
//! Grid vertices are numbered row-major: vertex `(i, j)` (column `i` in
//! `0..=W`, row `j` in `0..=H`) has id `j * (W + 1) + i`. Quad `(i, j)` with
//! corners `a = (i, j)`, `b = (i+1, j)`, `c = (i, j+1)`, `d = (i+1, j+1)` is
//! the two counter-clockwise triangles `a b c` and `c b d`.

use std::path::Path;

use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

use super::mesh::{Mesh, MeshError, RESTART, Topology};
use super::obj::read_obj;
use super::optimize::optimize_vertex_cache;

/// The most indices a generated mesh may have ([`crate::limits::MAX_MESH_INDICES`]).
pub const MAX_INDICES: u64 = crate::limits::MAX_MESH_INDICES;

/// Builds a mesh from a spec (see the module docs and [`MeshError::UnknownGenerator`]
/// for the forms). File paths are relative to `base_dir` unless absolute.
pub fn mesh_from_spec(spec: &str, base_dir: &Path) -> Result<Mesh, MeshError> {
    let spec = spec.trim();
    let lower = spec.to_ascii_lowercase();
    if lower.ends_with(".obj") || lower.ends_with(".idx") {
        let path = Path::new(spec);
        let path = if path.is_absolute() {
            path.to_path_buf()
        } else {
            base_dir.join(path)
        };
        if !path.exists() {
            return Err(MeshError::FileNotFound(path));
        }
        return if lower.ends_with(".obj") {
            load_obj(&path, spec)
        } else {
            load_idx(&path, spec)
        };
    }
    let parts: Vec<&str> = spec.split(':').collect();
    let unknown = || MeshError::UnknownGenerator(spec.to_string());
    match parts.as_slice() {
        ["grid", size] => {
            let (w, h) = parse_size(size, spec)?;
            Ok(grid(w, h, spec))
        }
        ["grid", size, "shuffled", seed] => {
            let (w, h) = parse_size(size, spec)?;
            let seed = parse_num::<u64>(seed, "seed", spec)?;
            let mut mesh = grid(w, h, spec);
            shuffle_triangles(&mut mesh.indices, seed);
            Ok(mesh)
        }
        ["grid", size, "local", window, seed] => {
            let (w, h) = parse_size(size, spec)?;
            let window = parse_num::<usize>(window, "window", spec)?;
            nonzero(window as u64, "window", spec)?;
            let seed = parse_num::<u64>(seed, "seed", spec)?;
            let mut mesh = grid(w, h, spec);
            shuffle_within_windows(&mut mesh.indices, window, seed);
            Ok(mesh)
        }
        ["grid", size, "optimized"] => {
            let (w, h) = parse_size(size, spec)?;
            let mut mesh = grid(w, h, spec);
            mesh.indices = optimize_vertex_cache(&mesh.indices, mesh.vertex_count);
            Ok(mesh)
        }
        ["strip", size] => {
            let (w, h) = parse_size(size, spec)?;
            Ok(strip(w, h, spec))
        }
        ["random", t, v, seed] => {
            let t = parse_num::<u64>(t, "triangle count", spec)?;
            let v = parse_num::<u32>(v, "vertex count", spec)?;
            let seed = parse_num::<u64>(seed, "seed", spec)?;
            nonzero(t, "triangle count", spec)?;
            nonzero(u64::from(v), "vertex count", spec)?;
            check_indices(t.checked_mul(3), spec)?;
            check_vertices(u64::from(v), spec, "")?;
            Ok(random(t, v, seed, spec))
        }
        _ => Err(unknown()),
    }
}

/// Indices a generator spec (`grid:`, `strip:`, `random:`) will produce,
/// read from the spec without building the mesh; `None` for a file or a
/// spec that does not parse (building it reports the error). For memory
/// estimates made before anything is allocated.
pub fn spec_index_count(spec: &str) -> Option<u64> {
    let parts: Vec<&str> = spec.trim().split(':').collect();
    let wh = |size: &str| -> Option<(u64, u64)> {
        let (w, h) = size.split_once(['x', 'X'])?;
        Some((w.trim().parse().ok()?, h.trim().parse().ok()?))
    };
    match parts.as_slice() {
        ["grid", size, ..] => wh(size).map(|(w, h)| w.saturating_mul(h).saturating_mul(6)),
        ["strip", size] => wh(size).map(|(w, h)| (2 * (w.saturating_add(1)) + 1).saturating_mul(h)),
        ["random", t, _, _] => t.trim().parse::<u64>().ok().map(|t| t.saturating_mul(3)),
        _ => None,
    }
}

fn parse_num<T: std::str::FromStr>(s: &str, field: &'static str, spec: &str) -> Result<T, MeshError> {
    s.trim().parse().map_err(|_| MeshError::BadNumber {
        field,
        value: s.to_string(),
        spec: spec.to_string(),
    })
}

fn nonzero(x: u64, field: &'static str, spec: &str) -> Result<(), MeshError> {
    if x == 0 {
        Err(MeshError::ZeroSize {
            field,
            spec: spec.to_string(),
        })
    } else {
        Ok(())
    }
}

fn check_indices(count: Option<u64>, spec: &str) -> Result<(), MeshError> {
    match count {
        Some(n) if n <= MAX_INDICES => Ok(()),
        _ => Err(MeshError::TooLarge {
            spec: spec.to_string(),
            indices: count.map_or_else(|| "more than 2^64".to_string(), |n| n.to_string()),
        }),
    }
}

fn check_vertices(vertices: u64, name: &str, what: &'static str) -> Result<(), MeshError> {
    if vertices > crate::limits::MAX_MESH_VERTICES {
        return Err(MeshError::TooManyVertices {
            name: name.to_string(),
            vertices,
            what,
        });
    }
    Ok(())
}

/// Parses `WxH` and checks that a grid of that size fits the index limit
/// (the limit also keeps every vertex id below [`RESTART`]).
fn parse_size(s: &str, spec: &str) -> Result<(u32, u32), MeshError> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| MeshError::BadNumber {
        field: "size (WxH)",
        value: s.to_string(),
        spec: spec.to_string(),
    })?;
    let w = parse_num::<u32>(w, "width", spec)?;
    let h = parse_num::<u32>(h, "height", spec)?;
    nonzero(u64::from(w), "width", spec)?;
    nonzero(u64::from(h), "height", spec)?;
    // A list needs 6 indices per quad; a strip fewer.
    check_indices(
        u64::from(w).checked_mul(u64::from(h)).and_then(|q| q.checked_mul(6)),
        spec,
    )?;
    Ok((w, h))
}

/// `W x H` quads, row by row, two triangles each.
fn grid(w: u32, h: u32, name: &str) -> Mesh {
    let row = w + 1;
    let mut indices = Vec::with_capacity(6 * w as usize * h as usize);
    for j in 0..h {
        for i in 0..w {
            let a = j * row + i;
            let (b, c) = (a + 1, a + row);
            let d = c + 1;
            indices.extend_from_slice(&[a, b, c, c, b, d]);
        }
    }
    Mesh {
        name: name.to_string(),
        topology: Topology::TriangleList,
        indices,
        vertex_count: row * (h + 1),
    }
}

/// The grid as one strip per row of quads, rows separated by restarts.
fn strip(w: u32, h: u32, name: &str) -> Mesh {
    let row = w + 1;
    let mut indices = Vec::with_capacity((2 * row as usize + 1) * h as usize);
    for j in 0..h {
        if j > 0 {
            indices.push(RESTART);
        }
        for i in 0..row {
            // Top then bottom vertex: the first triangle (i,j+1) (i,j) (i+1,j+1)
            // is counter-clockwise like the list's.
            indices.push((j + 1) * row + i);
            indices.push(j * row + i);
        }
    }
    Mesh {
        name: name.to_string(),
        topology: Topology::TriangleStrip,
        indices,
        vertex_count: row * (h + 1),
    }
}

/// Shuffles whole triangles of a list, deterministically from `seed`.
fn shuffle_triangles(indices: &mut Vec<u32>, seed: u64) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut tris: Vec<[u32; 3]> = indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    tris.shuffle(&mut rng);
    *indices = tris.into_iter().flatten().collect();
}

/// Shuffles the triangles of a list within consecutive windows of `window`
/// triangles (the last window may be shorter).
fn shuffle_within_windows(indices: &mut Vec<u32>, window: usize, seed: u64) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut tris: Vec<[u32; 3]> = indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    for chunk in tris.chunks_mut(window) {
        chunk.shuffle(&mut rng);
    }
    *indices = tris.into_iter().flatten().collect();
}

/// `t` triangles with vertices uniform over `0..v`.
fn random(t: u64, v: u32, seed: u64, name: &str) -> Mesh {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let indices = (0..3 * t).map(|_| rng.random_range(0..v)).collect();
    Mesh {
        name: name.to_string(),
        topology: Topology::TriangleList,
        indices,
        vertex_count: v,
    }
}

/// Loads an OBJ file's faces as one triangle list, keeping the file's vertex
/// numbering where faces reference positions only (see [`super::obj`]).
fn load_obj(path: &Path, name: &str) -> Result<Mesh, MeshError> {
    let file = crate::limits::open_input(path, crate::limits::InputKind::Data).map_err(|source| MeshError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let t = read_obj(std::io::BufReader::new(file)).map_err(|f| MeshError::Obj {
        path: path.to_path_buf(),
        line: f.line,
        source: f.error,
    })?;
    finish_file(path, name, t.indices, t.vertex_count)
}

/// Loads whitespace-separated triangle-list indices (`#` starts a comment).
fn load_idx(path: &Path, name: &str) -> Result<Mesh, MeshError> {
    let text =
        crate::limits::read_input_string(path, crate::limits::InputKind::Data).map_err(|source| MeshError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    let mut indices = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let content = line.split('#').next().unwrap_or("");
        for token in content.split_whitespace() {
            match token.parse::<u32>() {
                Ok(i) if i != RESTART => {
                    if indices.len() as u64 >= MAX_INDICES {
                        return Err(MeshError::TooLarge {
                            spec: format!("{} (at line {})", path.display(), n + 1),
                            indices: format!("at least {}", MAX_INDICES + 1),
                        });
                    }
                    indices.push(i)
                }
                _ => {
                    return Err(MeshError::IdxToken {
                        path: path.to_path_buf(),
                        line: n + 1,
                        token: token.to_string(),
                    });
                }
            }
        }
    }
    if !indices.len().is_multiple_of(3) {
        return Err(MeshError::NotMultipleOfThree {
            name: path.display().to_string(),
            count: indices.len(),
        });
    }
    let vertex_count = indices.iter().max().map_or(0, |m| m + 1);
    finish_file(path, name, indices, vertex_count)
}

fn finish_file(path: &Path, name: &str, indices: Vec<u32>, vertex_count: u32) -> Result<Mesh, MeshError> {
    if indices.len() < 3 {
        return Err(MeshError::Empty(path.display().to_string()));
    }
    check_indices(Some(indices.len() as u64), &path.display().to_string())?;
    let what = if name.to_ascii_lowercase().ends_with(".idx") {
        " (its largest index + 1)"
    } else {
        " (its `v` lines, or distinct corners)"
    };
    check_vertices(u64::from(vertex_count), &path.display().to_string(), what)?;
    let mesh = Mesh {
        name: name.to_string(),
        topology: Topology::TriangleList,
        indices,
        vertex_count,
    };
    mesh.validate()?;
    Ok(mesh)
}

#[cfg(test)]
mod tests;
