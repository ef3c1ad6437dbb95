//! The analyser's loop for a list whose clock cannot wrap: every list below
//! about 4e9 / (cache + 4) triangles, so every list in practice. The counts
//! are the general loop's, exactly ([`super::analyze`] picks this loop
//! when the list's most possible ticks fit in 32 bits); what changes is
//! what a triangle costs.
//!
//! - With no wrap every stamp is at most the clock, so "stale" is `stamp <
//!   live` with `live = clock - cache` kept beside the clock: one compare of
//!   the loaded stamp against a register.
//! - The warp's fill is the clock's distance from its value right after the
//!   last flush (each miss ticks the clock once), and the warp test is one
//!   compare of the clock against `warn`, the clock at which the warp has
//!   fewer than three free slots; only then are a triangle's stamps read
//!   twice (a triangle misses at most three times).
//! - A primitive group's end is the loop's bound, so counting a group's
//!   triangles costs nothing per triangle.
//! - The indices are checked against the stamp array a block at a time
//!   ([`CHECKED`] triangles, with AVX2's unsigned maximum where the
//!   processor has it), and the loop then reads the stamps unchecked.
//! - Each triangle asks for the indices one block ahead to be prefetched
//!   ([`prefetch_ahead`]): the next block's check then reads them from the
//!   first-level cache, instead of waiting on the shared cache for a pass
//!   of its own while the loop's work stands still. A list of 2.16 M
//!   indices (8.6 MB) does not fit the 2 MB second-level cache, so without
//!   it the check took about a sixth of the analyser's time (sampled:
//!   18% in `largest`).
//! - Each of the four variants is a function of its own (`inline(never)`),
//!   so that changing one does not move another's code: when the four were
//!   inlined into one, the same variant's time moved by up to 20% with
//!   changes to the others.
//!
//! `cargo bench --bench vcache` times it against meshoptimizer's C++ in the
//! same process; `docs/models.md` has the figures.

use super::{Counts, OutOfRange, Policy};

/// Triangles checked at a time before the loop runs over them unchecked
/// (3 KiB of indices, prefetched while the block before runs and still in
/// the first-level cache when the loop reads them; 1024 measured within the
/// noise of 256, with 12 KiB a block to hold there). Tests use small blocks
/// so that every boundary is crossed.
const CHECKED: usize = if cfg!(test) { 5 } else { 256 };

/// `$portable(x)` compiled with AVX2 where the processor has it (one
/// runtime check), as written otherwise: the body of a slice scan that
/// the compiler vectorises.
macro_rules! avx2_or_portable {
    ($portable:ident, $x:expr, $out:ty) => {{
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2")]
            fn avx2(x: &[u32]) -> $out {
                $portable(x)
            }
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the processor has AVX2, checked just above.
                return unsafe { avx2($x) };
            }
        }
        $portable($x)
    }};
}

/// The largest of `x` (0 when empty): AVX2's unsigned maximum where the
/// processor has it, the portable loop otherwise.
fn largest(x: &[u32]) -> u32 {
    #[inline(always)]
    fn portable(x: &[u32]) -> u32 {
        x.iter().copied().fold(0, u32::max)
    }
    avx2_or_portable!(portable, x, u32)
}

/// How many of `stamps` are not zero: the unique vertices (a stamp is the
/// clock, never zero, once its vertex has been inserted), with AVX2 where
/// the processor has it.
pub(super) fn stamped(stamps: &[u32]) -> u64 {
    #[inline(always)]
    fn portable(x: &[u32]) -> u64 {
        // 32-bit sums over chunks too short to overflow one.
        x.chunks(1 << 24)
            .map(|c| u64::from(c.iter().map(|&s| u32::from(s != 0)).sum::<u32>()))
            .sum()
    }
    avx2_or_portable!(portable, stamps, u64)
}

/// Whether a list of `triangles` can be run by [`run`]: the most its clock
/// can tick fits in 32 bits. That is three misses a triangle and two
/// flushes before it: a group's end, then, with warps of one or two
/// vertices, the triangle's own warp test (a second flush of an empty warp,
/// which changes no count: everything is stale after the first).
pub(super) fn fits(p: &Policy, triangles: usize) -> bool {
    let n = triangles as u64;
    (u64::from(p.cache) + 1) * (2 * n + 1) + 3 * n < u64::from(u32::MAX)
}

/// The clock of a list that cannot wrap: `ts` ticks once a miss, and a
/// vertex is in the cache while its stamp is at least `live = ts - cache`.
struct Clock {
    ts: u32,
    live: u32,
}

