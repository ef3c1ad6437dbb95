//! A radix heap for monotone integer time, with 256-way digits.
//!
//! A discrete-event loop only ever schedules events at or after the time it
//! last popped, so keys are monotone (Ahuja, Mehlhorn, Orlin & Tarjan's
//! radix heap exploits exactly that). Here a time is read as eight bytes.
//!
//! The earliest events wait in the *run*, sorted by `(time, seq)`; every
//! other event is due after the run's last one and is kept in the bucket
//! (level `l`, digit `v`): `l` is the highest byte in which its time `t`
//! differs from `last` (the run's first time when the run was made), and
//! `v` is `t`'s value of that byte. Buckets of a lower level hold earlier
//! events, and within a level a lower digit means earlier, so the earliest
//! bucket is found from two bit masks. When the run is empty the earliest
//! bucket becomes the next run: a level-0 bucket holds one single time and
//! is the run as it is; a level-1 bucket (256 ps) is sorted in place by its
//! low byte (a stable counting sort, no comparisons) and becomes the run; a
//! bucket of at most [`SORT_MAX`] events
//! is sorted instead, and a larger one above level 1 spread around its
//! minimum into lower buckets. `last` moves only then (moving it while the run is popped could
//! file a later event into a lower bucket than an earlier one). An event
//! therefore moves at most eight times in all, and for the nanosecond
//! delays of a GPU model (below 2^24 ps) at most three times: the cost per
//! event stays flat however many are pending and however far apart their
//! times are (picosecond costs next to one-second periods), where a binary
//! heap pays log n cache misses. A new event due no later than the run's
//! last one is inserted into the run in its place (usually at its end).
//!
//! Same-time events leave in scheduling order: every bucket is in sequence
//! order (a new event has the largest sequence number so far and is
//! appended; a bucket is only spread into buckets that are empty, in its own
//! order; the counting sort is stable), so the pop order is exactly the
//! binary heap's `(time, seq)` order.
//!
//! An event scheduled before the last popped time (a model bug the run loop
//! reports) is kept aside and popped first, so the loop sees it at once.
//!
//! While few events are pending (a rendering pipeline keeps about five: the
//! next vertical blank, the noise sources, the CPU's and the GPU's next
//! completion) they are kept in one small array sorted latest first, so a
//! push is a short scan and a pop takes the last element: no buckets, no
//! spreading. Past [`SMALL_MAX`] pending the heap files them into its
//! buckets (in `(time, seq)` order, which keeps every bucket in sequence
//! order) and goes back to the array once at most [`SMALL_BACK`] are left.
//! The pop order is the same `(time, seq)` order in both forms.

use std::collections::VecDeque;

use super::queue::Scheduled;

const LEVELS: usize = 8;
const DIGITS: usize = 256;
/// Buckets in all: (level l, digit v) at index `l * 256 + v`.
const BUCKETS: usize = LEVELS * DIGITS;
/// Pending events the small sorted array holds before the heap uses its buckets.
pub const SMALL_MAX: usize = 32;
/// Pending events at or below which the heap returns to the small array.
pub const SMALL_BACK: usize = 8;
/// A bucket is sorted into the run when it holds at most this many events;
/// a larger one is counting-sorted (level 1) or spread into lower buckets.
pub const SORT_MAX: usize = 16;
/// Spread buckets' allocations kept for reuse.
const SPARE_MAX: usize = 16;

