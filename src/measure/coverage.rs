//! What a measured pass's triangles cover on its render target, counted the
//! way a GPU's rasterizer feeds its shader cores: fragments (pixel centres
//! inside a triangle, half-open edges so shared edges count once), 2x2 quads
//! touched (a quad with any covered pixel runs four lanes: the others are
//! helper invocations), and warps of [`WARP_QUADS`] quads, packed from
//! consecutive triangles only while they stay in one [`TILE_PIXELS`] screen
//! tile (a draw order that jumps about starts a new, partly filled warp for
//! nearly every triangle). The positions are the ones `rendersim measure`
//! draws ([`super::mesh_positions`]). Scanline by scanline, so the cost is
//! proportional to triangles x rows plus quads / 8, not to fragments.

use serde::Serialize;

use super::mesh_positions;
use crate::scene::mesh::Mesh;

/// Quads per warp (32 lanes).
pub const WARP_QUADS: u32 = 8;
/// Side of the screen tile within which consecutive triangles share a warp.
pub const TILE_PIXELS: u32 = 16;

/// Rasterization counts of one draw of a mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct Coverage {
    /// Triangles that cover at least one pixel centre.
    pub triangles: u64,
    /// Triangles drawn.
    pub drawn_triangles: u64,
    /// Pixel centres covered (fragment-shader invocations without depth test).
    pub fragments: u64,
    /// 2x2 quads with at least one covered pixel, per triangle, summed.
    pub quads: u64,
    /// Warps of up to [`WARP_QUADS`] quads.
    pub warps: u64,
}

/// Open warp of the packing model.
struct Packer {
    tile: Option<u32>,
    fill: u32,
    warps: u64,
}

impl Packer {
    fn emit(&mut self, tile: u32, mut n: u32) {
        if self.tile == Some(tile) {
            let take = n.min(WARP_QUADS - self.fill);
            self.fill += take;
            n -= take;
        }
        while n > 0 {
            self.warps += 1;
            self.tile = Some(tile);
            self.fill = n.min(WARP_QUADS);
            n -= self.fill;
        }
    }
}

/// Pixel columns `[first, last]` of row centre `yc` inside the triangle, or
/// `None`.
fn row_span(p: &[[f64; 2]; 3], yc: f64, width: u32) -> Option<(u32, u32)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for k in 0..3 {
        let (a, b) = (p[k], p[(k + 1) % 3]);
        if a[1] == b[1] || yc < a[1].min(b[1]) || yc > a[1].max(b[1]) {
            continue;
        }
        let x = a[0] + (yc - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
        lo = lo.min(x);
        hi = hi.max(x);
    }
    if lo >= hi {
        return None;
    }
    // Centres x + 0.5 with lo <= x + 0.5 < hi.
    let first = (lo - 0.5).ceil().max(0.0);
    let last = ((hi - 0.5).ceil() - 1.0).min(f64::from(width) - 1.0);
    (first <= last).then_some((first as u32, last as u32))
}