impl Clock {
    /// One triangle's three indices through the FIFO, in order: each stale
    /// vertex is stamped with the clock, which then ticks. Returns the
    /// triangle's misses.
    ///
    /// Every index of `t` must be below `stamps.len()`.
    #[inline(always)]
    fn visit(&mut self, stamps: &mut [u32], t: &[u32; 3]) -> u32 {
        let before = self.ts;
        for &v in t {
            debug_assert!((v as usize) < stamps.len());
            // SAFETY: `run` checks every index of a block against
            // `stamps.len()` before it visits the block's triangles.
            let s = unsafe { stamps.get_unchecked_mut(v as usize) };
            if *s < self.live {
                *s = self.ts;
                self.ts += 1;
                self.live += 1;
            }
        }
        self.ts - before
    }

    /// The misses `t` would take now (its stamps read, none written).
    ///
    /// Every index of `t` must be below `stamps.len()`.
    #[inline(always)]
    fn would_miss(&self, stamps: &[u32], t: &[u32; 3]) -> u32 {
        let mut m = 0;
        for &v in t {
            debug_assert!((v as usize) < stamps.len());
            // SAFETY: as in `visit`.
            m += u32::from(unsafe { *stamps.get_unchecked(v as usize) } < self.live);
        }
        m
    }
}

/// Asks for the indices one checked block past `t` to be brought into the
/// first-level cache, so that the next block's check reads them there
/// while this block's loop runs (a hint: it reads nothing and cannot fault).
/// One a triangle, about five a cache line: the repeats hit the line
/// already asked for, and cost less than a counter that skips them.
#[inline(always)]
fn prefetch_ahead(t: &[u32; 3]) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let ahead = (t as *const [u32; 3]).wrapping_add(CHECKED);
        // SAFETY: a prefetch is a hint; it neither reads nor faults, even
        // past the end of the list.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(ahead.cast::<i8>()) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = t;
}

/// meshoptimizer's loop over a whole list that [`fits`], from a fresh
/// cache, charging each triangle's misses. Returns the counts and the fill
/// of the last, open warp; `Err` as soon as a block holds an index past
/// `stamps` (what was charged is then to be discarded).
#[inline(never)]
fn run_variant<const WARP: bool, const PRIM: bool>(
    p: &Policy,
    stamps: &mut [u32],
    tris: &[[u32; 3]],
    mut charge: impl FnMut(u8),
) -> Result<(Counts, u32), OutOfRange> {
    let Policy { cache, warp, primgroup } = *p;
    let n = tris.len();
    let mut clock = Clock { ts: cache + 1, live: 1 };
    // The clock right after the last flush, and the clock from which the
    // warp has fewer than three free slots.
    let mut seg = clock.ts;
    let slack = warp.saturating_sub(2);
    let mut warn = seg.saturating_add(slack);
    // The current group ends before triangle `end`.
    let group = if PRIM { primgroup as usize } else { n };
    let mut end = n.min(group);
    // Triangles before `checked` have had their indices checked.
    let mut checked = 0usize;
    let mut counts = Counts::default();
    let mut j = 0usize;
    macro_rules! flush {
        () => {
            counts.transformed += u64::from(clock.ts - seg);
            counts.warps += u64::from(clock.ts > seg);
            counts.flushes += 1;
            clock.ts += cache + 1;
            clock.live = clock.ts - cache;
            seg = clock.ts;
            warn = seg.saturating_add(slack);
        };
    }
    'blocks: while j < n {
        if j == checked {
            checked = n.min(checked + CHECKED);
            if largest(tris[j..checked].as_flattened()) as usize >= stamps.len() {
                return Err(OutOfRange);
            }
        }
        if j == end {
            // The group is full: flush before triangle j.
            flush!();
            end = n.min(j + group);
        }
        let stop = end.min(checked);
        let mut it = tris[j..stop].iter();
        while let Some(t) = it.next() {
            prefetch_ahead(t);
            if WARP && clock.ts >= warn && clock.ts - seg + clock.would_miss(stamps, t) > warp {
                flush!();
                charge(clock.visit(stamps, t) as u8);
                // A new group starts at this triangle.
                let at = stop - it.len() - 1;
                j = at + 1;
                end = n.min(at + group);
                continue 'blocks;
            }
            charge(clock.visit(stamps, t) as u8);
        }
        j = stop;
    }
    counts.transformed += u64::from(clock.ts - seg);
    Ok((counts, clock.ts - seg))
}

/// [`run_variant`] in the variant `p` needs: the warp and group tests are
/// compiled only into the variants whose policy has them.
pub(super) fn run(
    p: &Policy,
    stamps: &mut [u32],
    tris: &[[u32; 3]],
    charge: impl FnMut(u8),
) -> Result<(Counts, u32), OutOfRange> {
    debug_assert!(fits(p, tris.len()));
    match (p.warp != 0, p.primgroup != 0) {
        (false, false) => run_variant::<false, false>(p, stamps, tris, charge),
        (true, false) => run_variant::<true, false>(p, stamps, tris, charge),
        (false, true) => run_variant::<false, true>(p, stamps, tris, charge),
        (true, true) => run_variant::<true, true>(p, stamps, tris, charge),
    }
}
