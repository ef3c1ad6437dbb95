//! Where the primitives go: primitives per rasterizing node (round robin, as
//! a balanced display-list distribution) and, per node, how many of its
//! primitives fall in each screen region (the bins of the bucket sort).

use rand::Rng;

use super::config::{PixelFlowConfig, Placement, Size};
use crate::engine::RngStreams;

/// Primitive counts per node and per (node, region).
#[derive(Debug, Clone)]
pub struct Layout {
    /// Rasterizing nodes.
    pub nodes: usize,
    /// Screen regions.
    pub regions: usize,
    /// Primitives per node.
    pub prims: Vec<u64>,
    /// Region entries, node-major: `bins[node * regions + region]`.
    pub bins: Vec<u64>,
}

impl Layout {
    /// Region entries of `node` in `region`.
    #[inline]
    pub fn bin(&self, node: usize, region: usize) -> u64 {
        self.bins[node * self.regions + region]
    }

    /// All region entries of `node`.
    pub fn node_entries(&self, node: usize) -> u64 {
        self.bins[node * self.regions..(node + 1) * self.regions].iter().sum()
    }

    /// Region entries per region, summed over nodes.
    pub fn region_entries(&self) -> Vec<u64> {
        (0..self.regions)
            .map(|j| (0..self.nodes).map(|r| self.bin(r, j)).sum())
            .collect()
    }

    /// The realised overlap: region entries per primitive.
    pub fn realised_overlap(&self) -> f64 {
        let n: u64 = self.prims.iter().sum();
        if n == 0 {
            return 0.0;
        }
        self.bins.iter().sum::<u64>() as f64 / n as f64
    }
}

/// Builds the layout the configuration describes.
pub fn build(cfg: &PixelFlowConfig) -> Layout {
    let nodes = cfg.rasterizers().max(1) as usize;
    let regions = cfg.regions() as usize;
    let n = cfg.primitives;
    let prims = node_counts(n, nodes, cfg.node_skew);
    let mut bins = vec![0u64; nodes * regions];
    match cfg.placement {
        Placement::Uniform => {
            let overlap = cfg.overlap();
            for (r, &p) in prims.iter().enumerate() {
                let total = (p as f64 * overlap).round() as u64;
                let (q, rem) = (total / regions as u64, total % regions as u64);
                for j in 0..regions {
                    // Spread the remainder, rotated per node, so no region
                    // collects every node's extra entry.
                    let k = ((j + regions - r % regions) % regions) as u64;
                    bins[r * regions + j] = q + u64::from(k < rem);
                }
            }
        }
        Placement::Random | Placement::Clustered => {
            let mut rng = RngStreams::new(cfg.run.seed).stream("pixelflow.placement");
            let fp = cfg.footprint();
            let (cols, _) = cfg.region_grid();
            let cluster = cfg.cluster.as_ref().filter(|_| cfg.placement == Placement::Clustered);
            let mut cov_x = Vec::with_capacity(8);
            let mut cov_y = Vec::with_capacity(8);
            // Round robin over the nodes that still have primitives to take:
            // node i % nodes when the counts are balanced.
            let mut left = prims.clone();
            let mut next = 0usize;
            for _ in 0..n {
                while left[next] == 0 {
                    next = (next + 1) % nodes;
                }
                left[next] -= 1;
                let node = next;
                next = (next + 1) % nodes;
                let (x0, y0) = match cluster {
                    Some(c) if rng.random::<f64>() < c.fraction => (
                        c.x + rng.random::<f64>() * c.width,
                        c.y + rng.random::<f64>() * c.height,
                    ),
                    _ => (
                        rng.random::<f64>() * cfg.display.width,
                        rng.random::<f64>() * cfg.display.height,
                    ),
                };
                covered(x0, fp.width, cfg.display.width, cfg.region.width, &mut cov_x);
                covered(y0, fp.height, cfg.display.height, cfg.region.height, &mut cov_y);
                for &ry in &cov_y {
                    for &cx in &cov_x {
                        bins[node * regions + ry * cols as usize + cx] += 1;
                    }
                }
            }
        }
    }
    Layout {
        nodes,
        regions,
        prims,
        bins,
    }
}

/// Primitives per rasterizing node: `n / nodes` each (the first `n % nodes`
/// one more) for `skew = 0`; otherwise shares proportional to
/// `1 + skew (1 - 2r / (nodes - 1))`, rounded so that they add up to `n`.
pub fn node_counts(n: u64, nodes: usize, skew: f64) -> Vec<u64> {
    if skew == 0.0 || nodes < 2 {
        return (0..nodes as u64)
            .map(|r| n / nodes as u64 + u64::from(r < n % nodes as u64))
            .collect();
    }
    let weight = |r: usize| 1.0 + skew * (1.0 - 2.0 * r as f64 / (nodes - 1) as f64);
    let total: f64 = (0..nodes).map(weight).sum();
    let mut prefix = 0.0;
    let mut prev = 0u64;
    (0..nodes)
        .map(|r| {
            prefix += weight(r);
            let cum = if r + 1 == nodes {
                n
            } else {
                ((n as f64 * prefix / total).round() as u64).min(n)
            };
            let c = cum.saturating_sub(prev);
            prev = prev.max(cum);
            c
        })
        .collect()
}

/// Region indices along one axis covered by `[start, start + len)`, wrapping
/// around the screen edge (distinct indices only).
fn covered(start: f64, len: f64, screen: f64, region: f64, out: &mut Vec<usize>) {
    out.clear();
    let end = start + len.max(f64::MIN_POSITIVE);
    let mut x = start;
    while x < end {
        let px = x.rem_euclid(screen);
        let idx = (px / region).floor() as usize;
        if !out.contains(&idx) {
            out.push(idx);
        }
        let boundary = ((idx + 1) as f64 * region).min(screen);
        x += (boundary - px).max(1e-9);
    }
}

/// The footprint's expected overlap factor, for documentation and tests.
pub fn overlap_of(p: Size, region: Size) -> f64 {
    (p.width + region.width) * (p.height + region.height) / region.area()
}

#[cfg(test)]
mod tests {
    use super::node_counts;

    #[test]
    fn node_counts_balanced_and_skewed() {
        assert_eq!(node_counts(10, 3, 0.0), vec![4, 3, 3]);
        // 15 nodes, skew 0.5: the first node gets 1.5 times the mean, the last 0.5 times.
        let c = node_counts(1_500_000, 15, 0.5);
        assert_eq!(c.iter().sum::<u64>(), 1_500_000);
        assert_eq!(c[0], 150_000);
        assert_eq!(c[7], 100_000);
        assert_eq!(c[14], 50_000);
        assert!(c.windows(2).all(|w| w[0] >= w[1]), "{c:?}");
        // A few primitives still add up.
        let c = node_counts(7, 15, 0.9);
        assert_eq!(c.iter().sum::<u64>(), 7);
    }
}
