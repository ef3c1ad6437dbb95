//! Index buffers: indexed triangle lists and strips, and their vertex cost.
//!
//! Follows Wimmer & Wonka (paper 000), section 2 and Figure 1: for an indexed
//! triangle strip we count *polygons* (triangles), *indices* (restart markers
//! excluded), *vertices* (three per triangle) and *actually transformed
//! vertices* (post-transform cache misses). Section 4.5 obtains the last from
//! a FIFO cache simulation over the index stream, which
//! [`Mesh::cache_stats`] performs for any [`CachePolicy`].
//!
//! Strips use primitive restart ([`RESTART`]). A restart starts a new run of
//! the strip but does not flush the vertex cache. A run shorter than three
//! indices forms no triangle; we assume the GPU's primitive assembly drops it
//! without fetching its vertices, so such runs count neither indices nor
//! misses anywhere in this module. Degenerate triangles (repeated indices)
//! are counted like any other triangle.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::components::vertex_cache::{CachePolicy, CacheStats, VertexCache};

/// The primitive restart marker in strip index buffers.
pub const RESTART: u32 = u32::MAX;

/// How an index buffer forms triangles.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Topology {
    /// Three indices per triangle.
    TriangleList,
    /// Triangle strips separated by [`RESTART`].
    TriangleStrip,
}

/// An indexed mesh (only the index buffer matters for the cost model).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Mesh {
    /// A name for reports (the spec or file it came from).
    pub name: String,
    /// How the indices form triangles.
    pub topology: Topology,
    /// The index buffer; strips may contain [`RESTART`].
    pub indices: Vec<u32>,
    /// Size of the vertex buffer; every index is below it.
    pub vertex_count: u32,
}

/// Errors building, loading or validating a mesh.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The spec matches no generator.
    #[error(
        "unknown mesh spec `{0}`; expected one of: grid:WxH, grid:WxH:shuffled:SEED, \
         grid:WxH:optimized, grid:WxH:local:WINDOW:SEED, strip:WxH, random:T:V:SEED, or a path ending in .obj or .idx"
    )]
    UnknownGenerator(String),
    /// A number in a spec does not parse.
    #[error("bad {field} `{value}` in mesh spec `{spec}`: expected a non-negative integer")]
    BadNumber {
        /// Which number (width, height, seed, ...).
        field: &'static str,
        /// The text found.
        value: String,
        /// The whole spec.
        spec: String,
    },
    /// A size is zero.
    #[error("{field} must be at least 1 in mesh spec `{spec}`")]
    ZeroSize {
        /// Which size.
        field: &'static str,
        /// The whole spec.
        spec: String,
    },
    /// The mesh would have too many indices.
    #[error(
        "mesh spec `{spec}` is too large: {indices} indices, more than the limit of {}",
        crate::limits::MAX_MESH_INDICES
    )]
    TooLarge {
        /// The whole spec.
        spec: String,
        /// The indices it would have (or "more than 2^64").
        indices: String,
    },
    /// The mesh would have too many vertices.
    #[error(
        "mesh `{name}` has {vertices} vertices{what}, more than the limit of {}",
        crate::limits::MAX_MESH_VERTICES
    )]
    TooManyVertices {
        /// The spec or file.
        name: String,
        /// Its vertex count.
        vertices: u64,
        /// Where the count comes from (` (its largest index + 1)`), or empty.
        what: &'static str,
    },
    /// A mesh file does not exist.
    #[error("mesh file `{}` not found", .0.display())]
    FileNotFound(PathBuf),
    /// A mesh file cannot be read.
    #[error("cannot read mesh file `{}`: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// An OBJ file that cannot be read as triangles.
    #[error("malformed OBJ file `{}`{}: {source}", path.display(),
        line.map(|l| format!(" at line {l}")).unwrap_or_default())]
    Obj {
        /// The file.
        path: PathBuf,
        /// The line of the error, where it belongs to one.
        line: Option<usize>,
        /// What is wrong.
        source: crate::scene::obj::ObjError,
    },
    /// A token in an `.idx` file is not a vertex index.
    #[error("bad index `{token}` in `{}` line {line}: expected an integer below 4294967295",
        path.display())]
    IdxToken {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// The offending token.
        token: String,
    },
    /// A triangle list whose length is not a multiple of 3.
    #[error("`{name}` has {count} indices, not a multiple of 3")]
    NotMultipleOfThree {
        /// Mesh or file name.
        name: String,
        /// The index count.
        count: usize,
    },
    /// A file with no triangles.
    #[error("`{0}` contains no triangles")]
    Empty(String),
    /// An index at or beyond the vertex count.
    #[error("index {index} at position {position} is out of range (vertex count {vertex_count})")]
    IndexOutOfRange {
        /// Position in the index buffer.
        position: usize,
        /// The index.
        index: u32,
        /// The mesh's vertex count.
        vertex_count: u32,
    },
    /// A restart marker in a triangle list.
    #[error("primitive restart at position {0} in a triangle list")]
    RestartInList(usize),
}

