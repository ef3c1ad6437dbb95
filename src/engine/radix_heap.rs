//! A radix heap for monotone integer time, with 256-way digits.
//!
//! A discrete-event loop only ever schedules events at or after the time it
//! last popped, so keys are monotone (Ahuja, Mehlhorn, Orlin & Tarjan's
//! radix heap exploits exactly that). Here a time is read as eight bytes. An
//! event due at `t` is kept in the bucket (level `l`, digit `v`): `l` is the
//! highest byte in which `t` differs from the last popped time `last`, and
//! `v` is `t`'s value of that byte (events due at `last` itself wait in the
//! "now" list). Buckets of a lower level hold earlier events, and within a
//! level a lower digit means earlier, so the earliest bucket is found from
//! two bit masks. A level-0 bucket holds one single time and becomes the
//! "now" list as it is; a higher one is spread around its minimum into lower
//! buckets. An event therefore moves at most eight times in all, and for the
//! nanosecond delays of a GPU model (below 2^24 ps) at most twice: the cost
//! per event stays flat however many are pending and however far apart
//! their times are (picosecond costs next to one-second periods), where a
//! binary heap pays log n cache misses.
//!
//! Same-time events leave in scheduling order: every bucket is in sequence
//! order (a new event has the largest sequence number so far and is
//! appended; a bucket is only spread into buckets that are empty, in its own
//! order), so the pop order is exactly the binary heap's `(time, seq)` order.
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
/// Pending events the small sorted array holds before the heap uses its buckets.
pub const SMALL_MAX: usize = 32;
/// Pending events at or below which the heap returns to the small array.
pub const SMALL_BACK: usize = 8;

/// The radix heap (see the module documentation).
#[derive(Debug)]
pub struct RadixHeap<E> {
    /// The last popped time: every pending event is due at or after it.
    last: u64,
    /// Due at `last`, in sequence order.
    now: VecDeque<Scheduled<E>>,
    /// Bucket (level l, digit v) at index l * 256 + v.
    buckets: Box<[Vec<Scheduled<E>>]>,
    /// Bit l set when level l has a non-empty bucket.
    levels: u32,
    /// Per level, bit v set when bucket (l, v) is non-empty.
    digits: [[u64; 4]; LEVELS],
    /// Events scheduled before `last` (model bugs), popped first.
    stale: Vec<Scheduled<E>>,
    len: usize,
    /// True while the events are in `small` (and nothing is in the buckets,
    /// `now` or `stale`).
    is_small: bool,
    /// Small form: pending events sorted by `(time, seq)`, latest first.
    small: Vec<Scheduled<E>>,
}

impl<E> Default for RadixHeap<E> {
    fn default() -> Self {
        Self::new()
    }
}

/// The bucket of `time` relative to `last` (`None`: due at `last`).
#[inline]
fn slot(time: u64, last: u64) -> Option<(usize, usize)> {
    let x = time ^ last;
    if x == 0 {
        return None;
    }
    let level = (63 - x.leading_zeros() as usize) / 8;
    Some((level, ((time >> (8 * level)) & 0xff) as usize))
}

impl<E> RadixHeap<E> {
    /// An empty heap at time zero.
    pub fn new() -> Self {
        RadixHeap {
            last: 0,
            now: VecDeque::new(),
            buckets: (0..LEVELS * DIGITS).map(|_| Vec::new()).collect(),
            levels: 0,
            digits: [[0; 4]; LEVELS],
            stale: Vec::new(),
            len: 0,
            is_small: true,
            small: Vec::with_capacity(SMALL_MAX),
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

    /// Leaves the small form: files its events into the buckets in
    /// `(time, seq)` order.
    #[cold]
    fn spill_to_buckets(&mut self) {
        self.is_small = false;
        let mut small = std::mem::take(&mut self.small);
        while let Some(s) = small.pop() {
            if s.time.0 < self.last {
                self.stale.push(s);
            } else {
                self.file(s);
            }
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

    #[inline]
    fn file(&mut self, s: Scheduled<E>) {
        match slot(s.time.0, self.last) {
            None => self.now.push_back(s),
            Some((l, v)) => {
                self.buckets[l * DIGITS + v].push(s);
                self.levels |= 1 << l;
                self.digits[l][v / 64] |= 1 << (v % 64);
            }
        }
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
        if s.time.0 < self.last {
            self.stale.push(s);
        } else {
            self.file(s);
        }
    }

    /// Puts back the event just popped (it goes before every other event
    /// due at the same time, as it was).
    pub fn restore(&mut self, s: Scheduled<E>) {
        if self.is_small {
            // It was the earliest: it goes back to the end.
            self.len += 1;
            self.small.push(s);
            return;
        }
        if s.time.0 == self.last {
            self.len += 1;
            self.now.push_front(s);
        } else {
            self.push(s);
        }
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
        let s = self.pop_buckets();
        if self.len <= SMALL_BACK {
            self.gather_to_small();
        }
        s
    }

    /// Removes the earliest event from the bucket form.
    #[inline]
    fn pop_buckets(&mut self) -> Option<Scheduled<E>> {
        if !self.stale.is_empty() {
            return self.pop_stale();
        }
        if self.now.is_empty() {
            if self.levels == 0 {
                return None;
            }
            // The earliest bucket holds a single event (the common case when
            // few are pending): it is the next one, no need to spread it.
            let (l, v) = self.first_bucket()?;
            let b = &mut self.buckets[l * DIGITS + v];
            if b.len() == 1 {
                let s = b.pop()?;
                self.clear_bucket(l, v);
                self.last = s.time.0;
                self.len -= 1;
                return Some(s);
            }
            self.refill();
        }
        self.len -= 1;
        self.now.pop_front()
    }

    /// The earliest non-empty bucket, as (level, digit).
    #[inline]
    fn first_bucket(&self) -> Option<(usize, usize)> {
        if self.levels == 0 {
            return None;
        }
        let l = self.levels.trailing_zeros() as usize;
        let words = &self.digits[l];
        let w = words.iter().position(|&w| w != 0)?;
        Some((l, w * 64 + words[w].trailing_zeros() as usize))
    }

    /// Marks bucket (l, v) empty in the masks.
    #[inline]
    fn clear_bucket(&mut self, l: usize, v: usize) {
        self.digits[l][v / 64] &= !(1 << (v % 64));
        if self.digits[l].iter().all(|&w| w == 0) {
            self.levels &= !(1 << l);
        }
    }

    /// Moves the earliest bucket to "now" (level 0: one time) or spreads it
    /// around its minimum, which becomes the new `last`.
    fn refill(&mut self) {
        let Some((l, v)) = self.first_bucket() else {
            return;
        };
        let mut moving = std::mem::take(&mut self.buckets[l * DIGITS + v]);
        self.clear_bucket(l, v);
        if l == 0 {
            self.last = (self.last & !0xff) | v as u64;
            self.now.extend(moving.drain(..));
        } else {
            self.last = moving.iter().map(|s| s.time.0).min().unwrap_or(self.last);
            for s in moving.drain(..) {
                // Lands below level l: it agreed with the old `last` above
                // byte l, and so does the new one.
                self.file(s);
            }
        }
        // Keep the allocation for the next time this bucket fills.
        self.buckets[l * DIGITS + v] = moving;
        debug_assert!(self.now.iter().zip(self.now.iter().skip(1)).all(|(a, b)| a.seq < b.seq));
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
        if let Some(s) = self.now.front() {
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
