//! meshoptimizer's vertex-cache analyser (`meshopt_analyzeVertexCache`) on
//! whole triangle lists: the same counts, exactly, computed faster (issue 30
//! item 3).
//!
//! The model (paper 000 section 4.5's FIFO, with the warps and primitive
//! groups of meshoptimizer's GPU model): every vertex carries the clock
//! value of its last insertion; a vertex is in the cache while the clock
//! has moved at most `cache` ticks since; each miss ticks the clock once; a
//! triangle that would take its warp past `warp` vertices, or that starts a
//! new group of `primgroup` triangles, first flushes the cache (the clock
//! jumps by `cache + 1`, so every stamp is stale).
//!
//! Two loops give the same counts. The general one (`run_span`) is
//! meshoptimizer's, with the clock compared by wrapping subtraction as its
//! C++ does, and the warp and group tests compiled only into the variants
//! whose policy has them. Lists short enough that the clock cannot wrap
//! (below about 4e9 / (2 cache + 5) triangles: all but the largest) run
//! `no_wrap`'s loop, which costs a triangle fewer instructions (its
//! module says how). `cargo bench --bench vcache` compares them with
//! meshoptimizer's C++ in the same process; `docs/models.md` has the
//! figures.
//!
//! Tried and dropped (slower here, kept out): hit and miss as arithmetic
//! instead of a branch (every index then stores its stamp, and the next
//! triangle's loads wait on those stores: 2-3x slower than the branch),
//! checking the whole index buffer in a first pass (it streams the indices
//! twice), a stamp buffer kept between calls (cleared each call, and
//! again with an epoch base so that a call neither clears nor allocates it:
//! our time 0.95-1.08x of before over four A/B rounds, no gain; what moved
//! was meshoptimizer's own time, with the allocator's state), for a cache
//! that holds a whole warp (`cache >= warp`: a vertex hits exactly when seen
//! since the last flush) misses counted without a branch and every vertex
//! stamped with the segment's number (1.37-1.57x slower on `32,32,32`, four A/B rounds: the
//! unconditional stores cost more than the mispredicted branches they
//! replace), and splitting the list
//! across threads with a catch-up at each part's start (the warp and group
//! policies never fall into step with the true state, so the catch-up ran
//! whole parts again). For the flushes of `32,32,32`: the triangles right
//! after a flush visited by a copy of the loop of their own (no gain), and
//! the first of them without reading its stamps (all are stale; slower on
//! optimized meshes), and one flat loop over the triangles with a single
//! bookkeeping test a triangle, so that a flush does not leave the inner
//! loop (slower on all nine of the benchmark's cases: lowest ratio to
//! meshoptimizer 1.08x, optimized `32,32,32` 1.31x against 1.34x), and
//! prefetching the next block's indices all at once at each block's check
//! (slower than no prefetch on eight of the nine cases), and prefetching
//! the stamps of the triangle eight ahead (no gain on shuffled `32,0,0`,
//! 1.0-1.5x slower on the ordered meshes).

mod no_wrap;

/// The analyser's policy: FIFO of `cache` entries, warps of `warp` vertices
/// (0: none), groups of `primgroup` triangles (0: none).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Policy {
    cache: u32,
    warp: u32,
    primgroup: u32,
}

/// The analyser's state beside the stamps: the clock and the fill of the
/// current warp and group.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Clock {
    timestamp: u32,
    warp_offset: u32,
    prim_offset: u32,
}

impl Clock {
    fn start(p: &Policy) -> Self {
        Clock {
            timestamp: p.cache.wrapping_add(1),
            warp_offset: 0,
            prim_offset: 0,
        }
    }
}

/// Counts of a span of triangles: vertices transformed, warps closed (the
/// last, open warp is counted once, at the end of the whole list) and
/// flushes (each moves the clock by `cache + 1`).
#[derive(Debug, Clone, Copy, Default)]
struct Counts {
    transformed: u64,
    warps: u64,
    flushes: u64,
}

impl Counts {
    /// The most a clock can have moved over these counts, from its start.
    fn ticks(&self, p: &Policy) -> u64 {
        (u64::from(p.cache) + 1) * (self.flushes + 1) + self.transformed
    }
}

/// An index at or past the stamp array.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct OutOfRange;

/// Whether a vertex with this stamp misses at this clock.
#[inline(always)]
fn stale(p: &Policy, clock: &Clock, stamp: u32) -> bool {
    clock.timestamp.wrapping_sub(stamp) > p.cache
}

