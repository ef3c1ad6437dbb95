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
//!
//! [`optimize_vertex_cache`] is the fast form; `reference` keeps the
//! first, direct form, which it must match byte for byte (the tests and
//! `rendersim bench build` compare them).

/// The cache size the scores are tuned for.
pub const CACHE_SIZE: usize = 32;

const CACHE_DECAY_POWER: f32 = 1.5;
const LAST_TRI_SCORE: f32 = 0.75;
const VALENCE_BOOST_SCALE: f32 = 2.0;
const VALENCE_BOOST_POWER: f32 = 0.5;

mod reference;
pub use reference::optimize_vertex_cache_reference;

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

/// Valences up to this many live triangles score from [`ScoreTable`];
/// higher ones (random meshes, fans) call [`vertex_score`].
const TABLE_VALENCE: usize = 32;

/// [`vertex_score`] for cache positions `0..CACHE_SIZE` (row `CACHE_SIZE`:
/// not cached) and `0..=TABLE_VALENCE` live triangles: the same `f32`
/// values, computed once instead of two `powf` per vertex per step.
struct ScoreTable([[f32; TABLE_VALENCE + 1]; CACHE_SIZE + 1]);

impl ScoreTable {
    fn new() -> Self {
        let mut t = [[0.0f32; TABLE_VALENCE + 1]; CACHE_SIZE + 1];
        for (p, row) in t.iter_mut().enumerate() {
            for (r, s) in row.iter_mut().enumerate() {
                // black_box: computed at run time by the same `powf` as the
                // scores it stands for, never folded by the compiler.
                let (p, r) = std::hint::black_box((p, r as u32));
                *s = vertex_score((p < CACHE_SIZE).then_some(p), r);
            }
        }
        ScoreTable(t)
    }

    /// The score at cache position `p` (`CACHE_SIZE` or more: not cached)
    /// with `remaining` live triangles.
    #[inline]
    fn get(&self, p: usize, remaining: u32) -> f32 {
        let p = p.min(CACHE_SIZE);
        match self.0[p].get(remaining as usize) {
            Some(&s) => s,
            None => vertex_score((p < CACHE_SIZE).then_some(p), remaining),
        }
    }
}

