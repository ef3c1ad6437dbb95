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
    let prims: Vec<u64> = (0..nodes as u64)
        .map(|r| n / nodes as u64 + u64::from(r < n % nodes as u64))
        .collect();
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
            for i in 0..n {
                let node = (i % nodes as u64) as usize;
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