/// Flushes before triangle `t` if its group is full or it would overflow
/// its warp (meshoptimizer's test, in that order).
#[inline(always)]
fn flush_before<const WARP: bool, const PRIM: bool>(
    p: &Policy,
    clock: &mut Clock,
    stamps: &[u32],
    t: &[u32; 3],
    counts: &mut Counts,
) -> Result<bool, OutOfRange> {
    if !(WARP || PRIM) {
        return Ok(false);
    }
    let full_group = PRIM && clock.prim_offset == p.primgroup;
    // At most three misses: only a warp with fewer than three free slots
    // can overflow, so only then are the stamps read.
    let over_warp = WARP && !full_group && clock.warp_offset + 3 > p.warp && {
        let mut m = 0;
        for &v in t {
            m += u32::from(stale(p, clock, *stamps.get(v as usize).ok_or(OutOfRange)?));
        }
        clock.warp_offset + m > p.warp
    };
    if full_group || over_warp {
        counts.warps += u64::from(clock.warp_offset > 0);
        counts.flushes += 1;
        clock.warp_offset = 0;
        clock.prim_offset = 0;
        clock.timestamp = clock.timestamp.wrapping_add(p.cache.wrapping_add(1));
        return Ok(true);
    }
    Ok(false)
}

/// The analyser's loop over `tris` from `clock`, charging each triangle's
/// misses.
#[inline(always)]
fn run_span<const WARP: bool, const PRIM: bool>(
    p: &Policy,
    clock: &mut Clock,
    stamps: &mut [u32],
    tris: &[[u32; 3]],
    mut charge: impl FnMut(u8),
) -> Result<Counts, OutOfRange> {
    let mut counts = Counts::default();
    for t in tris {
        flush_before::<WARP, PRIM>(p, clock, stamps, t, &mut counts)?;
        let mut k = 0u32;
        for &v in t {
            let s = stamps.get_mut(v as usize).ok_or(OutOfRange)?;
            if stale(p, clock, *s) {
                *s = clock.timestamp;
                clock.timestamp = clock.timestamp.wrapping_add(1);
                k += 1;
            }
        }
        clock.warp_offset = clock.warp_offset.wrapping_add(k);
        if PRIM {
            clock.prim_offset += 1;
        }
        counts.transformed += u64::from(k);
        charge(k as u8);
    }
    Ok(counts)
}

/// [`run_span`] in the variant `p` needs.
fn run_any(
    p: &Policy,
    clock: &mut Clock,
    stamps: &mut [u32],
    tris: &[[u32; 3]],
    charge: impl FnMut(u8),
) -> Result<Counts, OutOfRange> {
    match (p.warp != 0, p.primgroup != 0) {
        (false, false) => run_span::<false, false>(p, clock, stamps, tris, charge),
        (true, false) => run_span::<true, false>(p, clock, stamps, tris, charge),
        (false, true) => run_span::<false, true>(p, clock, stamps, tris, charge),
        (true, true) => run_span::<true, true>(p, clock, stamps, tris, charge),
    }
}

/// Unique vertices of `indices` without stamps (when a 32-bit clock may
/// have wrapped to zero).
fn count_seen(indices: &[u32], vertex_count: usize) -> u64 {
    let mut seen = vec![false; vertex_count];
    indices
        .iter()
        .filter(|&&i| !std::mem::replace(&mut seen[i as usize], true))
        .count() as u64
}

/// meshoptimizer's analyser on a whole triangle list (`indices.len()` a
/// multiple of 3): a FIFO of `cache` entries, warps of `warp` vertices,
/// groups of `primgroup` triangles (`fifo:N` is `(N, 0, 0)`), on a dense
/// stamp array of `vertex_count` entries, charging each triangle's misses.
/// Returns (transformed, warps, unique vertices), or `None` as soon as an
/// index is not below `vertex_count` (what was charged is then to be
/// discarded). Re-exported as `vertex_cache::analyze_triangle_list`.
pub fn analyze(
    indices: &[u32],
    vertex_count: usize,
    cache: u32,
    warp: u32,
    primgroup: u32,
    charge: impl FnMut(u8),
) -> Option<(u64, u64, u64)> {
    let p = Policy { cache, warp, primgroup };
    let (tris, _) = indices.as_chunks::<3>();
    if !no_wrap::fits(&p, tris.len()) {
        return general(indices, vertex_count, &p, charge);
    }
    let mut stamps = vec![0u32; vertex_count];
    let (counts, open) = no_wrap::run(&p, &mut stamps, tris, charge).ok()?;
    let warps = counts.warps + u64::from(open > 0);
    Some((counts.transformed, warps, no_wrap::stamped(&stamps)))
}

