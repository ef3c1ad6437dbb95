//! The first, direct implementation of Forsyth's reordering (see
//! [`super`]), kept unchanged as the oracle: the tests check that
//! [`super::optimize_vertex_cache`] returns exactly its index buffer, and
//! `rendersim bench build` times one against the other.

use super::{CACHE_SIZE, vertex_score};

/// [`super::optimize_vertex_cache`] in its first, direct form: the same
/// walk, scoring every vertex with `powf` and every candidate triangle each
/// time it is met. The reference the fast form is tested and benchmarked
/// against (`rendersim bench build`); its output is the same, byte for byte.
///
/// Works on any triangle list; indices at or above `vertex_count` are
/// tolerated (the count is widened), and a trailing partial triangle is
/// appended unchanged.
pub fn optimize_vertex_cache_reference(indices: &[u32], vertex_count: u32) -> Vec<u32> {
    let tri_count = indices.len() / 3;
    let tris = &indices[..3 * tri_count];
    let vcount = tris
        .iter()
        .map(|&i| i as usize + 1)
        .max()
        .unwrap_or(0)
        .max(vertex_count as usize);

    // Vertex -> triangles adjacency (CSR); each vertex's first `remaining[v]`
    // entries are the triangles not yet emitted.
    let mut remaining = vec![0u32; vcount];
    for &v in tris {
        remaining[v as usize] += 1;
    }
    let mut offsets = vec![0usize; vcount + 1];
    for v in 0..vcount {
        offsets[v + 1] = offsets[v] + remaining[v] as usize;
    }
    let mut adjacency = vec![0u32; tris.len()];
    let mut fill = offsets.clone();
    for (t, tri) in tris.chunks_exact(3).enumerate() {
        for &v in tri {
            adjacency[fill[v as usize]] = t as u32;
            fill[v as usize] += 1;
        }
    }

    let mut cache_pos: Vec<Option<usize>> = vec![None; vcount];
    let mut score: Vec<f32> = (0..vcount).map(|v| vertex_score(None, remaining[v])).collect();
    let tri_score =
        |score: &[f32], t: usize| -> f32 { tris[3 * t..3 * t + 3].iter().map(|&v| score[v as usize]).sum() };
    let mut emitted = vec![false; tri_count];
    let mut best = (0..tri_count)
        .map(|t| (t, tri_score(&score, t)))
        .fold(None::<(usize, f32)>, |acc, (t, s)| match acc {
            Some((_, bs)) if bs >= s => acc,
            _ => Some((t, s)),
        })
        .map(|(t, _)| t);

    let mut out = Vec::with_capacity(indices.len());
    let mut cache: Vec<u32> = Vec::with_capacity(CACHE_SIZE + 3);
    let mut next_cache: Vec<u32> = Vec::with_capacity(CACHE_SIZE + 3);
    let mut cursor = 0usize;

    while let Some(t) = best {
        emitted[t] = true;
        let tri = &tris[3 * t..3 * t + 3];
        out.extend_from_slice(tri);

        // Remove the triangle from its vertices' live adjacency.
        for &v in tri {
            let v = v as usize;
            let live = &mut adjacency[offsets[v]..offsets[v] + remaining[v] as usize];
            if let Some(k) = live.iter().position(|&x| x as usize == t) {
                let last = live.len() - 1;
                live.swap(k, last);
                remaining[v] -= 1;
            }
        }

        // Move the triangle's vertices to the front of the LRU cache.
        next_cache.clear();
        for &v in tri {
            if !next_cache.contains(&v) {
                next_cache.push(v);
            }
        }
        next_cache.extend(cache.iter().copied().filter(|v| !tri.contains(v)));
        std::mem::swap(&mut cache, &mut next_cache);

        // Update the scores of cached and evicted vertices.
        for (p, &v) in cache.iter().enumerate() {
            let v = v as usize;
            let pos = (p < CACHE_SIZE).then_some(p);
            cache_pos[v] = pos;
            score[v] = vertex_score(pos, remaining[v]);
        }
        cache.truncate(CACHE_SIZE);

        // The best triangle around the cached vertices.
        best = None;
        let mut best_score = f32::NEG_INFINITY;
        for &v in &cache {
            let v = v as usize;
            for &n in &adjacency[offsets[v]..offsets[v] + remaining[v] as usize] {
                let s = tri_score(&score, n as usize);
                if s > best_score {
                    best_score = s;
                    best = Some(n as usize);
                }
            }
        }
        if best.is_none() {
            while cursor < tri_count && emitted[cursor] {
                cursor += 1;
            }
            best = (cursor < tri_count).then_some(cursor);
        }
    }

    out.extend_from_slice(&indices[3 * tri_count..]);
    out
}