/// The radix heap (see the module documentation).
#[derive(Debug)]
pub struct RadixHeap<E> {
    /// Small form: the last popped time. Bucket form: the run's first time
    /// when it was made (the buckets are relative to it). Every pending
    /// event but the stale ones is due at or after it.
    last: u64,
    /// The run: the earliest events, sorted by `(time, seq)`, earliest first.
    run: VecDeque<Scheduled<E>>,
    /// The latest time in the run (`last` when it is empty): every event in
    /// the buckets is due after it.
    run_hi: u64,
    /// Bucket (level l, digit v) at index l * 256 + v (a fixed-size array,
    /// indexed under a mask: no bounds checks).
    buckets: Box<[Vec<Scheduled<E>>; BUCKETS]>,
    /// Bit l set when level l has a non-empty bucket.
    levels: u32,
    /// Bit `i % 64` of word `i / 64` set when bucket `i` is non-empty (four
    /// words per level).
    digits: [u64; BUCKETS / 64],
    /// Events scheduled before `last` (model bugs), popped first.
    stale: Vec<Scheduled<E>>,
    len: usize,
    /// True while the events are in `small` (and nothing is in the buckets,
    /// the run or `stale`).
    is_small: bool,
    /// Small form: pending events sorted by `(time, seq)`, latest first.
    small: Vec<Scheduled<E>>,
    /// The counting sort's destinations (kept for its allocation).
    scratch: Vec<u32>,
    /// Allocations of spread buckets, handed to the next empty bucket that
    /// fills (at most [`SPARE_MAX`]): a bucket above level 1 holds tens of
    /// thousands of events on a stiff mix, and growing a new one from
    /// nothing each time would double it a dozen times and touch fresh
    /// pages (page faults were a sixth of the run's time).
    spare: Vec<Vec<Scheduled<E>>>,
}

impl<E> Default for RadixHeap<E> {
    fn default() -> Self {
        Self::new()
    }
}

/// The bucket of `time` relative to `last` (`time` must differ from `last`).
#[inline]
fn slot(time: u64, last: u64) -> (usize, usize) {
    let x = time ^ last;
    debug_assert!(x != 0);
    let level = (63 - x.leading_zeros() as usize) / 8;
    (level, ((time >> (8 * level)) & 0xff) as usize)
}

impl<E> RadixHeap<E> {
    /// An empty heap at time zero.
    pub fn new() -> Self {
        RadixHeap {
            last: 0,
            run: VecDeque::new(),
            run_hi: 0,
            buckets: (0..BUCKETS)
                .map(|_| Vec::new())
                .collect::<Vec<_>>()
                .into_boxed_slice()
                .try_into()
                .unwrap_or_else(|_| unreachable!("BUCKETS buckets made")),
            levels: 0,
            digits: [0; BUCKETS / 64],
            stale: Vec::new(),
            len: 0,
            is_small: true,
            small: Vec::with_capacity(SMALL_MAX),
            scratch: Vec::new(),
            spare: Vec::new(),
        }
    }

    /// Small form: inserts `s` after (in pop order) every event due at or
    /// before its time (it has the largest sequence number so far).
    #[inline(always)]
    fn small_insert(&mut self, s: Scheduled<E>) {
        // Appended, then moved down past the earlier ones (usually few: a
        // new event tends to be among the next due); no memmove call.
        let v = &mut self.small;
        v.push(s);
        let mut i = v.len() - 1;
        while i > 0 && v[i - 1].time <= v[i].time {
            v.swap(i - 1, i);
            i -= 1;
        }
    }

    /// Leaves the small form: files its events into the run and the buckets
    /// in `(time, seq)` order.
    #[cold]
    fn spill_to_buckets(&mut self) {
        self.is_small = false;
        self.run_hi = self.last;
        let mut small = std::mem::take(&mut self.small);
        while let Some(s) = small.pop() {
            self.place(s);
        }
        self.small = small;
    }

    /// Back to the small form (few events left): pops them in order.
    #[cold]
    fn gather_to_small(&mut self) {
        let mut out = std::mem::take(&mut self.small);
        debug_assert!(out.is_empty());
        let n = self.len;
        while let Some(s) = self.pop_buckets() {
            out.push(s);
        }
        out.reverse();
        self.len = n;
        self.small = out;
        self.is_small = true;
    }

    /// Bucket form: puts a new event (the largest sequence number so far)
    /// where it belongs: aside if stale, into the run if due no later than
    /// the run's last event, else into its bucket.
    #[inline(always)]
    fn place(&mut self, s: Scheduled<E>) {
        let t = s.time.0;
        if t > self.run_hi {
            self.file(s);
        } else if t >= self.last {
            self.run_insert(s);
        } else {
            self.stale.push(s);
        }
    }

    /// Inserts into the run after every event due at or before its time.
    #[inline]
    fn run_insert(&mut self, s: Scheduled<E>) {
        let t = s.time;
        // Usually due at the run's end or after (the same instant).
        if self.run.back().is_none_or(|b| b.time <= t) {
            self.run_hi = t.0;
            self.run.push_back(s);
        } else {
            self.run_insert_inside(s);
        }
    }