/// Reorders the triangles of an indexed triangle list for a post-transform
/// vertex cache (Forsyth's algorithm, cache size 32). The result holds the
/// same triangles, each with its vertices in the same order.
///
/// Works on any triangle list; indices at or above `vertex_count` are
/// tolerated (the count is widened), and a trailing partial triangle is
/// appended unchanged.
///
/// The output is byte for byte that of
/// [`optimize_vertex_cache_reference`], the direct form, several times
/// faster (`rendersim bench build`): vertex scores come from a table
/// (`ScoreTable`) instead of two `powf` each; each vertex's live
/// triangles are one `[start, len]` pair into a flat adjacency array; the
/// cache keeps only the vertices that still have live triangles (about 12
/// of the 32 in a grid), with their positions, so the rest are neither
/// rescored nor scanned; and a triangle around several cached vertices is
/// scored once per step. The walk still keeps the first triangle of the
/// highest score in the same scan order, so every tie breaks the same way.
pub fn optimize_vertex_cache(indices: &[u32], vertex_count: u32) -> Vec<u32> {
    let (tris, rest) = indices.as_chunks::<3>();
    let tri_count = tris.len();
    if indices.len() > u32::MAX as usize {
        // Offsets into the adjacency array are u32.
        return optimize_vertex_cache_reference(indices, vertex_count);
    }
    let vcount = tris
        .as_flattened()
        .iter()
        .map(|&i| i as usize + 1)
        .max()
        .unwrap_or(0)
        .max(vertex_count as usize);

    // live[v] = [start, len]: the triangles using vertex v not yet emitted
    // are adjacency[start..start + len] (CSR).
    let mut live = vec![[0u32; 2]; vcount];
    for tri in tris {
        for &v in tri {
            live[v as usize][1] += 1;
        }
    }
    let mut fill = Vec::with_capacity(vcount);
    let mut start = 0u32;
    for l in &mut live {
        l[0] = start;
        fill.push(start);
        start += l[1];
    }
    let mut adjacency = vec![0u32; 3 * tri_count];
    for (t, tri) in tris.iter().enumerate() {
        for &v in tri {
            let f = &mut fill[v as usize];
            adjacency[*f as usize] = t as u32;
            *f += 1;
        }
    }
    drop(fill);

    let table = ScoreTable::new();
    let mut score: Vec<f32> = live.iter().map(|l| table.get(CACHE_SIZE, l[1])).collect();
    let tri_score = |score: &[f32], tri: &[u32; 3]| -> f32 {
        score[tri[0] as usize] + score[tri[1] as usize] + score[tri[2] as usize]
    };
    let mut emitted = vec![false; tri_count];
    // The first triangle of the highest score.
    let mut best = None;
    let mut best_score = f32::NEG_INFINITY;
    for (t, tri) in tris.iter().enumerate() {
        let s = tri_score(&score, tri);
        if best.is_none() || s > best_score {
            best = Some(t);
            best_score = s;
        }
    }

    let mut out = Vec::with_capacity(indices.len());
    // The cached vertices that still have live triangles, with their
    // positions in the LRU cache (most recent first, so ascending). A cached
    // vertex with none left still holds its position, but it is never
    // scored or scanned again, so only the positions of the others say it
    // is there.
    let mut cache: Vec<(u32, u32)> = Vec::with_capacity(CACHE_SIZE + 3);
    let mut next_cache: Vec<(u32, u32)> = Vec::with_capacity(CACHE_SIZE + 3);
    // The step at which each triangle was last scored (0: never).
    let mut seen = vec![0u32; tri_count];
    let mut step = 0u32;
    let mut cursor = 0usize;

    while let Some(t) = best {
        step += 1;
        emitted[t] = true;
        let tri = tris[t];
        out.extend_from_slice(&tri);

        // Remove the triangle from its vertices' live adjacency.
        for &v in &tri {
            let [start, len] = &mut live[v as usize];
            let adj = &mut adjacency[*start as usize..(*start + *len) as usize];
            if let Some(k) = adj.iter().position(|&x| x as usize == t) {
                adj.swap(k, adj.len() - 1);
                *len -= 1;
            }
        }

        // Move the triangle's distinct vertices to the front of the LRU
        // cache (positions 0, 1, 2): every other entry moves down by their
        // number, less those of them that were cached before it; entries
        // pushed to CACHE_SIZE or past are evicted. Rescore the moved ones.
        next_cache.clear();
        let mut k = 0u32;
        for (i, &v) in tri.iter().enumerate() {
            if !tri[..i].contains(&v) {
                let len = live[v as usize][1];
                if len > 0 {
                    next_cache.push((v, k));
                    score[v as usize] = table.get(k as usize, len);
                }
                k += 1;
            }
        }
        let mut before = 0u32;
        for &(v, q) in &cache {
            if v == tri[0] || v == tri[1] || v == tri[2] {
                before += 1;
                continue;
            }
            let p = k + q - before;
            score[v as usize] = table.get(p as usize, live[v as usize][1]);
            if (p as usize) < CACHE_SIZE {
                next_cache.push((v, p));
            }
        }
        std::mem::swap(&mut cache, &mut next_cache);

        // The best triangle around the cached vertices: the first of the
        // highest score in cache order. A triangle met again has the same
        // score, so it could not replace itself or an earlier one: it is
        // skipped.
        best = None;
        let mut best_score = f32::NEG_INFINITY;
        for &(v, _) in &cache {
            let [start, len] = live[v as usize];
            for &c in &adjacency[start as usize..(start + len) as usize] {
                let c = c as usize;
                if seen[c] == step {
                    continue;
                }
                seen[c] = step;
                let sc = tri_score(&score, &tris[c]);
                if sc > best_score {
                    best_score = sc;
                    best = Some(c);
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

    out.extend_from_slice(rest);
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