impl Mesh {
    /// Checks indices against the vertex count and the topology's rules.
    pub fn validate(&self) -> Result<(), MeshError> {
        let list = self.topology == Topology::TriangleList;
        if list && !self.indices.len().is_multiple_of(3) {
            return Err(MeshError::NotMultipleOfThree {
                name: self.name.clone(),
                count: self.indices.len(),
            });
        }
        for (position, &index) in self.indices.iter().enumerate() {
            if index == RESTART {
                if list {
                    return Err(MeshError::RestartInList(position));
                }
            } else if index >= self.vertex_count {
                return Err(MeshError::IndexOutOfRange {
                    position,
                    index,
                    vertex_count: self.vertex_count,
                });
            }
        }
        Ok(())
    }

    /// The runs of a strip that form triangles (length >= 3).
    fn strip_runs(&self) -> impl Iterator<Item = &[u32]> {
        self.indices.split(|&i| i == RESTART).filter(|r| r.len() >= 3)
    }

    /// Number of triangles (polygons in paper 000's Figure 1).
    pub fn triangles(&self) -> u64 {
        match self.topology {
            Topology::TriangleList => (self.indices.len() / 3) as u64,
            Topology::TriangleStrip => self.strip_runs().map(|r| r.len() as u64 - 2).sum(),
        }
    }

    /// Number of indices fetched: restart markers and runs shorter than 3
    /// excluded (and a list's trailing partial triangle, if any).
    pub fn index_count(&self) -> u64 {
        match self.topology {
            Topology::TriangleList => 3 * self.triangles(),
            Topology::TriangleStrip => self.strip_runs().map(|r| r.len() as u64).sum(),
        }
    }

    /// Three times the triangle count: paper 000 Figure 1's "number of
    /// vertices" (what a non-indexed triangle list would send).
    pub fn vertices(&self) -> u64 {
        3 * self.triangles()
    }

