//! What a measured pass's triangles cover on its render target, counted the
//! way a GPU's rasterizer feeds its shader cores: fragments (pixel centres
//! inside a triangle, half-open edges so shared edges count once), 2x2 quads
//! touched (a quad with any covered pixel runs four lanes: the others are
//! helper invocations), and warps of [`WARP_QUADS`] quads, packed from
//! consecutive triangles only while they stay in one [`TILE_PIXELS`] screen
//! tile (a draw order that jumps about starts a new, partly filled warp for
//! nearly every triangle). The positions are the ones `rendersim measure`
//! draws ([`super::mesh_positions`]). Scanline by scanline, and per row of
//! tiles through a difference array (each quad row's range adds its two
//! partial tiles and marks its full ones), so the cost is proportional to
//! triangles x rows plus the tiles touched, not to fragments or to tiles x
//! rows.

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
    /// Covered triangles by how many screen tiles ([`TILE_PIXELS`] square)
    /// they touch: [`SIZE_CLASSES`] (one tile; up to 16; more).
    pub by_size: [u64; 3],
    /// Screen tiles touched, summed over the triangles.
    pub tiles: u64,
}

/// Upper bounds (tiles touched) of the size classes of [`Coverage::by_size`]
/// but the last: a triangle within one tile, within 16 tiles (a 64x64-pixel
/// square), and larger.
pub const SIZE_CLASSES: [u64; 2] = [1, 16];

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

