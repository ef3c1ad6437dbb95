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
use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// A post-transform vertex cache's replacement policy and size.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum CachePolicy {
    /// No reuse: every index is transformed.
    None,
    /// A FIFO of N entries; a hit does not reorder, a miss evicts the oldest.
    Fifo(u32),
    /// Least recently used, N entries; a hit moves the vertex to the front.
    Lru(u32),
}

/// A cache policy string that does not parse.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum CachePolicyError {
    /// The policy name is not known.
    #[error("unknown vertex cache policy `{0}`; expected `none`, `fifo:N` or `lru:N`")]
    UnknownPolicy(String),
    /// The policy needs a size (`fifo:N`).
    #[error("vertex cache policy `{0}` needs a size, e.g. `{0}:32`")]
    MissingSize(String),
    /// The size is not a positive integer.
    #[error("vertex cache size `{size}` in `{spec}` is not an integer from 1 to 4294967295")]
    BadSize {
        /// The whole policy string.
        spec: String,
        /// The size part.
        size: String,
    },
    /// `none` takes no size.
    #[error("vertex cache policy `none` takes no size, got `{0}`")]
    UnexpectedSize(String),
}

impl FromStr for CachePolicy {
    type Err = CachePolicyError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let spec = s.trim();
        let (name, size) = match spec.split_once(':') {
            Some((n, z)) => (n.trim(), Some(z.trim())),
            None => (spec, None),
        };
        let parse_size = || -> Result<u32, CachePolicyError> {
            let z = size.ok_or_else(|| CachePolicyError::MissingSize(name.to_string()))?;
            match z.parse::<u32>() {
                Ok(n) if n >= 1 => Ok(n),
                _ => Err(CachePolicyError::BadSize {
                    spec: spec.to_string(),
                    size: z.to_string(),
                }),
            }
        };
        match name.to_ascii_lowercase().as_str() {
            "none" => match size {
                None => Ok(CachePolicy::None),
                Some(_) => Err(CachePolicyError::UnexpectedSize(spec.to_string())),
            },
            "fifo" => Ok(CachePolicy::Fifo(parse_size()?)),
            "lru" => Ok(CachePolicy::Lru(parse_size()?)),
            _ => Err(CachePolicyError::UnknownPolicy(spec.to_string())),
        }
    }
}

impl fmt::Display for CachePolicy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CachePolicy::None => write!(f, "none"),
            CachePolicy::Fifo(n) => write!(f, "fifo:{n}"),
            CachePolicy::Lru(n) => write!(f, "lru:{n}"),
        }
    }
}

impl Serialize for CachePolicy {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for CachePolicy {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

/// Indices below this use a dense stamp array; larger ones (sparse, huge
/// vertex ids from user files) go to a hash map so memory stays bounded.
const DENSE_LIMIT: usize = 1 << 24;

/// A simulated post-transform vertex cache.
#[derive(Clone, Debug)]
pub struct VertexCache {
    policy: CachePolicy,
    /// FIFO: per-vertex insertion stamp (the miss counter after insertion).
    stamps: Vec<u64>,
    /// FIFO: stamps of vertices with ids beyond the dense array.
    sparse: HashMap<u32, u64>,
    /// FIFO: number of insertions so far.
    now: u64,
    /// FIFO: value of `now` at the last reset; older stamps are invalid.
    epoch: u64,
    /// LRU: the cached vertices, most recent first.
    lru: Vec<u32>,
}

impl VertexCache {
    /// An empty cache; `vertex_count_hint` presizes the FIFO stamp array.
    pub fn new(policy: &CachePolicy, vertex_count_hint: usize) -> Self {
        let (stamps, lru) = match policy {
            CachePolicy::None => (Vec::new(), Vec::new()),
            CachePolicy::Fifo(_) => (vec![0; vertex_count_hint.min(DENSE_LIMIT)], Vec::new()),
            CachePolicy::Lru(n) => (Vec::new(), Vec::with_capacity((*n as usize).min(1024))),
        };
        VertexCache {
            policy: policy.clone(),
            stamps,
            sparse: HashMap::new(),
            now: 0,
            epoch: 0,
            lru,
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
        }
    }

    /// Looks up vertex `index`; returns `true` on a miss (the vertex is
    /// fetched and transformed, then cached).
    pub fn access(&mut self, index: u32) -> bool {
        match self.policy {
            CachePolicy::None => true,
            CachePolicy::Fifo(n) => {
                let i = index as usize;
                if i >= self.stamps.len() && i < DENSE_LIMIT {
                    let len = (i + 1).max(2 * self.stamps.len()).min(DENSE_LIMIT);
                    self.stamps.resize(len, 0);
                }
                let stamp = match self.stamps.get(i) {
                    Some(s) => *s,
                    None => self.sparse.get(&index).copied().unwrap_or(0),
                };
                // Valid since the last reset and fewer than n insertions ago.
                if stamp > self.epoch && self.now - stamp < u64::from(n) {
                    return false;
                }
                self.now += 1;
                match self.stamps.get_mut(i) {
                    Some(s) => *s = self.now,
                    None => {
                        self.sparse.insert(index, self.now);
                    }
                }
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