    /// [`RadixHeap::run_insert`] before the run's last event.
    #[inline(never)]
    fn run_insert_inside(&mut self, s: Scheduled<E>) {
        let t = s.time;
        let i = self.run.partition_point(|x| x.time <= t);
        self.run.insert(i, s);
    }

    /// Files an event due after `run_hi` into its bucket.
    #[inline]
    fn file(&mut self, s: Scheduled<E>) {
        let (l, v) = slot(s.time.0, self.last);
        let i = (l * DIGITS + v) & (BUCKETS - 1);
        let b = &mut self.buckets[i];
        if b.len() == b.capacity() {
            self.grow_bucket(i);
        }
        self.buckets[i].push(s);
        self.levels |= 1 << l;
        self.digits[(i / 64) & (BUCKETS / 64 - 1)] |= 1 << (i % 64);
    }

    /// Bucket `i` is full: an empty one takes a spare allocation if there is
    /// one; a full one grows as a vector does.
    #[cold]
    #[inline(never)]
    fn grow_bucket(&mut self, i: usize) {
        let b = &mut self.buckets[i];
        if b.capacity() == 0
            && let Some(v) = self.spare.pop()
        {
            *b = v;
            return;
        }
        b.reserve(b.capacity().max(4));
    }

    /// Adds an event. Its sequence number must be larger than every one
    /// pushed before (the queue's counter guarantees it).
    /// The small form's path is inlined into the caller (a push passes the
    /// event in registers instead of through the stack); the rest is not.
    #[inline(always)]
    pub fn push(&mut self, s: Scheduled<E>) {
        // The array is made with room for SMALL_MAX, so the second test
        // always holds with the first; it lets the compiler drop Vec::push's
        // growing path.
        if self.is_small && self.small.len() < SMALL_MAX && self.small.len() < self.small.capacity() {
            self.len += 1;
            self.small_insert(s);
            return;
        }
        // Passed as fields: handing the whole event to a call that is not
        // inlined would keep it in memory on the fast path too.
        let Scheduled { time, seq, event } = s;
        self.push_large(time, seq, event);
    }

    /// [`RadixHeap::push`] when the small array is full or not in use.
    #[inline(never)]
    fn push_large(&mut self, time: super::time::Time, seq: u64, event: E) {
        let s = Scheduled { time, seq, event };
        self.len += 1;
        if self.is_small {
            self.spill_to_buckets();
        }
        self.place(s);
    }

    /// Puts back the event just popped (it goes before every other event
    /// due at the same time, as it was).
    pub fn restore(&mut self, s: Scheduled<E>) {
        self.len += 1;
        if self.is_small {
            // It was the earliest: it goes back to the end.
            self.small.push(s);
            return;
        }
        if s.time.0 < self.last {
            // It was stale (and the earliest of them).
            self.stale.push(s);
            return;
        }
        // It was the earliest: first in the run.
        if self.run.is_empty() {
            self.run_hi = s.time.0;
        }
        self.run.push_front(s);
    }

    /// Removes the earliest event (ties: the first scheduled).
    #[inline]
    pub fn pop(&mut self) -> Option<Scheduled<E>> {
        if self.is_small {
            let s = self.small.pop()?;
            self.len -= 1;
            // A stale event (a model bug) does not move time back.
            self.last = self.last.max(s.time.0);
            return Some(s);
        }
        // The common case first, returned straight from the run: nothing
        // stale, the run not empty, and enough left not to go back to the
        // small form. (Keeping the popped event in a local across the rest
        // would put it on the stack and read it back with wider loads than
        // the stores that wrote it: a store-forwarding stall on every pop.)
        if self.len > SMALL_BACK + 1 && self.stale.is_empty() && !self.run.is_empty() {
            self.len -= 1;
            return self.run.pop_front();
        }
        self.pop_slow()
    }