/// Counts what one draw of `mesh` (generator spec `spec`) covers on a
/// `width` x `height` target.
pub fn coverage(mesh: &Mesh, spec: &str, width: u32, height: u32) -> Coverage {
    let list = mesh.to_triangle_list();
    let pos = mesh_positions(mesh, spec);
    let (w, h) = (f64::from(width), f64::from(height));
    let tiles_x = width.div_ceil(TILE_PIXELS);
    let tiles = (tiles_x * height.div_ceil(TILE_PIXELS)) as usize;
    let (mut counts, mut touched) = (vec![0u32; tiles], Vec::<u32>::new());
    let mut pack = Packer {
        tile: None,
        fill: 0,
        warps: 0,
    };
    let mut c = Coverage::default();
    let tile_quads = TILE_PIXELS / 2;
    for t in list.indices.chunks_exact(3) {
        c.drawn_triangles += 1;
        let p = [0, 1, 2].map(|k| {
            let v = pos.get(t[k] as usize).copied().unwrap_or([0.0, 0.0]);
            [f64::from(v[0]) * w, f64::from(v[1]) * h]
        });
        let ymin = p.iter().map(|v| v[1]).fold(f64::INFINITY, f64::min);
        let ymax = p.iter().map(|v| v[1]).fold(f64::NEG_INFINITY, f64::max);
        // Rows whose centre y + 0.5 lies in [ymin, ymax).
        let r0 = (ymin - 0.5).ceil().max(0.0) as i64;
        let r1 = ((ymax - 0.5).ceil() as i64 - 1).min(i64::from(height) - 1);
        if r1 < r0 {
            continue;
        }
        let (mut frags, mut quads) = (0u64, 0u64);
        let mut qr = r0 / 2;
        while qr * 2 <= r1 {
            let span = |r: i64| {
                if r < r0 || r > r1 {
                    None
                } else {
                    row_span(&p, r as f64 + 0.5, width)
                }
            };
            let (a, b) = (span(qr * 2), span(qr * 2 + 1));
            for s in [a, b].into_iter().flatten() {
                frags += u64::from(s.1 - s.0 + 1);
            }
            let q = |s: (u32, u32)| (s.0 / 2, s.1 / 2);
            let ranges: [Option<(u32, u32)>; 2] = match (a.map(q), b.map(q)) {
                (Some(x), Some(y)) if x.0 <= y.1 && y.0 <= x.1 => [Some((x.0.min(y.0), x.1.max(y.1))), None],
                (x, y) => [x, y],
            };
            let trow = (qr as u32 / tile_quads) * tiles_x;
            for (q0, q1) in ranges.into_iter().flatten() {
                quads += u64::from(q1 - q0 + 1);
                let mut s = q0;
                while s <= q1 {
                    let tile = trow + s / tile_quads;
                    let e = ((s / tile_quads + 1) * tile_quads - 1).min(q1);
                    if counts[tile as usize] == 0 {
                        touched.push(tile);
                    }
                    counts[tile as usize] += e - s + 1;
                    s = e + 1;
                }
            }
            qr += 1;
        }
        for tile in touched.drain(..) {
            pack.emit(tile, std::mem::take(&mut counts[tile as usize]));
        }
        if frags > 0 {
            c.triangles += 1;
        }
        c.fragments += frags;
        c.quads += quads;
    }
    c.warps = pack.warps;
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::generators::mesh_from_spec;

    fn cov(spec: &str, w: u32, h: u32) -> Coverage {
        coverage(&mesh_from_spec(spec, std::path::Path::new(".")).unwrap(), spec, w, h)
    }

    #[test]
    fn a_grid_covers_every_pixel_once() {
        for (spec, w, h) in [
            ("grid:32x32", 128, 128),
            ("grid:96x96:optimized", 128, 128),
            ("strip:64x64", 512, 512),
        ] {
            let c = cov(spec, w, h);
            assert_eq!(c.fragments, u64::from(w * h), "{spec}");
            assert!(c.quads * 4 >= c.fragments && c.warps * 8 >= c.quads, "{c:?}");
        }
    }

    #[test]
    fn large_cells_fill_quads_and_shuffling_wastes_warps() {
        // 16 x 16 pixel cells: quads nearly full.
        let big = cov("grid:8x8", 128, 128);
        assert!((big.quads * 4) as f64 / (big.fragments as f64) < 1.2, "{big:?}");
        let strip = cov("grid:64x64", 128, 128);
        let shuffled = cov("grid:64x64:shuffled:1", 128, 128);
        assert_eq!(strip.quads, shuffled.quads);
        assert!(shuffled.warps > 2 * strip.warps, "{strip:?} {shuffled:?}");
    }

    #[test]
    fn the_random_mesh_matches_the_h200_counter() {
        // docs/measurements/nvidia-h200/load-sweep.csv: 37,549,075 at 128x128.
        let c = cov("random:30000:5000:7", 128, 128);
        let rel = (c.fragments as f64 - 37_549_075.0).abs() / 37_549_075.0;
        assert!(rel < 0.01, "{c:?}");
    }
}
