//! Post-transform vertex cache policies.
//!
//! Wimmer & Wonka (paper 000, section 2 and Figure 1) price geometry by the
//! number of *actually transformed vertices*: indices whose vertex is not found
//! in the GPU's post-transform cache and so is fetched and run through the
//! vertex shader. Section 4.5 obtains that number from a FIFO cache
//! simulation. [`VertexCache`] is that simulation, for several policies;
//! [`CacheStats`] summarizes a run.
//!
//! Every policy's logic lives in `match` arms inside [`VertexCache`], so new
//! policies are new variants of [`CachePolicy`] plus one arm per method.

use std::collections::HashMap;

use serde::{Deserialize, Serialize};

pub mod analyzer;
mod policy;

pub use policy::{CachePolicy, CachePolicyError, NVIDIA_LOOKBACK};

/// Indices below this use a dense stamp array; larger ones (sparse, huge
/// vertex ids from user files) go to a hash map so memory stays bounded.
const DENSE_LIMIT: usize = 1 << 24;

/// Fast path for whole triangle lists: meshoptimizer's analyser loop
/// ([`analyzer::analyze`]).
pub use analyzer::analyze as analyze_triangle_list;

/// A simulated post-transform vertex cache.
///
/// Two triangles sharing an edge transform 4 vertices through any cache,
/// 6 without one. Through a FIFO of 3, a triangle of new vertices pushes the
/// first one's out: drawing it again transforms all three again; a FIFO of
/// 6 keeps them.
///
/// ```
/// use rendersim_models::components::vertex_cache::{CachePolicy, VertexCache};
///
/// let transformed = |policy: &str, tris: &[[u32; 3]]| {
///     let policy: CachePolicy = policy.parse().unwrap();
///     let mut cache = VertexCache::new(&policy, 8);
///     tris.iter().map(|&t| u64::from(cache.access_triangle(t))).sum::<u64>()
/// };
/// let quad = [[0, 1, 2], [2, 1, 3]];
/// assert_eq!(transformed("fifo:3", &quad), 4);
/// assert_eq!(transformed("none", &quad), 6);
/// let again = [[0, 1, 2], [3, 4, 5], [0, 1, 2]];
/// assert_eq!(transformed("fifo:3", &again), 9);
/// assert_eq!(transformed("fifo:6", &again), 6);
/// ```
#[derive(Clone, Debug)]
pub struct VertexCache {
    policy: CachePolicy,
    /// FIFO: per-vertex insertion stamp (the miss counter after insertion).
    /// Lookback: 1 + the stream position of the vertex's last index.
    stamps: Vec<u64>,
    /// FIFO, lookback: stamps of vertices with ids beyond the dense array.
    sparse: HashMap<u32, u64>,
    /// FIFO: number of insertions so far. Lookback: indices read so far.
    now: u64,
    /// FIFO: value of `now` at the last reset; older stamps are invalid.
    /// Lookback: the position where the current batch began.
    epoch: u64,
    /// LRU: the cached vertices, most recent first.
    lru: Vec<u32>,
    /// Triangle-level policies: meshoptimizer's per-vertex 32-bit timestamps
    /// (wrapping arithmetic, as in its C code), the clock, and the current
    /// warp's vertices and triangles.
    tri: TriangleState,
}

#[derive(Clone, Debug, Default)]
struct TriangleState {
    stamps: Vec<u32>,
    /// Direct-mapped: the slots written since the last flush (at most as
    /// many as there are slots; past that, `dirty_all`), so a flush costs
    /// what the segment wrote, not every slot: `direct:1048576,1` flushed a
    /// million slots per triangle.
    dirty: Vec<u32>,
    dirty_all: bool,
    sparse: HashMap<u32, u32>,
    timestamp: u32,
    warp_offset: u32,
    prim_offset: u32,
    warps: u64,
}

impl TriangleState {
    #[inline]
    fn stamp(&self, v: u32) -> u32 {
        match self.stamps.get(v as usize) {
            Some(s) => *s,
            None => self.sparse.get(&v).copied().unwrap_or(0),
        }
    }

    #[inline]
    fn set_stamp(&mut self, v: u32, t: u32) {
        let i = v as usize;
        if i >= self.stamps.len() && i < DENSE_LIMIT {
            let len = (i + 1).max(2 * self.stamps.len()).min(DENSE_LIMIT);
            self.stamps.resize(len, 0);
        }
        match self.stamps.get_mut(i) {
            Some(s) => *s = t,
            None => {
                self.sparse.insert(v, t);
            }
        }
    }
}