/// [`analyze`] by the general loop, for any length of list.
fn general(indices: &[u32], vertex_count: usize, p: &Policy, charge: impl FnMut(u8)) -> Option<(u64, u64, u64)> {
    let (tris, _) = indices.as_chunks::<3>();
    let mut stamps = vec![0u32; vertex_count];
    let mut clock = Clock::start(p);
    let counts = run_any(p, &mut clock, &mut stamps, tris, charge).ok()?;
    let warps = counts.warps + u64::from(clock.warp_offset > 0);
    // A stamp stays non-zero after its vertex's first insertion unless the
    // clock wrapped to zero (about 4e9 / cache triangles would be needed).
    let unique = if counts.ticks(p) < u64::from(u32::MAX) {
        no_wrap::stamped(&stamps)
    } else {
        count_seen(indices, vertex_count)
    };
    Some((counts.transformed, warps, unique))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// meshoptimizer's loop as written in its C++ (`indexanalyzer.cpp`):
    /// the oracle.
    fn meshopt_loop(indices: &[u32], n: usize, cache: u32, warp: u32, primgroup: u32) -> (u64, u64, u64) {
        let mut stamps = vec![0u32; n];
        let mut ts = cache.wrapping_add(1);
        let (mut wo, mut po, mut warps, mut transformed) = (0u32, 0u32, 0u64, 0u64);
        for t in indices.chunks_exact(3) {
            let m: u32 = t
                .iter()
                .map(|&v| u32::from(ts.wrapping_sub(stamps[v as usize]) > cache))
                .sum();
            if (primgroup != 0 && po == primgroup) || (warp != 0 && wo + m > warp) {
                warps += u64::from(wo > 0);
                wo = 0;
                po = 0;
                ts = ts.wrapping_add(cache + 1);
            }
            for &v in t {
                if ts.wrapping_sub(stamps[v as usize]) > cache {
                    stamps[v as usize] = ts;
                    ts = ts.wrapping_add(1);
                    transformed += 1;
                    wo += 1;
                }
            }
            po += 1;
        }
        warps += u64::from(wo > 0);
        (transformed, warps, stamps.iter().filter(|&&s| s != 0).count() as u64)
    }

    /// Triangle lists over `n` vertices, with repeated and degenerate
    /// triangles and runs of neighbours (so caches hit).
    fn list() -> impl Strategy<Value = (Vec<u32>, usize)> {
        (3usize..300).prop_flat_map(|n| {
            let tri = prop_oneof![
                3 => (0..n as u32).prop_map(move |a| vec![a, a.saturating_add(1) % n as u32, a.saturating_add(2) % n as u32]),
                2 => prop::collection::vec(0..n as u32, 3),
                1 => (0..n as u32).prop_map(|a| vec![a, a, a]),
            ];
            (prop::collection::vec(tri, 0..400).prop_map(|v| v.concat()), Just(n))
        })
    }

    fn policy() -> impl Strategy<Value = (u32, u32, u32)> {
        (
            3u32..40,
            prop_oneof![Just(0u32), 1u32..70],
            prop_oneof![Just(0u32), 1u32..130],
        )
    }

    proptest! {
        #[test]
        fn the_analyser_counts_what_meshoptimizer_counts((idx, n) in list(), (c, w, p) in policy()) {
            let oracle = meshopt_loop(&idx, n, c, w, p);
            let mut charged = vec![];
            prop_assert_eq!(analyze(&idx, n, c, w, p, |k| charged.push(k)), Some(oracle));
            prop_assert_eq!(charged.iter().map(|&k| u64::from(k)).sum::<u64>(), oracle.0);
            // The general loop, which the lists too long for a 32-bit clock
            // run: the same counts, and the same misses triangle by triangle.
            let mut general_charged = vec![];
            let policy = Policy { cache: c, warp: w, primgroup: p };
            prop_assert_eq!(general(&idx, n, &policy, |k| general_charged.push(k)), Some(oracle));
            prop_assert_eq!(general_charged, charged);
        }
    }

    #[test]
    fn an_index_past_the_vertices_is_refused() {
        let mut idx: Vec<u32> = (0..3000u32).map(|i| i % 90).collect();
        assert_eq!(
            analyze(&idx, 90, 16, 0, 0, |_| {}),
            Some(meshopt_loop(&idx, 90, 16, 0, 0))
        );
        // In the first triangle, at a block's edge, in a block's middle and
        // in the last triangle, under each variant of the loop.
        for at in [0, 14, 15, 2500, 2999] {
            let before = idx[at];
            idx[at] = 90;
            for (w, p) in [(0, 0), (32, 0), (0, 7), (32, 7)] {
                assert_eq!(
                    analyze(&idx, 90, 16, w, p, |_| {}),
                    None,
                    "index {at}, warp {w}, group {p}"
                );
                let policy = Policy {
                    cache: 16,
                    warp: w,
                    primgroup: p,
                };
                assert_eq!(
                    general(&idx, 90, &policy, |_| {}),
                    None,
                    "index {at}, warp {w}, group {p}"
                );
            }
            idx[at] = u32::MAX;
            assert_eq!(analyze(&idx, 90, 16, 0, 0, |_| {}), None);
            idx[at] = before;
        }
        assert_eq!(analyze(&[0, 0, 0], 0, 16, 0, 0, |_| {}), None);
        assert_eq!(analyze(&[], 0, 16, 32, 7, |_| {}), Some((0, 0, 0)));
    }

    #[test]
    fn only_lists_whose_clock_could_wrap_take_the_general_loop() {
        let p = |cache| Policy {
            cache,
            warp: 0,
            primgroup: 0,
        };
        // 2 flushes and 3 misses a triangle at most: (33 * (2n + 1) + 3n < 2^32.
        assert!(no_wrap::fits(&p(32), 62_000_000));
        assert!(!no_wrap::fits(&p(32), 63_000_000));
        assert!(no_wrap::fits(&p(u32::MAX - 2), 0));
        assert!(!no_wrap::fits(&p(u32::MAX), 0));
    }
}