    /// The fetched indices in stream order (see [`index_count`](Self::index_count)).
    fn fetched(&self) -> Box<dyn Iterator<Item = u32> + '_> {
        match self.topology {
            Topology::TriangleList => Box::new(self.indices[..3 * (self.indices.len() / 3)].iter().copied()),
            Topology::TriangleStrip => Box::new(self.strip_runs().flatten().copied()),
        }
    }

    /// Number of distinct vertices among the fetched indices.
    pub fn unique_vertices(&self) -> u64 {
        // A bitmap over the vertex range: linear, no sort (indices were
        // checked against vertex_count; larger ones fall back to a sort).
        let n = self.vertex_count as usize;
        let mut seen = vec![0u64; n.div_ceil(64)];
        let mut count = 0u64;
        let mut outside: Vec<u32> = Vec::new();
        for i in self.fetched() {
            let k = i as usize;
            if k < n {
                let (w, b) = (k / 64, 1u64 << (k % 64));
                if seen[w] & b == 0 {
                    seen[w] |= b;
                    count += 1;
                }
            } else {
                outside.push(i);
            }
        }
        outside.sort_unstable();
        outside.dedup();
        count + outside.len() as u64
    }

    /// Runs the cache over the index stream; calls `charge(misses)` once per
    /// triangle in order. Returns (indices fetched, total misses).
    fn simulate(&self, policy: &CachePolicy, mut charge: impl FnMut(u8)) -> (u64, u64) {
        let mut cache = VertexCache::new(policy, self.vertex_count as usize);
        let (mut indices, mut total) = (0u64, 0u64);
        if cache.is_triangle_level() {
            // Warps and batches are cut per triangle: feed whole triangles
            // (a strip's triangles as the list it stands for).
            let list;
            let tris: &[u32] = match self.topology {
                Topology::TriangleList => &self.indices,
                Topology::TriangleStrip => {
                    list = self.to_triangle_list();
                    &list.indices
                }
            };
            for t in tris.chunks_exact(3) {
                let m = cache.access_triangle([t[0], t[1], t[2]]);
                charge(m);
                indices += 3;
                total += u64::from(m);
            }
            return (indices, total);
        }
        let mut miss = |i: u32| u8::from(cache.access(i));
        match self.topology {
            Topology::TriangleList => {
                for tri in self.indices.chunks_exact(3) {
                    let m = miss(tri[0]) + miss(tri[1]) + miss(tri[2]);
                    charge(m);
                    indices += 3;
                    total += u64::from(m);
                }
            }
            Topology::TriangleStrip => {
                for run in self.strip_runs() {
                    // The run's first triangle pays for its first two indices too.
                    let mut m = miss(run[0]) + miss(run[1]);
                    for &i in &run[2..] {
                        m += miss(i);
                        charge(m);
                        total += u64::from(m);
                        m = 0;
                    }
                    indices += run.len() as u64;
                }
            }
        }
        (indices, total)
    }

    /// Simulates `policy` over the index stream in order (a restart does not
    /// flush the cache) and counts actually transformed vertices.
    pub fn cache_stats(&self, policy: &CachePolicy) -> CacheStats {
        if let Some((transformed, _, unique)) = self.fast_list(policy, |_| {}) {
            let triangles = self.indices.len() as u64 / 3;
            return CacheStats {
                indices: 3 * triangles,
                triangles,
                unique_vertices: unique,
                transformed,
            };
        }
        let mut triangles = 0u64;
        let (indices, transformed) = self.simulate(policy, |_| triangles += 1);
        CacheStats {
            indices,
            triangles,
            unique_vertices: self.unique_vertices(),
            transformed,
        }
    }

    /// Cache misses charged to each triangle (0 to 3), in draw order: a
    /// list's triangle pays for its three indices; a strip's triangle pays for
    /// the index that completes it, and a run's first triangle also for the
    /// run's first two. The sum equals `cache_stats(policy).transformed`.
    pub fn misses_per_triangle(&self, policy: &CachePolicy) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.triangles() as usize);
        if self.fast_list(policy, |m| out.push(m)).is_some() {
            return out;
        }
        out.clear();
        self.simulate(policy, |m| out.push(m));
        out
    }

    /// The policy as meshoptimizer's analyser parameters `(cache, warp,
    /// primgroup)` and the stamp array's length, when the dense fast path
    /// applies: a whole triangle list under a FIFO, `meshopt:` or `batch:`
    /// policy.
    fn fast_params(&self, policy: &CachePolicy) -> Option<((u32, u32, u32), usize)> {
        if self.topology != Topology::TriangleList || !self.indices.len().is_multiple_of(3) {
            return None;
        }
        let params = match *policy {
            CachePolicy::Fifo(n) if n >= 3 => (n, 0, 0),
            CachePolicy::Meshopt { cache, warp, primgroup } => (cache, warp, primgroup),
            CachePolicy::Batch { vertices, triangles } => (vertices, vertices, triangles),
            _ => return None,
        };
        let n = self.vertex_count as usize;
        (n <= 1 << 28).then_some((params, n))
    }

    /// The dense fast path (`analyze_triangle_list`) when it applies and
    /// every index is below `vertex_count`; `None` otherwise.
    fn fast_list(&self, policy: &CachePolicy, charge: impl FnMut(u8)) -> Option<(u64, u64, u64)> {
        let ((c, w, p), n) = self.fast_params(policy)?;
        crate::components::vertex_cache::analyze_triangle_list(&self.indices, n, c, w, p, charge)
    }

    /// The same triangles as an indexed list. Strip winding alternates: the
    /// odd triangles of a run swap their first two vertices, so every
    /// triangle keeps the orientation of the run's first.
    pub fn to_triangle_list(&self) -> Mesh {
        let indices = match self.topology {
            Topology::TriangleList => self.indices[..3 * (self.indices.len() / 3)].to_vec(),
            Topology::TriangleStrip => {
                let mut out = Vec::with_capacity(3 * self.triangles() as usize);
                for run in self.strip_runs() {
                    for (j, w) in run.windows(3).enumerate() {
                        if j % 2 == 0 {
                            out.extend_from_slice(&[w[0], w[1], w[2]]);
                        } else {
                            out.extend_from_slice(&[w[1], w[0], w[2]]);
                        }
                    }
                }
                out
            }
        };
        Mesh {
            name: self.name.clone(),
            topology: Topology::TriangleList,
            indices,
            vertex_count: self.vertex_count,
        }
    }
}

#[cfg(test)]
mod tests;