impl VertexCache {
    /// An empty cache; `vertex_count_hint` presizes the FIFO stamp array.
    pub fn new(policy: &CachePolicy, vertex_count_hint: usize) -> Self {
        let (stamps, lru) = match policy {
            CachePolicy::None
            | CachePolicy::Meshopt { .. }
            | CachePolicy::Batch { .. }
            | CachePolicy::Direct { .. }
            | CachePolicy::Lavapipe => (Vec::new(), Vec::new()),
            CachePolicy::Fifo(_) | CachePolicy::Lookback { .. } | CachePolicy::Nvidia => {
                (vec![0; vertex_count_hint.min(DENSE_LIMIT)], Vec::new())
            }
            CachePolicy::Lru(n) => (Vec::new(), Vec::with_capacity((*n as usize).min(1024))),
        };
        let tri = match policy {
            CachePolicy::Meshopt { cache, .. } => TriangleState {
                stamps: vec![0; vertex_count_hint.min(DENSE_LIMIT)],
                timestamp: cache.wrapping_add(1),
                ..TriangleState::default()
            },
            CachePolicy::Batch { vertices, .. } => TriangleState {
                stamps: vec![0; vertex_count_hint.min(DENSE_LIMIT)],
                timestamp: vertices.wrapping_add(1),
                ..TriangleState::default()
            },
            CachePolicy::Direct { slots, .. } => TriangleState {
                stamps: vec![u32::MAX; *slots as usize],
                ..TriangleState::default()
            },
            CachePolicy::Lavapipe => TriangleState {
                stamps: vec![u32::MAX; 256],
                ..TriangleState::default()
            },
            _ => TriangleState::default(),
        };
        VertexCache {
            policy: policy.clone(),
            stamps,
            sparse: HashMap::new(),
            now: 0,
            epoch: 0,
            lru,
            tri,
        }
    }

    /// The policy this cache simulates.
    pub fn policy(&self) -> &CachePolicy {
        &self.policy
    }

    /// Empties the cache (O(1) for FIFO).
    pub fn reset(&mut self) {
        match self.policy {
            CachePolicy::None => {}
            CachePolicy::Fifo(_) => {
                self.epoch = self.now;
                self.sparse.clear();
            }
            CachePolicy::Lru(_) => self.lru.clear(),
            CachePolicy::Meshopt { .. } | CachePolicy::Batch { .. } => self.flush_warp(),
            CachePolicy::Direct { .. } | CachePolicy::Lavapipe => self.flush_direct(),
            CachePolicy::Lookback { .. } | CachePolicy::Nvidia => self.flush_lookback(),
        }
    }

    /// True for policies that decide per triangle (warps, batches): use
    /// [`VertexCache::access_triangle`] with them.
    pub fn is_triangle_level(&self) -> bool {
        matches!(
            self.policy,
            CachePolicy::Meshopt { .. }
                | CachePolicy::Batch { .. }
                | CachePolicy::Direct { .. }
                | CachePolicy::Lavapipe
                | CachePolicy::Lookback { .. }
                | CachePolicy::Nvidia
        )
    }

    /// (slots, triangles per segment) of a direct-mapped policy.
    fn direct_params(&self) -> Option<(u32, u32)> {
        match self.policy {
            CachePolicy::Direct { slots, segment } => Some((slots, segment)),
            CachePolicy::Lavapipe => Some((256, 341)),
            _ => None,
        }
    }

    /// (vertices, triangles, window) of a lookback policy.
    fn lookback_params(&self) -> Option<(u32, u32, u32)> {
        match self.policy {
            CachePolicy::Lookback {
                vertices,
                triangles,
                window,
            } => Some((vertices, triangles, window)),
            CachePolicy::Nvidia => Some(NVIDIA_LOOKBACK),
            _ => None,
        }
    }

    /// The per-vertex stamp (FIFO: insertion count; lookback: 1 + last
    /// position); 0 = never seen.
    #[inline]
    fn stamp64(&self, v: u32) -> u64 {
        match self.stamps.get(v as usize) {
            Some(s) => *s,
            None => self.sparse.get(&v).copied().unwrap_or(0),
        }
    }

    /// Sets the per-vertex stamp, growing the dense array up to
    /// [`DENSE_LIMIT`] and keeping larger ids in the hash map.
    #[inline]
    fn set_stamp64(&mut self, v: u32, stamp: u64) {
        let i = v as usize;
        if i >= self.stamps.len() && i < DENSE_LIMIT {
            let len = (i + 1).max(2 * self.stamps.len()).min(DENSE_LIMIT);
            self.stamps.resize(len, 0);
        }
        match self.stamps.get_mut(i) {
            Some(s) => *s = stamp,
            None => {
                self.sparse.insert(v, stamp);
            }
        }
    }

