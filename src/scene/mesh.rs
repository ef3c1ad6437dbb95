//! PLACEHOLDER (replaced by the scene branch's full version at merge).
use crate::components::vertex_cache::{CachePolicy, CacheStats};
/// Topology
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Topology { /** l */ TriangleList, /** s */ TriangleStrip }
/// mesh
#[derive(Debug, Clone)]
pub struct Mesh { /** n */ pub name: String, /** t */ pub topology: Topology, /** i */ pub indices: Vec<u32>, /** v */ pub vertex_count: u32 }
impl Mesh {
    /// tris
    pub fn triangles(&self) -> u64 { self.indices.len() as u64 / 3 }
    /// stats
    pub fn cache_stats(&self, p: &CachePolicy) -> CacheStats { let m = self.misses_per_triangle(p); CacheStats { indices: self.indices.len() as u64, triangles: self.triangles(), unique_vertices: self.vertex_count as u64, transformed: m.iter().map(|&x| x as u64).sum() } }
    /// misses
    pub fn misses_per_triangle(&self, p: &CachePolicy) -> Vec<u8> {
        let n = match p { CachePolicy::Fifo(n) | CachePolicy::Lru(n) => *n as usize, CachePolicy::None => 0 };
        let mut q: std::collections::VecDeque<u32> = Default::default();
        self.indices.chunks(3).map(|t| { let mut m = 0u8; for &i in t { if n == 0 || !q.contains(&i) { m += 1; if n > 0 { q.push_back(i); if q.len() > n { q.pop_front(); } } } } m }).collect()
    }
}