    /// [`RadixHeap::pop`] in the bucket form when the run is empty, an
    /// event is stale, or the heap goes back to the small form.
    #[inline(never)]
    fn pop_slow(&mut self) -> Option<Scheduled<E>> {
        let s = self.pop_buckets();
        if self.len <= SMALL_BACK {
            self.gather_to_small();
            // The small form's `last` is the time just popped.
            if let Some(p) = &s {
                self.last = p.time.0;
            }
        }
        s
    }

    /// Removes the earliest event from the bucket form.
    #[inline]
    fn pop_buckets(&mut self) -> Option<Scheduled<E>> {
        if !self.stale.is_empty() {
            return self.pop_stale();
        }
        if self.run.is_empty() {
            let (l, v) = self.first_bucket()?;
            let i = (l * DIGITS + v) & (BUCKETS - 1);
            if self.buckets[i].len() == 1 {
                // A single event (common when the pending events are
                // sparse): it is the next one, and its time the new `last`
                // (the earliest bucket's minimum, as when spreading).
                let s = self.buckets[i].pop()?;
                self.clear_bucket(l, v);
                self.last = s.time.0;
                self.run_hi = self.last;
                self.len -= 1;
                return Some(s);
            }
            self.refill();
        }
        // `last` stays the run's first time: the buckets are relative to
        // it, and moving it inside the run could file a later event below
        // an earlier one.
        let s = self.run.pop_front()?;
        self.len -= 1;
        Some(s)
    }

    /// The earliest non-empty bucket, as (level, digit).
    #[inline]
    fn first_bucket(&self) -> Option<(usize, usize)> {
        if self.levels == 0 {
            return None;
        }
        let l = self.levels.trailing_zeros() as usize & (LEVELS - 1);
        let words = &self.digits[l * 4..l * 4 + 4];
        let w = words.iter().position(|&w| w != 0)?;
        Some((l, w * 64 + words[w].trailing_zeros() as usize))
    }

    /// Marks bucket (l, v) empty in the masks.
    #[inline]
    fn clear_bucket(&mut self, l: usize, v: usize) {
        let i = (l * DIGITS + v) & (BUCKETS - 1);
        self.digits[(i / 64) & (BUCKETS / 64 - 1)] &= !(1 << (i % 64));
        if self.digits[l * 4..l * 4 + 4].iter().all(|&w| w == 0) {
            self.levels &= !(1 << l);
        }
    }

    /// The run is empty: the earliest bucket becomes the run. A level-0
    /// bucket holds one time and is in order already; one of at most
    /// [`SORT_MAX`] events is sorted; a larger level-1 bucket is
    /// sorted in place by its low byte (a stable counting sort: no
    /// comparisons, no allocation); a larger one above is spread around its minimum,
    /// which becomes the new `last`, into lower buckets.
    fn refill(&mut self) {
        debug_assert!(self.run.is_empty());
        let Some((l, v)) = self.first_bucket() else {
            return;
        };
        let mut moving = std::mem::take(&mut self.buckets[l * DIGITS + v]);
        self.clear_bucket(l, v);
        if l == 0 || moving.len() <= SORT_MAX {
            // In sequence order already: a level-0 bucket (one time) or a
            // single event needs nothing. Times and sequence numbers are
            // unique together, so the unstable sort on both gives the
            // `(time, seq)` order.
            if l > 0 && moving.len() > 1 {
                moving.sort_unstable_by_key(|s| (s.time.0, s.seq));
            }
            self.last = moving.first().map_or(self.last, |s| s.time.0);
            self.run_hi = moving.last().map_or(self.last, |s| s.time.0);
            // The bucket keeps the run's old (empty) allocation, the run
            // takes the bucket's: no copying, no allocation.
            let old = std::mem::replace(&mut self.run, VecDeque::from(moving));
            self.buckets[l * DIGITS + v] = Vec::from(old);
            return;
        }
        if l == 1 {
            // A stable counting sort on the low byte, in place: each event's
            // place from the counts of the smaller digits (and of the
            // earlier events of its own digit), then every event swapped
            // into its place along the permutation's cycles. No comparisons
            // and no allocation: the bucket becomes the run.
            let mut count = [0u32; DIGITS];
            for s in &moving {
                count[(s.time.0 & 0xff) as usize] += 1;
            }
            let mut at = 0u32;
            for c in count.iter_mut() {
                let n = *c;
                *c = at;
                at += n;
            }
            let dest = &mut self.scratch;
            dest.clear();
            dest.extend(moving.iter().map(|s| {
                let c = &mut count[(s.time.0 & 0xff) as usize];
                *c += 1;
                *c - 1
            }));
            for i in 0..moving.len() {
                loop {
                    let j = dest[i] as usize;
                    if j == i {
                        break;
                    }
                    moving.swap(i, j);
                    dest.swap(i, j);
                }
            }
            self.last = moving.first().map_or(self.last, |s| s.time.0);
            self.run_hi = moving.last().map_or(self.last, |s| s.time.0);
            let old = std::mem::replace(&mut self.run, VecDeque::from(moving));
            self.buckets[l * DIGITS + v] = Vec::from(old);
            return;
        }
        self.last = moving.iter().map(|s| s.time.0).min().unwrap_or(self.last);
        self.run_hi = self.last;
        for s in moving.drain(..) {
            // Lands below level l: it agreed with the old `last` above byte
            // l, and so does the new one. Due at the new `last`: into the
            // run, in sequence order.
            if s.time.0 == self.last {
                self.run.push_back(s);
            } else {
                self.file(s);
            }
        }
        // The allocation goes to the next empty bucket that fills (the
        // next bucket of this level usually, long before this one fills
        // again).
        if self.spare.len() < SPARE_MAX {
            self.spare.push(moving);
        }
    }

