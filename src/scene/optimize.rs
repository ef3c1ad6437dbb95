//! Vertex-cache-aware triangle reordering.
//!
//! Paper 000 (section 4.5) notes that the number of actually transformed
//! vertices can be minimized by reordering triangles for the post-transform
//! cache. This module implements Tom Forsyth's "Linear-Speed Vertex Cache
//! Optimisation" (2006): a greedy walk that repeatedly emits the triangle
//! whose vertices score highest, where a vertex scores for being recently used
//! (its position in a simulated LRU cache of [`CACHE_SIZE`] entries) and for
//! having few triangles left (so that no vertex is left stranded).
//!
//! When no triangle around the cached vertices remains, the walk restarts
//! from the first not yet emitted triangle in input order, which keeps the
//! whole run linear in the triangle count.

/// The cache size the scores are tuned for.
pub const CACHE_SIZE: usize = 32;

const CACHE_DECAY_POWER: f32 = 1.5;
const LAST_TRI_SCORE: f32 = 0.75;
const VALENCE_BOOST_SCALE: f32 = 2.0;
const VALENCE_BOOST_POWER: f32 = 0.5;

/// Forsyth's vertex score from its cache position (`None` = not cached) and
/// the number of triangles still to be emitted that use it.
fn vertex_score(cache_pos: Option<usize>, remaining: u32) -> f32 {
    if remaining == 0 {
        // Nothing left to draw with this vertex.
        return -1.0;
    }
    let cache = match cache_pos {
        None => 0.0,
        // The last triangle's vertices: a fixed score, so the walk does not
        // prefer re-using exactly the same edge.
        Some(p) if p < 3 => LAST_TRI_SCORE,
        Some(p) => {
            let scale = 1.0 / (CACHE_SIZE - 3) as f32;
            (1.0 - (p - 3) as f32 * scale).powf(CACHE_DECAY_POWER)
        }
    };
    cache + VALENCE_BOOST_SCALE * (remaining as f32).powf(-VALENCE_BOOST_POWER)
}

/// Reorders the triangles of an indexed triangle list for a post-transform
/// vertex cache (Forsyth's algorithm, cache size 32). The result holds the
/// same triangles, each with its vertices in the same order.
///
/// Works on any triangle list; indices at or above `vertex_count` are
/// tolerated (the count is widened), and a trailing partial triangle is
/// appended unchanged.
pub fn optimize_vertex_cache(indices: &[u32], vertex_count: u32) -> Vec<u32> {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn sorted_tris(ix: &[u32]) -> Vec<[u32; 3]> {
        let mut v: Vec<[u32; 3]> = ix.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        v.sort_unstable();
        v
    }

    #[test]
    fn keeps_the_same_triangles() {
        let ix = [0, 1, 2, 2, 1, 3, 4, 5, 6, 6, 5, 7, 0, 2, 4, 9, 9, 9];
        let out = optimize_vertex_cache(&ix, 10);
        assert_eq!(out.len(), ix.len());
        assert_eq!(sorted_tris(&out), sorted_tris(&ix));
    }

    #[test]
    fn tolerates_odd_input() {
        assert!(optimize_vertex_cache(&[], 0).is_empty());
        // Index beyond vertex_count and a trailing partial triangle.
        let out = optimize_vertex_cache(&[0, 1, 5, 7], 2);
        assert_eq!(out, [0, 1, 5, 7]);
    }

    #[test]
    fn scores_follow_forsyth() {
        assert_eq!(vertex_score(Some(0), 0), -1.0);
        assert!((vertex_score(Some(1), 1) - (0.75 + 2.0)).abs() < 1e-6);
        assert!((vertex_score(Some(3), 4) - (1.0 + 1.0)).abs() < 1e-6);
        assert!(vertex_score(Some(31), 4) < vertex_score(Some(10), 4));
        assert!(vertex_score(None, 1) > vertex_score(None, 9));
    }
}