    /// Closes the current lookback batch; the next index starts a new one.
    fn flush_lookback(&mut self) {
        self.tri.warps += u64::from(self.tri.warp_offset > 0);
        self.tri.warp_offset = 0;
        self.tri.prim_offset = 0;
        self.epoch = self.now;
        // Every sparse entry predates the new batch.
        self.sparse.clear();
    }

    /// Lookback: whether vertex `v`, read `offset` indices after the next
    /// stream position, occurred in the current batch among the previous
    /// `window` indices.
    #[inline]
    fn lookback_hit(&self, v: u32, offset: u64, window: u32) -> bool {
        let last = self.stamp64(v);
        last > self.epoch && self.now + offset - (last - 1) <= u64::from(window)
    }

    /// Lookback: how many of `tri`'s vertices would be shaded if the triangle
    /// joined the current batch (a vertex repeated inside the triangle once).
    fn lookback_misses(&self, tri: [u32; 3], window: u32) -> u32 {
        (0..3)
            .filter(|&j| !tri[..j].contains(&tri[j]) && !self.lookback_hit(tri[j], j as u64, window))
            .count() as u32
    }

    /// Lookback: one triangle; starts a new batch first when the current one
    /// has `triangles` triangles or cannot take the triangle's new vertices.
    fn lookback_triangle(&mut self, tri: [u32; 3], (vertices, triangles, window): (u32, u32, u32)) -> u8 {
        let mut m = self.lookback_misses(tri, window);
        if self.tri.prim_offset == triangles || u64::from(self.tri.warp_offset) + u64::from(m) > u64::from(vertices) {
            self.flush_lookback();
            m = self.lookback_misses(tri, window);
        }
        for (j, &v) in tri.iter().enumerate() {
            self.set_stamp64(v, self.now + j as u64 + 1);
        }
        self.now += 3;
        self.tri.warp_offset += m;
        self.tri.prim_offset += 1;
        m as u8
    }

    fn flush_direct(&mut self) {
        let t = &mut self.tri;
        if t.dirty_all {
            t.stamps.iter_mut().for_each(|s| *s = u32::MAX);
        } else {
            for &i in &t.dirty {
                t.stamps[i as usize] = u32::MAX;
            }
        }
        t.dirty.clear();
        t.dirty_all = false;
        self.tri.warps += u64::from(self.tri.prim_offset > 0);
        self.tri.prim_offset = 0;
        self.tri.warp_offset = 0;
    }

    /// One vertex through a direct-mapped cache (slot array in `tri.stamps`;
    /// `u32::MAX` = empty). True on a miss.
    #[inline]
    fn direct_access(&mut self, v: u32) -> bool {
        let t = &mut self.tri;
        let slots = t.stamps.len() as u32;
        let i = v % slots;
        let slot = &mut t.stamps[i as usize];
        if *slot == v && v != u32::MAX {
            false
        } else {
            *slot = v;
            t.warp_offset += 1;
            if t.dirty.len() < t.stamps.len() {
                t.dirty.push(i);
            } else {
                t.dirty_all = true;
            }
            true
        }
    }

    /// (cache entries, warp vertices, triangles per group) of a
    /// triangle-level policy; `batch:V,T` is `meshopt:V,V,T` (a cache that
    /// holds a whole batch never evicts inside it).
    fn triangle_params(&self) -> (u32, u32, u32) {
        match self.policy {
            CachePolicy::Meshopt { cache, warp, primgroup } => (cache, warp, primgroup),
            CachePolicy::Batch { vertices, triangles } => (vertices, vertices, triangles),
            _ => (0, 0, 0),
        }
    }

    fn flush_warp(&mut self) {
        let (cache, _, _) = self.triangle_params();
        let t = &mut self.tri;
        t.warps += u64::from(t.warp_offset > 0);
        t.warp_offset = 0;
        t.prim_offset = 0;
        t.timestamp = t.timestamp.wrapping_add(cache.wrapping_add(1));
    }

    /// Warps (batches) executed so far, counting the current one if it has
    /// any vertex. Zero for per-index policies.
    pub fn warps(&self) -> u64 {
        self.tri.warps + u64::from(self.tri.warp_offset > 0)
    }