/// `x.ceil()`, exactly, without a library call where `x` fits in an `i64`
/// (the default x86-64 target has no rounding instruction; this loop does
/// millions of them). Only the sign of a zero result can differ, which no
/// caller sees (each one casts or compares it).
#[inline]
fn ceil(x: f64) -> f64 {
    if x.abs() < 4.0e15 {
        let t = x as i64 as f64;
        if t < x { t + 1.0 } else { t }
    } else {
        x.ceil()
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
    let first = ceil(lo - 0.5).max(0.0);
    let last = (ceil(hi - 0.5) - 1.0).min(f64::from(width) - 1.0);
    (first <= last).then_some((first as u32, last as u32))
}

/// One triangle's row spans, fast: per edge (in the triangle's vertex
/// order, horizontal ones left out) its slope once, so that a row costs a
/// multiply-add per edge instead of a division. The slope's rounding moves
/// an edge's x by at most a few units in the last place of the triangle's
/// coordinates (|error| <= 16 u max|x| with u = 2^-53, far below `eps`); a
/// row whose span end lies within `eps` of a pixel centre, or whose span is
/// within `eps` of empty, is computed exactly by [`row_span`], so every
/// span equals [`row_span`]'s.
struct Spans {
    p: [[f64; 2]; 3],
    /// (a_x, a_y, slope, y_lo, y_hi) per non-horizontal edge.
    edges: [(f64, f64, f64, f64, f64); 3],
    n: usize,
    eps: f64,
    /// Coordinates or slopes not finite: every row exactly.
    exact: bool,
}

impl Spans {
    fn new(p: [[f64; 2]; 3]) -> Spans {
        let mut s = Spans {
            p,
            edges: [(0.0, 0.0, 0.0, 0.0, 0.0); 3],
            n: 0,
            eps: 1e-9 * (1.0 + p.iter().map(|v| v[0].abs()).fold(0.0, f64::max)),
            exact: !p.iter().all(|v| v[0].is_finite() && v[1].is_finite()),
        };
        for k in 0..3 {
            let (a, b) = (p[k], p[(k + 1) % 3]);
            if a[1] == b[1] {
                continue;
            }
            let slope = (b[0] - a[0]) / (b[1] - a[1]);
            s.exact |= !slope.is_finite();
            s.edges[s.n] = (a[0], a[1], slope, a[1].min(b[1]), a[1].max(b[1]));
            s.n += 1;
        }
        s
    }

    /// [`row_span`] of row centre `yc`.
    #[inline]
    fn row(&self, yc: f64, width: u32) -> Option<(u32, u32)> {
        if self.exact {
            return row_span(&self.p, yc, width);
        }
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for &(a0, a1, slope, ylo, yhi) in &self.edges[..self.n] {
            if yc < ylo || yc > yhi {
                continue;
            }
            let x = a0 + (yc - a1) * slope;
            lo = lo.min(x);
            hi = hi.max(x);
        }
        let (zl, zh) = (lo - 0.5, hi - 0.5);
        let (cl, ch) = (ceil(zl), ceil(zh));
        let clear = |z: f64, c: f64| (c - z).min(z - (c - 1.0)) > self.eps;
        if !(hi - lo > self.eps && clear(zl, cl) && clear(zh, ch)) {
            return row_span(&self.p, yc, width);
        }
        let first = cl.max(0.0);
        let last = (ch - 1.0).min(f64::from(width) - 1.0);
        (first <= last).then_some((first as u32, last as u32))
    }
}

/// Per-triangle quad counts of one row of screen tiles: every quad-row
/// range `[q0, q1]` (quad columns) adds its partial first and last tiles
/// directly and its full tiles through a difference array, so a tile row
/// costs its ranges plus one pass over its tile columns, not one update per
/// tile per quad row.
struct TileRow {
    /// Difference array of the full-tile contributions, per tile column.
    diff: Vec<i64>,
    /// Partial contributions, per tile column.
    part: Vec<u32>,
    /// Columns seen while ordering the last tile row's first touches.
    seen: Vec<bool>,
}

/// What one triangle's tile rows add up to.
#[derive(Default)]
struct TriangleTiles {
    /// Tiles touched.
    tiles: u64,
    /// Sum over the touched tiles of their warps, ceil(quads / 8).
    warps: u64,
    /// The first tile touched and its quads.
    first: Option<(u32, u32)>,
    /// The last tile touched for the first time and its quads.
    last: Option<(u32, u32)>,
}

impl TileRow {
    /// Adds tile row `trow`'s quad ranges (in the order the rasterizer
    /// emits them) to `acc`; `is_last` when no later tile row of the
    /// triangle has a range.
    fn flush(&mut self, trow: u32, tiles_x: u32, ranges: &[(u32, u32)], is_last: bool, acc: &mut TriangleTiles) {
        let tq = TILE_PIXELS / 2;
        let (mut cmin, mut cmax) = (u32::MAX, 0);
        for &(q0, q1) in ranges {
            let (c0, c1) = (q0 / tq, q1 / tq);
            if c0 == c1 {
                self.part[c0 as usize] += q1 - q0 + 1;
            } else {
                self.part[c0 as usize] += (c0 + 1) * tq - q0;
                self.part[c1 as usize] += q1 - c1 * tq + 1;
                if c1 > c0 + 1 {
                    self.diff[(c0 + 1) as usize] += i64::from(tq);
                    self.diff[c1 as usize] -= i64::from(tq);
                }
            }
            cmin = cmin.min(c0);
            cmax = cmax.max(c1);
        }
        let first_col = match acc.first {
            None => ranges.first().map(|r| r.0 / tq),
            Some(_) => None,
        };
        // The last tile touched for the first time: in touch order (ranges
        // in order, columns left to right), the last unseen column.
        let last_col = if is_last {
            let mut last = None;
            for &(q0, q1) in ranges {
                for col in q0 / tq..=q1 / tq {
                    if !self.seen[col as usize] {
                        self.seen[col as usize] = true;
                        last = Some(col);
                    }
                }
            }
            last
        } else {
            None
        };
        let mut run = 0i64;
        for col in cmin..=cmax {
            let k = col as usize;
            run += self.diff[k];
            let n = run as u32 + self.part[k];
            self.diff[k] = 0;
            self.part[k] = 0;
            self.seen[k] = false;
            if n == 0 {
                continue;
            }
            acc.tiles += 1;
            acc.warps += u64::from(n.div_ceil(WARP_QUADS));
            let tile = trow * tiles_x + col;
            if first_col == Some(col) {
                acc.first = Some((tile, n));
            }
            if last_col == Some(col) {
                acc.last = Some((tile, n));
            }
        }
    }
}

/// Triangles counted per parallel chunk, and chunks per batch (the
/// per-triangle tile summaries of one batch are held at once).
const CHUNK: usize = 4096;
const BATCH: usize = 64;

/// What the warp packing needs of one triangle that touched a tile: its
/// first tile and quads, its last tile and quads, and the warps of every
/// tile after the first.
#[derive(Clone, Copy)]
struct Touch {
    first: (u32, u32),
    last: (u32, u32),
    more: bool,
    rest_warps: u64,
}

/// Counts what one draw of `mesh` (generator spec `spec`) covers on a
/// `width` x `height` target. Triangles are counted in parallel chunks
/// (rayon); the warp packing, which carries an open warp from one triangle
/// to the next, then runs over their summaries in draw order, so the
/// counts do not depend on the threads.
pub fn coverage(mesh: &Mesh, spec: &str, width: u32, height: u32) -> Coverage {
    use rayon::prelude::*;
    let list = mesh.to_triangle_list();
    let pos = mesh_positions(mesh, spec);
    let mut pack = Packer {
        tile: None,
        fill: 0,
        warps: 0,
    };
    let mut c = Coverage::default();
    for batch in list.indices.chunks(3 * CHUNK * BATCH) {
        let parts: Vec<(Coverage, Vec<Touch>)> = batch
            .par_chunks(3 * CHUNK)
            .map(|chunk| count_chunk(chunk, &pos, width, height))
            .collect();
        for (part, touches) in parts {
            c.drawn_triangles += part.drawn_triangles;
            c.triangles += part.triangles;
            c.fragments += part.fragments;
            c.quads += part.quads;
            c.tiles += part.tiles;
            for (a, b) in c.by_size.iter_mut().zip(part.by_size) {
                *a += b;
            }
            for t in touches {
                // The first tile may continue the previous triangle's open
                // warp; every later tile differs from the open warp's tile,
                // so it starts its own warps, and the last one stays open.
                pack.emit(t.first.0, t.first.1);
                if t.more {
                    let (tk, nk) = t.last;
                    pack.warps += t.rest_warps;
                    pack.tile = Some(tk);
                    pack.fill = nk - WARP_QUADS * (nk.div_ceil(WARP_QUADS) - 1);
                }
            }
        }
    }
    c.warps = pack.warps;
    c
}

/// Fragments, quads and covered triangles of the triangles in `indices`
/// (a triangle list), and the tile summary of each that touched a tile.
fn count_chunk(indices: &[u32], pos: &[[f32; 2]], width: u32, height: u32) -> (Coverage, Vec<Touch>) {
    let (w, h) = (f64::from(width), f64::from(height));
    let tiles_x = width.div_ceil(TILE_PIXELS);
    let cols = tiles_x as usize + 1;
    let mut row = TileRow {
        diff: vec![0; cols],
        part: vec![0; cols],
        seen: vec![false; cols],
    };
    let mut c = Coverage::default();
    let mut touches = Vec::new();
    let tile_quads = TILE_PIXELS / 2;
    let mut ranges_buf: Vec<(u32, u32)> = Vec::with_capacity(2 * tile_quads as usize);
    for t in indices.chunks_exact(3) {
        c.drawn_triangles += 1;
        let p = [0, 1, 2].map(|k| {
            let v = pos.get(t[k] as usize).copied().unwrap_or([0.0, 0.0]);
            [f64::from(v[0]) * w, f64::from(v[1]) * h]
        });
        let ymin = p.iter().map(|v| v[1]).fold(f64::INFINITY, f64::min);
        let ymax = p.iter().map(|v| v[1]).fold(f64::NEG_INFINITY, f64::max);
        // Rows whose centre y + 0.5 lies in [ymin, ymax).
        let r0 = ceil(ymin - 0.5).max(0.0) as i64;
        let r1 = (ceil(ymax - 0.5) as i64 - 1).min(i64::from(height) - 1);
        if r1 < r0 {
            continue;
        }
        let (mut frags, mut quads) = (0u64, 0u64);
        let mut acc = TriangleTiles::default();
        // The tile row whose ranges are gathered in `ranges_buf` (flushed
        // once a later tile row has ranges too, or at the end as the last).
        let mut pending: Option<u32> = None;
        ranges_buf.clear();
        let spans = Spans::new(p);
        let mut qr = r0 / 2;
        while qr * 2 <= r1 {
            let span = |r: i64| {
                if r < r0 || r > r1 {
                    None
                } else {
                    spans.row(r as f64 + 0.5, width)
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
            let trow = qr as u32 / tile_quads;
            for r in ranges.into_iter().flatten() {
                if let Some(done) = pending
                    && done != trow
                {
                    row.flush(done, tiles_x, &ranges_buf, false, &mut acc);
                    ranges_buf.clear();
                }
                pending = Some(trow);
                quads += u64::from(r.1 - r.0 + 1);
                ranges_buf.push(r);
            }
            qr += 1;
        }
        if let Some(done) = pending {
            row.flush(done, tiles_x, &ranges_buf, true, &mut acc);
        }
        if let (Some(first), Some(last)) = (acc.first, acc.last) {
            touches.push(Touch {
                first,
                last,
                more: acc.tiles > 1,
                rest_warps: acc.warps - u64::from(first.1.div_ceil(WARP_QUADS)),
            });
        }
        if frags > 0 {
            c.triangles += 1;
            let class = SIZE_CLASSES
                .iter()
                .position(|&b| acc.tiles <= b)
                .unwrap_or(SIZE_CLASSES.len());
            c.by_size[class] += 1;
        }
        c.tiles += acc.tiles;
        c.fragments += frags;
        c.quads += quads;
    }
    (c, touches)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::generators::mesh_from_spec;

    fn cov(spec: &str, w: u32, h: u32) -> Coverage {
        coverage(&mesh_from_spec(spec, std::path::Path::new(".")).unwrap(), spec, w, h)
    }

    /// The counting as it was before the tile rows were summed through a
    /// difference array (one update per tile per quad row, `f64::ceil`),
    /// kept to check that the faster counting gives the same numbers.
    fn reference(mesh: &Mesh, spec: &str, width: u32, height: u32) -> Coverage {
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
            let first = (lo - 0.5).ceil().max(0.0);
            let last = ((hi - 0.5).ceil() - 1.0).min(f64::from(width) - 1.0);
            (first <= last).then_some((first as u32, last as u32))
        }
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
            let n_tiles = touched.len() as u64;
            for tile in touched.drain(..) {
                pack.emit(tile, std::mem::take(&mut counts[tile as usize]));
            }
            c.tiles += n_tiles;
            if frags > 0 {
                c.triangles += 1;
                c.by_size[if n_tiles <= 1 {
                    0
                } else if n_tiles <= 16 {
                    1
                } else {
                    2
                }] += 1;
            }
            c.fragments += frags;
            c.quads += quads;
        }
        c.warps = pack.warps;
        c
    }

    #[test]
    fn the_counts_equal_the_per_tile_reference() {
        // Every mesh and size of the shipped pass CSVs (H200 and llvmpipe),
        // and odd target sizes, thin and off-screen triangles.
        let cases: &[(&str, &[(u32, u32)])] = &[
            (
                "grid:256x256",
                &[(64, 64), (128, 128), (512, 512), (1024, 1024), (2048, 2048)],
            ),
            (
                "grid:32x32",
                &[(64, 64), (128, 128), (512, 512), (1024, 1024), (2048, 2048), (37, 101)],
            ),
            ("grid:64x64:shuffled:1", &[(128, 128), (512, 512), (2048, 2048)]),
            (
                "grid:96x96:optimized",
                &[(128, 128), (384, 384), (512, 512), (2048, 2048)],
            ),
            (
                "random:30000:5000:7",
                &[(128, 128), (512, 512), (2048, 2048), (333, 77)],
            ),
            ("strip:64x64", &[(128, 128), (512, 512), (2048, 2048)]),
            ("grid:100x40", &[(256, 256)]),
            ("grid:128x128:local:64:1", &[(256, 256)]),
            ("grid:128x128:shuffled:2", &[(256, 256), (17, 33)]),
            ("grid:1x1", &[(384, 384), (1, 1)]),
            ("grid:33x17", &[(256, 256)]),
            ("random:3000:700:3", &[(256, 256), (31, 2000), (1, 5)]),
            ("strip:20x20", &[(256, 256)]),
        ];
        for (spec, sizes) in cases {
            let mesh = mesh_from_spec(spec, std::path::Path::new(".")).unwrap();
            for &(w, h) in *sizes {
                assert_eq!(
                    coverage(&mesh, spec, w, h),
                    reference(&mesh, spec, w, h),
                    "{spec} at {w}x{h}"
                );
            }
        }
    }

    #[test]
    fn the_fast_ceiling_is_the_ceiling() {
        for x in [
            -2.5, -1.0, -0.5, -1e-300, 0.0, 1e-300, 0.5, 0.999_999, 1.0, 1.000_001, 2047.5, 3.9e15, 5e15, -5e15, 1e300,
        ] {
            assert_eq!(ceil(x), x.ceil(), "{x}");
        }
        assert!(ceil(f64::NAN).is_nan());
        assert_eq!(ceil(f64::INFINITY), f64::INFINITY);
        assert_eq!(ceil(f64::NEG_INFINITY), f64::NEG_INFINITY);
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