    #[cold]
    fn pop_stale(&mut self) -> Option<Scheduled<E>> {
        let i = (0..self.stale.len()).min_by_key(|&i| (self.stale[i].time, self.stale[i].seq))?;
        self.len -= 1;
        Some(self.stale.swap_remove(i))
    }

    /// The earliest due time, without removing anything.
    pub fn peek_time(&self) -> Option<super::time::Time> {
        if self.is_small {
            return self.small.last().map(|s| s.time);
        }
        if let Some(s) = self.stale.iter().min_by_key(|s| (s.time, s.seq)) {
            return Some(s.time);
        }
        if let Some(s) = self.run.front() {
            return Some(s.time);
        }
        let (l, v) = self.first_bucket()?;
        self.buckets[l * DIGITS + v].iter().map(|s| s.time).min()
    }

    /// Pending events.
    #[inline]
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when nothing is pending.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::time::Time;

    fn ev(time: u64, seq: u64) -> Scheduled<()> {
        Scheduled {
            time: Time(time),
            seq,
            event: (),
        }
    }

    /// A spread bucket's allocation goes to the next empty bucket that
    /// fills, instead of that bucket growing from nothing (on a stiff mix
    /// the buckets above level 1 hold tens of thousands of events each).
    #[test]
    fn a_spread_buckets_allocation_is_reused_by_the_next_bucket_that_fills() {
        let mut h = RadixHeap::new();
        let mut seq = 0;
        // 2,000 events in level-2 digit 1 (65,536 .. 131,071 ps), one each
        // 32 ps, past the small form.
        for k in 0..2_000u64 {
            h.push(ev(65_536 + 32 * k, seq));
            seq += 1;
        }
        let first = &h.buckets[2 * DIGITS + 1];
        assert_eq!(first.len(), 2_000);
        let cap = first.capacity();
        // The first pop spreads that bucket; its allocation becomes a spare.
        assert_eq!(h.pop().map(|s| s.time.0), Some(65_536));
        assert_eq!(h.spare.len(), 1);
        assert_eq!(h.buckets[2 * DIGITS + 1].capacity(), 0);
        // A new event two level-2 digits on files into an empty bucket,
        // which takes the spare whole: no growing.
        h.push(ev(3 * 65_536, seq));
        assert!(h.spare.is_empty());
        assert_eq!(h.buckets[2 * DIGITS + 3].capacity(), cap);
        // And the order is unchanged.
        let mut last = 0;
        let mut n = 1;
        while let Some(s) = h.pop() {
            assert!(s.time.0 >= last);
            last = s.time.0;
            n += 1;
        }
        assert_eq!(n, 2_001);
        assert_eq!(last, 3 * 65_536);
    }
}