    /// Processes one triangle; returns how many of its vertices were
    /// transformed (0 to 3). For `meshopt:` and `batch:` this is
    /// meshoptimizer's `meshopt_analyzeVertexCache` step, including its
    /// 32-bit wrapping timestamps; `direct:`/`lavapipe` flush every segment
    /// and `lookback:`/`nvidia` cut batches as [`CachePolicy::Lookback`]
    /// says; for the per-index policies it is three [`VertexCache::access`]
    /// calls.
    #[inline]
    pub fn access_triangle(&mut self, tri: [u32; 3]) -> u8 {
        if !self.is_triangle_level() {
            return u8::from(self.access(tri[0])) + u8::from(self.access(tri[1])) + u8::from(self.access(tri[2]));
        }
        if let Some(params) = self.lookback_params() {
            return self.lookback_triangle(tri, params);
        }
        if let Some((_, segment)) = self.direct_params() {
            if self.tri.prim_offset == segment {
                self.flush_direct();
            }
            self.tri.prim_offset += 1;
            return u8::from(self.direct_access(tri[0]))
                + u8::from(self.direct_access(tri[1]))
                + u8::from(self.direct_access(tri[2]));
        }
        let (cache, warp, primgroup) = self.triangle_params();
        let miss = |t: &TriangleState, v: u32| t.timestamp.wrapping_sub(t.stamp(v)) > cache;
        let m = u32::from(miss(&self.tri, tri[0]))
            + u32::from(miss(&self.tri, tri[1]))
            + u32::from(miss(&self.tri, tri[2]));
        if (primgroup != 0 && self.tri.prim_offset == primgroup) || (warp != 0 && self.tri.warp_offset + m > warp) {
            self.flush_warp();
        }
        let mut transformed = 0u8;
        for v in tri {
            if miss(&self.tri, v) {
                let t = self.tri.timestamp;
                self.tri.set_stamp(v, t);
                self.tri.timestamp = t.wrapping_add(1);
                self.tri.warp_offset += 1;
                transformed += 1;
            }
        }
        self.tri.prim_offset += 1;
        transformed
    }

    /// Looks up vertex `index`; returns `true` on a miss (the vertex is
    /// fetched and transformed, then cached).
    ///
    /// Triangle-level policies given single indices behave as a FIFO of
    /// their cache size (no warp or batch limits); lookback policies reuse
    /// within their window of indices, with no batch limits.
    pub fn access(&mut self, index: u32) -> bool {
        if let Some((_, _, window)) = self.lookback_params() {
            let hit = self.lookback_hit(index, 0, window);
            self.now += 1;
            self.set_stamp64(index, self.now);
            return !hit;
        }
        match self.policy {
            CachePolicy::Direct { .. } | CachePolicy::Lavapipe => self.direct_access(index),
            CachePolicy::Meshopt { .. } | CachePolicy::Batch { .. } => {
                let (cache, _, _) = self.triangle_params();
                let t = &mut self.tri;
                if t.timestamp.wrapping_sub(t.stamp(index)) > cache {
                    let now = t.timestamp;
                    t.set_stamp(index, now);
                    t.timestamp = now.wrapping_add(1);
                    true
                } else {
                    false
                }
            }
            CachePolicy::None | CachePolicy::Lookback { .. } | CachePolicy::Nvidia => true,
            CachePolicy::Fifo(n) => {
                let stamp = self.stamp64(index);
                // Valid since the last reset and fewer than n insertions ago.
                if stamp > self.epoch && self.now - stamp < u64::from(n) {
                    return false;
                }
                self.now += 1;
                self.set_stamp64(index, self.now);
                true
            }
            CachePolicy::Lru(n) => {
                if let Some(pos) = self.lru.iter().position(|&v| v == index) {
                    self.lru[..=pos].rotate_right(1);
                    false
                } else {
                    if self.lru.len() >= n as usize {
                        self.lru.pop();
                    }
                    self.lru.insert(0, index);
                    true
                }
            }
        }
    }
}

/// Counts from simulating a vertex cache over an index stream.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct CacheStats {
    /// Indices fetched (restart markers excluded).
    pub indices: u64,
    /// Triangles assembled.
    pub triangles: u64,
    /// Distinct vertices referenced.
    pub unique_vertices: u64,
    /// Actually transformed vertices (cache misses).
    pub transformed: u64,
}

impl CacheStats {
    /// Average cache miss ratio: transformed vertices per triangle (0 for no
    /// triangles).
    pub fn acmr(&self) -> f64 {
        if self.triangles == 0 {
            0.0
        } else {
            self.transformed as f64 / self.triangles as f64
        }
    }

    /// Average transform to vertex ratio: transformed per unique vertex
    /// (1.0 is optimal; 0 for no vertices).
    pub fn atvr(&self) -> f64 {
        if self.unique_vertices == 0 {
            0.0
        } else {
            self.transformed as f64 / self.unique_vertices as f64
        }
    }
}

#[cfg(test)]
mod tests;
